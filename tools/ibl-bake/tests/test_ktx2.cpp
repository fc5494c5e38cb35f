// tools/ibl-bake/tests/test_ktx2.cpp — the KTX2 cubemap writer, checked by parsing the bytes
// back: header fields, level index (sizes, order, alignment), DFD, key/value data, face order
// and a texel read at an offset computed independently of the writer; half-float conversion.

#include <doctest/doctest.h>

#include "io/image_io.hpp"
#include "io/ktx2.hpp"

#include <bit>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <string>

using namespace ibl_bake;

namespace {

// A value that identifies (level, face, x, y, channel); exact in half precision for the sizes
// used (small integers and eighths).
float tag(int level, int face, int x, int y, int c) { return float(level * 64 + face * 8 + c) + float(x + 2 * y) / 8.0f; }

cubemap_rgb32f tagged_cube(int size, int levels) {
    cubemap_rgb32f cube = cubemap_rgb32f::zeros(size, levels);
    for (int l = 0; l < levels; ++l) {
        const int s = cube.face_size(l);
        for (int f = 0; f < 6; ++f)
            for (int y = 0; y < s; ++y)
                for (int x = 0; x < s; ++x)
                    for (int c = 0; c < 3; ++c)
                        cube.levels[std::size_t(l)][std::size_t(f)][std::size_t(3 * (y * s + x) + c)] = tag(l, f, x, y, c);
    }
    return cube;
}

std::uint32_t u32_at(const std::vector<unsigned char>& b, std::size_t at) {
    return std::uint32_t(b[at]) | (std::uint32_t(b[at + 1]) << 8) | (std::uint32_t(b[at + 2]) << 16) |
           (std::uint32_t(b[at + 3]) << 24);
}

} // namespace

TEST_CASE("ktx2: float32 cubemap layout parsed back field by field") {
    const int n = 8, L = 4;
    const auto file = encode_ktx2_cubemap(tagged_cube(n, L), ktx2_format::rgba32f, "ibl-bake test");
    // Identifier and header at their fixed offsets (read by hand, not through parse_ktx2).
    const unsigned char id[12] = {0xAB, 0x4B, 0x54, 0x58, 0x20, 0x32, 0x30, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A};
    CHECK(std::memcmp(file.data(), id, 12) == 0);
    CHECK(u32_at(file, 12) == 109u); // VK_FORMAT_R32G32B32A32_SFLOAT
    CHECK(u32_at(file, 16) == 4u);   // typeSize
    CHECK(u32_at(file, 36) == 6u);   // faceCount

    const ktx2_info k = parse_ktx2(file);
    CHECK(k.vk_format == 109u);
    CHECK(k.type_size == 4u);
    CHECK(k.pixel_width == 8u);
    CHECK(k.pixel_height == 8u);
    CHECK(k.pixel_depth == 0u);
    CHECK(k.layer_count == 0u);
    CHECK(k.face_count == 6u);
    CHECK(k.level_count == 4u);
    CHECK(k.supercompression == 0u);
    CHECK(k.sgd_offset == 0u);
    CHECK(k.sgd_length == 0u);
    CHECK(k.dfd_offset == 80u + 24u * 4u);
    REQUIRE(k.levels.size() == 4);
    for (std::size_t l = 0; l < 4; ++l) {
        const std::uint64_t s = std::uint64_t(n >> l);
        CHECK(k.levels[l].byte_length == 6 * s * s * 16);
        CHECK(k.levels[l].uncompressed_byte_length == k.levels[l].byte_length);
        CHECK(k.levels[l].byte_offset % 16 == 0);
        if (l > 0) CHECK(k.levels[l].byte_offset < k.levels[l - 1].byte_offset); // smallest level first in the file
    }
    CHECK(k.levels[0].byte_offset + k.levels[0].byte_length == file.size());
    // DFD: total 92 bytes, basic block of 88 bytes, RGBSDA / BT709 / linear, 16 bytes a texel,
    // four float samples of 32 bits at offsets 0, 32, 64, 96, channels R G B A.
    REQUIRE(k.dfd.size() == 23);
    CHECK(k.dfd[0] == 92u);
    CHECK(k.dfd[1] == 0u);
    CHECK(k.dfd[2] == (2u | (88u << 16)));
    CHECK(k.dfd[3] == (1u | (1u << 8) | (1u << 16)));
    CHECK(k.dfd[5] == 16u);
    const std::uint32_t channels[4] = {0, 1, 2, 15};
    for (std::uint32_t c = 0; c < 4; ++c) {
        const std::uint32_t* s = &k.dfd[7 + 4 * c];
        CHECK((s[0] & 0xffffu) == 32u * c);
        CHECK(((s[0] >> 16) & 0xffu) == 31u);
        CHECK((s[0] >> 24) == (channels[c] | 0xC0u));
        CHECK(s[2] == 0xBF800000u);
        CHECK(s[3] == 0x3F800000u);
    }
    REQUIRE(k.key_values.size() == 1);
    CHECK(k.key_values[0].first == "KTXwriter");
    CHECK(k.key_values[0].second == "ibl-bake test");

    // A texel by hand: level 1 (4 x 4), face 3 (-Y), x = 2, y = 1, green; faces in the order
    // +X -X +Y -Y +Z -Z, rows from t = 0, RGBA float.
    const std::size_t s1 = 4;
    const std::size_t at = std::size_t(k.levels[1].byte_offset) + ((3 * s1 + 1) * s1 + 2) * 16 + 4;
    CHECK(std::bit_cast<float>(u32_at(file, at)) == tag(1, 3, 2, 1, 1));
    CHECK(std::bit_cast<float>(u32_at(file, at + 8)) == 1.0f); // alpha

    // The whole chain reads back exactly.
    const cubemap_rgb32f back = decode_ktx2_cubemap(file);
    const cubemap_rgb32f ref = tagged_cube(n, L);
    CHECK(back.size == n);
    CHECK(back.levels == ref.levels);
}

