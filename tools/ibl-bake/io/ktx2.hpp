#pragma once
// tools/ibl-bake/io/ktx2.hpp — KTX 2.0 cubemap (and cubemap-array) writer (and a validating reader for tests and
// verification) for a mip chain of 6 faces of linear RGB float data.
//
// Why KTX2: a published, complete specification (Khronos KTX File Format 2.0), cubemap face order
// and orientation equal to the library's convention (DESIGN.md: +X, -X, +Y, -Y, +Z, -Z, GL table,
// row 0 of a face = t = 0), loaded directly by Vulkan/GL/WebGPU engines and libktx.
//
// What is written (all integers little-endian; offsets from the start of the file):
//   offset 0    identifier  AB 4B 54 58 20 32 30 BB 0D 0A 1A 0A  ("«KTX 20»\r\n\x1A\n")
//          12   vkFormat    one of the seven formats below
//          16   typeSize    4 (RGBA32F), 2 (RGBA16F), 4 (the two PACK32 formats: the size of the packed word),
//                           1 (the block formats)
//          20   pixelWidth  n (face size of level 0), 24 pixelHeight n, 28 pixelDepth 0
//          32   layerCount  0 (not an array; N for encode_ktx2_cubemap_array's N layers),
//               36 faceCount 6, 40 levelCount L (>= 1),
//          44   supercompressionScheme 0 (none) or 2 (Zstandard, ktx2_encoding::zstd_level > 0)
//          48   index: dfdByteOffset, dfdByteLength, kvdByteOffset, kvdByteLength (u32),
//               sgdByteOffset = 0, sgdByteLength = 0 (u64)
//          80   level index, L entries of {byteOffset, byteLength, uncompressedByteLength} (u64),
//               level 0 (finest) first
//               (with Zstandard: byteLength the deflated size, uncompressedByteLength the raw size)
//   80+24L      data format descriptor (Khronos Data Format Specification 1.3), dfdTotalSize then
//               one basic descriptor block: vendorId 0 / descriptorType 0, versionNumber 2 (1.3),
//               descriptorBlockSize 24 + 16 x samples, colorModel RGBSDA (1), colorPrimaries BT709
//               (1), transferFunction LINEAR (1), flags ALPHA_STRAIGHT (0), texelBlockDimension
//               0 0 0 0 (1x1x1x1), bytesPlane0 = texel bytes, then the samples (as KTX-Software's
//               createDFDUnpacked / createDFDPacked write them for these formats):
//     format                 bytes  samples (channel id | qualifiers, bitOffset, bitLength field = bits - 1,
//                                    sampleLower, sampleUpper)
//     109 R32G32B32A32_SFLOAT  16   R, G, B, A (0, 1, 2, 15) | FLOAT|SIGNED (0xC0), offset 32c, 31,
//                                    0xBF800000 (-1.0f), 0x3F800000 (1.0f)
//      97 R16G16B16A16_SFLOAT   8   the same with offset 16c, 15 (the float range is still given as
//                                    float32 bit patterns, as libktx writes it)
//     122 B10G11R11_UFLOAT      4   R (0) | FLOAT (0x80) offset 0 length 11; G (1) | FLOAT offset 11
//                                    length 11; B (2) | FLOAT offset 22 length 10; lower 0 (0.0f),
//                                    upper 0x3F800000 (1.0f)                       (dfdTotalSize 76)
//     123 E5B9G9R9_UFLOAT       4   six samples, a mantissa and the shared exponent per channel:
//                                    R mantissa (0) offset 0 length 9, lower 0, upper 8448;
//                                    R exponent (0 | EXPONENT 0x20) offset 27 length 5, lower 15
//                                    (the bias), upper 31; then G (1) with mantissa offset 9 and
//                                    B (2) with mantissa offset 18, each with the same exponent
//                                    sample at offset 27. Mantissas carry no FLOAT qualifier (they
//                                    are unsigned integers scaled by the exponent).   (dfdTotalSize 124)
//     block formats (as KTX-Software's createDFDCompressed writes them): colorModel BC6H (131) or
//                 ASTC (162), texelBlockDimension 3 3 0 0 (4x4) or 5 5 0 0 (6x6), bytesPlane0 16
//                 (kept with Zstandard: the DFD describes the inflated data), one sample: channel 0
//                 (BC6H_COLOR / ASTC_DATA), offset 0, length field 127; BC6H_UFLOAT: FLOAT (0x80),
//                 lower 0 (0.0f), upper 0x3F800000; ASTC SFLOAT: FLOAT|SIGNED (0xC0), lower
//                 0xBF800000, upper 0x3F800000                               (dfdTotalSize 44)
//   then        key/value data: one entry "KTXwriter" = "<writer>\0" (the spec's recommended
//               key), {u32 keyAndValueByteLength, key\0value\0, padding to 4}
//   then        the mip levels, SMALLEST FIRST (level L-1 ... level 0), each starting at a
//               multiple of lcm(texel or block size, 4) (16, 8, 4, 4; 16 for blocks; 1 when
//               supercompressed), zero padding between. Block formats store every level down to
//               1x1 (a level smaller than a block is one block: its texels outside the level are
//               padding the encoder ignores), faces in order, blocks row-major from t = 0.
//               A level holds the 6 faces in order +X, -X, +Y, -Y, +Z, -Z, each s x s texels
//               (s = max(1, n >> level)), rows from t = 0; RGBA texels with A = 1, packed texels
//               as one little-endian u32.
//
// Encoding of the formats (all round to nearest, ties to even where a tie can occur):
//   RGBA16F     IEEE binary16. Finite values above 65504 (the largest half) clamp to 65504 instead
//               of becoming infinity (a very bright sun saturates); NaN stays NaN; negatives kept.
//   B10G11R11   unsigned floats without sign bit, 5-bit exponent (bias 15, denormals at exponent
//               0, exponent 31 = inf/NaN), 6-bit mantissa for R and G (11 bits, max finite
//               2^15 (1 + 63/64) = 65024), 5-bit mantissa for B (10 bits, max 2^15 (1 + 31/32) =
//               64512). Vulkan "Unsigned 11-Bit / 10-Bit Floating-Point Numbers". Policy: negative
//               values (and -0, -inf) -> 0, NaN -> 0, values above the channel's max finite (and
//               +inf) -> max finite; never writes inf or NaN. For normal values the relative error is
//               at most 2^-(m+1) (2^-7 for R, G; 2^-6 for B).
//   E5B9G9R9    the shared-exponent algorithm of GL_EXT_texture_shared_exponent (also in the Vulkan
//               spec), N = 9 mantissa bits, bias B = 15, Emax = 31, sharedexp_max = 511/512 x 2^16 =
//               65408: each channel clamped to [0, 65408] (NaN -> 0), exp' = max(-B-1,
//               floor(log2(max channel))) + 1 + B, max_s = floor(max / 2^(exp'-B-N) + 1/2), exp = exp'
//               + 1 if max_s = 2^N, channel_s = floor(channel / 2^(exp-B-N) + 1/2); bits 0-8 R, 9-17 G,
//               18-26 B, 27-31 exp. Decoded value channel_s x 2^(exp - 24). Every channel's error is
//               at most half a unit 2^(exp-25) <= max channel / 511.5 (a dim channel next to a bright
//               one loses relative precision: that is the format).
// Out-of-range values are counted (ktx2_clamp_counts, ktx2_quantisation_report), never silent.

