// tools/ibl-bake/tests/test_ktx2_formats.cpp — the packed HDR formats of the KTX2 writer
// (B10G11R11_UFLOAT_PACK32, E5B9G9R9_UFLOAT_PACK32): encodings of known values against bit
// patterns worked out by hand from the Vulkan / GL_EXT_texture_shared_exponent definitions,
// round-trip bounds from the mantissa widths, the data format descriptors word by word against
// the Khronos Data Format Specification layout, header fields of the written files, the
// quantisation report on values whose errors are known exactly.

#include <doctest/doctest.h>

#include "io/image_io.hpp"
#include "io/ktx2.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <string>
#include <vector>

using namespace ibl_bake;

namespace {

constexpr float inf = std::numeric_limits<float>::infinity();
constexpr float qnan = std::numeric_limits<float>::quiet_NaN();

cubemap_rgb32f constant_cube(int n, int levels, float r, float g, float b) {
    cubemap_rgb32f c = cubemap_rgb32f::zeros(n, levels);
    for (auto& level : c.levels)
        for (auto& face : level)
            for (std::size_t i = 0; i < face.size(); i += 3) {
                face[i] = r;
                face[i + 1] = g;
                face[i + 2] = b;
            }
    return c;
}

// Values spread over many binades (log-uniform in [2^-16, 2^17]) with a few exact specials.
cubemap_rgb32f varied_cube(int n, int levels, unsigned seed) {
    cubemap_rgb32f c = cubemap_rgb32f::zeros(n, levels);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> e(-16.0, 17.0);
    for (auto& level : c.levels)
        for (auto& face : level)
            for (float& x : face) x = float(std::exp2(e(rng)));
    return c;
}

} // namespace

TEST_CASE("ktx2 formats: B10G11R11 small floats, hand-computed codes") {
    // 11-bit: 5-bit exponent (bias 15) << 6 | 6-bit mantissa; 10-bit: << 5 | 5-bit mantissa.
    CHECK(float_to_ufloat(1.0f, 6) == 0x3C0u);  // exponent 15
    CHECK(float_to_ufloat(1.0f, 5) == 0x1E0u);
    CHECK(float_to_ufloat(0.5f, 6) == 0x380u);  // exponent 14
    CHECK(float_to_ufloat(1.5f, 6) == 0x3E0u);  // mantissa 32/64
    CHECK(float_to_ufloat(65024.0f, 6) == 0x7BFu); // max finite 2^15 (1 + 63/64)
    CHECK(float_to_ufloat(64512.0f, 5) == 0x3DFu); // max finite 2^15 (1 + 31/32)
    CHECK(float_to_ufloat(65504.0f, 6) == 0x7BFu); // above: clamped, never inf
    CHECK(float_to_ufloat(65504.0f, 5) == 0x3DFu);
    CHECK(float_to_ufloat(1e9f, 6) == 0x7BFu);
    CHECK(float_to_ufloat(inf, 6) == 0x7BFu);
    CHECK(float_to_ufloat(-1.0f, 6) == 0u);
    CHECK(float_to_ufloat(-0.0f, 6) == 0u);
    CHECK(float_to_ufloat(-inf, 6) == 0u);
    CHECK(float_to_ufloat(qnan, 6) == 0u);
    CHECK(float_to_ufloat(0.0f, 6) == 0u);
    // Denormals: code = value / 2^(-14 - m).
    CHECK(float_to_ufloat(0x1p-20f, 6) == 1u);            // smallest 11-bit denormal
    CHECK(float_to_ufloat(0x1p-19f, 5) == 1u);            // smallest 10-bit denormal
    CHECK(float_to_ufloat(0x1p-21f, 6) == 0u);            // exactly half of it: tie to even (0)
    CHECK(float_to_ufloat(0x1.8p-21f, 6) == 1u);          // 0.75 units: rounds up
    CHECK(float_to_ufloat(0x1.8p-20f, 6) == 2u);          // 1.5 units: tie to even (2)
    CHECK(float_to_ufloat(63.0f * 0x1p-20f, 6) == 63u);   // largest denormal
    CHECK(float_to_ufloat(0x1p-14f, 6) == 64u);           // smallest normal: exponent 1, mantissa 0
    CHECK(float_to_ufloat(127.6f * 0x1p-21f, 6) == 64u);  // 63.8 units rounds up into the normals
    CHECK(float_to_ufloat(std::numeric_limits<float>::denorm_min(), 6) == 0u);
    // Round to nearest even on normals: the ulp at 1 is 2^-6 (R, G) and 2^-5 (B).
    CHECK(float_to_ufloat(1.0f + 0x1p-7f, 6) == 0x3C0u);            // tie -> even mantissa 0
    CHECK(float_to_ufloat(1.0f + 3 * 0x1p-7f, 6) == 0x3C2u);        // tie -> even mantissa 2
    CHECK(float_to_ufloat(1.0f + 0x1p-7f + 0x1p-20f, 6) == 0x3C1u); // above the tie
    CHECK(float_to_ufloat(2.0f - 0x1p-8f, 6) == 0x400u);            // carries into exponent 16
    // Decoding.
    CHECK(ufloat_to_float(0x3C0u, 6) == 1.0f);
    CHECK(ufloat_to_float(0x7BFu, 6) == 65024.0f);
    CHECK(ufloat_to_float(0x3DFu, 5) == 64512.0f);
    CHECK(ufloat_to_float(1u, 6) == 0x1p-20f);
    CHECK(ufloat_to_float(63u, 6) == 63.0f * 0x1p-20f);
    CHECK(std::isinf(ufloat_to_float(0x7C0u, 6)));
    CHECK(std::isnan(ufloat_to_float(0x7C1u, 6)));
    // Packing order: R bits 0-10, G 11-21, B 22-31.
    CHECK(pack_b10g11r11(1.0f, 1.0f, 1.0f) == (0x3C0u | (0x3C0u << 11) | (0x1E0u << 22)));
    CHECK(pack_b10g11r11(1.0f, 1.0f, 1.0f) == 0x781E03C0u);
    CHECK(pack_b10g11r11(0.5f, 0.0f, 0.0f) == 0x380u);
    CHECK(pack_b10g11r11(0.0f, 0.5f, 0.0f) == 0x380u << 11);
    CHECK(pack_b10g11r11(0.0f, 0.0f, 0.5f) == 0x1C0u << 22);
    float rgb[3];
    unpack_b10g11r11(0x781E03C0u, rgb);
    CHECK(rgb[0] == 1.0f);
    CHECK(rgb[1] == 1.0f);
    CHECK(rgb[2] == 1.0f);
    // Every code decodes and re-encodes to itself (finite codes: exponent < 31).
    for (std::uint32_t code = 0; code < (31u << 6); ++code) REQUIRE(float_to_ufloat(ufloat_to_float(code, 6), 6) == code);
    for (std::uint32_t code = 0; code < (31u << 5); ++code) REQUIRE(float_to_ufloat(ufloat_to_float(code, 5), 5) == code);
}

