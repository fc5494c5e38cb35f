// tools/ibl-bake/tests/test_cube_layout.cpp — cube layouts (crosses, strips, face files, KTX2
// input) and the lat-long / octahedral outputs. The cross orientation is checked against the
// library's geometry only (cube_face_point, cube_lookup, cube_texel_direction): every pair of
// neighbouring pixels across every fold of a cross must be neighbouring texels on the cube.

#include <doctest/doctest.h>

#include "io/cube_layout.hpp"
#include "io/image_io.hpp"
#include "io/ktx2.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include <ibl/env/cube_geometry.hpp>
#include <ibl/env/latlong.hpp>

using namespace ibl_bake;

namespace {

// A smooth, non-symmetric function of the direction (every face and orientation differs).
ibl::vec3<double> field(const ibl::vec3<double>& d) {
    return {1.0 + 0.5 * d.x + 0.25 * d.y * d.y, 2.0 + d.y + 0.3 * d.z * d.x, 1.5 + 0.7 * d.z - 0.2 * d.x * d.y};
}

cube_faces field_faces(int n) {
    cube_faces c;
    c.size = n;
    for (int f = 0; f < 6; ++f) {
        image_rgb32f im(n, n);
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
                const ibl::vec3<double> v = field(ibl::cube_texel_direction<double>(f, x, y, n));
                im.texel(x, y)[0] = float(v.x);
                im.texel(x, y)[1] = float(v.y);
                im.texel(x, y)[2] = float(v.z);
            }
        c.face[std::size_t(f)] = std::move(im);
    }
    return c;
}

bool same_image(const image_rgb32f& a, const image_rgb32f& b) {
    return a.width == b.width && a.height == b.height && a.rgb.size() == b.rgb.size() &&
           std::memcmp(a.rgb.data(), b.rgb.data(), a.rgb.size() * sizeof(float)) == 0;
}

} // namespace

TEST_CASE("cube layout: detection from the aspect ratio, overrides, mis-sized images") {
    CHECK(detect_layout(512, 256, "a") == input_layout::latlong);
    CHECK(detect_layout(1024, 768, "a") == input_layout::cross_horizontal);
    CHECK(detect_layout(768, 1024, "a") == input_layout::cross_vertical);
    CHECK(detect_layout(1536, 256, "a") == input_layout::strip_horizontal);
    CHECK(detect_layout(256, 1536, "a") == input_layout::strip_vertical);
    CHECK_THROWS_WITH_AS(detect_layout(500, 300, "pano.hdr"),
                         doctest::Contains("pano.hdr: cannot tell the layout of a 500 x 300 image"), image_error);
    CHECK_THROWS_AS(detect_layout(0, 0, "z"), image_error);
    CHECK(resolve_layout(1024, 768, layout_choice::automatic, "a") == input_layout::cross_horizontal);
    CHECK(resolve_layout(1024, 768, layout_choice::cross_vertical, "a") == input_layout::cross_vertical);
    CHECK(parse_layout_choice("vcross") == layout_choice::cross_vertical);
    CHECK(parse_layout_choice("auto") == layout_choice::automatic);
    CHECK(!parse_layout_choice("cross").has_value());
    for (input_layout l : {input_layout::latlong, input_layout::cross_horizontal, input_layout::cross_vertical,
                           input_layout::strip_horizontal, input_layout::strip_vertical}) {
        const auto c = parse_layout_choice(layout_name(l));
        REQUIRE(c.has_value());
        CHECK(resolve_layout(6, 6, *c, "a") == l);
    }

    CHECK(layout_face_size(input_layout::cross_horizontal, 64, 48, "c") == 16);
    CHECK(layout_face_size(input_layout::cross_vertical, 48, 64, "c") == 16);
    CHECK_THROWS_WITH_AS(layout_face_size(input_layout::cross_horizontal, 10, 7, "c.exr"),
                         doctest::Contains("c.exr: a 10 x 7 image is not a horizontal cross (4:3, 4 x 3 square faces): "
                                           "width 10 is not a multiple of 4"),
                         image_error);
    CHECK_THROWS_WITH_AS(layout_face_size(input_layout::cross_horizontal, 8, 7, "c.exr"),
                         doctest::Contains("height 7 is not a multiple of 3"), image_error);
    CHECK_THROWS_WITH_AS(layout_face_size(input_layout::cross_horizontal, 8, 9, "c.exr"),
                         doctest::Contains("faces would be 2 x 3, not square"), image_error);
    // An explicit vertical cross on a horizontal-cross-shaped image: the size is still checked.
    const image_rgb32f wide(64, 48);
    CHECK_THROWS_WITH_AS(faces_from_layout(wide, input_layout::cross_vertical, "w.hdr"),
                         doctest::Contains("w.hdr: a 64 x 48 image is not a vertical cross"), image_error);
}

