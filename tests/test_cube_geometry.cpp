// env/cube_geometry.hpp: the GL face table, texel centres, edge ties and exact solid angles.
#include <doctest/doctest.h>

#include <ibl/env/cube_geometry.hpp>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

namespace {
using d3 = ibl::vec3<double>;
}

TEST_CASE("cube faces follow the OpenGL sc/tc/ma table") {
    // Face centres point along their axes.
    const d3 axes[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    for (int f = 0; f < 6; ++f) {
        const d3 c = ibl::cube_direction(f, 0.5, 0.5);
        CHECK(glm::length(c - axes[f]) == doctest::Approx(0.0));
    }
    // (s, t) = (0, 0) is the corner (sc, tc) = (-1, -1). From the table:
    //   +X: (1, -tc, -sc) = (1, 1, 1);   -X: (-1, -tc, sc) = (-1, 1, -1)
    //   +Y: (sc, 1, tc) = (-1, 1, -1);   -Y: (sc, -1, -tc) = (-1, -1, 1)
    //   +Z: (sc, -tc, 1) = (-1, 1, 1);   -Z: (-sc, -tc, -1) = (1, 1, -1)
    const d3 corner00[6] = {{1, 1, 1}, {-1, 1, -1}, {-1, 1, -1}, {-1, -1, 1}, {-1, 1, 1}, {1, 1, -1}};
    for (int f = 0; f < 6; ++f) CHECK(ibl::cube_face_point(f, -1.0, -1.0) == corner00[f]);
    // Texel (0, 0) of an 8x8 +X face points toward (+, +, +): row 0 is t = 0, i.e. the top (+Y).
    const d3 d = ibl::cube_texel_direction<double>(0, 0, 0, 8);
    CHECK(d.x > 0);
    CHECK(d.y > 0);
    CHECK(d.z > 0);
}

TEST_CASE_TEMPLATE("cube_lookup inverts cube_direction at every texel centre", T, float, double) {
    // The round trip goes through a normalise and a divide: a few ulps in s and t.
    const T tol = T(8) * std::numeric_limits<T>::epsilon();
    for (int n : {1, 2, 7, 16}) {
        for (int f = 0; f < 6; ++f)
            for (int y = 0; y < n; ++y)
                for (int x = 0; x < n; ++x) {
                    const auto c = ibl::cube_lookup(ibl::cube_texel_direction<T>(f, x, y, n));
                    CHECK(c.face == f);
                    CHECK(std::fabs(c.s - (T(x) + T(0.5)) / T(n)) <= tol);
                    CHECK(std::fabs(c.t - (T(y) + T(0.5)) / T(n)) <= tol);
                }
    }
}

TEST_CASE("edge and corner directions get exactly one face; degenerate input is clamped") {
    // Exactly on the +X/+Y edge: X wins (ties X before Y before Z).
    CHECK(ibl::cube_lookup(d3(1, 1, 0)).face == 0);
    CHECK(ibl::cube_lookup(d3(0, 1, 1)).face == 2);
    CHECK(ibl::cube_lookup(d3(-1, -1, -1)).face == 1);
    const auto z = ibl::cube_lookup(d3(0, 0, 0));
    CHECK(z.face == 0);
    CHECK(z.s == 0.5);
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const auto q = ibl::cube_lookup(d3(nan, 0, 0));
    CHECK(q.face >= 0);
    CHECK(q.face < 6);
    CHECK(std::isfinite(q.s));
    // Coordinates on an edge are exactly 0 or 1.
    const auto e = ibl::cube_lookup(d3(1, 1, 0.25));
    CHECK(e.t == 0.0); // +X face: tc = -ry / |rx| = -1 -> t = 0
}

TEST_CASE_TEMPLATE("cube_face_solid_angles is cube_texel_solid_angle at every texel, from the corners", T, float, double) {
    for (int n : {1, 2, 3, 7, 64, 257}) {
        const std::vector<T> table = ibl::cube_face_solid_angles<T>(n);
        REQUIRE(table.size() == std::size_t(n) * std::size_t(n));
        int differ = 0;
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x)
                differ += table[std::size_t(y) * std::size_t(n) + std::size_t(x)] == ibl::cube_texel_solid_angle<T>(x, y, n) ? 0 : 1;
        CHECK(differ == 0); // the same four antiderivative values in the same order: the same bits
    }
    CHECK(ibl::cube_face_solid_angles<double>(0).empty());
}

TEST_CASE("texel solid angles are exact: sum 4 pi, match the face integral, symmetric") {
    for (int n : {1, 2, 3, 7, 64, 256}) {
        double face = 0;
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) face += ibl::cube_texel_solid_angle<double>(x, y, n);
        // A face is 4 pi / 6 exactly; summing n^2 terms of ~4pi/(6 n^2) costs ~n^2 eps relative.
        CHECK(face == doctest::Approx(4.0 * ibl::pi_v<double> / 6.0).epsilon(1e-15 * n * n + 1e-15));
        // Mirror symmetry of the face.
        CHECK(ibl::cube_texel_solid_angle<double>(0, 0, n) ==
              doctest::Approx(ibl::cube_texel_solid_angle<double>(n - 1, n - 1, n)).epsilon(1e-12));
    }
    // Against an independent midpoint-rule integral of da db / (1 + a^2 + b^2)^(3/2) over one
    // texel of a 4x4 face (texel (1, 0)); 400^2 midpoints: error ~ h^2 |f''| / 24 < 1e-7 relative.
    const int m = 400;
    const double a0 = -0.5, b0 = -1.0, h = 0.5 / m;
    double q = 0;
    for (int i = 0; i < m; ++i)
        for (int j = 0; j < m; ++j) {
            const double a = a0 + (i + 0.5) * h, b = b0 + (j + 0.5) * h;
            q += h * h / std::pow(1 + a * a + b * b, 1.5);
        }
    CHECK(ibl::cube_texel_solid_angle<double>(1, 0, 4) == doctest::Approx(q).epsilon(1e-7));
    // A 1x1 face: 4 pi / 6.
    CHECK(ibl::cube_texel_solid_angle<double>(0, 0, 1) == doctest::Approx(4.0 * ibl::pi_v<double> / 6.0));
}