TEST_CASE("ktx2 formats: B10G11R11 round trip within half an ulp of the mantissa") {
    // For x in the normal range [2^-14, max], |x' - x| <= 2^-(m+1) 2^floor(log2 x) <= 2^-(m+1) x.
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> e(-14.0, 15.99);
    for (int i = 0; i < 20000; ++i) {
        const float x = float(std::exp2(e(rng)));
        for (int m : {6, 5}) {
            const float max = m == 6 ? 65024.0f : 64512.0f;
            if (x > max) continue;
            const float y = ufloat_to_float(float_to_ufloat(x, m), m);
            REQUIRE(std::fabs(double(y) - double(x)) <= std::ldexp(double(x), -(m + 1)));
        }
    }
    // Denormal range: absolute error <= half the denormal unit 2^(-14 - m) / 2.
    std::uniform_real_distribution<double> d(0.0, 0x1p-14);
    for (int i = 0; i < 2000; ++i) {
        const float x = float(d(rng));
        for (int m : {6, 5}) {
            const float y = ufloat_to_float(float_to_ufloat(x, m), m);
            REQUIRE(std::fabs(double(y) - double(x)) <= std::ldexp(1.0, -14 - m - 1));
        }
    }
}

TEST_CASE("ktx2 formats: E5B9G9R9 shared exponent, hand-computed codes") {
    // max = 1: floor(log2 1) = 0, exponent 0 + 1 + 15 = 16, unit 2^(16-24) = 2^-8, mantissa 256.
    CHECK(pack_e5b9g9r9(1.0f, 1.0f, 1.0f) == (256u | (256u << 9) | (256u << 18) | (16u << 27)));
    CHECK(pack_e5b9g9r9(1.0f, 1.0f, 1.0f) == 0x84020100u);
    // max = 0.5: exponent 15, unit 2^-9: R 256, G 128, B 0.
    CHECK(pack_e5b9g9r9(0.5f, 0.25f, 0.0f) == (256u | (128u << 9) | (15u << 27)));
    // 65408 = 511 x 2^7: exponent 31, mantissa 511; larger values clamp to it.
    CHECK(pack_e5b9g9r9(65408.0f, 0.0f, 0.0f) == (511u | (31u << 27)));
    CHECK(pack_e5b9g9r9(65504.0f, 0.0f, 0.0f) == (511u | (31u << 27)));
    CHECK(pack_e5b9g9r9(1e9f, 1e9f, inf) == (511u | (511u << 9) | (511u << 18) | (31u << 27)));
    // Negatives, NaN -> 0; all zero -> exponent 0.
    CHECK(pack_e5b9g9r9(-1.0f, qnan, -inf) == 0u);
    CHECK(pack_e5b9g9r9(0.0f, 0.0f, 0.0f) == 0u);
    // Mantissa rounding to 2^N bumps the exponent: 1.999 x 256 = 511.74 -> 512, so exponent 17,
    // unit 2^-7, R = floor(1.999 x 128 + 0.5) = 256 (decodes to 2).
    CHECK(pack_e5b9g9r9(1.999f, 0.0f, 0.0f) == (256u | (17u << 27)));
    // Smallest values: exponent clamps at 0 (floor(log2) >= -16), unit 2^-24.
    CHECK(pack_e5b9g9r9(0x1p-24f, 0.0f, 0.0f) == 1u);
    CHECK(pack_e5b9g9r9(0x1p-26f, 0.0f, 0.0f) == 0u);
    CHECK(pack_e5b9g9r9(0x1p-16f, 0.0f, 0.0f) == 256u); // 2^-16 / 2^-24 = 256, exponent 0
    // A dim channel next to a bright one rounds to the bright one's unit: 3 x 2^-9 with max 1.
    CHECK(pack_e5b9g9r9(1.0f, 3.0f * 0x1p-9f, 0.0f) == (256u | (2u << 9) | (16u << 27))); // 1.5 units: ties up (floor(x + 1/2))
    float rgb[3];
    unpack_e5b9g9r9(0x84020100u, rgb);
    CHECK(rgb[0] == 1.0f);
    CHECK(rgb[1] == 1.0f);
    CHECK(rgb[2] == 1.0f);
    unpack_e5b9g9r9(511u | (31u << 27), rgb);
    CHECK(rgb[0] == 65408.0f);
    unpack_e5b9g9r9(1u, rgb);
    CHECK(rgb[0] == 0x1p-24f);
}

