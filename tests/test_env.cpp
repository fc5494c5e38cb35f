// env/: environment concept, cubemap (seamless bilinear, trilinear, exact spherical mips),
// latlong (mapping, seam, poles, mips), analytic environments and their oracles, conversions.
#include <doctest/doctest.h>

#include <ibl/core/frame.hpp>
#include <ibl/env.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <vector>

namespace {

template <class T> using v3 = ibl::vec3<T>;

template <class T> T max_abs(const v3<T>& a) { return std::max({std::fabs(a.x), std::fabs(a.y), std::fabs(a.z)}); }

/// Deterministic uniform directions on the sphere (xorshift + area-preserving map).
struct dir_gen {
    std::uint64_t s = 0x9E3779B97F4A7C15ull;
    double uniform() {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        return double(s >> 11) * 0x1p-53;
    }
    template <class T> v3<T> next() {
        const double z = 1.0 - 2.0 * uniform(), phi = ibl::two_pi_v<double> * uniform();
        const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
        return v3<T>(v3<double>(r * std::cos(phi), r * std::sin(phi), z));
    }
};

/// The smooth test function of the brief: L(d) = d.x + 2 d.y + 3 d.z + 4 (grey).
template <class T> v3<T> linear_fn(const v3<T>& d) { return v3<T>(d.x + T(2) * d.y + T(3) * d.z + T(4)); }
constexpr double linear_grad = 3.7416573867739413; // |(1, 2, 3)|

/// The 12 edges and 8 corners of the cube, as directions with components in {-1, 0(free), 1}.
std::vector<v3<double>> cube_corners() {
    std::vector<v3<double>> c;
    for (int i = 0; i < 8; ++i) c.emplace_back(i & 1 ? 1 : -1, i & 2 ? 1 : -1, i & 4 ? 1 : -1);
    return c;
}

} // namespace

// ---------------------------------------------------------------------------------------------
// concept

TEST_CASE("environment concept: models and lod helpers") {
    static_assert(ibl::environment<ibl::cubemap<float>, float>);
    static_assert(ibl::environment<ibl::latlong<double>, double>);
    static_assert(ibl::environment<ibl::constant_environment<float>, float>);
    static_assert(ibl::environment<ibl::sky_environment<float>, float>);
    auto lam = ibl::make_lambda_environment<float>([](const v3<float>& d) { return d; });
    static_assert(ibl::environment<decltype(lam), float>);
    CHECK(lam.radiance(v3<float>(0, 1, 0), 3.f) == v3<float>(0, 1, 0));
    CHECK(ibl::env_max_lod<float>(lam) == 0.f);
    CHECK(ibl::env_lod_for_solid_angle(lam, 0.1f) == 0.f);

    const ibl::cubemap<double> c(16); // levels 16, 8, 4, 2, 1
    CHECK(c.levels() == 5);
    CHECK(ibl::env_max_lod<double>(c) == 4.0);
    // Power-of-two chain: Omega(lod) = Omega_0 4^lod, and lod_for_solid_angle inverts it
    // (log2/exp2 round trip: a few ulps of the lod).
    const double omega0 = ibl::four_pi_v<double> / (6.0 * 256.0);
    for (double lod : {0.0, 0.25, 1.0, 2.5, 3.999, 4.0}) {
        CHECK(c.texel_solid_angle(lod) == doctest::Approx(omega0 * std::pow(4.0, lod)).epsilon(1e-14));
        CHECK(ibl::env_lod_for_solid_angle(c, c.texel_solid_angle(lod)) == doctest::Approx(lod).epsilon(1e-12));
    }
    CHECK(c.lod_for_solid_angle(omega0 / 10) == 0.0);                 // finer than the map: lod 0
    CHECK(c.lod_for_solid_angle(100.0) == 4.0);                       // coarser than 1x1: clamp
    CHECK(c.lod_for_solid_angle(std::numeric_limits<double>::quiet_NaN()) == 0.0);
}

// ---------------------------------------------------------------------------------------------
// cubemap

TEST_CASE("cubemap: zero or negative size and bad level counts throw") {
    CHECK_THROWS_AS(ibl::cubemap<float>(0), std::invalid_argument);
    CHECK_THROWS_AS(ibl::cubemap<float>(-3), std::invalid_argument);
    CHECK_THROWS_AS(ibl::cubemap<float>(8, 5), std::invalid_argument); // 8 has 4 levels
    CHECK_THROWS_AS(ibl::cubemap<float>(8, -1), std::invalid_argument);
    CHECK_NOTHROW(ibl::cubemap<float>(8, 4));
    CHECK_THROWS_AS(ibl::latlong<float>(0, 4), std::invalid_argument);
    CHECK_THROWS_AS(ibl::latlong<float>(4, 0), std::invalid_argument);
    const ibl::constant_environment<float> one;
    CHECK_THROWS_AS(ibl::bake_cubemap<float>(one, 0, 2), std::invalid_argument);
    CHECK_THROWS_AS(ibl::bake_cubemap<float>(one, 4, 0), std::invalid_argument);
    const std::vector<float> short_data(5);
    CHECK_THROWS_AS(ibl::latlong<float>(2, 1, short_data), std::invalid_argument);
    try {
        ibl::cubemap<float> bad(0);
    } catch (const std::invalid_argument& e) {
        CHECK(std::string(e.what()).find("face size must be >= 1") != std::string::npos);
    }
}

