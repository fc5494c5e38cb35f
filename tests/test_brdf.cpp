// tests/test_brdf.cpp — the BRDF layer as a specification: normalisation of the distributions,
// closed-form values of masking and Fresnel, the white-furnace property of the GGX microfacet model
// and the consistency of the BRDF models' sample weights with their ndf / visibility.
//
// Integrals are computed by deterministic Gauss-Legendre quadrature in double with the function
// under test evaluated in T; the flattening substitution tan(theta) = alpha tan(psi) maps the GGX
// lobe D(h) (n.h) d(omega_h) to exactly (sin(2 psi) / 2pi) d(psi) d(phi), so the rules converge to
// double precision and the tolerances are set by the rounding of T.

#include <doctest/doctest.h>

#include <ibl/brdf.hpp>

#include <cmath>
#include <initializer_list>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

namespace {

constexpr double pi = 3.141592653589793238462643383279502884;

// Gauss-Legendre nodes and weights on [a, b] (Newton on P_n from Tricomi's initial guess; converged
// to double precision).
struct quadrature {
    std::vector<double> x, w;
};

quadrature gauss_legendre(int n, double a, double b) {
    quadrature q;
    q.x.resize(static_cast<std::size_t>(n));
    q.w.resize(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) {
        double z = std::cos(pi * (i + 0.75) / (n + 0.5));
        double dp = 0;
        for (int it = 0; it < 100; ++it) {
            double p0 = 1, p1 = z;
            for (int k = 2; k <= n; ++k) {
                const double p2 = ((2 * k - 1) * z * p1 - (k - 1) * p0) / k;
                p0 = p1;
                p1 = p2;
            }
            dp = n * (z * p1 - p0) / (z * z - 1);
            const double dz = p1 / dp;
            z -= dz;
            if (std::fabs(dz) < 1e-16) break;
        }
        const auto k = static_cast<std::size_t>(i);
        q.x[k] = 0.5 * (a + b) + 0.5 * (b - a) * (-z);
        q.w[k] = (b - a) / ((1 - z * z) * dp * dp);
    }
    return q;
}

// Polar angle theta of the flattening substitution tan(theta) = alpha tan(psi), and d theta / d psi.
struct flattened {
    double sin_theta, cos_theta, jacobian;
};
flattened flatten(double psi, double alpha) {
    const double s = alpha * std::sin(psi), c = std::cos(psi);
    const double r = std::hypot(s, c);
    // theta = atan2(alpha sin psi, cos psi); d theta / d psi = alpha / (cos^2 psi + alpha^2 sin^2 psi).
    return {s / r, c / r, alpha / (r * r)};
}

// Integral over the hemisphere of ndf(h) (n.h) d(omega_h), phi integrated analytically (2 pi).
template <class F> double hemisphere_integral(F ndf, double alpha, int n) {
    const quadrature q = gauss_legendre(n, 0.0, pi / 2);
    double sum = 0;
    for (std::size_t i = 0; i < q.x.size(); ++i) {
        const flattened f = flatten(q.x[i], alpha);
        sum += q.w[i] * ndf(f.sin_theta, f.cos_theta) * f.cos_theta * f.sin_theta * f.jacobian;
    }
    return 2 * pi * sum;
}

template <class T> constexpr double eps = std::numeric_limits<T>::epsilon();

const double roughness_grid[] = {0.02, 0.05, 0.1, 0.25, 0.5, 0.75, 1.0};

} // namespace

TEST_CASE_TEMPLATE("GGX NDF integrates to 1 over the projected hemisphere", T, float, double) {
    for (const double r : roughness_grid) {
        const double alpha = r * r;
        const T alpha_t = T(alpha);
        CAPTURE(r);
        // Half-vector overload (sin^2 from x^2 + y^2): each term of the sum has relative error
        // <= ~10 eps_T (rounding of sin, cos to T: eps each on sin^2, cos^2; sum, square, quotient:
        // ~5 eps) and the weights are positive, so the sum has the same bound; 16 eps_T for margin.
        // The quadrature itself is exact to ~1e-15 (integrand sin(2 psi)/2 after substitution).
        const double i_vec = hemisphere_integral(
            [&](double s, double c) { return double(ibl::ndf_ggx(ibl::vec3<T>(T(s), T(0), T(c)), alpha_t)); },
            alpha, 48);
        CHECK(std::fabs(i_vec - 1) <= 16 * eps<T> + 1e-13);
        // n.h overload: rounding n.h to T perturbs sin^2 = 1 - (n.h)^2 by up to eps_T (n.h)^2, and
        // D ~ 1 / (sin^2 + alpha^2 cos^2)^2 turns that into a relative error <= 2 eps_T / alpha^2.
        // Where that bound exceeds 1e-2 (float, r < 0.1) n.h cannot resolve the lobe: not checked.
        const double bound = 2 * eps<T> / (alpha * alpha) + 16 * eps<T> + 1e-13;
        if (bound < 1e-2) {
            const double i_cos =
                hemisphere_integral([&](double, double c) { return double(ibl::ndf_ggx(T(c), alpha_t)); }, alpha, 48);
            CHECK(std::fabs(i_cos - 1) <= bound);
        }
    }
}