TEST_CASE("ktx2 formats: E5B9G9R9 round trip within half a unit of the shared exponent") {
    // Half a unit is 2^(exp - 25); the unit is at most max / 255.75 ... derived: max_s =
    // round(max / unit') >= 256 for the unrounded exponent, and when rounding bumps it the unit
    // doubles with max >= 511.5 unit', so |x' - x| <= max / 511.5 for every channel, and
    // <= 2^-25 once the exponent is clamped at 0 (max < 2^-15).
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> e(-30.0, 15.99);
    for (int i = 0; i < 20000; ++i) {
        const float in[3] = {float(std::exp2(e(rng))), float(std::exp2(e(rng))), float(std::exp2(e(rng)))};
        float out[3];
        unpack_e5b9g9r9(pack_e5b9g9r9(in[0], in[1], in[2]), out);
        const double mx = std::max({double(in[0]), double(in[1]), double(in[2])});
        for (int c = 0; c < 3; ++c)
            REQUIRE(std::fabs(double(out[c]) - double(in[c])) <= std::max(mx / 511.5, 0x1p-25));
        // The largest channel keeps 9 significant bits: relative error <= 1/511.5 when normal.
        const int k = in[0] == mx ? 0 : (in[1] == mx ? 1 : 2);
        if (mx >= 0x1p-15) REQUIRE(std::fabs(double(out[k]) - mx) <= mx / 511.5);
    }
}

