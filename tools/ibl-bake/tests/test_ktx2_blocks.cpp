// tools/ibl-bake/tests/test_ktx2_blocks.cpp — the block-compressed HDR formats of the KTX2 writer
// (BC6H_UFLOAT, ASTC 4x4 / 6x6 SFLOAT) and its Zstandard supercompression: header fields and the
// data format descriptor word by word against the Khronos Data Format Specification (as
// KTX-Software writes these formats), every level down to 1x1 stored as whole blocks, decoded
// values against the input (RMSLE bounds from the formats' precision), the input policy (NaN,
// negatives, infinities, values above the half range), encoder threads that do not change a byte,
// Zstandard levels that inflate to the same texels, and damaged or hostile files refused.

#include <doctest/doctest.h>

#include "io/block_codec.hpp"
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

std::uint32_t u32(const std::vector<unsigned char>& b, std::size_t at) {
    return std::uint32_t(b[at]) | std::uint32_t(b[at + 1]) << 8 | std::uint32_t(b[at + 2]) << 16 | std::uint32_t(b[at + 3]) << 24;
}
void put_u32(std::vector<unsigned char>& b, std::size_t at, std::uint32_t v) {
    for (int i = 0; i < 4; ++i) b[at + std::size_t(i)] = static_cast<unsigned char>(v >> (8 * i));
}

/// A smooth HDR cube: a sky-like gradient over four decades with a bright spot on +Y (a "sun"
/// 1e4 x the rest), each level the 2 x 2 box of the one above (what a chain looks like).
cubemap_rgb32f hdr_cube(int n, int levels, bool with_sun = true) {
    cubemap_rgb32f c = cubemap_rgb32f::zeros(n, levels);
    for (int f = 0; f < 6; ++f)
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
                const double u = (x + 0.5) / n, v = (y + 0.5) / n;
                const double base = std::exp2(8.0 * v - 4.0 + 0.5 * f) * (1.0 + 0.3 * std::sin(7.0 * u + f));
                const bool sun = with_sun && f == 2 && std::abs(x - n / 2) <= 1 && std::abs(y - n / 2) <= 1;
                float* t = c.levels[0][std::size_t(f)].data() + 3 * (std::size_t(y) * std::size_t(n) + std::size_t(x));
                t[0] = float(base * (sun ? 1e4 : 1.0));
                t[1] = float(base * 0.8 * (sun ? 1e4 : 1.0));
                t[2] = float(base * (0.6 + 0.4 * u));
            }
    for (int l = 1; l < levels; ++l) {
        const int s = c.face_size(l), p = c.face_size(l - 1);
        for (int f = 0; f < 6; ++f)
            for (int y = 0; y < s; ++y)
                for (int x = 0; x < s; ++x)
                    for (int ch = 0; ch < 3; ++ch) {
                        double sum = 0.0;
                        for (int dy = 0; dy < 2; ++dy)
                            for (int dx = 0; dx < 2; ++dx) {
                                const int sx = std::min(2 * x + dx, p - 1), sy = std::min(2 * y + dy, p - 1);
                                sum += c.levels[std::size_t(l - 1)][std::size_t(f)][3 * (std::size_t(sy) * std::size_t(p) + std::size_t(sx)) + std::size_t(ch)];
                            }
                        c.levels[std::size_t(l)][std::size_t(f)][3 * (std::size_t(y) * std::size_t(s) + std::size_t(x)) + std::size_t(ch)] = float(0.25 * sum);
                    }
    }
    return c;
}

/// RMS over the values of level l of ln(1 + x') - ln(1 + x).
double rmsle(const cubemap_rgb32f& a, const cubemap_rgb32f& b, std::size_t l) {
    double sq = 0.0;
    std::size_t n = 0;
    for (std::size_t f = 0; f < 6; ++f)
        for (std::size_t i = 0; i < a.levels[l][f].size(); ++i) {
            const double d = std::log1p(double(b.levels[l][f][i])) - std::log1p(double(a.levels[l][f][i]));
            sq += d * d;
            ++n;
        }
    return std::sqrt(sq / double(n));
}

