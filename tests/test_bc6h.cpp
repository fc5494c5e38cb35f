// bake/bc6h: the BC6H_UFLOAT decoder against blocks built bit by bit from the specification's
// tables (Khronos Data Format Specification 1.3, "BC6H": the per-bit interpretation tables of the
// modes, the two-subset partition and anchor tables, the 3- and 4-bit weights, unquantize and
// finish_unquantize), and the encoder's round trips, input policy, quality ordering and image API.
#include <doctest/doctest.h>

#include <ibl/bake/bc6h.hpp>
#include <ibl/core/executor.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <utility>
#include <vector>

namespace {

// ---- the specification's arithmetic, written out for the expected values ----------------------

/// Unsigned unquantization of an endpoint of `bits` bits.
int spec_unquantize(int e, int bits) {
    if (bits >= 15) return e;
    if (e == 0) return 0;
    if (e == (1 << bits) - 1) return 0xFFFF;
    return ((e << 15) + 0x4000) >> (bits - 1);
}

constexpr int spec_w3[8] = {0, 9, 18, 27, 37, 46, 55, 64};
constexpr int spec_w4[16] = {0, 4, 9, 13, 17, 21, 26, 30, 34, 38, 43, 47, 51, 55, 60, 64};

/// The half pattern of one channel: interpolation of the unquantized endpoints, then (i * 31) >> 6.
std::uint16_t spec_texel(int u0, int u1, int weight) {
    const int i = ((64 - weight) * u0 + weight * u1 + 32) >> 6;
    return std::uint16_t((i * 31) >> 6);
}

/// A 128-bit block written at explicit bit positions (bit p is bit p % 8 of byte p / 8).
struct block_bits {
    unsigned char b[16] = {};
    int written = 0;
    /// Bits [pos, pos + n) from the low bits of v, LSB first.
    void put(int pos, int n, unsigned v) {
        for (int i = 0; i < n; ++i)
            if ((v >> i) & 1u) b[(pos + i) / 8] |= static_cast<unsigned char>(1u << ((pos + i) % 8));
        written += n;
    }
    /// One bit: bit `bit` of v at position pos.
    void put1(int pos, unsigned v, int bit) { put(pos, 1, (v >> bit) & 1u); }
};

void decode(const block_bits& bits, std::uint16_t out[16][3]) { ibl::bc6h_decode_block_half(bits.b, out); }

// ---- deterministic content ---------------------------------------------------------------------

struct rng {
    std::uint64_t s;
    std::uint64_t next() {
        std::uint64_t z = (s += 0x9E3779B97F4A7C15ull);
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        return z ^ (z >> 31);
    }
    float uniform() { return float(next() >> 40) * 0x1p-24f; } // [0, 1)
};

/// The error the encoder minimises: sum over texels and channels of (ln(1 + decoded) - ln(1 + x))^2,
/// x through the input policy.
double block_error(const float in[16][3], const unsigned char block[16]) {
    float out[16][3];
    ibl::bc6h_decode_block(block, out);
    double e = 0;
    for (int t = 0; t < 16; ++t)
        for (int c = 0; c < 3; ++c) {
            const float x = in[t][c] > 0.f ? std::min(in[t][c], 65504.f) : 0.f;
            const double d = std::log1p(double(out[t][c])) - std::log1p(double(x));
            e += d * d;
        }
    return e;
}

double block_rmsle(const float in[16][3], const unsigned char block[16]) {
    return std::sqrt(block_error(in, block) / 48.0);
}

/// Synthetic HDR image: a log-space gradient over 2^-6 .. 2^12 with a tint, multiplicative noise
/// (+-20% shared, +-5% per channel) and bright spots (x 1e3 .. 1e4, at most 6e4).
std::vector<float> hdr_image(int w, int h, std::uint64_t seed) {
    rng r{seed};
    const float tint[3] = {0.6f + 0.4f * r.uniform(), 0.6f + 0.4f * r.uniform(), 0.6f + 0.4f * r.uniform()};
    std::vector<float> img(std::size_t(w) * std::size_t(h) * 3);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const float g = std::exp2(-6.f + 18.f * float(x + 2 * y) / float(w + 2 * h));
            const float shared = 0.8f + 0.4f * r.uniform();
            for (int c = 0; c < 3; ++c)
                img[(std::size_t(y) * std::size_t(w) + std::size_t(x)) * 3 + std::size_t(c)] =
                    g * tint[c] * shared * (0.95f + 0.1f * r.uniform());
        }
    for (int k = 0; k < w * h / 40 + 1; ++k) {
        const std::size_t i = std::size_t(r.next() % std::uint64_t(w * h)) * 3;
        const float gain = std::pow(10.f, 3.f + r.uniform());
        for (int c = 0; c < 3; ++c) img[i + std::size_t(c)] = std::min(img[i + std::size_t(c)] * gain, 60000.f);
    }
    return img;
}

/// A random-ish HDR block of one of six kinds: smooth gradient, two regions, noise, a sun texel
/// 1e4 x the rest, a diagonal ramp over 1e-3 .. 6e4, values drawn log-uniformly over 1e-3 .. 6e4.
void hdr_block(rng& r, int kind, float out[16][3]) {
    const float level = std::exp2(-8.f + 20.f * r.uniform());
    const float tint[3] = {0.3f + r.uniform(), 0.3f + r.uniform(), 0.3f + r.uniform()};
    for (int t = 0; t < 16; ++t) {
        const float x = float(t % 4) / 3.f, y = float(t / 4) / 3.f;
        for (int c = 0; c < 3; ++c) {
            float v = level * tint[c];
            switch (kind) {
            case 0: v *= std::exp2(2.f * (x - y) + float(c) * 0.3f * x); break;
            case 1: v *= (x + y > 1.f) ? 8.f * tint[(c + 1) % 3] : 1.f; break;
            case 2: v *= 0.5f + r.uniform(); break;
            case 3: v *= (t == 5) ? 1e4f : 1.f + 0.1f * x; break;
            case 4: v = 1e-3f * std::pow(6e7f, (x + y) / 2.f) * (1.f + 0.2f * float(c)); break;
            default: v = std::exp2(std::log2(1e-3f) + (std::log2(6e4f) - std::log2(1e-3f)) * r.uniform()); break;
            }
            out[t][c] = std::min(v, 60000.f);
        }
    }
}

