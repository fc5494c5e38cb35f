#pragma once
// tools/ibl-bake/io/image_common.hpp — what the format units of image_io.hpp share (not part of the
// tool's interface): the checks every reader and writer applies, the texel policy, the format
// signatures and the byte sink of stb_image_write.

#include <cstddef>
#include <span>
#include <string>
#include <string_view>

#include "io/image_io.hpp"

namespace ibl_bake {

constexpr unsigned char exr_magic[4] = {0x76, 0x2f, 0x31, 0x01};
constexpr std::string_view hdr_magic1 = "#?RADIANCE\n";
constexpr std::string_view hdr_magic2 = "#?RGBE\n";

/// A short printable excerpt of untrusted text for error messages.
std::string printable(std::string_view s, std::size_t max_len = 48);

/// Width and height in [1, o.max_dimension], their product at most o.max_pixels (image_error otherwise).
void check_dimensions(int width, int height, const read_options& o, const std::string& name, const char* format);

/// The texel policy of image_io.hpp: clamp finite negatives to 0, reject or zero non-finite values.
void apply_texel_policy(image_rgb32f& img, const read_options& o, read_report& r, const std::string& name);

/// An image the writers can encode (consistent sizes, small enough for stb_image_write).
void check_image(const image_rgb32f& img, const std::string& name);

bool starts_with(std::span<const unsigned char> b, std::string_view s);

/// The write callback of stb_image_write: appends to the std::vector<unsigned char> `context`.
void append_bytes(void* context, void* data, int size);

} // namespace ibl_bake
