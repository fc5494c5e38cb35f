// tests/test_sheen.cpp — specification of the sheen lobe: the Charlie NDF and Neubelt visibility
// (values, normalisation, limits), the Charlie samplers (chi-square, round trips), the sheen albedo
// against an independent quadrature and closed forms, its table, and the Charlie-prefiltered chain
// (white furnace, closed-form LD of a polynomial environment per level and between levels).
//
// Figures are printed when IBL_TEST_VERBOSE is set; the assertions do not depend on it.

#include <ibl/brdf/charlie.hpp>
#include <ibl/env/analytic.hpp>
#include <ibl/env/convert.hpp>
#include <ibl/env/cubemap.hpp>
#include <ibl/bake/prefilter.hpp>
#include <ibl/reference/ld_irradiance.hpp>
#include <ibl/bake/sheen.hpp>
#include <ibl/sampling/charlie.hpp>
#include <ibl/sampling/lobe.hpp>

#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <iostream>
#include <limits>
#include <string>
#include <vector>

#include "support/ld_poly.hpp"
#include "support/stats.hpp"

namespace {

using ibl_test::graded_integral;
using ibl_test::kernel_moments_quadrature;
using ibl_test::moment_bound;
using ibl_test::moments_of;
using ibl_test::poly_env;
using dvec2 = ibl::vec2<double>;
using dvec3 = ibl::vec3<double>;
constexpr double kPi = 3.141592653589793238462643383279502884;

bool verbose() {
    static const bool v = std::getenv("IBL_TEST_VERBOSE") != nullptr;
    return v;
}
#define SHEEN_REPORT(expr)                                                                               \
    do {                                                                                                 \
        if (verbose()) std::cout << expr << '\n';                                                       \
    } while (0)

double sqr_tan(double th) { return std::tan(th) * std::tan(th); }

template <class T> const char* type_name() { return sizeof(T) == sizeof(float) ? "float" : "double"; }

// -------------------------------------------------------------------------------------------------
// Independent sheen albedo: the raw integrand D V (n.l) 4 (v.h) over the half vector, in theta (not
// the library's ln cos), hp-graded toward the n.l = 0 boundary's breakpoints, phi graded toward its
// support edge. theta1 = asin(mu) / 2 (the library uses atan(mu / (1 + sin theta_v))).
// -------------------------------------------------------------------------------------------------
double reference_albedo(double mu, double r) {
    const double alpha = std::max(r * r, 0x1p-255), e = 1.0 / alpha, k = 2.0 + e;
    const double sv = std::sqrt(1.0 - mu * mu);
    const dvec3 v(sv, 0.0, mu);
    const double theta1 = 0.5 * std::asin(mu), theta2 = 0.5 * kPi - theta1;
    const ibl_test::gauss_legendre gl(10);
    auto integrand = [&](double th, double phi) {
        const double s = std::sin(th), c = std::cos(th);
        const dvec3 h(s * std::cos(phi), s * std::sin(phi), c);
        const double vh = glm::dot(v, h);
        const dvec3 l = 2.0 * vh * h - v;
        if (!(l.z > 0.0) || !(vh > 0.0)) return 0.0;
        const double d = k / (2.0 * kPi) * std::pow(s, e);
        const double vis = 1.0 / (4.0 * (l.z + mu - l.z * mu));
        return d * vis * l.z * 4.0 * vh * s;
    };
    auto over_phi = [&](double th) {
        const double s = std::sin(th), c = std::cos(th);
        const double a = 2.0 * c * s * sv, b = mu * (2.0 * c * c - 1.0);
        const double phi_max = a > 0.0 ? std::acos(std::clamp(-b / a, -1.0, 1.0)) : (b > 0.0 ? kPi : 0.0);
        return 2.0 * graded_integral([&](double phi) { return integrand(th, phi); }, 0.0, phi_max, 24, gl);
    };
    return graded_integral(over_phi, 0.0, theta1, 30, gl) + graded_integral(over_phi, theta1, theta2, 30, gl);
}

/// E(1, r) in closed form: V = 1/4, n.l = cos(2 theta_h): 2^(1 - k/2) / (k + 2).
double albedo_normal_incidence(double r) {
    const double k = 2.0 + 1.0 / std::max(r * r, 0x1p-255);
    return std::exp2(1.0 - 0.5 * k) / (k + 2.0);
}

// -------------------------------------------------------------------------------------------------
// Chi-square of isotropic half-vector samplers. Bins: n_b in a polar coordinate b(h) in [0, 1]
// chosen to resolve the lobe, n_phi in azimuth; expected counts by Gauss-Legendre in theta of the
// sampler's pdf over each cell (independent of the inverse CDF).
// -------------------------------------------------------------------------------------------------
constexpr double kFamilySignificance = 0.01;
constexpr int kChi2Tests = 2 * (4 + 3); // both types x (4 NDF alphas + 3 LD-lobe roughnesses)
const double kChi2Significance = 1.0 - std::pow(1.0 - kFamilySignificance, 1.0 / kChi2Tests);

/// Charlie NDF sampler; b = atan2(cos, beta sin) / (pi/2), beta = sqrt(alpha) (the lobe's width in cos).
struct charlie_ndf_warp {
    double alpha;
    double beta = std::sqrt(alpha);
    template <class S> ibl::vec3<S> sample(const ibl::vec2<S>& u) const { return ibl::sample_charlie_ndf(u, S(alpha)); }
    double pdf(const dvec3& h) const { return ibl::charlie_ndf_pdf(h, alpha); }
    double b_of(const dvec3& h) const {
        return std::atan2(h.z, beta * std::sqrt(h.x * h.x + h.y * h.y)) / (0.5 * kPi);
    }
    double theta_of_b(double b) const {
        const double psi = 0.5 * kPi * b;
        return std::atan2(std::cos(psi), beta * std::sin(psi));
    }
};

/// The Charlie LD lobe (theta_h < pi/4); b resolves n.l = cos(2 theta) on the scale beta = 2 alpha:
/// b = atan2(n.l, beta (1 - n.l)) / (pi/2).
struct charlie_lobe_warp {
    double roughness;
    double beta = 2.0 * roughness * roughness;
    template <class S> ibl::vec3<S> sample(const ibl::vec2<S>& u) const {
        return ibl::vec3<S>(ibl::charlie_lobe::sample(dvec2(u), roughness));
    }
    double pdf(const dvec3& h) const { return ibl::charlie_lobe::pdf(h, roughness); }
    double b_of(const dvec3& h) const {
        const double nl = h.z * h.z - (h.x * h.x + h.y * h.y);
        return std::atan2(std::max(nl, 0.0), beta * (1.0 - nl)) / (0.5 * kPi);
    }
    double theta_of_b(double b) const {
        const double psi = 0.5 * kPi * b;
        const double nl = beta * std::sin(psi) / (std::cos(psi) + beta * std::sin(psi));
        return 0.5 * std::acos(nl);
    }
};

template <class T, class Warp> ibl_test::chi2_result run_chi2(const Warp& w, std::uint64_t seed, int n = 100000, int n_b = 10,
                                                             int n_phi = 20) {
    ibl_test::uniform_rng rng(seed);
    std::vector<double> observed(std::size_t(n_b * n_phi), 0.0), expected(observed.size(), 0.0);
    int bad = 0;
    for (int i = 0; i < n; ++i) {
        const T u0 = rng.next<T>(), u1 = rng.next<T>();
        const dvec3 h(w.sample(ibl::vec2<T>(u0, u1)));
        if (!(h.z > 0.0) || !std::isfinite(h.x) || !std::isfinite(h.y)) {
            ++bad;
            continue;
        }
        const int ib = std::min(int(w.b_of(h) * n_b), n_b - 1);
        double phi = std::atan2(h.y, h.x);
        if (phi < 0) phi += 2 * kPi;
        const int ip = std::min(int(phi / (2 * kPi) * n_phi), n_phi - 1);
        observed[std::size_t(ib * n_phi + ip)] += 1;
    }
    CHECK(bad == 0);
    const ibl_test::gauss_legendre gl(16);
    for (int i = 0; i < n_b; ++i) {
        const double t0 = w.theta_of_b(double(i + 1) / n_b), t1 = w.theta_of_b(double(i) / n_b); // theta decreases in b
        for (int j = 0; j < n_phi; ++j) {
            const double phi_c = 2 * kPi * (j + 0.5) / n_phi;
            const double mass = gl.integrate(
                [&](double th) {
                    const dvec3 h(std::sin(th) * std::cos(phi_c), std::sin(th) * std::sin(phi_c), std::cos(th));
                    return w.pdf(h) * std::sin(th);
                },
                t0, t1, 4);
            expected[std::size_t(i * n_phi + j)] = n * mass * (2 * kPi / n_phi);
        }
    }
    return ibl_test::chi2_test(observed, expected);
}

template <class T, class Warp> void check_chi2(const Warp& w, std::uint64_t seed, const std::string& name) {
    const ibl_test::chi2_result r = run_chi2<T>(w, seed + (sizeof(T) == 4 ? 0 : 7919));
    SHEEN_REPORT(name << " <" << type_name<T>() << ">: chi2 = " << r.statistic << ", dof = " << r.dof << ", p = " << r.p_value
                      << ", pooled = " << r.pooled_cells);
    // The cell masses integrate the pdf to 1 up to the 4 x 16-node rule's error (far below the
    // Poisson noise of 1e5 samples, relative 3e-3).
    CHECK(r.expected_total == doctest::Approx(r.observed_total).epsilon(1e-4));
    CHECK(r.dof >= 60);
    CHECK(r.p_value > kChi2Significance);
}

/// The Charlie LD kernel's moments in closed form. With u the restricted CDF variable and
/// z = -ln u, the kernel D (n.l) dl is e^-z n.l dz dphi up to a constant and n.l = 1 - e^(-a z),
/// a = 2 / k; int e^-z (1 - e^(-a z))^m dz = m! a^m / prod_{j=1..m} (1 + j a) (a Beta integral), so
/// E[n.l] = 2a / (1 + 2a), E[(n.l)^2] = 6 a^2 / ((1 + 2a)(1 + 3a)).
dvec2 charlie_kernel_moments(double roughness) {
    const double a = 2.0 / ibl::charlie_exponent(ibl::charlie_lobe::alpha(roughness));
    return {2 * a / (1 + 2 * a), 6 * a * a / ((1 + 2 * a) * (1 + 3 * a))};
}

} // namespace

