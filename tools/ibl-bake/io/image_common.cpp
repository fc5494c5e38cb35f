// tools/ibl-bake/io/image_common.cpp — image_io.hpp's files (read_file, write_file_atomic), the
// format dispatch of read_image, the lat-long check and what the format units share
// (image_common.hpp). The formats: image_hdr.cpp, image_exr.cpp, image_png.cpp.

#include "io/image_common.hpp"

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <system_error>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace ibl_bake {

// ---- helpers -----------------------------------------------------------------------------------

std::string printable(std::string_view s, std::size_t max_len) {
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

bool starts_with(std::span<const unsigned char> b, std::string_view s) {
    return b.size() >= s.size() && std::memcmp(b.data(), s.data(), s.size()) == 0;
}

void append_bytes(void* context, void* data, int size) {
    auto* out = static_cast<std::vector<unsigned char>*>(context);
    const auto* p = static_cast<const unsigned char*>(data);
    out->insert(out->end(), p, p + size);
}

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

} // namespace ibl_bake
