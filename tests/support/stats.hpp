#pragma once
// tests/support/stats.hpp — statistics and quadrature for the tests, all in double:
//   * regularized incomplete gamma P(a, x) / Q(a, x) (series + Lentz continued fraction, as in
//     W. H. Press et al., "Numerical Recipes", 3rd ed., sec. 6.2), the chi-square CDF and quantile;
//   * Pearson's chi-square goodness-of-fit test with pooling of cells whose expected count is
//     below 5 (the rule of thumb of W. G. Cochran, "Some Methods for Strengthening the Common
//     chi^2 Tests", Biometrics 10, 1954), as in Mitsuba 3's chi2 test;
//   * Gauss-Legendre nodes and weights (Newton on P_n, Golub-Welsch-free), composite rules;
//   * a small fixed-seed PRNG wrapper producing uniform floats/doubles in [0, 1).

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <random>
#include <vector>

namespace ibl_test {

// ---------------------------------------------------------------------------------------------
// Incomplete gamma and chi-square.
// ---------------------------------------------------------------------------------------------

namespace detail {
/// log(e^-x x^a / Gamma(a)), the common prefactor of both expansions.
inline double gamma_log_prefactor(double a, double x) { return a * std::log(x) - x - std::lgamma(a); }

/// P(a, x) by its power series, for x < a + 1:
/// P = e^-x x^a / Gamma(a+1) * sum_n x^n / ((a+1)...(a+n)).
inline double gamma_p_series(double a, double x) {
    double term = 1.0 / a, sum = term, ap = a;
    for (int n = 0; n < 10000; ++n) {
        ap += 1.0;
        term *= x / ap;
        sum += term;
        if (std::fabs(term) < std::fabs(sum) * 1e-16) break;
    }
    return sum * std::exp(gamma_log_prefactor(a, x));
}

/// Q(a, x) by its continued fraction (modified Lentz), for x >= a + 1:
/// Q = e^-x x^a / Gamma(a) * 1/(x+1-a - 1(1-a)/(x+3-a - 2(2-a)/(x+5-a - ...))).
inline double gamma_q_fraction(double a, double x) {
    constexpr double tiny = 1e-300;
    double b = x + 1.0 - a, c = 1.0 / tiny, d = 1.0 / b, h = d;
    for (int i = 1; i < 10000; ++i) {
        const double an = -i * (i - a);
        b += 2.0;
        d = an * d + b;
        if (std::fabs(d) < tiny) d = tiny;
        c = b + an / c;
        if (std::fabs(c) < tiny) c = tiny;
        d = 1.0 / d;
        const double del = d * c;
        h *= del;
        if (std::fabs(del - 1.0) < 1e-16) break;
    }
    return std::exp(gamma_log_prefactor(a, x)) * h;
}
} // namespace detail

/// Regularized lower incomplete gamma P(a, x), a > 0, x >= 0 (relative accuracy ~1e-15).
inline double gamma_p(double a, double x) {
    if (x <= 0.0) return 0.0;
    return x < a + 1.0 ? detail::gamma_p_series(a, x) : 1.0 - detail::gamma_q_fraction(a, x);
}

/// Regularized upper incomplete gamma Q(a, x) = 1 - P(a, x); computed directly in the
/// continued-fraction regime so that small p-values keep their relative accuracy.
inline double gamma_q(double a, double x) {
    if (x <= 0.0) return 1.0;
    return x < a + 1.0 ? 1.0 - detail::gamma_p_series(a, x) : detail::gamma_q_fraction(a, x);
}

/// Chi-square CDF with k degrees of freedom: P(k/2, x/2).
inline double chi2_cdf(double x, int dof) { return gamma_p(0.5 * dof, 0.5 * x); }

/// Upper-tail probability (p-value) of the chi-square statistic x with k degrees of freedom.
inline double chi2_sf(double x, int dof) { return gamma_q(0.5 * dof, 0.5 * x); }

/// Critical value c with chi2_sf(c, dof) = significance, by bisection (the sf is monotone).
inline double chi2_critical(double significance, int dof) {
    double lo = 0.0, hi = dof + 20.0 * std::sqrt(2.0 * dof) + 100.0;
    for (int it = 0; it < 200; ++it) {
        const double mid = 0.5 * (lo + hi);
        (chi2_sf(mid, dof) > significance ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
}

struct chi2_result {
    double statistic = 0;   ///< Pearson's sum of (O - E)^2 / E over the (pooled) cells
    int dof = 0;            ///< cells after pooling, minus 1
    double p_value = 1;     ///< upper-tail probability of the statistic
    int pooled_cells = 0;   ///< number of original cells merged into the pooled cell
    double observed_total = 0, expected_total = 0;
};

/// Pearson's chi-square test of observed counts against expected counts (same length). Cells
/// with expected < min_expected are pooled, smallest first, into one cell (added to the smallest
/// kept cell if the pool itself stays below min_expected).
inline chi2_result chi2_test(const std::vector<double>& observed, const std::vector<double>& expected,
                             double min_expected = 5.0) {
    std::vector<std::size_t> order(expected.size());
    std::iota(order.begin(), order.end(), std::size_t(0));
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return expected[a] < expected[b]; });
    chi2_result r;
    double pool_o = 0, pool_e = 0;
    std::size_t i = 0;
    for (; i < order.size() && expected[order[i]] < min_expected; ++i, ++r.pooled_cells) {
        pool_o += observed[order[i]];
        pool_e += expected[order[i]];
    }
    int cells = 0;
    if (pool_e >= min_expected || (pool_e > 0 && i == order.size())) {
        r.statistic += (pool_o - pool_e) * (pool_o - pool_e) / pool_e;
        ++cells;
        pool_o = pool_e = 0;
    }
    for (; i < order.size(); ++i) {
        double o = observed[order[i]], e = expected[order[i]];
        o += pool_o; // a pool below min_expected joins the smallest kept cell
        e += pool_e;
        pool_o = pool_e = 0;
        r.statistic += (o - e) * (o - e) / e;
        ++cells;
    }
    for (std::size_t k = 0; k < observed.size(); ++k) {
        r.observed_total += observed[k];
        r.expected_total += expected[k];
    }
    r.dof = cells - 1;
    r.p_value = r.dof > 0 ? chi2_sf(r.statistic, r.dof) : 1.0;
    return r;
}

// ---------------------------------------------------------------------------------------------
// Gauss-Legendre quadrature.
// ---------------------------------------------------------------------------------------------

struct gauss_legendre {
    std::vector<double> x, w; ///< nodes and weights on [-1, 1]

