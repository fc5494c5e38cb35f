#pragma once
// tools/ibl-bake/io/block_codec.hpp — the block-compressed HDR formats of the KTX2 writer: BC6H
// (BC6H_UFLOAT, the library's own codec, ibl/bake/bc6h.hpp) and ASTC HDR 4x4 / 6x6 (SFLOAT, ARM's
// astc-encoder from Debian's libastcenc-dev, never written by hand). Both store 16 bytes per block:
// 8 bits per texel for BC6H and ASTC 4x4, 3.56 for ASTC 6x6.
//
// Encoding policy (both formats): NaN and negative values become 0 (neither format has a sign
// in these variants), values above 65504 (the largest half; also +inf) are clamped to 65504.
// Decoding returns what a GPU sampling the texture returns: the half-float results of the block
// (BC6H: the library's decoder, bit-exact to the specification; ASTC: astcenc's decompressor to
// half floats, the format's own reference decoder).
//
// Quality levels:
//   fast        BC6H one-subset search (dynamic probes compressed at run time); astcenc -fast
//   normal      BC6H one- and two-subset modes over a shortlist of partitions, endpoint
//               refinement; astcenc -medium (the default of both)
//   exhaustive  BC6H every mode and partition (the tests' reference); astcenc -exhaustive

#include <cstddef>
#include <cstdint>
#include <vector>

#include "io/ktx2.hpp"

namespace ibl_bake {

/// The texels along x and y of one block of `format` (1 for the per-texel formats).
int ktx2_block_dim(ktx2_format format) noexcept;
/// True for BC6H and the ASTC formats.
bool ktx2_block_compressed(ktx2_format format) noexcept;
/// Bytes of the compressed s x s image of `format`: ceil(s / b)^2 x 16.
std::size_t block_image_bytes(ktx2_format format, int s) noexcept;

/// Encodes an s x s image of RGB float (3 floats per texel, row-major) into the blocks of a
/// block-compressed `format`, row-major block order; `threads` workers (0 = all cores). The
/// result does not depend on `threads`.
std::vector<unsigned char> encode_block_image(ktx2_format format, const float* rgb, int s, block_quality quality,
                                              unsigned threads = 1);

/// The six faces of one cube level (faces[f]: s x s x 3 floats) as their blocks, face after face
/// (encode_block_image of each, concatenated). Where the blocks tile every face (s a multiple of
/// the block size) BC6H encodes the six faces as one s x 6s image: one parallel pass per level
/// instead of six, the same bytes.
std::vector<unsigned char> encode_block_level(ktx2_format format, const float* const faces[6], int s, block_quality quality,
                                              unsigned threads = 1);

/// Decodes such blocks (exactly block_image_bytes(format, s) of them) to s x s x 3 floats.
std::vector<float> decode_block_image(ktx2_format format, const unsigned char* blocks, std::size_t bytes, int s);

} // namespace ibl_bake