/// Nearest half pattern (its position rounded; exact for representable values).
int half_bits_of(float x) {
    if (x < 0x1p-14f) return int(std::lround(x * 0x1p24f));
    int e = 0;
    const float m = std::frexp(x, &e); // x = m 2^e, m in [0.5, 1)
    return int(std::lround(float((e - 1 + 15) * 1024) + (2.f * m - 1.f) * 1024.f));
}

float half_value(int h) {
    const int e = h >> 10, m = h & 1023;
    return e == 0 ? float(m) * 0x1p-24f : std::ldexp(1.f + float(m) / 1024.f, e - 15);
}

} // namespace

// =================================================================================================
// Decoder
// =================================================================================================

TEST_CASE("bc6h decode: mode 11 (one subset, raw 10-bit endpoints, 4-bit indices)") {
    // Per-bit table, mode 00011: M 0..4; R0 5..14, G0 15..24, B0 25..34, R1 35..44, G1 45..54,
    // B1 55..64; index of texel 0 in 3 bits at 65, the others 4 bits each from 68.
    const int r0 = 0, g0 = 512, b0 = 1, r1 = 1023, g1 = 256, b1 = 1022;
    block_bits bits;
    bits.put(0, 5, 0b00011);
    bits.put(5, 10, r0), bits.put(15, 10, g0), bits.put(25, 10, b0);
    bits.put(35, 10, r1), bits.put(45, 10, g1), bits.put(55, 10, b1);
    bits.put(65, 3, 0);
    for (int t = 1; t < 16; ++t) bits.put(68 + 4 * (t - 1), 4, unsigned(t)); // texel t: index t
    REQUIRE(bits.written == 128);
    std::uint16_t out[16][3];
    decode(bits, out);
    for (int t = 0; t < 16; ++t) {
        CHECK(out[t][0] == spec_texel(spec_unquantize(r0, 10), spec_unquantize(r1, 10), spec_w4[t]));
        CHECK(out[t][1] == spec_texel(spec_unquantize(g0, 10), spec_unquantize(g1, 10), spec_w4[t]));
        CHECK(out[t][2] == spec_texel(spec_unquantize(b0, 10), spec_unquantize(b1, 10), spec_w4[t]));
    }
    // By hand: R0 = 0 and R1 = 1023 unquantize to 0 and 0xFFFF; texel 15 (weight 64) gives
    // i = 65535 and (65535 * 31) >> 6 = 0x7BFF = 65504. Texel 8 (weight 34):
    // i = (34 * 65535 + 32) >> 6 = 34815, (34815 * 31) >> 6 = 16863.
    CHECK(out[15][0] == 0x7BFF);
    CHECK(out[8][0] == 16863);
    // G0 = 512 -> ((512 << 15) + 0x4000) >> 9 = 32800, half (32800 * 31) >> 6 = 15887 at texel 0.
    CHECK(out[0][1] == 15887);
    // B0 = 1 -> 96, (96 * 31) >> 6 = 46.
    CHECK(out[0][2] == 46);
}

TEST_CASE("bc6h decode: mode 14 (16-bit base, 4-bit deltas stored with reversed high bits, wrap-around)") {
    // Per-bit table, mode 01111: R0^0..9 at 5..14, G0 15..24, B0 25..34; R1 (delta) 35..38 and
    // R0^15, R0^14, ..., R0^10 at 39..44; G1 45..48, G0^15..10 at 49..54; B1 55..58, B0^15..10 at
    // 59..64 (the high bits of the base come MSB first).
    const int r0 = 0x8000, g0 = 0x1234, b0 = 0xFFFF;
    const int dr = -1, dg = 7, db = 1; // B1 = (0xFFFF + 1) mod 2^16 = 0
    block_bits bits;
    bits.put(0, 5, 0b01111);
    bits.put(5, 10, r0 & 1023), bits.put(15, 10, g0 & 1023), bits.put(25, 10, b0 & 1023);
    const int base[3] = {r0, g0, b0}, delta[3] = {dr, dg, db};
    for (int c = 0; c < 3; ++c) {
        bits.put(35 + 10 * c, 4, unsigned(delta[c]) & 15u);
        for (int k = 0; k < 6; ++k) bits.put1(39 + 10 * c + k, unsigned(base[c]), 15 - k);
    }
    bits.put(65, 3, 7); // texel 0: the largest 3-bit index
    for (int t = 1; t < 16; ++t) bits.put(68 + 4 * (t - 1), 4, unsigned(15 - t));
    REQUIRE(bits.written == 128);
    std::uint16_t out[16][3];
    decode(bits, out);
    for (int t = 0; t < 16; ++t) {
        const int idx = t == 0 ? 7 : 15 - t;
        for (int c = 0; c < 3; ++c) {
            const int e1 = (base[c] + delta[c]) & 0xFFFF;
            CHECK(out[t][c] == spec_texel(base[c], e1, spec_w4[idx]));
        }
    }
    // By hand, texel 0 (index 7, weight 30): R interpolates 0x8000 .. 0x7FFF to 32768 (half 15872
    // = 1.5); B interpolates 0xFFFF .. 0 (the wrapped endpoint) to (34 * 65535 + 32) >> 6 = 34815,
    // half 16863.
    CHECK(out[0][0] == 15872);
    CHECK(out[0][2] == 16863);
    CHECK(out[1][2] == 1984); // index 14 (weight 60): i = (4 * 65535 + 32) >> 6 = 4096
}