TEST_CASE("cubemap: level sizes for power-of-two and other sizes") {
    const ibl::cubemap<float> a(7); // 7, 3, 1
    CHECK(a.levels() == 3);
    CHECK(a.size(1) == 3);
    CHECK(a.size(2) == 1);
    const ibl::cubemap<float> b(12, 2);
    CHECK(b.levels() == 2);
    CHECK(b.size(1) == 6);
    CHECK(ibl::cubemap<float>(1).levels() == 1);
}

TEST_CASE_TEMPLATE("cubemap: face orientation follows the GL table", T, float, double) {
    // Mark each texel by face, x, y, then look up directions derived by hand from the table:
    // texel (0, 0) is the (sc, tc) = (-1, -1) corner; texel (n-1, 0) the (+1, -1) corner.
    //   face  (sc,tc)=(-1,-1)   (sc,tc)=(+1,-1)
    //   +X    ( 1,  1,  1)      ( 1,  1, -1)
    //   -X    (-1,  1, -1)      (-1,  1,  1)
    //   +Y    (-1,  1, -1)      ( 1,  1, -1)
    //   -Y    (-1, -1,  1)      ( 1, -1,  1)
    //   +Z    (-1,  1,  1)      ( 1,  1,  1)
    //   -Z    ( 1,  1, -1)      (-1,  1, -1)
    const int n = 4;
    ibl::cubemap<T> c(n, 1);
    c.fill(0, [](int f, int x, int y) { return v3<T>(T(f), T(x), T(y)); });
    c.update_borders();
    const v3<T> c00[6] = {{1, 1, 1}, {-1, 1, -1}, {-1, 1, -1}, {-1, -1, 1}, {-1, 1, 1}, {1, 1, -1}};
    const v3<T> c10[6] = {{1, 1, -1}, {-1, 1, 1}, {1, 1, -1}, {1, -1, 1}, {1, 1, 1}, {-1, 1, -1}};
    const v3<T> axis[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    for (int f = 0; f < 6; ++f) {
        // Pull the corner 10% toward the face's axis: inside texel (0,0) resp. (n-1,0) of face f.
        const v3<T> d00 = T(0.9) * c00[f] + T(0.1) * axis[f];
        const v3<T> d10 = T(0.9) * c10[f] + T(0.1) * axis[f];
        CHECK(c.nearest(d00) == v3<T>(T(f), 0, 0));
        CHECK(c.nearest(d10) == v3<T>(T(f), T(n - 1), 0));
        // And the library's texel-centre direction agrees with the table's corner octant.
        const v3<T> t00 = ibl::cube_texel_direction<T>(f, 0, 0, n);
        for (int k = 0; k < 3; ++k)
            if (c00[f][k] != 0 && axis[f][k] == 0) CHECK(t00[k] * c00[f][k] > 0);
    }
}

TEST_CASE("cubemap: exact texel solid angles sum to 4 pi at every level") {
    for (int n : {1, 2, 7, 64}) {
        const ibl::cubemap<double> c(n);
        for (int l = 0; l < c.levels(); ++l) {
            double sum = 0.0;
            const int m = c.size(l);
            for (int y = 0; y < m; ++y)
                for (int x = 0; x < m; ++x) sum += 6.0 * c.exact_texel_solid_angle(x, y, l);
            // 4 m^2 terms each within a few ulps of 4 pi / (6 m^2)... summed naively: <= 1e-12.
            CHECK(sum == doctest::Approx(ibl::four_pi_v<double>).epsilon(1e-12));
        }
    }
}

TEST_CASE_TEMPLATE("cubemap: branch-free face selection equals cube_lookup bit for bit", T, float, double) {
    dir_gen g;
    std::vector<v3<T>> dirs;
    for (int i = 0; i < 2000; ++i) dirs.push_back(g.next<T>() * T(1 + i % 7)); // not unit either
    for (int i = 0; i < 27; ++i) // every tie: axes, edges, corners, with signed zeros
        for (T z : {T(0), T(-0.0)}) {
            const T c[3] = {T(i % 3 - 1), T((i / 3) % 3 - 1), T(i / 9 - 1)};
            if (c[0] == 0 && c[1] == 0 && c[2] == 0) continue;
            dirs.push_back(v3<T>(c[0] == 0 ? z : c[0], c[1] == 0 ? z : c[1], c[2] == 0 ? z : c[2]));
        }
    for (const auto& d : dirs) {
        const auto a = ibl::cube_lookup(d), b = ibl::detail::cube_lookup_select(d);
        CHECK(a.face == b.face);
        CHECK(a.s == b.s);
        CHECK(a.t == b.t);
    }
    const auto z = ibl::detail::cube_lookup_select(v3<T>(0));
    CHECK((z.face == 0 && z.s == T(0.5) && z.t == T(0.5)));
    // Bad directions read a valid texel (no out-of-bounds access, finite result).
    const ibl::cubemap<T> c = ibl::bake_cubemap<T>(ibl::constant_environment<T>{v3<T>(2)}, 4, 1);
    const T nan = std::numeric_limits<T>::quiet_NaN(), inf = std::numeric_limits<T>::infinity();
    for (const v3<T>& d : {v3<T>(nan, 0, 1), v3<T>(inf, 1, 0), v3<T>(0, -inf, nan), v3<T>(0)}) {
        CHECK(c.radiance(d, T(0.5)) == v3<T>(2));
        CHECK(c.nearest(d) == v3<T>(2));
    }
}

TEST_CASE_TEMPLATE("cubemap: constant environment is reproduced exactly everywhere", T, float, double) {
    // Every stage is written ref + w (x - ref) (bake, mips, corner borders, bilinear, trilinear),
    // so equal inputs give that input bit for bit: the tolerance is 0.
    const v3<T> L(T(0.75), T(1.5), T(3.1));
    const ibl::constant_environment<T> env{L};
    for (int n : {1, 2, 7, 16}) {
        const ibl::cubemap<T> c = ibl::bake_cubemap<T>(env, n, 3);
        dir_gen g;
        std::vector<v3<T>> dirs;
        for (int i = 0; i < 500; ++i) dirs.push_back(g.next<T>());
        for (const auto& k : cube_corners()) dirs.push_back(v3<T>(k)); // exactly on corners
        for (int a = 0; a < 3; ++a)                                     // exactly on edges / axes
            for (T s : {T(-1), T(1)}) {
                v3<T> d(0);
                d[a] = s;
                dirs.push_back(d);
                d[(a + 1) % 3] = -s;
                dirs.push_back(d);
                d[(a + 2) % 3] = T(0.3);
                dirs.push_back(d);
            }
        int bad = 0;
        for (const auto& d : dirs)
            for (T lod : {T(0), T(0.3), T(1), T(1.7), T(100)}) {
                bad += c.radiance(d, lod) != L;
                bad += c.nearest(d, lod) != L;
            }
        CHECK(bad == 0);
        for (int l = 0; l < c.levels(); ++l) CHECK(c.bilinear(v3<T>(1, 1, 1), l) == L);
    }
}

TEST_CASE_TEMPLATE("cubemap: bilinear lookup at texel centres returns the texel", T, float, double) {
    for (int n : {1, 4, 7}) {
        ibl::cubemap<T> c(n);
        dir_gen g;
        c.fill(0, [&](int, int, int) { return v3<T>(T(g.uniform()), T(g.uniform()), T(g.uniform())); });
        c.generate_mips();
        for (int l = 0; l < c.levels(); ++l) {
            const int m = c.size(l);
            for (int f = 0; f < 6; ++f)
                for (int y = 0; y < m; ++y)
                    for (int x = 0; x < m; ++x) {
                        const T s = (T(x) + T(0.5)) / T(m), t = (T(y) + T(0.5)) / T(m);
                        const v3<T> got = c.bilinear(f, s, t, l), want = c.texel(f, x, y, l);
                        if ((m & (m - 1)) == 0) {
                            CHECK(got == want); // s m + 0.5 is exactly an integer: weights 0
                        } else {
                            // s m + 0.5 may miss the integer by an ulp: the weight is ~eps and the
                            // texels are in [0, 1]: 4 eps.
                            CHECK(max_abs(got - want) <= T(4) * ibl::epsilon_v<T>);
                        }
                        // Through a direction: cube_texel_direction + cube_lookup move s, t by a
                        // few ulps (test_cube_geometry: 8 eps), times n texels per unit, times
                        // the texel difference (<= 1).
                        const v3<T> via_dir = c.bilinear(ibl::cube_texel_direction<T>(f, x, y, m), l);
                        CHECK(max_abs(via_dir - want) <= T(16) * T(m) * ibl::epsilon_v<T>);
                    }
        }
    }
}

TEST_CASE_TEMPLATE("cubemap: seamless across every face edge and at the 8 corners", T, float, double) {
    const int n = 16;
    const auto env = ibl::make_lambda_environment<T>(linear_fn<T>);
    const ibl::cubemap<T> c = ibl::bake_cubemap<T>(env, n, 2);
    for (int l = 0; l < c.levels(); ++l) {
        const int m = c.size(l);
        // Largest difference between interior neighbours on this level.
        T neighbour = 0;
        for (int f = 0; f < 6; ++f)
            for (int y = 0; y < m; ++y)
                for (int x = 0; x + 1 < m; ++x) {
                    neighbour = std::max(neighbour, max_abs(c.texel(f, x + 1, y, l) - c.texel(f, x, y, l)));
                    neighbour = std::max(neighbour, max_abs(c.texel(f, y, x + 1, l) - c.texel(f, y, x, l)));
                }
        if (m == 1) neighbour = T(2) * T(linear_grad); // no interior neighbours: the range of L
        // Just on either side of each of the 12 edges: the edge point p has |p_a| = |p_b| = 1;
        // move it by eps into face a or into face b.
        const T eps = T(1e-4);
        T worst_edge = 0;
        for (int a = 0; a < 3; ++a) {
            const int b = (a + 1) % 3, o = (a + 2) % 3;
            for (T sa : {T(-1), T(1)})
                for (T sb : {T(-1), T(1)})
                    for (int i = -19; i <= 19; ++i) {
                        v3<T> p;
                        p[a] = sa;
                        p[b] = sb;
                        p[o] = T(i) / T(20);
                        v3<T> pa = p, pb = p;
                        pa[b] = sb * (T(1) - eps);
                        pb[a] = sa * (T(1) - eps);
                        worst_edge = std::max(worst_edge, max_abs(c.bilinear(pa, l) - c.bilinear(pb, l)));
                    }
        }
        T worst_corner = 0;
        for (const auto& k : cube_corners()) {
            v3<T> q[3];
            for (int a = 0; a < 3; ++a) {
                q[a] = v3<T>(k) * (T(1) - eps);
                q[a][a] = T(k[a]); // face a is the major axis
            }
            for (int a = 0; a < 3; ++a)
                worst_corner = std::max(worst_corner, max_abs(c.bilinear(q[a], l) - c.bilinear(q[(a + 1) % 3], l)));
        }
        MESSAGE("level ", l, " (", m, "): max interior neighbour diff ", double(neighbour), ", across edges ",
                double(worst_edge), ", at corners ", double(worst_corner));
        CHECK(worst_edge <= neighbour);
        CHECK(worst_corner <= neighbour);
        // Continuity proper: an eps step moves the lookup by at most eps * m texels of change
        // (times the unfolding distortion, <= 2) plus rounding.
        CHECK(worst_edge <= T(2) * eps * T(m) * neighbour + T(64) * ibl::epsilon_v<T>);
    }
}

TEST_CASE_TEMPLATE("cubemap: trilinear is linear in lod, lod is clamped", T, float, double) {
    const ibl::cubemap<T> c = ibl::bake_cubemap<T>(ibl::make_lambda_environment<T>(linear_fn<T>), 8, 1);
    dir_gen g;
    for (int i = 0; i < 50; ++i) {
        const v3<T> d = g.next<T>();
        const v3<T> a = c.bilinear(d, 1), b = c.bilinear(d, 2);
        // a + 0.25 (b - a), evaluated in the same order: exact up to the lod's own rounding.
        CHECK(max_abs(c.radiance(d, T(1.25)) - (a + T(0.25) * (b - a))) <= T(8) * ibl::epsilon_v<T>);
        CHECK(c.radiance(d, T(-3)) == c.bilinear(d, 0));
        CHECK(c.radiance(d, std::numeric_limits<T>::quiet_NaN()) == c.bilinear(d, 0));
        CHECK(c.radiance(d, T(1e9)) == c.bilinear(d, c.levels() - 1));
        CHECK(c.radiance(d, std::numeric_limits<T>::infinity()) == c.bilinear(d, c.levels() - 1));
    }
}

TEST_CASE_TEMPLATE("cubemap: mip generation preserves the spherical integral at every level", T, float, double) {
    for (int n : {16, 7, 12}) { // power of two, odd (texels straddle coarse texels), even non-pow2
        ibl::cubemap<T> c(n);
        dir_gen g;
        c.fill(0, [&](int, int, int) { return v3<T>(T(g.uniform() * 10), T(g.uniform()), T(g.uniform() * 1e4)); });
        c.generate_mips();
        v3<double> ref(0);
        for (int l = 0; l < c.levels(); ++l) {
            v3<double> sum(0);
            const int m = c.size(l);
            for (int f = 0; f < 6; ++f)
                for (int y = 0; y < m; ++y)
                    for (int x = 0; x < m; ++x)
                        sum += v3<double>(c.texel(f, x, y, l)) * double(c.exact_texel_solid_angle(x, y, l));
            if (l == 0) ref = sum;
            // Each coarse texel is a weighted mean rounded once to T (eps/2 relative), and the
            // weights are exact solid angles up to ~1e-14 relative (double): eps of T, plus 1e-12.
            const double tol = double(ibl::epsilon_v<T>) + 1e-12;
            for (int k = 0; k < 3; ++k) CHECK(sum[k] == doctest::Approx(ref[k]).epsilon(tol));
        }
    }
}

TEST_CASE_TEMPLATE("cubemap: 1x1 per face", T, float, double) {
    ibl::cubemap<T> c(1);
    CHECK(c.levels() == 1);
    c.fill(0, [](int f, int, int) { return v3<T>(T(1 << f)); }); // faces 1, 2, 4, 8, 16, 32
    c.update_borders();
    const v3<T> axis[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    for (int f = 0; f < 6; ++f) CHECK(c.radiance(axis[f]) == v3<T>(T(1 << f)));
    // On the +X/+Y edge the two faces blend half and half; at the (+,+,+) corner all three meet
    // (+X 1, +Y 4, +Z 16): (1 + 4 + 16) / 3 = 7 (a + ((b - a) + (c - a)) / 3: 1 + 18/3, exact).
    CHECK(c.radiance(v3<T>(1, 1, 0))[0] == doctest::Approx(2.5));
    CHECK(c.radiance(v3<T>(1, 1, 1))[0] == doctest::Approx(7.0));
    dir_gen g;
    for (int i = 0; i < 200; ++i) {
        const T v = c.radiance(g.next<T>())[0];
        CHECK((v >= T(1) && v <= T(32)));
    }
}

TEST_CASE("cubemap: borders rebuilt a face at a time equal update_borders; validity follows the written levels") {
    ibl::cubemap<float> a(8, 3);
    for (int l = 0; l < 3; ++l)
        a.fill(l, [&](int f, int x, int y) { return ibl::vec3<float>(float(f) + 0.1f * float(x), float(y) * 0.37f, float(l) - 0.3f * float(x * y)); });
    ibl::cubemap<float> b = a;
    a.update_borders();
    CHECK(a.borders_valid());
    CHECK_FALSE(b.borders_valid());
    for (int l = 0; l < 3; ++l)
        for (int f = 0; f < 6; ++f) {
            CHECK_FALSE(b.borders_valid()); // faces still stale
            b.update_borders(l, f);
        }
    CHECK(b.borders_valid());
    bool same = true;
    for (int l = 0; l < 3; ++l)
        for (int f = 0; f < 6; ++f)
            for (int y = -1; y <= a.size(l); ++y)
                for (int x = -1; x <= a.size(l); ++x)
                    for (int c = 0; c < 3; ++c) same = same && a.texel(f, x, y, l)[c] == b.texel(f, x, y, l)[c];
    CHECK(same);
    // a write marks only its own level stale: rebuilding that level's faces suffices
    b.set_texel(2, 1, 1, 1, ibl::vec3<float>(5.0f));
    CHECK_FALSE(b.borders_valid());
    for (int f = 0; f < 6; ++f) b.update_borders(1, f);
    CHECK(b.borders_valid());
    // and a face rebuilt before a later write to its level is stale again
    b.update_borders(0, 0);
    b.set_texel(0, 0, 0, 0, ibl::vec3<float>(1.0f));
    for (int f = 1; f < 6; ++f) b.update_borders(0, f);
    CHECK_FALSE(b.borders_valid());
    b.update_borders(0, 0);
    CHECK(b.borders_valid());
    CHECK_THROWS_AS(b.update_borders(3, 0), std::invalid_argument);
    CHECK_THROWS_AS(b.update_borders(0, 6), std::invalid_argument);
    CHECK_THROWS_AS(b.update_borders(-1, 0), std::invalid_argument);
}

TEST_CASE_TEMPLATE("cubemap: sanitize zeroes NaN, inf and (optionally) negatives and counts texels", T, float, double) {
    ibl::cubemap<T> c(4);
    c.fill(0, [](int, int, int) { return v3<T>(1); });
    const T nan = std::numeric_limits<T>::quiet_NaN(), inf = std::numeric_limits<T>::infinity();
    c.set_texel(0, 0, 0, 0, v3<T>(nan, 1, 1));
    c.set_texel(2, 3, 3, 0, v3<T>(1, -inf, nan)); // two bad channels: one texel
    c.set_texel(5, 1, 2, 0, v3<T>(1, 1, -0.5));
    c.set_texel(4, 1, 1, 0, v3<T>(-0.0, 1, 1)); // -0 is not negative
    CHECK_FALSE(c.borders_valid());
    {
        ibl::cubemap<T> keep_neg = c;
        CHECK(keep_neg.sanitize(false) == 2);
        CHECK(keep_neg.texel(5, 1, 2)[2] == T(-0.5));
    }
    CHECK(c.sanitize() == 3);
    CHECK(c.borders_valid());
    CHECK(c.texel(0, 0, 0) == v3<T>(0, 1, 1));
    CHECK(c.texel(2, 3, 3) == v3<T>(1, 0, 0));
    CHECK(c.sanitize() == 0);
    c.generate_mips();
    dir_gen g;
    for (int i = 0; i < 100; ++i) {
        const v3<T> v = c.radiance(g.next<T>(), T(g.uniform() * 2));
        CHECK((std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z)));
    }
}

TEST_CASE_TEMPLATE("bake_cubemap: linear function baked matches at texel centres to O(h^2)", T, float, double) {
    const int n = 16;
    const ibl::cubemap<T> c = ibl::bake_cubemap<T>(ibl::make_lambda_environment<T>(linear_fn<T>), n, 4);
    T worst = 0;
    for (int f = 0; f < 6; ++f)
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
                const v3<T> d = ibl::cube_texel_direction<T>(f, x, y, n);
                worst = std::max(worst, max_abs(c.texel(f, x, y) - linear_fn(d)));
            }
    // A texel is the mean of L over it; for linear L the error is |grad| |mean(w) - w_centre|,
    // and the mean of unit vectors over a cap of angular radius rho is within rho^2 / 2 of its
    // centre; rho <= sqrt(2) / n (face half-width 1/n at most, diagonal): |grad| / n^2.
    MESSAGE("bake vs centre value: ", double(worst), " (bound ", linear_grad / (n * n), ")");
    CHECK(worst <= T(linear_grad / (n * n)));
}