// =================================================================================================
// The Charlie NDF and the Neubelt visibility.
// =================================================================================================

TEST_CASE_TEMPLATE("ndf_charlie: closed-form values, normalisation and the r -> 0 limit", T, float, double) {
    const double eps = double(ibl::epsilon_v<T>);
    // r = 1: D = 3 sin / (2 pi); exp/log evaluation: a few eps relative.
    // The reference takes sin from the rounded input cosine (in long double), so only the
    // function's own rounding remains.
    for (double th : {0.1, 0.7, 1.2, 1.5}) {
        const T c = T(std::cos(th));
        const long double cl = c, sl = std::sqrt((1.0L - cl) * (1.0L + cl));
        const double d = double(ibl::ndf_charlie(c, T(1)));
        CHECK(std::fabs(d / double(3.0L * sl / (2.0L * 3.14159265358979323846264338327950288L)) - 1.0) <= 16 * eps);
    }
    // The peak (n.h = 0) and the zeros (n.h = 1, n.h < 0, NaN).
    for (double a : {1.0, 0.25, 0.01, 1e-4}) {
        CHECK(double(ibl::ndf_charlie(T(0), T(a))) == doctest::Approx((2 + 1 / a) / (2 * kPi)).epsilon(8 * eps));
        CHECK(ibl::ndf_charlie(T(1), T(a)) == T(0));
        CHECK(ibl::ndf_charlie(T(-0.3), T(a)) == T(0));
        CHECK(ibl::ndf_charlie(std::numeric_limits<T>::quiet_NaN(), T(a)) == T(0));
    }
    // Vector and scalar forms agree: the rounded components give sin^2 (from h.x, h.y) and
    // 1 - h.z^2 that differ by ~4 eps (1 + cot^2) relative; D scales that by 1/(2 alpha).
    for (double a : {1.0, 0.1})
        for (double th : {0.05, 0.6, 1.4}) {
            const ibl::vec3<T> h(T(std::sin(th) * 0.6), T(std::sin(th) * 0.8), T(std::cos(th)));
            const double rel = std::fabs(double(ibl::ndf_charlie(h, T(a))) / double(ibl::ndf_charlie(h.z, T(a))) - 1.0);
            CHECK(rel <= 4 * eps * (1 + 1 / sqr_tan(th)) / (2 * a) + 16 * eps);
        }
    // r = 0 and alpha = 0: finite everywhere (the clamp), the peak at the horizon.
    for (T c : {T(0), T(1e-3), T(0.5), T(1)}) {
        const T d = ibl::ndf_charlie(c, T(0));
        CHECK(std::isfinite(double(d)));
        CHECK(d >= T(0));
    }
    CHECK(ibl::ndf_charlie(T(0.5), T(0)) == T(0)); // sin^(2^31) underflows: D -> 0 off the horizon
}