TEST_CASE_TEMPLATE("Blinn-Phong NDF integrates to 1 and peaks with GGX", T, float, double) {
    for (const double r : roughness_grid) {
        const double alpha = r * r;
        const T alpha_t = T(alpha);
        CAPTURE(r);
        // Half-vector overload: (n.h)^e = exp(x), x = (e/2) log1p(-sin^2), carries ~3 eps_T relative,
        // i.e. 3 |x| eps_T absolute in the exponent; terms with |x| > 10 weigh < e^-10 of the
        // integral, so the relative error of the sum is below (3 * 10 + 10) eps_T; 48 eps_T.
        // Quadrature: the substituted integrand ~ exp(-tan^2 psi) sin(2 psi) is smooth; 64 nodes
        // agree with 128 to 1e-14 (measured).
        const double i_vec = hemisphere_integral(
            [&](double s, double c) { return double(ibl::ndf_blinn_phong(ibl::vec3<T>(T(s), T(0), T(c)), alpha_t)); },
            alpha, 64);
        CHECK(std::fabs(i_vec - 1) <= 48 * eps<T> + 1e-12);
        // n.h overload: pow(n.h, e) has relative error e eps_T / 2 ~ eps_T / alpha^2 from the
        // rounding of n.h; checked where that bound is below 1e-2.
        const double bound = eps<T> / (alpha * alpha) + 48 * eps<T> + 1e-12;
        if (bound < 1e-2) {
            const double i_cos = hemisphere_integral(
                [&](double, double c) { return double(ibl::ndf_blinn_phong(T(c), alpha_t)); }, alpha, 64);
            CHECK(std::fabs(i_cos - 1) <= bound);
        }
        // Walter's mapping e = 2/alpha^2 - 2 makes the peaks equal: (e + 2)/(2 pi) = 1/(pi alpha^2).
        // Both sides are a handful of roundings of the same quantity: 8 eps_T.
        const T peak_bp = ibl::ndf_blinn_phong(T(1), alpha_t);
        const T peak_ggx = ibl::ndf_ggx(T(1), alpha_t);
        CHECK(double(peak_bp) == doctest::Approx(double(peak_ggx)).epsilon(8 * eps<T>));
    }
    // Exponent <-> alpha round trip and the endpoints: e(1) = 0 exactly, alpha(e = 0) = 1 exactly.
    CHECK(ibl::blinn_phong_exponent_from_alpha(T(1)) == T(0));
    CHECK(ibl::alpha_from_blinn_phong_exponent(T(0)) == T(1));
    CHECK(double(ibl::blinn_phong_exponent_from_alpha(T(0.5))) == doctest::Approx(6.0).epsilon(4 * eps<T>));
    CHECK(double(ibl::alpha_from_blinn_phong_exponent(T(6))) == doctest::Approx(0.5).epsilon(4 * eps<T>));
    // alpha = 1 is the uniform lobe 1/pi; D = 0 below the horizon.
    CHECK(double(ibl::ndf_blinn_phong(T(0), T(1))) == doctest::Approx(1 / pi).epsilon(4 * eps<T>));
    CHECK(ibl::ndf_blinn_phong(T(-0.5), T(0.5)) == T(0));
}

