// sh/: basis, projection (cube, lat-long, quadrature), Lambert convolution, quadratic form, shader
// constants, windowing, rotation, probe interpolation, determinism.
#include <doctest/doctest.h>

#include <ibl/core/executor.hpp>
#include <ibl/env/cubemap.hpp>
#include <ibl/env/latlong.hpp>
#include <ibl/sh.hpp>

#include <glm/mat3x3.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

namespace {

using ibl::sh_coeffs;
using ibl::vec3;

template <class T> vec3<T> random_dir(std::mt19937& g) {
    std::normal_distribution<double> n(0.0, 1.0);
    glm::dvec3 v;
    do v = glm::dvec3(n(g), n(g), n(g));
    while (glm::dot(v, v) < 1e-6);
    return vec3<T>(glm::normalize(v));
}

/// Uniformly random rotation from a random unit quaternion (w, x, y, z).
template <class T> glm::mat<3, 3, T, glm::defaultp> random_rotation(std::mt19937& g) {
    std::normal_distribution<double> n(0.0, 1.0);
    double q[4];
    double len = 0;
    for (double& c : q) {
        c = n(g);
        len += c * c;
    }
    len = std::sqrt(len);
    const double w = q[0] / len, x = q[1] / len, y = q[2] / len, z = q[3] / len;
    glm::dmat3 r; // r[col][row]
    r[0] = glm::dvec3(1 - 2 * (y * y + z * z), 2 * (x * y + w * z), 2 * (x * z - w * y));
    r[1] = glm::dvec3(2 * (x * y - w * z), 1 - 2 * (x * x + z * z), 2 * (y * z + w * x));
    r[2] = glm::dvec3(2 * (x * z + w * y), 2 * (y * z - w * x), 1 - 2 * (x * x + y * y));
    return glm::mat<3, 3, T, glm::defaultp>(r);
}

template <class T, int B> sh_coeffs<T, B> random_coeffs(std::mt19937& g) {
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    sh_coeffs<T, B> c;
    for (int k = 0; k < B * B; ++k) c[k] = vec3<T>(T(u(g)), T(u(g)), T(u(g)));
    return c;
}

template <class T, int B> double max_abs_diff(const sh_coeffs<T, B>& a, const sh_coeffs<T, B>& b) {
    double m = 0;
    for (int k = 0; k < B * B; ++k)
        for (int ch = 0; ch < 3; ++ch) m = std::max(m, std::fabs(double(a[k][ch]) - double(b[k][ch])));
    return m;
}

/// Reference real SH by the trigonometric definition (associated Legendre recurrences, no
/// Condon-Shortley phase, pole +Z, phi = atan2(y, x)): the independent oracle of the table.
double reference_sh(int l, int m, const glm::dvec3& d) {
    const int am = std::abs(m);
    const double z = d.z, s = std::sqrt(std::max(0.0, 1 - z * z)), phi = std::atan2(d.y, d.x);
    double pmm = 1;
    for (int i = 1; i <= am; ++i) pmm *= (2 * i - 1) * s; // P_m^m = (2m-1)!! sin^m
    double p = pmm;
    if (l > am) {
        double p0 = pmm, p1 = z * (2 * am + 1) * pmm;
        for (int ll = am + 2; ll <= l; ++ll) {
            const double p2 = ((2 * ll - 1) * z * p1 - (ll + am - 1) * p0) / (ll - am);
            p0 = p1;
            p1 = p2;
        }
        p = p1;
    }
    double ratio = 1; // (l - m)! / (l + m)!
    for (int i = l - am + 1; i <= l + am; ++i) ratio /= i;
    const double nlm = std::sqrt((2 * l + 1) / (4 * ibl::pi_v<double>) * ratio);
    if (m == 0) return nlm * p;
    return std::sqrt(2.0) * nlm * p * (m > 0 ? std::cos(m * phi) : std::sin(am * phi));
}

/// Cube fetch that samples a direction -> radiance function at texel centres.
template <class T, class F> auto cube_sampler(int n, const F& f) {
    return [n, &f](int face, int x, int y) { return vec3<T>(f(ibl::cube_texel_direction<T>(face, x, y, n))); };
}

/// Lat-long fetch that samples f at texel centres (u = 0.5 + atan2(z,x)/2pi, v = 0.5 + asin(y)/pi).
template <class T, class F> auto latlong_sampler(int w, int h, const F& f) {
    return [w, h, &f](int x, int y) {
        const double phi = ibl::two_pi_v<double> * (x + 0.5) / w - ibl::pi_v<double>;
        const double lat = ibl::half_pi_v<double> - ibl::pi_v<double> * (y + 0.5) / h;
        return vec3<T>(f(vec3<T>(T(std::cos(lat) * std::cos(phi)), T(std::sin(lat)), T(std::cos(lat) * std::sin(phi)))));
    };
}

/// Funk-Hecke factor of a cap of angular radius alpha: 2 pi integral_{cos alpha}^1 P_l(t) dt
/// = 2 pi (P_{l-1}(c) - P_{l+1}(c)) / (2l + 1) for l >= 1 and 2 pi (1 - c) for l = 0.
double cap_factor(int l, double c) {
    auto legendre = [](int n, double t) {
        double p0 = 1, p1 = t;
        if (n == 0) return p0;
        for (int k = 1; k < n; ++k) {
            const double p2 = ((2 * k + 1) * t * p1 - k * p0) / (k + 1);
            p0 = p1;
            p1 = p2;
        }
        return p1;
    };
    if (l == 0) return ibl::two_pi_v<double> * (1 - c);
    return ibl::two_pi_v<double> * (legendre(l - 1, c) - legendre(l + 1, c)) / (2 * l + 1);
}

template <class T> T eps() { return std::numeric_limits<T>::epsilon(); }

} // namespace