TEST_CASE("ndf_charlie integrates to 1 against n.h (graded double quadrature)") {
    const ibl_test::gauss_legendre gl(12);
    for (double a : {1.0, 0.5, 0.1, 0.01, 1e-3, 1e-5}) {
        const double s = 2 * kPi * graded_integral([&](double th) { return ibl::ndf_charlie(std::cos(th), a) * std::cos(th) * std::sin(th); },
                                                   0.0, 0.5 * kPi, 40, gl);
        SHEEN_REPORT("int D n.h, alpha = " << a << ": " << s - 1);
        CHECK(std::fabs(s - 1.0) <= 1e-12); // graded 12-node panels on a smooth integrand: rounding only
    }
}

TEST_CASE_TEMPLATE("v_neubelt: values and limits", T, float, double) {
    const double eps = double(ibl::epsilon_v<T>);
    CHECK(ibl::v_neubelt(T(1), T(1)) == T(0.25));
    for (double x : {1.0, 0.5, 0.1, 1e-3}) {
        CHECK(double(ibl::v_neubelt(T(0), T(x))) == doctest::Approx(0.25 / x).epsilon(2 * eps));
        CHECK(double(ibl::v_neubelt(T(x), T(0))) == doctest::Approx(0.25 / x).epsilon(2 * eps));
        CHECK(double(ibl::v_neubelt(T(0), T(x)) * T(x)) == doctest::Approx(0.25).epsilon(2 * eps));
    }
    for (double v : {0.0, 0.2, 0.9})
        for (double l : {0.0, 0.3, 1.0}) {
            const double val = double(ibl::v_neubelt(T(v), T(l)));
            CHECK(val >= 0.25 * (1 - eps));
            if (v + l > 0) CHECK(val == doctest::Approx(0.25 / (l + v - l * v)).epsilon(4 * eps));
            CHECK(val * l <= 0.25 * (1 + 2 * eps));
        }
    const T corner = ibl::v_neubelt(T(0), T(0));
    CHECK(std::isfinite(double(corner)));
    CHECK(corner * T(0) == T(0));
}

