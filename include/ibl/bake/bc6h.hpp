#pragma once
// ibl/bake/bc6h.hpp — BC6H_UFLOAT (unsigned half-float) block compression: a decoder bit-exact to
// the format's specification and an encoder with three quality levels (host only).
//
// Format (Khronos Data Format Specification 1.3, "BC6H"; Microsoft, "BC6H Format"). A 16-byte
// block holds a 4 x 4 tile of RGB texels, texel t = 4 y + x. Its low 2 bits (values 0, 1) or low 5
// bits select one of 14 modes; modes are numbered 1..14 here as in Microsoft's table:
//     mode  code   subsets  endpoint bits  delta bits (R, G, B)  index bits
//     1     00     2        10             5, 5, 5               3
//     2     01     2         7             6, 6, 6               3
//     3     00010  2        11             5, 4, 4               3
//     4     00110  2        11             4, 5, 4               3
//     5     01010  2        11             4, 4, 5               3
//     6     01110  2         9             5, 5, 5               3
//     7     10010  2         8             6, 5, 5               3
//     8     10110  2         8             5, 6, 5               3
//     9     11010  2         8             5, 5, 6               3
//     10    11110  2         6             (raw endpoints)       3
//     11    00011  1        10             (raw endpoints)       4
//     12    00111  1        11             9, 9, 9               4
//     13    01011  1        12             8, 8, 8               4
//     14    01111  1        16             4, 4, 4               4
// Codes 10011, 10111, 11011 and 11111 are reserved: such a block decodes to (0, 0, 0).
// Two-subset modes carry a 5-bit partition number selecting one of the first 32 two-subset
// partitions of BPTC. Transformed ("delta") modes store endpoint 0 in full and the other endpoints
// as two's-complement offsets from it, added modulo 2^(endpoint bits). Each endpoint channel e of
// b bits is unquantized to 16 bits, U(e) = 0 for e = 0, 0xFFFF for e = 2^b - 1, otherwise
// ((e << 15) + 0x4000) >> (b - 1) (b = 16: U = e); a texel with index k interpolates
// i = ((64 - w_k) U_0 + w_k U_1 + 32) >> 6 with the BPTC weights w_k of its index width, and the
// result is the half-float whose bit pattern is (31 i) >> 6, a value in [0, 65504]. The first texel
// of each subset in the partition's anchor table (texel 0 for subset 0) stores its index with one
// bit less (the top bit is 0).
//
// The encoder works in that interpolation domain: the target of an input value x is
// T(x) = (h(x) + 1/2) 64 / 31, where h(x) is the position of x on the half-float bit-pattern axis
// (continuous: the bit pattern for representable values, linear between them), so a decoded i
// near T(x) returns the half nearest to x. The bit pattern of a half grows like 1024 log2(x), so
// this domain is close to logarithmic and suits HDR content.
//
// Error (what the encoder minimises, and bc6h_rmsle reports): the squared difference of
// ln(1 + x) per channel, summed over texels with their weights; bc6h_rmsle is the root of its
// mean over values (RMSLE). It weighs relative error for values well above 1 and absolute error
// below 1, the measure of an HDR environment's radiance that a renderer integrates. The encoder
// evaluates it exactly through a table of ln(1 + half) over all 31744 finite half patterns (the
// input's own value by linear interpolation in that table), and fits endpoints by least squares in
// the interpolation domain weighted by (d ln(1 + x) / dT)^2, the same error to first order.
//
// Input policy: NaN and negative values encode as 0; values above 65504 (the largest finite half)
// and +inf encode as 65504. Texel weights (optional) are >= 0; a NaN, infinite or negative weight
// counts as 0, and a block whose weights are all 0 is encoded as if they were all 1. Weight 0 marks
// a texel the encoder may ignore (padding outside the image): its value changes nothing.
//
// Encoder. A candidate is a mode and a partition with endpoints in the interpolation domain; its
// evaluation quantizes the endpoints to the mode (nearest code; in a transformed mode every
// endpoint clamped into the reach of endpoint 0's offsets, so the block is always valid), chooses
// each texel's index by the exact error, refits the endpoints by least squares on those indices,
// and repeats while the quantized endpoints change, up to a number of refits; the best pass counts.
// Starting endpoints: the extremes of each subset's texels along its principal axis, ordered so the
// subset's anchor texel lies in the half nearer endpoint 0 (its index is searched only in the
// lower half of the palette). Polishing: coordinate descent of +-1 code on every quantized endpoint
// channel while the error falls. Per level:
//   fast        one subset: the finest of modes 14, 13, 12 whose offsets reach the starting
//               endpoints (else mode 11), two refits (a third moved RMSLE by < 1% on real
//               HDRIs for 15-25% more time). About 1.5 us a block on one core (x86-64, -O2
//               -march=native; bench/bench_bc6h.cpp); meant for probes compressed at run time.
//   normal      one subset: modes 14, 13, 12, 11 finest first while their offsets reach the
//               endpoints with a slack of 1.5, until one reaches without it (fast's mode is among
//               them); two subsets: the 4 partitions of lowest estimated error (for each subset the
//               scatter off its principal axis plus a uniform spread quantised to 8 levels along
//               it), on each the first 2 precision groups (11, 10, 9, 8, 7, 6 endpoint bits; in a
//               group the member whose widest offsets match the widest channel) that reach the same
//               way; three refits each; the 2 best candidates polished (2 rounds). About 30 us a
//               block.
//   exhaustive  normal's block, then every mode on every partition with six refits; the 8 best
//               candidates polished (8 rounds). About 0.5 ms a block: a reference.
// Each level's candidates include the one before it (normal repeats fast's mode with as many
// refits; exhaustive starts from normal's block) and polishing never raises an error, so
// exhaustive <= normal <= fast in the error above, block by block.
//
// Determinism: every block is encoded independently by the same operations, so
// bc6h_encode_image's bytes do not depend on the executor.

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include "../core/executor.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace ibl {

/// Encoder effort (see the header comment for what each level searches).
enum class bc6h_quality { fast, normal, exhaustive };

/// The largest finite UF16 value (half-float bit pattern 0x7BFF).
inline constexpr float bc6h_max_value = 65504.f;

