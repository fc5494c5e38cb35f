// tools/ibl-bake/io/ktx2.cpp — KTX2 cubemap writer and validating reader (layout: ktx2.hpp).

#include "io/ktx2.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <string_view>

#include <zstd.h>

#include "io/block_codec.hpp"
#include "io/image_io.hpp"

namespace ibl_bake {
namespace {

constexpr unsigned char ktx2_identifier[12] = {0xAB, 0x4B, 0x54, 0x58, 0x20, 0x32, 0x30, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A};
constexpr std::size_t header_bytes = 80;
constexpr std::size_t level_entry_bytes = 24;
constexpr std::uint32_t khr_df_model_rgbsda = 1, khr_df_model_bc6h = 131, khr_df_model_astc = 162;
constexpr std::uint32_t khr_df_primaries_bt709 = 1, khr_df_transfer_linear = 1;
constexpr std::uint32_t ktx2_ss_zstd = 2;
constexpr std::uint64_t max_inflated_bytes = std::uint64_t(1) << 31; ///< what the reader inflates at most
constexpr std::uint32_t khr_df_version_1_3 = 2;
constexpr std::uint32_t khr_df_float = 0x80, khr_df_signed = 0x40, khr_df_exponent = 0x20;
constexpr std::uint32_t float_minus_one_bits = 0xBF800000u, float_one_bits = 0x3F800000u;

/// One DFD sample: channel id with qualifiers, bit offset, bit count, lower, upper.
struct dfd_sample {
    std::uint32_t channel, offset, bits, lower, upper;
};

std::vector<dfd_sample> dfd_samples(ktx2_format f) {
    switch (f) {
    case ktx2_format::rgba32f:
    case ktx2_format::rgba16f: {
        const std::uint32_t bits = f == ktx2_format::rgba32f ? 32 : 16;
        std::vector<dfd_sample> v;
        const std::uint32_t ids[4] = {0, 1, 2, 15};
        for (std::uint32_t c = 0; c < 4; ++c)
            v.push_back({ids[c] | khr_df_float | khr_df_signed, bits * c, bits, float_minus_one_bits, float_one_bits});
        return v;
    }
    case ktx2_format::b10g11r11:
        return {{0 | khr_df_float, 0, 11, 0, float_one_bits},
                {1 | khr_df_float, 11, 11, 0, float_one_bits},
                {2 | khr_df_float, 22, 10, 0, float_one_bits}};
    case ktx2_format::e5b9g9r9:
        break;
    case ktx2_format::bc6h: return {{0 | khr_df_float, 0, 128, 0, float_one_bits}};
    case ktx2_format::astc4x4:
    case ktx2_format::astc6x6: return {{0 | khr_df_float | khr_df_signed, 0, 128, float_minus_one_bits, float_one_bits}};
    }
    std::vector<dfd_sample> v;
    for (std::uint32_t c = 0; c < 3; ++c) {
        v.push_back({c, 9 * c, 9, 0, 8448});
        v.push_back({c | khr_df_exponent, 27, 5, 15, 31});
    }
    return v;
}

std::uint32_t dfd_total_bytes(ktx2_format f) { return std::uint32_t(4 + 24 + 16 * dfd_samples(f).size()); }

bool known_format(std::uint32_t vk) {
    return vk == std::uint32_t(ktx2_format::rgba32f) || vk == std::uint32_t(ktx2_format::rgba16f) ||
           vk == std::uint32_t(ktx2_format::b10g11r11) || vk == std::uint32_t(ktx2_format::e5b9g9r9) ||
           vk == std::uint32_t(ktx2_format::bc6h) || vk == std::uint32_t(ktx2_format::astc4x4) ||
           vk == std::uint32_t(ktx2_format::astc6x6);
}

/// typeSize of the header: 2 for RGBA16F, 1 for the block formats, 4 otherwise.
std::uint32_t type_size(ktx2_format f) {
    return f == ktx2_format::rgba16f ? 2 : ktx2_block_compressed(f) ? 1 : 4;
}

/// Bytes of one level (6 faces of s x s texels) in `format`, before supercompression.
std::size_t level_bytes(ktx2_format f, std::size_t s) {
    return ktx2_block_compressed(f) ? 6 * block_image_bytes(f, int(s)) : 6 * s * s * ktx2_texel_bytes(f);
}

int full_chain(int n) {
    int levels = 1;
    while ((n >> levels) > 0) ++levels;
    return levels;
}

std::size_t texel_bytes(ktx2_format f) { return ktx2_texel_bytes(f); }

std::size_t align_up(std::size_t x, std::size_t a) { return (x + a - 1) / a * a; }

void put32(std::vector<unsigned char>& b, std::size_t at, std::uint32_t v) {
    for (int i = 0; i < 4; ++i) b[at + std::size_t(i)] = static_cast<unsigned char>(v >> (8 * i));
}
void put64(std::vector<unsigned char>& b, std::size_t at, std::uint64_t v) {
    for (int i = 0; i < 8; ++i) b[at + std::size_t(i)] = static_cast<unsigned char>(v >> (8 * i));
}
std::uint32_t get32(std::span<const unsigned char> b, std::size_t at) {
    std::uint32_t v = 0;
    for (int i = 3; i >= 0; --i) v = (v << 8) | b[at + std::size_t(i)];
    return v;
}
std::uint64_t get64(std::span<const unsigned char> b, std::size_t at) {
    return std::uint64_t(get32(b, at)) | (std::uint64_t(get32(b, at + 4)) << 32);
}

void check_cube(const cubemap_rgb32f& c, const std::string& name) {
    if (c.size < 1) throw image_error(name, "cubemap face size must be >= 1, got " + std::to_string(c.size));
    if (c.size > 65536) throw image_error(name, "cubemap face size " + std::to_string(c.size) + " too large");
    const int L = int(c.levels.size());
    if (L < 1 || L > full_chain(c.size))
        throw image_error(name, "cubemap of face size " + std::to_string(c.size) + " cannot have " + std::to_string(L) +
                                    " mip levels (1 to " + std::to_string(full_chain(c.size)) + ")");
    for (int l = 0; l < L; ++l) {
        const std::size_t s = std::size_t(c.face_size(l));
        for (int f = 0; f < 6; ++f)
            if (c.levels[std::size_t(l)][std::size_t(f)].size() != s * s * 3)
                throw image_error(name, "cubemap level " + std::to_string(l) + " face " + std::to_string(f) + " has " +
                                            std::to_string(c.levels[std::size_t(l)][std::size_t(f)].size()) +
                                            " values, expected " + std::to_string(s * s * 3));
    }
}

} // namespace

// ---- format properties -------------------------------------------------------------------------

std::size_t ktx2_texel_bytes(ktx2_format f) noexcept {
    switch (f) {
    case ktx2_format::rgba32f: return 16;
    case ktx2_format::rgba16f: return 8;
    case ktx2_format::bc6h:
    case ktx2_format::astc4x4:
    case ktx2_format::astc6x6: return 16;
    default: return 4;
    }
}

float ktx2_channel_max(ktx2_format f, int channel) noexcept {
    switch (f) {
    case ktx2_format::rgba32f: return std::numeric_limits<float>::max();
    case ktx2_format::rgba16f: return 65504.0f;
    case ktx2_format::b10g11r11: return channel == 2 ? 64512.0f : 65024.0f;
    case ktx2_format::e5b9g9r9: return 65408.0f;
    default: return 65504.0f; // the block formats decode to half floats
    }
}

bool ktx2_unsigned(ktx2_format f) noexcept { return f != ktx2_format::rgba32f && f != ktx2_format::rgba16f; }

namespace {
void count_clamps(ktx2_format f, const float* px, ktx2_clamp_counts& k) noexcept {
    const bool uns = ktx2_unsigned(f);
    for (int c = 0; c < 3; ++c) {
        const float x = px[c];
        if (std::isnan(x)) ++k.nan;
        else if (x > ktx2_channel_max(f, c)) ++k.above_range;
        else if (uns && x < 0.0f) ++k.negative;
    }
}
} // namespace

// ---- half floats -------------------------------------------------------------------------------

std::uint16_t float_to_half(float f) noexcept {
    const std::uint32_t bits = std::bit_cast<std::uint32_t>(f);
    const std::uint16_t sign = static_cast<std::uint16_t>((bits >> 16) & 0x8000u);
    const std::uint32_t a = bits & 0x7fffffffu;
    if (a > 0x7f800000u) return static_cast<std::uint16_t>(sign | 0x7e00u); // NaN (quiet)
    if (a == 0x7f800000u) return static_cast<std::uint16_t>(sign | 0x7c00u); // infinity
    if (a >= 0x477fe000u) return static_cast<std::uint16_t>(sign | 0x7bffu); // >= 65504: clamp
    const int e = int(a >> 23) - 127;
    const std::uint32_t m24 = (a & 0x7fffffu) | 0x800000u;
    std::uint32_t h, rem, halfway;
    if (e >= -14) { // normal half: 10 mantissa bits, drop 13
        h = (std::uint32_t(e + 15) << 10) | ((a & 0x7fffffu) >> 13);
        rem = a & 0x1fffu;
        halfway = 0x1000u;
    } else { // subnormal half: value / 2^-24 = m24 * 2^(e + 1)
        const int s = -(e + 1); // >= 14
        if (s >= 25) return sign;
        h = m24 >> s;
        rem = m24 & ((1u << s) - 1u);
        halfway = 1u << (s - 1);
    }
    if (rem > halfway || (rem == halfway && (h & 1u))) ++h; // may carry into the exponent: correct
    return static_cast<std::uint16_t>(sign | h);
}

float half_to_float(std::uint16_t h) noexcept {
    const std::uint32_t sign = std::uint32_t(h & 0x8000u) << 16;
    const std::uint32_t e = (h >> 10) & 0x1fu;
    const std::uint32_t m = h & 0x3ffu;
    if (e == 0x1f) return std::bit_cast<float>(sign | 0x7f800000u | (m << 13));
    if (e == 0) { // zero or subnormal: m * 2^-24, exact in float
        const float v = float(m) * 0x1p-24f;
        return sign ? -v : v;
    }
    return std::bit_cast<float>(sign | ((e + 112) << 23) | (m << 13));
}

// ---- unsigned small floats (B10G11R11) ---------------------------------------------------------

std::uint32_t float_to_ufloat(float f, int m) noexcept {
    const std::uint32_t bits = std::bit_cast<std::uint32_t>(f);
    const std::uint32_t mask = (1u << m) - 1u;
    const std::uint32_t max_code = (30u << m) | mask; // exponent 30, all mantissa bits: max finite
    if (bits & 0x80000000u) return 0;                 // negative, -0, -inf, negative NaN
    if (bits > 0x7f800000u) return 0;                 // NaN
    if ((bits >> 23) == 0) return 0;                  // 0 and float denormals (< 2^-126, far below half the smallest code)
    const int e = int(bits >> 23) - 127;
    if (e > 15) return max_code;                      // >= 2^16 and +inf
    const std::uint32_t m24 = (bits & 0x7fffffu) | 0x800000u;
    std::uint32_t h, rem, halfway;
    if (e >= -14) { // normal: keep m of the 23 mantissa bits
        const int drop = 23 - m;
        h = (std::uint32_t(e + 15) << m) | ((bits & 0x7fffffu) >> drop);
        rem = bits & ((1u << drop) - 1u);
        halfway = 1u << (drop - 1);
    } else { // denormal: value / 2^(-14 - m) = m24 * 2^(e - 23 + 14 + m)
        const int sh = 9 - m - e; // > 23 - m
        if (sh >= 25) return 0;   // below half the smallest denormal
        h = m24 >> sh;
        rem = m24 & ((1u << sh) - 1u);
        halfway = 1u << (sh - 1);
    }
    if (rem > halfway || (rem == halfway && (h & 1u))) ++h; // a carry moves into the exponent: correct
    return h > max_code ? max_code : h;
}

float ufloat_to_float(std::uint32_t code, int m) noexcept {
    const std::uint32_t e = (code >> m) & 0x1fu;
    const std::uint32_t mant = code & ((1u << m) - 1u);
    if (e == 31) return mant ? std::numeric_limits<float>::quiet_NaN() : std::numeric_limits<float>::infinity();
    if (e == 0) return std::ldexp(float(mant), -14 - m); // exact
    return std::bit_cast<float>(((e + 112) << 23) | (mant << (23 - m)));
}

std::uint32_t pack_b10g11r11(float r, float g, float b) noexcept {
    return float_to_ufloat(r, 6) | (float_to_ufloat(g, 6) << 11) | (float_to_ufloat(b, 5) << 22);
}

void unpack_b10g11r11(std::uint32_t p, float rgb[3]) noexcept {
    rgb[0] = ufloat_to_float(p & 0x7ffu, 6);
    rgb[1] = ufloat_to_float((p >> 11) & 0x7ffu, 6);
    rgb[2] = ufloat_to_float((p >> 22) & 0x3ffu, 5);
}

// ---- shared exponent (E5B9G9R9) ------------------------------------------------------------------

std::uint32_t pack_e5b9g9r9(float r, float g, float b) noexcept {
    constexpr int N = 9, B = 15;
    static constexpr double sharedexp_max = 65408.0; // (2^N - 1) / 2^N * 2^(Emax - B)
    const auto clampc = [](float x) {
        if (!(x > 0.0f)) return 0.0; // negative, zero, NaN
        return std::min(double(x), sharedexp_max);
    };
    const double rc = clampc(r), gc = clampc(g), bc = clampc(b);
    const double maxc = std::max(rc, std::max(gc, bc));
    int floor_log2 = -B - 1; // max(-B - 1, floor(log2(0)) = -inf)
    if (maxc > 0.0) {
        int e2 = 0;
        (void)std::frexp(maxc, &e2); // maxc = f 2^e2, f in [0.5, 1): floor(log2 maxc) = e2 - 1 exactly
        floor_log2 = std::max(-B - 1, e2 - 1);
    }
    int exp_shared = floor_log2 + 1 + B;
    const double max_s = std::floor(std::ldexp(maxc, -(exp_shared - B - N)) + 0.5);
    if (max_s == double(1 << N)) ++exp_shared;
    const auto quant = [&](double x) {
        return std::uint32_t(std::floor(std::ldexp(x, -(exp_shared - B - N)) + 0.5));
    };
    return quant(rc) | (quant(gc) << 9) | (quant(bc) << 18) | (std::uint32_t(exp_shared) << 27);
}

void unpack_e5b9g9r9(std::uint32_t p, float rgb[3]) noexcept {
    const int e = int(p >> 27) - 15 - 9;
    rgb[0] = std::ldexp(float(p & 0x1ffu), e);
    rgb[1] = std::ldexp(float((p >> 9) & 0x1ffu), e);
    rgb[2] = std::ldexp(float((p >> 18) & 0x1ffu), e);
}

void ktx2_roundtrip_texel(ktx2_format f, const float in[3], float out[3]) noexcept {
    switch (f) {
    case ktx2_format::rgba32f:
        for (int c = 0; c < 3; ++c) out[c] = in[c];
        return;
    case ktx2_format::rgba16f:
        for (int c = 0; c < 3; ++c) out[c] = half_to_float(float_to_half(in[c]));
        return;
    case ktx2_format::b10g11r11: unpack_b10g11r11(pack_b10g11r11(in[0], in[1], in[2]), out); return;
    case ktx2_format::e5b9g9r9: unpack_e5b9g9r9(pack_e5b9g9r9(in[0], in[1], in[2]), out); return;
    default: { // a block format: the texel as a constant block
        const float block[3] = {in[0], in[1], in[2]};
        std::vector<float> img(std::size_t(3 * ktx2_block_dim(f) * ktx2_block_dim(f)));
        for (std::size_t i = 0; i < img.size(); ++i) img[i] = block[i % 3];
        const std::vector<unsigned char> b = encode_block_image(f, img.data(), ktx2_block_dim(f), block_quality::normal);
        const std::vector<float> d = decode_block_image(f, b.data(), b.size(), ktx2_block_dim(f));
        for (int c = 0; c < 3; ++c) out[c] = d[std::size_t(c)];
        return;
    }
    }
}

// ---- writer ------------------------------------------------------------------------------------

cubemap_rgb32f cubemap_rgb32f::zeros(int size, int level_count) {
    cubemap_rgb32f c;
    c.size = size;
    c.levels.resize(std::size_t(level_count > 0 ? level_count : 0));
    for (int l = 0; l < level_count; ++l) {
        const std::size_t s = std::size_t(c.face_size(l));
        for (auto& face : c.levels[std::size_t(l)]) face.assign(s * s * 3, 0.0f);
    }
    return c;
}

namespace {

/// One texel of `format` at b[at..] from RGB floats (alpha 1).
void put_texel(std::vector<unsigned char>& b, std::size_t at, ktx2_format format, const float* px) {
    switch (format) {
    case ktx2_format::rgba32f:
        for (int c = 0; c < 4; ++c) put32(b, at + 4 * std::size_t(c), std::bit_cast<std::uint32_t>(c < 3 ? px[c] : 1.0f));
        break;
    case ktx2_format::rgba16f:
        for (int c = 0; c < 4; ++c) {
            const std::uint16_t h = float_to_half(c < 3 ? px[c] : 1.0f);
            b[at + 2 * std::size_t(c)] = static_cast<unsigned char>(h & 0xff);
            b[at + 2 * std::size_t(c) + 1] = static_cast<unsigned char>(h >> 8);
        }
        break;
    case ktx2_format::b10g11r11: put32(b, at, pack_b10g11r11(px[0], px[1], px[2])); break;
    case ktx2_format::e5b9g9r9: put32(b, at, pack_e5b9g9r9(px[0], px[1], px[2])); break;
    default: break; // the block formats are written a whole image at a time (level_texels)
    }
}

/// The Data Format Descriptor of `format` at b[d..] (total dfd_total bytes).
void put_dfd(std::vector<unsigned char>& b, std::size_t d, ktx2_format format, std::uint32_t dfd_total, std::size_t tb) {
    const std::vector<dfd_sample> samples = dfd_samples(format);
    const std::uint32_t block_bytes = dfd_total - 4;
    put32(b, d, dfd_total);
    put32(b, d + 4, 0); // vendorId 0 (Khronos), descriptorType 0 (basic)
    put32(b, d + 8, khr_df_version_1_3 | (block_bytes << 16));
    const std::uint32_t model = format == ktx2_format::bc6h ? khr_df_model_bc6h
                                : ktx2_block_compressed(format) ? khr_df_model_astc
                                                                : khr_df_model_rgbsda;
    put32(b, d + 12, model | (khr_df_primaries_bt709 << 8) | (khr_df_transfer_linear << 16));
    const std::uint32_t bd = std::uint32_t(ktx2_block_dim(format) - 1);
    put32(b, d + 16, bd | (bd << 8));     // texelBlockDimension0..3 (0: 1 texel)
    put32(b, d + 20, std::uint32_t(tb));  // bytesPlane0
    put32(b, d + 24, 0);                  // bytesPlane4..7
    for (std::size_t i = 0; i < samples.size(); ++i) {
        const std::size_t at = d + 28 + 16 * i;
        const dfd_sample& sm = samples[i];
        put32(b, at, sm.offset | ((sm.bits - 1) << 16) | (sm.channel << 24));
        put32(b, at + 4, 0); // samplePosition
        put32(b, at + 8, sm.lower);
        put32(b, at + 12, sm.upper);
    }

}

/// The key/value pairs, sorted by key (the KTX2 rule), KTXwriter among them; their total length.
std::vector<std::pair<std::string, std::string>> ktx2_key_values(const std::string& writer, const std::string& name,
                                                                 const std::vector<std::pair<std::string, std::string>>& metadata,
                                                                 std::size_t& kvd_length) {
    std::vector<std::pair<std::string, std::string>> kv = metadata;
    kv.emplace_back("KTXwriter", writer);
    std::sort(kv.begin(), kv.end());
    for (std::size_t i = 0; i < kv.size(); ++i)
        if (kv[i].first.empty() || kv[i].first.find('\0') != std::string::npos || kv[i].second.find('\0') != std::string::npos ||
            (i > 0 && kv[i].first == kv[i - 1].first))
            throw image_error(name, "bad KTX2 key/value metadata key '" + kv[i].first + "'");
    kvd_length = 0;
    for (const auto& [k, v] : kv) kvd_length += align_up(4 + k.size() + 1 + v.size() + 1, 4);
    return kv;
}

void put_key_values(std::vector<unsigned char>& b, std::size_t at_kv, const std::vector<std::pair<std::string, std::string>>& kv) {
    for (const auto& [k, v] : kv) {
        const std::size_t len = k.size() + 1 + v.size() + 1;
        put32(b, at_kv, std::uint32_t(len));
        std::memcpy(b.data() + at_kv + 4, k.c_str(), k.size() + 1);
        std::memcpy(b.data() + at_kv + 4 + k.size() + 1, v.c_str(), v.size() + 1);
        at_kv += align_up(4 + len, 4);
    }
}

/// Where the parts of a KTX2 file lie: the DFD, the key/value data, each level's bytes (the
/// smallest level first in the file), and the file's size.
struct ktx2_placement {
    std::uint32_t dfd_total = 0;
    std::size_t dfd_offset = 0, kvd_offset = 0, kvd_length = 0, size = 0;
    std::vector<std::size_t> offset, length, raw_length;
};

/// levels[l]: the bytes of level l as stored (deflated when supercompressed); raw[l] its size inflated.
ktx2_placement place_ktx2(ktx2_format format, std::size_t kvd_length, const std::vector<std::vector<unsigned char>>& levels,
                          const std::vector<std::size_t>& raw, bool supercompressed) {
    ktx2_placement p;
    const std::size_t L = levels.size();
    const std::size_t align = supercompressed ? 1 : texel_bytes(format); // lcm(texel or block size, 4) = that size
    p.dfd_total = dfd_total_bytes(format);
    p.dfd_offset = header_bytes + level_entry_bytes * L;
    p.kvd_offset = p.dfd_offset + p.dfd_total;
    p.kvd_length = kvd_length;
    std::size_t pos = p.kvd_offset + kvd_length;
    p.offset.resize(L);
    p.length.resize(L);
    p.raw_length = raw;
    for (std::size_t i = L; i-- > 0;) {
        pos = align_up(pos, align);
        p.offset[i] = pos;
        p.length[i] = levels[i].size();
        pos += p.length[i];
    }
    p.size = pos;
    return p;
}

/// The identifier, the header and the level index.
void put_ktx2_header(std::vector<unsigned char>& b, const cubemap_rgb32f& cube, ktx2_format format, const ktx2_placement& p,
                     bool supercompressed, std::uint32_t layer_count = 0) {
    const std::size_t L = p.offset.size();
    std::memcpy(b.data(), ktx2_identifier, sizeof ktx2_identifier);
    put32(b, 12, std::uint32_t(format));
    put32(b, 16, type_size(format));
    put32(b, 20, std::uint32_t(cube.size));
    put32(b, 24, std::uint32_t(cube.size));
    put32(b, 28, 0); // pixelDepth
    put32(b, 32, layer_count); // layerCount (0: not an array)
    put32(b, 36, 6); // faceCount
    put32(b, 40, std::uint32_t(L));
    put32(b, 44, supercompressed ? ktx2_ss_zstd : 0);
    put32(b, 48, std::uint32_t(p.dfd_offset));
    put32(b, 52, p.dfd_total);
    put32(b, 56, std::uint32_t(p.kvd_offset));
    put32(b, 60, std::uint32_t(p.kvd_length));
    put64(b, 64, 0); // sgdByteOffset
    put64(b, 72, 0); // sgdByteLength
    for (std::size_t l = 0; l < L; ++l) {
        const std::size_t at = header_bytes + level_entry_bytes * l;
        put64(b, at, p.offset[l]);
        put64(b, at + 8, p.length[l]);
        put64(b, at + 16, p.raw_length[l]);
    }
}

/// Level l's bytes in `format` (6 faces in order); adds what the format clamped to `seen`.
std::vector<unsigned char> level_texels(const cubemap_rgb32f& cube, std::size_t l, ktx2_format format, const ktx2_encoding& enc,
                                        ktx2_clamp_counts& seen) {
    const std::size_t s = std::size_t(cube.face_size(int(l)));
    std::vector<unsigned char> b(level_bytes(format, s), 0);
    for (const std::vector<float>& face : cube.levels[l])
        for (std::size_t t = 0; t < s * s; ++t) count_clamps(format, face.data() + 3 * t, seen);
    if (ktx2_block_compressed(format)) {
        const float* faces[6];
        for (std::size_t f = 0; f < 6; ++f) faces[f] = cube.levels[l][f].data();
        return encode_block_level(format, faces, int(s), enc.quality, enc.threads);
    }
    const std::size_t tb = texel_bytes(format);
    std::size_t at = 0;
    for (std::size_t f = 0; f < 6; ++f)
        for (std::size_t t = 0; t < s * s; ++t, at += tb) put_texel(b, at, format, cube.levels[l][f].data() + 3 * t);
    return b;
}

std::vector<unsigned char> zstd_deflate(const std::vector<unsigned char>& raw, int level, const std::string& name) {
    // One frame with its content size (the reader checks it against the level) and a checksum (a
    // damaged level is refused instead of inflating to wrong blocks).
    std::vector<unsigned char> out(ZSTD_compressBound(raw.size()));
    const std::unique_ptr<ZSTD_CCtx, std::size_t (*)(ZSTD_CCtx*)> cctx(ZSTD_createCCtx(), ZSTD_freeCCtx);
    if (!cctx) throw image_error(name, "Zstandard: out of memory");
    ZSTD_CCtx_setParameter(cctx.get(), ZSTD_c_compressionLevel, level);
    ZSTD_CCtx_setParameter(cctx.get(), ZSTD_c_checksumFlag, 1);
    ZSTD_CCtx_setParameter(cctx.get(), ZSTD_c_contentSizeFlag, 1);
    const std::size_t n = ZSTD_compress2(cctx.get(), out.data(), out.size(), raw.data(), raw.size());
    if (ZSTD_isError(n)) throw image_error(name, std::string("Zstandard compression failed: ") + ZSTD_getErrorName(n));
    out.resize(n);
    return out;
}

} // namespace

namespace {
/// The file of `layers` cubemaps (checked: equal sizes and level counts); layer_count 0 writes a
/// single cubemap (layers has one element), n >= 1 an array of n.
std::vector<unsigned char> encode_layers(const std::vector<const cubemap_rgb32f*>& layers, std::uint32_t layer_count,
                                         ktx2_format format, const std::string& writer, const std::string& name,
                                         ktx2_clamp_counts* counts, const std::vector<std::pair<std::string, std::string>>& metadata,
                                         const ktx2_encoding& encoding) {
    if (layers.empty()) throw image_error(name, "a cubemap array needs at least one layer");
    for (const cubemap_rgb32f* c : layers) {
        check_cube(*c, name);
        if (c->size != layers[0]->size || c->levels.size() != layers[0]->levels.size())
            throw image_error(name, "the layers of a cubemap array differ in face size or level count");
    }
    if (!known_format(std::uint32_t(format)))
        throw image_error(name, "unsupported KTX2 format " + std::to_string(std::uint32_t(format)));
    if (encoding.zstd_level < 0 || encoding.zstd_level > ZSTD_maxCLevel())
        throw image_error(name, "Zstandard level " + std::to_string(encoding.zstd_level) + " outside 0.." + std::to_string(ZSTD_maxCLevel()));
    std::size_t kvd_length = 0;
    const std::vector<std::pair<std::string, std::string>> kv = ktx2_key_values(writer, name, metadata, kvd_length);
    const bool zstd = encoding.zstd_level > 0;
    ktx2_clamp_counts seen;
    const cubemap_rgb32f& cube = *layers[0];
    std::vector<std::vector<unsigned char>> levels(cube.levels.size());
    std::vector<std::size_t> raw(cube.levels.size());
    for (std::size_t l = 0; l < levels.size(); ++l) {
        // KTX2 order within a level: for each layer, for each face
        for (const cubemap_rgb32f* c : layers) {
            const std::vector<unsigned char> one = level_texels(*c, l, format, encoding, seen);
            levels[l].insert(levels[l].end(), one.begin(), one.end());
        }
        raw[l] = levels[l].size();
        if (zstd) levels[l] = zstd_deflate(levels[l], encoding.zstd_level, name);
    }
    const ktx2_placement p = place_ktx2(format, kvd_length, levels, raw, zstd);
    std::vector<unsigned char> b(p.size, 0);
    put_ktx2_header(b, cube, format, p, zstd, layer_count);
    put_dfd(b, p.dfd_offset, format, p.dfd_total, texel_bytes(format));
    put_key_values(b, p.kvd_offset, kv);
    for (std::size_t l = 0; l < levels.size(); ++l)
        if (!levels[l].empty()) std::memcpy(b.data() + p.offset[l], levels[l].data(), levels[l].size());
    if (counts) *counts = seen;
    return b;
}
} // namespace

std::vector<unsigned char> encode_ktx2_cubemap(const cubemap_rgb32f& cube, ktx2_format format, const std::string& writer,
                                               const std::string& name, ktx2_clamp_counts* counts,
                                               const std::vector<std::pair<std::string, std::string>>& metadata,
                                               const ktx2_encoding& encoding) {
    return encode_layers({&cube}, 0, format, writer, name, counts, metadata, encoding);
}

std::vector<unsigned char> encode_ktx2_cubemap_array(const std::vector<cubemap_rgb32f>& layers, ktx2_format format,
                                                     const std::string& writer, const std::string& name, ktx2_clamp_counts* counts,
                                                     const std::vector<std::pair<std::string, std::string>>& metadata,
                                                     const ktx2_encoding& encoding) {
    if (layers.empty() || layers.size() > ktx2_max_array_layers)
        throw image_error(name, "a cubemap array takes 1.." + std::to_string(ktx2_max_array_layers) + " layers, got " +
                                    std::to_string(layers.size()));
    std::vector<const cubemap_rgb32f*> p;
    for (const cubemap_rgb32f& c : layers) p.push_back(&c);
    return encode_layers(p, std::uint32_t(layers.size()), format, writer, name, counts, metadata, encoding);
}

void write_ktx2_cubemap(const std::string& path, const cubemap_rgb32f& cube, ktx2_format format, const std::string& writer,
                        const std::vector<std::pair<std::string, std::string>>& metadata, const ktx2_encoding& encoding) {
    write_file_atomic(path, encode_ktx2_cubemap(cube, format, writer, path, nullptr, metadata, encoding));
}

// ---- reader ------------------------------------------------------------------------------------

ktx2_info parse_ktx2(std::span<const unsigned char> b, const std::string& name) {
    const auto bad = [&](const std::string& what) { return image_error(name, "invalid KTX2 file: " + what); };
    if (b.size() < header_bytes) throw bad("truncated header (" + std::to_string(b.size()) + " bytes)");
    if (std::memcmp(b.data(), ktx2_identifier, sizeof ktx2_identifier) != 0) throw bad("wrong identifier");
    ktx2_info k;
    k.vk_format = get32(b, 12);
    k.type_size = get32(b, 16);
    k.pixel_width = get32(b, 20);
    k.pixel_height = get32(b, 24);
    k.pixel_depth = get32(b, 28);
    k.layer_count = get32(b, 32);
    k.face_count = get32(b, 36);
    k.level_count = get32(b, 40);
    k.supercompression = get32(b, 44);
    k.dfd_offset = get32(b, 48);
    k.dfd_length = get32(b, 52);
    k.kvd_offset = get32(b, 56);
    k.kvd_length = get32(b, 60);
    k.sgd_offset = get64(b, 64);
    k.sgd_length = get64(b, 72);
    const std::uint64_t n = b.size();
    const std::uint32_t levels = k.level_count == 0 ? 1 : k.level_count;
    if (levels > 32) throw bad("levelCount " + std::to_string(k.level_count) + " > 32");
    if (header_bytes + level_entry_bytes * levels > n) throw bad("truncated level index");
    const auto in_bounds = [&](std::uint64_t off, std::uint64_t len) { return off <= n && len <= n - off; };
    if (!in_bounds(k.dfd_offset, k.dfd_length) || k.dfd_length < 4 || k.dfd_offset % 4 || k.dfd_length % 4)
        throw bad("data format descriptor out of bounds or misaligned");
    if (!in_bounds(k.kvd_offset, k.kvd_length)) throw bad("key/value data out of bounds");
    if (!in_bounds(k.sgd_offset, k.sgd_length)) throw bad("supercompression global data out of bounds");
    for (std::uint32_t l = 0; l < levels; ++l) {
        const std::size_t at = header_bytes + level_entry_bytes * l;
        ktx2_level lv{get64(b, at), get64(b, at + 8), get64(b, at + 16)};
        if (!in_bounds(lv.byte_offset, lv.byte_length)) throw bad("level " + std::to_string(l) + " out of bounds");
        k.levels.push_back(lv);
    }
    for (std::uint32_t i = 0; i < k.dfd_length / 4; ++i) k.dfd.push_back(get32(b, k.dfd_offset + 4 * i));
    if (k.dfd[0] != k.dfd_length) throw bad("dfdTotalSize differs from dfdByteLength");
    // Key/value pairs: {u32 length, key\0value, padding to 4}.
    std::uint64_t p = k.kvd_offset;
    const std::uint64_t kv_end = std::uint64_t(k.kvd_offset) + k.kvd_length;
    while (p + 4 <= kv_end) {
        const std::uint32_t len = get32(b, std::size_t(p));
        if (len > kv_end - p - 4) throw bad("key/value entry overruns the key/value data");
        const char* s = reinterpret_cast<const char*>(b.data() + p + 4);
        const std::string_view entry(s, len);
        const std::size_t nul = entry.find('\0');
        if (nul == std::string_view::npos) throw bad("key without terminating NUL");
        std::string value(entry.substr(nul + 1));
        if (!value.empty() && value.back() == '\0') value.pop_back();
        k.key_values.emplace_back(std::string(entry.substr(0, nul)), value);
        p = align_up(std::size_t(p + 4 + len), 4);
    }
    return k;
}

namespace {
/// Unpacks one cubemap level of a texel format (6 faces of s x s) into faces.
void decode_texels(ktx2_format fmt, std::span<const unsigned char> level, std::size_t s, std::array<std::vector<float>, 6>& faces) {
    const std::size_t tb = texel_bytes(fmt);
    std::size_t at = 0;
    for (std::size_t f = 0; f < 6; ++f)
        for (std::size_t t = 0; t < s * s; ++t, at += tb) {
            float* out = faces[f].data() + 3 * t;
            switch (fmt) {
            case ktx2_format::rgba32f:
                for (std::size_t ch = 0; ch < 3; ++ch) out[ch] = std::bit_cast<float>(get32(level, at + 4 * ch));
                break;
            case ktx2_format::rgba16f:
                for (std::size_t ch = 0; ch < 3; ++ch)
                    out[ch] = half_to_float(static_cast<std::uint16_t>(level[at + 2 * ch] | (level[at + 2 * ch + 1] << 8)));
                break;
            case ktx2_format::b10g11r11: unpack_b10g11r11(get32(level, at), out); break;
            case ktx2_format::e5b9g9r9: unpack_e5b9g9r9(get32(level, at), out); break;
            default: break;
            }
        }
}
} // namespace

namespace {
/// The layers of a cubemap (array = false: a single cubemap, layerCount 0) or a cubemap array
/// (array = true: layerCount 1..ktx2_max_array_layers).
std::vector<cubemap_rgb32f> decode_layers(std::span<const unsigned char> b, const std::string& name, bool array) {
    const ktx2_info k = parse_ktx2(b, name);
    const auto bad = [&](const std::string& what) { return image_error(name, "unsupported KTX2 cubemap: " + what); };
    if (!known_format(k.vk_format))
        throw bad("vkFormat " + std::to_string(k.vk_format) +
                  " (readable: 109 R32G32B32A32_SFLOAT, 97 R16G16B16A16_SFLOAT, 122 B10G11R11_UFLOAT_PACK32, "
                  "123 E5B9G9R9_UFLOAT_PACK32, 143 BC6H_UFLOAT_BLOCK, 1000066000 ASTC_4x4_SFLOAT_BLOCK, "
                  "1000066004 ASTC_6x6_SFLOAT_BLOCK)");
    const ktx2_format fmt = ktx2_format(k.vk_format);
    const std::size_t tb = texel_bytes(fmt);
    const bool zstd = k.supercompression == ktx2_ss_zstd;
    if (k.supercompression != 0 && !zstd)
        throw bad("supercompression scheme " + std::to_string(k.supercompression) + " (readable: 0 none, 2 Zstandard)");
    if (!array && (k.face_count != 6 || k.layer_count != 0 || k.pixel_depth != 0)) throw bad("not a single cubemap");
    if (array && (k.face_count != 6 || k.pixel_depth != 0)) throw bad("not a cubemap array (faceCount " + std::to_string(k.face_count) + ")");
    if (array && (k.layer_count < 1 || k.layer_count > ktx2_max_array_layers))
        throw bad("layerCount " + std::to_string(k.layer_count) + " (a cubemap array has 1.." + std::to_string(ktx2_max_array_layers) + ")");
    const std::size_t layers = array ? k.layer_count : 1;
    if (k.pixel_width != k.pixel_height || k.pixel_width < 1 || k.pixel_width > 65536) throw bad("faces not square");
    const std::uint32_t want_type_size = type_size(fmt);
    if (k.type_size != want_type_size)
        throw bad("typeSize " + std::to_string(k.type_size) + " for vkFormat " + std::to_string(k.vk_format) +
                  " (expected " + std::to_string(want_type_size) + ")");
    if (k.dfd.size() < 7 || (k.dfd[5] & 0xffu) != tb)
        throw bad("data format descriptor's bytesPlane0 differs from the " + std::to_string(tb) + "-byte " +
                  (ktx2_block_compressed(fmt) ? "block" : "texel") + " of vkFormat " + std::to_string(k.vk_format));
    if (int(k.levels.size()) > full_chain(int(k.pixel_width))) throw bad("more levels than the face size allows");
    // Every level's size inflated, bounded before anything is allocated.
    std::uint64_t total = 0;
    for (std::size_t l = 0; l < k.levels.size(); ++l) {
        const std::size_t s = std::max<std::size_t>(1, std::size_t(k.pixel_width) >> l);
        total += (level_bytes(fmt, s) + 6 * s * s * 12) * layers; // the stored level and its floats
        if (total > max_inflated_bytes) break;
    }
    if (total > max_inflated_bytes) throw bad("the decoded cubemap would take more than 2 GiB");
    std::vector<cubemap_rgb32f> out(layers, cubemap_rgb32f::zeros(int(k.pixel_width), int(k.levels.size())));
    std::vector<unsigned char> inflated;
    for (std::size_t l = 0; l < k.levels.size(); ++l) {
        const std::size_t s = std::size_t(out[0].face_size(int(l)));
        const std::size_t one = level_bytes(fmt, s), want = one * layers;
        std::span<const unsigned char> level;
        if (zstd) {
            if (k.levels[l].uncompressed_byte_length != want)
                throw bad("level " + std::to_string(l) + " inflates to " + std::to_string(k.levels[l].uncompressed_byte_length) +
                          " bytes, expected " + std::to_string(want));
            const unsigned char* src = b.data() + k.levels[l].byte_offset;
            const std::size_t len = std::size_t(k.levels[l].byte_length);
            const unsigned long long content = ZSTD_getFrameContentSize(src, len);
            if (content != want) throw bad("level " + std::to_string(l) + " is not one Zstandard frame of " + std::to_string(want) + " bytes");
            inflated.assign(want, 0);
            const std::size_t got = ZSTD_decompress(inflated.data(), want, src, len);
            if (ZSTD_isError(got) || got != want)
                throw bad("level " + std::to_string(l) + ": Zstandard data corrupt (" +
                          (ZSTD_isError(got) ? std::string(ZSTD_getErrorName(got)) : std::to_string(got) + " bytes") + ")");
            level = std::span<const unsigned char>(inflated);
        } else {
            if (k.levels[l].byte_length != want || k.levels[l].byte_offset % tb)
                throw bad("level " + std::to_string(l) + " has the wrong size or alignment");
            level = b.subspan(std::size_t(k.levels[l].byte_offset), want);
        }
        for (std::size_t layer = 0; layer < layers; ++layer) {
            cubemap_rgb32f& c = out[layer];
            const std::span<const unsigned char> part = level.subspan(layer * one, one);
            if (ktx2_block_compressed(fmt)) {
                const std::size_t fb = block_image_bytes(fmt, int(s));
                for (std::size_t f = 0; f < 6; ++f) c.levels[l][f] = decode_block_image(fmt, part.data() + f * fb, fb, int(s));
                continue;
            }
            decode_texels(fmt, part, s, c.levels[l]);
        }
    }
    return out;
}
} // namespace

cubemap_rgb32f decode_ktx2_cubemap(std::span<const unsigned char> b, const std::string& name) {
    return std::move(decode_layers(b, name, false).front());
}

std::vector<cubemap_rgb32f> decode_ktx2_cubemap_array(std::span<const unsigned char> b, const std::string& name) {
    return decode_layers(b, name, true);
}


// ---- quantisation report -----------------------------------------------------------------------

std::vector<ktx2_quantisation_level> ktx2_quantisation_report(const cubemap_rgb32f& cube, ktx2_format format,
                                                             const cubemap_rgb32f* decoded) {
    check_cube(cube, "<quantisation report>");
    cubemap_rgb32f own;
    if (ktx2_block_compressed(format) && !decoded) {
        own = decode_ktx2_cubemap(encode_ktx2_cubemap(cube, format, "report"), "<quantisation report>");
        decoded = &own;
    }
    std::vector<ktx2_quantisation_level> out;
    for (std::size_t l = 0; l < cube.levels.size(); ++l) {
        ktx2_quantisation_level q;
        q.level = int(l);
        q.face_size = cube.face_size(int(l));
        double sum = 0.0;
        std::size_t finite = 0;
        for (const auto& face : cube.levels[l])
            for (float x : face)
                if (std::isfinite(x)) {
                    sum += std::fabs(double(x));
                    ++finite;
                }
        const double mean = finite ? sum / double(finite) : 0.0;
        q.floor = mean > 0.0 ? 1e-3 * mean : 1e-30;
        double sq = 0.0;
        ktx2_clamp_counts seen;
        for (std::size_t f = 0; f < 6; ++f)
            for (std::size_t t = 0; t < cube.levels[l][f].size() / 3; ++t) {
                const float* in = cube.levels[l][f].data() + 3 * t;
                float dec[3];
                if (decoded)
                    for (int c = 0; c < 3; ++c) dec[c] = decoded->levels[l][f][3 * t + std::size_t(c)];
                else ktx2_roundtrip_texel(format, in, dec);
                count_clamps(format, in, seen);
                for (int c = 0; c < 3; ++c) {
                    if (std::isnan(in[c])) continue;
                    double rel;
                    if (std::isinf(in[c]))
                        rel = std::isinf(dec[c]) && (dec[c] > 0) == (in[c] > 0) ? 0.0 : 1.0; // clamped infinity: 100 %
                    else
                        rel = std::fabs(double(dec[c]) - double(in[c])) / std::max(std::fabs(double(in[c])), q.floor);
                    q.max_rel_error = std::max(q.max_rel_error, rel);
                    sq += rel * rel;
                    ++q.values;
                }
            }
        q.rms_rel_error = q.values ? std::sqrt(sq / double(q.values)) : 0.0;
        q.above_range = seen.above_range;
        q.negative_clamped = seen.negative;
        q.nan = seen.nan;
        out.push_back(q);
    }
    return out;
}

} // namespace ibl_bake