TEST_CASE("cube layout: every fold of both crosses is seamless on the sphere") {
    for (input_layout layout : {input_layout::cross_horizontal, input_layout::cross_vertical})
        for (int n : {1, 2, 5, 8}) {
            CAPTURE(layout_name(layout));
            CAPTURE(n);
            const int W = layout == input_layout::cross_horizontal ? 4 * n : 3 * n;
            const int H = layout == input_layout::cross_horizontal ? 3 * n : 4 * n;
            int folds = 0;
            for (int py = 0; py < H; ++py)
                for (int px = 0; px < W; ++px) {
                    const auto a = layout_texel(layout, n, px, py);
                    if (!a) continue;
                    const int step[2][2] = {{1, 0}, {0, 1}};
                    for (const auto& st : step) {
                        const auto b = layout_texel(layout, n, px + st[0], py + st[1]);
                        if (!b || b->face == a->face) continue;
                        ++folds;
                        // One image step from A, taken in A's face plane: the face-coordinate step
                        // follows the face's orientation in the image (found from the neighbours
                        // of A inside its own cell), the extended point is projected back onto the
                        // cube. It must land in B's texel; and the same from B towards A.
                        const auto check = [&](const face_texel& p, const face_texel& q, int ix, int iy, int dx, int dy) {
                            // Face step of an image step: compare with the texel one step the other way.
                            const auto back = layout_texel(layout, n, ix - dx, iy - dy);
                            int fx = dx, fy = dy;
                            if (back && back->face == p.face) {
                                fx = p.x - back->x;
                                fy = p.y - back->y;
                            } else if (n == 1) {
                                // 1 x 1 faces: orientation from the cell table (rotation flips the step).
                                fx = dx;
                                fy = dy;
                                if (layout == input_layout::cross_vertical && p.face == 5) {
                                    fx = -dx;
                                    fy = -dy;
                                }
                            }
                            const double inv = 2.0 / double(n);
                            const double sc = (double(p.x) + 0.5 + double(fx)) * inv - 1.0;
                            const double tc = (double(p.y) + 0.5 + double(fy)) * inv - 1.0;
                            const ibl::cube_coord<double> c = ibl::cube_lookup(ibl::cube_face_point<double>(p.face, sc, tc));
                            CHECK(c.face == q.face);
                            CHECK(std::min(int(c.s * n), n - 1) == q.x);
                            CHECK(std::min(int(c.t * n), n - 1) == q.y);
                            // And the two texel centres are about one texel apart on the sphere.
                            const double cosang = glm::dot(ibl::cube_texel_direction<double>(p.face, p.x, p.y, n),
                                                           ibl::cube_texel_direction<double>(q.face, q.x, q.y, n));
                            CHECK(std::acos(std::min(1.0, cosang)) < 1.6 * (2.0 / double(n)));
                        };
                        check(*a, *b, px, py, st[0], st[1]);
                        check(*b, *a, px + st[0], py + st[1], -st[0], -st[1]);
                    }
                }
            CHECK(folds == 5 * n); // 5 internal edges between the 6 cells of either cross
        }
    // Anchors: the centre cell of the row is +Z seen with +Y above it (image up = +y).
    const int n = 8;
    for (input_layout layout : {input_layout::cross_horizontal, input_layout::cross_vertical}) {
        const auto centre = layout_texel(layout, n, n + n / 2, n + n / 2);
        REQUIRE(centre);
        CHECK(centre->face == 4);
        const auto up = layout_texel(layout, n, n + n / 2, n - 1);
        REQUIRE(up);
        CHECK(up->face == 2);
        const auto left = layout_texel(layout, n, n - 1, n + n / 2);
        REQUIRE(left);
        CHECK(left->face == 1);
    }
    // -Z: right of +X in the horizontal cross, below -Y in the vertical one.
    CHECK(layout_texel(input_layout::cross_horizontal, n, 3 * n, n)->face == 5);
    CHECK(layout_texel(input_layout::cross_vertical, n, n, 3 * n)->face == 5);
    CHECK(!layout_texel(input_layout::cross_horizontal, n, 0, 0).has_value());
    CHECK(!layout_texel(input_layout::cross_vertical, n, 0, 3 * n).has_value());
}