namespace detail::bc6h {

// ---------------------------------------------------------------------------------------------
// The format's tables.

/// One mode: its code bits, subsets, endpoint precision and delta widths.
struct mode_desc {
    std::uint8_t code;     // value of the mode bits
    std::uint8_t header;   // number of mode bits (2 or 5)
    std::uint8_t subsets;  // 1 or 2
    std::uint8_t epb;      // endpoint bits
    std::uint8_t delta[3]; // bits of the stored offsets per channel (== epb when not transformed)
    bool transformed;
};

inline constexpr int mode_count = 14;
inline constexpr int first_single = 10; // modes 11..14 (indices 10..13) have one subset

inline constexpr mode_desc modes[mode_count] = {
    {0x00, 2, 2, 10, {5, 5, 5}, true},     {0x01, 2, 2, 7, {6, 6, 6}, true},
    {0x02, 5, 2, 11, {5, 4, 4}, true},     {0x06, 5, 2, 11, {4, 5, 4}, true},
    {0x0A, 5, 2, 11, {4, 4, 5}, true},     {0x0E, 5, 2, 9, {5, 5, 5}, true},
    {0x12, 5, 2, 8, {6, 5, 5}, true},      {0x16, 5, 2, 8, {5, 6, 5}, true},
    {0x1A, 5, 2, 8, {5, 5, 6}, true},      {0x1E, 5, 2, 6, {6, 6, 6}, false},
    {0x03, 5, 1, 10, {10, 10, 10}, false}, {0x07, 5, 1, 11, {9, 9, 9}, true},
    {0x0B, 5, 1, 12, {8, 8, 8}, true},     {0x0F, 5, 1, 16, {4, 4, 4}, true},
};

/// Mode index (0..13) of a block's low 5 bits, or -1 for the reserved codes.
constexpr int mode_of_bits(unsigned low5) noexcept {
    if ((low5 & 2u) == 0) return int(low5 & 1u); // codes 00 and 01: the low two bits alone
    for (int m = 2; m < mode_count; ++m)
        if (modes[m].code == (low5 & 31u)) return m;
    return -1;
}

/// Fields of the endpoint and partition data: endpoint k channel c is field 3 k + c.
enum field : std::uint8_t { r0, g0, b0, r1, g1, b1, r2, g2, b2, r3, g3, b3, pb, field_count };

/// The specification's v^{hi..lo}: the next (hi - lo + 1) block bits, the first one into bit lo
/// of field v, the following ones towards bit hi (hi < lo: the bits are stored reversed).
struct segment {
    field f;
    std::uint8_t hi, lo;
};

/// For each block bit below the index data: field * 16 + bit of field (0xFF: a mode bit).
struct bit_map {
    std::array<std::uint8_t, 82> bits{};
    int end = 0; // first bit after the header, endpoints and partition (82 or 65)
};

constexpr bit_map make_map(int header, std::initializer_list<segment> segments) {
    bit_map m;
    for (int i = 0; i < header; ++i) m.bits[std::size_t(i)] = 0xFF;
    int pos = header;
    for (const segment& s : segments) {
        const int step = s.hi >= s.lo ? 1 : -1;
        for (int b = s.lo;; b += step) {
            m.bits[std::size_t(pos++)] = std::uint8_t(s.f * 16 + b);
            if (b == s.hi) break;
        }
    }
    m.end = pos;
    return m;
}

// Block descriptions of the specification (LSB first, after the mode bits).
inline constexpr bit_map maps[mode_count] = {
    make_map(2, {{g2, 4, 4}, {b2, 4, 4}, {b3, 4, 4}, {r0, 9, 0}, {g0, 9, 0}, {b0, 9, 0}, {r1, 4, 0},
                 {g3, 4, 4}, {g2, 3, 0}, {g1, 4, 0}, {b3, 0, 0}, {g3, 3, 0}, {b1, 4, 0}, {b3, 1, 1},
                 {b2, 3, 0}, {r2, 4, 0}, {b3, 2, 2}, {r3, 4, 0}, {b3, 3, 3}, {pb, 4, 0}}),
    make_map(2, {{g2, 5, 5}, {g3, 4, 4}, {g3, 5, 5}, {r0, 6, 0}, {b3, 0, 0}, {b3, 1, 1}, {b2, 4, 4},
                 {g0, 6, 0}, {b2, 5, 5}, {b3, 2, 2}, {g2, 4, 4}, {b0, 6, 0}, {b3, 3, 3}, {b3, 5, 5},
                 {b3, 4, 4}, {r1, 5, 0}, {g2, 3, 0}, {g1, 5, 0}, {g3, 3, 0}, {b1, 5, 0}, {b2, 3, 0},
                 {r2, 5, 0}, {r3, 5, 0}, {pb, 4, 0}}),
    make_map(5, {{r0, 9, 0}, {g0, 9, 0}, {b0, 9, 0}, {r1, 4, 0}, {r0, 10, 10}, {g2, 3, 0}, {g1, 3, 0},
                 {g0, 10, 10}, {b3, 0, 0}, {g3, 3, 0}, {b1, 3, 0}, {b0, 10, 10}, {b3, 1, 1}, {b2, 3, 0},
                 {r2, 4, 0}, {b3, 2, 2}, {r3, 4, 0}, {b3, 3, 3}, {pb, 4, 0}}),
    make_map(5, {{r0, 9, 0}, {g0, 9, 0}, {b0, 9, 0}, {r1, 3, 0}, {r0, 10, 10}, {g3, 4, 4}, {g2, 3, 0},
                 {g1, 4, 0}, {g0, 10, 10}, {g3, 3, 0}, {b1, 3, 0}, {b0, 10, 10}, {b3, 1, 1}, {b2, 3, 0},
                 {r2, 3, 0}, {b3, 0, 0}, {b3, 2, 2}, {r3, 3, 0}, {g2, 4, 4}, {b3, 3, 3}, {pb, 4, 0}}),
    make_map(5, {{r0, 9, 0}, {g0, 9, 0}, {b0, 9, 0}, {r1, 3, 0}, {r0, 10, 10}, {b2, 4, 4}, {g2, 3, 0},
                 {g1, 3, 0}, {g0, 10, 10}, {b3, 0, 0}, {g3, 3, 0}, {b1, 4, 0}, {b0, 10, 10}, {b2, 3, 0},
                 {r2, 3, 0}, {b3, 1, 1}, {b3, 2, 2}, {r3, 3, 0}, {b3, 4, 4}, {b3, 3, 3}, {pb, 4, 0}}),
    make_map(5, {{r0, 8, 0}, {b2, 4, 4}, {g0, 8, 0}, {g2, 4, 4}, {b0, 8, 0}, {b3, 4, 4}, {r1, 4, 0},
                 {g3, 4, 4}, {g2, 3, 0}, {g1, 4, 0}, {b3, 0, 0}, {g3, 3, 0}, {b1, 4, 0}, {b3, 1, 1},
                 {b2, 3, 0}, {r2, 4, 0}, {b3, 2, 2}, {r3, 4, 0}, {b3, 3, 3}, {pb, 4, 0}}),
    make_map(5, {{r0, 7, 0}, {g3, 4, 4}, {b2, 4, 4}, {g0, 7, 0}, {b3, 2, 2}, {g2, 4, 4}, {b0, 7, 0},
                 {b3, 3, 3}, {b3, 4, 4}, {r1, 5, 0}, {g2, 3, 0}, {g1, 4, 0}, {b3, 0, 0}, {g3, 3, 0},
                 {b1, 4, 0}, {b3, 1, 1}, {b2, 3, 0}, {r2, 5, 0}, {r3, 5, 0}, {pb, 4, 0}}),
    make_map(5, {{r0, 7, 0}, {b3, 0, 0}, {b2, 4, 4}, {g0, 7, 0}, {g2, 5, 5}, {g2, 4, 4}, {b0, 7, 0},
                 {g3, 5, 5}, {b3, 4, 4}, {r1, 4, 0}, {g3, 4, 4}, {g2, 3, 0}, {g1, 5, 0}, {g3, 3, 0},
                 {b1, 4, 0}, {b3, 1, 1}, {b2, 3, 0}, {r2, 4, 0}, {b3, 2, 2}, {r3, 4, 0}, {b3, 3, 3},
                 {pb, 4, 0}}),
    make_map(5, {{r0, 7, 0}, {b3, 1, 1}, {b2, 4, 4}, {g0, 7, 0}, {b2, 5, 5}, {g2, 4, 4}, {b0, 7, 0},
                 {b3, 5, 5}, {b3, 4, 4}, {r1, 4, 0}, {g3, 4, 4}, {g2, 3, 0}, {g1, 4, 0}, {b3, 0, 0},
                 {g3, 3, 0}, {b1, 5, 0}, {b2, 3, 0}, {r2, 4, 0}, {b3, 2, 2}, {r3, 4, 0}, {b3, 3, 3},
                 {pb, 4, 0}}),
    make_map(5, {{r0, 5, 0}, {g3, 4, 4}, {b3, 0, 0}, {b3, 1, 1}, {b2, 4, 4}, {g0, 5, 0}, {g2, 5, 5},
                 {b2, 5, 5}, {b3, 2, 2}, {g2, 4, 4}, {b0, 5, 0}, {g3, 5, 5}, {b3, 3, 3}, {b3, 5, 5},
                 {b3, 4, 4}, {r1, 5, 0}, {g2, 3, 0}, {g1, 5, 0}, {g3, 3, 0}, {b1, 5, 0}, {b2, 3, 0},
                 {r2, 5, 0}, {r3, 5, 0}, {pb, 4, 0}}),
    make_map(5, {{r0, 9, 0}, {g0, 9, 0}, {b0, 9, 0}, {r1, 9, 0}, {g1, 9, 0}, {b1, 9, 0}}),
    make_map(5, {{r0, 9, 0}, {g0, 9, 0}, {b0, 9, 0}, {r1, 8, 0}, {r0, 10, 10}, {g1, 8, 0}, {g0, 10, 10},
                 {b1, 8, 0}, {b0, 10, 10}}),
    make_map(5, {{r0, 9, 0}, {g0, 9, 0}, {b0, 9, 0}, {r1, 7, 0}, {r0, 10, 11}, {g1, 7, 0}, {g0, 10, 11},
                 {b1, 7, 0}, {b0, 10, 11}}),
    make_map(5, {{r0, 9, 0}, {g0, 9, 0}, {b0, 9, 0}, {r1, 3, 0}, {r0, 10, 15}, {g1, 3, 0}, {g0, 10, 15},
                 {b1, 3, 0}, {b0, 10, 15}}),
};

/// Compile-time check of the maps against the mode table: each field bit below its width appears
/// exactly once, none above, and the data ends where the indices begin.
constexpr bool maps_match_modes() {
    for (int m = 0; m < mode_count; ++m) {
        const mode_desc& d = modes[m];
        if (maps[m].end != (d.subsets == 2 ? 82 : 65)) return false;
        int count[field_count][16] = {};
        for (int i = d.header; i < maps[m].end; ++i) {
            const int code = maps[m].bits[std::size_t(i)];
            if (code == 0xFF) return false;
            ++count[code >> 4][code & 15];
        }
        for (int f = 0; f < field_count; ++f) {
            int width = 0;
            if (f == pb) width = d.subsets == 2 ? 5 : 0;
            else if (f / 3 >= 2 * d.subsets) width = 0;
            else width = f < 3 ? d.epb : d.delta[f % 3];
            for (int b = 0; b < 16; ++b)
                if (count[f][b] != (b < width ? 1 : 0)) return false;
        }
    }
    return true;
}
static_assert(maps_match_modes(), "BC6H bit maps disagree with the mode table");

/// The first 32 two-subset BPTC partitions: bit t is the subset of texel t.
inline constexpr std::uint16_t partitions[32] = {
    0xCCCC, 0x8888, 0xEEEE, 0xECC8, 0xC880, 0xFEEC, 0xFEC8, 0xEC80, 0xC800, 0xFFEC, 0xFE80,
    0xE800, 0xFFE8, 0xFF00, 0xFFF0, 0xF000, 0xF710, 0x008E, 0x7100, 0x08CE, 0x008C, 0x7310,
    0x3100, 0x8CCE, 0x088C, 0x3110, 0x6666, 0x366C, 0x17E8, 0x0FF0, 0x718E, 0x399C};

/// Anchor texel of subset 1 per partition (subset 0's anchor is texel 0).
inline constexpr std::uint8_t anchors[32] = {15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15,
                                             15, 2,  8,  2,  2,  8,  8,  15, 2,  8,  2,  2,  8,  8,  2,  2};

/// BPTC interpolation weights (out of 64) of 3-bit and 4-bit indices.
inline constexpr int weights3[8] = {0, 9, 18, 27, 37, 46, 55, 64};
inline constexpr int weights4[16] = {0, 4, 9, 13, 17, 21, 26, 30, 34, 38, 43, 47, 51, 55, 60, 64};

// ---------------------------------------------------------------------------------------------
// Arithmetic of the format.

/// Unsigned unquantization of an endpoint channel of `epb` bits to 16 bits.
constexpr int unquantize(int e, int epb) noexcept {
    if (epb >= 15) return e;
    if (e == 0) return 0;
    if (e == (1 << epb) - 1) return 0xFFFF;
    return ((e << 15) + 0x4000) >> (epb - 1);
}

/// Interpolated 16-bit value -> half-float bit pattern in [0, 0x7BFF] (finish_unquantize).
constexpr int finish(int i) noexcept { return (i * 31) >> 6; }

constexpr int interpolate(int u0, int u1, int w) noexcept { return ((64 - w) * u0 + w * u1 + 32) >> 6; }

/// Two's-complement value of the low `bits` bits of v.
constexpr int sign_extend(int v, int bits) noexcept {
    const int m = 1 << (bits - 1);
    return ((v & ((1 << bits) - 1)) ^ m) - m;
}

/// Half-float bit pattern (0..0x7BFF, no sign) -> float, exactly.
inline float half_to_float(unsigned h) noexcept {
    const unsigned e = h >> 10, m = h & 1023u;
    if (e == 0) return float(m) * 0x1p-24f;
    return std::bit_cast<float>(((e + 112u) << 23) | (m << 13));
}

/// Input policy: NaN and negatives -> 0, above 65504 (and +inf) -> 65504.
inline float sanitize(float x) noexcept { return x > 0.f ? (x < bc6h_max_value ? x : bc6h_max_value) : 0.f; }

/// Continuous position of x in [0, 65504] on the half bit-pattern axis: the bit pattern for a
/// representable value, linear in x between consecutive ones.
inline float half_position(float x) noexcept {
    if (x < 0x1p-14f) return x * 0x1p24f; // subnormal halves: steps of 2^-24
    const std::uint32_t b = std::bit_cast<std::uint32_t>(x);
    const int e = int(b >> 23) - 127;
    return float((e + 15) * 1024) + float(b & 0x7FFFFFu) * 0x1p-13f;
}

/// ln(1 + x) of every finite half pattern 0..0x7BFF, and at 0x7C00 the value for 65536 (the end
/// of the last interval, for interpolation).
struct log_table {
    static constexpr int size = 0x7C01;
    float v[size];
    log_table() noexcept {
        for (int h = 0; h < 0x7C00; ++h) v[h] = float(std::log1p(double(half_to_float(unsigned(h)))));
        v[0x7C00] = float(std::log1p(65536.0));
    }
};

inline const float* log_of_half() noexcept {
    static const log_table table;
    return table.v;
}

// ---------------------------------------------------------------------------------------------
// Bits.

struct bits128 {
    std::uint64_t lo = 0, hi = 0;
};

inline bits128 load(const unsigned char* b) noexcept {
    bits128 v;
    for (int i = 7; i >= 0; --i) v.lo = (v.lo << 8) | b[i];
    for (int i = 15; i >= 8; --i) v.hi = (v.hi << 8) | b[i];
    return v;
}

inline void store(const bits128& v, unsigned char* b) noexcept {
    for (int i = 0; i < 8; ++i) b[i] = static_cast<unsigned char>(v.lo >> (8 * i));
    for (int i = 0; i < 8; ++i) b[8 + i] = static_cast<unsigned char>(v.hi >> (8 * i));
}

inline unsigned get_bits(const bits128& v, int pos, int n) noexcept {
    const std::uint64_t mask = (std::uint64_t(1) << n) - 1;
    if (pos >= 64) return unsigned((v.hi >> (pos - 64)) & mask);
    if (pos + n <= 64) return unsigned((v.lo >> pos) & mask);
    return unsigned(((v.lo >> pos) | (v.hi << (64 - pos))) & mask);
}

inline void put_bits(bits128& v, int pos, int n, unsigned value) noexcept {
    const std::uint64_t x = std::uint64_t(value) & ((std::uint64_t(1) << n) - 1);
    if (pos >= 64) {
        v.hi |= x << (pos - 64);
    } else {
        v.lo |= x << pos;
        if (pos + n > 64) v.hi |= x >> (64 - pos);
    }
}

/// Index bits of texel t: one less for the anchors (texel 0, and subset 1's anchor).
constexpr int index_bits(int subsets, int partition, int t) noexcept {
    const int bits = subsets == 2 ? 3 : 4;
    return (t == 0 || (subsets == 2 && t == anchors[partition])) ? bits - 1 : bits;
}

/// A block in unpacked form: mode, partition, absolute endpoints (endpoint k = 2 subset + end),
/// indices.
struct unpacked {
    int mode = 10;
    int partition = 0;
    int e[4][3] = {};
    std::uint8_t idx[16] = {};
};

/// Parses a block; false for a reserved mode. Endpoints come back absolute (deltas applied).
inline bool unpack(const unsigned char block[16], unpacked& u) noexcept {
    const bits128 v = load(block);
    const int m = mode_of_bits(unsigned(v.lo & 31u));
    if (m < 0) return false;
    const mode_desc& d = modes[m];
    const bit_map& map = maps[m];
    int f[field_count] = {};
    for (int i = d.header; i < map.end; ++i) {
        const int code = map.bits[std::size_t(i)];
        const int bit = int(((i < 64 ? v.lo >> i : v.hi >> (i - 64))) & 1u);
        f[code >> 4] |= bit << (code & 15);
    }
    u.mode = m;
    u.partition = d.subsets == 2 ? f[pb] : 0;
    const int mask = (1 << d.epb) - 1;
    for (int k = 0; k < 2 * d.subsets; ++k)
        for (int c = 0; c < 3; ++c) {
            const int x = f[3 * k + c];
            u.e[k][c] = (d.transformed && k > 0) ? (f[c] + sign_extend(x, d.delta[c])) & mask : x;
        }
    int pos = map.end;
    for (int t = 0; t < 16; ++t) {
        const int n = index_bits(d.subsets, u.partition, t);
        u.idx[t] = std::uint8_t(get_bits(v, pos, n));
        pos += n;
    }
    return true;
}

/// Writes an unpacked block (its endpoints must be representable in its mode, the anchors'
/// indices in their width).
inline void pack(const unpacked& u, unsigned char out[16]) noexcept {
    const mode_desc& d = modes[u.mode];
    const bit_map& map = maps[u.mode];
    int f[field_count] = {};
    for (int k = 0; k < 2 * d.subsets; ++k)
        for (int c = 0; c < 3; ++c)
            f[3 * k + c] =
                (d.transformed && k > 0) ? (u.e[k][c] - u.e[0][c]) & ((1 << d.delta[c]) - 1) : u.e[k][c];
    f[pb] = u.partition;
    bits128 v;
    put_bits(v, 0, d.header, d.code);
    for (int i = d.header; i < map.end; ++i) {
        const int code = map.bits[std::size_t(i)];
        put_bits(v, i, 1, unsigned(f[code >> 4] >> (code & 15)) & 1u);
    }
    int pos = map.end;
    for (int t = 0; t < 16; ++t) {
        const int n = index_bits(d.subsets, u.partition, t);
        put_bits(v, pos, n, u.idx[t]);
        pos += n;
    }
    store(v, out);
}

/// The half patterns of an unpacked block.
inline void decode_unpacked(const unpacked& u, std::uint16_t out[16][3]) noexcept {
    const mode_desc& d = modes[u.mode];
    const int n = d.subsets == 2 ? 8 : 16;
    const int* w = d.subsets == 2 ? weights3 : weights4;
    std::uint16_t pal[2][16][3];
    for (int s = 0; s < d.subsets; ++s)
        for (int c = 0; c < 3; ++c) {
            const int u0 = unquantize(u.e[2 * s][c], d.epb), u1 = unquantize(u.e[2 * s + 1][c], d.epb);
            for (int k = 0; k < n; ++k) pal[s][k][c] = std::uint16_t(finish(interpolate(u0, u1, w[k])));
        }
    const unsigned mask = d.subsets == 2 ? partitions[u.partition] : 0u;
    for (int t = 0; t < 16; ++t) {
        const std::uint16_t* v = pal[(mask >> t) & 1u][u.idx[t]];
        out[t][0] = v[0], out[t][1] = v[1], out[t][2] = v[2];
    }
}

// ---------------------------------------------------------------------------------------------
// Encoder.

inline constexpr float domain_max = 65535.f; // the 16-bit interpolation domain

/// A block's input as the encoder sees it.
struct prepared {
    float t[16][3];  // targets in the interpolation domain, T(x)
    float l[16][3];  // ln(1 + x)
    float om[16][3]; // least-squares weights: texel weight * (d ln(1 + x) / dT)^2, max 1
    float w[16];     // texel weights
    float ws[16];    // one weight per texel for the line fits: the mean of om over channels
};

inline void prepare(const float in[16][3], const float* weights, prepared& p) noexcept {
    const float* L = log_of_half();
    float total = 0.f;
    for (int t = 0; t < 16; ++t) {
        const float w = weights ? weights[t] : 1.f;
        p.w[t] = w > 0.f && w <= std::numeric_limits<float>::max() ? w : 0.f;
        total += p.w[t];
    }
    if (!(total > 0.f))
        for (float& w : p.w) w = 1.f;
    float om_max = 0.f;
    for (int t = 0; t < 16; ++t)
        for (int c = 0; c < 3; ++c) {
            const float h = half_position(sanitize(in[t][c]));
            const int h0 = std::min(int(h), 0x7BFF);
            const float slope = L[h0 + 1] - L[h0];
            p.t[t][c] = (h + 0.5f) * (64.f / 31.f);
            p.l[t][c] = L[h0] + (h - float(h0)) * slope;
            const float d = slope * (31.f / 64.f);
            p.om[t][c] = p.w[t] * d * d;
            om_max = std::max(om_max, p.om[t][c]);
        }
    const float scale = om_max > 0.f ? 1.f / om_max : 1.f;
    for (int t = 0; t < 16; ++t) {
        for (float& o : p.om[t]) o *= scale;
        p.ws[t] = (p.om[t][0] + p.om[t][1] + p.om[t][2]) * (1.f / 3.f);
    }
}

/// Endpoints of the subsets in the interpolation domain: ends[s][0] maps to index 0.
struct float_ends {
    float v[2][2][3] = {};
};

/// An encoding candidate: its block and its error (sum of texel weight * squared ln(1 + x)
/// difference).
struct candidate {
    unpacked block;
    float err = std::numeric_limits<float>::infinity();
};

/// Nearest endpoint code of `epb` bits for a target u in [0, 65535] of the interpolation domain.
/// Inside the range U(e) = floor((e + 1/2) step) with step = 2^(16 - epb) (and U = 0, 65535 at
/// the ends), so with e = floor(u / step) the nearest code is e - 1 or e when u < U(e), else e or
/// e + 1.
inline int quantize(float u, int epb) noexcept {
    const int top = (1 << epb) - 1;
    if (epb >= 16) return std::clamp(int(u + 0.5f), 0, top);
    const int e = std::min(int(u * (1.f / float(1 << (16 - epb)))), top);
    const int a = float(unquantize(e, epb)) > u ? std::max(e - 1, 0) : e;
    const int b = std::min(a + 1, top);
    return float(unquantize(b, epb)) - u < u - float(unquantize(a, epb)) ? b : a;
}

/// Quantizes the endpoints for mode m; in a transformed mode every endpoint is kept inside the
/// offsets' reach of endpoint 0 (the nearest code in reach: U is increasing, so it is the clamp of
/// the nearest code).
inline void quantize_ends(int m, const float_ends& f, int e[4][3]) noexcept {
    const mode_desc& d = modes[m];
    for (int c = 0; c < 3; ++c) e[0][c] = quantize(f.v[0][0][c], d.epb);
    for (int k = 1; k < 2 * d.subsets; ++k)
        for (int c = 0; c < 3; ++c) {
            const int q = quantize(f.v[k / 2][k % 2][c], d.epb);
            const int reach = d.transformed ? 1 << (d.delta[c] - 1) : 1 << d.epb;
            e[k][c] = std::clamp(q, e[0][c] - reach, e[0][c] + reach - 1);
        }
}

/// How far mode m's offsets must reach for the endpoints, as a fraction of their reach: the largest
/// over channels and endpoints of the offset from endpoint 0 over the offsets' range in that
/// direction ([-2^(d-1), 2^(d-1) - 1] codes of 2^(16 - epb)). 0 for a mode without offsets.
inline float reach_ratio(int m, const float_ends& f) noexcept {
    const mode_desc& d = modes[m];
    if (!d.transformed) return 0.f;
    const float step = float(1 << (16 - std::min<int>(d.epb, 16)));
    float ratio = 0.f;
    for (int c = 0; c < 3; ++c) {
        const float reach = float(1 << (d.delta[c] - 1)) * step;
        for (int k = 1; k < 2 * d.subsets; ++k) {
            const float off = f.v[k / 2][k % 2][c] - f.v[0][0][c];
            ratio = std::max(ratio, off >= 0.f ? off / (reach - step) : -off / reach);
        }
    }
    return ratio;
}

/// Whether mode m's offsets reach the endpoints (reach_ratio <= 1).
inline bool reaches(int m, const float_ends& f) noexcept { return reach_ratio(m, f) <= 1.f; }

/// key[0] = the minimum of key[0 .. 2 H), by halving (fixed trip counts: unrolled, vectorized).
template <int H> void min_tree(std::uint32_t* key) noexcept {
    for (int k = 0; k < H; ++k) key[k] = std::min(key[k], key[k + H]);
    if constexpr (H > 1) min_tree<H / 2>(key);
}

/// Chooses the index of every texel of subset s for the block's endpoints (the anchor in the
/// lower half of the palette); returns their error. N: palette size (8 or 16).
template <int N> float assign_subset(const prepared& p, unpacked& u, int s) noexcept {
    const float* L = log_of_half();
    const mode_desc& d = modes[u.mode];
    const int* wk = N == 8 ? weights3 : weights4;
    float pal[3][N]; // ln(1 + decoded value) of each palette entry, per channel
    for (int c = 0; c < 3; ++c) {
        const int u0 = unquantize(u.e[2 * s][c], d.epb), u1 = unquantize(u.e[2 * s + 1][c], d.epb);
        for (int k = 0; k < N; ++k) pal[c][k] = L[finish(interpolate(u0, u1, wk[k]))];
    }
    const unsigned mask = N == 8 ? partitions[u.partition] : 0u;
    const int anchor = s == 0 ? 0 : anchors[u.partition];
    float err = 0.f;
    for (int t = 0; t < 16; ++t) {
        if (int((mask >> t) & 1u) != s) continue;
        if (p.w[t] == 0.f) { // ignored: index 0, so the block does not depend on the texel's value
            u.idx[t] = 0;
            continue;
        }
        const float l0 = p.l[t][0], l1 = p.l[t][1], l2 = p.l[t][2];
        float e[N];
        for (int k = 0; k < N; ++k) {
            const float dr = pal[0][k] - l0, dg = pal[1][k] - l1, db = pal[2][k] - l2;
            e[k] = dr * dr + dg * dg + db * db;
        }
        // Argmin as a minimum of keys: the bits of e >= 0 order like e, with the index in the
        // low bits (ties and differences below 2^-19 relative go to the lower index).
        // The anchor's upper half is excluded by the largest key. The minimum is taken as a tree
        // (halving the array), which keeps the dependency chain short.
        const std::uint32_t upper = t == anchor ? ~std::uint32_t(0) : 0u;
        std::uint32_t key[N];
        for (int k = 0; k < N; ++k)
            key[k] = ((std::bit_cast<std::uint32_t>(e[k]) & ~std::uint32_t(N - 1)) | std::uint32_t(k)) |
                     (k >= N / 2 ? upper : 0u);
        min_tree<N / 2>(key);
        const int bk = int(key[0] & std::uint32_t(N - 1));
        u.idx[t] = std::uint8_t(bk);
        err += p.w[t] * e[bk];
    }
    return err;
}

/// Chooses every texel's index for the block's endpoints; returns the error of each subset.
inline void assign_indices(const prepared& p, unpacked& u, float err[2]) noexcept {
    if (modes[u.mode].subsets == 1) {
        err[0] = assign_subset<16>(p, u, 0);
        err[1] = 0.f;
    } else {
        err[0] = assign_subset<8>(p, u, 0);
        err[1] = assign_subset<8>(p, u, 1);
    }
}

inline float assign_indices(const prepared& p, unpacked& u) noexcept {
    float err[2];
    assign_indices(p, u, err);
    return err[0] + err[1];
}

/// Relative determinant below which the refit's normal equations count as singular (all texels of
/// the subset on one index, or nearly): the subset's weighted mean is used for both endpoints.
inline constexpr float refit_singular = 1e-6f;

/// Weighted least-squares endpoints for the indices of u (each subset and channel on its own),
/// in the interpolation domain: the 2 x 2 normal equations of sum om (alpha e0 + beta e1 - t)^2
/// with beta = w / 64, alpha = 1 - beta.
inline float_ends refit(const prepared& p, const unpacked& u) noexcept {
    const mode_desc& d = modes[u.mode];
    const int* wk = d.subsets == 2 ? weights3 : weights4;
    const unsigned mask = d.subsets == 2 ? partitions[u.partition] : 0u;
    float aa[2][3] = {}, ab[2][3] = {}, bb[2][3] = {}, ra[2][3] = {}, rb[2][3] = {};
    for (int t = 0; t < 16; ++t) {
        const int s = int((mask >> t) & 1u);
        const float beta = float(wk[u.idx[t]]) * (1.f / 64.f), alpha = 1.f - beta;
        for (int c = 0; c < 3; ++c) {
            const float oa = p.om[t][c] * alpha, ob = p.om[t][c] * beta;
            aa[s][c] += oa * alpha;
            ab[s][c] += oa * beta;
            bb[s][c] += ob * beta;
            ra[s][c] += oa * p.t[t][c];
            rb[s][c] += ob * p.t[t][c];
        }
    }
    float_ends f;
    for (int s = 0; s < d.subsets; ++s)
        for (int c = 0; c < 3; ++c) {
            const float det = aa[s][c] * bb[s][c] - ab[s][c] * ab[s][c];
            float e0, e1;
            if (det > refit_singular * aa[s][c] * bb[s][c] && det > 0.f) {
                e0 = (ra[s][c] * bb[s][c] - rb[s][c] * ab[s][c]) / det;
                e1 = (rb[s][c] * aa[s][c] - ra[s][c] * ab[s][c]) / det;
            } else {
                const float sum = aa[s][c] + 2.f * ab[s][c] + bb[s][c]; // one index only: the mean
                e0 = e1 = sum > 0.f ? (ra[s][c] + rb[s][c]) / sum : 0.f;
            }
            f.v[s][0][c] = std::clamp(e0, 0.f, domain_max);
            f.v[s][1][c] = std::clamp(e1, 0.f, domain_max);
        }
    return f;
}

inline bool same_ends(const unpacked& a, const unpacked& b) noexcept {
    for (int k = 0; k < 4; ++k)
        for (int c = 0; c < 3; ++c)
            if (a.e[k][c] != b.e[k][c]) return false;
    return true;
}

/// Quantize, choose indices, then up to `refits` times: refit by least squares and repeat while
/// the quantized endpoints change. The best of the passes.
inline candidate evaluate(const prepared& p, int m, int partition, const float_ends& start, int refits) noexcept {
    candidate best;
    candidate c;
    c.block.mode = m;
    c.block.partition = partition;
    quantize_ends(m, start, c.block.e);
    for (int it = 0;; ++it) {
        c.err = assign_indices(p, c.block);
        if (c.err < best.err) best = c;
        if (it == refits || c.err == 0.f) break;
        const unpacked previous = c.block;
        quantize_ends(m, refit(p, c.block), c.block.e);
        if (same_ends(previous, c.block)) break; // a fixed point: the same indices again
    }
    return best;
}

/// Power iteration for the dominant eigenvector of a symmetric positive semi-definite 3 x 3
/// matrix m: three steps on m^2 from its column of largest norm, each scaled by its largest
/// component (no square roots); v is not normalised (all zero when m is).
inline void dominant_direction(const double m[3][3], double v[3]) noexcept {
    double m2[3][3];
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) m2[i][j] = m[i][0] * m[0][j] + m[i][1] * m[1][j] + m[i][2] * m[2][j];
    int col = 0;
    for (int i = 1; i < 3; ++i)
        if (m2[i][i] > m2[col][col]) col = i;
    for (int i = 0; i < 3; ++i) v[i] = m2[i][col];
    for (int it = 0; it < 3; ++it) {
        double next[3];
        for (int i = 0; i < 3; ++i) next[i] = m2[i][0] * v[0] + m2[i][1] * v[1] + m2[i][2] * v[2];
        const double scale = std::max({std::abs(next[0]), std::abs(next[1]), std::abs(next[2])});
        if (!(scale > 0)) return;
        const double inv = 1.0 / scale;
        for (int i = 0; i < 3; ++i) v[i] = next[i] * inv;
    }
}