const ktx2_format block_formats[] = {ktx2_format::bc6h, ktx2_format::astc4x4, ktx2_format::astc6x6};

} // namespace

TEST_CASE("ktx2 blocks: header, level index and data format descriptor of each block format") {
    const int n = 16, L = 5; // 16, 8, 4, 2, 1: the last three levels are one block per face
    const cubemap_rgb32f cube = hdr_cube(n, L);
    for (ktx2_format f : block_formats) {
        CAPTURE(std::uint32_t(f));
        const std::vector<unsigned char> b = encode_ktx2_cubemap(cube, f, "test", "<t>", nullptr, {}, {block_quality::fast, 0, 1});
        const ktx2_info k = parse_ktx2(b);
        CHECK(k.vk_format == std::uint32_t(f));
        CHECK(k.type_size == 1);
        CHECK(k.pixel_width == 16);
        CHECK(k.face_count == 6);
        CHECK(k.level_count == 5);
        CHECK(k.supercompression == 0);
        const int dim = f == ktx2_format::astc6x6 ? 6 : 4;
        for (int l = 0; l < L; ++l) {
            const std::size_t s = std::size_t(std::max(1, n >> l)), blocks = (s + std::size_t(dim) - 1) / std::size_t(dim);
            CHECK(k.levels[std::size_t(l)].byte_length == 6 * blocks * blocks * 16);
            CHECK(k.levels[std::size_t(l)].uncompressed_byte_length == k.levels[std::size_t(l)].byte_length);
            CHECK(k.levels[std::size_t(l)].byte_offset % 16 == 0);
        }
        CHECK(k.levels[0].byte_offset > k.levels[1].byte_offset); // smallest level first in the file
        // DFD: dfdTotalSize, vendor/type, version 2 | block size 40, model | primaries | transfer,
        // texelBlockDimension, bytesPlane0, then one sample.
        REQUIRE(k.dfd.size() == 11);
        CHECK(k.dfd[0] == 44);
        CHECK(k.dfd[1] == 0);
        CHECK(k.dfd[2] == (2u | (40u << 16)));
        CHECK(k.dfd[3] == ((f == ktx2_format::bc6h ? 131u : 162u) | (1u << 8) | (1u << 16)));
        CHECK(k.dfd[4] == (std::uint32_t(dim - 1) | (std::uint32_t(dim - 1) << 8)));
        CHECK(k.dfd[5] == 16);
        CHECK(k.dfd[6] == 0);
        const std::uint32_t qualifiers = f == ktx2_format::bc6h ? 0x80u : 0xC0u;
        CHECK(k.dfd[7] == (0u | (127u << 16) | (qualifiers << 24)));
        CHECK(k.dfd[8] == 0);
        CHECK(k.dfd[9] == (f == ktx2_format::bc6h ? 0u : 0xBF800000u));
        CHECK(k.dfd[10] == 0x3F800000u);
    }
}