// =================================================================================================
// Samplers.
// =================================================================================================

TEST_CASE_TEMPLATE("sample_charlie_ndf: chi-square goodness of fit", T, float, double) {
    std::uint64_t seed = 101;
    for (double a : {1.0, 0.25, 0.04, 0.0025}) check_chi2<T>(charlie_ndf_warp{a}, seed++, "Charlie NDF alpha " + std::to_string(a));
}

TEST_CASE_TEMPLATE("charlie_lobe (LD draws, theta_h < pi/4): chi-square goodness of fit", T, float, double) {
    std::uint64_t seed = 201;
    for (double r : {1.0, 0.5, 0.1}) check_chi2<T>(charlie_lobe_warp{r}, seed++, "Charlie LD lobe r " + std::to_string(r));
}

TEST_CASE_TEMPLATE("sample_charlie_ndf: range, the corners of the domain, round trips", T, float, double) {
    const double eps = double(ibl::epsilon_v<T>);
    ibl_test::uniform_rng rng(7);
    for (double a : {1.0, 0.25, 0.04}) {
        const double k = 2 + 1 / a;
        double worst = 0;
        for (int i = 0; i < 2000; ++i) {
            const ibl::vec2<T> u = rng.next2<ibl::vec2<T>>();
            const ibl::vec3<T> h = ibl::sample_charlie_ndf(u, T(a));
            CHECK(std::fabs(double(glm::length(h)) - 1.0) <= 4 * eps);
            CHECK(h.z > T(0));
            const ibl::vec2<T> back = ibl::invert_charlie_ndf(h, T(a));
            // u.x = s^k: a relative error of ~4 eps in s^2 (sampling, then x^2 + y^2) becomes k/2 of
            // it in u.x; u.y = phi / 2 pi within a few eps (atan2 of rounded components).
            const double ex = std::fabs(double(back.x) - double(u.x)) / (2 * k * eps * double(u.x) + eps);
            double dy = std::fabs(double(back.y) - double(u.y));
            dy = std::min(dy, 1 - dy);
            CHECK(ex <= 1.0);
            CHECK(dy <= 8 * eps);
            worst = std::max(worst, ex);
        }
        SHEEN_REPORT("Charlie round trip <" << type_name<T>() << ">, alpha " << a << ": worst |du.x| / tol = " << worst);
    }
    // u = 0 gives the normal; the largest variate stays above the horizon; alpha = 0 is finite.
    const ibl::vec3<T> n = ibl::sample_charlie_ndf(ibl::vec2<T>(T(0), T(0.3)), T(0.5));
    CHECK(n.z == T(1));
    for (double a : {1.0, 1e-3, 0.0}) {
        const ibl::vec3<T> g = ibl::sample_charlie_ndf(ibl::vec2<T>(ibl::one_minus_epsilon_v<T>, T(0.5)), T(a));
        CHECK(g.z > T(0));
        CHECK(std::isfinite(double(ibl::charlie_ndf_pdf(g, T(a)))));
    }
}