TEST_CASE("ktx2 formats: data format descriptors word by word") {
    const cubemap_rgb32f cube = constant_cube(4, 3, 1.0f, 0.5f, 0.25f);
    SUBCASE("B10G11R11_UFLOAT_PACK32") {
        const auto file = encode_ktx2_cubemap(cube, ktx2_format::b10g11r11);
        const ktx2_info k = parse_ktx2(file);
        CHECK(k.vk_format == 122u);
        CHECK(k.type_size == 4u);
        REQUIRE(k.dfd.size() == 19); // 76 bytes: total + 24-byte block header + 3 samples of 16
        CHECK(k.dfd[0] == 76u);
        CHECK(k.dfd[1] == 0u);                         // vendorId 0, descriptorType 0
        CHECK(k.dfd[2] == (2u | (72u << 16)));         // versionNumber 2 (1.3), blockSize 72
        CHECK(k.dfd[3] == (1u | (1u << 8) | (1u << 16))); // RGBSDA, BT709, LINEAR, flags 0
        CHECK(k.dfd[4] == 0u);                         // 1x1x1x1 texel block
        CHECK(k.dfd[5] == 4u);                         // bytesPlane0 = 4
        CHECK(k.dfd[6] == 0u);
        // bitOffset | (bitLength - 1) << 16 | (channel | FLOAT 0x80) << 24, position, lower, upper
        const std::uint32_t word0[3] = {0x800A0000u, 0x810A000Bu, 0x82090016u};
        for (int s = 0; s < 3; ++s) {
            CHECK(k.dfd[std::size_t(7 + 4 * s)] == word0[s]);
            CHECK(k.dfd[std::size_t(8 + 4 * s)] == 0u);
            CHECK(k.dfd[std::size_t(9 + 4 * s)] == 0u);          // 0.0f
            CHECK(k.dfd[std::size_t(10 + 4 * s)] == 0x3F800000u); // 1.0f
        }
        REQUIRE(k.levels.size() == 3);
        for (std::size_t l = 0; l < 3; ++l) {
            const std::uint64_t s = 4u >> l;
            CHECK(k.levels[l].byte_length == 6 * s * s * 4);
            CHECK(k.levels[l].byte_offset % 4 == 0);
        }
        CHECK(k.levels[0].byte_offset + k.levels[0].byte_length == file.size());
        // First texel of level 0 face +X, read at the offset of the level index: the packed word.
        const std::size_t at = std::size_t(k.levels[0].byte_offset);
        const std::uint32_t w = std::uint32_t(file[at]) | (std::uint32_t(file[at + 1]) << 8) |
                                (std::uint32_t(file[at + 2]) << 16) | (std::uint32_t(file[at + 3]) << 24);
        CHECK(w == (0x3C0u | (0x380u << 11) | (0x1A0u << 22))); // 1, 0.5 (e 14), 0.25 (e 13 << 5)
    }
    SUBCASE("E5B9G9R9_UFLOAT_PACK32") {
        const auto file = encode_ktx2_cubemap(cube, ktx2_format::e5b9g9r9);
        const ktx2_info k = parse_ktx2(file);
        CHECK(k.vk_format == 123u);
        CHECK(k.type_size == 4u);
        REQUIRE(k.dfd.size() == 31); // 124 bytes: 6 samples
        CHECK(k.dfd[0] == 124u);
        CHECK(k.dfd[2] == (2u | (120u << 16)));
        CHECK(k.dfd[3] == (1u | (1u << 8) | (1u << 16)));
        CHECK(k.dfd[5] == 4u);
        // Per channel c: mantissa (channel c, no qualifier) offset 9c length 9, lower 0, upper 8448;
        // exponent (channel c | EXPONENT 0x20) offset 27 length 5, lower 15 (bias), upper 31.
        for (std::uint32_t c = 0; c < 3; ++c) {
            const std::size_t m = 7 + 8 * c, e = m + 4;
            CHECK(k.dfd[m] == ((9u * c) | (8u << 16) | (c << 24)));
            CHECK(k.dfd[m + 1] == 0u);
            CHECK(k.dfd[m + 2] == 0u);
            CHECK(k.dfd[m + 3] == 8448u);
            CHECK(k.dfd[e] == (27u | (4u << 16) | ((c | 0x20u) << 24)));
            CHECK(k.dfd[e + 1] == 0u);
            CHECK(k.dfd[e + 2] == 15u);
            CHECK(k.dfd[e + 3] == 31u);
        }
        const std::size_t at = std::size_t(k.levels[0].byte_offset);
        const std::uint32_t w = std::uint32_t(file[at]) | (std::uint32_t(file[at + 1]) << 8) |
                                (std::uint32_t(file[at + 2]) << 16) | (std::uint32_t(file[at + 3]) << 24);
        CHECK(w == (256u | (128u << 9) | (64u << 18) | (16u << 27)));
    }
}

TEST_CASE("ktx2 formats: decode reads all four formats back as the per-texel round trip") {
    const cubemap_rgb32f cube = varied_cube(8, 4, 3);
    for (ktx2_format f : {ktx2_format::rgba32f, ktx2_format::rgba16f, ktx2_format::b10g11r11, ktx2_format::e5b9g9r9}) {
        CAPTURE(std::uint32_t(f));
        const cubemap_rgb32f back = decode_ktx2_cubemap(encode_ktx2_cubemap(cube, f));
        REQUIRE(back.size == 8);
        REQUIRE(back.levels.size() == 4);
        for (std::size_t l = 0; l < 4; ++l)
            for (std::size_t face = 0; face < 6; ++face)
                for (std::size_t t = 0; t < cube.levels[l][face].size(); t += 3) {
                    float want[3];
                    ktx2_roundtrip_texel(f, cube.levels[l][face].data() + t, want);
                    for (std::size_t c = 0; c < 3; ++c) REQUIRE(back.levels[l][face][t + c] == want[c]);
                }
    }
}