TEST_CASE("ktx2 blocks: decoded levels near the input, every level, both encoder efforts") {
    const int n = 32, L = 6;
    const cubemap_rgb32f smooth = hdr_cube(n, L, false), cube = hdr_cube(n, L);
    for (ktx2_format f : block_formats)
        for (block_quality q : {block_quality::fast, block_quality::normal}) {
            CAPTURE(std::uint32_t(f));
            CAPTURE(int(q));
            // Smooth HDR content over four decades: a few percent in log terms where a block
            // spans a few texels of the gradient (levels 0, 1); the 4^2 and smaller levels put a
            // 256x range with a cross-wise ripple into one block, which one line of endpoints
            // cannot follow. An undecodable or misplaced block gives RMSLE ~2 here.
            const cubemap_rgb32f ds = decode_ktx2_cubemap(encode_ktx2_cubemap(smooth, f, "t", "<t>", nullptr, {}, {q, 0, 2}));
            for (std::size_t l = 0; l < smooth.levels.size(); ++l) {
                CAPTURE(l);
                CHECK(rmsle(smooth, ds, l) < (l < 2 ? (f == ktx2_format::astc6x6 ? 0.05 : 0.03) : 0.1));
            }
            // With a sun 1e4 x the sky: blocks that hold both cannot keep both (one pair of
            // endpoints per subset, interpolated); level 0 stays close, the small levels where the
            // sun's blocks are a large share of the face are looser.
            const cubemap_rgb32f d = decode_ktx2_cubemap(encode_ktx2_cubemap(cube, f, "t", "<t>", nullptr, {}, {q, 0, 2}));
            REQUIRE(d.levels.size() == cube.levels.size());
            CHECK(rmsle(cube, d, 0) < 0.05);
            for (std::size_t l = 1; l < cube.levels.size(); ++l) {
                CAPTURE(l);
                CHECK(rmsle(cube, d, l) < 0.35);
            }
            // The quantisation report compares the same decoded values.
            const auto qr = ktx2_quantisation_report(cube, f, &d);
            REQUIRE(qr.size() == cube.levels.size());
            CHECK(qr[0].rms_rel_error < 0.15);
            CHECK(qr[0].above_range == 0);
        }
}

TEST_CASE("ktx2 blocks: encoder threads do not change a byte") {
    const cubemap_rgb32f cube = hdr_cube(64, 3);
    for (ktx2_format f : block_formats) {
        CAPTURE(std::uint32_t(f));
        const auto a = encode_ktx2_cubemap(cube, f, "t", "<t>", nullptr, {}, {block_quality::fast, 0, 1});
        const auto b = encode_ktx2_cubemap(cube, f, "t", "<t>", nullptr, {}, {block_quality::fast, 0, 2});
        CHECK(a == b);
    }
}

TEST_CASE("ktx2 blocks: input policy for NaN, negatives, infinities and values above the half range") {
    cubemap_rgb32f c = cubemap_rgb32f::zeros(4, 1);
    const float special[] = {std::numeric_limits<float>::quiet_NaN(), -3.0f, std::numeric_limits<float>::infinity(), 1e6f,
                             -std::numeric_limits<float>::infinity(), 2.0f};
    for (auto& face : c.levels[0])
        for (std::size_t i = 0; i < face.size(); ++i) face[i] = special[i % 6];
    for (ktx2_format f : block_formats) {
        CAPTURE(std::uint32_t(f));
        ktx2_clamp_counts counts;
        const auto bytes = encode_ktx2_cubemap(c, f, "t", "<t>", &counts, {}, {});
        CHECK(counts.nan == 6 * 16 * 3 / 6);
        CHECK(counts.negative == 6 * 16 * 3 * 2 / 6);
        CHECK(counts.above_range == 6 * 16 * 3 * 2 / 6);
        const cubemap_rgb32f d = decode_ktx2_cubemap(bytes);
        for (const auto& face : d.levels[0])
            for (float x : face) {
                CHECK(std::isfinite(x));
                CHECK(x >= 0.0f);
                CHECK(x <= 65504.0f);
            }
    }
}

TEST_CASE("ktx2 blocks: Zstandard supercompression inflates to the same texels; damaged levels refused") {
    const cubemap_rgb32f cube = hdr_cube(32, 6);
    for (ktx2_format f : {ktx2_format::rgba16f, ktx2_format::bc6h, ktx2_format::astc4x4}) {
        CAPTURE(std::uint32_t(f));
        const auto plain = encode_ktx2_cubemap(cube, f, "t", "<t>", nullptr, {}, {block_quality::fast, 0, 1});
        const auto z = encode_ktx2_cubemap(cube, f, "t", "<t>", nullptr, {}, {block_quality::fast, 19, 1});
        const ktx2_info k = parse_ktx2(z), kp = parse_ktx2(plain);
        CHECK(k.supercompression == 2);
        CHECK(z.size() < plain.size());
        for (std::size_t l = 0; l < k.levels.size(); ++l) CHECK(k.levels[l].uncompressed_byte_length == kp.levels[l].byte_length);
        CHECK(k.dfd == kp.dfd); // the DFD describes the inflated data
        const cubemap_rgb32f a = decode_ktx2_cubemap(plain), b = decode_ktx2_cubemap(z);
        CHECK(a.levels == b.levels);
        // A flipped byte inside level 0's frame, a wrong inflated length: clear errors.
        std::vector<unsigned char> bad = z;
        bad[std::size_t(k.levels[0].byte_offset + k.levels[0].byte_length / 2)] ^= 0x5A;
        CHECK_THROWS_AS(decode_ktx2_cubemap(bad), image_error);
        bad = z;
        put_u32(bad, 80 + 16, u32(bad, 80 + 16) + 16); // level 0's uncompressedByteLength
        CHECK_THROWS_AS(decode_ktx2_cubemap(bad), image_error);
    }
    CHECK_THROWS_AS(encode_ktx2_cubemap(cube, ktx2_format::bc6h, "t", "<t>", nullptr, {}, {block_quality::fast, 23, 1}), image_error);
}