/// The unit principal axis of a scatter matrix (0 when the scatter is 0).
inline void principal_axis(const double m[3][3], double axis[3]) noexcept {
    dominant_direction(m, axis);
    const double len = std::sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
    for (int i = 0; i < 3; ++i) axis[i] = len > 0 ? axis[i] / len : 0.0;
}

/// Largest eigenvalue of a symmetric positive semi-definite 3 x 3 matrix (the Rayleigh quotient
/// of its dominant direction).
inline double largest_eigenvalue(const double m[3][3]) noexcept {
    double v[3];
    dominant_direction(m, v);
    double mv[3];
    for (int i = 0; i < 3; ++i) mv[i] = m[i][0] * v[0] + m[i][1] * v[1] + m[i][2] * v[2];
    const double vv = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
    return vv > 0 ? (v[0] * mv[0] + v[1] * mv[1] + v[2] * mv[2]) / vv : 0;
}

/// Added to every texel's weight in the line fits (ws is at most 1): a subset of texels whose
/// weights are all near 0 (values far below 1, where ln(1 + x) is flat) still gets a line through
/// them rather than a degenerate one.
inline constexpr double fit_weight_floor = 1e-12;

/// Principal-axis endpoints of the texels in `mask` (weighted by ws), ordered so that the anchor
/// texel lies in the half nearer ends[0].
inline void fit_subset(const prepared& p, unsigned mask, int anchor, float a[3], float b[3]) noexcept {
    double sw = 0, mean[3] = {0, 0, 0};
    for (int t = 0; t < 16; ++t) {
        if (!((mask >> t) & 1u) || p.w[t] <= 0.f) continue;
        const double w = double(p.ws[t]) + fit_weight_floor;
        sw += w;
        for (int c = 0; c < 3; ++c) mean[c] += w * p.t[t][c];
    }
    if (!(sw > 0)) { // no texel inside: any valid endpoints (the middle of the domain)
        for (int c = 0; c < 3; ++c) a[c] = b[c] = 0.5f * domain_max;
        return;
    }
    for (double& m : mean) m /= sw;
    double cov[3][3] = {};
    for (int t = 0; t < 16; ++t) {
        if (!((mask >> t) & 1u) || p.w[t] <= 0.f) continue;
        const double w = double(p.ws[t]) + fit_weight_floor;
        const double d[3] = {p.t[t][0] - mean[0], p.t[t][1] - mean[1], p.t[t][2] - mean[2]};
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) cov[i][j] += w * d[i] * d[j];
    }
    double axis[3];
    principal_axis(cov, axis);
    double lo = 0, hi = 0, pa = 0;
    for (int t = 0; t < 16; ++t) {
        if (!((mask >> t) & 1u) || p.w[t] <= 0.f) continue;
        const double proj = (p.t[t][0] - mean[0]) * axis[0] + (p.t[t][1] - mean[1]) * axis[1] +
                            (p.t[t][2] - mean[2]) * axis[2];
        lo = std::min(lo, proj);
        hi = std::max(hi, proj);
        if (t == anchor) pa = proj;
    }
    if (pa - lo > hi - pa) std::swap(lo, hi); // the anchor nearer ends[0]
    for (int c = 0; c < 3; ++c) {
        a[c] = float(std::clamp(mean[c] + lo * axis[c], 0.0, double(domain_max)));
        b[c] = float(std::clamp(mean[c] + hi * axis[c], 0.0, double(domain_max)));
    }
}

