#pragma once
// ibl/core/gauss_legendre.hpp — Gauss-Legendre nodes and weights on [0, 1] (host only); used by
// the DFG quadrature (bake/dfg.hpp) and the SH quadrature projection (sh/).
//
// The n nodes are the roots of the Legendre polynomial P_n (on [-1, 1], or mapped to [0, 1] with
// weights summing to 1, so that sum_k w_k f(x_k) approximates the MEAN of f over [0, 1]); exact for
// polynomials of degree <= 2n - 1. Roots by Newton's method on the three-term recurrence
//   j P_j(z) = (2j - 1) z P_{j-1}(z) - (j - 1) P_{j-2}(z),
// started from Tricomi's approximation z_i ~ cos(pi (i + 3/4) / (n + 1/2)); weights
// 2 / ((1 - z^2) P_n'(z)^2) halved for the unit interval (A. H. Stroud, D. Secrest, "Gaussian
// Quadrature Formulas", 1966). Nodes ascend; the rule is symmetric about 1/2 to rounding.

#include "config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <cmath>
#include <cstddef>
#include <vector>

#include "constants.hpp"
#include "limits.hpp"

namespace ibl {

struct gauss_legendre_rule {
    std::vector<double> x; ///< nodes, ascending
    std::vector<double> w; ///< weights
};

namespace detail {
/// P_n(t) and P_n'(t) by the three-term recurrence (n >= 1).
inline void legendre_and_derivative(std::size_t n, double t, double& p, double& dp) {
    double p0 = 1.0, p1 = t;
    for (std::size_t k = 1; k < n; ++k) {
        const double p2 = (double(2 * k + 1) * t * p1 - double(k) * p0) / double(k + 1);
        p0 = p1;
        p1 = p2;
    }
    p = p1;
    dp = n == 1 ? 1.0 : double(n) * (t * p1 - p0) / ((t - 1.0) * (t + 1.0));
}
} // namespace detail

/// The n-point rule on [-1, 1] (n >= 1): weights sum to 2; nodes ascend, symmetric (the centre
/// node of odd n is exactly 0). Newton's method to |dt| <= 4 eps, then the weight from P_n' at
/// the converged node: nodes and weights to about 1 ulp for n up to several hundred.
/// Throws std::invalid_argument for n = 0, std::length_error for n > limits::max_gauss_legendre_nodes.
inline gauss_legendre_rule make_gauss_legendre_symmetric(std::size_t n) {
    detail::check_arg("make_gauss_legendre", "n", n, std::size_t(1), limits::max_gauss_legendre_nodes,
                      "limits::max_gauss_legendre_nodes");
    gauss_legendre_rule r{std::vector<double>(n), std::vector<double>(n)};
    const double nd = double(n);
    for (std::size_t i = 0; i < (n + 1) / 2; ++i) {
        double t = std::cos(pi_v<double> * (double(i) + 0.75) / (nd + 0.5)); // Tricomi's guess
        double p = 0.0, dp = 1.0;
        for (int it = 0; it < 100; ++it) {
            detail::legendre_and_derivative(n, t, p, dp);
            const double dt = p / dp;
            t -= dt;
            if (std::fabs(dt) <= 4.0 * epsilon_v<double>) break; // quadratic convergence
        }
        detail::legendre_and_derivative(n, t, p, dp);
        const double w = 2.0 / ((1.0 - t) * (1.0 + t) * dp * dp);
        r.x[n - 1 - i] = t; // t > 0 for i < n/2: the upper half
        r.x[i] = -t;
        r.w[i] = r.w[n - 1 - i] = w;
    }
    if (n % 2 == 1) r.x[n / 2] = 0.0;
    return r;
}

/// The n-point rule on [0, 1] (n >= 1; bounds as make_gauss_legendre_symmetric), x = (1 + t)/2, normalised to weights summing to 1.
inline gauss_legendre_rule make_gauss_legendre(std::size_t n) {
    gauss_legendre_rule r = make_gauss_legendre_symmetric(n);
    for (std::size_t i = 0; i < n; ++i) {
        r.x[i] = 0.5 * (1.0 + r.x[i]);
        r.w[i] *= 0.5;
    }
    return r;
}

} // namespace ibl

#endif // IBL_DETAIL_CXX20