TEST_CASE("bc6h decode: mode 13 (12-bit base, 8-bit deltas, two reversed high bits)") {
    // Per-bit table, mode 01011: R0^0..9 5..14, G0 15..24, B0 25..34; R1 35..42, then R0^11 at 43
    // and R0^10 at 44; G1 45..52, G0^11 53, G0^10 54; B1 55..62, B0^11 63, B0^10 64.
    const int base[3] = {0xABC, 0x800, 4095};
    const int delta[3] = {-128, 127, 5}; // B: (4095 + 5) mod 4096 = 4
    block_bits bits;
    bits.put(0, 5, 0b01011);
    for (int c = 0; c < 3; ++c) bits.put(5 + 10 * c, 10, unsigned(base[c]) & 1023u);
    for (int c = 0; c < 3; ++c) {
        bits.put(35 + 10 * c, 8, unsigned(delta[c]) & 255u);
        bits.put1(43 + 10 * c, unsigned(base[c]), 11);
        bits.put1(44 + 10 * c, unsigned(base[c]), 10);
    }
    bits.put(65, 3, 5);
    for (int t = 1; t < 16; ++t) bits.put(68 + 4 * (t - 1), 4, unsigned(t * 7 % 16));
    REQUIRE(bits.written == 128);
    std::uint16_t out[16][3];
    decode(bits, out);
    for (int t = 0; t < 16; ++t) {
        const int idx = t == 0 ? 5 : t * 7 % 16;
        for (int c = 0; c < 3; ++c) {
            const int e1 = (base[c] + delta[c]) & 4095;
            CHECK(out[t][c] == spec_texel(spec_unquantize(base[c], 12), spec_unquantize(e1, 12), spec_w4[idx]));
        }
    }
    // By hand: 12-bit codes unquantize to 16 e + 8 inside the range: 0xABC -> 43976, 2620 -> 41928;
    // B: 4095 -> 0xFFFF (the top code), 4 -> 72.
    CHECK(spec_unquantize(0xABC, 12) == 43976);
    CHECK(out[0][2] == spec_texel(0xFFFF, 72, spec_w4[5]));
}

TEST_CASE("bc6h decode: mode 1 (two subsets, 10-bit base, 5-bit signed deltas, anchor after a subset-1 texel)") {
    // Per-bit table, mode 00: G2^4 2, B2^4 3, B3^4 4; R0 5..14, G0 15..24, B0 25..34; R1 35..39,
    // G3^4 40, G2^0..3 41..44, G1 45..49, B3^0 50, G3^0..3 51..54, B1 55..59, B3^1 60, B2^0..3
    // 61..64, R2 65..69, B3^2 70, R3 71..75, B3^3 76, partition 77..81; indices from 82.
    const int e0[3] = {100, 200, 300};
    const int d[3][3] = {{15, -16, 1}, {-1, 5, -7}, {8, -8, 0}}; // E1, E2, E3 - E0
    auto v = [&](int k, int c) { return unsigned(d[k - 1][c]) & 31u; };
    const int partition = 17; // texels 1, 2, 3, 7 in subset 1; its anchor is texel 2
    block_bits bits;
    bits.put(0, 2, 0b00);
    bits.put1(2, v(2, 1), 4), bits.put1(3, v(2, 2), 4), bits.put1(4, v(3, 2), 4);
    bits.put(5, 10, unsigned(e0[0])), bits.put(15, 10, unsigned(e0[1])), bits.put(25, 10, unsigned(e0[2]));
    bits.put(35, 5, v(1, 0)), bits.put1(40, v(3, 1), 4), bits.put(41, 4, v(2, 1)), bits.put(45, 5, v(1, 1));
    bits.put1(50, v(3, 2), 0), bits.put(51, 4, v(3, 1)), bits.put(55, 5, v(1, 2)), bits.put1(60, v(3, 2), 1);
    bits.put(61, 4, v(2, 2)), bits.put(65, 5, v(2, 0)), bits.put1(70, v(3, 2), 2), bits.put(71, 5, v(3, 0));
    bits.put1(76, v(3, 2), 3), bits.put(77, 5, unsigned(partition));
    const int idx[16] = {0, 1, 2, 3, 4, 5, 6, 7, 0, 1, 2, 3, 4, 5, 6, 7};
    int pos = 82;
    for (int t = 0; t < 16; ++t) {
        const int n = (t == 0 || t == 2) ? 2 : 3; // texel 1 (subset 1, not the anchor) keeps 3 bits
        bits.put(pos, n, unsigned(idx[t]));
        pos += n;
    }
    REQUIRE(pos == 128);
    REQUIRE(bits.written == 128);
    std::uint16_t out[16][3];
    decode(bits, out);
    const unsigned subset1 = (1u << 1) | (1u << 2) | (1u << 3) | (1u << 7);
    for (int t = 0; t < 16; ++t) {
        const int s = (subset1 >> t) & 1u ? 1 : 0;
        for (int c = 0; c < 3; ++c) {
            const int a = s == 0 ? e0[c] : e0[c] + d[1][c], b = s == 0 ? e0[c] + d[0][c] : e0[c] + d[2][c];
            CHECK(out[t][c] == spec_texel(spec_unquantize(a, 10), spec_unquantize(b, 10), spec_w3[idx[t]]));
        }
    }
    // By hand, texel 0 (subset 0, index 0): R0 = 100 -> ((100 << 15) + 0x4000) >> 9 = 6432, half
    // (6432 * 31) >> 6 = 3115.
    CHECK(out[0][0] == 3115);
}