/// Endpoints of partition `partition` (two subsets), or of the whole block (partition < 0).
inline float_ends fit(const prepared& p, int partition) noexcept {
    float_ends f;
    if (partition < 0) {
        fit_subset(p, 0xFFFFu, 0, f.v[0][0], f.v[0][1]);
    } else {
        const unsigned mask = partitions[partition];
        fit_subset(p, ~mask & 0xFFFFu, 0, f.v[0][0], f.v[0][1]);
        fit_subset(p, mask, anchors[partition], f.v[1][0], f.v[1][1]);
    }
    return f;
}

/// Weighted moments of one subset: sum w, sum w t, sum w t t^T (targets relative to the block mean).
struct moments {
    double w = 0, s[3] = {}, ss[6] = {};
};

/// Estimated error of a subset coded on a line with `levels` indices: the scatter off its
/// principal axis plus the quantisation of a uniform spread along it.
inline double line_estimate(const moments& m, int levels) noexcept {
    if (!(m.w > 0)) return 0;
    double c[3][3];
    const int ij[3][3] = {{0, 1, 2}, {1, 3, 4}, {2, 4, 5}};
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) c[i][j] = m.ss[ij[i][j]] - m.s[i] * m.s[j] / m.w;
    const double trace = c[0][0] + c[1][1] + c[2][2];
    const double lambda = std::min(largest_eigenvalue(c), trace);
    const double steps = double(levels - 1);
    return std::max(0.0, trace - lambda) + lambda / (steps * steps);
}

