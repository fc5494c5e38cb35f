#pragma once
// ibl/integrate/gauss_legendre.hpp — Gauss-Legendre nodes and weights on [0, 1] (host only).
//
// The n nodes are the roots of the Legendre polynomial P_n mapped from [-1, 1] to [0, 1]; the
// weights sum to 1, so sum_k w_k f(x_k) approximates the MEAN of f over [0, 1] and is exact for
// polynomials of degree <= 2n - 1. Roots by Newton's method on the three-term recurrence
//   j P_j(z) = (2j - 1) z P_{j-1}(z) - (j - 1) P_{j-2}(z),
// started from Tricomi's approximation z_i ~ cos(pi (i + 3/4) / (n + 1/2)); weights
// 2 / ((1 - z^2) P_n'(z)^2) halved for the unit interval (A. H. Stroud, D. Secrest, "Gaussian
// Quadrature Formulas", 1966). Nodes ascend; the rule is symmetric about 1/2 to rounding.

#include <cmath>
#include <cstddef>
#include <vector>

#include "../core/constants.hpp"

namespace ibl {

struct gauss_legendre_rule {
    std::vector<double> x; ///< nodes in (0, 1), ascending
    std::vector<double> w; ///< weights, sum 1
};

/// The n-point Gauss-Legendre rule on [0, 1] (n >= 1), normalised to weights summing to 1.
inline gauss_legendre_rule make_gauss_legendre(std::size_t n) {
    gauss_legendre_rule r{std::vector<double>(n), std::vector<double>(n)};
    const double nd = double(n);
    for (std::size_t i = 0; i < (n + 1) / 2; ++i) {
        double z = std::cos(pi_v<double> * (double(i) + 0.75) / (nd + 0.5));
        double dp = 1.0;
        for (int it = 0; it < 100; ++it) {
            double p1 = 1.0, p2 = 0.0;
            for (std::size_t j = 1; j <= n; ++j) {
                const double p3 = p2;
                p2 = p1;
                p1 = ((2.0 * double(j) - 1.0) * z * p2 - (double(j) - 1.0) * p3) / double(j);
            }
            dp = nd * (z * p1 - p2) / ((z - 1.0) * (z + 1.0));
            const double dz = p1 / dp;
            z -= dz;
            if (std::fabs(dz) <= 4.0 * epsilon_v<double>) break; // quadratic convergence: one more step is noise
        }
        const double wi = 1.0 / ((1.0 - z) * (1.0 + z) * dp * dp); // = (2 / ((1-z^2) P'^2)) / 2
        // z > 0 for i < n/2: the node near +1 maps to the upper end of [0, 1].
        r.x[n - 1 - i] = 0.5 * (1.0 + z);
        r.x[i] = 0.5 * (1.0 - z);
        r.w[i] = r.w[n - 1 - i] = wi;
    }
    return r;
}

} // namespace ibl