#include <array>
#include <cstddef>
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
    rgba32f = 109,   ///< VK_FORMAT_R32G32B32A32_SFLOAT
    rgba16f = 97,    ///< VK_FORMAT_R16G16B16A16_SFLOAT
    b10g11r11 = 122, ///< VK_FORMAT_B10G11R11_UFLOAT_PACK32
    e5b9g9r9 = 123,  ///< VK_FORMAT_E5B9G9R9_UFLOAT_PACK32
    bc6h = 143,                    ///< VK_FORMAT_BC6H_UFLOAT_BLOCK (4x4 blocks of 16 bytes)
    astc4x4 = 1000066000,          ///< VK_FORMAT_ASTC_4x4_SFLOAT_BLOCK (VK_EXT_texture_compression_astc_hdr)
    astc6x6 = 1000066004,          ///< VK_FORMAT_ASTC_6x6_SFLOAT_BLOCK
};

/// Encoder effort of the block-compressed formats (io/block_codec.hpp says what each does).
enum class block_quality { fast, normal, exhaustive };

/// How encode_ktx2_cubemap encodes: the block formats' effort and threads, and the optional
/// Zstandard supercompression of every level (KTX2 supercompressionScheme 2).
struct ktx2_encoding {
    block_quality quality = block_quality::normal;
    int zstd_level = 0;   ///< 0: none; 1..22: each level deflated with this Zstandard level
    unsigned threads = 1; ///< encoder threads (0 = all cores); the bytes do not depend on it
};