/// The `count` partitions of lowest estimated two-subset error, best first.
inline int rank_partitions(const prepared& p, int count, int out[32]) noexcept {
    double centre[3] = {0, 0, 0}, sw = 0;
    for (int t = 0; t < 16; ++t) {
        sw += p.ws[t];
        for (int c = 0; c < 3; ++c) centre[c] += double(p.ws[t]) * p.t[t][c];
    }
    for (double& x : centre) x = sw > 0 ? x / sw : 0;
    moments texel[16], all;
    for (int t = 0; t < 16; ++t) {
        const double w = p.ws[t];
        const double d[3] = {p.t[t][0] - centre[0], p.t[t][1] - centre[1], p.t[t][2] - centre[2]};
        moments& m = texel[t];
        m.w = w;
        for (int c = 0; c < 3; ++c) m.s[c] = w * d[c];
        m.ss[0] = w * d[0] * d[0], m.ss[1] = w * d[0] * d[1], m.ss[2] = w * d[0] * d[2];
        m.ss[3] = w * d[1] * d[1], m.ss[4] = w * d[1] * d[2], m.ss[5] = w * d[2] * d[2];
        all.w += m.w;
        for (int c = 0; c < 3; ++c) all.s[c] += m.s[c];
        for (int c = 0; c < 6; ++c) all.ss[c] += m.ss[c];
    }
    double score[32];
    for (int q = 0; q < 32; ++q) {
        moments one;
        for (int t = 0; t < 16; ++t) {
            if (!((partitions[q] >> t) & 1u)) continue;
            one.w += texel[t].w;
            for (int c = 0; c < 3; ++c) one.s[c] += texel[t].s[c];
            for (int c = 0; c < 6; ++c) one.ss[c] += texel[t].ss[c];
        }
        moments zero;
        zero.w = all.w - one.w;
        for (int c = 0; c < 3; ++c) zero.s[c] = all.s[c] - one.s[c];
        for (int c = 0; c < 6; ++c) zero.ss[c] = all.ss[c] - one.ss[c];
        score[q] = line_estimate(zero, 8) + line_estimate(one, 8);
    }
    int order[32]; // insertion sort by score (stable: ties keep the partition order)
    for (int q = 0; q < 32; ++q) {
        int i = q;
        for (; i > 0 && score[q] < score[order[i - 1]]; --i) order[i] = order[i - 1];
        order[i] = q;
    }
    count = std::clamp(count, 0, 32);
    for (int q = 0; q < count; ++q) out[q] = order[q];
    return count;
}

