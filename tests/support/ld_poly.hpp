#pragma once
// tests/support/ld_poly.hpp — shared by the lobe tests: graded Gauss-Legendre quadrature, a
// polynomial environment with its LD in closed form for any kernel symmetric about R, the kernel
// moments by quadrature of an NDF, and the bound of a sample table's LD error from its moments.

#include <ibl/core/vec.hpp>
#include <ibl/bake/sphere_convolve.hpp>

#include <cmath>
#include <cstddef>

#include "stats.hpp"

namespace ibl_test {

using ld_dvec2 = ibl::vec2<double>;
using ld_dvec3 = ibl::vec3<double>;
inline constexpr double ld_pi = 3.141592653589793238462643383279502884;

/// Composite Gauss-Legendre over [a, b] graded geometrically toward both ends (panels of relative
/// size 2^-j, j < levels, then one end panel): resolves algebraic end behaviour and features at
/// every scale down to 2^-levels of the interval.
template <class F> inline double graded_integral(F&& f, double a, double b, int levels, const gauss_legendre& gl) {
    if (!(b > a)) return 0.0;
    const double h = 0.5 * (b - a);
    double s = 0.0;
    for (int side = 0; side < 2; ++side) {
        double d = h; // distance of the panel's inner edge from the end
        for (int j = 0; j <= levels; ++j) {
            const double d_next = j < levels ? 0.5 * d : 0.0;
            const double lo = side == 0 ? a + d_next : b - d, hi = side == 0 ? a + d : b - d_next;
            s += gl.integrate(f, lo, hi);
            d = d_next;
        }
    }
    return s;
}

// -------------------------------------------------------------------------------------------------
// A polynomial environment L(d) = a + b.d + d^T C d (positive on the sphere) and its LD in closed
// form. For a kernel symmetric about R with moments E[n.l] = m1, E[(n.l)^2] = m2 (tangential
// second moments (1 - m2)/2 each), LD(R) = a + m1 b.R + (1 - m2)/2 tr C + (m2 - (1 - m2)/2) R^T C R.
// -------------------------------------------------------------------------------------------------
struct poly_env {
    double a = 1.0;
    ld_dvec3 b{0.3, -0.2, 0.25};
    double c[3][3] = {{0.2, 0.1, 0.0}, {0.1, -0.1, 0.05}, {0.0, 0.05, 0.15}};
    double value(const ld_dvec3& d) const {
        double q = 0;
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) q += d[i] * c[i][j] * d[j];
        return a + glm::dot(b, d) + q;
    }
    ibl::vec3<double> radiance(const ld_dvec3& d, double) const {
        const double v = value(d);
        return {v, 0.5 * v, 0.25 * v};
    }
    double texel_solid_angle(double) const { return 0.0; }
    double ld(const ld_dvec3& R, double m1, double m2) const {
        const double tr = c[0][0] + c[1][1] + c[2][2];
        double q = 0;
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) q += R[i] * c[i][j] * R[j];
        const double t = 0.5 * (1.0 - m2);
        return a + m1 * glm::dot(b, R) + t * tr + (m2 - t) * q;
    }
    /// |b| |dm1| + ||C||_F |dM2|_F: the bound of |LD_table - LD| from the table's moment errors.
    double frob() const {
        double s = 0;
        for (auto& row : c)
            for (double x : row) s += x * x;
        return std::sqrt(s);
    }
};

/// The same moments by graded quadrature in theta_h of D(theta) n.l 4 n.h sin (any NDF D).
template <class D> ld_dvec2 kernel_moments_quadrature(D&& ndf) {
    const gauss_legendre gl(12);
    auto m = [&](int p) {
        return graded_integral(
            [&](double th) {
                const double nl = std::cos(2 * th);
                return ndf(th) * std::pow(nl, p) * std::cos(th) * std::sin(th);
            },
            0.0, 0.25 * ld_pi, 40, gl);
    };
    const double m0 = m(1);
    return {m(2) / m0, m(3) / m0};
}

/// Normalised first and second moments of a table's directions (tangent frame), in double.
struct table_moments {
    ld_dvec3 m1{0.0};
    double m2[3][3] = {};
};
template <class S> table_moments moments_of(const ibl::sphere_sample_table<S>& t) {
    table_moments out;
    double w = 0;
    for (std::size_t i = 0; i < t.size(); ++i) {
        const ld_dvec3 l(double(t.x[i]), double(t.y[i]), double(t.z[i]));
        const double wi = double(t.weight[i]);
        w += wi;
        out.m1 += wi * l;
        for (int p = 0; p < 3; ++p)
            for (int q = 0; q < 3; ++q) out.m2[p][q] += wi * l[p] * l[q];
    }
    out.m1 /= w;
    for (auto& row : out.m2)
        for (double& x : row) x /= w;
    return out;
}
/// |b| |m1_table - m1| + ||C|| ||M2_table - M2||_F for kernel moments (m1, m2).
inline double moment_bound(const poly_env& env, const table_moments& t, ld_dvec2 m) {
    const double d1 = glm::length(t.m1 - ld_dvec3(0, 0, m.x));
    const double tt = 0.5 * (1.0 - m.y);
    const double exact[3][3] = {{tt, 0, 0}, {0, tt, 0}, {0, 0, m.y}};
    double d2 = 0;
    for (int p = 0; p < 3; ++p)
        for (int q = 0; q < 3; ++q) d2 += (t.m2[p][q] - exact[p][q]) * (t.m2[p][q] - exact[p][q]);
    return glm::length(env.b) * d1 + env.frob() * std::sqrt(d2);
}

} // namespace ibl_test
