#pragma once
// tools/ibl-bake/ktx2.hpp — KTX 2.0 cubemap writer (and a validating reader for tests and
// verification) for a mip chain of 6 faces of linear RGB float data.
//
// Why KTX2: a published, complete specification (Khronos KTX File Format 2.0), cubemap face order
// and orientation equal to the library's convention (DESIGN.md: +X, -X, +Y, -Y, +Z, -Z, GL table,
// row 0 of a face = t = 0), loaded directly by Vulkan/GL/WebGPU engines and libktx.
//
// What is written (all integers little-endian; offsets from the start of the file):
//   offset 0    identifier  AB 4B 54 58 20 32 30 BB 0D 0A 1A 0A  ("«KTX 20»\r\n\x1A\n")
//          12   vkFormat    109 VK_FORMAT_R32G32B32A32_SFLOAT or 97 VK_FORMAT_R16G16B16A16_SFLOAT
//          16   typeSize    4 or 2 (bytes of one component)
//          20   pixelWidth  n (face size of level 0), 24 pixelHeight n, 28 pixelDepth 0
//          32   layerCount  0 (not an array), 36 faceCount 6, 40 levelCount L (>= 1),
//          44   supercompressionScheme 0 (none)
//          48   index: dfdByteOffset, dfdByteLength, kvdByteOffset, kvdByteLength (u32),
//               sgdByteOffset = 0, sgdByteLength = 0 (u64)
//          80   level index, L entries of {byteOffset, byteLength, uncompressedByteLength} (u64),
//               level 0 (finest) first
//   80+24L      data format descriptor: dfdTotalSize = 92, then one basic descriptor block:
//               vendorId 0 / descriptorType 0, versionNumber 2 (1.3), descriptorBlockSize 88,
//               colorModel RGBSDA (1), colorPrimaries BT709 (1), transferFunction LINEAR (1),
//               flags ALPHA_STRAIGHT (0), texelBlockDimension 0 0 0 0 (1x1x1x1),
//               bytesPlane0 16 (or 8), and four samples R, G, B, A (channel ids 0, 1, 2, 15):
//               bitOffset 32c (16c), bitLength 31 (15), qualifiers FLOAT | SIGNED (0xC0),
//               samplePosition 0, sampleLower 0xBF800000 (-1.0f), sampleUpper 0x3F800000
//               (1.0f) — the float range is given as float32 bit patterns for both widths,
//               as libktx's createDFDUnpacked writes it.
//   then        key/value data: one entry "KTXwriter" = "<writer>\0" (the spec's recommended
//               key), {u32 keyAndValueByteLength, key\0value\0, padding to 4}
//   then        the mip levels, SMALLEST FIRST (level L-1 ... level 0), each starting at a
//               multiple of lcm(texel size, 4) = 16 (RGBA32F) or 8 (RGBA16F), zero padding between.
//               A level holds the 6 faces in order +X, -X, +Y, -Y, +Z, -Z, each s x s texels
//               (s = max(1, n >> level)), rows from t = 0, texels RGBA with A = 1.
// Half floats: round to nearest even; finite values above 65504 (the largest half) are clamped
// to 65504 instead of becoming infinity (a very bright sun saturates); NaN stays NaN.

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace ibl_bake {

/// Six faces per level of linear RGB float: levels[l][face][3 (y s + x) + c], s = face_size(l).
struct cubemap_rgb32f {
    int size = 0; ///< level-0 face size n
    std::vector<std::array<std::vector<float>, 6>> levels;

    int face_size(int level) const noexcept {
        const int s = size >> level;
        return s > 0 ? s : 1;
    }
    /// A cubemap of L levels (sizes n, n/2, ..., at least 1) filled with 0.
    static cubemap_rgb32f zeros(int size, int level_count);
};

enum class ktx2_format : std::uint32_t {
    rgba32f = 109, ///< VK_FORMAT_R32G32B32A32_SFLOAT
    rgba16f = 97,  ///< VK_FORMAT_R16G16B16A16_SFLOAT
};

/// The file layout described in the header comment. Throws image_error (named `name`) for an
/// inconsistent cubemap (size < 1, level count not in [1, floor(log2 n) + 1], face sizes).
std::vector<unsigned char> encode_ktx2_cubemap(const cubemap_rgb32f& cube, ktx2_format format,
                                               const std::string& writer = "ibl-bake",
                                               const std::string& name = "<ktx2>");
/// encode_ktx2_cubemap + write_file_atomic.
void write_ktx2_cubemap(const std::string& path, const cubemap_rgb32f& cube, ktx2_format format,
                        const std::string& writer = "ibl-bake");

/// Parsed header and indices of a KTX2 file (for tests and verification).
struct ktx2_level {
    std::uint64_t byte_offset, byte_length, uncompressed_byte_length;
};
struct ktx2_info {
    std::uint32_t vk_format, type_size, pixel_width, pixel_height, pixel_depth, layer_count, face_count,
        level_count, supercompression;
    std::uint32_t dfd_offset, dfd_length, kvd_offset, kvd_length;
    std::uint64_t sgd_offset, sgd_length;
    std::vector<ktx2_level> levels;
    std::vector<std::uint32_t> dfd; ///< the DFD as u32 words, starting with dfdTotalSize
    std::vector<std::pair<std::string, std::string>> key_values; ///< value without its final NUL
};

/// Parses and validates a KTX2 file of the kind written here (uncompressed, bounds and
/// alignment of every index checked). Throws image_error naming `name`.
ktx2_info parse_ktx2(std::span<const unsigned char> bytes, const std::string& name = "<ktx2>");

/// Reads back a cubemap written by encode_ktx2_cubemap (RGBA32F or RGBA16F, alpha dropped).
cubemap_rgb32f decode_ktx2_cubemap(std::span<const unsigned char> bytes, const std::string& name = "<ktx2>");

/// IEEE binary16 conversions used by the RGBA16F path (see the header comment for the policy).
std::uint16_t float_to_half(float f) noexcept;
float half_to_float(std::uint16_t h) noexcept;

} // namespace ibl_bake