// =================================================================================================
// The sheen albedo.
// =================================================================================================

TEST_CASE("sheen_albedo: closed form at n.v = 1 and the limits") {
    for (double r : {1.0, 0.7, 0.5, 0.3, 0.2, 0.1}) {
        const double e = ibl::sheen_albedo(1.0, r), ref = albedo_normal_incidence(r);
        SHEEN_REPORT("E(1, " << r << ") = " << e << ", closed form " << ref);
        // Gauss-Legendre in theta on an entire integrand: converged to rounding (measured <= 4e-12).
        CHECK(std::fabs(e - ref) <= 1e-10 * ref);
    }
    // r -> 0: E -> 0 for mu > 0 (exp(-k c2^2 / 2) underflows); finite and large at the n.v clamp.
    CHECK(ibl::sheen_albedo(0.5, 0.0) == 0.0);
    const double grazing = ibl::sheen_albedo(0.0, 0.05);
    CHECK(std::isfinite(grazing));
    CHECK(grazing > 1.0);
    CHECK(std::isfinite(ibl::sheen_albedo(0.0, 0.0)));
    // n.v below the clamp gives the clamp's value.
    CHECK(ibl::sheen_albedo(1e-9, 0.3) == ibl::sheen_albedo(ibl::sheen_min_n_dot_v, 0.3));
}

TEST_CASE("sheen_albedo against an independent quadrature (texel centres of 32^2, the edges of 128^2)") {
    std::vector<dvec2> pts;
    for (int j = 0; j < 32; j += 3)
        for (int i = 0; i < 32; i += 3) pts.emplace_back((i + 0.5) / 32, (j + 0.5) / 32);
    for (int t = 0; t < 128; t += 9) {
        pts.emplace_back(0.5 / 128, (t + 0.5) / 128); // first column: n.v = 0.5 / 128
        pts.emplace_back((t + 0.5) / 128, 0.5 / 128); // first row: r = 0.5 / 128
    }
    pts.emplace_back(0.5 / 128, 0.5 / 128);
    double worst_abs = 0, worst_rel = 0, e_max = 0;
    for (const dvec2& p : pts) {
        const double e = ibl::sheen_albedo(p.x, p.y), ref = reference_albedo(p.x, p.y);
        const double err = std::fabs(e - ref);
        e_max = std::max(e_max, ref);
        if (ref > 1.0) {
            worst_rel = std::max(worst_rel, err / ref);
            CHECK_MESSAGE(err / ref <= 1e-5, "n.v = " << p.x << ", r = " << p.y << ": " << e << " vs " << ref);
        } else {
            worst_abs = std::max(worst_abs, err);
            CHECK_MESSAGE(err <= 1e-5, "n.v = " << p.x << ", r = " << p.y << ": " << e << " vs " << ref);
        }
    }
    SHEEN_REPORT("sheen albedo vs independent quadrature, " << pts.size() << " points: max abs error (E <= 1) " << worst_abs
                                                             << ", max rel error (E > 1) " << worst_rel << ", largest E " << e_max);
}

