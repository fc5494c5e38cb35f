#pragma once
// ibl/bake/dfg.hpp — the split-sum DFG terms (A, B) of a BRDF model: Monte Carlo (GGX-NDF and
// visible-normal sampling) and a deterministic quadrature that converges to 1e-6 and beyond.
//
// The quantity (Karis 2013, "Real Shading in Unreal Engine 4"). For a model M (brdf/model.hpp)
// with specular lobe f = D V F and Schlick Fresnel F = F0 (1 - Fc) + F90 Fc, Fc = (1 - v.h)^5:
//   int f(v, l) (n.l) d(omega_l) = F0 A + F90 B,
//   A = int D V (n.l) (1 - Fc) d(omega_l),   B = int D V (n.l) Fc d(omega_l),
// and E = A + B is the directional albedo for F = 1 (used by bake/dfg_multiscatter.hpp).
// v = (sqrt(1 - mu^2), 0, mu) in tangent space, mu = n.v; r = perceptual roughness.
//
// Half-vector form. With d(omega_l) = 4 (v.h) d(omega_h) and h parameterised by the GGX NDF's CDF
// variable u (tan^2(theta_h) = alpha^2 u / (1 - u)) and phi, D_ggx(h) (n.h) d(omega_h) =
// du dphi / (2 pi), so
//   (A, B) = (1 / 2 pi) int_0^1 du int_0^{2 pi} dphi  w(h) [1 - Fc, Fc] 1[n.l > 0],
//   w = M::sample_weight = f (n.l) / pdf_l / F   (= 4 V (n.l)(v.h)/(n.h) for a GGX model).
// Monte Carlo draws (u, phi) from a Hammersley set (dfg_mc) — the literature's estimator — or
// draws h from the visible normals of v (dfg_mc_vndf, weight w (n.h) / ((v.h) G1(v)/(n.v))).
//
// Quadrature (dfg_exact). The integrand depends on phi only through cos(phi): integrate phi over
// [0, pi] (the mean over phi). n.l = 2 (v.h) cos(theta_h) - mu > 0  <=>  cos(phi) > c*(theta_h) =
// -mu cot(2 theta_h) / sin(theta_v). Hence two panels in theta_h:
//   [0, theta1], theta1 = pi/4 - theta_v/2: every phi is valid. The phi integrand is smooth and
//       periodic: the midpoint rule in phi converges exponentially.
//   [theta1, theta2], theta2 = pi/4 + theta_v/2: phi in [0, phi_max], phi_max = acos(c*), with
//       Gauss-Legendre in phi / phi_max. Beyond theta2 no direction is above the horizon.
//   tan(theta1) = mu / (1 + sin(theta_v)), tan(theta2) = 1 / tan(theta1) (exact, no cancellation).
// The radial variable is y = -ln(1 - u) = ln(1 + tan^2(theta_h) / alpha^2), du = e^-y dy:
// it is u near the peak (y ~ u for small u; the full-circle integrand is smooth in tan^2, so in
// y) and 2 ln(tan(theta_h) / alpha) in the tail, which resolves the lobe's tail for small alpha
// (where in u everything happens at 1 - u ~ alpha^2) and the grazing geometry near theta2
// (cos(theta2) ~ mu / 2). tan^2(theta_h) = alpha^2 expm1(y): accurate for every alpha down to
// ggx_min_alpha_v, so row 0 of a table (alpha = 1.5e-5) is integrated, not replaced by the r = 0
// limit. Panel 1 uses Gauss-Legendre in y on [0, y1]. On panel 2 the inner integral behaves like
// (y - y1)^(3/2) and (y2 - y)^(3/2) at the ends (a circle segment whose integrand vanishes
// linearly in n.l), so y = y1 + (y2 - y1) sin^2(pi tau / 2) makes it analytic in tau; then
// Gauss-Legendre in tau. Both y limits are capped at dfg_quadrature_y_max (batch/dfg_kernel.hpp).
// Node counts (dfg_quadrature_nodes) are the cost knob; convergence figures: docs and bench.
//
// Limits: at r = 0 the lobe is a mirror, h = n: A = 1 - (1 - mu)^5, B = (1 - mu)^5
// (dfg_smooth_limit); the quadrature reaches it by itself (the whole lobe lies below the y cap).
// mu -> 0 stays finite: the weight is finite for n.v = 0 in every shipped model.

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <cstddef>
#include <cstdint>
#include <vector>