TEST_CASE_TEMPLATE("Fresnel: exact limits, monotone, hand values", T, float, double) {
    using v3 = ibl::vec3<T>;
    const v3 f0(T(0.04), T(0.56), T(0.955)); // dielectric, gold-ish red channel, silver-ish
    const v3 f90(T(1), T(0.9), T(0.98));

    SUBCASE("cos = 1 gives F0 and cos = 0 gives F90, bit for bit") {
        CHECK(ibl::fresnel_schlick(T(1), f0, f90) == f0);
        CHECK(ibl::fresnel_schlick(T(0), f0, f90) == f90);
        CHECK(ibl::fresnel_schlick(T(0), f0) == v3(T(1)));
        CHECK(ibl::fresnel_schlick(T(1), T(0.3), T(0.7)) == T(0.3));
        CHECK(ibl::fresnel_schlick(T(0), T(0.3), T(0.7)) == T(0.7));
        // Outside [0, 1] cos is clamped: -0.5 -> 0 (F90), 2 -> 1 (F0); NaN -> 0.
        CHECK(ibl::fresnel_schlick(T(-0.5), f0, f90) == f90);
        CHECK(ibl::fresnel_schlick(T(2), f0, f90) == f0);
        CHECK(ibl::fresnel_schlick(std::numeric_limits<T>::quiet_NaN(), f0, f90) == f90);
    }
    SUBCASE("hand value at cos = 0.5: w = 1/32, F = 0.04 + 0.96/32 = 0.07") {
        // Four roundings (1 - cos exact, w, two products, sum): 4 eps_T.
        CHECK(double(ibl::fresnel_schlick(T(0.5), T(0.04))) == doctest::Approx(0.07).epsilon(4 * eps<T>));
        CHECK(double(ibl::fresnel_schlick(T(0.5), f0).y) == doctest::Approx(0.56 + 0.44 / 32).epsilon(4 * eps<T>));
    }
    SUBCASE("scalar and RGB overloads agree per channel") {
        for (int i = 0; i <= 20; ++i) {
            const T c = T(i) / T(20);
            const v3 f = ibl::fresnel_schlick(c, f0, f90);
            CHECK(f.x == ibl::fresnel_schlick(c, f0.x, f90.x));
            CHECK(f.z == ibl::fresnel_schlick(c, f0.z, f90.z));
        }
    }
    SUBCASE("monotone non-increasing in cos when F0 <= F90") {
        // The lerp form is exact at the ends; in between, two rounded products and a sum may move
        // a value by 2 eps_T relative, so consecutive values may rise by at most that much.
        v3 prev = ibl::fresnel_schlick(T(0), f0, f90);
        for (int i = 1; i <= 4096; ++i) {
            const v3 f = ibl::fresnel_schlick(T(i) / T(4096), f0, f90);
            for (int ch = 0; ch < 3; ++ch) CHECK(f[ch] <= prev[ch] * (1 + 2 * T(eps<T>)));
            prev = f;
        }
    }
    SUBCASE("roughness-aware Schlick") {
        for (int i = 0; i <= 16; ++i) {
            const T c = T(i) / T(16);
            // r = 0: F90 = max(1, F0) = 1, the same call as fresnel_schlick(c, f0): bit for bit.
            CHECK(ibl::fresnel_schlick_roughness(c, f0, T(0)) == ibl::fresnel_schlick(c, f0));
            // r = 1: F90 = max(0, F0) = F0, so F = (1 - w) F0 + w F0 = F0 up to two roundings.
            const v3 f1 = ibl::fresnel_schlick_roughness(c, f0, T(1));
            for (int ch = 0; ch < 3; ++ch) CHECK(double(f1[ch]) == doctest::Approx(double(f0[ch])).epsilon(2 * eps<T>));
        }
        // r = 1 at the ends is exact: cos = 0 gives max(0, F0) = F0, cos = 1 gives F0.
        CHECK(ibl::fresnel_schlick_roughness(T(0), f0, T(1)) == f0);
        CHECK(ibl::fresnel_schlick_roughness(T(1), f0, T(1)) == f0);
        // r = 0.5, cos = 0: F90 = max(0.5, F0) = (0.5, 0.56, 0.955) per channel.
        CHECK(ibl::fresnel_schlick_roughness(T(0), f0, T(0.5)) == v3(T(0.5), T(0.56), T(0.955)));
        // r = 0.5, cos = 0.5: 0.04 + (0.5 - 0.04)/32 = 0.054375 (4 roundings: 4 eps_T).
        CHECK(double(ibl::fresnel_schlick_roughness(T(0.5), f0, T(0.5)).x) ==
              doctest::Approx(0.054375).epsilon(4 * eps<T>));
        CHECK(double(ibl::fresnel_schlick_roughness(T(0.5), T(0.04), T(0.5))) ==
              doctest::Approx(0.054375).epsilon(4 * eps<T>));
    }
    SUBCASE("F0 from IOR") {
        // ((1.5 - 1)/(1.5 + 1))^2 = 0.2^2 = 0.04; quotient and square: 3 eps_T.
        CHECK(double(ibl::f0_from_ior(T(1.5))) == doctest::Approx(0.04).epsilon(3 * eps<T>));
        CHECK(ibl::f0_from_ior(T(1)) == T(0));
        // Glass (1.5) in water (1.33): (0.17 / 2.83)^2; symmetric in the two media.
        CHECK(double(ibl::f0_from_ior(T(1.5), T(1.33))) == doctest::Approx(std::pow(0.17 / 2.83, 2)).epsilon(64 * eps<T>));
        CHECK(ibl::f0_from_ior(T(1.5), T(1.33)) == ibl::f0_from_ior(T(1.33), T(1.5)));
        // Clamps: both media 0 -> 0; n -> infinity -> 1; NaN and negative IOR -> 0 (F0 = 1).
        CHECK(ibl::f0_from_ior(T(0), T(0)) == T(0));
        CHECK(ibl::f0_from_ior(std::numeric_limits<T>::infinity()) == T(1));
        CHECK(ibl::f0_from_ior(std::numeric_limits<T>::quiet_NaN()) == T(1));
        CHECK(ibl::f0_from_ior(T(-2)) == T(1));
    }
    SUBCASE("metallic workflow endpoints") {
        const v3 base(T(0.9), T(0.6), T(0.2));
        CHECK(ibl::f0_from_metallic(base, T(0)) == v3(T(0.04)));
        CHECK(ibl::f0_from_metallic(base, T(1)) == base);
        CHECK(ibl::f0_from_metallic(base, T(2)) == base);                                // clamped
        CHECK(ibl::f0_from_metallic(base, std::numeric_limits<T>::quiet_NaN()) == v3(T(0.04))); // NaN -> 0
        // metallic = 0.5: (0.04 + 0.9)/2 = 0.47 (two products and a sum: 3 eps_T).
        CHECK(double(ibl::f0_from_metallic(base, T(0.5)).x) == doctest::Approx(0.47).epsilon(3 * eps<T>));
        CHECK(ibl::diffuse_from_metallic(base, T(0)) == base);
        CHECK(ibl::diffuse_from_metallic(base, T(1)) == v3(T(0)));
    }
}