TEST_CASE("bake_cubemap is deterministic for any executor") {
    const auto sky = ibl::make_default_sky<float>();
    const auto a = ibl::bake_cubemap<float>(sky, 16, 3, ibl::serial_executor{});
    const auto b = ibl::bake_cubemap<float>(sky, 16, 3, ibl::thread_executor{2});
    const auto c = ibl::bake_cubemap<float>(sky, 16, 3, ibl::thread_executor{5});
    int diff = 0;
    for (int l = 0; l < a.levels(); ++l)
        for (int f = 0; f < 6; ++f)
            for (int y = 0; y < a.size(l); ++y)
                for (int x = 0; x < a.size(l); ++x)
                    diff += (a.texel(f, x, y, l) != b.texel(f, x, y, l)) + (a.texel(f, x, y, l) != c.texel(f, x, y, l));
    CHECK(diff == 0);
}

// ---------------------------------------------------------------------------------------------
// latlong

TEST_CASE_TEMPLATE("latlong: direction <-> (u, v) round trip, poles and seam", T, float, double) {
    // u, v go through atan2, sin, cos: a few ulps of their range (2 pi, pi): 8 eps.
    const T tol = T(8) * ibl::epsilon_v<T>;
    for (int i = 0; i <= 40; ++i)
        for (int j = 1; j < 40; ++j) {
            const T u = T(i) / T(40), v = T(j) / T(40);
            const v3<T> d = ibl::latlong_direction(u, v);
            CHECK(glm::length(d) == doctest::Approx(1.0).epsilon(double(tol)));
            const ibl::vec2<T> uv = ibl::latlong_uv(d);
            // u = 0 and u = 1 are the same meridian (-X): compare modulo 1.
            const T du = std::fabs(uv.x - u);
            CHECK(std::min(du, T(1) - du) <= tol);
            CHECK(std::fabs(uv.y - v) <= tol);
        }
    // Directions of the convention: +X -> u = 0.5, +Z -> 0.75, -Z -> 0.25, +Y -> v = 1 (top row).
    CHECK(ibl::latlong_uv(v3<T>(1, 0, 0)).x == T(0.5));
    CHECK(ibl::latlong_uv(v3<T>(0, 0, 1)).x == doctest::Approx(0.75));
    CHECK(ibl::latlong_uv(v3<T>(0, 0, -1)).x == doctest::Approx(0.25));
    CHECK(ibl::latlong_uv(v3<T>(0, 1, 0)).y == T(1));
    CHECK(ibl::latlong_uv(v3<T>(0, -1, 0)).y == T(0));
    CHECK(ibl::latlong_uv(v3<T>(0, 0, 0)) == ibl::vec2<T>(0.5, 0.5));
}