#include "../batch/dfg_kernel.hpp"
#include "../brdf/model.hpp"
#include "../core/constants.hpp"
#include "../core/math.hpp"
#include "../core/vec.hpp"
#include "../sampling/ggx.hpp"
#include "../sampling/sequence.hpp"
#include "../core/gauss_legendre.hpp"
#include "../core/limits.hpp"

namespace ibl {

/// The r = 0 (mirror) limit of the DFG terms: (1 - (1 - mu)^5, (1 - mu)^5), mu clamped to [0, 1].
template <class T> IBL_FUNC vec2<T> dfg_smooth_limit(T n_dot_v) noexcept {
    const T fc = pow5(T(1) - saturate(n_dot_v));
    return {T(1) - fc, fc};
}

// -------------------------------------------------------------------------------------------------
// Quadrature.
// -------------------------------------------------------------------------------------------------

/// Node counts of the quadrature (its cost: full_y * full_phi + partial_y * partial_phi evaluations
/// of the weight per texel).
struct dfg_quadrature_nodes {
    std::uint32_t full_y = 16;      ///< Gauss-Legendre nodes in y on the full-circle panel
    std::uint32_t full_phi = 16;    ///< midpoint nodes in phi on [0, pi] there
    std::uint32_t partial_y = 40;   ///< Gauss-Legendre nodes (after the sin^2 map) on the partial panel
    std::uint32_t partial_phi = 16; ///< Gauss-Legendre nodes in phi / phi_max there