TEST_CASE_TEMPLATE("Schlick-GGX and height-correlated Smith: closed-form points", T, float, double) {
    // Tolerances: each closed form below is a few (<= 8) roundings in T; 8 eps_T relative.
    const double tol = 8 * eps<T>;
    SUBCASE("k policies") {
        CHECK(ibl::k_ibl(T(0.5)) == T(0.125));     // 0.25 / 2, exact
        CHECK(ibl::k_direct(T(0.5)) == T(0.28125)); // 1.5^2 / 8 = 2.25 / 8, exact
        CHECK(ibl::k_ibl(T(1)) == T(0.5));
        CHECK(ibl::k_direct(T(0)) == T(0.125));
        CHECK(ibl::k_ibl(T(-1)) == T(0));
        CHECK(ibl::k_ibl(std::numeric_limits<T>::quiet_NaN()) == T(0));
        CHECK(ibl::k_direct(T(3)) == T(0.5));
    }
    SUBCASE("Schlick-GGX at n.v = n.l = 0.5, r = 0.5") {
        // k_ibl = 0.125: G1 = 0.5 / (0.5 * 0.875 + 0.125) = 0.5 / 0.5625 = 8/9; G = 64/81;
        // V = G / (4 * 0.25) = 64/81.
        const T k = ibl::k_ibl(T(0.5));
        CHECK(double(ibl::g1_schlick_ggx(T(0.5), k)) == doctest::Approx(8.0 / 9).epsilon(tol));
        CHECK(double(ibl::g_smith_schlick_ggx(T(0.5), T(0.5), k)) == doctest::Approx(64.0 / 81).epsilon(tol));
        CHECK(double(ibl::v_smith_schlick_ggx(T(0.5), T(0.5), k)) == doctest::Approx(64.0 / 81).epsilon(tol));
        // k_direct = 0.28125 = 9/32: G1 = 0.5 / (0.5 * 23/32 + 9/32) = 0.5 / (41/64) = 32/41.
        const T kd = ibl::k_direct(T(0.5));
        CHECK(double(ibl::g1_schlick_ggx(T(0.5), kd)) == doctest::Approx(32.0 / 41).epsilon(tol));
        CHECK(double(ibl::g_smith_schlick_ggx(T(0.5), T(0.5), kd)) == doctest::Approx(1024.0 / 1681).epsilon(tol));
        // Asymmetric: n.v = 0.8, n.l = 0.2, k = 0.5 (r = 1): G1(0.8) = 0.8/0.9, G1(0.2) = 0.2/0.6;
        // V = 1 / (4 * 0.9 * 0.6) = 1/2.16.
        CHECK(double(ibl::v_smith_schlick_ggx(T(0.8), T(0.2), T(0.5))) == doctest::Approx(1 / 2.16).epsilon(tol));
        CHECK(double(ibl::g_smith_schlick_ggx(T(0.8), T(0.2), T(0.5))) ==
              doctest::Approx((0.8 / 0.9) * (0.2 / 0.6)).epsilon(tol));
    }
    SUBCASE("limits: G(1, 1) = 1, G1(0) = 0, V(1, 1) = 1/4 exactly") {
        for (const T k : {T(0), T(0.125), T(0.28125), T(0.5), T(1)}) {
            CHECK(ibl::g_smith_schlick_ggx(T(1), T(1), k) == T(1));
            CHECK(ibl::g1_schlick_ggx(T(0), k) == T(0));
            CHECK(ibl::v_smith_schlick_ggx(T(1), T(1), k) == T(0.25));
        }
        for (const T a : {T(0), T(1e-4), T(0.25), T(1)}) {
            CHECK(ibl::g2_smith_ggx_correlated(T(1), T(1), a) == T(1));
            CHECK(ibl::g2_smith_ggx_correlated(T(0), T(0.5), a) == T(0));
            CHECK(ibl::v_smith_ggx_correlated(T(1), T(1), a) == T(0.25));
        }
    }
    SUBCASE("height-correlated V at hand-computed points") {
        // n.v = n.l = 0.5, alpha = 0.25: s = sqrt(0.25 + 0.0625 * 0.75) = sqrt(19/64) = sqrt(19)/8;
        // denominator 0.5 s + 0.5 s = s, V = 0.5 / s = 4 / sqrt(19) = 0.91766...; G2 = 4 n.v n.l V = V.
        CHECK(double(ibl::v_smith_ggx_correlated(T(0.5), T(0.5), T(0.25))) == doctest::Approx(4 / std::sqrt(19.0)).epsilon(tol));
        CHECK(double(ibl::g2_smith_ggx_correlated(T(0.5), T(0.5), T(0.25))) == doctest::Approx(4 / std::sqrt(19.0)).epsilon(tol));
        // alpha = 1: s(mu) = 1, V = 0.5 / (n.l + n.v); at (0.8, 0.6): 0.5 / 1.4 = 5/14.
        CHECK(double(ibl::v_smith_ggx_correlated(T(0.8), T(0.6), T(1))) == doctest::Approx(5.0 / 14).epsilon(tol));
        // n.v = 0: V = 0.5 / (alpha n.l), the exact limit; alpha = 0.25, n.l = 0.5: 4.
        CHECK(double(ibl::v_smith_ggx_correlated(T(0), T(0.5), T(0.25))) == doctest::Approx(4.0).epsilon(tol));
        // Symmetric in v and l.
        CHECK(ibl::v_smith_ggx_correlated(T(0.3), T(0.7), T(0.2)) == ibl::v_smith_ggx_correlated(T(0.7), T(0.3), T(0.2)));
    }
}