inline void keep_better(candidate& best, const candidate& c) noexcept {
    if (c.err < best.err) best = c;
}

/// Whether every offset of a transformed mode's channel c is in reach of endpoint 0.
inline bool in_reach(const unpacked& u, int c) noexcept {
    const mode_desc& d = modes[u.mode];
    if (!d.transformed) return true;
    const int reach = 1 << (d.delta[c] - 1);
    for (int k = 1; k < 2 * d.subsets; ++k) {
        const int off = u.e[k][c] - u.e[0][c];
        if (off < -reach || off >= reach) return false;
    }
    return true;
}

/// Coordinate descent on the quantized endpoints: +-1 code on each endpoint channel, kept when it
/// lowers the error (indices re-chosen), until a round changes nothing (at most `rounds`).
inline void polish(const prepared& p, candidate& best, int rounds) noexcept {
    const mode_desc& d = modes[best.block.mode];
    const int top = (1 << d.epb) - 1;
    float err[2];
    assign_indices(p, best.block, err);
    for (int round = 0; round < rounds; ++round) {
        bool improved = false;
        for (int k = 0; k < 2 * d.subsets; ++k)
            for (int c = 0; c < 3; ++c)
                for (int step : {-1, 1}) {
                    unpacked trial = best.block;
                    const int x = trial.e[k][c] + step;
                    if (x < 0 || x > top) continue;
                    trial.e[k][c] = x;
                    if (!in_reach(trial, c)) continue;
                    // Endpoint k belongs to subset k / 2; endpoint 0 is also the base of the
                    // others, whose absolute values do not move, so only subset k / 2 changes.
                    const int s = k / 2;
                    const float e = d.subsets == 1 ? assign_subset<16>(p, trial, s) : assign_subset<8>(p, trial, s);
                    if (e < err[s]) {
                        err[s] = e;
                        best.block = trial;
                        best.err = err[0] + err[1];
                        improved = true;
                    }
                }
        if (!improved) break;
    }
}