TEST_CASE("sheen_albedo agrees with Monte Carlo over the Charlie sampler") {
    // Mean of D V (n.l) / pdf_l = 4 V (n.l) (v.h) / (n.h) over h ~ sample_charlie_ndf (independent of
    // the quadrature's change of variables). 4 standard errors.
    for (const dvec2 p : {dvec2(0.5, 0.5), dvec2(0.1, 0.3), dvec2(0.8, 0.9)}) {
        const double mu = p.x, r = p.y, alpha = r * r;
        const dvec3 v(std::sqrt(1 - mu * mu), 0, mu);
        ibl_test::uniform_rng rng(3);
        const int n = 200000;
        double s = 0, s2 = 0;
        for (int i = 0; i < n; ++i) {
            const dvec3 h = ibl::sample_charlie_ndf(rng.next2<dvec2>(), alpha);
            const double vh = glm::dot(v, h);
            const double nl = 2 * vh * h.z - mu;
            const double w = nl > 0 && vh > 0 ? 4 * ibl::v_neubelt(mu, nl) * nl * vh / h.z : 0.0;
            s += w;
            s2 += w * w;
        }
        const double mean = s / n, se = std::sqrt((s2 / n - mean * mean) / n);
        const double e = ibl::sheen_albedo(mu, r);
        SHEEN_REPORT("MC E(" << mu << ", " << r << ") = " << mean << " +- " << se << ", quadrature " << e);
        CHECK(std::fabs(mean - e) <= 4 * se);
    }
}

TEST_CASE("make_sheen_lut: the DFG layout, one channel, bilinear sample at texel centres") {
    const std::uint32_t n = 16;
    const ibl::dfg_lut lut = ibl::make_sheen_lut(n);
    CHECK(lut.size == n);
    CHECK(lut.channels == 1);
    REQUIRE(lut.data.size() == std::size_t(n) * n);
    for (std::uint32_t j = 0; j < n; j += 5)
        for (std::uint32_t i = 0; i < n; i += 3) {
            const float e = float(ibl::sheen_albedo(lut.n_dot_v(i), lut.roughness(j)));
            CHECK(lut.at(i, j, 0) == e);
            const ibl::vec3<float> s = lut.sample(float(lut.n_dot_v(i)), float(lut.roughness(j)));
            CHECK(double(s.x) == doctest::Approx(double(e)).epsilon(1e-6)); // float centre coordinates
            CHECK(s.y == 0.0f);
        }
    // Serial and threaded tables are identical.
    const ibl::dfg_lut serial = ibl::make_sheen_lut(n, ibl::sheen_lut_default_nodes, ibl::serial_executor{});
    CHECK(serial.data == lut.data);
}

// =================================================================================================
// The Charlie-prefiltered chain.
// =================================================================================================

TEST_CASE("charlie LD kernel moments: closed form against quadrature") {
    for (double r : {1.0, 0.75, 0.5, 0.3}) {
        const double a = r * r;
        const dvec2 c = charlie_kernel_moments(r);
        const dvec2 q = kernel_moments_quadrature([&](double th) { return ibl::ndf_charlie(std::cos(th), a); });
        CHECK(std::fabs(c.x - q.x) <= 1e-12);
        CHECK(std::fabs(c.y - q.y) <= 1e-12);
    }
}

TEST_CASE("prefilter<charlie_lobe>: white furnace") {
    ibl::cubemap<float> ones(16);
    ones.fill(0, [](int, int, int) { return ibl::vec3<float>(1.0f); });
    ones.generate_mips();
    ibl::prefilter_options o;
    o.levels = 5;
    o.samples = 256;
    for (bool tri : {true, false}) {
        o.trilinear = tri;
        const ibl::cubemap<float> m = ibl::prefilter_sheen(ones, o);
        double worst = 0;
        for (int l = 0; l < m.levels(); ++l)
            for (int f = 0; f < 6; ++f)
                for (int y = 0; y < m.size(l); ++y)
                    for (int x = 0; x < m.size(l); ++x)
                        for (int c = 0; c < 3; ++c) worst = std::max(worst, std::fabs(double(m.texel(f, x, y, l)[c]) - 1.0));
        SHEEN_REPORT("Charlie chain white furnace (trilinear " << tri << "): max |LD - 1| = " << worst);
        // Normalised blocked float sums of equal values: the weights' sum divides the same sum.
        CHECK(worst <= 4 * double(ibl::epsilon_v<float>));
    }
}