TEST_CASE("latlong: texel solid angles sum to 4 pi") {
    for (auto [w, h] : {std::pair{1, 1}, {2, 1}, {7, 3}, {64, 32}, {1024, 512}}) {
        double sum = 0.0;
        for (int j = 0; j < h; ++j) sum += w * ibl::latlong_texel_solid_angle<double>(j, w, h);
        // h terms, each a product of correctly rounded sines: 1e-13.
        CHECK(sum == doctest::Approx(ibl::four_pi_v<double>).epsilon(1e-13));
        // The product form equals (2 pi / W)(sin lat_top - sin lat_bottom).
        const double lt = ibl::half_pi_v<double>, lb = ibl::half_pi_v<double> - ibl::pi_v<double> / h;
        CHECK(ibl::latlong_texel_solid_angle<double>(0, w, h) ==
              doctest::Approx(ibl::two_pi_v<double> / w * (std::sin(lt) - std::sin(lb))).epsilon(1e-12));
    }
}

TEST_CASE_TEMPLATE("latlong: bilinear of a linear function is accurate everywhere, poles and seam included", T, float, double) {
    const int w = 64, h = 32;
    ibl::latlong<T> m(w, h);
    m.fill(0, [&](int x, int y) {
        return linear_fn(ibl::latlong_direction((T(x) + T(0.5)) / T(w), T(1) - (T(y) + T(0.5)) / T(h)));
    });
    m.generate_mips();
    // Bilinear error of a function with second derivatives <= |grad| per radian^2 on a grid of
    // steps (dphi, dlat): |grad| (dphi^2 + dlat^2) / 8; doubled for the pole blend (the pole
    // value, the row mean, is off by |grad_y| (1 - cos(dlat/2)) ~ |grad| dlat^2 / 8).
    const double dphi = ibl::two_pi_v<double> / w, dlat = ibl::pi_v<double> / h;
    const T tol = T(linear_grad * (dphi * dphi + dlat * dlat) / 4);
    dir_gen g;
    std::vector<v3<T>> dirs;
    for (int i = 0; i < 2000; ++i) dirs.push_back(g.next<T>());
    for (int i = 0; i < 64; ++i) { // around both poles and along the seam
        const T phi = T(i) * ibl::two_pi_v<T> / T(64);
        dirs.push_back(v3<T>(T(1e-3) * std::cos(phi), T(1), T(1e-3) * std::sin(phi)));
        dirs.push_back(v3<T>(T(0.02) * std::cos(phi), T(-1), T(0.02) * std::sin(phi)));
        const T y = T(i - 32) / T(33);
        dirs.push_back(v3<T>(-std::sqrt(1 - y * y), y, T(1e-6)));
        dirs.push_back(v3<T>(-std::sqrt(1 - y * y), y, T(-1e-6)));
        dirs.push_back(v3<T>(-std::sqrt(1 - y * y), y, T(0)));
    }
    dirs.push_back(v3<T>(0, 1, 0));
    dirs.push_back(v3<T>(0, -1, 0));
    T worst = 0;
    for (const auto& d0 : dirs) {
        const v3<T> d = glm::normalize(d0);
        const v3<T> got = m.radiance(d);
        CHECK((std::isfinite(got.x) && std::isfinite(got.y) && std::isfinite(got.z)));
        worst = std::max(worst, max_abs(got - linear_fn(d)));
    }
    MESSAGE("latlong 64x32 bilinear max error ", double(worst), " (bound ", double(tol), ")");
    CHECK(worst <= tol);
    // At the pole every azimuth gives the same value (the pole value), exactly.
    const v3<T> north = m.radiance(v3<T>(0, 1, 0));
    for (int i = 0; i < 8; ++i) {
        const T u = T(i) / T(8);
        CHECK(m.bilinear(u, T(1)) == north);
    }
}