/// Refits per quality level (each level's count >= the one before: encode_normal relies on it).
inline constexpr int fast_refits = 2;
inline constexpr int normal_refits = 3;
inline constexpr int exhaustive_refits = 6;
static_assert(fast_refits <= normal_refits && normal_refits <= exhaustive_refits);
/// Normal: partitions tried (best estimates), precision groups tried per partition, candidates
/// polished and polish rounds. The reach slack: principal-axis endpoints span the extreme texels
/// and the refit pulls them inward, so a mode whose offsets reach 1 / 1.5 of the span often fits
/// after the refit (its clamped first pass is valid anyway).
inline constexpr int normal_partitions = 4;
inline constexpr int normal_groups_per_partition = 2;
inline constexpr int normal_polished = 2;
inline constexpr int normal_polish_rounds = 2;
inline constexpr float normal_reach_slack = 1.5f;
/// Exhaustive: candidates polished and polish rounds.
inline constexpr int exhaustive_polished = 8;
inline constexpr int exhaustive_polish_rounds = 8;

/// The N candidates of lowest error offered so far, best first (ties: the earlier first).
template <int N> struct best_candidates {
    candidate c[N];
    int n = 0;

    void offer(const candidate& x) noexcept {
        int i = n < N ? n++ : N;
        if (i == N && !(x.err < c[N - 1].err)) return;
        if (i == N) i = N - 1;
        while (i > 0 && x.err < c[i - 1].err) {
            c[i] = c[i - 1];
            --i;
        }
        c[i] = x;
    }
};

/// Fast: the finest one-subset mode whose offsets reach the principal-axis endpoints.
inline candidate encode_fast(const prepared& p, const float_ends& single) noexcept {
    int m = 10;
    for (int k : {13, 12, 11})
        if (reaches(k, single)) {
            m = k;
            break;
        }
    return evaluate(p, m, 0, single, fast_refits);
}

/// The two-subset modes in groups of equal endpoint precision, finest first; within a group they
/// differ in which channel has the widest offsets.
inline constexpr int precision_groups[6][3] = {{2, 3, 4}, {0, -1, -1}, {5, -1, -1},
                                                {6, 7, 8}, {1, -1, -1}, {9, -1, -1}};

/// Polishes each candidate kept and returns the best.
template <int N> candidate polish_best(const prepared& p, best_candidates<N>& keep, int rounds) noexcept {
    candidate best;
    for (int i = 0; i < keep.n; ++i) {
        polish(p, keep.c[i], rounds);
        keep_better(best, keep.c[i]);
    }
    return best;
}

/// Normal. The one-subset modes finest first, while their offsets reach the endpoints with the
/// slack, up to the first that reaches without it (a coarser mode then only loses precision): fast's
/// mode is among them with at least fast's refits, so normal's error is never above fast's. Then
/// the two-subset precision groups the same way on the partitions of lowest estimate; the best
/// candidates are polished.
inline candidate encode_normal(const prepared& p, const float_ends& single) noexcept {
    best_candidates<normal_polished> keep;
    for (int m = mode_count - 1; m >= first_single; --m) {
        const float ratio = reach_ratio(m, single);
        if (ratio > normal_reach_slack) continue;
        keep.offer(evaluate(p, m, 0, single, normal_refits));
        if (ratio <= 1.f) break;
    }
    int shortlist[32];
    const int n = rank_partitions(p, normal_partitions, shortlist);
    for (int i = 0; i < n; ++i) {
        const int q = shortlist[i];
        const float_ends f = fit(p, q);
        int tried = 0;
        for (const auto& group : precision_groups) {
            int m = -1; // the member whose offsets reach furthest for these endpoints
            float ratio = std::numeric_limits<float>::infinity();
            for (int g : group)
                if (g >= 0 && reach_ratio(g, f) < ratio) m = g, ratio = reach_ratio(g, f);
            if (ratio > normal_reach_slack) continue;
            keep.offer(evaluate(p, m, q, f, normal_refits));
            if (ratio <= 1.f || ++tried == normal_groups_per_partition) break;
        }
    }
    return polish_best(p, keep, normal_polish_rounds);
}

