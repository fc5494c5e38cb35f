// python/tabulated_lobe.hpp — the LD lobe of a BRDF model written in Python, tabulated from one
// vectorised call of its ndf, for the library's prefilter and reference LD (sampling/lobe.hpp).
//
// With N = V = R the LD kernel D(h) max(n.l, 0) depends on h only through n.h (an isotropic D), so
// one radial table per roughness describes the lobe. The table variable is the DFG quadrature's
//     y = ln(1 + tan^2(theta_h) / a^2),     a = clamp(alpha, 2^-20, 1) (alpha = the model's alpha),
// on a uniform grid of G cells over [0, Y], Y = ln(1 + T / a^2), T = 1e12 (theta_h up to 90 - 6e-5
// degrees). In y the measure of D (n.h) over the hemisphere is
//     D cos(theta_h) d(omega_h) = f(y) dy d(phi) / (2 pi),    f(y) = pi a^2 D cos^4(theta_h) e^y,
// which is e^-y for GGX at alpha = a (a smooth function for every NDF whose width scales with
// alpha: GGX, Beckmann, Blinn-Phong by Walter's mapping). f is interpolated between the nodes
// exponentially (linearly in ln f; exact for GGX) where both node values are positive, linearly
// otherwise, and the lobe is that interpolated D (call it D~):
//   sample(u, r): phi = 2 pi u.y; y from the inverse of the cumulative integral of f~ (exact within
//       a cell: a logarithm, or a quadratic's root for a linear cell), h from y as sample_ggx_ndf
//       forms it (for GGX this is sample_ggx_ndf's map u.x -> theta_h up to rounding, apart from the
//       mass beyond T, ~a^2 1e-12 of the lobe);
//   pdf(h, r) = D~(h) (n.h) / M, M the integral of f~ (so the draws have density D~ (n.h) / M);
//   ld_weight = 1 (the draws follow D~ (n.h));  ld_pdf = D~ / (4 M) (pdf_l with v.h = n.h).
// So prefilter<python_lobe> and reference_ld<python_lobe> estimate the LD of D~; the difference to
// the model's own D is the interpolation error of ln f (zero for GGX; for Beckmann of the order of
// (Y / G)^2 e^y / 8 <= 1e-4 relative where the lobe has its mass). Mirror limit: r = 0 is taken
// as the mirror (prefilter level 0 a copy of the source), as for every microfacet NDF.
//
// The lobe concept has static member functions (the prefilter and reference LD are templated on the
// type), so the tables of one call are reached through a process-wide pointer, set for the call's
// duration under a mutex (lobe_tables_scope): one tabulated call at a time. Lookups are by exact
// roughness value: the binding tabulates every roughness the C++ call will use (the prefilter
// plan's levels, the reference's points) before it starts.
#pragma once

#include <ibl/core/constants.hpp>
#include <ibl/core/vec.hpp>
#include <ibl/sampling/ggx.hpp>
#include <ibl/sampling/lobe.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <mutex>
#include <vector>

namespace ibl_py {

/// One roughness: the nodes f_k = f(k dy), their cumulative integral and the grid.
struct lobe_table {
    double roughness = 0.0;
    double a = 1.0;     ///< the grid's alpha, clamp(alpha, 2^-20, 1)
    double y_max = 0.0; ///< Y
    double dy = 0.0;    ///< Y / G
    std::vector<double> f, cum; ///< G + 1 values each; cum[k] = integral of f~ over [0, k dy]

    static constexpr std::size_t cells = 4096;
    static constexpr double tan2_max = 1e12;
    static constexpr double min_a = 0x1p-20;

    double mass() const noexcept { return cum.back(); }

    /// The grid for a model alpha: y_k and the n.h of each node (what the model's ndf is given).
    void set_grid(double r, double alpha) {
        roughness = r;
        a = std::clamp(alpha, min_a, 1.0);
        y_max = std::log1p(tan2_max / (a * a));
        dy = y_max / double(cells);
    }
    double node_y(std::size_t k) const noexcept { return double(k) * dy; }
    double node_n_dot_h(std::size_t k) const noexcept {
        const double t = a * a * std::expm1(node_y(k)); // tan^2(theta_h)
        return std::sqrt(1.0 / (1.0 + t));
    }

    /// f_k from the model's D at the nodes (finite, >= 0: checked by the caller), and the cumulative integral.
    void set_values(const double* d) {
        f.resize(cells + 1);
        for (std::size_t k = 0; k <= cells; ++k) {
            const double em = std::expm1(node_y(k)); // e^y - 1
            const double c2 = 1.0 / (1.0 + a * a * em);
            f[k] = ibl::pi_v<double> * a * a * d[k] * c2 * c2 * (1.0 + em);
        }
        cum.assign(cells + 1, 0.0);
        for (std::size_t k = 0; k < cells; ++k) cum[k + 1] = cum[k] + cell_mass(k);
    }