TEST_CASE_TEMPLATE("V forms equal G / (4 n.v n.l) at interior points", T, float, double) {
    const T cosines[] = {T(0.05), T(0.3), T(0.7), T(0.99)};
    const T roughnesses[] = {T(0.05), T(0.3), T(0.6), T(1)};
    for (const T r : roughnesses)
        for (const T nv : cosines)
            for (const T nl : cosines) {
                CAPTURE(r);
                CAPTURE(nv);
                CAPTURE(nl);
                const T alpha = ibl::alpha_from_roughness(r);
                // Reference G2 = 1 / (1 + Lambda(v) + Lambda(l)) from ggx.hpp's lambda_ggx, in double
                // from T's Lambdas: lambda_ggx carries ~6 eps_T (root, products, quotient), the
                // sum and quotient ~2 more, the V under test ~6: 32 eps_T covers both sides.
                const double g2 = 1.0 / (1.0 + double(ibl::lambda_ggx(nv, alpha)) + double(ibl::lambda_ggx(nl, alpha)));
                const double v_ref = g2 / (4.0 * double(nv) * double(nl));
                CHECK(double(ibl::v_smith_ggx_correlated(nv, nl, alpha)) == doctest::Approx(v_ref).epsilon(32 * eps<T>));
                CHECK(double(ibl::g2_smith_ggx_correlated(nv, nl, alpha)) == doctest::Approx(g2).epsilon(32 * eps<T>));
                // G2 >= G1 G1 (correlation only removes double counting of masking) and <= min G1.
                const double g1v = ibl::g1_smith_ggx(nv, alpha), g1l = ibl::g1_smith_ggx(nl, alpha);
                CHECK(g2 >= g1v * g1l * (1 - 32 * eps<T>));
                CHECK(g2 <= std::fmin(g1v, g1l) * (1 + 32 * eps<T>));
                // Schlick's G1 with k = alpha/2 never exceeds the exact G1 (proof in the furnace test);
                // both are a few roundings: 8 eps_T.
                CHECK(double(ibl::g1_schlick_ggx(nv, ibl::k_ibl(r))) <= g1v * (1 + 8 * eps<T>));
                // Schlick-GGX: the one-expression V equals G / (4 n.v n.l) (each side ~6 roundings).
                const T k = ibl::k_ibl(r);
                const double v_schlick = double(ibl::g_smith_schlick_ggx(nv, nl, k)) / (4.0 * double(nv) * double(nl));
                CHECK(double(ibl::v_smith_schlick_ggx(nv, nl, k)) == doctest::Approx(v_schlick).epsilon(16 * eps<T>));
            }
}