TEST_CASE("cube layout: cross and strip round trips are bit-exact and hold the function") {
    const int n = 6;
    const cube_faces faces = field_faces(n);
    for (input_layout layout : {input_layout::cross_horizontal, input_layout::cross_vertical,
                                input_layout::strip_horizontal, input_layout::strip_vertical}) {
        CAPTURE(layout_name(layout));
        const image_rgb32f im = layout_from_faces(faces, layout);
        CHECK(detect_layout(im.width, im.height, "im") == layout);
        const cube_faces back = faces_from_layout(im, layout, "im");
        REQUIRE(back.size == n);
        for (std::size_t f = 0; f < 6; ++f) CHECK(same_image(back.face[f], faces.face[f]));
        CHECK(same_image(layout_from_faces(back, layout), im));
        // Every image pixel of a face cell holds the function at the direction of its face texel;
        // empty cells are 0.
        for (int py = 0; py < im.height; ++py)
            for (int px = 0; px < im.width; ++px) {
                const auto t = layout_texel(layout, n, px, py);
                const float* p = im.texel(px, py);
                if (!t) {
                    REQUIRE((p[0] == 0.0f && p[1] == 0.0f && p[2] == 0.0f));
                    continue;
                }
                const ibl::vec3<double> v = field(ibl::cube_texel_direction<double>(t->face, t->x, t->y, n));
                REQUIRE(p[0] == float(v.x));
                REQUIRE(p[1] == float(v.y));
                REQUIRE(p[2] == float(v.z));
            }
    }
    // The same through an ibl::cubemap.
    const ibl::cubemap<float> cube = cubemap_from_faces(faces);
    CHECK(cube.levels() == 3);
    const cube_faces again = faces_from_cubemap(cube, 0);
    for (std::size_t f = 0; f < 6; ++f) CHECK(same_image(again.face[f], faces.face[f]));
    CHECK(faces_from_cubemap(cube, 1).size == 3);
    CHECK_THROWS_AS(faces_from_cubemap(cube, 3), image_error);
    // Mismatched faces are refused.
    cube_faces broken = faces;
    broken.face[3] = image_rgb32f(5, 5);
    CHECK_THROWS_WITH_AS(layout_from_faces(broken, input_layout::cross_horizontal, "b"),
                         doctest::Contains("face 3 is 5 x 5, expected 6 x 6"), image_error);
}