TEST_CASE_TEMPLATE("latlong: mips preserve the spherical integral; constant map exact", T, float, double) {
    for (auto [w, h] : {std::pair{32, 16}, {12, 7}, {5, 9}}) {
        ibl::latlong<T> m(w, h);
        dir_gen g;
        m.fill(0, [&](int, int) { return v3<T>(T(g.uniform()), T(g.uniform() * 100), T(1)); });
        m.generate_mips();
        v3<double> ref(0);
        for (int l = 0; l < m.levels(); ++l) {
            v3<double> sum(0);
            for (int y = 0; y < m.height(l); ++y)
                for (int x = 0; x < m.width(l); ++x)
                    sum += v3<double>(m.texel(x, y, l)) * double(m.exact_texel_solid_angle(y, l));
            if (l == 0) ref = sum;
            const double tol = double(ibl::epsilon_v<T>) + 1e-12; // as for the cubemap
            for (int k = 0; k < 3; ++k) CHECK(sum[k] == doctest::Approx(ref[k]).epsilon(tol));
            for (int y = 0; y < m.height(l); ++y)
                for (int x = 0; x < m.width(l); ++x) CHECK(m.texel(x, y, l)[2] == T(1)); // constant channel
        }
    }
}

TEST_CASE_TEMPLATE("latlong: sanitize and construction from RGB floats", T, float, double) {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    std::vector<float> rgb = {1, 2, 3, nan, 1, 1, -0.003f, 1, 1, 4, 5, 6, 1, 1, 1, 1, 1, 1}; // 3 x 2
    ibl::latlong<T> m(3, 2, rgb);
    CHECK(m.texel(2, 1) == v3<T>(1, 1, 1));
    CHECK(m.texel(0, 1) == v3<T>(4, 5, 6)); // row 1 starts at float 9
    CHECK(m.sanitize() == 2);
    CHECK(m.texel(0, 0) == v3<T>(1, 2, 3));
    CHECK(m.texel(1, 0) == v3<T>(0, 1, 1));
    m.generate_mips();
    CHECK(std::isfinite(m.radiance(v3<T>(0, 1, 0), T(0.5)).x));
}