TEST_CASE("bc6h decode: mode 2 (two subsets, 7-bit base, 6-bit deltas, scattered bits)") {
    // Per-bit table, mode 01: G2^5 2, G3^4 3, G3^5 4, R0 5..11, B3^0 12, B3^1 13, B2^4 14,
    // G0 15..21, B2^5 22, B3^2 23, G2^4 24, B0 25..31, B3^3 32, B3^5 33, B3^4 34, R1 35..40,
    // G2^0..3 41..44, G1 45..50, G3^0..3 51..54, B1 55..60, B2^0..3 61..64, R2 65..70,
    // R3 71..76, partition 77..81.
    const int e0[3] = {64, 1, 126};
    const int d[3][3] = {{-32, 31, 1}, {10, -5, -30}, {0, 20, 31}};
    auto v = [&](int k, int c) { return unsigned(d[k - 1][c]) & 63u; };
    block_bits bits;
    bits.put(0, 2, 0b01);
    bits.put1(2, v(2, 1), 5), bits.put1(3, v(3, 1), 4), bits.put1(4, v(3, 1), 5);
    bits.put(5, 7, unsigned(e0[0])), bits.put1(12, v(3, 2), 0), bits.put1(13, v(3, 2), 1), bits.put1(14, v(2, 2), 4);
    bits.put(15, 7, unsigned(e0[1])), bits.put1(22, v(2, 2), 5), bits.put1(23, v(3, 2), 2), bits.put1(24, v(2, 1), 4);
    bits.put(25, 7, unsigned(e0[2])), bits.put1(32, v(3, 2), 3), bits.put1(33, v(3, 2), 5), bits.put1(34, v(3, 2), 4);
    bits.put(35, 6, v(1, 0)), bits.put(41, 4, v(2, 1)), bits.put(45, 6, v(1, 1)), bits.put(51, 4, v(3, 1));
    bits.put(55, 6, v(1, 2)), bits.put(61, 4, v(2, 2)), bits.put(65, 6, v(2, 0)), bits.put(71, 6, v(3, 0));
    bits.put(77, 5, 0); // partition 0: columns 2 and 3 are subset 1, anchor texel 15
    const int idx[16] = {3, 7, 0, 5, 6, 1, 2, 4, 7, 7, 0, 1, 2, 3, 4, 3};
    int pos = 82;
    for (int t = 0; t < 16; ++t) {
        const int n = (t == 0 || t == 15) ? 2 : 3;
        bits.put(pos, n, unsigned(idx[t]));
        pos += n;
    }
    REQUIRE(bits.written == 128);
    std::uint16_t out[16][3];
    decode(bits, out);
    for (int t = 0; t < 16; ++t) {
        const int s = (t % 4) >= 2 ? 1 : 0;
        for (int c = 0; c < 3; ++c) {
            const int a = s == 0 ? e0[c] : (e0[c] + d[1][c]) & 127, b = (e0[c] + d[s == 0 ? 0 : 2][c]) & 127;
            CHECK(out[t][c] == spec_texel(spec_unquantize(a, 7), spec_unquantize(b, 7), spec_w3[idx[t]]));
        }
    }
    // By hand: subset 0 blue runs from 126 (-> 126 * 512 + 256 = 64768) to 127 = the top code
    // (-> 0xFFFF); subset 1 green from (1 - 5) mod 128 = 124 to 21.
    CHECK(out[2][2] == spec_texel(spec_unquantize(126 - 30, 7), spec_unquantize((126 + 31) & 127, 7), 0));
    CHECK(out[1][2] == spec_texel(64768, 0xFFFF, 64));
}

TEST_CASE("bc6h decode: mode 10 (two subsets, raw 6-bit endpoints, scattered bits)") {
    // Per-bit table, mode 11110: R0 5..10, G3^4 11, B3^0 12, B3^1 13, B2^4 14, G0 15..20, G2^5 21,
    // B2^5 22, B3^2 23, G2^4 24, B0 25..30, G3^5 31, B3^3 32, B3^5 33, B3^4 34, R1 35..40,
    // G2^0..3 41..44, G1 45..50, G3^0..3 51..54, B1 55..60, B2^0..3 61..64, R2 65..70, R3 71..76,
    // partition 77..81.
    const int e[4][3] = {{0, 63, 1}, {63, 0, 62}, {21, 42, 5}, {42, 21, 58}};
    auto u = [&](int k, int c) { return unsigned(e[k][c]); };
    block_bits bits;
    bits.put(0, 5, 0b11110);
    bits.put(5, 6, u(0, 0)), bits.put1(11, u(3, 1), 4), bits.put1(12, u(3, 2), 0), bits.put1(13, u(3, 2), 1);
    bits.put1(14, u(2, 2), 4), bits.put(15, 6, u(0, 1)), bits.put1(21, u(2, 1), 5), bits.put1(22, u(2, 2), 5);
    bits.put1(23, u(3, 2), 2), bits.put1(24, u(2, 1), 4), bits.put(25, 6, u(0, 2)), bits.put1(31, u(3, 1), 5);
    bits.put1(32, u(3, 2), 3), bits.put1(33, u(3, 2), 5), bits.put1(34, u(3, 2), 4), bits.put(35, 6, u(1, 0));
    bits.put(41, 4, u(2, 1)), bits.put(45, 6, u(1, 1)), bits.put(51, 4, u(3, 1)), bits.put(55, 6, u(1, 2));
    bits.put(61, 4, u(2, 2)), bits.put(65, 6, u(2, 0)), bits.put(71, 6, u(3, 0));
    const int partition = 30; // 0x718E: texels 1, 2, 3, 7, 8, 12, 13, 14 in subset 1; anchor 2
    bits.put(77, 5, unsigned(partition));
    const int idx[16] = {0, 7, 3, 5, 1, 6, 2, 4, 7, 0, 3, 5, 6, 1, 2, 4};
    int pos = 82;
    for (int t = 0; t < 16; ++t) {
        const int n = (t == 0 || t == 2) ? 2 : 3;
        bits.put(pos, n, unsigned(idx[t]));
        pos += n;
    }
    REQUIRE(bits.written == 128);
    std::uint16_t out[16][3];
    decode(bits, out);
    const unsigned subset1 = 0x718E;
    for (int t = 0; t < 16; ++t) {
        const int s = int((subset1 >> t) & 1u);
        for (int c = 0; c < 3; ++c) {
            const int u0 = spec_unquantize(e[2 * s][c], 6), u1 = spec_unquantize(e[2 * s + 1][c], 6);
            CHECK(out[t][c] == spec_texel(u0, u1, spec_w3[idx[t]]));
        }
    }
    // By hand: 6-bit codes unquantize to 1024 e + 512 inside the range; texel 0 (subset 0, index 0)
    // is R 0, G 0xFFFF -> 0x7BFF, B 1536 -> (1536 * 31) >> 6 = 744.
    CHECK(out[0][0] == 0);
    CHECK(out[0][1] == 0x7BFF);
    CHECK(out[0][2] == 744);
}

