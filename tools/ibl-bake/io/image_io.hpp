#pragma once
// tools/ibl-bake/io/image_io.hpp — image input/output of the ibl-bake tool (host only).
//
// Reading: Radiance .hdr (RGBE, decoded by stb_image) and OpenEXR (decoded by OpenEXR 3, see
// below) into image_rgb32f: linear RGB, float32, interleaved, top row first.
// The format is recognised from the first bytes, never from the file name:
//   "v/1\x01" (0x76 0x2f 0x31 0x01)   OpenEXR
//   "#?RADIANCE\n" or "#?RGBE\n"      Radiance HDR (stbi_is_hdr must agree)
//   anything stb_image recognises     LDR image: rejected ("LDR input not supported")
//   anything else                     rejected ("unrecognised image format")
//
// Error policy: every problem throws image_error (a std::runtime_error) whose message starts with
// the file name (or the name given for a memory buffer) and says what is wrong: missing file,
// empty file, truncated data, unsupported variant, absurd dimensions, corrupt data. The readers
// never return a partially decoded image: a Radiance file is walked structurally before decoding
// (stb_image itself reads zeros past the end of a truncated file, and loops forever on a
// truncated run-length scanline), and every exception of OpenEXR becomes an image_error whose
// message quotes OpenEXR's ("truncated OpenEXR file" when it read past the end).
//
// OpenEXR input, what is read:
//   * every compression of OpenEXR 3.1 (NONE, RLE, ZIPS, ZIP, PIZ, PXR24, B44, B44A, DWAA, DWAB),
//     scanline and tiled parts; of a tiled part (mip- or ripmapped) only level 0 is read;
//   * the part: read_options::part names it (the `name` attribute); by default the first part
//     with channels R, G and B, else the first with Y. Deep parts are never read;
//   * the channels, by their exact names: R, G, B (any other channel, A included, is ignored);
//     else Y alone (grey: R = G = B = Y); else Y, RY, BY (luminance/chroma, converted to RGB by
//     OpenEXR's RgbaInputFile with the file's chromaticities; its result is half precision).
//     HALF, FLOAT and UINT channels are converted to float by OpenEXR (exact for HALF, for FLOAT
//     and for UINT below 2^24); R, G, B and Y must not be subsampled;
//   * the windows: the image is the display window. Its pixels outside the data window are 0;
//     data outside the display window is cropped. (A lat-long map is its display window.)
//   * threads: OpenEXR decodes in the calling thread (numThreads = 0 for every OpenEXR object;
//     the global thread count, Imf::setGlobalThreadCount, is left alone).
// Before OpenEXR parses anything, the headers of all parts are walked with bounds checks
// (image_exr.cpp, scan_exr_headers): attribute sizes that OpenEXR would misread, a `type`
// attribute that contradicts the file's layout (e.g. "deepscanline" in a scanline file), chunk
// offset tables larger than the file, and sizes beyond the limits below are refused there.
//
// Limits (read_options): width and height in [1, max_dimension] (16384) and width * height
// <= max_pixels (16384 * 8192: a 16k lat-long map, 1.6 GB as float RGB). They are checked from
// the header, before any pixel memory is allocated. For OpenEXR they apply to the display and
// the data window of every part (OpenEXR sizes each part's chunk table from its data window),
// tile sizes must lie in [1, max_dimension], and max_decoded_bytes bounds both the decoded data
// window of the part that is read (all its channels) and one decoded chunk (a block of
// scanlines or a tile, which OpenEXR allocates whole).
//
// Texel policy, applied to every value after decoding (read_report counts what was changed):
//   * finite negative values are clamped to 0. Radiance is non-negative; lossy EXR compression
//     (PIZ/B44/DWA rounding of half floats) leaves small negative values around dark edges (the
//     shared data: studio.exr 3 values, courtyard.exr 1818 values down to about -0.003). Clamping
//     changes the map's integral by at most count * |most negative| * texel solid angle, which
//     the report makes visible;
//   * NaN and +-infinity are rejected by default (image_error with the count and the first texel):
//     one non-finite texel poisons every prefiltered texel and every SH coefficient it touches,
//     and replacing a +inf (a sun that overflowed half floats) by 0 would silently remove the
//     brightest light. nonfinite_policy::replace_with_zero opts into replacing them by 0.
//     (Radiance RGBE cannot encode non-finite values; EXR can.)
//
// Lat-long inputs must be 2:1 (check_latlong, read_latlong): another aspect ratio is an error,
// not a warning, because a lat-long map with unequal angular resolutions is almost always the
// wrong file (a cube cross, a cropped panorama) and would be baked into plausible-looking but
// wrong lighting.
//
// Writing: float32 RGB OpenEXR (ZIP compressed, lossless), Radiance HDR (RLE RGBE, via
// stb_image_write), 8-bit sRGB PNG previews (tonemap_png below). Every writer encodes into memory
// first and then writes atomically (write_file_atomic): a temporary file in the same directory,
// fsync, rename over the destination. On failure the temporary is removed and the destination
// is untouched, so no half-written file is ever left behind.