TEST_CASE_TEMPLATE("latlong -> cubemap of a linear function matches the analytic bake", T, float, double) {
    const int w = 128, h = 64, n = 16, k = 4;
    ibl::latlong<T> m(w, h);
    m.fill(0, [&](int x, int y) {
        return linear_fn(ibl::latlong_direction((T(x) + T(0.5)) / T(w), T(1) - (T(y) + T(0.5)) / T(h)));
    });
    m.generate_mips();
    const ibl::cubemap<T> from_ll = ibl::latlong_to_cubemap(m, n, k, ibl::thread_executor{2});
    const ibl::cubemap<T> exact = ibl::bake_cubemap<T>(ibl::make_lambda_environment<T>(linear_fn<T>), n, k);
    T worst = 0;
    for (int f = 0; f < 6; ++f)
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) worst = std::max(worst, max_abs(from_ll.texel(f, x, y) - exact.texel(f, x, y)));
    // Same sub-samples on both sides: only the latlong bilinear error remains (see above).
    const double dphi = ibl::two_pi_v<double> / w, dlat = ibl::pi_v<double> / h;
    const T tol = T(linear_grad * (dphi * dphi + dlat * dlat) / 4);
    MESSAGE("latlong->cubemap vs analytic bake: ", double(worst), " (bound ", double(tol), ")");
    CHECK(worst <= tol);
}