TEST_CASE("bc6h decode: one random block per mode against an independent decode of the specification") {
    // Blocks of random bits with each mode's code; expected: an implementation of the
    // specification's per-bit tables written apart from this library (and checked against a third
    // decoder on 5400 random blocks): texels 0, 7, 15 and an FNV-1a hash of all 48 half patterns
    // (each fed low byte first, texels in order, R G B).
    struct golden {
        int mode;
        std::array<unsigned char, 16> bytes;
        std::array<std::uint16_t, 9> texels; // t0 RGB, t7 RGB, t15 RGB
        std::uint32_t hash;
    };
    const golden cases[] = {
        {1, {0x84, 0xDD, 0x57, 0x78, 0x6E, 0x49, 0x84, 0x2E, 0x5C, 0x87, 0x6F, 0xBA, 0x3C, 0xEE, 0x0E, 0x94},
         {23373, 5466, 25644, 23637, 5068, 25714, 23436, 5476, 25629}, 0xC158E75C},
        {2, {0x25, 0xA6, 0xC2, 0x4D, 0xC4, 0x6B, 0x40, 0x33, 0xA6, 0xFA, 0x25, 0xE3, 0x1E, 0x45, 0x38, 0xB9},
         {11997, 1468, 8641, 11129, 1794, 5820, 14895, 22777, 5556}, 0x064F32CA},
        {3, {0xC2, 0x90, 0xFB, 0x68, 0xC1, 0xFA, 0xD8, 0xC1, 0x63, 0x0A, 0x74, 0xB7, 0x2B, 0x4E, 0x35, 0xC2},
         {2067, 7819, 2804, 1852, 7757, 2766, 1872, 7744, 2805}, 0xE7A7B262},
        {4, {0x46, 0x88, 0xE5, 0x43, 0x00, 0x84, 0x7E, 0x88, 0xD6, 0x3D, 0xC3, 0x3E, 0xA8, 0x95, 0xDA, 0xA2},
         {1030, 30930, 16391, 1030, 30770, 16391, 1030, 30796, 16391}, 0xC0330A4D},
        {5, {0x6A, 0x59, 0x05, 0xD0, 0x56, 0xD7, 0x38, 0xBC, 0xE7, 0xAD, 0x90, 0x7F, 0x37, 0x0A, 0xAB, 0x5A},
         {11090, 162, 29395, 11136, 85, 29349, 11119, 111, 29334}, 0x354C331F},
        {6, {0x0E, 0x98, 0x76, 0x6A, 0xE2, 0x0D, 0xFF, 0x86, 0x36, 0x6C, 0x4E, 0xBA, 0x2A, 0x53, 0x9B, 0x9D},
         {11830, 14515, 19529, 11598, 15035, 19410, 11791, 14438, 19654}, 0xF14508E8},
        {7, {0x72, 0x87, 0x97, 0xF6, 0x4A, 0x2E, 0xD7, 0x37, 0x7B, 0x4E, 0x3D, 0x4F, 0x64, 0x90, 0x38, 0x8B},
         {7848, 5523, 16098, 7546, 6810, 16534, 8087, 6862, 16639}, 0x34556E05},
        {8, {0x16, 0x43, 0x3D, 0xB4, 0xA5, 0x84, 0x8A, 0x54, 0x4B, 0x2B, 0xF4, 0x84, 0x18, 0xB6, 0x1D, 0x13},
         {2828, 15538, 27250, 3658, 15438, 26350, 3658, 15438, 26350}, 0x28C091FD},
        {9, {0x1A, 0x6A, 0x3A, 0xBB, 0x77, 0x5F, 0x3D, 0xC6, 0x11, 0xEC, 0xE9, 0xFF, 0xA4, 0x7F, 0xFA, 0xDD},
         {10470, 14794, 27884, 11473, 15511, 28744, 10137, 13903, 28936}, 0xD2D35998},
        {10, {0x9E, 0x70, 0xD5, 0x34, 0x84, 0xE3, 0x70, 0xB0, 0xBE, 0xC8, 0xA9, 0xC0, 0x9F, 0xC1, 0x49, 0xBA},
         {8370, 16197, 13981, 9656, 6285, 13748, 13671, 2557, 22351}, 0xA2F352CA},
        {11, {0xE3, 0xCA, 0xF1, 0x77, 0xD8, 0x36, 0xB7, 0xEC, 0x4C, 0x4F, 0x83, 0xB5, 0xD3, 0x79, 0xDD, 0xD4},
         {20246, 23883, 7058, 21589, 18248, 11269, 22101, 16101, 12873}, 0x8E527111},
        {12, {0x87, 0x47, 0x35, 0xDF, 0x7A, 0x96, 0x0B, 0xA7, 0x1B, 0xAB, 0xFB, 0x25, 0xBD, 0x7A, 0x17, 0x88},
         {25798, 10054, 20662, 25197, 9787, 21180, 26450, 10344, 20102}, 0x892CA4A5},
        {13, {0xCB, 0xAD, 0x6D, 0x36, 0x00, 0xEE, 0x11, 0xDE, 0x83, 0xF6, 0x72, 0x69, 0x22, 0xED, 0xAC, 0xFA},
         {18681, 1646, 23988, 18510, 1345, 23807, 18216, 825, 23494}, 0xDAC88DF9},
        {14, {0x0F, 0xE0, 0xF8, 0x0E, 0x1C, 0xE0, 0x4B, 0xC5, 0xCB, 0x38, 0x75, 0x59, 0x80, 0x97, 0xF0, 0xA0},
         {372, 20576, 3722, 372, 20576, 3722, 372, 20576, 3721}, 0xF0570DD2},
    };
    for (const golden& g : cases) {
        CAPTURE(g.mode);
        std::uint16_t out[16][3];
        ibl::bc6h_decode_block_half(g.bytes.data(), out);
        const int texels[3] = {0, 7, 15};
        for (int i = 0; i < 3; ++i)
            for (int c = 0; c < 3; ++c) CHECK(out[texels[i]][c] == g.texels[std::size_t(3 * i + c)]);
        std::uint32_t h = 0x811C9DC5u;
        for (int t = 0; t < 16; ++t)
            for (int c = 0; c < 3; ++c)
                for (unsigned byte : {unsigned(out[t][c]) & 255u, unsigned(out[t][c]) >> 8})
                    h = (h ^ byte) * 0x01000193u;
        CHECK(h == g.hash);
    }
}