namespace {

// Directional albedo of a model with F = 1,  E(v) = int f(v, l) (n.l) d(omega_l)
//   = int over h of [D_ggx(h) (n.h)] * weight(v, h) d(omega_h)     (l = reflect(-v, h), Jacobian 4 v.h)
// with the measure D_ggx (n.h) d(omega_h) = sin(2 psi)/(2 pi) d(psi) d(phi) after the substitution
// tan(theta_h) = alpha tan(psi). With v = (sin_v, 0, cos_v),
//   n.l = cos_v cos(2 theta) + sin_v cos(phi) sin(2 theta) = R cos(2 theta - beta),
//   R = hypot(cos_v, sin_v cos phi), beta = atan2(sin_v cos phi, cos_v),
// so the weight is non-zero for theta < theta_max = (beta + pi/2) / 2; integrating only up to there
// keeps the integrand smooth. Panels in theta (Gauss-Legendre on each):
//   [0, atan(alpha)]            in psi (the peak of D; psi in [0, pi/4]);
//   beyond, in t = log(tan(theta) / alpha), where the weight varies on the scale of theta itself
//                               (psi would squeeze it into a sliver of width ~alpha near pi/2) and
//                               the measure is dt / (4 pi cosh^2 t);
//   a last panel where n.l < 8 alpha: the root sqrt(n.l^2 + alpha^2 (1 - n.l^2)) of the correlated
//                               V has complex singularities at n.l ~ +-i alpha, which a panel of
//                               length ~1 resolves only slowly.
// phi in two panels [0, pi/2], [pi/2, pi] (theta_max moves fastest at phi = pi/2), doubled by symmetry.
//
// `density(n_dot_v, n_dot_l, n_dot_h, v_dot_h, p)` returns the integrand per unit of the quadrature
// variable and of phi; p gives theta, d theta / d(variable) and the GGX measure per unit of both.
struct polar_point {
    double sin_theta, cos_theta;
    double dtheta;  ///< d theta / d(quadrature variable)
    double measure; ///< D_ggx (n.h) sin(theta) d theta / d(variable): the GGX measure per unit phi
};
template <class W> double directional_albedo(double n_dot_v, double alpha, int n, W density) {
    const double sin_v = std::sqrt((1 - n_dot_v) * (1 + n_dot_v));
    const quadrature q_unit = gauss_legendre(n, 0.0, 1.0);
    const double theta_peak = std::atan(alpha);
    double sum = 0;
    for (int panel = 0; panel < 2; ++panel) {
        const quadrature q_phi = gauss_legendre(n, panel * pi / 2, (panel + 1) * pi / 2);
        for (std::size_t j = 0; j < q_phi.x.size(); ++j) {
            const double phi = q_phi.x[j];
            const double radius = std::hypot(n_dot_v, sin_v * std::cos(phi));
            const double beta = std::atan2(sin_v * std::cos(phi), n_dot_v);
            const double theta_max = 0.5 * (beta + pi / 2);
            auto point = [&](const polar_point& p) {
                const double v_dot_h = sin_v * std::cos(phi) * p.sin_theta + n_dot_v * p.cos_theta;
                const double n_dot_l = 2 * v_dot_h * p.cos_theta - n_dot_v;
                return density(n_dot_v, n_dot_l, p.cos_theta, v_dot_h, p);
            };
            auto psi_panel = [&](double theta0, double theta1) { // theta1 <= atan(alpha)
                const double psi0 = std::atan2(std::sin(theta0), alpha * std::cos(theta0));
                const double psi1 = std::atan2(std::sin(theta1), alpha * std::cos(theta1));
                double s = 0;
                for (std::size_t i = 0; i < q_unit.x.size(); ++i) {
                    const double psi = psi0 + (psi1 - psi0) * q_unit.x[i];
                    const flattened f = flatten(psi, alpha);
                    s += q_unit.w[i] * point({f.sin_theta, f.cos_theta, f.jacobian, std::sin(2 * psi) / (2 * pi)});
                }
                return (psi1 - psi0) * s;
            };
            auto t_panel = [&](double theta0, double theta1) { // theta0 >= atan(alpha)
                const double t0 = std::log(std::tan(theta0) / alpha), t1 = std::log(std::tan(theta1) / alpha);
                double s = 0;
                for (std::size_t i = 0; i < q_unit.x.size(); ++i) {
                    const double t = t0 + (t1 - t0) * q_unit.x[i];
                    const double tan_theta = alpha * std::exp(t);
                    const double c = 1 / std::sqrt(1 + tan_theta * tan_theta);
                    const double ch = std::cosh(t); // d theta / dt = tan cos^2; measure 1/(4 pi cosh^2 t)
                    s += q_unit.w[i] * point({tan_theta * c, c, tan_theta * c * c, 1 / (4 * pi * ch * ch)});
                }
                return (t1 - t0) * s;
            };
            auto panel_of = [&](double theta0, double theta1) {
                return theta1 <= theta0 ? 0.0 : theta1 <= theta_peak ? psi_panel(theta0, theta1) : t_panel(theta0, theta1);
            };
            // Breakpoints: 0 <= theta_peak (if below theta_max) <= theta_near (n.l = 8 alpha) <= theta_max.
            const double near = 8 * alpha;
            double theta_near = near < radius ? 0.5 * (beta + std::acos(near / radius)) : 0.0;
            const double b1 = std::fmin(theta_peak, theta_max);
            theta_near = std::fmax(theta_near, b1);
            sum += q_phi.w[j] * (panel_of(0, b1) + panel_of(b1, theta_near) + panel_of(theta_near, theta_max));
        }
    }
    return 2 * sum;
}

template <class M, class T> double albedo_by_weight(double n_dot_v, double r, int n) {
    const double alpha = double(M::alpha(T(r)));
    return directional_albedo(n_dot_v, alpha, n, [&](double nv, double nl, double nh, double vh, const polar_point& p) {
        return p.measure * double(M::sample_weight(T(nv), T(nl), T(nh), T(vh), T(r)));
    });
}

// The same integral from the model's ndf and visibility: f (n.l) d(omega_l) = D V (n.l) 4 (v.h) d(omega_h),
// d(omega_h) = sin(theta) d(theta) d(phi) = sin(theta) (d theta / d psi) d(psi) d(phi).
template <class M, class T> double albedo_by_ndf(double n_dot_v, double r, int n) {
    const double alpha = double(M::alpha(T(r)));
    return directional_albedo(n_dot_v, alpha, n, [&](double nv, double nl, double nh, double vh, const polar_point& p) {
        const double d = M::ndf(T(nh), T(alpha));
        const double v = M::visibility(T(nv), T(nl), T(r));
        return d * v * nl * 4 * vh * p.sin_theta * p.dtheta;
    });
}

} // namespace