// ---------------------------------------------------------------------------------------------
// analytic

TEST_CASE_TEMPLATE("constant environment: furnace irradiance pi L", T, float, double) {
    const ibl::constant_environment<T> e{v3<T>(2)};
    CHECK(e.radiance(v3<T>(0, 0, 1), T(3)) == v3<T>(2));
    CHECK(e.texel_solid_angle(T(0)) == T(0));
    CHECK(ibl::constant_environment<T>::irradiance(v3<T>(2))[0] == doctest::Approx(2 * ibl::pi_v<double>));
}

TEST_CASE_TEMPLATE("sky: sun irradiance oracle against a brute-force integral", T, float, double) {
    const ibl::sky_environment<T> sky = ibl::make_default_sky<T>();
    ibl::sky_environment<T> no_sun = sky;
    no_sun.sun_radiance = v3<T>(0);
    const double r = double(sky.sun_angular_radius);
    // Sun-only integrand on a polar grid around the sun axis; theta in [0, 1.5 r] with 300 cells
    // puts the cap edge r on a cell boundary, so the hard edge adds no error; the midpoint rule
    // for sin(theta)cos(theta) then errs by ~(h/r)^2/6 ~ 4e-6 relative: tolerance 1e-4.
    const ibl::frame<double> fr = ibl::make_frame(v3<double>(sky.sun_dir));
    const int nt = 300, np = 64;
    const double ht = 1.5 * r / nt, hp = ibl::two_pi_v<double> / np;
    for (double tilt_deg : {0.0, 40.0}) {
        // Normal tilted away from the sun about the frame's tangent.
        const double tilt = tilt_deg * ibl::pi_v<double> / 180;
        const v3<double> nrm = std::cos(tilt) * fr.n + std::sin(tilt) * fr.b;
        v3<double> brute(0);
        for (int i = 0; i < nt; ++i) {
            const double th = (i + 0.5) * ht;
            for (int j = 0; j < np; ++j) {
                const double ph = (j + 0.5) * hp;
                const v3<double> wd = fr.to_world(v3<double>(std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th)));
                const v3<T> wt(wd);
                const v3<double> sun = v3<double>(sky.radiance(wt)) - v3<double>(no_sun.radiance(wt));
                brute += sun * (glm::dot(nrm, wd) * std::sin(th) * ht * hp);
            }
        }
        const v3<T> oracle = sky.sun_irradiance(v3<T>(nrm));
        MESSAGE("tilt ", tilt_deg, ": brute ", brute.x, " oracle ", double(oracle.x));
        for (int k = 0; k < 3; ++k) CHECK(brute[k] == doctest::Approx(double(oracle[k])).epsilon(1e-4));
    }
    // Facing the sun: L_sun pi sin^2 r, and the cap is 2 pi (1 - cos r).
    CHECK(double(sky.sun_irradiance(sky.sun_dir).x) == doctest::Approx(3e4 * ibl::pi_v<double> * std::sin(r) * std::sin(r)).epsilon(1e-5));
    CHECK(double(ibl::sky_environment<T>::cap_solid_angle(T(r))) == doctest::Approx(ibl::two_pi_v<double> * (1 - std::cos(r))).epsilon(1e-5));
    // The default sun is 1e4..1e5 times the sky, 0.5..2 degrees, at ~30 degrees elevation.
    const double ratio = double(sky.sun_radiance.x) / double(sky.horizon.x);
    CHECK((ratio >= 1e4 && ratio <= 1e5));
    CHECK(std::asin(double(sky.sun_dir.y)) == doctest::Approx(ibl::pi_v<double> / 6).epsilon(1e-5));
}