TEST_CASE("ktx2 blocks: a header claiming a huge cube is refused before allocating") {
    const cubemap_rgb32f cube = hdr_cube(8, 1);
    std::vector<unsigned char> b = encode_ktx2_cubemap(cube, ktx2_format::bc6h, "t", "<t>", nullptr, {}, {block_quality::fast, 3, 1});
    put_u32(b, 20, 65536); // pixelWidth
    put_u32(b, 24, 65536);
    CHECK_THROWS_AS(decode_ktx2_cubemap(b), image_error);
    // a block file with the wrong typeSize or bytesPlane0
    std::vector<unsigned char> p = encode_ktx2_cubemap(cube, ktx2_format::astc4x4, "t", "<t>", nullptr, {}, {block_quality::fast, 0, 1});
    std::vector<unsigned char> t = p;
    put_u32(t, 16, 4);
    CHECK_THROWS_AS(decode_ktx2_cubemap(t), image_error);
    const ktx2_info k = parse_ktx2(p);
    put_u32(p, k.dfd_offset + 20, 8);
    CHECK_THROWS_AS(decode_ktx2_cubemap(p), image_error);
}

TEST_CASE("block codec: image sizes and partial blocks") {
    CHECK(block_image_bytes(ktx2_format::bc6h, 1) == 16);
    CHECK(block_image_bytes(ktx2_format::bc6h, 5) == 4 * 16);
    CHECK(block_image_bytes(ktx2_format::astc6x6, 13) == 9 * 16);
    CHECK(ktx2_block_dim(ktx2_format::rgba16f) == 1);
    CHECK_FALSE(ktx2_block_compressed(ktx2_format::e5b9g9r9));
    // a 5 x 5 image: its partial blocks decode to the image's own texels
    for (ktx2_format f : block_formats) {
        std::vector<float> img(5 * 5 * 3);
        // a gradient of one colour (a line in RGB: what one subset's endpoints represent)
        const double tint[3] = {1.0, 0.8, 0.6};
        for (std::size_t i = 0; i < img.size(); ++i) {
            const std::size_t t = i / 3, x = t % 5, y = t / 5;
            img[i] = float((1.0 + 0.1 * double(x) + 0.05 * double(y)) * tint[i % 3]);
        }
        const auto blocks = encode_block_image(f, img.data(), 5, block_quality::normal);
        const auto back = decode_block_image(f, blocks.data(), blocks.size(), 5);
        REQUIRE(back.size() == img.size());
        double worst = 0.0;
        for (std::size_t i = 0; i < img.size(); ++i) worst = std::max(worst, std::fabs(double(back[i]) / img[i] - 1.0));
        // BC6H interpolates the half bits (close to log2) with 8 or 16 weights, ASTC HDR its
        // log-like LNS codes: a 60% linear ramp is followed within about half a weight step
        CAPTURE(std::uint32_t(f));
        CHECK(worst < 0.04);
        CHECK_THROWS_AS(decode_block_image(f, blocks.data(), blocks.size() - 16, 5), image_error);
    }
}