#include <cstddef>
#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace ibl_bake {

/// Every I/O failure: the message names the file and the problem.
class image_error : public std::runtime_error {
public:
    image_error(const std::string& file, const std::string& problem)
        : std::runtime_error(file + ": " + problem), file_(file) {}
    const std::string& file() const noexcept { return file_; }

private:
    std::string file_;
};

/// Linear RGB float32 image: rgb[3 (y width + x) + c], row y = 0 at the top.
struct image_rgb32f {
    int width = 0;
    int height = 0;
    std::vector<float> rgb;

    image_rgb32f() = default;
    image_rgb32f(int w, int h) : width(w), height(h), rgb(std::size_t(w) * std::size_t(h) * 3, 0.0f) {}

    float* texel(int x, int y) noexcept { return rgb.data() + 3 * (std::size_t(y) * std::size_t(width) + std::size_t(x)); }
    const float* texel(int x, int y) const noexcept {
        return rgb.data() + 3 * (std::size_t(y) * std::size_t(width) + std::size_t(x));
    }
};

enum class nonfinite_policy { reject, replace_with_zero };

struct read_options {
    int max_dimension = 16384;
    std::uint64_t max_pixels = std::uint64_t(16384) * 8192;
    nonfinite_policy nonfinite = nonfinite_policy::reject;
    /// OpenEXR: decoded bytes of the part read and of one chunk (default: a max_pixels image
    /// of four float channels, 2 GiB).
    std::uint64_t max_decoded_bytes = std::uint64_t(16384) * 8192 * 16;
    /// OpenEXR: the name of the part to read (its `name` attribute); empty = the first part with
    /// R, G, B channels, else the first with Y. The tool's option: --part NAME.
    std::string part;
};

/// What a reader found and changed.
struct read_report {
    std::string format;                ///< "OpenEXR" or "Radiance HDR"
    std::size_t negative_values = 0;   ///< channel values < 0 clamped to 0
    std::size_t negative_texels = 0;   ///< texels with at least one such value
    float most_negative = 0.0f;        ///< the smallest value seen before clamping (0 if none)
    std::size_t nonfinite_values = 0;  ///< NaN / inf values (replaced by 0 under replace_with_zero)
    float max_value = 0.0f;            ///< largest channel value after the policy
    std::string detail;                ///< OpenEXR: part, compression, layout, channels read
};

// ---- files -----------------------------------------------------------------------------------

/// The whole file. Throws image_error for a missing file, a directory, a read error.
std::vector<unsigned char> read_file(const std::string& path);

/// Writes bytes atomically: temporary file in the same directory, fsync, rename over `path`.
void write_file_atomic(const std::string& path, std::span<const unsigned char> bytes);

// ---- reading ---------------------------------------------------------------------------------

/// Reads an HDR or EXR file (format from its content). Throws image_error.
image_rgb32f read_image(const std::string& path, const read_options& options = {}, read_report* report = nullptr);

/// The same from memory; `name` is used in messages (and is the file name for read_image).
image_rgb32f read_image_memory(std::span<const unsigned char> bytes, const std::string& name,
                               const read_options& options = {}, read_report* report = nullptr);