TEST_CASE("bc6h decode: reserved mode codes decode to 0; every other code is a mode") {
    rng r{7};
    for (unsigned code : {0x13u, 0x17u, 0x1Bu, 0x1Fu}) {
        for (int k = 0; k < 8; ++k) {
            unsigned char b[16];
            for (auto& x : b) x = static_cast<unsigned char>(r.next());
            b[0] = static_cast<unsigned char>((b[0] & ~31u) | code);
            std::uint16_t out[16][3];
            ibl::bc6h_decode_block_half(b, out);
            for (int t = 0; t < 16; ++t)
                for (int c = 0; c < 3; ++c) CHECK(out[t][c] == 0);
        }
    }
    // A valid mode with an all-ones payload is not mistaken for a reserved one: mode 11 with every
    // endpoint at its top code decodes to 65504 everywhere.
    unsigned char ones[16];
    std::memset(ones, 0xFF, sizeof ones);
    ones[0] = static_cast<unsigned char>((0xFFu & ~31u) | 0x03u);
    float out[16][3];
    ibl::bc6h_decode_block(ones, out);
    for (int t = 0; t < 16; ++t)
        for (int c = 0; c < 3; ++c) CHECK(out[t][c] == 65504.f);
}

TEST_CASE("bc6h decode: constant blocks and the float output") {
    SUBCASE("mode 14 with equal endpoints returns the endpoint's finish_unquantize exactly") {
        for (int e : {0, 1, 2, 0x4000, 0x7C00, 0x8421, 0xFFFE, 0xFFFF}) {
            block_bits bits;
            bits.put(0, 5, 0b01111);
            for (int c = 0; c < 3; ++c) {
                bits.put(5 + 10 * c, 10, unsigned(e) & 1023u);
                for (int k = 0; k < 6; ++k) bits.put1(39 + 10 * c + k, unsigned(e), 15 - k);
            }
            std::uint16_t h[16][3];
            float f[16][3];
            ibl::bc6h_decode_block_half(bits.b, h);
            ibl::bc6h_decode_block(bits.b, f);
            const int expected = (e * 31) >> 6;
            for (int t = 0; t < 16; ++t)
                for (int c = 0; c < 3; ++c) {
                    CHECK(h[t][c] == expected);
                    CHECK(f[t][c] == half_value(expected)); // exact: every half is a float
                }
        }
    }
    SUBCASE("the float of the largest and the smallest patterns") {
        CHECK(half_value(0x7BFF) == 65504.f);
        block_bits bits; // mode 14, R0 = 3: (3 * 31) >> 6 = 1, the smallest subnormal 2^-24
        bits.put(0, 5, 0b01111);
        bits.put(5, 10, 3);
        float f[16][3];
        ibl::bc6h_decode_block(bits.b, f);
        CHECK(f[0][0] == 0x1p-24f);
        CHECK(f[0][1] == 0.f);
    }
}

// =================================================================================================
// Encoder
// =================================================================================================

TEST_CASE("bc6h encode: constant blocks of many magnitudes") {
    const ibl::bc6h_quality qualities[] = {ibl::bc6h_quality::fast, ibl::bc6h_quality::normal,
                                           ibl::bc6h_quality::exhaustive};
    SUBCASE("representable values come back exactly") {
        // A constant block is coded with equal 16-bit endpoints e = round((h + 1/2) 64 / 31), and
        // floor(31 e / 64) = h for every half pattern h (or by a mode at least as close).
        for (int h : {0, 1, 7, 1023, 1024, 0x3C00, 0x3C01, 0x5A5A, 0x7BFE, 0x7BFF}) {
            float in[16][3];
            for (auto& t : in) t[0] = half_value(h), t[1] = half_value(std::max(h - 1, 0)), t[2] = half_value(h / 2);
            for (auto q : qualities) {
                unsigned char b[16];
                ibl::bc6h_encode_block(in, b, q);
                float out[16][3];
                ibl::bc6h_decode_block(b, out);
                for (int t = 0; t < 16; ++t)
                    for (int c = 0; c < 3; ++c) CHECK(out[t][c] == in[t][c]);
            }
        }
    }
    SUBCASE("other values land within one half step") {
        rng r{11};
        for (int k = 0; k < 40; ++k) {
            const float v[3] = {std::exp2(-20.f + 35.5f * r.uniform()), std::exp2(-20.f + 35.5f * r.uniform()),
                                std::exp2(-20.f + 35.5f * r.uniform())};
            float in[16][3];
            for (auto& t : in) t[0] = v[0], t[1] = v[1], t[2] = v[2];
            for (auto q : {ibl::bc6h_quality::fast, ibl::bc6h_quality::normal}) {
                unsigned char b[16];
                ibl::bc6h_encode_block(in, b, q);
                std::uint16_t out[16][3];
                ibl::bc6h_decode_block_half(b, out);
                // Tolerance: the 16-bit endpoint step is 31/64 of a half step, so the decoded
                // pattern is one of the two around the value.
                for (int t = 0; t < 16; ++t)
                    for (int c = 0; c < 3; ++c) CHECK(std::abs(int(out[t][c]) - half_bits_of(v[c])) <= 1);
            }
        }
    }
}

TEST_CASE("bc6h encode: input policy (NaN, negatives, infinities, above 65504)") {
    const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
    auto constant = [](float v, ibl::bc6h_quality q) {
        float in[16][3];
        for (auto& t : in) t[0] = t[1] = t[2] = v;
        unsigned char b[16];
        ibl::bc6h_encode_block(in, b, q);
        std::uint16_t out[16][3];
        ibl::bc6h_decode_block_half(b, out);
        return out[9][1];
    };
    for (auto q : {ibl::bc6h_quality::fast, ibl::bc6h_quality::normal}) {
        CHECK(constant(nan, q) == 0);
        CHECK(constant(-1.f, q) == 0);
        CHECK(constant(-inf, q) == 0);
        CHECK(constant(-0.f, q) == 0);
        CHECK(constant(inf, q) == 0x7BFF);
        CHECK(constant(1e6f, q) == 0x7BFF);
        CHECK(constant(65504.f, q) == 0x7BFF);
        CHECK(constant(65519.f, q) == 0x7BFF); // rounds to infinity as a half; clamped instead
    }
    SUBCASE("mixed: each special value encodes exactly as its replacement") {
        float in[16][3], replaced[16][3];
        for (int t = 0; t < 16; ++t)
            for (int c = 0; c < 3; ++c) in[t][c] = replaced[t][c] = 1.f + 0.05f * float(t);
        in[3][0] = nan, in[5][1] = -3.f, in[9][2] = inf, in[12][0] = 3e5f, in[14][1] = -inf;
        replaced[3][0] = 0.f, replaced[5][1] = 0.f, replaced[14][1] = 0.f;
        replaced[9][2] = 65504.f, replaced[12][0] = 65504.f;
        for (auto q : {ibl::bc6h_quality::fast, ibl::bc6h_quality::normal}) {
            unsigned char a[16], b[16];
            ibl::bc6h_encode_block(in, a, q);
            ibl::bc6h_encode_block(replaced, b, q);
            CHECK(std::memcmp(a, b, 16) == 0);
        }
    }
}