// ---------------------------------------------------------------------------------------------
TEST_CASE_TEMPLATE("sh basis: the table equals the trigonometric definition (phase, order, axes)", T, float, double) {
    std::mt19937 g(1);
    for (int it = 0; it < 200; ++it) {
        const vec3<T> d = random_dir<T>(g);
        const auto y = ibl::sh_basis<5>(d);
        for (int l = 0; l < 5; ++l)
            for (int m = -l; m <= l; ++m) {
                // |Y| <= 2.5 and a degree-4 polynomial: ~10 roundings of eps(T) each, plus the
                // rounding of d to T (4 eps |grad Y| <= 4 eps * 10).
                CHECK(std::fabs(double(y[ibl::sh_index(l, m)]) - reference_sh(l, m, glm::dvec3(d))) <= 100 * eps<T>());
            }
    }
    // the frame: Y_1,-1 ~ +y, Y_10 ~ +z, Y_11 ~ +x with positive constants
    CHECK(ibl::sh_basis<2>(vec3<T>(0, 1, 0))[1] == doctest::Approx(0.488602511902919921586));
    CHECK(ibl::sh_basis<2>(vec3<T>(0, 0, 1))[2] == doctest::Approx(0.488602511902919921586));
    CHECK(ibl::sh_basis<2>(vec3<T>(1, 0, 0))[3] == doctest::Approx(0.488602511902919921586));
    CHECK(ibl::sh_index(2, -2) == 4);
    CHECK(ibl::sh_index(4, 4) == 24);
    CHECK(ibl::sh_band_of(8) == 2);
    CHECK(ibl::sh_band_of(9) == 3);
}

TEST_CASE_TEMPLATE("sh basis: orthonormal (Gram matrix = identity) for B = 5 by exact quadrature", T, float, double) {
    // project_function with degree 4 integrates products of degree <= 8 exactly, so the Gram matrix
    // is exact up to rounding: double accumulation of ~90 terms of size <= |Y|^2 w (sum |.| <= 2.5)
    // computed in T -> a few eps(T) * 2.5.
    const double tol = 20 * eps<T>();
    double worst = 0;
    for (int j = 0; j < 25; ++j) {
        const auto col = ibl::project_function<5, T>(
            [j](const vec3<T>& d) { return vec3<T>(ibl::sh_basis<5>(d)[j], T(0), T(0)); }, 4);
        for (int k = 0; k < 25; ++k) worst = std::max(worst, std::fabs(double(col[k].x) - (j == k ? 1.0 : 0.0)));
    }
    MESSAGE("max |Gram - I| = " << worst);
    CHECK(worst <= tol);
}

TEST_CASE_TEMPLATE("sh basis: batch evaluation equals scalar evaluation lane by lane", T, float, double) {
    std::mt19937 g(2);
    constexpr std::size_t n = 37; // not a multiple of any vector width: exercises the tail
    std::vector<T> x(n), y(n), z(n), out(25 * n);
    for (std::size_t i = 0; i < n; ++i) {
        const vec3<T> d = random_dir<T>(g);
        x[i] = d.x, y[i] = d.y, z[i] = d.z;
    }
    ibl::sh_basis_batch<5>(std::span<const T>(x), std::span<const T>(y), std::span<const T>(z), std::span<T>(out));
    double worst = 0;
    for (std::size_t i = 0; i < n; ++i) {
        const auto s = ibl::sh_basis<5>(vec3<T>(x[i], y[i], z[i]));
        for (int k = 0; k < 25; ++k) worst = std::max(worst, std::fabs(double(out[std::size_t(k) * n + i] - s[k])));
    }
    // same expression; only FMA contraction may differ between the vector and scalar code: a few
    // eps(T) of |Y| <= 2.5.
    CHECK(worst <= 8 * eps<T>());
}

TEST_CASE("sh projection: exact cube texel solid angles (table == cube_texel_solid_angle, sum 4 pi)") {
    for (int n : {1, 2, 3, 7, 64}) {
        const ibl::detail::cube_weight_table t(n);
        double worst = 0, total = 0;
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
                const double a = t.texel(x, y), b = ibl::cube_texel_solid_angle<double>(x, y, n);
                worst = std::max(worst, std::fabs(a - b) / b);
                total += 6 * a;
            }
        // both are four-term differences of O(1) arctangents: eps / texel solid angle relative
        // (texel >= 4pi/(6*64^2) = 5e-4 sr -> 4e-13).
        CHECK(worst <= 1e-12);
        CHECK(total == doctest::Approx(ibl::four_pi_v<double>).epsilon(1e-13)); // telescoping sum
    }
}

