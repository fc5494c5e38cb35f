// tests/test_sampling.cpp — specification of the sampling layer: sequences (exact values, net
// property), warps (known values, pdf normalisation, pdf = 1/|Jacobian|, chi-square
// goodness-of-fit, round trips through the inverses) and the GGX mirror limit.
//
// Tolerances are derived, each with a one-line comment. Two constants recur:
//   kRoundingSteps = 8: a bound on the rounding error, in units of epsilon_v<T>, of one evaluation
//   of a warp or of its inverse (each is at most ~10 correctly rounded operations of relative
//   error eps/2 plus libm sin/cos/atan2 within 1 ulp on glibc, i.e. <= ~6 eps; rounded up to 8).
//   Finite differences in double use the a-posteriori Richardson estimate |J(d) - J(2d)| of
//   their own truncation error plus eps_double / d of rounding.

#include <ibl/core/frame.hpp>
#include <ibl/sampling.hpp>

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

#include "support/stats.hpp"

namespace {

using dvec2 = ibl::vec2<double>;
using dvec3 = ibl::vec3<double>;
constexpr double kPi = 3.141592653589793238462643383279502884;
constexpr double kRoundingSteps = 8.0;

// Family-wise significance of all chi-square tests in this file, 1 %, split over the tests by
// the Sidak correction (as in Mitsuba 3's chi2 tests), so that the file as a whole rejects a
// correct sampler with probability 1 %. kChi2Tests is the number of run_chi2 calls (both types).
constexpr double kFamilySignificance = 0.01;
constexpr int kChi2Tests = 2 * (3 + 4 + 9);
const double kChi2Significance = 1.0 - std::pow(1.0 - kFamilySignificance, 1.0 / kChi2Tests);

/// Measured figures (chi-square statistics, integrals, error ratios) are printed when the
/// environment variable IBL_TEST_VERBOSE is set; the assertions do not depend on it.
bool verbose() {
    static const bool v = std::getenv("IBL_TEST_VERBOSE") != nullptr;
    return v;
}
#define IBL_TEST_REPORT(expr)                                                                            \
    do {                                                                                                 \
        if (verbose()) std::cout << expr << '\n';                                                       \
    } while (0)

template <class T> const char* type_name() { return sizeof(T) == sizeof(float) ? "float" : "double"; }
/// Different streams for the float and the double run of a test (independent evidence).
template <class T> std::uint64_t seed_for(std::uint64_t seed) { return seed + (sizeof(T) == sizeof(float) ? 0 : 7919); }

template <class T> dvec3 to_d(const ibl::vec3<T>& w) { return dvec3(w); }
template <class T> dvec2 to_d(const ibl::vec2<T>& u) { return dvec2(u); }

double wrap_2pi(double phi) {
    phi = std::fmod(phi, 2 * kPi);
    return phi < 0 ? phi + 2 * kPi : phi;
}

/// Distance on the circle of circumference 1 (for azimuthal variates u = phi / 2 pi).
double circular_diff(double a, double b) {
    const double d = a - b;
    return std::fabs(d - std::round(d));
}

dvec3 direction(double theta, double phi) {
    return dvec3(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
}

/// Bit reversal one bit at a time: the reference for ibl::reverse_bits.
std::uint32_t reverse_bits_reference(std::uint32_t x) {
    std::uint32_t r = 0;
    for (int b = 0; b < 32; ++b) r |= ((x >> b) & 1u) << (31 - b);
    return r;
}

// ---------------------------------------------------------------------------------------------
// Warps under test, as descriptors usable with any scalar type S (float, double).
// beta: the width of the lobe for the theta binning/quadrature variable (tan theta = beta tan psi);
// periodic_x/y: which variate is an azimuth (compared on the circle).
// ---------------------------------------------------------------------------------------------

struct uniform_hemisphere_warp {
    static constexpr bool periodic_x = false, periodic_y = true;
    double beta = 1, phi_offset = 0;
    template <class S> ibl::vec3<S> sample(const ibl::vec2<S>& u) const { return ibl::sample_uniform_hemisphere(u); }
    template <class S> ibl::vec2<S> invert(const ibl::vec3<S>& w) const { return ibl::invert_uniform_hemisphere(w); }
    double pdf(const dvec3&) const { return ibl::uniform_hemisphere_pdf<double>(); }
    int breaks(double, double*) const { return 0; }
    double kink_theta() const { return 0; }
};

struct cosine_hemisphere_warp {
    static constexpr bool periodic_x = false, periodic_y = false;
    double beta = 1, phi_offset = 0;
    template <class S> ibl::vec3<S> sample(const ibl::vec2<S>& u) const { return ibl::sample_cosine_hemisphere(u); }
    template <class S> ibl::vec2<S> invert(const ibl::vec3<S>& w) const { return ibl::invert_cosine_hemisphere(w); }
    double pdf(const dvec3& w) const { return ibl::cosine_hemisphere_pdf(w.z); }
    int breaks(double, double*) const { return 0; }
    double kink_theta() const { return 0; }
};

struct ggx_ndf_warp {
    static constexpr bool periodic_x = false, periodic_y = true;
    double alpha;
    double beta = alpha, phi_offset = 0;
    template <class S> ibl::vec3<S> sample(const ibl::vec2<S>& u) const { return ibl::sample_ggx_ndf(u, S(alpha)); }
    template <class S> ibl::vec2<S> invert(const ibl::vec3<S>& w) const { return ibl::invert_ggx_ndf(w, S(alpha)); }
    double pdf(const dvec3& h) const { return ibl::ggx_ndf_pdf(h, alpha); }
    int breaks(double, double*) const { return 0; }
    double kink_theta() const { return 0; }
};

/// View direction with n.v = cos_v at azimuth phi_v.
dvec3 view_direction(double cos_v, double phi_v) {
    const double s = std::sqrt((1 - cos_v) * (1 + cos_v));
    return dvec3(s * std::cos(phi_v), s * std::sin(phi_v), cos_v);
}

struct ggx_vndf_warp {
    static constexpr bool periodic_x = true, periodic_y = false;
    double alpha;
    dvec3 v;
    double beta = alpha, phi_offset = std::atan2(v.y, v.x);
    template <class S> ibl::vec3<S> sample(const ibl::vec2<S>& u) const {
        return ibl::sample_ggx_vndf(ibl::vec3<S>(v), u, S(alpha));
    }
    template <class S> ibl::vec2<S> invert(const ibl::vec3<S>& h) const {
        return ibl::invert_ggx_vndf(ibl::vec3<S>(v), h, S(alpha));
    }
    double pdf(const dvec3& h) const { return ibl::ggx_vndf_pdf(v, h, alpha); }
    /// The support edge v.h = 0 in the relative azimuth phi' = phi - phi_v at polar angle theta:
    /// v.h > 0 <=> cos(phi') > -cot(theta_v) cot(theta) =: k; breaks at phi' = +-acos(k).
    int breaks(double theta, double* out) const {
        const double sin_v = std::sqrt(v.x * v.x + v.y * v.y);
        if (sin_v == 0) return 0;
        const double k = -v.z * std::cos(theta) / (sin_v * std::sin(theta));
        if (!(k > -1 && k < 1)) return 0;
        const double phi = std::acos(k);
        out[0] = phi;
        out[1] = 2 * kPi - phi;
        return 2;
    }
    /// Polar angle pi/2 - theta_v beyond which the support edge cuts the azimuth range (0: none).
    /// There the phi-integral has a (theta - theta_0)^(3/2) term: the quadrature splits at it.
    double kink_theta() const {
        const double sin_v = std::sqrt(v.x * v.x + v.y * v.y);
        return sin_v > 0 && v.z > 0 ? std::atan2(v.z, sin_v) : 0.0;
    }
};

// ---------------------------------------------------------------------------------------------
// Quadrature of a solid-angle pdf over (theta, phi) cells, in the binning variable
// t = psi / (pi/2) in [0, 1], tan(theta) = beta tan(psi): cells of equal t resolve a GGX peak of
// width beta, and the integrand is smooth in t. d omega = sin(theta) (d theta / d t) dt dphi.
// ---------------------------------------------------------------------------------------------

double theta_of_t(double t, double beta) {
    const double psi = 0.5 * kPi * t;
    return std::atan2(beta * std::sin(psi), std::cos(psi));
}
double dtheta_dt(double t, double beta) {
    const double psi = 0.5 * kPi * t;
    const double c = std::cos(psi), s = std::sin(psi);
    return 0.5 * kPi * beta / (c * c + beta * beta * s * s);
}
double t_of_theta(double theta, double beta) {
    return std::atan2(std::sin(theta), beta * std::cos(theta)) / (0.5 * kPi);
}
double t_of_direction(const dvec3& w, double beta) {
    const double psi = std::atan2(std::sqrt(w.x * w.x + w.y * w.y), beta * w.z);
    return psi / (0.5 * kPi);
}

/// Integral over phi in [phi0, phi1] (relative azimuth) of warp.pdf at the polar angle of t,
/// times the solid-angle factor sin(theta) d theta / dt. The azimuth range is split at the pdf's
/// support edges so that each Gauss-Legendre piece has a smooth integrand.
template <class Warp>
double phi_integral(const Warp& warp, double t, double phi0, double phi1, const ibl_test::gauss_legendre& gl) {
    const double theta = theta_of_t(t, warp.beta);
    double cuts[4], b[2];
    int n = 0;
    cuts[n++] = phi0;
    const int nb = warp.breaks(theta, b);
    for (int i = 0; i < nb; ++i)
        if (b[i] > phi0 && b[i] < phi1) cuts[n++] = b[i];
    // At most two breaks: order them by hand (std::sort here trips a g++ 12 -Warray-bounds
    // false positive at -O2).
    if (n == 3 && cuts[2] < cuts[1]) std::swap(cuts[1], cuts[2]);
    cuts[n++] = phi1;
    double s = 0;
    for (int i = 0; i + 1 < n; ++i)
        s += gl.integrate([&](double phi) { return warp.pdf(direction(theta, phi + warp.phi_offset)); }, cuts[i],
                          cuts[i + 1]);
    return s * std::sin(theta) * dtheta_dt(t, warp.beta);
}

/// Integral of warp.pdf over the cell [t0, t1] x [phi0, phi1].
template <class Warp>
double integrate_cell(const Warp& warp, double t0, double t1, double phi0, double phi1,
                      const ibl_test::gauss_legendre& gl) {
    return gl.integrate([&](double t) { return phi_integral(warp, t, phi0, phi1, gl); }, t0, t1);
}

/// Integral of warp.pdf over the hemisphere: n_t panels in t times n_phi panels in phi, each with
/// the rule gl. If the support edge starts cutting the azimuth range at t_k (kink_theta), the t
/// range is split there and [t_k, 1] is integrated in s with t = t_k + (1 - t_k) s^2, which turns
/// the (t - t_k)^(3/2) term of the phi-integral into the smooth s^3.
template <class Warp> double integrate_hemisphere(const Warp& warp, int n_t, int n_phi, int nodes) {
    const ibl_test::gauss_legendre gl(nodes);
    const auto over_phi = [&](double t) {
        double sum = 0;
        for (int j = 0; j < n_phi; ++j)
            sum += phi_integral(warp, t, 2 * kPi * j / n_phi, 2 * kPi * (j + 1) / n_phi, gl);
        return sum;
    };
    const double tk = warp.kink_theta() > 0 ? t_of_theta(warp.kink_theta(), warp.beta) : 1.0;
    double total = gl.integrate(over_phi, 0.0, tk, n_t);
    if (tk < 1.0)
        total += gl.integrate([&](double s) { return over_phi(tk + (1 - tk) * s * s) * 2 * (1 - tk) * s; }, 0.0,
                              1.0, n_t);
    return total;
}

/// Integral over the hemisphere with an a-posteriori error estimate: the difference between the
/// grid and the grid refined twice in each direction (the coarse error dominates).
/// Rounding of the quadrature sums: ~3e4 node values added naively, n eps_double ~ 4e-12.
constexpr double kSumRounding = 4e-12;

struct integral_estimate {
    double value, error;
};
template <class Warp> integral_estimate integrate_pdf(const Warp& warp) {
    const double coarse = integrate_hemisphere(warp, 16, 8, 8);
    const double fine = integrate_hemisphere(warp, 32, 16, 8);
    return {fine, std::fabs(fine - coarse)};
}

// ---------------------------------------------------------------------------------------------
// Chi-square goodness of fit.
// ---------------------------------------------------------------------------------------------

struct chi2_report {
    ibl_test::chi2_result r;
    double critical;          ///< critical value at kChi2Significance (the test's threshold)
    double critical_1pct;     ///< critical value at 1 % (for the report)
    int out_of_domain = 0;    ///< samples with z < 0 or non-finite
};

/// Draws n samples of warp.sample<T> with a fixed-seed PRNG, bins them in n_t x n_phi cells of
/// (t, relative phi), and tests the counts against n * (integral of pdf over each cell).
template <class T, class Warp>
chi2_report run_chi2(const Warp& warp, std::uint64_t seed, int n = 100000, int n_t = 10, int n_phi = 20) {
    ibl_test::uniform_rng rng(seed);
    std::vector<double> observed(std::size_t(n_t * n_phi), 0.0), expected(observed.size(), 0.0);
    chi2_report rep{};
    for (int k = 0; k < n; ++k) {
        const T u0 = rng.next<T>();
        const T u1 = rng.next<T>();
        const dvec3 w = to_d(warp.sample(ibl::vec2<T>(u0, u1)));
        if (!(w.z >= 0) || !std::isfinite(w.x) || !std::isfinite(w.y) || !std::isfinite(w.z)) {
            ++rep.out_of_domain;
            continue;
        }
        const int it = std::min(int(t_of_direction(w, warp.beta) * n_t), n_t - 1);
        const double phi = wrap_2pi(std::atan2(w.y, w.x) - warp.phi_offset);
        const int ip = std::min(int(phi / (2 * kPi) * n_phi), n_phi - 1);
        observed[std::size_t(it * n_phi + ip)] += 1;
    }
    const ibl_test::gauss_legendre gl(8);
    for (int i = 0; i < n_t; ++i)
        for (int j = 0; j < n_phi; ++j)
            expected[std::size_t(i * n_phi + j)] =
                n * integrate_cell(warp, double(i) / n_t, double(i + 1) / n_t, 2 * kPi * j / n_phi,
                                   2 * kPi * (j + 1) / n_phi, gl);
    rep.r = ibl_test::chi2_test(observed, expected);
    rep.critical = ibl_test::chi2_critical(kChi2Significance, rep.r.dof);
    rep.critical_1pct = ibl_test::chi2_critical(0.01, rep.r.dof);
    return rep;
}

template <class T, class Warp> void check_chi2(const Warp& warp, std::uint64_t seed, const char* name) {
    const chi2_report rep = run_chi2<T>(warp, seed_for<T>(seed));
    IBL_TEST_REPORT(std::string(name) << " <" << type_name<T>() << ">: chi2 = " << rep.r.statistic
                 << ", dof = " << rep.r.dof << ", p = " << rep.r.p_value << ", critical(1%) = "
                 << rep.critical_1pct << ", critical(Sidak) = " << rep.critical
                 << ", pooled cells = " << rep.r.pooled_cells);
    CHECK(rep.out_of_domain == 0);
    // The expected counts sum to n times the pdf's integral (1, see the normalisation tests) up to
    // the cell quadrature error, which only has to stay far below the Poisson noise: a relative
    // 1e-4 moves a 500-count cell by 0.05, i.e. 0.05^2 / 500 per cell, nothing against chi2 ~ dof.
    CHECK(rep.r.expected_total == doctest::Approx(rep.r.observed_total).epsilon(1e-4));
    // The binning resolves the lobe: most of the 200 cells survive pooling (at grazing view half
    // of the hemisphere is invisible, so a floor of 60 rather than ~200).
    CHECK(rep.r.dof >= 60);
    CHECK(rep.r.p_value > kChi2Significance);
}

// ---------------------------------------------------------------------------------------------
// Jacobians by central differences (double).
// ---------------------------------------------------------------------------------------------

/// Central difference of f at x in [0, 1) with step d, kept inside [0, 1 - d].
template <class F> auto central_diff(F&& f, double x, double d) {
    const double lo = std::max(0.0, x - d), hi = std::min(1.0 - d, x + d);
    return (f(hi) - f(lo)) / (hi - lo);
}

struct forward_jacobian {
    double col_x, col_y; ///< |dw/du_x|, |dw/du_y|
    double area;         ///< |dw/du_x x dw/du_y| (solid angle per unit area of u)
};
template <class Warp> forward_jacobian jacobian_at(const Warp& warp, dvec2 u, double d) {
    const dvec3 jx = central_diff([&](double x) { return warp.sample(dvec2(x, u.y)); }, u.x, d);
    const dvec3 jy = central_diff([&](double y) { return warp.sample(dvec2(u.x, y)); }, u.y, d);
    return {glm::length(jx), glm::length(jy), glm::length(glm::cross(jx, jy))};
}

/// |grad u_x| and |grad u_y| of the inverse on the sphere at w (tangential derivatives).
template <class Warp> dvec2 inverse_gradient_at(const Warp& warp, const dvec3& w, double d) {
    const ibl::frame<double> f = ibl::make_frame(w);
    dvec2 g2(0);
    for (const dvec3& t : {f.t, f.b}) {
        const dvec2 a = warp.invert(glm::normalize(w + d * t));
        const dvec2 b = warp.invert(glm::normalize(w - d * t));
        const double dx = Warp::periodic_x ? circular_diff(a.x, b.x) : std::fabs(a.x - b.x);
        const double dy = Warp::periodic_y ? circular_diff(a.y, b.y) : std::fabs(a.y - b.y);
        g2 += dvec2(dx * dx, dy * dy) / (4 * d * d);
    }
    return dvec2(std::sqrt(g2.x), std::sqrt(g2.y));
}

/// pdf(w(u)) * |dw/du| = 1: the pdf is the density of the samples (change of variables).
template <class Warp> double max_jacobian_error(const Warp& warp, int n, std::uint64_t seed) {
    ibl_test::uniform_rng rng(seed);
    double worst = 0;
    for (int k = 0; k < n; ++k) {
        const dvec2 u = rng.next2<dvec2>();
        constexpr double d = 1e-5;
        const forward_jacobian j1 = jacobian_at(warp, u, d), j2 = jacobian_at(warp, u, 2 * d);
        const double product = warp.pdf(warp.sample(u)) * j1.area;
        // Richardson: the O(d^2) truncation error of j1 is |j1 - j2| / 3; allow 2x that, plus the
        // rounding of a difference quotient, eps_double / (d |column|) per column, relative.
        const double rounding = 4 * ibl::epsilon_v<double> / (d * std::min(j1.col_x, j1.col_y));
        const double tol = 2 * std::fabs(j1.area - j2.area) / j1.area + rounding + 1e-12;
        const double err = std::fabs(product - 1);
        CHECK_MESSAGE(err <= tol, "u = (" << u.x << ", " << u.y << "), pdf*|J| = " << product);
        worst = std::max(worst, err);
    }
    return worst;
}

/// Round trips in T: invert(sample(u)) = u and sample(invert(w)) = w for w = sample(u'), with
/// tolerances propagated through the local Jacobians (computed in double):
///   |du_i| <= K eps (1 + |grad u_i|)                          (forward error K eps on w, then inverse)
///   |dw|   <= K eps (1 + |dw/du_x| (1 + |grad u_x|) + |dw/du_y| (1 + |grad u_y|)).
/// Returns the largest ratio error / tolerance seen.
template <class T, class Warp> double max_round_trip_ratio(const Warp& warp, int n, std::uint64_t seed) {
    ibl_test::uniform_rng rng(seed);
    const double keps = kRoundingSteps * double(ibl::epsilon_v<T>);
    double worst = 0;
    for (int k = 0; k < n; ++k) {
        const ibl::vec2<T> u = rng.next2<ibl::vec2<T>>();
        const ibl::vec3<T> w = warp.sample(u);
        const dvec2 back = to_d(warp.invert(w));
        const dvec2 ud = to_d(u);
        const forward_jacobian j = jacobian_at(warp, ud, 1e-7);
        const dvec2 g = inverse_gradient_at(warp, to_d(w), 1e-7);
        const double ex = Warp::periodic_x ? circular_diff(back.x, ud.x) : std::fabs(back.x - ud.x);
        const double ey = Warp::periodic_y ? circular_diff(back.y, ud.y) : std::fabs(back.y - ud.y);
        const double tx = keps * (1 + g.x), ty = keps * (1 + g.y);
        const ibl::vec3<T> w2 = warp.sample(warp.invert(w));
        const double ew = glm::length(to_d(w2) - to_d(w));
        const double tw = keps * (1 + j.col_x * (1 + g.x) + j.col_y * (1 + g.y));
        CHECK_MESSAGE(ex <= tx, "u.x: u = (" << ud.x << ", " << ud.y << ") -> " << back.x);
        CHECK_MESSAGE(ey <= ty, "u.y: u = (" << ud.x << ", " << ud.y << ") -> " << back.y);
        CHECK_MESSAGE(ew <= tw, "w: u = (" << ud.x << ", " << ud.y << "), |dw| = " << ew);
        worst = std::max({worst, ex / tx, ey / ty, ew / tw});
    }
    return worst;
}

// Configurations shared by several tests.
constexpr std::array<double, 4> kNdfAlphas = {1.0, 0.5, 0.1, 0.02 * 0.02};
constexpr std::array<double, 3> kVndfAlphas = {1.0, 0.25, 0.02 * 0.02};
constexpr std::array<double, 3> kVndfCos = {1.0, 0.5, 1e-3};

} // namespace

// =============================================================================================
// Sequences.
// =============================================================================================

TEST_CASE("reverse_bits matches the bit-by-bit reference and is an involution") {
    ibl_test::uniform_rng rng(1);
    for (int k = 0; k < 10000; ++k) {
        const auto x = std::uint32_t(rng.engine());
        CHECK(ibl::reverse_bits(x) == reverse_bits_reference(x));
        CHECK(ibl::reverse_bits(ibl::reverse_bits(x)) == x);
    }
    static_assert(ibl::reverse_bits(1u) == 0x80000000u);
    static_assert(ibl::reverse_bits(0x0000FFFFu) == 0xFFFF0000u);
}

TEST_CASE_TEMPLATE("radical_inverse: known values, exactly k / 2^32, never 1", T, float, double) {
    SUBCASE("first terms of the van der Corput sequence") {
        const T expected[] = {0, 0.5, 0.25, 0.75, 0.125, 0.625, 0.375, 0.875, 0.0625};
        for (std::uint32_t i = 0; i < 9; ++i) CHECK(ibl::radical_inverse<T>(i) == expected[i]);
    }
    SUBCASE("largest index") {
        const T r = ibl::radical_inverse<T>(0xFFFFFFFFu);
        CHECK(r < T(1));
        if constexpr (sizeof(T) == sizeof(double))
            CHECK(r == double(0xFFFFFFFFu) / 0x1p32); // (2^32 - 1) / 2^32, exact in double
        else
            CHECK(r == float(0xFFFFFFu) * 0x1p-24f); // truncated to 24 bits: (2^24 - 1) / 2^24
    }
    SUBCASE("exactly the reversed bits as a binary fraction (truncated to 24 bits in float)") {
        ibl_test::uniform_rng rng(2);
        for (int k = 0; k < 10000; ++k) {
            const auto i = std::uint32_t(rng.engine());
            const std::uint32_t bits = reverse_bits_reference(i);
            const double r = double(ibl::radical_inverse<T>(i));
            if constexpr (sizeof(T) == sizeof(double))
                CHECK(r * 0x1p32 == double(bits));
            else
                CHECK(r * 0x1p24 == double(bits >> 8));
            CHECK(r < 1.0);
        }
    }
    SUBCASE("scrambled variants stay in [0, 1) and XOR scrambling is exact") {
        ibl_test::uniform_rng rng(3);
        for (int k = 0; k < 1000; ++k) {
            const auto i = std::uint32_t(rng.engine()), s = std::uint32_t(rng.engine());
            const T x = ibl::radical_inverse_xor<T>(i, s);
            const T o = ibl::radical_inverse_owen<T>(i, s);
            CHECK(x >= T(0));
            CHECK(x < T(1));
            CHECK(o >= T(0));
            CHECK(o < T(1));
            if constexpr (sizeof(T) == sizeof(double))
                CHECK(double(x) * 0x1p32 == double(reverse_bits_reference(i) ^ s));
        }
    }
}

namespace {
/// Counts, for the 2^m points p(i), i < 2^m, and every split m = j + (m - j), the points in each
/// elementary box [a / 2^j, (a+1) / 2^j) x [b / 2^(m-j), (b+1) / 2^(m-j)); true when every box
/// holds exactly one point (the (0, m, 2)-net property in base 2).
template <class T, class P> bool is_02_net(int m, P&& point) {
    const std::uint32_t n = 1u << m;
    std::vector<int> count(n);
    for (int j = 0; j <= m; ++j) {
        std::fill(count.begin(), count.end(), 0);
        for (std::uint32_t i = 0; i < n; ++i) {
            const ibl::vec2<T> p = point(i, n);
            if (!(p.x >= T(0) && p.x < T(1) && p.y >= T(0) && p.y < T(1))) return false;
            // Exact: p.x, p.y are dyadic and the scalings are powers of two.
            const auto a = std::uint32_t(double(p.x) * double(1u << j));
            const auto b = std::uint32_t(double(p.y) * double(1u << (m - j)));
            ++count[(a << (m - j)) | b];
        }
        for (int c : count)
            if (c != 1) return false;
    }
    return true;
}
} // namespace

TEST_CASE_TEMPLATE("hammersley: known points and the (0, m, 2)-net property", T, float, double) {
    SUBCASE("n = 4") {
        const T expected[4][2] = {{0, 0}, {0.25, 0.5}, {0.5, 0.25}, {0.75, 0.75}};
        for (std::uint32_t i = 0; i < 4; ++i) {
            const ibl::vec2<T> p = ibl::hammersley<T>(i, 4);
            CHECK(p.x == expected[i][0]);
            CHECK(p.y == expected[i][1]);
        }
    }
    SUBCASE("one sample, and i / n stays below 1 for the largest n") {
        CHECK(ibl::hammersley<T>(0, 1) == ibl::vec2<T>(0, 0));
        const ibl::vec2<T> p = ibl::hammersley<T>(0xFFFFFFFEu, 0xFFFFFFFFu);
        CHECK(p.x < T(1));
        CHECK(p.y < T(1));
    }
    SUBCASE("net property, m = 1..10") {
        for (int m = 1; m <= 10; ++m) {
            CAPTURE(m);
            CHECK(is_02_net<T>(m, [](std::uint32_t i, std::uint32_t n) { return ibl::hammersley<T>(i, n); }));
            for (std::uint32_t seed : {1u, 0xDEADBEEFu, 0x9E3779B9u}) {
                CHECK(is_02_net<T>(m, [&](std::uint32_t i, std::uint32_t n) {
                    return ibl::hammersley_owen<T>(i, n, seed);
                }));
                CHECK(is_02_net<T>(m, [&](std::uint32_t i, std::uint32_t n) {
                    return ibl::vec2<T>(T(i) / T(n), ibl::radical_inverse_xor<T>(i, seed));
                }));
            }
        }
    }
    SUBCASE("a counter-example is rejected (the net test has teeth)") {
        // Regular grid on the diagonal: i/n for both coordinates is not a net for m >= 1.
        CHECK_FALSE(is_02_net<T>(4, [](std::uint32_t i, std::uint32_t n) {
            return ibl::vec2<T>(T(i) / T(n), T(i) / T(n));
        }));
    }
    SUBCASE("Owen scrambling changes the points and depends on the seed") {
        int differ_plain = 0, differ_seed = 0;
        for (std::uint32_t i = 0; i < 256; ++i) {
            differ_plain += ibl::radical_inverse_owen<T>(i, 7u) != ibl::radical_inverse<T>(i);
            differ_seed += ibl::radical_inverse_owen<T>(i, 7u) != ibl::radical_inverse_owen<T>(i, 8u);
        }
        CHECK(differ_plain > 200);
        CHECK(differ_seed > 200);
    }
}

// =============================================================================================
// Disk and hemisphere warps.
// =============================================================================================

TEST_CASE_TEMPLATE("concentric disk and cosine hemisphere: known values", T, float, double) {
    const T tol = 4 * ibl::epsilon_v<T>; // one cos/sin of an exact angle: <= 1 ulp each, 2x margin
    const auto disk = [](T x, T y) { return ibl::sample_concentric_disk(ibl::vec2<T>(x, y)); };
    CHECK(disk(T(0.5), T(0.5)) == ibl::vec2<T>(0, 0));
    CHECK(disk(T(1), T(0.5)).x == doctest::Approx(1).epsilon(tol));
    CHECK(std::fabs(disk(T(1), T(0.5)).y) <= tol);
    CHECK(std::fabs(disk(T(0.5), T(1)).x) <= tol);
    CHECK(disk(T(0.5), T(1)).y == doctest::Approx(1).epsilon(tol));
    CHECK(disk(T(0), T(0.5)).x == doctest::Approx(-1).epsilon(tol));
    // The square's corner (1, 1) goes to the circle at 45 degrees; (0.75, 0.5) to radius 1/2.
    CHECK(disk(T(1), T(1)).x == doctest::Approx(std::sqrt(0.5)).epsilon(tol));
    CHECK(disk(T(1), T(1)).y == doctest::Approx(std::sqrt(0.5)).epsilon(tol));
    CHECK(disk(T(0.75), T(0.5)).x == doctest::Approx(0.5).epsilon(tol));
    CHECK(ibl::invert_concentric_disk(ibl::vec2<T>(0, 0)) == ibl::vec2<T>(T(0.5), T(0.5)));
    // Cosine hemisphere: the square's centre is the normal, the boundary the horizon.
    CHECK(ibl::sample_cosine_hemisphere(ibl::vec2<T>(T(0.5), T(0.5))) == ibl::vec3<T>(0, 0, 1));
    CHECK(ibl::sample_cosine_hemisphere(ibl::vec2<T>(T(0), T(0.3))).z == T(0));
    CHECK(ibl::cosine_hemisphere_pdf(T(1)) == doctest::Approx(1 / kPi).epsilon(tol));
    CHECK(ibl::cosine_hemisphere_pdf(T(-0.5)) == T(0));
    // Uniform hemisphere: z = u.x, phi = 2 pi u.y.
    const ibl::vec3<T> w = ibl::sample_uniform_hemisphere(ibl::vec2<T>(T(0.5), T(0.25)));
    CHECK(std::fabs(w.x) <= tol);
    CHECK(w.y == doctest::Approx(std::sqrt(0.75)).epsilon(tol));
    CHECK(w.z == T(0.5));
    CHECK(ibl::uniform_hemisphere_pdf<T>() == doctest::Approx(1 / (2 * kPi)).epsilon(tol));
}

TEST_CASE("disk and hemisphere pdfs integrate to 1 (double quadrature)") {
    const integral_estimate uni = integrate_pdf(uniform_hemisphere_warp{});
    const integral_estimate cosine = integrate_pdf(cosine_hemisphere_warp{});
    IBL_TEST_REPORT("uniform: " << uni.value - 1 << " (estimate " << uni.error << "), cosine: " << cosine.value - 1
                        << " (estimate " << cosine.error << ")");
    // Smooth integrands: the error estimate bounds the quadrature error; on top, the rounding of
    // summing ~3e4 node values, n eps_double = 4e-12.
    CHECK(std::fabs(uni.value - 1) <= 10 * uni.error + kSumRounding);
    CHECK(std::fabs(cosine.value - 1) <= 10 * cosine.error + kSumRounding);
    // The disk pdf is a constant over an area of pi.
    CHECK(ibl::concentric_disk_pdf<double>() * kPi == doctest::Approx(1).epsilon(4e-16));
}

TEST_CASE_TEMPLATE("disk and hemisphere warps: chi-square goodness of fit", T, float, double) {
    check_chi2<T>(uniform_hemisphere_warp{}, 11, "uniform hemisphere");
    check_chi2<T>(cosine_hemisphere_warp{}, 12, "cosine hemisphere");
    // The disk, lifted to the hemisphere by Malley's method, is the cosine warp; test it directly
    // in (r^2, phi) cells of equal area, whose expected counts are n * pdf * area.
    ibl_test::uniform_rng rng(seed_for<T>(13));
    constexpr int n = 100000, nr = 10, nphi = 20;
    std::vector<double> observed(nr * nphi, 0.0), expected(nr * nphi, 0.0);
    for (int k = 0; k < n; ++k) {
        const dvec2 p = to_d(ibl::sample_concentric_disk(rng.next2<ibl::vec2<T>>()));
        const double r2 = p.x * p.x + p.y * p.y;
        REQUIRE(r2 <= 1 + 4 * double(ibl::epsilon_v<T>)); // inside the disk up to rounding of |p|^2
        const int ir = std::min(int(r2 * nr), nr - 1);
        const int ip = std::min(int(wrap_2pi(std::atan2(p.y, p.x)) / (2 * kPi) * nphi), nphi - 1);
        observed[std::size_t(ir * nphi + ip)] += 1;
    }
    for (auto& e : expected) e = n * ibl::concentric_disk_pdf<double>() * (kPi / (nr * nphi));
    const ibl_test::chi2_result r = ibl_test::chi2_test(observed, expected);
    IBL_TEST_REPORT("concentric disk: chi2 = " << r.statistic << ", dof = " << r.dof << ", p = " << r.p_value);
    CHECK(r.p_value > kChi2Significance);
}

TEST_CASE("disk and hemisphere warps: pdf * |Jacobian| = 1 (double)") {
    const double e1 = max_jacobian_error(uniform_hemisphere_warp{}, 500, 21);
    const double e2 = max_jacobian_error(cosine_hemisphere_warp{}, 500, 22);
    IBL_TEST_REPORT("max |pdf*|J| - 1|: uniform " << e1 << ", cosine " << e2);
}

TEST_CASE_TEMPLATE("disk and hemisphere warps: round trips", T, float, double) {
    const double r1 = max_round_trip_ratio<T>(uniform_hemisphere_warp{}, 2000, 31);
    const double r2 = max_round_trip_ratio<T>(cosine_hemisphere_warp{}, 2000, 32);
    IBL_TEST_REPORT("max error / tolerance: uniform " << r1 << ", cosine " << r2);
    // Disk alone: invert(sample(u)) = u away from the centre, where the angle is undefined.
    ibl_test::uniform_rng rng(33);
    double worst = 0;
    for (int k = 0; k < 2000; ++k) {
        const ibl::vec2<T> u = rng.next2<ibl::vec2<T>>();
        const dvec2 back = to_d(ibl::invert_concentric_disk(ibl::sample_concentric_disk(u)));
        const double r = ibl::concentric_disk_radius(dvec2(u));
        // The angle within a wedge, pi/4 * (b / a), is recovered with relative error K eps; the
        // coordinate it encodes, b = a * angle * 4/pi, then has absolute error ~K eps. The radius
        // is recovered as |p| to K eps. Near the centre (r -> 0) the same errors hold in u.
        const double err = std::max(std::fabs(back.x - u.x), std::fabs(back.y - u.y));
        CHECK_MESSAGE(err <= kRoundingSteps * double(ibl::epsilon_v<T>), "u = (" << u.x << ", " << u.y
                                                                                 << "), r = " << r);
        worst = std::max(worst, err / double(ibl::epsilon_v<T>));
    }
    IBL_TEST_REPORT("disk: max |invert(sample(u)) - u| = " << worst << " eps");
}

// =============================================================================================
// GGX distribution of normals.
// =============================================================================================

TEST_CASE_TEMPLATE("sample_ggx_ndf: known values and the mirror limit", T, float, double) {
    const T tol = 4 * ibl::epsilon_v<T>; // a sqrt, a division and a cos/sin: <= 4 eps relative
    SUBCASE("u.x = 0 is the normal; u.x = 1/2 is the median, tan(theta) = alpha") {
        for (double alpha : {1.0, 0.5, 1e-2, 1e-4}) {
            CAPTURE(alpha);
            const ibl::vec3<T> n = ibl::sample_ggx_ndf(ibl::vec2<T>(0, T(0.3)), T(alpha));
            CHECK(n.z == T(1));
            const ibl::vec3<T> h = ibl::sample_ggx_ndf(ibl::vec2<T>(T(0.5), T(0)), T(alpha));
            CHECK(h.x / h.z == doctest::Approx(T(alpha)).epsilon(tol));
            CHECK(h.y == T(0));
        }
    }
    SUBCASE("alpha = 0 returns the normal exactly, for every u") {
        ibl_test::uniform_rng rng(41);
        for (int k = 0; k < 1000; ++k) {
            const ibl::vec2<T> u = rng.next2<ibl::vec2<T>>();
            CHECK(ibl::sample_ggx_ndf(u, T(0)) == ibl::vec3<T>(0, 0, 1));
            CHECK(ibl::sample_ggx_vndf(ibl::vec3<T>(view_direction(0.3, 1.0)), u, T(0)) == ibl::vec3<T>(0, 0, 1));
        }
        const T corner = ibl::one_minus_epsilon_v<T>;
        CHECK(ibl::sample_ggx_ndf(ibl::vec2<T>(corner, corner), T(0)) == ibl::vec3<T>(0, 0, 1));
    }
    SUBCASE("alpha = 1 is the cosine lobe: D(h) (n.h) = (n.h) / pi") {
        ibl_test::uniform_rng rng(42);
        for (int k = 0; k < 1000; ++k) {
            const ibl::vec3<T> h = ibl::sample_ggx_ndf(rng.next2<ibl::vec2<T>>(), T(1));
            // D at alpha = 1 is 1 / (pi |h|^4): |h|^2 = 1 within 3 eps, so 8 eps relative.
            CHECK(ibl::ggx_ndf_pdf(h, T(1)) ==
                  doctest::Approx(ibl::cosine_hemisphere_pdf(h.z)).epsilon(kRoundingSteps * ibl::epsilon_v<T>));
        }
    }
    SUBCASE("samples are unit vectors in the upper hemisphere") {
        ibl_test::uniform_rng rng(43);
        for (double alpha : kNdfAlphas)
            for (int k = 0; k < 1000; ++k) {
                const ibl::vec3<T> h = ibl::sample_ggx_ndf(rng.next2<ibl::vec2<T>>(), T(alpha));
                // cos^2 + sin^2 = 1 exactly in real arithmetic; ~4 roundings in each -> 4 eps on |h|^2.
                CHECK(std::fabs(glm::dot(h, h) - T(1)) <= 4 * ibl::epsilon_v<T>);
                CHECK(h.z > T(0));
            }
    }
}

TEST_CASE("ggx_ndf_pdf integrates to 1 over the hemisphere (double quadrature)") {
    for (double alpha : {1.0, 0.5, 0.1, 0.02 * 0.02, 1e-4 * 1e-4}) {
        const integral_estimate I = integrate_pdf(ggx_ndf_warp{alpha});
        IBL_TEST_REPORT("alpha = " << alpha << ": integral - 1 = " << I.value - 1 << " (estimate " << I.error << ")");
        // The substitution tan(theta) = alpha tan(psi) makes the integrand smooth in psi, so the
        // a-posteriori estimate bounds the quadrature error; plus the summation rounding.
        CHECK(std::fabs(I.value - 1) <= 10 * I.error + kSumRounding);
        CHECK(I.error <= 1e-9); // the quadrature itself is converged, so the check above has teeth
    }
}

TEST_CASE_TEMPLATE("sample_ggx_ndf: chi-square goodness of fit", T, float, double) {
    std::uint64_t seed = 100;
    for (double alpha : kNdfAlphas) {
        CAPTURE(alpha);
        check_chi2<T>(ggx_ndf_warp{alpha}, seed++, "GGX NDF");
    }
}

TEST_CASE("sample_ggx_ndf: pdf * |Jacobian| = 1 (double)") {
    for (double alpha : kNdfAlphas) {
        CAPTURE(alpha);
        const double e = max_jacobian_error(ggx_ndf_warp{alpha}, 500, 51);
        IBL_TEST_REPORT("alpha = " << alpha << ": max |pdf*|J| - 1| = " << e);
    }
}

TEST_CASE_TEMPLATE("sample_ggx_ndf / invert_ggx_ndf: round trips", T, float, double) {
    for (double alpha : kNdfAlphas) {
        CAPTURE(alpha);
        const double r = max_round_trip_ratio<T>(ggx_ndf_warp{alpha}, 2000, 61);
        IBL_TEST_REPORT("alpha = " << alpha << ": max error / tolerance = " << r);
    }
}

TEST_CASE_TEMPLATE("ggx reflected-direction pdfs", T, float, double) {
    const T tol = kRoundingSteps * ibl::epsilon_v<T>; // a few products and one quotient
    ibl_test::uniform_rng rng(71);
    for (int k = 0; k < 1000; ++k) {
        const dvec2 vr = rng.next2<dvec2>();
        const ibl::vec3<T> v(view_direction(0.05 + 0.95 * vr.x, 2 * kPi * vr.y));
        const T alpha = T(0.05 + 0.95 * rng.next<double>());
        const ibl::vec3<T> h = ibl::sample_ggx_vndf(v, rng.next2<ibl::vec2<T>>(), alpha);
        const T v_dot_h = glm::dot(v, h);
        if (!(v_dot_h > T(0))) continue;
        // The VNDF form with v.h cancelled equals the generic Jacobian rule.
        CHECK(ibl::ggx_vndf_reflected_pdf(v, h, alpha) ==
              doctest::Approx(ibl::ggx_reflected_pdf(ibl::ggx_vndf_pdf(v, h, alpha), v_dot_h)).epsilon(tol));
        CHECK(ibl::ggx_ndf_reflected_pdf(v, h, alpha) ==
              doctest::Approx(ibl::ggx_ndf_pdf(h, alpha) / (4 * v_dot_h)).epsilon(tol));
    }
    SUBCASE("the Jacobian d omega_l / d omega_h of l = 2 (v.h) h - v is 4 v.h") {
        ibl_test::uniform_rng r2(72);
        for (int k = 0; k < 200; ++k) {
            const dvec2 vr = r2.next2<dvec2>();
            const dvec3 v = view_direction(0.1 + 0.9 * vr.x, 2 * kPi * vr.y);
            const dvec3 h = ibl::sample_ggx_ndf(r2.next2<dvec2>(), 0.5);
            const double vh = glm::dot(v, h);
            if (vh < 0.05) continue;
            const auto l_of = [&](const dvec3& m) { return 2 * glm::dot(v, m) * m - v; };
            const ibl::frame<double> f = ibl::make_frame(h);
            constexpr double d = 1e-5;
            const dvec3 lt = (l_of(glm::normalize(h + d * f.t)) - l_of(glm::normalize(h - d * f.t))) / (2 * d);
            const dvec3 lb = (l_of(glm::normalize(h + d * f.b)) - l_of(glm::normalize(h - d * f.b))) / (2 * d);
            const double jac = glm::length(glm::cross(lt, lb));
            // Central differences of a quadratic map with curvature O(1): O(d^2) = 1e-10 relative.
            CHECK(jac == doctest::Approx(4 * vh).epsilon(1e-8));
            CHECK(ibl::ggx_reflected_pdf(1.0, vh) * jac == doctest::Approx(1.0).epsilon(1e-8));
        }
    }
    SUBCASE("no reflection for v.h <= 0; saturation instead of infinity as v.h -> 0+") {
        CHECK(ibl::ggx_reflected_pdf(T(1), T(0)) == T(0));
        CHECK(ibl::ggx_reflected_pdf(T(1), T(-0.5)) == T(0));
        const T huge = ibl::ggx_reflected_pdf(std::numeric_limits<T>::max(), std::numeric_limits<T>::denorm_min());
        CHECK(huge == std::numeric_limits<T>::max());
    }
}

// =============================================================================================
// GGX visible normals.
// =============================================================================================

TEST_CASE_TEMPLATE("ggx_g1_over_n_dot_v and ggx_vndf_pdf: closed forms and limits", T, float, double) {
    const T tol = kRoundingSteps * ibl::epsilon_v<T>;
    for (double alpha : {1.0, 0.5, 0.1, 1e-3}) {
        CAPTURE(alpha);
        // G1/(n.v) -> 2/alpha at grazing view; 1 at normal view.
        CHECK(ibl::ggx_g1_over_n_dot_v(T(0), T(alpha)) == doctest::Approx(T(2 / alpha)).epsilon(tol));
        CHECK(ibl::ggx_g1_over_n_dot_v(T(1), T(alpha)) == doctest::Approx(T(1)).epsilon(tol));
        for (double mu : {1e-3, 0.3, 0.9})
            CHECK(ibl::ggx_g1_over_n_dot_v(T(mu), T(alpha)) ==
                  doctest::Approx(ibl::g1_smith_ggx(T(mu), T(alpha)) / T(mu)).epsilon(tol));
        // At normal incidence the VNDF is the NDF pdf: G1(1) = 1, v.h = n.h.
        ibl_test::uniform_rng rng(81);
        for (int k = 0; k < 100; ++k) {
            const ibl::vec3<T> h = ibl::sample_ggx_ndf(rng.next2<ibl::vec2<T>>(), T(alpha));
            CHECK(ibl::ggx_vndf_pdf(ibl::vec3<T>(0, 0, 1), h, T(alpha)) ==
                  doctest::Approx(ibl::ggx_ndf_pdf(h, T(alpha))).epsilon(tol));
        }
    }
    // Half vectors invisible from v have zero density.
    const ibl::vec3<T> v(view_direction(0.5, 0.0));
    CHECK(ibl::ggx_vndf_pdf(v, ibl::vec3<T>(view_direction(0.3, kPi)), T(0.5)) == T(0));
}

TEST_CASE_TEMPLATE("sample_ggx_vndf: known values and unit outputs", T, float, double) {
    const T tol = 4 * ibl::epsilon_v<T>;
    // Normal incidence: the cap is the whole sphere; u.y = 1/2 is its equator, so h_s is at 45
    // degrees and h = normalize(alpha, 0, 1) for phi = 0, the median of the NDF.
    for (double alpha : {1.0, 0.5, 0.01}) {
        const ibl::vec3<T> h = ibl::sample_ggx_vndf(ibl::vec3<T>(0, 0, 1), ibl::vec2<T>(0, T(0.5)), T(alpha));
        CHECK(h.x / h.z == doctest::Approx(T(alpha)).epsilon(tol));
        // u.y = 0 is the cap's pole c = n: h_s is the half vector of v_s and n (= n here).
        CHECK(ibl::sample_ggx_vndf(ibl::vec3<T>(0, 0, 1), ibl::vec2<T>(T(0.3), 0), T(alpha)) == ibl::vec3<T>(0, 0, 1));
    }
    ibl_test::uniform_rng rng(91);
    for (double alpha : kVndfAlphas)
        for (double cv : {1.0, 0.5, 1e-3, 0.0})
            for (int k = 0; k < 300; ++k) {
                const ibl::vec3<T> v(view_direction(cv, 2 * kPi * rng.next<double>()));
                const ibl::vec3<T> h = ibl::sample_ggx_vndf(v, rng.next2<ibl::vec2<T>>(), T(alpha));
                // normalize_scaled: a scaling, a dot, a sqrt and a division: <= 4 eps on |h|^2.
                CHECK(std::fabs(glm::dot(h, h) - T(1)) <= 4 * ibl::epsilon_v<T>);
                CHECK(h.z > T(0));
                CHECK(glm::dot(v, h) >= -2 * ibl::epsilon_v<T>); // visible, up to the rounding of v.h
            }
}

TEST_CASE("ggx_vndf_pdf integrates to 1 over the hemisphere (double quadrature)") {
    for (double alpha : {1.0, 0.5, 0.1, 0.02 * 0.02})
        for (double cv : {1.0, 0.5, 1e-3, 0.0}) {
            const integral_estimate I = integrate_pdf(ggx_vndf_warp{alpha, view_direction(cv, 0.7)});
            IBL_TEST_REPORT("alpha = " << alpha << ", n.v = " << cv << ": integral - 1 = " << I.value - 1 << " (estimate "
                               << I.error << ")");
            // The support edge v.h = 0 is resolved exactly in phi, and its (theta - theta_0)^(3/2)
            // term in theta by the split and the s^2 substitution (integrate_hemisphere), so the
            // rule converges spectrally and the a-posteriori estimate bounds its error.
            CHECK(std::fabs(I.value - 1) <= 10 * I.error + kSumRounding);
            CHECK(I.error <= 1e-9);
        }
}

TEST_CASE_TEMPLATE("sample_ggx_vndf: chi-square goodness of fit", T, float, double) {
    std::uint64_t seed = 200;
    for (double alpha : kVndfAlphas)
        for (double cv : kVndfCos) {
            CAPTURE(alpha);
            CAPTURE(cv);
            check_chi2<T>(ggx_vndf_warp{alpha, view_direction(cv, 2.0)}, seed++, "GGX VNDF");
        }
}

TEST_CASE("sample_ggx_vndf: pdf * |Jacobian| = 1 (double)") {
    for (double alpha : kVndfAlphas)
        for (double cv : {1.0, 0.5, 1e-3, 0.0}) {
            CAPTURE(alpha);
            CAPTURE(cv);
            const double e = max_jacobian_error(ggx_vndf_warp{alpha, view_direction(cv, 0.4)}, 300, 52);
            IBL_TEST_REPORT("alpha = " << alpha << ", n.v = " << cv << ": max |pdf*|J| - 1| = " << e);
        }
}

TEST_CASE_TEMPLATE("sample_ggx_vndf / invert_ggx_vndf: round trips", T, float, double) {
    for (double alpha : kVndfAlphas)
        for (double cv : {1.0, 0.5, 1e-3, 0.0}) {
            CAPTURE(alpha);
            CAPTURE(cv);
            const double r = max_round_trip_ratio<T>(ggx_vndf_warp{alpha, view_direction(cv, 1.1)}, 1000, 62);
            IBL_TEST_REPORT("alpha = " << alpha << ", n.v = " << cv << ": max error / tolerance = " << r);
        }
}