TEST_CASE("bc6h encode: smooth gradients and HDR content") {
    SUBCASE("a smooth gradient over one octave is nearly lossless") {
        // A tinted ramp c_k (1 + s), s = (x + y) / 6 in [0, 1]: a line in the log-like domain the
        // format interpolates in.
        float in[16][3];
        for (int t = 0; t < 16; ++t) {
            const float s = float(t % 4 + t / 4) / 6.f;
            in[t][0] = 2.f * (1.f + s), in[t][1] = 1.5f * (1.f + s), in[t][2] = 0.8f * (1.f + s);
        }
        // Bounds: 1.5 x the measured RMSLE (fast 0.0120, normal 0.0097). The 4-bit indices step
        // by 1/15 of the octave (4.7%); the ramp's 7 values fall between steps by up to half of
        // one, which is most of the error.
        unsigned char b[16];
        ibl::bc6h_encode_block(in, b, ibl::bc6h_quality::fast);
        CHECK(block_rmsle(in, b) < 0.018);
        ibl::bc6h_encode_block(in, b, ibl::bc6h_quality::normal);
        CHECK(block_rmsle(in, b) < 0.015);
    }
    SUBCASE("a 1e-3 .. 6e4 range and a sun texel 1e4 x the rest") {
        rng r{5};
        for (int kind : {3, 4}) {
            double fast = 0, normal = 0;
            for (int k = 0; k < 16; ++k) {
                float in[16][3];
                hdr_block(r, kind, in);
                unsigned char b[16];
                ibl::bc6h_encode_block(in, b, ibl::bc6h_quality::fast);
                fast += block_error(in, b);
                ibl::bc6h_encode_block(in, b, ibl::bc6h_quality::normal);
                normal += block_error(in, b);
                // Every block decodes near its input, even where no delta mode reaches.
                CHECK(block_rmsle(in, b) < 0.2);
            }
            CAPTURE(kind);
            // Bounds: 1.5 x the measured aggregate RMSLE of the 16 blocks (sun: fast 0.0238,
            // normal 0.0235, the +-5% ramp of the sky texels on the one index the sun leaves
            // them; ramp over 26 octaves: fast 0.175 with 16 indices on one line, normal 0.060
            // with two subsets).
            CHECK(std::sqrt(normal / (16 * 48)) < (kind == 3 ? 0.035 : 0.09));
            CHECK(std::sqrt(fast / (16 * 48)) < (kind == 3 ? 0.036 : 0.26));
        }
    }
    SUBCASE("a synthetic HDR image") {
        const int n = 32;
        const std::vector<float> img = hdr_image(n, n, 3);
        for (auto q : {ibl::bc6h_quality::fast, ibl::bc6h_quality::normal}) {
            const std::vector<unsigned char> blocks = ibl::bc6h_encode_image(img.data(), n, n, q);
            const std::vector<float> dec = ibl::bc6h_decode_image(blocks.data(), n, n);
            // Bound: 1.5 x the measured RMSLE (fast 0.068, normal 0.049); the texel noise (+-20%
            // shared, +-5% per channel) is what a 4 x 4 block cannot follow.
            CHECK(ibl::bc6h_rmsle(img.data(), dec.data(), dec.size()) < (q == ibl::bc6h_quality::fast ? 0.10 : 0.075));
        }
    }
}

TEST_CASE("bc6h encode: exhaustive <= normal <= fast, block by block") {
    // Each level runs the one before it (normal repeats fast's mode with more refits, exhaustive
    // starts from normal's block) and keeps the better block, so the order holds per block in the
    // encoder's error. Tolerance: this test's error uses log1p of the inputs, the encoder a linear
    // interpolation of log1p between half patterns (within 1.2e-7 per value).
    rng r{99};
    int blocks = 0;
    double sum[3] = {0, 0, 0};
    for (int kind = 0; kind < 6; ++kind)
        for (int k = 0; k < 6; ++k) {
            float in[16][3];
            hdr_block(r, kind, in);
            double e[3];
            int i = 0;
            for (auto q : {ibl::bc6h_quality::fast, ibl::bc6h_quality::normal, ibl::bc6h_quality::exhaustive}) {
                unsigned char b[16];
                ibl::bc6h_encode_block(in, b, q);
                e[i] = block_error(in, b);
                sum[i] += e[i];
                ++i;
            }
            CAPTURE(kind);
            CHECK(e[1] <= e[0] * (1 + 1e-4) + 1e-9);
            CHECK(e[2] <= e[1] * (1 + 1e-4) + 1e-9);
            ++blocks;
        }
    CHECK(sum[2] < sum[1]); // and exhaustive finds something on this set
    CHECK(sum[1] < sum[0]);
}

TEST_CASE("bc6h encode: normal within 10% of exhaustive on synthetic HDR images") {
    // Three 24 x 24 images (108 blocks) of gradients, noise and bright spots. Measured: normal /
    // exhaustive RMSLE = 1.053 (on 64 x 64 crops of the real environments of tests/data and of a
    // textured sky: 1.01 - 1.03).
    double err[2] = {0, 0};
    std::size_t count = 0;
    for (std::uint64_t seed : {21u, 22u, 23u}) {
        const int n = 24;
        const std::vector<float> img = hdr_image(n, n, seed);
        int i = 0;
        for (auto q : {ibl::bc6h_quality::normal, ibl::bc6h_quality::exhaustive}) {
            const std::vector<unsigned char> blocks = ibl::bc6h_encode_image(img.data(), n, n, q);
            const std::vector<float> dec = ibl::bc6h_decode_image(blocks.data(), n, n);
            const double r = ibl::bc6h_rmsle(img.data(), dec.data(), dec.size());
            err[i++] += r * r * double(dec.size());
        }
        count += std::size_t(n * n * 3);
    }
    const double normal = std::sqrt(err[0] / double(count)), exhaustive = std::sqrt(err[1] / double(count));
    CAPTURE(normal);
    CAPTURE(exhaustive);
    CHECK(exhaustive <= normal);
    CHECK(normal <= 1.10 * exhaustive);
}