TEST_CASE("sh projection: Gauss-Legendre nodes integrate t^k exactly for k <= 2n - 1") {
    for (int n : {1, 2, 5, 9, 33}) {
        std::vector<double> x, w;
        ibl::detail::gauss_legendre(n, x, w);
        for (int k = 0; k <= 2 * n - 1; ++k) {
            double s = 0;
            for (int i = 0; i < n; ++i) s += w[std::size_t(i)] * std::pow(x[std::size_t(i)], k);
            const double exact = k % 2 ? 0.0 : 2.0 / (k + 1);
            CHECK(std::fabs(s - exact) <= 1e-14); // n terms of size <= 2: a few eps
        }
    }
}

// ---------------------------------------------------------------------------------------------
TEST_CASE_TEMPLATE("sh closed forms: constant environment gives L00 = 2 sqrt(pi) L and E = pi L", T, float, double) {
    const vec3<T> L(T(1.5), T(0.25), T(3));
    auto f = [&](const vec3<T>&) { return L; };
    const auto by_cube = ibl::project_cube<3>(5, cube_sampler<T>(5, f));
    const auto by_quad = ibl::project_function<3, T>(f, 0);
    std::mt19937 g(3);
    for (const auto* c : {&by_cube, &by_quad}) {
        // weights sum to 4 pi (telescoping / exact quadrature); products rounded in T: ~4 eps(T).
        // Bands 1, 2 vanish: exactly for the quadrature, by the cube's symmetry group for the cube
        // (sum w x^2 = sum w y^2 = sum w z^2 = 4pi/3, odd terms cancel in pairs).
        for (int ch = 0; ch < 3; ++ch) {
            CHECK((*c)[0][ch] == doctest::Approx(2 * std::sqrt(ibl::pi_v<double>) * L[ch]).epsilon(8 * eps<T>()));
            for (int k = 1; k < 9; ++k) CHECK(std::fabs(double((*c)[k][ch])) <= 16 * eps<T>() * L[ch]);
        }
        for (int i = 0; i < 20; ++i) {
            const vec3<T> e = ibl::sh_irradiance_at(*c, random_dir<T>(g));
            for (int ch = 0; ch < 3; ++ch) CHECK(e[ch] == doctest::Approx(ibl::pi_v<double> * L[ch]).epsilon(64 * eps<T>()));
        }
    }
    // lat-long: the row weights still sum to 4 pi (telescoping), so L00 is exact, but the y^2 terms
    // of band 2 see the midpoint rule in latitude: |err| <= (D^2/24) max|d^2/dlat^2 (y^2 cos lat)|
    // ~ D^2/12 relative, D = pi/H.
    const int h = 7;
    const auto by_ll = ibl::project_latlong<3>(12, h, latlong_sampler<T>(12, h, f));
    const double bound = ibl::sqr(ibl::pi_v<double> / h) / 12;
    for (int ch = 0; ch < 3; ++ch) {
        CHECK(by_ll[0][ch] == doctest::Approx(2 * std::sqrt(ibl::pi_v<double>) * L[ch]).epsilon(8 * eps<T>()));
        for (int i = 0; i < 20; ++i)
            CHECK(ibl::sh_irradiance_at(by_ll, random_dir<T>(g))[ch] ==
                  doctest::Approx(ibl::pi_v<double> * L[ch]).epsilon(bound));
    }
}