TEST_CASE("ktx2: half-float cubemap (RGBA16F) and a file on disk") {
    const cubemap_rgb32f cube = tagged_cube(4, 3);
    const auto file = encode_ktx2_cubemap(cube, ktx2_format::rgba16f);
    const ktx2_info k = parse_ktx2(file);
    CHECK(k.vk_format == 97u);
    CHECK(k.type_size == 2u);
    CHECK(k.dfd[5] == 8u);
    CHECK(((k.dfd[7 + 4] >> 16) & 0xffu) == 15u); // bitLength - 1 of G
    CHECK((k.dfd[7 + 4] & 0xffffu) == 16u);        // bitOffset of G
    for (std::size_t l = 0; l < 3; ++l) CHECK(k.levels[l].byte_offset % 8 == 0);
    CHECK(decode_ktx2_cubemap(file).levels == cube.levels); // tags are exact in half

    const std::string path = (std::filesystem::temp_directory_path() / "ibl_bake_test_cube.ktx2").string();
    write_ktx2_cubemap(path, cube, ktx2_format::rgba32f);
    CHECK(decode_ktx2_cubemap(read_file(path)).levels == cube.levels);
    std::filesystem::remove(path);
}

TEST_CASE("ktx2: inconsistent cubemaps and damaged files are refused") {
    cubemap_rgb32f c = cubemap_rgb32f::zeros(4, 3);
    c.levels[1][2].pop_back();
    CHECK_THROWS_AS((void)encode_ktx2_cubemap(c, ktx2_format::rgba32f), image_error);
    CHECK_THROWS_AS((void)encode_ktx2_cubemap(cubemap_rgb32f::zeros(4, 4), ktx2_format::rgba32f), image_error);
    CHECK_THROWS_AS((void)encode_ktx2_cubemap(cubemap_rgb32f::zeros(0, 1), ktx2_format::rgba32f), image_error);
    const auto file = encode_ktx2_cubemap(cubemap_rgb32f::zeros(4, 3), ktx2_format::rgba32f);
    CHECK_THROWS_AS((void)parse_ktx2(std::span(file).first(60)), image_error);
    CHECK_THROWS_AS((void)decode_ktx2_cubemap(std::span(file).first(file.size() - 1)), image_error);
    auto bad = file;
    bad[0] = 0;
    CHECK_THROWS_AS((void)parse_ktx2(bad), image_error);
}

TEST_CASE("ktx2: float -> half rounding, clamping and the exact inverse") {
    CHECK(float_to_half(1.0f) == 0x3C00);
    CHECK(float_to_half(-2.0f) == 0xC000);
    CHECK(float_to_half(0.0f) == 0x0000);
    CHECK(float_to_half(-0.0f) == 0x8000);
    CHECK(float_to_half(65504.0f) == 0x7BFF);
    CHECK(float_to_half(1e6f) == 0x7BFF); // clamped, not infinity (documented)
    CHECK(float_to_half(std::numeric_limits<float>::infinity()) == 0x7C00);
    CHECK((float_to_half(std::numeric_limits<float>::quiet_NaN()) & 0x7C00) == 0x7C00);
    CHECK(float_to_half(0x1p-24f) == 0x0001);            // smallest subnormal
    CHECK(float_to_half(0x1p-25f) == 0x0000);            // tie -> even (0)
    CHECK(float_to_half(0x1.8p-25f) == 0x0001);          // above the tie
    CHECK(float_to_half(0x1p-14f) == 0x0400);            // smallest normal
    CHECK(float_to_half(1.0f + 0x1p-11f) == 0x3C00);     // tie -> even
    CHECK(float_to_half(1.0f + 3 * 0x1p-11f) == 0x3C02); // tie -> even (up)
    CHECK(float_to_half(0x1.ffcp-15f) == 0x0400);        // subnormal rounding carries into the exponent
    // Every finite half converts to float and back unchanged.
    for (std::uint32_t h = 0; h < 0x10000u; ++h) {
        if ((h & 0x7C00u) == 0x7C00u) continue; // inf / NaN
        const float f = half_to_float(static_cast<std::uint16_t>(h));
        if (float_to_half(f) != h) FAIL("half " << h << " does not round-trip");
    }
    CHECK(half_to_float(0x3555) == 0.333251953125f);
}