TEST_CASE("cube layout: six face files and KTX2 cubemaps as inputs") {
    const auto paths = face_paths("dir/env_{face}.exr");
    CHECK(paths[0] == "dir/env_px.exr");
    CHECK(paths[1] == "dir/env_nx.exr");
    CHECK(paths[2] == "dir/env_py.exr");
    CHECK(paths[3] == "dir/env_ny.exr");
    CHECK(paths[4] == "dir/env_pz.exr");
    CHECK(paths[5] == "dir/env_nz.exr");
    CHECK(face_paths("{face}/{face}.hdr")[3] == "ny/ny.hdr");
    CHECK_THROWS_WITH_AS(face_paths("env.exr"), doctest::Contains("env.exr: a face file pattern must contain {face}"),
                         image_error);

    const cube_faces faces = field_faces(4);
    {
        std::array<image_rgb32f, 6> im = faces.face;
        im[2] = image_rgb32f(4, 3);
        CHECK_THROWS_WITH_AS(faces_from_images(im, paths), doctest::Contains("dir/env_py.exr: cube face is 4 x 3, not square"),
                             image_error);
        im[2] = image_rgb32f(8, 8);
        CHECK_THROWS_WITH_AS(faces_from_images(im, paths),
                             doctest::Contains("dir/env_py.exr: cube face is 8 x 8 but dir/env_px.exr is 4 x 4"), image_error);
    }

    const std::filesystem::path dir = std::filesystem::temp_directory_path() / "ibl_cube_layout_test";
    std::filesystem::create_directories(dir);
    const std::string pattern = (dir / "f_{face}.exr").string();
    const auto files = face_paths(pattern);
    for (std::size_t f = 0; f < 6; ++f) write_exr(files[f], faces.face[f]);
    const cube_faces read = read_face_files(pattern);
    for (std::size_t f = 0; f < 6; ++f) CHECK(same_image(read.face[f], faces.face[f])); // float32 EXR: lossless
    std::filesystem::remove(files[4]);
    CHECK_THROWS_WITH_AS(read_face_files(pattern), doctest::Contains("f_pz.exr"), image_error);
    std::filesystem::remove_all(dir);

    // KTX2 (float32): level 0 comes back as the faces, bit-exact.
    const ibl::cubemap<float> cube = cubemap_from_faces(faces);
    cubemap_rgb32f k = cubemap_rgb32f::zeros(4, cube.levels());
    for (int l = 0; l < cube.levels(); ++l) {
        const cube_faces lf = faces_from_cubemap(cube, l);
        for (std::size_t f = 0; f < 6; ++f) k.levels[std::size_t(l)][f] = lf.face[f].rgb;
    }
    const cubemap_rgb32f dec = decode_ktx2_cubemap(encode_ktx2_cubemap(k, ktx2_format::rgba32f));
    const cube_faces kf = faces_from_ktx2(dec);
    for (std::size_t f = 0; f < 6; ++f) CHECK(same_image(kf.face[f], faces.face[f]));
    CHECK(faces_from_ktx2(dec, 2).size == 1);
    CHECK_THROWS_WITH_AS(faces_from_ktx2(dec, 3, "e.ktx2"), doctest::Contains("e.ktx2: no level 3"), image_error);
}

TEST_CASE("cube layout: lat-long output, exact for constants, second-order accurate") {
    {
        ibl::cubemap<float> c(8, 2);
        c.fill(0, [](int, int, int) { return ibl::vec3<float>(0.3f, 1.5f, 7.0f); });
        c.fill(1, [](int, int, int) { return ibl::vec3<float>(2.0f, 2.0f, 2.0f); });
        c.update_borders();
        const image_rgb32f ll = latlong_from_cube(c, 0);
        CHECK(ll.width == 32);
        CHECK(ll.height == 16);
        for (std::size_t i = 0; i < ll.rgb.size(); i += 3) {
            REQUIRE(ll.rgb[i] == 0.3f);
            REQUIRE(ll.rgb[i + 1] == 1.5f);
            REQUIRE(ll.rgb[i + 2] == 7.0f);
        }
        const image_rgb32f l1 = latlong_from_cube(c, 1, 10);
        CHECK(l1.width == 10);
        CHECK(l1.height == 5);
        for (float v : l1.rgb) REQUIRE(v == 2.0f);
        CHECK_THROWS_AS(latlong_from_cube(c, 0, 7), image_error);
        CHECK_THROWS_AS(latlong_from_cube(c, 2), image_error);
    }
    // A smooth function sampled at texel centres, read back through seamless bilinear: away from
    // the cube's corners the error is the bilinear interpolation error, O(h^2) with h = 2/n the
    // texel size in face coordinates (folding a border texel onto the neighbouring face moves its
    // centre by O(h^2) too), so doubling n divides the RMS error by about 4. At the 8 corners the
    // border texel is the mean of three texels whose centres are not symmetric about the border
    // position: an O(h |grad f|) error in a region of a few texels, so the MAX error is first
    // order (halves with each doubling). Measured: RMS n = 16: 1.29e-3, 32: 3.05e-4, 64: 8.3e-5
    // (ratios 0.24, 0.27); max 9.2e-3, 3.2e-3, 1.6e-3 (ratios 0.34, 0.50).
    double rms[3], mx[3];
    const int sizes[3] = {16, 32, 64};
    for (int k = 0; k < 3; ++k) {
        const int n = sizes[k];
        ibl::cubemap<float> c(n, 1);
        c.fill(0, [&](int f, int x, int y) { return ibl::vec3<float>(field(ibl::cube_texel_direction<double>(f, x, y, n))); });
        c.update_borders();
        const image_rgb32f ll = latlong_from_cube(c, 0);
        double sq = 0.0, worst = 0.0;
        for (int j = 0; j < ll.height; ++j)
            for (int i = 0; i < ll.width; ++i) {
                const ibl::vec3<double> d = ibl::latlong_direction<double>((i + 0.5) / ll.width, 1.0 - (j + 0.5) / ll.height);
                const ibl::vec3<double> want = field(d);
                for (int ch = 0; ch < 3; ++ch) {
                    const double e = std::fabs(double(ll.texel(i, j)[ch]) - want[ch]);
                    sq += e * e;
                    worst = std::max(worst, e);
                }
            }
        rms[k] = std::sqrt(sq / double(ll.rgb.size()));
        mx[k] = worst;
        MESSAGE("lat-long from cube n = " << n << ": rms " << rms[k] << ", max " << mx[k]);
    }
    for (int k = 0; k < 2; ++k) {
        CHECK(rms[k + 1] / rms[k] < 0.3); // second order: 1/4, with slack for the corner regions
        CHECK(rms[k + 1] / rms[k] > 0.2);
        CHECK(mx[k + 1] / mx[k] < 0.55); // first order at the corners: 1/2
    }
}