TEST_CASE("sky: gradient integrals against brute force") {
    ibl::sky_environment<double> sky = ibl::make_default_sky<double>();
    sky.sun_radiance = v3<double>(0);
    // Midpoint rule in (mu = cos theta, phi): the integrand is quadratic in mu, so the error is
    // |Z - H| h^2 / 12 * 2 pi with h = 1/512: ~1e-6 relative; tolerance 1e-5.
    const int nm = 512, np = 8;
    v3<double> up(0), down(0), sphere(0);
    for (int i = 0; i < nm; ++i) {
        const double mu = (i + 0.5) / nm, s = std::sqrt(1 - mu * mu);
        for (int j = 0; j < np; ++j) {
            const double ph = (j + 0.5) * ibl::two_pi_v<double> / np;
            const double dw = (1.0 / nm) * (ibl::two_pi_v<double> / np);
            const v3<double> lu = sky.radiance(v3<double>(s * std::cos(ph), mu, s * std::sin(ph)));
            const v3<double> ld = sky.radiance(v3<double>(s * std::cos(ph), -mu, s * std::sin(ph)));
            up += lu * mu * dw;
            down += ld * mu * dw;
            sphere += (lu + ld) * dw;
        }
    }
    for (int k = 0; k < 3; ++k) {
        CHECK(up[k] == doctest::Approx(sky.sky_irradiance_up()[k]).epsilon(1e-5));
        CHECK(down[k] == doctest::Approx(sky.ground_irradiance_down()[k]).epsilon(1e-5));
        CHECK(sphere[k] == doctest::Approx(sky.sky_sphere_integral()[k]).epsilon(1e-5));
    }
}

TEST_CASE("sky baked to a cubemap keeps its total power") {
    auto sky = ibl::make_default_sky<double>();
    auto power = [](const ibl::cubemap<double>& c) {
        v3<double> sum(0);
        const int n = c.size();
        for (int f = 0; f < 6; ++f)
            for (int y = 0; y < n; ++y)
                for (int x = 0; x < n; ++x) sum += c.texel(f, x, y) * c.exact_texel_solid_angle(x, y);
        return sum;
    };
    // Sky and ground only: the weighted midpoint rule per texel errs by O((1/(n k))^2) on the
    // smooth part, but the horizon (a jump from ground to horizon colour) crosses texels: with
    // n k = 64 sub-samples per face side the jump is resolved to ~1/64 of a texel row around the
    // horizon, ~1e-3 of the total: tolerance 2e-3.
    ibl::sky_environment<double> no_sun = sky;
    no_sun.sun_radiance = v3<double>(0);
    const v3<double> smooth = power(ibl::bake_cubemap<double>(no_sun, 16, 4));
    for (int k = 0; k < 3; ++k) CHECK(smooth[k] == doctest::Approx(no_sun.sky_sphere_integral()[k]).epsilon(2e-3));
    // With the sun (1 degree radius, 9.6e-4 sr): at n = 32, k = 16 one sub-sample is ~1.5e-5 sr,
    // so the cap covers ~60 sub-samples and the count of those inside the hard edge is right to
    // a few samples (the lattice-point error of a disc of radius ~4.5 samples): 5%.
    const v3<double> all = power(ibl::bake_cubemap<double>(sky, 32, 16, ibl::thread_executor{2}));
    const v3<double> want = sky.sky_sphere_integral() + sky.sun_sphere_integral();
    MESSAGE("sky power: smooth part ", smooth.x, " vs ", no_sun.sky_sphere_integral().x, "; with sun ", all.x,
            " vs ", want.x);
    CHECK(all.x == doctest::Approx(want.x).epsilon(0.05));
}

TEST_CASE("cubemap: an edge's border sources are affine along it, the texels border_source folds to") {
    for (int n = 1; n <= 64; ++n)
        for (int f = 0; f < 6; ++f)
            for (int e = 0; e < 4; ++e) {
                const ibl::cubemap<float>::border_edge b = ibl::cubemap<float>::border_edge_source(f, e, n);
                for (int i = 0; i < n; ++i) {
                    const int x = e == 0 ? -1 : e == 1 ? n : i, y = e == 2 ? -1 : e == 3 ? n : i;
                    int g = -1, gx = -1, gy = -1;
                    ibl::cubemap<float>::border_source(f, x, y, n, g, gx, gy);
                    REQUIRE(g == b.g);
                    REQUIRE(gx == b.x0 + b.dx * i);
                    REQUIRE(gy == b.y0 + b.dy * i);
                    REQUIRE(g != f);
                }
            }
}