    /// ln(f_{k+1} / f_k) when the cell is exponential, else NaN (linear cell).
    double cell_slope(std::size_t k) const noexcept {
        return f[k] > 0.0 && f[k + 1] > 0.0 ? std::log(f[k + 1] / f[k]) : std::nan("");
    }
    double cell_mass(std::size_t k) const noexcept {
        const double s = cell_slope(k);
        if (std::isnan(s)) return 0.5 * dy * (f[k] + f[k + 1]);
        return dy * f[k] * (std::fabs(s) < 1e-12 ? 1.0 + 0.5 * s : std::expm1(s) / s);
    }
    /// f~(y) for y in [0, Y].
    double value(double y) const noexcept {
        const double q = y / dy;
        const std::size_t k = std::min(cells - 1, std::size_t(q));
        const double x = q - double(k); // in [0, 1]
        const double s = cell_slope(k);
        if (std::isnan(s)) return f[k] + (f[k + 1] - f[k]) * x;
        return f[k] * std::exp(s * x);
    }
    /// The y whose cumulative integral is c in [0, M).
    double inverse(double c) const noexcept {
        std::size_t k = std::size_t(std::upper_bound(cum.begin(), cum.end(), c) - cum.begin());
        k = std::clamp<std::size_t>(k, 1, cells) - 1; // cum[k] <= c < cum[k + 1]
        const double rest = std::max(0.0, c - cum[k]); // mass to cover within cell k
        const double s = cell_slope(k);
        double x; // offset in y within the cell
        if (std::isnan(s)) {
            // f_k x + g x^2 / 2 = rest, g = (f_{k+1} - f_k) / dy: the root in its stable form
            const double g = (f[k + 1] - f[k]) / dy;
            const double disc = std::max(0.0, f[k] * f[k] + 2.0 * g * rest);
            const double den = f[k] + std::sqrt(disc);
            x = den > 0.0 ? 2.0 * rest / den : 0.0;
        } else if (std::fabs(s) < 1e-12) {
            x = rest / f[k];
        } else {
            // f_k dy (e^(s x / dy) - 1) / s = rest
            x = dy / s * std::log1p(s * rest / (dy * f[k]));
        }
        return std::clamp(node_y(k) + std::clamp(x, 0.0, dy), 0.0, y_max);
    }
    /// D~(h) (n.h) / M without the factor n.h, i.e. D~ / M, at a unit h with h.z > 0 (0 beyond Y).
    double density_over_n_dot_h(const ibl::vec3<double>& h) const noexcept {
        const double c2 = h.z * h.z;
        if (!(h.z > 0.0)) return 0.0;
        const double q = (h.x * h.x + h.y * h.y) / (c2 * a * a); // tan^2 / a^2 = e^y - 1
        const double y = std::log1p(q);
        if (!(y <= y_max)) return 0.0;
        // D~ = f~ / (pi a^2 cos^4 e^y)
        return value(y) / (ibl::pi_v<double> * a * a * c2 * c2 * (1.0 + q)) / mass();
    }
};

/// The tables of one call, sorted by roughness.
struct lobe_tables {
    std::vector<lobe_table> tables;
    const lobe_table& at(double r) const noexcept {
        auto it = std::lower_bound(tables.begin(), tables.end(), r,
                                   [](const lobe_table& t, double v) { return t.roughness < v; });
        if (it == tables.end()) --it; // never: every roughness used is tabulated first
        return *it;
    }
};

inline const lobe_tables* active_lobe_tables = nullptr;
inline std::mutex active_lobe_tables_mutex;

/// Sets the process-wide tables for the duration of one C++ call (take with the GIL released).
class lobe_tables_scope {
public:
    explicit lobe_tables_scope(const lobe_tables& t) : lock_(active_lobe_tables_mutex) { active_lobe_tables = &t; }
    ~lobe_tables_scope() { active_lobe_tables = nullptr; }
    lobe_tables_scope(const lobe_tables_scope&) = delete;
    lobe_tables_scope& operator=(const lobe_tables_scope&) = delete;

private:
    std::lock_guard<std::mutex> lock_;
};

/// The lobe (sampling/lobe.hpp's concept) of the active tables.
struct python_lobe {
    static constexpr const char* name = "python";
    static constexpr bool mirror_limit = true;

    static ibl::vec3<double> sample(const ibl::vec2<double>& u, double roughness) noexcept {
        const lobe_table& t = active_lobe_tables->at(roughness);
        const double y = t.inverse(u.x * t.mass());
        const double den = 1.0 + t.a * t.a * std::expm1(y); // 1 + tan^2
        const double cos_theta = std::sqrt(1.0 / den);
        const double sin_theta = t.a * std::sqrt(std::expm1(y) / den);
        return ibl::detail::spherical_direction(sin_theta, cos_theta, ibl::two_pi_v<double> * u.y);
    }
    static double pdf(const ibl::vec3<double>& h, double roughness) noexcept {
        return active_lobe_tables->at(roughness).density_over_n_dot_h(h) * std::max(h.z, 0.0);
    }
    static double ld_weight(const ibl::vec3<double>&, double) noexcept { return 1.0; }
    static double ld_pdf(const ibl::vec3<double>& h, double roughness) noexcept {
        return 0.25 * active_lobe_tables->at(roughness).density_over_n_dot_h(h);
    }
};
static_assert(ibl::ld_lobe<python_lobe>);

} // namespace ibl_py