    /// The one-knob family used by the benchmarks: (n/2, n/2, n, n/2), n >= 2.
    static constexpr dfg_quadrature_nodes level(std::uint32_t n) noexcept {
        const std::uint32_t h = n / 2 > 0 ? n / 2 : 1;
        return {h, h, n, h};
    }
    constexpr std::size_t evaluations() const noexcept {
        return std::size_t(full_y) * full_phi + std::size_t(partial_y) * partial_phi;
    }
};

namespace detail {
/// Every count of `nodes` in [1, limits::max_quadrature_nodes] (zero nodes would integrate
/// nothing: E = 0 and k = (1 - E)/E = inf), checked for function `fn`.
inline void check_dfg_nodes(const char* fn, const dfg_quadrature_nodes& nodes) {
    const std::uint32_t hi = limits::max_quadrature_nodes;
    check_arg(fn, "nodes.full_y", nodes.full_y, 1u, hi, "limits::max_quadrature_nodes");
    check_arg(fn, "nodes.full_phi", nodes.full_phi, 1u, hi, "limits::max_quadrature_nodes");
    check_arg(fn, "nodes.partial_y", nodes.partial_y, 1u, hi, "limits::max_quadrature_nodes");
    check_arg(fn, "nodes.partial_phi", nodes.partial_phi, 1u, hi, "limits::max_quadrature_nodes");
}
/// samples <= limits::max_samples for function `fn` (std::length_error).
inline void check_samples(const char* fn, const char* arg, std::uint32_t samples) {
    check_total(fn, arg, samples, limits::max_samples, "limits::max_samples");
}
} // namespace detail

/// The node tables of dfg_quadrature_nodes (host-only owner of the arrays the kernel reads).
/// Throws std::invalid_argument for a zero count, std::length_error for a count above
/// limits::max_quadrature_nodes.
class dfg_quadrature_rule {
public:
    explicit dfg_quadrature_rule(dfg_quadrature_nodes nodes = {}) : nodes_(nodes) {
        detail::check_dfg_nodes("dfg_quadrature_rule", nodes);
        const gauss_legendre_rule fy = make_gauss_legendre(nodes.full_y);
        full_x_ = fy.x;
        full_w_ = fy.w;
        full_cos_.resize(nodes.full_phi);
        for (std::size_t j = 0; j < nodes.full_phi; ++j)
            full_cos_[j] = std::cos(pi_v<double> * (double(j) + 0.5) / double(nodes.full_phi));
        const gauss_legendre_rule py = make_gauss_legendre(nodes.partial_y);
        part_s_.resize(nodes.partial_y);
        part_w_.resize(nodes.partial_y);
        for (std::size_t k = 0; k < nodes.partial_y; ++k) {
            const double s = std::sin(half_pi_v<double> * py.x[k]);
            part_s_[k] = s * s;                                                     // sin^2(pi tau / 2)
            part_w_[k] = py.w[k] * half_pi_v<double> * std::sin(pi_v<double> * py.x[k]); // d s / d tau
        }
        const gauss_legendre_rule pp = make_gauss_legendre(nodes.partial_phi);
        part_xi_ = pp.x;
        part_xw_ = pp.w;
    }
    const dfg_quadrature_nodes& nodes() const noexcept { return nodes_; }
    dfg_quadrature_view view() const noexcept {
        return {full_x_.data(), full_w_.data(), full_x_.size(), full_cos_.data(), full_cos_.size(),
                part_s_.data(), part_w_.data(), part_s_.size(), part_xi_.data(), part_xw_.data(),
                part_xi_.size()};
    }

private:
    dfg_quadrature_nodes nodes_;
    std::vector<double> full_x_, full_w_, full_cos_, part_s_, part_w_, part_xi_, part_xw_;
};

/// The default rule, built once (thread-safe static initialisation).
inline const dfg_quadrature_rule& default_dfg_quadrature_rule() {
    static const dfg_quadrature_rule rule{};
    return rule;
}

/// (A, B) and E = A + B of model M by quadrature with the given rule (double inside).
template <class Model, class T> vec3<T> dfg_exact_abe(T n_dot_v, T roughness, const dfg_quadrature_rule& rule) {
    const double mu = double(n_dot_v);
    double e = 0.0, b = 0.0;
    dfg_quadrature_lanes<Model, 1>(rule.view(), double(roughness), &mu, &e, &b);
    return {T(e - b), T(b), T(e)};
}

/// Split-sum DFG terms (A, B) of model M by deterministic quadrature; with the default nodes
/// converged to <= 1e-6 (absolute) everywhere on [0, 1]^2 (figures: bench/bench_dfg.cpp). Computed
/// in double whatever T is. dfg_exact<ibl::ggx_height_correlated>(0.5, 0.3).
template <class Model, class T> vec2<T> dfg_exact(T n_dot_v, T roughness) {
    const vec3<T> abe = dfg_exact_abe<Model>(n_dot_v, roughness, default_dfg_quadrature_rule());
    return {abe.x, abe.y};
}

/// dfg_exact with explicit node counts (the cost knob).
template <class Model, class T> vec2<T> dfg_exact(T n_dot_v, T roughness, dfg_quadrature_nodes nodes) {
    const vec3<T> abe = dfg_exact_abe<Model>(n_dot_v, roughness, dfg_quadrature_rule(nodes));
    return {abe.x, abe.y};
}

// -------------------------------------------------------------------------------------------------
// Monte Carlo.
// -------------------------------------------------------------------------------------------------

/// The GGX-NDF half vectors of an n-point Hammersley set for one alpha: h = sample_ggx_ndf(
/// hammersley(i, n), alpha); only h.x and h.z are kept (v lies in the xz-plane).
template <class T> struct dfg_sample_table {
    std::vector<T> hx, hz;
};

/// n <= limits::max_samples (std::length_error beyond).
template <class T> dfg_sample_table<T> make_dfg_sample_table(T alpha, std::uint32_t n) {
    detail::check_samples("make_dfg_sample_table", "n", n);
    dfg_sample_table<T> t{std::vector<T>(n), std::vector<T>(n)};
    for (std::uint32_t i = 0; i < n; ++i) {
        const vec3<T> h = sample_ggx_ndf(hammersley<T>(i, n), alpha);
        t.hx[i] = h.x;
        t.hz[i] = h.z;
    }
    return t;
}

/// Split-sum DFG terms (A, B) of model M by Monte Carlo with `samples` Hammersley points and GGX
/// NDF importance sampling (the estimator of Karis 2013 / LearnOpenGL / Filament / glTF-IBL-
/// Sampler); samples with n.l <= 0 count as zeros. The batch kernel at width 1. samples = 0 gives 0;
/// samples > limits::max_samples throws std::length_error (the table holds 2 samples floats).
template <class Model, class T> vec2<T> dfg_mc(T n_dot_v, T roughness, std::uint32_t samples) {
    detail::check_samples("dfg_mc", "samples", samples);
    const dfg_sample_table<T> tab = make_dfg_sample_table(Model::alpha(roughness), samples);
    T e = T(0), b = T(0);
    dfg_mc_lanes<Model, 1>(tab.hx.data(), tab.hz.data(), samples, roughness, &n_dot_v, &e, &b);
    return {e - b, b};
}

/// The literature's loop written plainly, one texel at a time (LearnOpenGL's IntegrateBRDF with
/// the model's weight): for i < N: Xi = hammersley(i, N); H = sample_ggx_ndf(Xi, alpha);
/// L = reflect(-V, H); if n.l > 0 accumulate G_Vis (1 - Fc), G_Vis Fc; divide by N. The baseline
/// of the benchmarks and the oracle of the batch-kernel test. samples <= limits::max_samples.
template <class Model, class T> vec2<T> dfg_mc_scalar_loop(T n_dot_v, T roughness, std::uint32_t samples) {
    detail::check_samples("dfg_mc_scalar_loop", "samples", samples);
    const T mu = saturate(n_dot_v);
    const vec3<T> v(sin_from_cos(mu), T(0), mu);
    const T alpha = Model::alpha(roughness);
    T a = T(0), b = T(0);
    for (std::uint32_t i = 0; i < samples; ++i) {
        const vec3<T> h = sample_ggx_ndf(hammersley<T>(i, samples), alpha);
        const T v_dot_h = glm::dot(v, h);
        const vec3<T> l = T(2) * v_dot_h * h - v;
        const T n_dot_l = l.z;
        if (n_dot_l > T(0)) {
            const T g_vis = Model::sample_weight(mu, n_dot_l, h.z, v_dot_h, roughness);
            const T fc = pow5(T(1) - saturate(v_dot_h));
            a += (T(1) - fc) * g_vis;
            b += fc * g_vis;
        }
    }
    return samples > 0 ? vec2<T>(a / T(samples), b / T(samples)) : vec2<T>(T(0));
}

/// Split-sum DFG terms by Monte Carlo with visible-normal sampling (sample_ggx_vndf, Dupuy &
/// Benyoub 2023) of alpha = M::alpha(r): l = reflect(-v, h) has pdf_l = G1(v) D(h) / (4 n.v), so
/// the weight is M::sample_weight (n.h) / ((v.h) G1(v)/(n.v)) (= 4 V (n.l) (n.v) / G1(v) for a
/// GGX model: every sample lands where D is). Samples with n.l <= 0 count as zeros.
/// samples <= limits::max_samples (std::length_error beyond).
template <class Model, class T> vec2<T> dfg_mc_vndf(T n_dot_v, T roughness, std::uint32_t samples) {
    detail::check_samples("dfg_mc_vndf", "samples", samples);
    const T mu = saturate(n_dot_v);
    const vec3<T> v(sin_from_cos(mu), T(0), mu);
    const T alpha = Model::alpha(roughness);
    const T g1_over_mu = ggx_g1_over_n_dot_v(mu, alpha);
    T e = T(0), b = T(0);
    for (std::uint32_t i = 0; i < samples; ++i) {
        const vec3<T> h = sample_ggx_vndf(v, hammersley<T>(i, samples), alpha);
        const T v_dot_h = glm::dot(v, h);
        const T n_dot_l = T(2) * v_dot_h * h.z - mu;
        const T w = Model::sample_weight(mu, n_dot_l, h.z, v_dot_h, roughness);
        // w carries a factor v.h (> 0 for every VNDF sample; 0 only by rounding, where w = 0 too).
        const T wv = v_dot_h > T(0) ? w * h.z / (v_dot_h * g1_over_mu) : T(0);
        const T fc = pow5(T(1) - saturate(v_dot_h));
        e += wv;
        b += wv * fc;
    }
    return samples > 0 ? vec2<T>((e - b) / T(samples), b / T(samples)) : vec2<T>(T(0));
}

} // namespace ibl

#endif // IBL_DETAIL_CXX20
