#pragma once
// ibl/batch/dfg_kernel.hpp — the hot loops of the split-sum DFG integrators, as structure-of-arrays
// kernels over W texels of one LUT row (one roughness, W values of mu = n.v).
//
// Shape of every kernel: the node or sample table of the row is shared by all lanes (computed once
// per row, or once per table); per texel only the mu-dependent quantities are formed. The loops
// over lanes are branch-free (ternary selects inside the models' functions and here, no early
// exits), so that g++/clang -O3 auto-vectorise them (sqrt needs -fno-math-errno to vectorise in
// g++: the release preset sets it). The scalar entry points in bake/dfg.hpp call the same
// templates with W = 1, so scalar and batch results are the same arithmetic lane by lane.
//
// Geometry (tangent space, z = n): v = (sqrt(1 - mu^2), 0, mu) lies in the xz-plane, so for a half
// vector h only h.x and h.z matter: v.h = sin(theta_v) h.x + mu h.z, n.l = 2 (v.h) h.z - mu
// (l = 2 (v.h) h - v). Each kernel returns per lane
//   e = mean of w            (directional albedo with F = 1:  E = A + B)
//   b = mean of w Fc,  Fc = (1 - v.h)^5      (the F90 term B; the F0 term is A = e - b)
// with w = M::sample_weight(n.v, n.l, n.h, v.h, r) (brdf/model.hpp): f n.l / pdf_l / F for a half
// vector drawn from the GGX NDF, 0 below the horizon.

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <cmath>
#include <cstddef>
#include <cstdint>

#include "../brdf/model.hpp"
#include "../core/constants.hpp"
#include "../core/math.hpp"
#include "detail/lane_math.hpp"