/// Format-specific memory readers (the fuzz harness calls these directly).
image_rgb32f read_hdr_memory(std::span<const unsigned char> bytes, const std::string& name,
                             const read_options& options = {}, read_report* report = nullptr);
image_rgb32f read_exr_memory(std::span<const unsigned char> bytes, const std::string& name,
                             const read_options& options = {}, read_report* report = nullptr);

/// Throws image_error unless width == 2 height (the lat-long convention of DESIGN.md).
void check_latlong(const image_rgb32f& image, const std::string& name);

/// read_image + check_latlong.
image_rgb32f read_latlong(const std::string& path, const read_options& options = {}, read_report* report = nullptr);

// ---- writing ---------------------------------------------------------------------------------

/// String attributes written into an OpenEXR header (name, value): the conventions of a product
/// (ibl-bake writes ibl.* attributes: docs/ibl-bake.md, "Conventions in the files").
using exr_attributes = std::vector<std::pair<std::string, std::string>>;

/// Float32 RGB OpenEXR (channels B, G, R as OpenEXR orders them; ZIP compression, lossless), with
/// the given string attributes in its header.
std::vector<unsigned char> encode_exr(const image_rgb32f& image, const std::string& name = "<exr>",
                                      const exr_attributes& attributes = {});
void write_exr(const std::string& path, const image_rgb32f& image, const exr_attributes& attributes = {});

/// The string attributes of an OpenEXR file's first part (the file is checked as read_image checks
/// it first). Throws image_error.
exr_attributes read_exr_string_attributes(const std::string& path);

/// A four-channel float image (R, G, B, A interleaved, row 0 first): the lobe LUT's file.
struct image_rgba32f {
    int width = 0, height = 0;
    std::vector<float> rgba;
};
/// Float32 RGBA OpenEXR (ZIP); read back by read_exr_rgba (a missing channel reads as 0; the data
/// window must start at (0, 0), at most 4096 x 4096). Both throw image_error.
std::vector<unsigned char> encode_exr_rgba(const image_rgba32f& image, const std::string& name = "<exr>",
                                           const exr_attributes& attributes = {});
void write_exr_rgba(const std::string& path, const image_rgba32f& image, const exr_attributes& attributes = {});
image_rgba32f read_exr_rgba(const std::string& path);

/// Radiance HDR (RGBE, run-length encoded for widths 8..32767). RGBE stores one shared exponent e
/// (2^(e-1) <= max(r, g, b) < 2^e) and an 8-bit mantissa per channel; stb truncates on encoding
/// and decodes without centring, so each channel comes back as x' with |x - x'| < 2^(e-8), i.e.
/// below 2^-8 of 2^e and below 2^-7 of the largest channel. Negative and NaN values are written
/// as 0, values above 2^126 as 2^126 (the RGBE exponent byte would overflow).
std::vector<unsigned char> encode_hdr(const image_rgb32f& image, const std::string& name = "<hdr>");
void write_hdr(const std::string& path, const image_rgb32f& image);

/// PNG preview: x -> exposure * x -> tonemap -> sRGB OETF (IEC 61966-2-1) -> round(255 y).
///   clamp:    min(x, 1)
///   reinhard: x / (1 + x) per channel (E. Reinhard et al. 2002, eq. 3; keeps every HDR value
///             distinguishable, darkens mid-tones: 1 -> 0.5)
/// NaN and negative values map to 0.
enum class tonemap { clamp, reinhard };
struct png_options {
    float exposure = 1.0f;
    tonemap op = tonemap::reinhard;
};

/// The 8-bit sRGB code of one linear value under `options` (what encode_png writes per channel).
std::uint8_t tonemap_png(float linear, const png_options& options) noexcept;

std::vector<unsigned char> encode_png(const image_rgb32f& image, const png_options& options = {},
                                      const std::string& name = "<png>");
void write_png(const std::string& path, const image_rgb32f& image, const png_options& options = {});

} // namespace ibl_bake