/// Exhaustive: normal's block (so never worse), every mode on every partition, the best polished.
inline candidate encode_exhaustive(const prepared& p, const float_ends& single) noexcept {
    best_candidates<exhaustive_polished> keep;
    keep.offer(encode_normal(p, single));
    for (int m = first_single; m < mode_count; ++m) keep.offer(evaluate(p, m, 0, single, exhaustive_refits));
    for (int q = 0; q < 32; ++q) {
        const float_ends f = fit(p, q);
        for (int m = 0; m < first_single; ++m) keep.offer(evaluate(p, m, q, f, exhaustive_refits));
    }
    return polish_best(p, keep, exhaustive_polish_rounds);
}

/// Checks an image size: throws std::invalid_argument below 1, std::length_error above 65536
/// per side or 2^30 texels in all.
inline void check_image(const char* fn, const void* data, int width, int height) {
    constexpr int max_side = 65536;
    constexpr std::size_t max_texels = std::size_t(1) << 30;
    if (width < 1 || height < 1)
        throw std::invalid_argument(std::string("ibl::") + fn + ": width and height must be >= 1, got " +
                                    std::to_string(width) + " x " + std::to_string(height));
    if (width > max_side || height > max_side || std::size_t(width) * std::size_t(height) > max_texels)
        throw std::length_error(std::string("ibl::") + fn + ": " + std::to_string(width) + " x " +
                                std::to_string(height) + " exceeds 65536 per side or 2^30 texels");
    if (!data) throw std::invalid_argument(std::string("ibl::") + fn + ": null data");
}

} // namespace detail::bc6h

/// Decodes one 16-byte BC6H_UFLOAT block to 16 texels (row-major 4x4, texel y*4+x) of RGB as the
/// half-float bit patterns a GPU returns (reserved modes decode to 0 per the specification).
inline void bc6h_decode_block_half(const unsigned char block[16], std::uint16_t out[16][3]) noexcept {
    detail::bc6h::unpacked u;
    if (!detail::bc6h::unpack(block, u)) {
        for (int t = 0; t < 16; ++t) out[t][0] = out[t][1] = out[t][2] = 0;
        return;
    }
    detail::bc6h::decode_unpacked(u, out);
}

/// The same as floats (exact: every UF16 value is a float).
inline void bc6h_decode_block(const unsigned char block[16], float out[16][3]) noexcept {
    std::uint16_t h[16][3];
    bc6h_decode_block_half(block, h);
    for (int t = 0; t < 16; ++t)
        for (int c = 0; c < 3; ++c) out[t][c] = detail::bc6h::half_to_float(h[t][c]);
}

/// Encodes 16 texels of linear RGB (texel y*4+x) into one block. Input policy: NaN and negatives
/// -> 0, values above 65504 (and +inf) -> 65504. `weights`: optional per-texel weights (nullptr =
/// all 1; weight 0 marks padding texels outside the image that the encoder may ignore).
inline void bc6h_encode_block(const float in[16][3], unsigned char out[16], bc6h_quality quality,
                              const float* weights = nullptr) noexcept {
    using namespace detail::bc6h;
    prepared p;
    prepare(in, weights, p);
    const float_ends single = fit(p, -1);
    candidate best;
    switch (quality) {
    case bc6h_quality::fast: best = encode_fast(p, single); break;
    case bc6h_quality::exhaustive: best = encode_exhaustive(p, single); break;
    default: best = encode_normal(p, single); break;
    }
    pack(best.block, out);
}

/// Encodes a whole image (width x height texels of RGB float, row-major, 3 floats per texel,
/// any width, height >= 1): blocks in row-major block order, ceil(w/4) x ceil(h/4) x 16 bytes;
/// the texels of partial edge blocks outside the image have weight 0 (and repeat the edge). `ex`
/// is any executor of ibl/core/executor.hpp; the result does not depend on it. Throws
/// std::invalid_argument for a size below 1 or null data, std::length_error above 65536 per side
/// or 2^30 texels.
template <class Executor = serial_executor>
[[nodiscard]] std::vector<unsigned char> bc6h_encode_image(const float* rgb, int width, int height,
                                                         bc6h_quality quality, Executor&& ex = Executor{}) {
    detail::bc6h::check_image("bc6h_encode_image", rgb, width, height);
    const std::size_t bw = std::size_t(width + 3) / 4, bh = std::size_t(height + 3) / 4;
    std::vector<unsigned char> out(bw * bh * 16);
    ex(bw * bh, [&](std::size_t begin, std::size_t end) {
        for (std::size_t b = begin; b < end; ++b) {
            const int x0 = int(b % bw) * 4, y0 = int(b / bw) * 4;
            float texels[16][3], w[16];
            bool partial = false;
            for (int t = 0; t < 16; ++t) {
                const int x = x0 + t % 4, y = y0 + t / 4;
                const bool inside = x < width && y < height;
                partial |= !inside;
                w[t] = inside ? 1.f : 0.f;
                const std::size_t src = (std::size_t(std::min(y, height - 1)) * std::size_t(width) +
                                         std::size_t(std::min(x, width - 1))) * 3;
                for (int c = 0; c < 3; ++c) texels[t][c] = rgb[src + std::size_t(c)];
            }
            bc6h_encode_block(texels, out.data() + b * 16, quality, partial ? w : nullptr);
        }
    });
    return out;
}

/// Decodes blocks written by bc6h_encode_image (ceil(w/4) x ceil(h/4) of them, row-major) to
/// width x height x 3 floats. Throws as bc6h_encode_image does.
[[nodiscard]] inline std::vector<float> bc6h_decode_image(const unsigned char* blocks, int width, int height) {
    detail::bc6h::check_image("bc6h_decode_image", blocks, width, height);
    const std::size_t bw = std::size_t(width + 3) / 4, bh = std::size_t(height + 3) / 4;
    std::vector<float> out(std::size_t(width) * std::size_t(height) * 3);
    for (std::size_t b = 0; b < bw * bh; ++b) {
        float texels[16][3];
        bc6h_decode_block(blocks + b * 16, texels);
        const int x0 = int(b % bw) * 4, y0 = int(b / bw) * 4;
        for (int t = 0; t < 16; ++t) {
            const int x = x0 + t % 4, y = y0 + t / 4;
            if (x >= width || y >= height) continue;
            float* dst = out.data() + (std::size_t(y) * std::size_t(width) + std::size_t(x)) * 3;
            for (int c = 0; c < 3; ++c) dst[c] = texels[t][c];
        }
    }
    return out;
}

/// The encoder's error as a root mean square over `count` values: sqrt(mean (ln(1 + decoded) -
/// ln(1 + reference))^2), the reference taken through the input policy (NaN, negatives -> 0,
/// above 65504 -> 65504) and the decoded values as they are (>= 0). 0 for count = 0.
[[nodiscard]] inline double bc6h_rmsle(const float* reference, const float* decoded, std::size_t count) noexcept {
    if (count == 0) return 0.0;
    double sum = 0.0;
    for (std::size_t i = 0; i < count; ++i) {
        const double d = std::log1p(double(decoded[i])) - std::log1p(double(detail::bc6h::sanitize(reference[i])));
        sum += d * d;
    }
    return std::sqrt(sum / double(count));
}

} // namespace ibl

#endif // IBL_DETAIL_CXX20