TEST_CASE_TEMPLATE("white furnace: GGX + height-correlated Smith loses energy, none as r -> 0", T, float, double) {
    using M = ibl::ggx_height_correlated;
    const double cosines[] = {0.02, 0.1, 0.3, 0.5, 0.7, 0.9, 1.0};
    // Quadrature error: 32-node panels agree with 192-node panels to 9e-10 over this grid (measured in
    // double; 5e-12 with 48 nodes); the weight in T carries ~10 eps_T relative per term (inputs rounded to T, V, four
    // products), and the terms are positive, so the sum is within 16 eps_T of its exact value.
    const double tol = 16 * eps<T> + 1e-8;
    double max_albedo = 0, max_change = 0, min_albedo = 2;
    for (const double nv : cosines)
        for (const double r : roughness_grid) {
            CAPTURE(nv);
            CAPTURE(r);
            const double e = albedo_by_weight<M, T>(nv, r, 32);
            const double e_fine = albedo_by_weight<M, T>(nv, r, 64);
            max_change = std::fmax(max_change, std::fabs(e - e_fine));
            CHECK(std::fabs(e - e_fine) <= tol);
            // Single scattering never creates energy: E <= 1.
            CHECK(e <= 1 + tol);
            max_albedo = std::fmax(max_albedo, e);
            min_albedo = std::fmin(min_albedo, e);
            // As r -> 0 the loss is the masking of the near-mirror directions, 1 - E ~ Lambda(n.v) +
            // Lambda(n.l) with n.l ~ n.v and Lambda(mu) <= alpha / (2 mu): at r = 0.02 (alpha = 4e-4)
            // 1 - E <= alpha / n.v (measured: 2.1e-4 at n.v = 0.02, 1.6e-7 at n.v = 1).
            if (r == roughness_grid[0]) CHECK(1 - e <= r * r / nv + tol);
        }
    // Closed form at n.v = 1, r = 1: D = 1/pi, s(mu) = 1, V = 0.5 / (1 + n.l), l at polar angle
    // 2 theta_h, so E = 2 pi int_0^1 (1/pi) 0.5 mu / (1 + mu) d(mu) = 1 - ln 2 = 0.306853.
    CHECK(albedo_by_weight<M, T>(1.0, 1.0, 32) == doctest::Approx(1 - std::log(2.0)).epsilon(tol));
    MESSAGE("E in [" << min_albedo << ", 1 - " << 1 - max_albedo << "], max |E_32 - E_64| = " << max_change);
}

TEST_CASE_TEMPLATE("white furnace: the Schlick-GGX (k = r^2/2) model", T, float, double) {
    using M = ibl::ggx_schlick_ibl;
    const double cosines[] = {0.02, 0.1, 0.3, 0.5, 0.7, 0.9, 1.0};
    const double tol = 16 * eps<T> + 1e-8; // as in the correlated furnace test
    double max_albedo = 0, min_albedo = 2;
    for (const double nv : cosines)
        for (const double r : roughness_grid) {
            CAPTURE(nv);
            CAPTURE(r);
            const double e = albedo_by_weight<M, T>(nv, r, 32);
            max_albedo = std::fmax(max_albedo, e);
            min_albedo = std::fmin(min_albedo, e);
            // With k = alpha/2, Schlick's G1 <= the exact GGX G1: (mu + alpha (1 - mu))^2 minus
            // (mu^2 + alpha^2 (1 - mu^2)) = 2 alpha mu (1 - mu)(1 - alpha) >= 0. And
            // G1(v) G1(l) = 1/((1 + Lv)(1 + Ll)) <= 1/(1 + Lv + Ll) = G2. So pointwise
            // G_Schlick <= G2 and this model's albedo is below the correlated one's, hence <= 1.
            CHECK(e <= albedo_by_weight<ibl::ggx_height_correlated, T>(nv, r, 32) + tol);
        }
    // n.v = 1, r = 1 (k = 1/2): G1(1) = 1, G1(mu) = 2 mu / (1 + mu) = the exact GGX G1 at alpha = 1,
    // so E = 1 - ln 2 as for the correlated model.
    CHECK(albedo_by_weight<M, T>(1.0, 1.0, 32) == doctest::Approx(1 - std::log(2.0)).epsilon(tol));
    MESSAGE("Schlick-GGX model: E in [" << min_albedo << ", 1 - " << 1 - max_albedo << "]");
}