/// Bytes of one texel (16, 8, 4, 4) or, for the block formats, of one block (16).
std::size_t ktx2_texel_bytes(ktx2_format format) noexcept;
/// Largest finite value channel c (0 R, 1 G, 2 B) can hold: FLT_MAX, 65504, 65024/65024/64512, 65408.
float ktx2_channel_max(ktx2_format format, int channel) noexcept;
/// True for the formats without sign (negatives are written as 0).
bool ktx2_unsigned(ktx2_format format) noexcept;

/// What the encoder changed (RGB values only; alpha is the constant 1).
struct ktx2_clamp_counts {
    std::size_t above_range = 0; ///< values > the channel's max finite (+inf included), written as the max
                                 ///< (in RGBA16F +inf stays inf, finite values clamp to 65504)
    std::size_t negative = 0;    ///< values < 0 written as 0 (unsigned formats only; -inf included)
    std::size_t nan = 0;         ///< NaN values: 0 in the unsigned formats, NaN in the float formats
};

/// The file layout described in the header comment. Throws image_error (named `name`) for an
/// inconsistent cubemap (size < 1, level count not in [1, floor(log2 n) + 1], face sizes).
/// `counts` (optional) receives what the format's range forced (summed over all levels).
std::vector<unsigned char> encode_ktx2_cubemap(const cubemap_rgb32f& cube, ktx2_format format,
                                               const std::string& writer = "ibl-bake",
                                               const std::string& name = "<ktx2>",
                                               ktx2_clamp_counts* counts = nullptr,
                                               const std::vector<std::pair<std::string, std::string>>& metadata = {},
                                               const ktx2_encoding& encoding = {});
/// Most layers of a cubemap array (encode_ktx2_cubemap_array, decode_ktx2_cubemap_array).
inline constexpr std::uint32_t ktx2_max_array_layers = 2048;

/// A cubemap ARRAY of layers.size() cubemaps (1..ktx2_max_array_layers, equal face sizes and level
/// counts): the layout of the header comment with layerCount = the number of layers and each
/// level holding, as the KTX2 specification orders it, for each layer its 6 faces (layer-major,
/// then face). Everything else (formats, DFD, key/values, alignment, Zstandard per level) as
/// encode_ktx2_cubemap. Throws image_error named `name`.
std::vector<unsigned char> encode_ktx2_cubemap_array(const std::vector<cubemap_rgb32f>& layers, ktx2_format format,
                                                     const std::string& writer = "ibl-bake",
                                                     const std::string& name = "<ktx2>",
                                                     ktx2_clamp_counts* counts = nullptr,
                                                     const std::vector<std::pair<std::string, std::string>>& metadata = {},
                                                     const ktx2_encoding& encoding = {});
