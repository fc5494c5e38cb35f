// tools/ibl-bake/image_io.cpp — the one translation unit with the third-party implementations
// (stb_image, stb_image_write) and the readers/writers of image_io.hpp.
//
// Third-party code, all from Debian packages:
//   stb (libstb-dev): compiled here, from the headers, as static functions (STB_*_STATIC) so
//     that they cannot clash with another copy (libstb.so) in the same program; no stdio entry
//     points (the tool reads whole files itself and decodes from memory).
//   tinyexr (libtinyexr-dev): Debian ships it prebuilt (libtinyexr.so, zlib for ZIP, built-in
//     PIZ) with a CMake config (tinyexr::tinyexr), so by default only the declarations are
//     included and the library is linked. Defining IBL_BAKE_TINYEXR_IMPLEMENTATION compiles the
//     implementation from the same header instead (with zlib): the fuzz build does this so that
//     tinyexr's code is instrumented for coverage and for AddressSanitizer.

#include "image_io.hpp"

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <charconv>
#include <climits>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iterator>
#include <fstream>
#include <limits>
#include <memory>
#include <initializer_list>
#include <string_view>
#include <system_error>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#define STB_IMAGE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#define STBI_NO_STDIO
// Only stb's Radiance HDR decoder is compiled in. LDR inputs are recognised by their signature
// (ldr_format_name below), never parsed: fuzzing (scripts/fuzz.sh) found undefined behaviour in
// stb's PNM header parser (signed overflow) and JPEG Huffman-table builder (out-of-bounds write)
// when they only probed arbitrary bytes; regression inputs in tools/ibl-bake/tests/data/fuzz-*.
#define STBI_ONLY_HDR
#include <stb_image.h>

#define STB_IMAGE_WRITE_STATIC
#define STB_IMAGE_WRITE_IMPLEMENTATION
// (not STBI_WRITE_NO_STDIO: Debian's stb_image_write.h of 2022-09 then omits the HDR writer)
#include <stb_image_write.h>

#ifdef IBL_BAKE_TINYEXR_IMPLEMENTATION
#define TINYEXR_IMPLEMENTATION
#endif
#include <tinyexr.h>

