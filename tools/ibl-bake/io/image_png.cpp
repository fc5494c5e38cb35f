// tools/ibl-bake/io/image_png.cpp — the tone-mapped 8-bit PNG previews of image_io.hpp, encoded by
// stb_image_write (Debian's libstb-dev; compiled here as static functions, as in image_hdr.cpp).

#include "io/image_common.hpp"

#include <algorithm>
#include <cmath>

#define STB_IMAGE_WRITE_STATIC
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb_image_write.h>

namespace ibl_bake {
namespace {

float srgb_oetf(float x) noexcept {
    return x <= 0.0031308f ? 12.92f * x : 1.055f * std::pow(x, 1.0f / 2.4f) - 0.055f;
}

} // namespace

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