TEST_CASE("bc6h encode: weights") {
    SUBCASE("weight-0 texels do not pull the fit") {
        float in[16][3], clean[16][3], w[16];
        for (int t = 0; t < 16; ++t) {
            for (int c = 0; c < 3; ++c) clean[t][c] = in[t][c] = 1.f + 0.1f * float(t % 4) + 0.05f * float(c);
            w[t] = (t % 4 == 3) ? 0.f : 1.f; // the last column is padding: outliers either way
            if (w[t] == 0.f) in[t][0] = in[t][1] = in[t][2] = 50000.f, clean[t][0] = clean[t][1] = clean[t][2] = 1e-3f;
        }
        unsigned char with[16], without[16];
        ibl::bc6h_encode_block(in, with, ibl::bc6h_quality::normal, w);
        ibl::bc6h_encode_block(clean, without, ibl::bc6h_quality::normal, w);
        float a[16][3], b[16][3];
        ibl::bc6h_decode_block(with, a);
        ibl::bc6h_decode_block(without, b);
        for (int t = 0; t < 16; ++t)
            if (w[t] > 0.f) // 1%: about the index step over this ramp
                for (int c = 0; c < 3; ++c) CHECK(a[t][c] == doctest::Approx(clean[t][c]).epsilon(0.01));
        CHECK(std::memcmp(with, without, 16) == 0); // the padding's values do not matter at all
    }
    SUBCASE("all-zero weights encode as if all were 1") {
        float in[16][3], zero[16] = {};
        rng r{3};
        hdr_block(r, 0, in);
        unsigned char a[16], b[16];
        ibl::bc6h_encode_block(in, a, ibl::bc6h_quality::fast, zero);
        ibl::bc6h_encode_block(in, b, ibl::bc6h_quality::fast);
        CHECK(std::memcmp(a, b, 16) == 0);
    }
}

// =================================================================================================
// Image API
// =================================================================================================

TEST_CASE("bc6h image: partial edge blocks, sizes 1x1 .. 13x7") {
    const std::pair<int, int> sizes[] = {{1, 1}, {2, 2}, {3, 5}, {4, 4}, {5, 7}, {13, 7}};
    for (const auto& size : sizes) {
        const int w = size.first, h = size.second;
        CAPTURE(w);
        CAPTURE(h);
        const std::vector<float> img = hdr_image(w, h, std::uint64_t(w * 100 + h));
        const std::vector<unsigned char> blocks = ibl::bc6h_encode_image(img.data(), w, h, ibl::bc6h_quality::normal);
        const int bw = (w + 3) / 4, bh = (h + 3) / 4;
        REQUIRE(blocks.size() == std::size_t(bw * bh * 16));
        const std::vector<float> dec = ibl::bc6h_decode_image(blocks.data(), w, h);
        REQUIRE(dec.size() == img.size());
        CHECK(ibl::bc6h_rmsle(img.data(), dec.data(), dec.size()) < 0.1);
        // The last block is bc6h_encode_block of its texels, the outside ones repeating the edge
        // with weight 0.
        const int bx = bw - 1, by = bh - 1;
        float texels[16][3], weights[16];
        for (int t = 0; t < 16; ++t) {
            const int x = bx * 4 + t % 4, y = by * 4 + t / 4;
            weights[t] = (x < w && y < h) ? 1.f : 0.f;
            const std::size_t src =
                (std::size_t(std::min(y, h - 1)) * std::size_t(w) + std::size_t(std::min(x, w - 1))) * 3;
            for (int c = 0; c < 3; ++c) texels[t][c] = img[src + std::size_t(c)];
        }
        unsigned char expected[16];
        const bool partial = (w % 4) != 0 || (h % 4) != 0;
        ibl::bc6h_encode_block(texels, expected, ibl::bc6h_quality::normal, partial ? weights : nullptr);
        CHECK(std::memcmp(expected, blocks.data() + std::size_t(by * bw + bx) * 16, 16) == 0);
    }
}

TEST_CASE("bc6h image: the bytes do not depend on the executor") {
    const int w = 37, h = 21;
    const std::vector<float> img = hdr_image(w, h, 77);
    for (auto q : {ibl::bc6h_quality::fast, ibl::bc6h_quality::normal}) {
        const std::vector<unsigned char> serial = ibl::bc6h_encode_image(img.data(), w, h, q);
        const std::vector<unsigned char> threads = ibl::bc6h_encode_image(img.data(), w, h, q, ibl::thread_executor{2});
        const std::vector<unsigned char> many = ibl::bc6h_encode_image(img.data(), w, h, q, ibl::thread_executor{7});
        CHECK(serial == threads);
        CHECK(serial == many);
    }
}

TEST_CASE("bc6h image: argument checks") {
    const float px[3] = {1, 1, 1};
    const unsigned char block[16] = {};
    CHECK_THROWS_AS((void)ibl::bc6h_encode_image(px, 0, 1, ibl::bc6h_quality::fast), std::invalid_argument);
    CHECK_THROWS_AS((void)ibl::bc6h_encode_image(px, 1, -2, ibl::bc6h_quality::fast), std::invalid_argument);
    CHECK_THROWS_AS((void)ibl::bc6h_encode_image(nullptr, 1, 1, ibl::bc6h_quality::fast), std::invalid_argument);
    CHECK_THROWS_AS((void)ibl::bc6h_encode_image(px, 70000, 1, ibl::bc6h_quality::fast), std::length_error);
    CHECK_THROWS_AS((void)ibl::bc6h_decode_image(block, 1, 0), std::invalid_argument);
    CHECK_THROWS_AS((void)ibl::bc6h_decode_image(nullptr, 1, 1), std::invalid_argument);
    CHECK_THROWS_AS((void)ibl::bc6h_decode_image(block, 40000, 40000), std::length_error);
}