/// encode_ktx2_cubemap + write_file_atomic.
/// metadata: extra key/value pairs (UTF-8 keys without NUL, not starting with "KTX"; written sorted
/// by key after KTXwriter's place in that order).
void write_ktx2_cubemap(const std::string& path, const cubemap_rgb32f& cube, ktx2_format format,
                        const std::string& writer = "ibl-bake",
                        const std::vector<std::pair<std::string, std::string>>& metadata = {},
                        const ktx2_encoding& encoding = {});

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

/// Parses and validates a KTX2 file of the kind written here (bounds and alignment of every
/// index checked). Throws image_error naming `name`.
ktx2_info parse_ktx2(std::span<const unsigned char> bytes, const std::string& name = "<ktx2>");

/// Reads back a cubemap written by encode_ktx2_cubemap (any of its formats, alpha dropped; the
/// block formats decoded as a GPU decodes them; Zstandard levels inflated, at most 2 GiB in all).
/// Besides the header it checks typeSize and the DFD's bytesPlane0 against the format.
cubemap_rgb32f decode_ktx2_cubemap(std::span<const unsigned char> bytes, const std::string& name = "<ktx2>");

/// Reads back a cubemap array written by encode_ktx2_cubemap_array: the checks of
/// decode_ktx2_cubemap, except that layerCount must be in 1..ktx2_max_array_layers (a single
/// cubemap, layerCount 0, is refused here as an array is by decode_ktx2_cubemap).
std::vector<cubemap_rgb32f> decode_ktx2_cubemap_array(std::span<const unsigned char> bytes, const std::string& name = "<ktx2>");

/// IEEE binary16 conversions used by the RGBA16F path (see the header comment for the policy).
std::uint16_t float_to_half(float f) noexcept;
float half_to_float(std::uint16_t h) noexcept;

/// Unsigned small floats of B10G11R11: 5-bit exponent and `mantissa_bits` (6 or 5) mantissa bits,
/// the policy of the header comment (negative, -0, NaN -> 0; above max finite -> max finite).
std::uint32_t float_to_ufloat(float f, int mantissa_bits) noexcept;
float ufloat_to_float(std::uint32_t code, int mantissa_bits) noexcept;

/// One packed texel: R bits 0-10, G bits 11-21, B bits 22-31.
std::uint32_t pack_b10g11r11(float r, float g, float b) noexcept;
void unpack_b10g11r11(std::uint32_t packed, float rgb[3]) noexcept;
/// One packed texel by the shared-exponent algorithm of the header comment.
std::uint32_t pack_e5b9g9r9(float r, float g, float b) noexcept;
void unpack_e5b9g9r9(std::uint32_t packed, float rgb[3]) noexcept;

/// What a texel of RGB float becomes after encoding to `format` and decoding again.
void ktx2_roundtrip_texel(ktx2_format format, const float in[3], float out[3]) noexcept;

/// Quantisation of one level: the decoded values against the float input. Relative error of a
/// value x decoded as x' is |x' - x| / max(|x|, floor) with floor = 1e-3 x the level's mean |x|
/// over all finite values (the same floor as the bake's metrics; 1e-30 for an all-zero level),
/// so errors in values a thousand times darker than the mean are measured against the mean's
/// thousandth instead of blowing up. NaN inputs are counted, not measured. Clamped values
/// (above range, negatives) are included in the errors.
struct ktx2_quantisation_level {
    int level = 0;
    int face_size = 0;
    std::size_t values = 0;          ///< RGB values measured (6 s^2 x 3 minus NaNs)
    double floor = 0.0;
    double max_rel_error = 0.0;
    double rms_rel_error = 0.0;
    std::size_t above_range = 0;     ///< as ktx2_clamp_counts, for this level
    std::size_t negative_clamped = 0;
    std::size_t nan = 0;
};
/// `decoded`: the cube as the file decodes (a block format's result; computed here when absent).
std::vector<ktx2_quantisation_level> ktx2_quantisation_report(const cubemap_rgb32f& cube, ktx2_format format,
                                                             const cubemap_rgb32f* decoded = nullptr);

} // namespace ibl_bake