TEST_CASE_TEMPLATE("model sample_weight is f n.l / pdf_l from ndf and visibility", T, float, double) {
    // Pointwise: weight = D V (n.l) / (D_ggx (n.h) / (4 v.h)). The two D's are the same call on the
    // same rounded input, so they cancel exactly; the remaining ~6 roundings on each side: 16 eps_T.
    const double cosines[] = {0.05, 0.3, 0.7, 1.0};
    const double roughnesses[] = {0.02, 0.1, 0.4, 0.8, 1.0};
    for (const double nv : cosines)
        for (const double r : roughnesses)
            for (int iphi = 0; iphi < 5; ++iphi)
                for (int ipsi = 1; ipsi < 6; ++ipsi) {
                    const double alpha = r * r;
                    const double sin_v = std::sqrt(1 - nv * nv);
                    const double phi = pi * iphi / 4;
                    const flattened f = flatten(0.25 * pi * ipsi / 6, alpha);
                    const double vh = sin_v * std::cos(phi) * f.sin_theta + nv * f.cos_theta;
                    const double nl = 2 * vh * f.cos_theta - nv;
                    const T nv_t = T(nv), nl_t = T(nl), nh_t = T(f.cos_theta), vh_t = T(vh), r_t = T(r);
                    CAPTURE(nv);
                    CAPTURE(nl);
                    CAPTURE(r);
                    const T pdf_l = ibl::ndf_ggx(nh_t, T(alpha)) * nh_t / (T(4) * vh_t);
                    if (nl <= 0) {
                        CHECK(ibl::ggx_height_correlated::sample_weight(nv_t, nl_t, nh_t, vh_t, r_t) == T(0));
                        CHECK(ibl::ggx_schlick_ibl::sample_weight(nv_t, nl_t, nh_t, vh_t, r_t) == T(0));
                        continue;
                    }
                    using C = ibl::ggx_height_correlated;
                    using S = ibl::ggx_schlick_ibl;
                    const double ref_c = double(C::ndf(nh_t, C::alpha(r_t)) * C::visibility(nv_t, nl_t, r_t) * nl_t / pdf_l);
                    const double ref_s = double(S::ndf(nh_t, S::alpha(r_t)) * S::visibility(nv_t, nl_t, r_t) * nl_t / pdf_l);
                    CHECK(double(C::sample_weight(nv_t, nl_t, nh_t, vh_t, r_t)) == doctest::Approx(ref_c).epsilon(16 * eps<T>));
                    CHECK(double(S::sample_weight(nv_t, nl_t, nh_t, vh_t, r_t)) == doctest::Approx(ref_s).epsilon(16 * eps<T>));
                    // Separable G: weight = G (v.h) / ((n.h) (n.v)).
                    const double g = ibl::g_smith_schlick_ggx(nv_t, nl_t, ibl::k_ibl(r_t));
                    CHECK(double(S::sample_weight(nv_t, nl_t, nh_t, vh_t, r_t)) ==
                          doctest::Approx(g * double(vh_t) / (double(nh_t) * double(nv_t))).epsilon(16 * eps<T>));
                }
    // In the integral: the albedo from the weights equals the albedo from ndf * visibility
    // (the D of the measure is exact in the first, evaluated in T in the second). r >= 0.25 so
    // that the n.h form of D is accurate in float (2 eps / alpha^2 <= 3e-5, see the NDF test).
    for (const double nv : {0.1, 0.5, 0.9})
        for (const double r : {0.25, 0.5, 1.0}) {
            const double a = r * r;
            const double tol = 2 * eps<T> / (a * a) + 32 * eps<T>; // same nodes, same exact integrand: rounding only
            CHECK(albedo_by_weight<ibl::ggx_height_correlated, T>(nv, r, 32) ==
                  doctest::Approx(albedo_by_ndf<ibl::ggx_height_correlated, T>(nv, r, 32)).epsilon(tol));
            CHECK(albedo_by_weight<ibl::ggx_schlick_ibl, T>(nv, r, 32) ==
                  doctest::Approx(albedo_by_ndf<ibl::ggx_schlick_ibl, T>(nv, r, 32)).epsilon(tol));
        }
}

TEST_CASE_TEMPLATE("Lambert integrates to its albedo", T, float, double) {
    // int (albedo / pi) cos d(omega) = 2 pi int_0^{pi/2} (albedo / pi) cos sin d(theta) = albedo.
    // The integrand sin(2 theta) albedo / (2 pi) is analytic: 16 nodes are exact to 1e-16; albedo/pi
    // in T carries 1 eps_T: 2 eps_T.
    const quadrature q = gauss_legendre(16, 0.0, pi / 2);
    const ibl::vec3<T> albedo(T(0.8), T(0.5), T(0.05));
    double sum[3] = {0, 0, 0};
    for (std::size_t i = 0; i < q.x.size(); ++i) {
        const ibl::vec3<T> f = ibl::lambert(albedo);
        for (int ch = 0; ch < 3; ++ch) sum[ch] += q.w[i] * double(f[ch]) * std::cos(q.x[i]) * std::sin(q.x[i]) * 2 * pi;
    }
    for (int ch = 0; ch < 3; ++ch) CHECK(sum[ch] == doctest::Approx(double(albedo[ch])).epsilon(2 * eps<T> + 1e-14));
    CHECK(ibl::lambert(T(1)) == T(ibl::inv_pi_v<T>));
}

namespace {
struct no_weight_model { // a model missing sample_weight: not a brdf_model
    template <class T> static T alpha(T r) { return r * r; }
    template <class T> static T ndf(T n_dot_h, T alpha) { return ibl::ndf_ggx(n_dot_h, alpha); }
    template <class T> static T visibility(T, T, T) { return T(0.25); }
};
struct double_only_model { // returns double for float input: rejected for float
    static double alpha(double r) { return r * r; }
    static double ndf(double n_dot_h, double alpha) { return ibl::ndf_ggx(n_dot_h, alpha); }
    static double visibility(double, double, double) { return 0.25; }
    static double sample_weight(double, double, double, double, double) { return 1; }
};
} // namespace

TEST_CASE("brdf_model concept") {
    static_assert(ibl::brdf_model<ibl::ggx_schlick_ibl, float>);
    static_assert(ibl::brdf_model<ibl::ggx_height_correlated, double>);
    static_assert(!ibl::brdf_model<no_weight_model, float>);
    static_assert(ibl::brdf_model<double_only_model, double>);
    static_assert(!ibl::brdf_model<double_only_model, float>);
    static_assert(!ibl::brdf_model<ibl::ggx_schlick_ibl, int>);
    CHECK(std::string(ibl::ggx_height_correlated::name) == "ggx_height_correlated");
}