TEST_CASE_TEMPLATE("sh closed forms: hemisphere sky 1[y > 0] gives E = pi (1 + cos g) / 2", T, float, double) {
    // Derivation: L00 = integral_{y>0} K0 = 2 pi K0 = sqrt(pi); L1-1 = K1 integral_{y>0} y = K1 pi;
    // every other coefficient of l <= 2 vanishes by the symmetries x -> -x, z -> -z and because
    // 1[y>0] - 1/2 is odd in y (all even-band terms but l = 0 vanish; odd bands >= 3 do not). E = pi K0 L00 +
    // (2pi/3) K1^2 pi y = pi/2 + (pi/2) y: exact at 3 bands (and at 5: A3 = 0, band 4 vanishes).
    auto sky = [](const vec3<T>& d) { return d.y > T(0) ? vec3<T>(1) : vec3<T>(0); };
    std::mt19937 g(4);
    SUBCASE("quadrature path (exact: degree 0 per hemisphere)") {
        const auto c = ibl::project_function<5, T>(sky, 0);
        CHECK(c[0].x == doctest::Approx(std::sqrt(ibl::pi_v<double>)).epsilon(8 * eps<T>()));
        CHECK(c[1].x == doctest::Approx(0.488602511902919921586 * ibl::pi_v<double>).epsilon(8 * eps<T>()));
        // bands 0..2 and 4 as derived; band 3 is NOT zero (e.g. y (5z^2 - 1) is odd in y) but
        // A3 = 0 removes it from E
        for (int k = 2; k < 25; ++k)
            if (ibl::sh_band_of(k) != 3) CHECK(std::fabs(double(c[k].x)) <= 16 * eps<T>());
        for (int i = 0; i < 50; ++i) {
            const vec3<T> n = random_dir<T>(g);
            const double exact = ibl::pi_v<double> * (1 + double(n.y)) / 2;
            CHECK(std::fabs(ibl::sh_irradiance_at(c, n).x - exact) <= 32 * eps<T>()); // |E| <= pi, ~10 roundings
        }
    }
    SUBCASE("cube path (the horizon is a row boundary for even n): O(1/n^2) midpoint error") {
        // Each texel is weighted by its exact solid angle and sampled at its centre, so the error is
        // that of the midpoint rule for a smooth integrand: the first-order term is the offset of the
        // J-weighted centroid from the centre, (h^2/12) grad ln J with h = 2/n, J = (1+a^2+b^2)^-3/2.
        // Hence err(n) ~ C / n^2: halving h must divide the error by ~4.
        double err[3];
        const int sizes[3] = {8, 16, 32};
        for (int s = 0; s < 3; ++s) {
            const int n = sizes[s];
            const auto c = ibl::project_cube<3>(n, cube_sampler<T>(n, sky));
            err[s] = 0;
            std::mt19937 gg(5);
            for (int i = 0; i < 50; ++i) {
                const vec3<T> nn = random_dir<T>(gg);
                err[s] = std::max(err[s], std::fabs(ibl::sh_irradiance_at(c, nn).x - ibl::pi_v<double> * (1 + double(nn.y)) / 2));
            }
        }
        MESSAGE("hemisphere sky, cube path, max |E error| at n = 8, 16, 32: " << err[0] << " " << err[1] << " " << err[2]);
        CHECK(err[1] <= err[0] / 3.5); // ratio 4 of the h^2 law, minus the O(h^4) term
        CHECK(err[2] <= err[1] / 3.5 + 64 * eps<T>());
        CHECK(err[2] <= 1e-3); // C / 32^2 with C ~ 0.6 measured at n = 8 (ratio test above)
    }
}

TEST_CASE_TEMPLATE("sh closed forms: directional light and cosine sky max(0, y)", T, float, double) {
    SUBCASE("delta light: E(n) = I sum_l A_l (2l+1)/(4pi) P_l(n.d)") {
        // Addition theorem: sum_m Y_lm(d) Y_lm(n) = (2l+1)/(4pi) P_l(n.d). With A = pi, 2pi/3, pi/4:
        //   at n = d:  1/4 + 1/2 + 5/16 = 17/16;   at n = -d: 1/4 - 1/2 + 5/16 = 1/16;
        //   minimum at t = -8/15 (dE/dt = 1/2 + 15 t/16 = 0): -19/480. With bands 3, 4 added at n = d:
        //   A3 = 0 and 9 A4/(4pi) = -3/32 -> 31/32.
        std::mt19937 g(6);
        const vec3<T> d = random_dir<T>(g);
        const vec3<T> I(T(2), T(1), T(0.5));
        const auto c3 = ibl::sh_project_directional<3>(d, I);
        const auto c5 = ibl::sh_project_directional<5>(d, I);
        for (int ch = 0; ch < 3; ++ch) {
            CHECK(ibl::sh_irradiance_at(c3, d)[ch] == doctest::Approx(17.0 / 16 * I[ch]).epsilon(32 * eps<T>()));
            CHECK(ibl::sh_irradiance_at(c3, -d)[ch] == doctest::Approx(1.0 / 16 * I[ch]).epsilon(256 * eps<T>()));
            CHECK(ibl::sh_irradiance_at(c5, d)[ch] == doctest::Approx(31.0 / 32 * I[ch]).epsilon(32 * eps<T>()));
        }
        const auto mn = ibl::sh_min_irradiance(c3);
        for (int ch = 0; ch < 3; ++ch) {
            // the pattern search stops at 1e-6 rad: E is stationary there, error O(1e-12) + rounding
            CHECK(mn.value[ch] == doctest::Approx(-19.0 / 480 * I[ch]).epsilon(1e4 * eps<T>()));
            CHECK(double(glm::dot(mn.dir[ch], d)) == doctest::Approx(-8.0 / 15).epsilon(std::sqrt(1e4 * eps<T>())));
        }
    }
    SUBCASE("cosine sky: L_lm = A_l Y_lm(+Y) (Funk-Hecke with f = max(0, t))") {
        // max(0, n.Y) is zonal about +Y, so L_lm = 2pi integral_0^1 t P_l(t) dt Y_lm(+Y) = A_l Y_lm(+Y).
        // It is a polynomial of degree 1 on each hemisphere: the quadrature path is exact.
        auto sky = [](const vec3<T>& d) { return vec3<T>(d.y > T(0) ? d.y : T(0)); };
        const auto c = ibl::project_function<5, T>(sky, 1);
        const auto y = ibl::sh_basis<5>(vec3<T>(0, 1, 0));
        double worst = 0;
        for (int l = 0; l < 5; ++l)
            for (int m = -l; m <= l; ++m) {
                const int k = ibl::sh_index(l, m);
                worst = std::max(worst, std::fabs(double(c[k].x) - ibl::lambert_band_factor<double>(l) * double(y[k])));
            }
        MESSAGE("cosine sky, quadrature path, max coefficient error " << worst);
        CHECK(worst <= 32 * eps<T>()); // exact quadrature: rounding of ~200 products of size <= 2.5
        // the cube path converges to the same values (horizon on row boundaries for even n)
        const auto cc = ibl::project_cube<5>(32, cube_sampler<T>(32, sky));
        CHECK(max_abs_diff(c, cc) <= 2e-3); // midpoint h^2 law, same constant as the hemisphere sky
    }
}