TEST_CASE("cube layout: octahedral map") {
    // Mapping: centre +Y, corners -Y, edge midpoints +-X, +-Z; unit length; the boundary folds
    // onto itself (p and its mirror across an edge midpoint give the same direction).
    const auto near = [](ibl::vec3<float> a, ibl::vec3<float> b) { return glm::length(a - b) < 1e-6f; };
    CHECK(near(octahedral_direction(0, 0), {0, 1, 0}));
    CHECK(near(octahedral_direction(1, 1), {0, -1, 0}));
    CHECK(near(octahedral_direction(-1, 1), {0, -1, 0}));
    CHECK(near(octahedral_direction(1, 0), {1, 0, 0}));
    CHECK(near(octahedral_direction(-1, 0), {-1, 0, 0}));
    CHECK(near(octahedral_direction(0, 1), {0, 0, 1}));
    CHECK(near(octahedral_direction(0, -1), {0, 0, -1}));
    for (float t = -1.0f; t <= 1.0f; t += 0.125f) {
        CHECK(near(octahedral_direction(1, t), octahedral_direction(1, -t)));
        CHECK(near(octahedral_direction(t, -1), octahedral_direction(-t, -1)));
        CHECK(std::fabs(glm::length(octahedral_direction(t, 0.3f)) - 1.0f) < 1e-6f);
    }
    // The map is cube.bilinear at octahedral_direction of each texel centre (bit-exact), so its
    // accuracy is the lat-long test's; its RMS error converges at second order the same way.
    double rms[2];
    for (int k = 0; k < 2; ++k) {
        const int n = 16 << k;
        ibl::cubemap<float> c(n, 1);
        c.fill(0, [&](int f, int x, int y) { return ibl::vec3<float>(field(ibl::cube_texel_direction<double>(f, x, y, n))); });
        c.update_borders();
        const image_rgb32f oct = octahedral_from_cube(c, 0);
        REQUIRE(oct.width == 2 * n);
        REQUIRE(oct.height == 2 * n);
        double sq = 0.0;
        for (int j = 0; j < oct.height; ++j)
            for (int i = 0; i < oct.width; ++i) {
                const ibl::vec3<float> d =
                    octahedral_direction(float(2.0 * (i + 0.5) / oct.width - 1.0), float(2.0 * (j + 0.5) / oct.height - 1.0));
                const ibl::vec3<float> got = c.bilinear(d, 0);
                const ibl::vec3<double> want = field(ibl::vec3<double>(d));
                for (int ch = 0; ch < 3; ++ch) {
                    REQUIRE(oct.texel(i, j)[ch] == got[ch]);
                    sq += (double(got[ch]) - want[ch]) * (double(got[ch]) - want[ch]);
                }
            }
        rms[k] = std::sqrt(sq / double(oct.rgb.size()));
        MESSAGE("octahedral from cube n = " << n << ": rms " << rms[k]);
    }
    CHECK(rms[1] / rms[0] < 0.3);
    CHECK(rms[1] / rms[0] > 0.2);
}