TEST_CASE("ktx2 formats: clamp counts and the quantisation report") {
    SUBCASE("known relative errors") {
        // 1 + 2^-7 is a tie in R and G (rounds down to 1) and below half an ulp (2^-6) in B: every
        // value comes back as 1, relative error 2^-7 / (1 + 2^-7) exactly.
        const float x = 1.0f + 0x1p-7f;
        const auto rep = ktx2_quantisation_report(constant_cube(4, 3, x, x, x), ktx2_format::b10g11r11);
        REQUIRE(rep.size() == 3);
        const double want = 0x1p-7 / (1.0 + 0x1p-7);
        for (const auto& q : rep) {
            CHECK(q.values == std::size_t(6 * q.face_size * q.face_size * 3));
            CHECK(q.max_rel_error == doctest::Approx(want).epsilon(1e-12));
            CHECK(q.rms_rel_error == doctest::Approx(want).epsilon(1e-12));
            CHECK(q.floor == doctest::Approx(1e-3 * x).epsilon(1e-12));
            CHECK(q.above_range == 0);
            CHECK(q.negative_clamped == 0);
        }
        // Exactly representable values: no error in any format.
        for (ktx2_format f : {ktx2_format::rgba16f, ktx2_format::b10g11r11, ktx2_format::e5b9g9r9})
            for (const auto& q : ktx2_quantisation_report(constant_cube(4, 2, 1.0f, 0.5f, 0.25f), f)) {
                CHECK(q.max_rel_error == 0.0);
                CHECK(q.rms_rel_error == 0.0);
            }
    }
    SUBCASE("out-of-range values counted by the encoder and the report") {
        cubemap_rgb32f cube = constant_cube(2, 2, 1.0f, 1.0f, 1.0f);
        auto& f0 = cube.levels[0][0];
        f0[0] = 1e9f;   // above range
        f0[1] = -2.0f;  // negative
        f0[2] = qnan;   // NaN
        f0[3] = inf;    // above range
        ktx2_clamp_counts k;
        (void)encode_ktx2_cubemap(cube, ktx2_format::b10g11r11, "t", "<t>", &k);
        CHECK(k.above_range == 2);
        CHECK(k.negative == 1);
        CHECK(k.nan == 1);
        const auto rep = ktx2_quantisation_report(cube, ktx2_format::b10g11r11);
        CHECK(rep[0].above_range == 2);
        CHECK(rep[0].negative_clamped == 1);
        CHECK(rep[0].nan == 1);
        CHECK(rep[0].values == 6 * 4 * 3 - 1);
        // 1e9 -> 65024: relative error 1 - 65024/1e9; inf -> max: counted as 1.
        CHECK(rep[0].max_rel_error == doctest::Approx(1.0).epsilon(1e-9));
        CHECK(rep[1].above_range == 0);
        CHECK(rep[1].max_rel_error == 0.0);
        // The signed half format keeps negatives: none clamped; 1e9 is above 65504.
        ktx2_clamp_counts h;
        (void)encode_ktx2_cubemap(cube, ktx2_format::rgba16f, "t", "<t>", &h);
        CHECK(h.negative == 0);
        CHECK(h.above_range == 2);
    }
}

TEST_CASE("ktx2 formats: a file with a wrong typeSize or DFD is rejected with a message") {
    auto file = encode_ktx2_cubemap(constant_cube(2, 1, 1, 1, 1), ktx2_format::e5b9g9r9);
    auto bad = file;
    bad[16] = 2; // typeSize
    CHECK_THROWS_WITH_AS(decode_ktx2_cubemap(bad, "x.ktx2"), doctest::Contains("x.ktx2: unsupported KTX2 cubemap: typeSize 2"),
                         image_error);
    bad = file;
    bad[12] = 124; // vkFormat 124: not one of ours
    CHECK_THROWS_WITH_AS(decode_ktx2_cubemap(bad, "y.ktx2"), doctest::Contains("vkFormat 124"), image_error);
    CHECK_THROWS_WITH_AS(encode_ktx2_cubemap(constant_cube(2, 1, 1, 1, 1), ktx2_format(5)),
                         doctest::Contains("unsupported KTX2 format 5"), image_error);
}