TEST_CASE("sh convolution: A_l (Ramamoorthi & Hanrahan 2001 eq. 8-9)") {
    const double pi = ibl::pi_v<double>;
    CHECK(ibl::lambert_band_factor<double>(0) == doctest::Approx(pi));
    CHECK(ibl::lambert_band_factor<double>(1) == doctest::Approx(2 * pi / 3));
    CHECK(ibl::lambert_band_factor<double>(2) == doctest::Approx(pi / 4));
    CHECK(ibl::lambert_band_factor<double>(3) == 0.0);
    CHECK(ibl::lambert_band_factor<double>(4) == doctest::Approx(-pi / 24));
    CHECK(ibl::lambert_band_factor<double>(6) == doctest::Approx(pi / 64));
    static_assert(ibl::lambert_band_factor<double>(5) == 0.0);
}

TEST_CASE_TEMPLATE("sh convolution: E(n) == n^T M n == shader formula at random directions", T, float, double) {
    std::mt19937 g(7);
    const auto L = random_coeffs<T, 3>(g);
    const auto q = ibl::irradiance_quadratic_form(L);
    const auto k_e = ibl::sh_shader_coeffs(L, ibl::sh_shader_output::irradiance);
    const auto k_pi = ibl::sh_shader_coeffs(L, ibl::sh_shader_output::irradiance_over_pi);
    // R&H's printed constants, reproduced by the derivation in convolve.hpp
    CHECK(double(q.m[0][0][0]) == doctest::Approx(0.429043 * L[8].x).epsilon(1e-5));
    CHECK(double(q.m[0][3][3]) == doctest::Approx(0.886227 * L[0].x - 0.247708 * L[6].x).epsilon(1e-5));
    CHECK(double(q.m[0][3][1]) == doctest::Approx(0.511664 * L[1].x).epsilon(1e-5));
    double worst = 0;
    for (int i = 0; i < 100; ++i) {
        const vec3<T> n = random_dir<T>(g);
        const vec3<T> e = ibl::sh_irradiance_at(L, n);
        const vec3<T> eq = q.evaluate(n);
        const vec3<T> es = ibl::sh_shader_evaluate(k_e, n);
        const vec3<T> ep = ibl::sh_shader_evaluate(k_pi, n);
        for (int ch = 0; ch < 3; ++ch) {
            worst = std::max({worst, std::fabs(double(e[ch] - eq[ch])), std::fabs(double(e[ch] - es[ch])),
                              std::fabs(double(e[ch] - ibl::pi_v<T> * ep[ch]))});
        }
    }
    // |coefficients| <= 1: |E| <= sum_l A_l sqrt((2l+1)/4pi) sqrt(2l+1) ~ 5; ~20 roundings each.
    MESSAGE("max |E - n^T M n|, |E - shader| " << worst);
    CHECK(worst <= 100 * 5 * eps<T>());
}

// ---------------------------------------------------------------------------------------------
TEST_CASE_TEMPLATE("sh projection: a finite SH expansion projects to its coefficients", T, float, double) {
    std::mt19937 g(8);
    const auto c = random_coeffs<T, 3>(g);
    auto f = [&](const vec3<T>& d) { return ibl::sh_evaluate(c, d); };
    SUBCASE("quadrature path: exact (degree 2 per hemisphere)") {
        const auto p = ibl::project_function<3, T>(f, 2);
        // exact rule: rounding of ~50 terms |f Y w| (f <= 3, Y <= 1.1, sum w = 4pi) in T
        CHECK(max_abs_diff(p, c) <= 200 * eps<T>());
        // B = 5 projection of a band-2 function: bands 3, 4 vanish (orthogonality)
        const auto p5 = ibl::project_function<5, T>(f, 2);
        for (int k = 9; k < 25; ++k)
            for (int ch = 0; ch < 3; ++ch) CHECK(std::fabs(double(p5[k][ch])) <= 200 * eps<T>());
    }
    SUBCASE("cube path: error shrinks as 1/n^2") {
        // Midpoint rule with exact texel weights (see the hemisphere test): err ~ C h^2, h = 2/n,
        // C <= (1/12)(|grad g| |grad ln J| + |Hess g|) integrated over the sphere; for g = f Y_k,
        // |f| <= 3 and degree 4, that is ~ (1/12) 4 pi 3 (4 + 12) ~ 50 -> err <= 200 / n^2.
        double err[3];
        const int sizes[3] = {16, 32, 64};
        for (int s = 0; s < 3; ++s) {
            const int n = sizes[s];
            err[s] = max_abs_diff(ibl::project_cube<3>(n, cube_sampler<T>(n, f)), c);
            CHECK(err[s] <= 200.0 / (n * n));
        }
        MESSAGE("band-limited cube projection max error at n = 16, 32, 64: " << err[0] << " " << err[1] << " " << err[2]);
        CHECK(err[1] <= err[0] / 3.5);
        CHECK(err[2] <= err[1] / 3.5 + 100 * eps<T>());
    }
    SUBCASE("lat-long path: exact in phi for W > 2 * 4, h^2 in latitude") {
        double err[2];
        const int heights[2] = {16, 32};
        for (int s = 0; s < 2; ++s) {
            const int h = heights[s];
            err[s] = max_abs_diff(ibl::project_latlong<3>(2 * h, h, latlong_sampler<T>(2 * h, h, f)), c);
        }
        MESSAGE("band-limited lat-long projection max error at H = 16, 32: " << err[0] << " " << err[1]);
        CHECK(err[0] <= 200.0 / (16 * 16)); // same midpoint argument in latitude
        CHECK(err[1] <= err[0] / 3.5);
    }
}