namespace ibl_bake {
namespace {

// ---- helpers -----------------------------------------------------------------------------------

/// A short printable excerpt of untrusted text for error messages.
std::string printable(std::string_view s, std::size_t max_len = 48) {
    std::string out;
    for (std::size_t i = 0; i < s.size() && i < max_len; ++i) {
        const unsigned char c = static_cast<unsigned char>(s[i]);
        if (c >= 0x20 && c < 0x7f) {
            out += static_cast<char>(c);
        } else {
            char buf[8];
            std::snprintf(buf, sizeof buf, "\\x%02x", c);
            out += buf;
        }
    }
    if (s.size() > max_len) out += "...";
    return out;
}

void check_dimensions(int width, int height, const read_options& o, const std::string& name, const char* format) {
    if (width < 1 || height < 1)
        throw image_error(name, std::string(format) + ": invalid dimensions " + std::to_string(width) + " x " +
                                    std::to_string(height));
    if (width > o.max_dimension || height > o.max_dimension ||
        std::uint64_t(width) * std::uint64_t(height) > o.max_pixels)
        throw image_error(name, std::string(format) + ": dimensions " + std::to_string(width) + " x " +
                                    std::to_string(height) + " exceed the limit (" + std::to_string(o.max_dimension) +
                                    " per side, " + std::to_string(o.max_pixels) + " pixels)");
}

/// The texel policy of the header: clamp finite negatives to 0, reject or zero non-finite values.
void apply_texel_policy(image_rgb32f& img, const read_options& o, read_report& r, const std::string& name) {
    std::size_t first_bad = SIZE_MAX;
    for (std::size_t t = 0, n = img.rgb.size() / 3; t < n; ++t) {
        bool negative = false;
        for (std::size_t c = 0; c < 3; ++c) {
            float& x = img.rgb[3 * t + c];
            if (!std::isfinite(x)) {
                ++r.nonfinite_values;
                if (first_bad == SIZE_MAX) first_bad = t;
                x = 0.0f;
            } else if (x < 0.0f) {
                ++r.negative_values;
                negative = true;
                r.most_negative = std::min(r.most_negative, x);
                x = 0.0f;
            }
            r.max_value = std::max(r.max_value, x);
        }
        if (negative) ++r.negative_texels;
    }
    if (r.nonfinite_values > 0 && o.nonfinite == nonfinite_policy::reject) {
        const std::size_t w = std::size_t(img.width);
        throw image_error(name, std::to_string(r.nonfinite_values) + " NaN/infinite values (first at texel x = " +
                                    std::to_string(first_bad % w) + ", y = " + std::to_string(first_bad / w) +
                                    "); refusing to bake them (nonfinite_policy::replace_with_zero replaces them by 0)");
    }
}

void check_image(const image_rgb32f& img, const std::string& name) {
    if (img.width < 1 || img.height < 1 ||
        img.rgb.size() != std::size_t(img.width) * std::size_t(img.height) * 3)
        throw image_error(name, "cannot write an image of " + std::to_string(img.width) + " x " +
                                    std::to_string(img.height) + " with " + std::to_string(img.rgb.size()) + " values");
    if (img.width > INT_MAX / 4 / img.height) throw image_error(name, "image too large to encode");
}

// ---- Radiance HDR ------------------------------------------------------------------------------
//
// File: text header lines ending in '\n': "#?RADIANCE" (or "#?RGBE"), variables such as
// "FORMAT=32-bit_rle_rgbe" and comments, an empty line, the resolution line "-Y <h> +X <w>"
// (top row first, left to right; the only layout stb_image accepts), then h scanlines of w RGBE
// pixels, either flat (4 bytes a pixel) or, for 8 <= w < 32768, "new" run-length encoded:
// 2, 2, w >> 8, w & 255, then the four components one after the other, each as packets
// <count> <count bytes> (count <= 128) or <128 + run> <byte> (G. Ward, "Real Pixels", Graphics
// Gems II, 1991; Radiance's color.c). stb_image decodes a scanline that does not start with the
// 2, 2 marker as flat pixels from there on.
//
// The header parser below is stricter than stb's and accepts a subset of what stb accepts with
// the same data offset (no NUL bytes in the header, exact resolution syntax), so the structural
// walk of the data that follows describes exactly the bytes stb will read.

struct hdr_layout {
    int width = 0, height = 0;
    std::size_t data_offset = 0;
};

hdr_layout parse_hdr_header(std::span<const unsigned char> b, const std::string& name, const read_options& o) {
    std::size_t pos = 0;
    auto next_line = [&](const char* what) -> std::string_view {
        const auto* begin = b.data() + pos;
        const auto* end = b.data() + b.size();
        const auto* nl = std::find(begin, end, static_cast<unsigned char>('\n'));
        if (nl == end) throw image_error(name, std::string("truncated Radiance HDR header (") + what + ")");
        const std::string_view line(reinterpret_cast<const char*>(begin), std::size_t(nl - begin));
        if (line.find('\0') != std::string_view::npos)
            throw image_error(name, "corrupt Radiance HDR header (NUL byte in '" + printable(line) + "')");
        pos = std::size_t(nl - b.data()) + 1;
        return line;
    };
    const std::string_view magic = next_line("no signature line");
    if (magic != "#?RADIANCE" && magic != "#?RGBE")
        throw image_error(name, "not a Radiance HDR file (signature '" + printable(magic) + "')");
    bool rgbe = false;
    for (;;) {
        const std::string_view line = next_line("no empty line ending the header");
        if (line.empty()) break;
        if (line.starts_with("FORMAT=")) {
            if (line != "FORMAT=32-bit_rle_rgbe")
                throw image_error(name, "unsupported Radiance HDR pixel format '" + printable(line) +
                                            "' (only 32-bit_rle_rgbe)");
            rgbe = true;
        }
    }
    if (!rgbe) throw image_error(name, "Radiance HDR header has no FORMAT=32-bit_rle_rgbe line");

    // "-Y <h> +X <w>", decimal, no sign, no leading zeros beyond "0".
    const std::string_view res = next_line("no resolution line");
    const auto bad_layout = [&] {
        return image_error(name, "unsupported Radiance HDR resolution line '" + printable(res) +
                                     "' (only '-Y <height> +X <width>', top row first)");
    };
    if (res.size() > 40 || !res.starts_with("-Y ")) throw bad_layout();
    const char* p = res.data() + 3;
    const char* end = res.data() + res.size();
    long long h = 0, w = 0;
    auto r1 = std::from_chars(p, end, h);
    if (r1.ec != std::errc{} || r1.ptr == p || *p == '+' || *p == '-') throw bad_layout();
    std::string_view rest(r1.ptr, std::size_t(end - r1.ptr));
    if (!rest.starts_with(" +X ")) throw bad_layout();
    p = r1.ptr + 4;
    auto r2 = std::from_chars(p, end, w);
    if (r2.ec != std::errc{} || r2.ptr != end || r2.ptr == p || *p == '+' || *p == '-') throw bad_layout();
    check_dimensions(int(std::clamp<long long>(w, -1, INT_MAX)), int(std::clamp<long long>(h, -1, INT_MAX)), o, name,
                     "Radiance HDR");
    return {int(w), int(h), pos};
}

/// Walks the scanline data exactly as stb_image's decoder consumes it; throws if it is truncated
/// or corrupt (so that stb never reads past the end, where it would decode zeros or loop forever).
void check_hdr_data(std::span<const unsigned char> b, const hdr_layout& L, const std::string& name) {
    const std::size_t n = b.size();
    std::size_t pos = L.data_offset;
    const std::uint64_t flat_bytes = 4ull * std::uint64_t(L.width) * std::uint64_t(L.height);
    const auto truncated = [&] {
        return image_error(name, "truncated Radiance HDR data (" + std::to_string(n - L.data_offset) +
                                     " bytes of pixel data for " + std::to_string(L.width) + " x " +
                                     std::to_string(L.height) + " pixels)");
    };
    const auto flat_from_here = [&] {
        if (std::uint64_t(n - pos) < flat_bytes) throw truncated();
    };
    if (L.width < 8 || L.width >= 32768) return flat_from_here();
    const int w = L.width;
    for (int y = 0; y < L.height; ++y) {
        if (n - pos < 4) throw truncated();
        if (b[pos] != 2 || b[pos + 1] != 2 || (b[pos + 2] & 0x80)) return flat_from_here();
        const int len = (b[pos + 2] << 8) | b[pos + 3];
        if (len != w)
            throw image_error(name, "corrupt Radiance HDR data (scanline " + std::to_string(y) + " has length " +
                                        std::to_string(len) + ", expected " + std::to_string(w) + ")");
        pos += 4;
        for (int c = 0; c < 4; ++c) {
            for (int x = 0; x < w;) {
                if (pos >= n) throw truncated();
                int count = b[pos++];
                const bool run = count > 128;
                if (run) count -= 128;
                if (count > w - x)
                    throw image_error(name, "corrupt Radiance HDR data (run overflows scanline " + std::to_string(y) +
                                                ")");
                const std::size_t payload = run ? 1 : std::size_t(count);
                if (n - pos < payload) throw truncated();
                pos += payload;
                x += count;
            }
        }
    }
}

// ---- OpenEXR -----------------------------------------------------------------------------------

/// Copies tinyexr's error string into a std::string and frees it.
std::string take_exr_error(const char*& err, int code) {
    std::string s = err ? std::string(err) : std::string("tinyexr error code ") + std::to_string(code);
    if (err) FreeEXRErrorMessage(err);
    err = nullptr;
    while (!s.empty() && (s.back() == '\n' || s.back() == ' ')) s.pop_back();
    return printable(s, 200);
}

struct exr_header_owner {
    EXRHeader h;
    bool parsed = false;
    exr_header_owner() { InitEXRHeader(&h); }
    ~exr_header_owner() {
        if (parsed) FreeEXRHeader(&h);
    }
    exr_header_owner(const exr_header_owner&) = delete;
    exr_header_owner& operator=(const exr_header_owner&) = delete;
};

struct exr_image_owner {
    EXRImage img;
    bool loaded = false;
    exr_image_owner() { InitEXRImage(&img); }
    ~exr_image_owner() {
        if (loaded) FreeEXRImage(&img);
    }
    exr_image_owner(const exr_image_owner&) = delete;
    exr_image_owner& operator=(const exr_image_owner&) = delete;
};

/// The value of the single-part header's "compression" attribute, found by walking the attribute
/// list (name\0 type\0 int32 size, value) with bounds checks; -1 if absent or unreadable (tinyexr
/// then reports the problem). Used to name compressions tinyexr cannot decode before it says
/// "Unknown compression type".
int exr_compression_attribute(std::span<const unsigned char> b) {
    std::size_t p = 8; // magic + version
    const auto cstring = [&](std::string_view& out) {
        const auto* begin = b.data() + p;
        const auto* end = b.data() + b.size();
        const auto* nul = std::find(begin, std::min(end, begin + 256), static_cast<unsigned char>(0));
        if (nul == end || nul == begin + 256) return false;
        out = std::string_view(reinterpret_cast<const char*>(begin), std::size_t(nul - begin));
        p = std::size_t(nul - b.data()) + 1;
        return true;
    };
    while (p < b.size() && b[p] != 0) {
        std::string_view attr_name, attr_type;
        if (!cstring(attr_name) || !cstring(attr_type) || b.size() - p < 4) return -1;
        const std::uint32_t size = std::uint32_t(b[p]) | (std::uint32_t(b[p + 1]) << 8) | (std::uint32_t(b[p + 2]) << 16) |
                                   (std::uint32_t(b[p + 3]) << 24);
        p += 4;
        if (size > b.size() - p) return -1;
        if (attr_name == "compression" && attr_type == "compression" && size == 1) return b[p];
        p += size;
    }
    return -1;
}

const char* exr_compression_name(int c) {
    static constexpr const char* names[] = {"NONE", "RLE", "ZIPS", "ZIP", "PIZ", "PXR24", "B44", "B44A", "DWAA", "DWAB", "HTJ2K"};
    return c >= 0 && c < int(std::size(names)) ? names[c] : "unknown";
}

constexpr unsigned char exr_magic[4] = {0x76, 0x2f, 0x31, 0x01};
constexpr std::string_view hdr_magic1 = "#?RADIANCE\n";
constexpr std::string_view hdr_magic2 = "#?RGBE\n";

bool starts_with(std::span<const unsigned char> b, std::string_view s) {
    return b.size() >= s.size() && std::memcmp(b.data(), s.data(), s.size()) == 0;
}

} // namespace

// ---- files -------------------------------------------------------------------------------------

std::vector<unsigned char> read_file(const std::string& path) {
    std::error_code ec;
    const auto st = std::filesystem::status(path, ec);
    if (ec || !std::filesystem::exists(st))
        throw image_error(path, "no such file" + (ec && ec != std::errc::no_such_file_or_directory ? " (" + ec.message() + ")" : std::string()));
    if (std::filesystem::is_directory(st)) throw image_error(path, "is a directory, not an image file");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw image_error(path, std::string("cannot open for reading: ") + std::strerror(errno));
    std::vector<unsigned char> data;
    char buf[1 << 16];
    while (in.read(buf, sizeof buf) || in.gcount() > 0) data.insert(data.end(), buf, buf + in.gcount());
    if (in.bad()) throw image_error(path, "read error");
    return data;
}

void write_file_atomic(const std::string& path, std::span<const unsigned char> bytes) {
    namespace fs = std::filesystem;
    static std::atomic<unsigned> counter{0};
    const fs::path target(path);
    const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
    const std::string base = target.filename().string();
    if (base.empty() || base == "." || base == "..") throw image_error(path, "not a file name");
    std::string tmp;
    int fd = -1;
    for (int attempt = 0; attempt < 100 && fd < 0; ++attempt) {
        tmp = (dir / ("." + base + ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(counter++))).string();
        fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
        if (fd < 0 && errno != EEXIST)
            throw image_error(path, "cannot create a temporary file in '" + dir.string() + "': " + std::strerror(errno));
    }
    if (fd < 0) throw image_error(path, "cannot create a unique temporary file in '" + dir.string() + "'");
    const auto fail = [&](const char* what) {
        const int e = errno;
        ::close(fd);
        ::unlink(tmp.c_str());
        return image_error(path, std::string(what) + ": " + std::strerror(e));
    };
    std::size_t done = 0;
    while (done < bytes.size()) {
        const ssize_t k = ::write(fd, bytes.data() + done, bytes.size() - done);
        if (k < 0) {
            if (errno == EINTR) continue;
            throw fail("write failed");
        }
        done += std::size_t(k);
    }
    if (::fsync(fd) != 0) throw fail("fsync failed");
    if (::close(fd) != 0) {
        const int e = errno;
        ::unlink(tmp.c_str());
        throw image_error(path, std::string("close failed: ") + std::strerror(e));
    }
    if (::rename(tmp.c_str(), path.c_str()) != 0) {
        const int e = errno;
        ::unlink(tmp.c_str());
        throw image_error(path, std::string("cannot rename the temporary file into place: ") + std::strerror(e));
    }
}

// ---- reading -----------------------------------------------------------------------------------

image_rgb32f read_hdr_memory(std::span<const unsigned char> bytes, const std::string& name, const read_options& o,
                             read_report* report) {
    if (bytes.empty()) throw image_error(name, "empty file");
    const hdr_layout L = parse_hdr_header(bytes, name, o);
    check_hdr_data(bytes, L, name);
    if (bytes.size() > std::size_t(INT_MAX)) throw image_error(name, "file too large for stb_image (> 2 GiB)");
    const int len = int(bytes.size());
    if (!stbi_is_hdr_from_memory(bytes.data(), len)) throw image_error(name, "LDR input not supported");
    int w = 0, h = 0, comp = 0;
    std::unique_ptr<float, void (*)(void*)> data(stbi_loadf_from_memory(bytes.data(), len, &w, &h, &comp, 3),
                                                 stbi_image_free);
    if (!data) throw image_error(name, std::string("corrupt Radiance HDR file (stb_image: ") + stbi_failure_reason() + ")");
    if (w != L.width || h != L.height || comp != 3)
        throw image_error(name, "Radiance HDR decoder disagrees with the header (" + std::to_string(w) + " x " +
                                    std::to_string(h) + " x " + std::to_string(comp) + ")");
    image_rgb32f img(w, h);
    std::memcpy(img.rgb.data(), data.get(), img.rgb.size() * sizeof(float));
    read_report r;
    r.format = "Radiance HDR";
    apply_texel_policy(img, o, r, name);
    if (report) *report = r;
    return img;
}

image_rgb32f read_exr_memory(std::span<const unsigned char> bytes, const std::string& name, const read_options& o,
                             read_report* report) {
    if (bytes.empty()) throw image_error(name, "empty file");
    EXRVersion version;
    int rc = ParseEXRVersionFromMemory(&version, bytes.data(), bytes.size());
    if (rc != TINYEXR_SUCCESS)
        throw image_error(name, bytes.size() < 8 ? "truncated OpenEXR file (no version header)"
                                                 : "not a valid OpenEXR file (bad version header)");
    if (version.multipart) throw image_error(name, "multi-part OpenEXR not supported");
    if (version.non_image) throw image_error(name, "deep OpenEXR not supported");
    if (version.tiled) throw image_error(name, "tiled OpenEXR not supported (scanline images only)");

    const int compression = exr_compression_attribute(bytes);
    if (compression > TINYEXR_COMPRESSIONTYPE_PIZ)
        throw image_error(name, std::string("OpenEXR compression ") + exr_compression_name(compression) + " (" +
                                    std::to_string(compression) +
                                    ") is not supported by tinyexr 1.0.1, which decodes NONE, RLE, ZIPS, ZIP and PIZ; "
                                    "re-save the file with one of those (e.g. ZIP)");

    exr_header_owner header;
    const char* err = nullptr;
    rc = ParseEXRHeaderFromMemory(&header.h, &version, bytes.data(), bytes.size(), &err);
    header.parsed = true;
    if (rc != TINYEXR_SUCCESS) throw image_error(name, "corrupt OpenEXR header (" + take_exr_error(err, rc) + ")");
    EXRHeader& H = header.h;
    if (H.tiled) throw image_error(name, "tiled OpenEXR not supported (scanline images only)");
    const long long dw = static_cast<long long>(H.data_window.max_x) - H.data_window.min_x + 1;
    const long long dh = static_cast<long long>(H.data_window.max_y) - H.data_window.min_y + 1;
    check_dimensions(int(std::clamp<long long>(dw, -1, INT_MAX)), int(std::clamp<long long>(dh, -1, INT_MAX)), o, name,
                     "OpenEXR");
    // tinyexr sizes its offset table from the optional chunkCount attribute before checking it
    // (a 3 KB file asked for 6.6 GB; found by scripts/fuzz.sh, regression input
    // tools/ibl-bake/tests/data/fuzz-oom-exr-chunkcount). A scanline image has at most one
    // chunk per row.
    if (H.chunk_count < 0 || H.chunk_count > dh)
        throw image_error(name, "corrupt OpenEXR header (chunkCount " + std::to_string(H.chunk_count) + " for " +
                                    std::to_string(dh) + " scanlines)");

    int idx[3] = {-1, -1, -1};
    const char* wanted[3] = {"R", "G", "B"};
    std::string found;
    for (int c = 0; c < H.num_channels; ++c) {
        const EXRChannelInfo& ch = H.channels[c];
        const std::string_view ch_name(ch.name, strnlen(ch.name, sizeof ch.name));
        found += (found.empty() ? "" : ", ") + printable(ch_name, 32);
        for (int k = 0; k < 3; ++k)
            if (ch_name == wanted[k]) idx[k] = c;
    }
    for (int k = 0; k < 3; ++k) {
        if (idx[k] < 0)
            throw image_error(name, std::string("OpenEXR has no '") + wanted[k] + "' channel (channels: " + found + ")");
        const EXRChannelInfo& ch = H.channels[idx[k]];
        if (ch.x_sampling != 1 || ch.y_sampling != 1)
            throw image_error(name, std::string("subsampled OpenEXR channel '") + wanted[k] + "' not supported");
        if (H.pixel_types[idx[k]] == TINYEXR_PIXELTYPE_UINT)
            throw image_error(name, std::string("OpenEXR channel '") + wanted[k] + "' is UINT, not HALF or FLOAT");
    }
    for (int c = 0; c < H.num_channels; ++c)
        if (H.pixel_types[c] == TINYEXR_PIXELTYPE_HALF) H.requested_pixel_types[c] = TINYEXR_PIXELTYPE_FLOAT;

    exr_image_owner image;
    // tinyexr 1.0.1 frees a failed image itself with FreeEXRImage, which frees the channel buffers
    // only for i < image.num_channels, and sets num_channels only after a successful decode: the
    // buffers of a chunk that fails to decode leaked (found by fuzzing, regression input
    // tests/data/fuzz-leak-tinyexr-decodechunk). Setting num_channels first lets that cleanup free
    // them; on failure the image must not be freed again (tinyexr leaves `images` dangling).
    image.img.num_channels = H.num_channels;
    rc = LoadEXRImageFromMemory(&image.img, &H, bytes.data(), bytes.size(), &err);
    image.loaded = rc == TINYEXR_SUCCESS;
    if (rc != TINYEXR_SUCCESS) {
        std::string msg = take_exr_error(err, rc);
        throw image_error(name, "corrupt or truncated OpenEXR data (" + msg + ")");
    }
    const EXRImage& I = image.img;
    if (!I.images || I.width != dw || I.height != dh || I.num_channels != H.num_channels)
        throw image_error(name, "OpenEXR decoder returned an unexpected image (" + std::to_string(I.width) + " x " +
                                    std::to_string(I.height) + ")");
    image_rgb32f img(I.width, I.height);
    const std::size_t n = std::size_t(I.width) * std::size_t(I.height);
    for (int k = 0; k < 3; ++k) {
        const auto* src = reinterpret_cast<const float*>(I.images[idx[k]]);
        if (!src) throw image_error(name, "OpenEXR decoder returned no data for a channel");
        for (std::size_t t = 0; t < n; ++t) img.rgb[3 * t + std::size_t(k)] = src[t];
    }
    read_report r;
    r.format = "OpenEXR";
    apply_texel_policy(img, o, r, name);
    if (report) *report = r;
    return img;
}

namespace {
/// The name of a common 8-bit image format recognised by its signature, or nullptr.
const char* ldr_format_name(std::span<const unsigned char> b) {
    auto sig = [&](std::initializer_list<unsigned char> m) {
        return b.size() >= m.size() && std::equal(m.begin(), m.end(), b.begin());
    };
    if (sig({0x89, 'P', 'N', 'G', 0x0D, 0x0A, 0x1A, 0x0A})) return "PNG";
    if (sig({0xFF, 0xD8, 0xFF})) return "JPEG";
    if (sig({'G', 'I', 'F', '8'})) return "GIF";
    if (sig({'B', 'M'})) return "BMP";
    if (sig({'8', 'B', 'P', 'S'})) return "PSD";
    if (sig({'I', 'I', 0x2A, 0x00}) || sig({'M', 'M', 0x00, 0x2A})) return "TIFF";
    if (sig({'R', 'I', 'F', 'F'}) && b.size() >= 12 && std::equal(b.begin() + 8, b.begin() + 12, "WEBP")) return "WebP";
    if (b.size() >= 2 && b[0] == 'P' && b[1] >= '1' && b[1] <= '6') return "PNM";
    return nullptr;
}
} // namespace

image_rgb32f read_image_memory(std::span<const unsigned char> bytes, const std::string& name, const read_options& o,
                               read_report* report) {
    if (bytes.empty()) throw image_error(name, "empty file");
    if (bytes.size() >= 4 && std::memcmp(bytes.data(), exr_magic, 4) == 0) return read_exr_memory(bytes, name, o, report);
    if (starts_with(bytes, hdr_magic1) || starts_with(bytes, hdr_magic2)) return read_hdr_memory(bytes, name, o, report);
    if (const char* ldr = ldr_format_name(bytes))
        throw image_error(name, std::string("LDR input not supported (a ") + ldr +
                                    " file; give a Radiance .hdr or an OpenEXR file)");
    if (bytes.size() < 4) throw image_error(name, "truncated or unrecognised image (" + std::to_string(bytes.size()) + " bytes)");
    throw image_error(name, "unrecognised image format (neither Radiance HDR nor OpenEXR)");
}

image_rgb32f read_image(const std::string& path, const read_options& o, read_report* report) {
    const std::vector<unsigned char> bytes = read_file(path);
    return read_image_memory(bytes, path, o, report);
}

void check_latlong(const image_rgb32f& image, const std::string& name) {
    if (image.width != 2 * image.height)
        throw image_error(name, "not a lat-long (equirectangular) map: " + std::to_string(image.width) + " x " +
                                    std::to_string(image.height) + " is not 2:1");
}

image_rgb32f read_latlong(const std::string& path, const read_options& o, read_report* report) {
    image_rgb32f img = read_image(path, o, report);
    check_latlong(img, path);
    return img;
}

// ---- writing -----------------------------------------------------------------------------------

namespace {
void append_bytes(void* context, void* data, int size) {
    auto* out = static_cast<std::vector<unsigned char>*>(context);
    const auto* p = static_cast<const unsigned char*>(data);
    out->insert(out->end(), p, p + size);
}

float srgb_oetf(float x) noexcept {
    return x <= 0.0031308f ? 12.92f * x : 1.055f * std::pow(x, 1.0f / 2.4f) - 0.055f;
}
} // namespace

std::vector<unsigned char> encode_exr(const image_rgb32f& image, const std::string& name) {
    check_image(image, name);
    const std::size_t n = std::size_t(image.width) * std::size_t(image.height);
    std::vector<float> planes[3]; // B, G, R
    for (int k = 0; k < 3; ++k) {
        planes[k].resize(n);
        for (std::size_t t = 0; t < n; ++t) planes[k][t] = image.rgb[3 * t + std::size_t(2 - k)];
    }
    unsigned char* ptrs[3] = {reinterpret_cast<unsigned char*>(planes[0].data()),
                              reinterpret_cast<unsigned char*>(planes[1].data()),
                              reinterpret_cast<unsigned char*>(planes[2].data())};
    EXRChannelInfo channels[3];
    std::memset(channels, 0, sizeof channels);
    const char* names[3] = {"B", "G", "R"};
    int pixel_types[3], requested[3];
    for (int k = 0; k < 3; ++k) {
        std::strcpy(channels[k].name, names[k]);
        channels[k].pixel_type = TINYEXR_PIXELTYPE_FLOAT;
        channels[k].x_sampling = channels[k].y_sampling = 1;
        pixel_types[k] = requested[k] = TINYEXR_PIXELTYPE_FLOAT;
    }
    EXRHeader header;
    InitEXRHeader(&header);
    header.num_channels = 3;
    header.channels = channels;
    header.pixel_types = pixel_types;
    header.requested_pixel_types = requested;
    header.compression_type = TINYEXR_COMPRESSIONTYPE_ZIP;
    EXRImage img;
    InitEXRImage(&img);
    img.images = ptrs;
    img.width = image.width;
    img.height = image.height;
    img.num_channels = 3;
    unsigned char* mem = nullptr;
    const char* err = nullptr;
    const std::size_t size = SaveEXRImageToMemory(&img, &header, &mem, &err);
    if (size == 0 || !mem) {
        std::free(mem);
        throw image_error(name, "OpenEXR encoding failed (" + take_exr_error(err, 0) + ")");
    }
    std::vector<unsigned char> out(mem, mem + size);
    std::free(mem);
    return out;
}

void write_exr(const std::string& path, const image_rgb32f& image) { write_file_atomic(path, encode_exr(image, path)); }

std::vector<unsigned char> encode_hdr(const image_rgb32f& image, const std::string& name) {
    check_image(image, name);
    // stb converts x * 2^(8 - e) to unsigned char: UB for negative x, and the exponent byte wraps
    // for x >= 2^127. Clamp to [0, rgbe_max] (NaN -> 0) first.
    constexpr float rgbe_max = 0x1p126f;
    std::vector<float> safe(image.rgb.size());
    for (std::size_t i = 0; i < safe.size(); ++i) {
        const float x = image.rgb[i];
        safe[i] = x > 0.0f ? std::min(x, rgbe_max) : 0.0f;
    }
    std::vector<unsigned char> out;
    if (!stbi_write_hdr_to_func(append_bytes, &out, image.width, image.height, 3, safe.data()))
        throw image_error(name, "Radiance HDR encoding failed");
    return out;
}

void write_hdr(const std::string& path, const image_rgb32f& image) { write_file_atomic(path, encode_hdr(image, path)); }

std::uint8_t tonemap_png(float linear, const png_options& o) noexcept {
    float x = linear * o.exposure;
    if (!(x > 0.0f)) return 0; // NaN and negatives
    if (o.op == tonemap::reinhard)
        x = std::isinf(x) ? 1.0f : x / (1.0f + x);
    else
        x = std::min(x, 1.0f);
    const float y = srgb_oetf(x) * 255.0f + 0.5f;
    return static_cast<std::uint8_t>(std::clamp(y, 0.0f, 255.0f));
}

std::vector<unsigned char> encode_png(const image_rgb32f& image, const png_options& options, const std::string& name) {
    check_image(image, name);
    std::vector<unsigned char> ldr(image.rgb.size());
    for (std::size_t i = 0; i < ldr.size(); ++i) ldr[i] = tonemap_png(image.rgb[i], options);
    std::vector<unsigned char> out;
    if (!stbi_write_png_to_func(append_bytes, &out, image.width, image.height, 3, ldr.data(), image.width * 3))
        throw image_error(name, "PNG encoding failed");
    return out;
}

void write_png(const std::string& path, const image_rgb32f& image, const png_options& options) {
    write_file_atomic(path, encode_png(image, options, path));
}

} // namespace ibl_bake
