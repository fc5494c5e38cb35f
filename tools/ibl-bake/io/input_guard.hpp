#pragma once
// tools/ibl-bake/io/input_guard.hpp — checks on input files before they are read, and the radiance
// clamp applied to an input image before it becomes an ibl::latlong.
//
// Input files (check_input_file): only regular files are read. A FIFO would block the reader
// forever, a character device such as /dev/zero never ends (the reader grows its buffer until
// memory runs out), a directory has no bytes. The file is stat()ed first (nothing is opened
// before its type is known, so opening a device never has side effects) and must be a regular
// file of at most `max_bytes` bytes. The bound for images is input_byte_limit(max_input_pixels):
// 64 MiB + 32 bytes per allowed pixel, i.e. room for an uncompressed OpenEXR of that many pixels
// with 8 half or 4 float32 channels plus its offset tables and header (default --max-input-pixels
// 2^27: 4 GiB + 64 MiB). Scene files are bounded by scene_byte_limit (16 MiB). A file replaced
// between the check and the read is not guarded against (the checks are not a security
// boundary; they turn a wrong path into a clear error).
//
// Radiance clamp (clamp_radiance): finite channel values above radiance_clamp_bound = 1e30 are
// set to the bound and counted (report.json: source.values_clamped). Why 1e30: the pipeline
// accumulates radiance in float (sub-sample sums of the cube bake, box mips, the prefilter's
// weighted sums of up to 16384 samples, luminance sums over every input texel for importance
// sampling). The longest such sum has at most 2^27 terms (--max-input-pixels' largest default
// map) with weights <= 1, so with every term <= B the sum stays <= 2^27 B; B = 1e30 < 2^100 keeps
// it below 2^127, half of FLT_MAX (2^128), which leaves a factor 2 for rounding and for a
// channel sum. Texels of 1e37 (or a Radiance file at the largest exponent, about 1.7e38) made
// every specular texel of the rough levels +inf before the clamp. No physical radiance comes
// near 1e30 in any unit (the sun is about 1e9 nit), so the clamp changes only broken or hostile
// files. NaN and infinities are the image reader's business (rejected by default).

#include <cstddef>
#include <cstdint>
#include <string>

#include "io/image_io.hpp"

namespace ibl_bake {

/// Largest channel value an input keeps (see the header).
inline constexpr float radiance_clamp_bound = 1e30f;

/// Bytes an image file may have when at most `max_pixels` pixels are accepted.
std::uint64_t input_byte_limit(std::uint64_t max_pixels) noexcept;

/// Bytes a scene file may have.
inline constexpr std::uint64_t scene_byte_limit = std::uint64_t(16) << 20;

/// Throws image_error (message: the path and what is wrong) unless `path` names an existing
/// regular file (symbolic links followed) of at most `max_bytes` bytes.
void check_input_file(const std::string& path, std::uint64_t max_bytes);

/// Clamps finite channel values above radiance_clamp_bound to it; returns how many were changed.
/// Updates report.max_value to the largest value after the clamp.
std::size_t clamp_radiance(image_rgb32f& image, read_report& report) noexcept;

} // namespace ibl_bake
