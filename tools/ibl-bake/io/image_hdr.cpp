// tools/ibl-bake/io/image_hdr.cpp — Radiance HDR (RGBE) of image_io.hpp: the structural walk of the
// header and scanlines, decoding by stb_image and encoding by stb_image_write.
//
// Third-party code from Debian's libstb-dev, compiled here from the headers as static functions
// (STB_*_STATIC) so that they cannot clash with another copy (libstb.so) in the same program; no
// stdio entry points (the tool reads whole files itself and decodes from memory).

#include "io/image_common.hpp"

#include <algorithm>
#include <charconv>
#include <climits>
#include <cstring>
#include <memory>
#include <string_view>

#define STB_IMAGE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#define STBI_NO_STDIO
// Only stb's Radiance HDR decoder is compiled in. LDR inputs are recognised by their signature
// (ldr_format_name, image_common.cpp), never parsed: fuzzing (scripts/fuzz.sh) found undefined behaviour in
// stb's PNM header parser (signed overflow) and JPEG Huffman-table builder (out-of-bounds write)
// when they only probed arbitrary bytes; regression inputs in tools/ibl-bake/tests/data/fuzz-*.
#define STBI_ONLY_HDR
#include <stb_image.h>

#define STB_IMAGE_WRITE_STATIC
#define STB_IMAGE_WRITE_IMPLEMENTATION
// (not STBI_WRITE_NO_STDIO: Debian's stb_image_write.h of 2022-09 then omits the HDR writer)
#include <stb_image_write.h>

namespace ibl_bake {
namespace {

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

} // namespace

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

} // namespace ibl_bake