TEST_CASE_TEMPLATE("sh projection: environments with a radiance(dir, lod) member are accepted", T, float, double) {
    struct sky {
        vec3<T> radiance(const vec3<T>& d, T) const { return vec3<T>(d.y > T(0) ? T(2) : T(0)); }
        T texel_solid_angle(T) const { return T(0); }
    };
    const auto c = ibl::project_function<3, T>(sky{}, 0);
    CHECK(c[0].x == doctest::Approx(2 * std::sqrt(ibl::pi_v<double>)).epsilon(8 * eps<T>()));
}

TEST_CASE("sh projection: ibl::cubemap and ibl::latlong overloads == the fetch overloads") {
    std::mt19937 g(14);
    const auto c = random_coeffs<float, 3>(g);
    auto f = [&](const vec3<float>& d) { return ibl::sh_evaluate(c, d); };
    ibl::cubemap<float> cube(16, 1);
    cube.fill(0, [&](int face, int x, int y) { return f(ibl::cube_texel_direction<float>(face, x, y, 16)); });
    const auto a = ibl::project_cube<3>(cube);
    const auto b = ibl::project_cube<3>(16, cube_sampler<float>(16, f));
    CHECK(std::memcmp(&a, &b, sizeof a) == 0); // same texels, same kernel: bit-identical
    ibl::latlong<float> ll(32, 16, 1);
    auto ls = latlong_sampler<float>(32, 16, f);
    ll.fill(0, [&](int x, int y) { return ls(x, y); });
    const auto la = ibl::project_latlong<3>(ll, ibl::thread_executor{2});
    const auto lb = ibl::project_latlong<3>(32, 16, ls);
    CHECK(std::memcmp(&la, &lb, sizeof la) == 0);
}

TEST_CASE("sh projection: bit-identical for every thread count") {
    std::mt19937 g(9);
    const int n = 48;
    std::vector<glm::vec3> tex(std::size_t(6 * n * n));
    std::uniform_real_distribution<float> u(0.0f, 100.0f);
    for (auto& t : tex) t = glm::vec3(u(g), u(g), u(g));
    auto fetch = [&](int f, int x, int y) { return tex[std::size_t((f * n + y) * n + x)]; };
    const auto c1 = ibl::project_cube<5>(n, fetch, ibl::thread_executor{1});
    const auto c2 = ibl::project_cube<5>(n, fetch, ibl::thread_executor{2});
    const auto c3 = ibl::project_cube<5>(n, fetch, ibl::thread_executor{3});
    const auto cs = ibl::project_cube<5>(n, fetch);
    CHECK(std::memcmp(&c1, &c2, sizeof c1) == 0);
    CHECK(std::memcmp(&c1, &c3, sizeof c1) == 0);
    CHECK(std::memcmp(&c1, &cs, sizeof c1) == 0);
    auto ll = [&](int x, int y) { return tex[std::size_t(y * 96 + x)]; };
    const auto l1 = ibl::project_latlong<3>(96, 48, ll, ibl::thread_executor{1});
    const auto l3 = ibl::project_latlong<3>(96, 48, ll, ibl::thread_executor{3});
    CHECK(std::memcmp(&l1, &l3, sizeof l1) == 0);
    auto fn = [](const glm::dvec3& d) { return glm::dvec3(std::exp(d.x), d.y * d.y, 1.0 / (2.0 + d.z)); };
    const auto q1 = ibl::project_function<4, double>(fn, 20, ibl::thread_executor{1});
    const auto q2 = ibl::project_function<4, double>(fn, 20, ibl::thread_executor{2});
    CHECK(std::memcmp(&q1, &q2, sizeof q1) == 0);
}