    /// n-point rule by Newton iteration on P_n from Chebyshev-like initial guesses (Numerical
    /// Recipes, sec. 4.6); exact for polynomials of degree 2n - 1.
    explicit gauss_legendre(int n) : x(n), w(n) {
        const double pi = 3.14159265358979323846;
        for (int i = 0; i < (n + 1) / 2; ++i) {
            double z = std::cos(pi * (i + 0.75) / (n + 0.5)), dp = 0;
            for (int it = 0; it < 100; ++it) {
                double p0 = 1, p1 = 0;
                for (int j = 0; j < n; ++j) {
                    const double p2 = p1;
                    p1 = p0;
                    p0 = ((2.0 * j + 1.0) * z * p1 - j * p2) / (j + 1.0);
                }
                dp = n * (z * p0 - p1) / (z * z - 1.0);
                const double dz = p0 / dp;
                z -= dz;
                if (std::fabs(dz) < 1e-16) break;
            }
            x[i] = -z;
            x[n - 1 - i] = z;
            w[i] = w[n - 1 - i] = 2.0 / ((1.0 - z * z) * dp * dp);
        }
    }

    /// Integral of f over [a, b] with this rule.
    template <class F> double integrate(F&& f, double a, double b) const {
        const double h = 0.5 * (b - a), m = 0.5 * (a + b);
        double s = 0;
        for (std::size_t i = 0; i < x.size(); ++i) s += w[i] * f(m + h * x[i]);
        return s * h;
    }

    /// Composite rule: [a, b] split into `panels` equal panels.
    template <class F> double integrate(F&& f, double a, double b, int panels) const {
        double s = 0;
        for (int p = 0; p < panels; ++p)
            s += integrate(f, a + (b - a) * p / panels, a + (b - a) * (p + 1) / panels);
        return s;
    }
};

// ---------------------------------------------------------------------------------------------
// Random numbers.
// ---------------------------------------------------------------------------------------------

/// Fixed-seed uniform variates in [0, 1) for T = float (top 24 bits) or double (top 53 bits):
/// exact dyadic values, never 1 (unlike std::generate_canonical for float, which can round up).
struct uniform_rng {
    std::mt19937_64 engine;
    explicit uniform_rng(std::uint64_t seed) : engine(seed) {}
    template <class T> T next() {
        const std::uint64_t bits = engine();
        if constexpr (sizeof(T) == sizeof(float))
            return T(bits >> 40) * T(0x1p-24);
        else
            return T(bits >> 11) * T(0x1p-53);
    }
    /// Two variates in a fixed order (the order of evaluation of function arguments is
    /// unspecified, so rng.next() twice in one call would differ between compilers).
    template <class V> V next2() {
        using T = typename V::value_type;
        const T a = next<T>();
        const T b = next<T>();
        return V(a, b);
    }
};

} // namespace ibl_test