TEST_CASE("prefilter<charlie_lobe> on a polynomial environment against the closed-form LD, per level and between levels") {
    const poly_env env;
    ibl::prefilter_options o;
    o.levels = 5;
    o.base_size = 8;
    o.samples = 512;
    o.samples_per_level = {512};
    const ibl::cubemap<float> m = ibl::prefilter<ibl::charlie_lobe>(env, o);
    const int levels = m.levels();
    double between = 0;
    for (int l = 0; l < levels; ++l) {
        const double r = o.policy.roughness(double(l), levels);
        const dvec2 mom = charlie_kernel_moments(r);
        const auto table = ibl::make_ld_table_for<float, ibl::charlie_lobe>(env, r, ibl::prefilter_samples(o, l, levels), o.method,
                                                                          o.lod_bias);
        const double bound = moment_bound(env, moments_of(table), mom);
        double worst = 0;
        const int n = m.size(l);
        for (int f = 0; f < 6; ++f)
            for (int y = 0; y < n; ++y)
                for (int x = 0; x < n; ++x) {
                    const dvec3 d = ibl::cube_texel_direction<double>(f, x, y, n);
                    const double ref = env.ld(d, mom.x, mom.y);
                    worst = std::max(worst, std::fabs(double(m.texel(f, x, y, l).x) - ref));
                }
        SHEEN_REPORT("Charlie LD level " << l << " (r = " << r << ", " << table.size() << " draws): max |LD - closed form| = "
                                         << worst << ", moment bound " << bound);
        // The estimate is exactly the table's moments applied to the polynomial: its error is at most
        // the moment bound, plus float storage of the table (directions and weights, 2^-24 relative:
        // 4 eps_f |L|max) and of the result.
        CHECK(worst <= bound + 8 * double(ibl::epsilon_v<float>) * 2.0);
        // Between levels: a renderer's linear blend of levels l and l + 1 at the mid roughness.
        if (l + 1 < levels) {
            const double rm = o.policy.roughness(double(l) + 0.5, levels);
            const dvec2 mm = charlie_kernel_moments(rm);
            for (int f = 0; f < 6; ++f) {
                const dvec3 d = ibl::cube_texel_direction<double>(f, 0, 0, 1);
                const double blend = 0.5 * (double(m.radiance(ibl::vec3<float>(d), float(l)).x) +
                                            double(m.radiance(ibl::vec3<float>(d), float(l + 1)).x));
                between = std::max(between, std::fabs(blend - env.ld(d, mm.x, mm.y)));
            }
            SHEEN_REPORT("  between levels " << l << " and " << l + 1 << " (r = " << rm << "): max |blend - closed form| = " << between);
            between = 0;
        }
    }
    // Also through a cubemap source (the fast path, texel and mip filtering included): figure only.
    const ibl::cubemap<float> src = ibl::bake_cubemap<float>(ibl::make_lambda_environment<double>([&](const dvec3& d) {
                                                                 return env.radiance(d, 0.0);
                                                             }),
                                                             32, 2);
    ibl::prefilter_options oc;
    oc.levels = 5;
    oc.base_size = 16;
    const ibl::cubemap<float> mc = ibl::prefilter_sheen(src, oc);
    for (int l = 0; l < mc.levels(); ++l) {
        const dvec2 mom = charlie_kernel_moments(oc.policy.roughness(double(l), mc.levels()));
        double worst = 0;
        const int n = mc.size(l);
        for (int f = 0; f < 6; ++f)
            for (int y = 0; y < n; ++y)
                for (int x = 0; x < n; ++x) {
                    const dvec3 d = ibl::cube_texel_direction<double>(f, x, y, n);
                    worst = std::max(worst, std::fabs(double(mc.texel(f, x, y, l).x) - env.ld(d, mom.x, mom.y)));
                }
        SHEEN_REPORT("Charlie chain from a 32^2 cubemap, level " << l << ": max |LD - closed form| = " << worst);
        CHECK(worst < 0.05); // a sanity ceiling for the figure (texel, mip and QMC error together)
    }
}

TEST_CASE("reference_ld<charlie_lobe> converges to the closed-form LD") {
    const poly_env env;
    for (double r : {0.0, 0.25, 0.6, 1.0}) {
        const dvec2 mom = charlie_kernel_moments(r);
        const dvec3 R = glm::normalize(dvec3(0.3, -0.5, 0.8));
        const double ref = env.ld(R, mom.x, mom.y);
        const double e = ibl::reference_ld<ibl::charlie_lobe>(env, R, r, 1u << 16).x;
        SHEEN_REPORT("reference_ld<charlie> r = " << r << ": " << e - ref);
        CHECK(std::fabs(e - ref) <= 1e-3); // 2^16 Hammersley points on a smooth integrand: O(log n / n)
    }
}