// ---------------------------------------------------------------------------------------------
TEST_CASE_TEMPLATE("sh rotation: Y(R d) = D(R) Y(d) for every band", T, float, double) {
    std::mt19937 g(10);
    double worst = 0;
    for (int it = 0; it < 20; ++it) {
        const auto r = random_rotation<T>(g);
        const auto rot = ibl::sh_rotation<T, 5>::from_matrix(r);
        const vec3<T> d = random_dir<T>(g);
        const auto yd = ibl::sh_basis<5>(d);
        const auto yrd = ibl::sh_basis<5>(vec3<T>(r * d));
        for (int l = 0; l < 5; ++l)
            for (int m = -l; m <= l; ++m) {
                double s = 0;
                for (int n = -l; n <= l; ++n) s += double(rot(l, m, n)) * double(yd[ibl::sh_index(l, n)]);
                worst = std::max(worst, std::fabs(s - double(yrd[ibl::sh_index(l, m)])));
            }
    }
    MESSAGE("max |Y(Rd) - D Y(d)| = " << worst);
    // entries of D^4 carry ~4 levels of recurrence rounding (a few eps each) times |Y| <= 2.5 * 9
    CHECK(worst <= 400 * eps<T>());
    // band 1 is R permuted to (y, z, x)
    const auto r = random_rotation<T>(g);
    const auto rot = ibl::sh_rotation<T, 2>::from_matrix(r);
    CHECK(rot(1, -1, 0) == r[2][1]); // D_{y,z} = R[y][z] = glm r[z][y]
    CHECK(rot(1, 1, -1) == r[1][0]); // D_{x,y} = R[x][y]
}

TEST_CASE("sh rotation: projecting a rotated environment == rotating the projection (double)") {
    std::mt19937 g(11);
    const auto c = random_coeffs<double, 5>(g);
    for (int it = 0; it < 5; ++it) {
        const auto r = random_rotation<double>(g);
        const glm::dmat3 rt = glm::transpose(r);
        // L'(w) = L(R^T w): band-limited (degree 4), so the quadrature projection is exact
        const auto projected = ibl::project_function<5, double>([&](const glm::dvec3& w) { return ibl::sh_evaluate(c, rt * w); }, 4);
        const auto rotated = ibl::sh_rotate(c, r);
        double scale = 0;
        for (int k = 0; k < 25; ++k) scale = std::max(scale, double(glm::length(c[k])));
        const double err = max_abs_diff(projected, rotated) / scale;
        CHECK(err <= 1e-5); // the brief's bound; measured ~1e-15 (exact quadrature, rounding only)
        CHECK(err <= 1e-13);
    }
    // rotation by the identity is the identity; a rotation of the constant term never changes it
    const auto same = ibl::sh_rotate(c, glm::dmat3(1.0));
    CHECK(max_abs_diff(same, c) <= 1e-15);
}

// ---------------------------------------------------------------------------------------------
TEST_CASE("sh window: factors") {
    using ibl::sh_window_kind;
    for (auto kind : {sh_window_kind::hanning, sh_window_kind::lanczos}) {
        CHECK(ibl::sh_window_factor(kind, 0, 2.5) == 1.0);
        CHECK(ibl::sh_window_factor(kind, 3, 2.5) == 0.0);  // l >= W
        CHECK(ibl::sh_window_factor(kind, 2, 1e30) == doctest::Approx(1.0));
        double prev = 1;
        for (int l = 1; l < 5; ++l) { // monotone non-increasing in l
            const double w = ibl::sh_window_factor(kind, l, 4.5);
            CHECK(w <= prev);
            CHECK(w >= 0.0);
            prev = w;
        }
    }
    CHECK(ibl::sh_window_factor(sh_window_kind::hanning, 1, 4.0) == doctest::Approx(0.5 * (1 + std::cos(ibl::pi_v<double> / 4))));
    CHECK(ibl::sh_window_factor(sh_window_kind::lanczos, 2, 4.0) == doctest::Approx(2 / ibl::pi_v<double>));
}