namespace ibl {

namespace detail {

/// sin(theta_v) = sqrt((1 - mu)(1 + mu)) for mu in [0, 1].
template <class T> IBL_FUNC T dfg_sin_view(T mu) noexcept { return sin_from_cos(mu); }

/// One direction's contribution: accumulates w into e and w Fc into b.
template <class Model, class T>
IBL_FUNC_VOID void dfg_accumulate(T mu, T sin_v, T hx, T hz, T roughness, T& e, T& b) noexcept {
    const T v_dot_h = sin_v * hx + mu * hz;
    const T n_dot_l = T(2) * v_dot_h * hz - mu;
    const T w = Model::sample_weight(mu, n_dot_l, hz, v_dot_h, roughness);
    const T fc = pow5(T(1) - saturate(v_dot_h));
    e += w;
    b += w * fc;
}

} // namespace detail

// -------------------------------------------------------------------------------------------------
// Monte Carlo, GGX-NDF half vectors (the literature's estimator).
// -------------------------------------------------------------------------------------------------

/// Monte Carlo DFG of W texels sharing one roughness: the sample table holds h.x and h.z of n half
/// vectors drawn from the GGX NDF with alpha = Model::alpha(roughness) (h.y is not needed, see the
/// header comment). Every sample counts in n, also those with n.l <= 0 (weight 0), as in the
/// literature. Output per lane: e = mean w, b = mean w Fc (so A = e - b, B = b).
/// Accumulates in T (float: the literature's precision).
template <class Model, std::size_t W, class T>
IBL_FUNC_VOID void dfg_mc_lanes(const T* hx, const T* hz, std::uint32_t n, T roughness, const T* n_dot_v, T* e_out,
                                T* b_out) noexcept {
    // The roughness is held per lane although it is uniform: g++ does not vectorise a select on a
    // loop-invariant scalar condition (the models' clamps of r), but does one on a lane array.
    T mu[W], sin_v[W], e[W], b[W], rough[W];
    for (std::size_t l = 0; l < W; ++l) {
        rough[l] = roughness;
        mu[l] = saturate(n_dot_v[l]);
        sin_v[l] = detail::dfg_sin_view(mu[l]);
        e[l] = T(0);
        b[l] = T(0);
    }
    for (std::uint32_t i = 0; i < n; ++i) {
        const T x = hx[i], z = hz[i];
        for (std::size_t l = 0; l < W; ++l) detail::dfg_accumulate<Model>(mu[l], sin_v[l], x, z, rough[l], e[l], b[l]);
    }
    const T inv_n = n > 0 ? T(1) / T(n) : T(0);
    for (std::size_t l = 0; l < W; ++l) {
        e_out[l] = e[l] * inv_n;
        b_out[l] = b[l] * inv_n;
    }
}

// -------------------------------------------------------------------------------------------------
// Deterministic quadrature.
// -------------------------------------------------------------------------------------------------

/// Upper limit of the quadrature variable y = -ln(1 - u) (u the GGX NDF's CDF variable).
/// Reason: the D-weighted measure beyond it is e^-40 = 4e-18, and the weight grows at most like
/// e^(y/2) (at grazing view, where w ~ tan(theta_h)), so the neglected part is below 4 e^-20 = 8e-9
/// even at mu = 0; for alpha below ~1e-8 it is where all of the lobe sits (the r = 0 limit).
inline constexpr double dfg_quadrature_y_max = 40.0;

/// The node tables of the DFG quadrature in normalised panel coordinates (independent of mu and
/// roughness; see bake/dfg.hpp for the derivation). Pointers into arrays owned elsewhere.
struct dfg_quadrature_view {
    const double* full_x;      ///< full-circle panel: Gauss-Legendre nodes in [0, 1] (y = y1 x)
    const double* full_w;      ///<   their weights (sum 1)
    std::size_t full_n;
    const double* full_cos;    ///< cos(phi_j), phi_j = pi (j + 1/2) / m: midpoint rule on [0, pi]
    std::size_t full_m;
    const double* part_s;      ///< partial panel: y = y1 + (y2 - y1) s_k, s_k = sin^2(pi tau_k / 2)
    const double* part_w;      ///<   weight of node k: GL weight * (pi/2) sin(pi tau_k) (sum 1)
    std::size_t part_n;
    const double* part_xi;     ///< partial circle: phi = phi_max xi_j, GL nodes xi_j in [0, 1]
    const double* part_xw;     ///<   their weights (sum 1)
    std::size_t part_m;
};

namespace detail {
/// Panel limits for one lane: tan(theta1) = mu / (1 + sin(theta_v)) (theta1 = pi/4 - theta_v/2,
/// below which every phi has n.l > 0), tan(theta2) = 1 / tan(theta1) (theta2 = pi/4 + theta_v/2,
/// above which none has); y_i = ln(1 + tan^2(theta_i) / alpha^2), both capped at
/// dfg_quadrature_y_max.
IBL_FUNC_VOID void dfg_panel_limits(double mu, double sin_v, double alpha2, double& y1, double& y2) noexcept {
    const double t1 = mu / (1.0 + sin_v);
    const double q = t1 * t1 / alpha2;               // tan^2(theta1) / alpha^2, may be +inf
    const double a = std::log1p(q);
    const double b = std::log1p(1.0 / (q * alpha2 * alpha2)); // tan^2(theta2) / alpha^2
    y1 = a < dfg_quadrature_y_max ? a : dfg_quadrature_y_max;
    y2 = b < dfg_quadrature_y_max ? b : dfg_quadrature_y_max;
    y2 = y2 > y1 ? y2 : y1;
}
} // namespace detail

namespace detail {
/// The per-lane state of dfg_quadrature_lanes: the view (mu, sin(theta_v)), the panel limits
/// (y1, len = y2 - y1), the accumulators (e, b) in double and the Eval copies of the inputs.
template <std::size_t W, class Eval> struct dfg_lanes {
    double alpha2;
    double mu[W], sin_v[W], y1[W], len[W], e[W], b[W];
    Eval mu_e[W], sin_v_e[W], rough[W]; // rough: uniform, held per lane (see dfg_mc_lanes)
};

template <std::size_t W, class Eval>
inline void dfg_lanes_init(dfg_lanes<W, Eval>& s, double alpha2, double roughness, const double* n_dot_v) noexcept {
    s.alpha2 = alpha2;
    for (std::size_t l = 0; l < W; ++l) {
        s.mu[l] = saturate(n_dot_v[l]);
        s.sin_v[l] = dfg_sin_view(s.mu[l]);
        double y2;
        dfg_panel_limits(s.mu[l], s.sin_v[l], alpha2, s.y1[l], y2);
        s.len[l] = y2 - s.y1[l];
        s.e[l] = 0.0;
        s.b[l] = 0.0;
        s.mu_e[l] = Eval(s.mu[l]);
        s.sin_v_e[l] = Eval(s.sin_v[l]);
        s.rough[l] = Eval(roughness);
    }
}

/// Panel 1, theta_h in [0, theta1]: the whole phi circle is valid; midpoint rule in phi
/// (exponentially convergent for the smooth periodic integrand), Gauss-Legendre in y.
template <class Model, std::size_t W, class Eval>
inline void dfg_full_panel(const dfg_quadrature_view& q, dfg_lanes<W, Eval>& s) noexcept {
    double wy[W];
    Eval ct[W], st[W], pe[W], pb[W];
    double e[W], b[W]; // the accumulators in locals: no store through s in the loops
    for (std::size_t l = 0; l < W; ++l) {
        e[l] = s.e[l];
        b[l] = s.b[l];
    }
    for (std::size_t k = 0; k < q.full_n; ++k) {
        for (std::size_t l = 0; l < W; ++l) {
            const double y = s.y1[l] * q.full_x[k];
            const double em = lane_expm1_nonneg(y); // e^y - 1
            const double tan2 = s.alpha2 * em;      // tan^2(theta_h) = alpha^2 (e^y - 1)
            const double inv = 1.0 / (1.0 + tan2);
            ct[l] = Eval(std::sqrt(inv));
            st[l] = Eval(std::sqrt(tan2 * inv));
            wy[l] = s.y1[l] * q.full_w[k] / (1.0 + em) / double(q.full_m); // du = e^-y dy; mean over phi
            pe[l] = Eval(0);
            pb[l] = Eval(0);
        }
        for (std::size_t j = 0; j < q.full_m; ++j) {
            const Eval c = Eval(q.full_cos[j]);
            for (std::size_t l = 0; l < W; ++l)
                dfg_accumulate<Model>(s.mu_e[l], s.sin_v_e[l], st[l] * c, ct[l], s.rough[l], pe[l], pb[l]);
        }
        for (std::size_t l = 0; l < W; ++l) {
            e[l] += wy[l] * double(pe[l]);
            b[l] += wy[l] * double(pb[l]);
        }
    }
    for (std::size_t l = 0; l < W; ++l) {
        s.e[l] = e[l];
        s.b[l] = b[l];
    }
}

/// Panel 2, theta_h in [theta1, theta2]: phi in [0, phi_max], cos(phi_max) = -mu cot(2 theta_h)
/// / sin(theta_v); the sin^2 map of y removes the (y - y_i)^(3/2) endpoint behaviour.
template <class Model, std::size_t W, class Eval>
inline void dfg_partial_panel(const dfg_quadrature_view& q, dfg_lanes<W, Eval>& s) noexcept {
    double wy[W], phi_max[W];
    Eval ct[W], st[W], pe[W], pb[W];
    double e[W], b[W]; // the accumulators in locals: no store through s in the loops
    for (std::size_t l = 0; l < W; ++l) {
        e[l] = s.e[l];
        b[l] = s.b[l];
    }
    for (std::size_t k = 0; k < q.part_n; ++k) {
        for (std::size_t l = 0; l < W; ++l) {
            const double y = s.y1[l] + s.len[l] * q.part_s[k];
            const double em = lane_expm1_nonneg(y);
            const double tan2 = s.alpha2 * em;
            const double inv = 1.0 / (1.0 + tan2);
            ct[l] = Eval(std::sqrt(inv));
            st[l] = Eval(std::sqrt(tan2 * inv));
            // cot(2 theta) = (1 - tan^2) / (2 tan); NaN (0/0, only outside every used node) and
            // values beyond [-1, 1] clamp to the full or empty circle.
            const double c_star = -s.mu[l] * (1.0 - tan2) / (2.0 * std::sqrt(tan2) * s.sin_v[l]);
            phi_max[l] = lane_acos(c_star);
            wy[l] = s.len[l] * q.part_w[k] / (1.0 + em) * phi_max[l] * inv_pi_v<double>;
            pe[l] = Eval(0);
            pb[l] = Eval(0);
        }
        for (std::size_t j = 0; j < q.part_m; ++j) {
            const Eval xi = Eval(q.part_xi[j]), xw = Eval(q.part_xw[j]);
            for (std::size_t l = 0; l < W; ++l) {
                const Eval c = lane_cos_0_pi(Eval(phi_max[l]) * xi);
                Eval de = Eval(0), db = Eval(0);
                dfg_accumulate<Model>(s.mu_e[l], s.sin_v_e[l], st[l] * c, ct[l], s.rough[l], de, db);
                pe[l] += xw * de;
                pb[l] += xw * db;
            }
        }
        for (std::size_t l = 0; l < W; ++l) {
            e[l] += wy[l] * double(pe[l]);
            b[l] += wy[l] * double(pb[l]);
        }
    }
    for (std::size_t l = 0; l < W; ++l) {
        s.e[l] = e[l];
        s.b[l] = b[l];
    }
}
} // namespace detail

/// Deterministic DFG of W texels sharing one roughness. The panel geometry, node positions and
/// all accumulation are in double; the weight itself (the inner phi loops, the cost) is evaluated
/// in Eval: double for the reference entry points, float for tables (twice the SIMD lanes; its
/// relative rounding ~1e-7 per evaluation is far below the tables' 1e-5 target, and the sums over
/// phi have at most a few dozen terms before they join the double accumulators).
/// Output per lane: e = E = A + B and b = B.
template <class Model, std::size_t W, class Eval = double>
inline void dfg_quadrature_lanes(const dfg_quadrature_view& q, double roughness, const double* n_dot_v, double* e_out,
                                 double* b_out) noexcept {
    const double alpha = clamp_alpha(double(Model::alpha(roughness)));
    detail::dfg_lanes<W, Eval> s;
    detail::dfg_lanes_init(s, alpha * alpha, roughness, n_dot_v);
    detail::dfg_full_panel<Model>(q, s);
    detail::dfg_partial_panel<Model>(q, s);
    for (std::size_t l = 0; l < W; ++l) {
        e_out[l] = s.e[l];
        b_out[l] = s.b[l];
    }
}

} // namespace ibl

#endif // IBL_DETAIL_CXX20