TEST_CASE_TEMPLATE("sh window: a sun rings negative; the auto window removes it with minimal strength", T, float, double) {
    // Sun: a cap of angular radius 0.5 deg and radiance 5e4 (~ the real sun's solid angle, 6e-5 sr)
    // in a constant sky of 0.01, direction off every axis. Coefficients by Funk-Hecke (cap_factor),
    // in double. Unwindowed 3-band minimum ~ -19/480 * 5e4 * 6e-5 + pi 0.01 = -0.09 < 0.
    std::mt19937 g(12);
    const glm::dvec3 d = glm::normalize(glm::dvec3(0.3, 0.8, -0.5));
    const double cos_a = std::cos(0.5 * ibl::pi_v<double> / 180), sun = 5e4, sky = 0.01;
    sh_coeffs<double, 3> cd;
    const auto yd = ibl::sh_basis<3>(d);
    for (int l = 0; l < 3; ++l)
        for (int m = -l; m <= l; ++m) {
            const int k = ibl::sh_index(l, m);
            cd[k] = glm::dvec3(sun * cap_factor(l, cos_a) * yd[k]);
        }
    cd[0] += glm::dvec3(1.0, 1.0, 0.5) * (sky * 2 * std::sqrt(ibl::pi_v<double>)); // a bluish-less sky in z
    sh_coeffs<T, 3> c;
    for (int k = 0; k < 9; ++k) c[k] = vec3<T>(cd[k]);

    for (auto kind : {ibl::sh_window_kind::hanning, ibl::sh_window_kind::lanczos}) {
        ibl::sh_auto_window_options opt;
        opt.kind = kind;
        const auto r = ibl::sh_auto_window(c, opt);
        MESSAGE("kind " << int(kind) << ": min E before " << r.min_before.x << " after " << r.min_after.x << ", "
                        << r.min_after.z << ", width " << r.width);
        CHECK(r.ok);
        CHECK(r.min_before.x < T(0));
        CHECK(r.min_after.x >= T(0));
        CHECK(r.min_after.z >= T(0));
        // independent check on 20000 random directions: non-negative up to rounding of E (|E| <= 5)
        double lowest = 1e300;
        const auto e = ibl::sh_irradiance(r.radiance);
        for (int i = 0; i < 20000; ++i) {
            const vec3<T> v = ibl::sh_evaluate(e, random_dir<T>(g));
            lowest = std::min({lowest, double(v.x), double(v.y), double(v.z)});
        }
        CHECK(lowest >= -50 * eps<T>());
        // minimal: a 1% weaker window (wider W) rings negative again
        const auto weaker = ibl::sh_min_irradiance(ibl::sh_apply_window(c, kind, r.width * T(1.01)));
        CHECK(std::min({weaker.value.x, weaker.value.y, weaker.value.z}) < T(0));
    }
    // a non-ringing input is left alone
    const auto calm = ibl::sh_auto_window(ibl::sh_project_directional<3>(vec3<T>(0, 1, 0), vec3<T>(1)) +
                                          T(1) * [] {
                                              sh_coeffs<T, 3> s;
                                              s[0] = vec3<T>(T(2 * std::sqrt(ibl::pi_v<double>)));
                                              return s;
                                          }());
    CHECK(calm.ok);
    CHECK(std::isinf(calm.width));
}

// ---------------------------------------------------------------------------------------------
TEST_CASE_TEMPLATE("sh probes: trilinear grid and inverse-distance interpolation", T, float, double) {
    std::mt19937 g(13);
    const auto a = random_coeffs<T, 3>(g), b = random_coeffs<T, 3>(g);
    ibl::probe_grid<T> grid{vec3<T>(-1, 0, 2), vec3<T>(T(0.5), T(1), T(2)), 3, 2, 4};
    // a field linear in position: probe(p) = a + p.x b - p.z a
    auto field = [&](const vec3<T>& p) { return a + p.x * b + (-p.z) * a; };
    std::vector<sh_coeffs<T, 3>> probes(std::size_t(3 * 2 * 4));
    for (int k = 0; k < 4; ++k)
        for (int j = 0; j < 2; ++j)
            for (int i = 0; i < 3; ++i)
                probes[std::size_t(i + 3 * (j + 2 * k))] = field(grid.origin + vec3<T>(T(i), T(j), T(k)) * grid.spacing);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (int it = 0; it < 50; ++it) {
        const vec3<T> p = grid.origin + vec3<T>(T(2 * u(g)), T(u(g)), T(3 * u(g))) * grid.spacing;
        const auto w = ibl::probe_grid_weights(grid, p);
        T total = 0;
        for (T x : w.weight) total += x;
        CHECK(double(total) == doctest::Approx(1.0).epsilon(8 * eps<T>()));
        // trilinear reproduces linear fields: |field| <= ~15, ~10 roundings
        CHECK(max_abs_diff(ibl::sh_interpolate_grid(grid, probes.data(), p), field(p)) <= 300 * eps<T>());
    }
    // outside the box: clamped to the nearest boundary point
    const vec3<T> outside = grid.origin + vec3<T>(T(-3), T(0.5), T(100));
    const vec3<T> clamped = grid.origin + vec3<T>(T(0), T(0.5), T(6));
    CHECK(max_abs_diff(ibl::sh_interpolate_grid(grid, probes.data(), outside), field(clamped)) <= 300 * eps<T>());
    // IDW: exact at a probe, between probes a convex combination
    std::vector<vec3<T>> pos = {vec3<T>(0), vec3<T>(1, 0, 0), vec3<T>(0, 1, 0)};
    std::vector<sh_coeffs<T, 3>> pr = {a, b, a + b};
    CHECK(max_abs_diff(ibl::sh_interpolate_idw(pos[1], pos.data(), pr.data(), 3), b) == 0.0);
    const auto mid = ibl::sh_interpolate_idw(vec3<T>(T(0.5), T(0), T(0)), pos.data(), pr.data(), 3);
    // distances 0.5, 0.5, sqrt(1.25): weights 4, 4, 0.8 -> (4a + 4b + 0.8(a + b)) / 8.8
    const auto expect = T(1) * ((T(4.8) / T(8.8)) * (a + b));
    CHECK(max_abs_diff(mid, expect) <= 32 * eps<T>());
}
