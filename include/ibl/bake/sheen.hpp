#pragma once
// ibl/bake/sheen.hpp — the sheen products: the directional albedo of the Charlie sheen lobe by
// deterministic quadrature, as a look-up table in the DFG table's layout, and the Charlie-
// prefiltered environment (host only).
//
// The albedo (Estevez & Kulla 2017's D, Neubelt & Pettineo 2013's V; brdf/charlie.hpp):
//   E(mu, r) = integral over the hemisphere of D(h) V(n.v, n.l) (n.l) d(omega_l),   mu = n.v,
// the quantity of Filament's cloth DFG term (cmgen --ibl-dfg-cloth) and of the Khronos glTF IBL
// sampler's Charlie LUT: a renderer scales its sheen by E (or energy-compensates with 1 - E max).
// Not bounded by 1: V is not a masking term, and E(mu -> 0, r -> 0) grows like
// sqrt((2 + 1/alpha) / (2 pi)) (at n.v = 0, V n.l = 1/4 and integral D d(omega_h) ~ sqrt(pi/(2 alpha))).
// Limits: E(1, r) = 2^(1 - k/2) / (k + 2) in closed form (k = 2 + 1/alpha; V = 1/4 at n.v = 1);
// E(mu, r) -> 0 as r -> 0 for every mu > 0 (faster than exp(-k c2^2 / 2), c2 ~ mu / 2 below).
//
// Quadrature. In the half vector h = (theta, phi), v = (sin theta_v, 0, mu), d(omega_l) =
// 4 (v.h) d(omega_h), D d(omega_h) = (k / 2 pi) s^(1/alpha) s d(theta) d(phi) (s = sin theta,
// c = cos theta), and with n.l = 2 (v.h) c - mu (so v.h = (n.l + mu) / (2 c)):
//   4 V (n.l) (v.h) = g(n.l) / (2 c),   g(x) = x (x + mu) / (x + mu (1 - x)),
// which removes V's near-singularity at n.l, n.v -> 0 (g(x) = x (1 + O(mu)): the Jacobian's
// (n.l + mu) cancels V's denominator up to O(mu) terms). On a theta slice n.l = A cos(phi) + B,
// A = 2 c s sin(theta_v), B = mu (c^2 - s^2), and the n.l = 0 boundary splits theta exactly as in
// the DFG quadrature (bake/dfg.hpp): tan(theta1) = mu / (1 + sin theta_v), theta2 = pi/2 -
// theta1 (cos(theta2) = sin(theta1) ~ mu / 2 for small mu: exact, no cancellation). Then
//   E = (k / pi) [ int_0^theta1 s^(1/alpha + 1) / (2 c) Phi(theta) d(theta)
//                + int_{ln c2}^{ln c1} s^(1/alpha) / 2 Phi d(ln c) ],   Phi = int_0^{phi_max} g dphi,
//   * full panel [0, theta1] (phi_max = pi): Gauss-Legendre in theta x midpoint in phi (the phi
//     integrand is smooth and periodic: exponential convergence);
//   * partial panel [theta1, theta2]: the variable t = ln(cos theta) resolves both small scales
//     that meet there for small mu and small alpha, c2 ~ mu / 2 and the lobe's c ~ sqrt(alpha)
//     (s^(1/alpha) ~ exp(-c^2 / (2 alpha))); t = t1 + (t2 - t1) sin^2(pi tau / 2) removes the
//     (t - t1)^(3/2), (t2 - t)^(3/2) end behaviour of Phi; Gauss-Legendre in tau x Gauss-Legendre
//     in phi / phi_max (cos phi_max = -B / A; g vanishes linearly there).
// Computed in double. n.v is clamped to [sheen_min_n_dot_v, 1] = [2^-20, 1] (the panel ends at
// ln(c2) ~ ln(mu / 2) and must stay finite; the albedo changes by O(mu sqrt(k)) between mu = 0 and
// the clamp), roughness to [0, 1] with alpha clamped at charlie_min_alpha_v<double>.
// Accuracy with the default nodes (tests/test_sheen.cpp, against an independent hp-graded
// quadrature of the raw integrand at 152 points including the first row and column of a 128^2
// table): max abs error 1.0e-8 where E <= 1, max relative error 1.0e-8 where E > 1; E(1, r) matches
// its closed form to 4e-12 relative. 1088 evaluations of g per (n.v, r); 128^2 in 0.18 s serial.
//
// Table: make_sheen_lut(size) returns an ibl::dfg_lut with channels = 1 (channel 0 = E) in the DFG
// layout (texel centres x = n.v = (i + 0.5) / size, y = r = (j + 0.5) / size, row 0 = r = 0.5 /
// size first); dfg_lut::sample(n.v, r).x is its bilinear lookup. Rows go through the executor;
// the table does not depend on the partition.
//
// Prefiltered chain: prefilter<charlie_lobe>(env, opt) (bake/prefilter.hpp with the lobe of
// sampling/lobe.hpp): level l holds the Charlie LD (N = V = R) for sheen roughness
// opt.policy.roughness(l, levels); level 0 (r = 0) is the ring limit, convolved like the others.
// prefilter_sheen(env, opt) is that call.

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "../brdf/charlie.hpp"
#include "../brdf/ggx.hpp"
#include "../core/constants.hpp"
#include "../core/executor.hpp"
#include "../core/gauss_legendre.hpp"
#include "../core/math.hpp"
#include "../env/cubemap.hpp"
#include "../sampling/lobe.hpp"
#include "dfg_lut.hpp"
#include "prefilter.hpp"

namespace ibl {

/// Smallest n.v of the sheen albedo quadrature (reason: header comment).
inline constexpr double sheen_min_n_dot_v = 0x1p-20;

/// Node counts of the sheen albedo quadrature (cost: full_theta * full_phi + partial_t *
/// partial_phi evaluations of g per (n.v, r)).
struct sheen_quadrature_nodes {
    std::uint32_t full_theta = 24;  ///< Gauss-Legendre nodes in theta on [0, theta1]
    std::uint32_t full_phi = 16;    ///< midpoint nodes in phi on [0, pi]
    std::uint32_t partial_t = 64;   ///< Gauss-Legendre nodes in tau on the partial panel
    std::uint32_t partial_phi = 16; ///< Gauss-Legendre nodes in phi / phi_max there

    constexpr std::size_t evaluations() const noexcept {
        return std::size_t(full_theta) * full_phi + std::size_t(partial_t) * partial_phi;
    }
};

/// The node tables of sheen_quadrature_nodes (host-only owner).
class sheen_quadrature_rule {
public:
    explicit sheen_quadrature_rule(sheen_quadrature_nodes nodes = {}) : nodes_(nodes) {
        const std::uint32_t nt = nodes.full_theta > 0 ? nodes.full_theta : 1;
        const std::uint32_t np = nodes.full_phi > 0 ? nodes.full_phi : 1;
        const std::uint32_t pt = nodes.partial_t > 0 ? nodes.partial_t : 1;
        const std::uint32_t pp = nodes.partial_phi > 0 ? nodes.partial_phi : 1;
        full_theta_ = make_gauss_legendre(nt);
        full_cos_.resize(np);
        for (std::uint32_t j = 0; j < np; ++j) full_cos_[j] = std::cos(pi_v<double> * (double(j) + 0.5) / double(np));
        const gauss_legendre_rule tr = make_gauss_legendre(pt);
        part_s_.resize(pt);
        part_w_.resize(pt);
        for (std::uint32_t k = 0; k < pt; ++k) {
            const double s = std::sin(half_pi_v<double> * tr.x[k]);
            part_s_[k] = s * s;                                                             // sin^2(pi tau / 2)
            part_w_[k] = tr.w[k] * half_pi_v<double> * std::sin(pi_v<double> * tr.x[k]); // d(sin^2) / d tau
        }
        part_phi_ = make_gauss_legendre(pp);
    }
    const sheen_quadrature_nodes& nodes() const noexcept { return nodes_; }

    /// E(n.v, r) (see the header), double.
    double albedo(double n_dot_v, double roughness) const noexcept {
        const double mu = clamp(n_dot_v, sheen_min_n_dot_v, 1.0);
        const double sv = safe_sqrt((1.0 - mu) * (1.0 + mu));
        const double alpha = charlie_clamp_alpha(alpha_from_roughness(roughness));
        const double e = 1.0 / alpha, k = 2.0 + e;
        // tan(theta1) = mu / (1 + sin theta_v); cos(theta2) = sin(theta1), sin(theta2) = cos(theta1).
        const double t1 = mu / (1.0 + sv);
        const double c1 = 1.0 / std::sqrt(1.0 + t1 * t1), s1 = t1 * c1; // cos, sin of theta1
        const double theta1 = std::atan(t1);
        auto g = [mu](double x) { return x > 0.0 ? x * (x + mu) / (x + mu * (1.0 - x)) : 0.0; };
        // s^p from log(s^2) (p = e or e + 1), underflowing to 0 for small alpha.
        auto spow = [](double log_s2, double p) { return std::exp(0.5 * p * log_s2); };

        double full = 0.0;
        if (theta1 > 0.0) {
            for (std::size_t i = 0; i < full_theta_.x.size(); ++i) {
                const double th = theta1 * full_theta_.x[i];
                const double s = std::sin(th), c = std::cos(th);
                const double ls2 = 2.0 * std::log(s);
                const double a = 2.0 * c * sv * s, b = mu * (c - s) * (c + s);
                double inner = 0.0;
                for (double cp : full_cos_) inner += g(a * cp + b);
                inner *= pi_v<double> / double(full_cos_.size());
                full += full_theta_.w[i] * theta1 * spow(ls2, e + 1.0) / (2.0 * c) * inner;
            }
        }
        double part = 0.0;
        const double lt1 = std::log(c1), lt2 = std::log(s1); // ln c at theta1 and theta2 (lt2 < lt1)
        const double span = lt1 - lt2;
        if (span > 0.0) {
            for (std::size_t q = 0; q < part_s_.size(); ++q) {
                const double t = lt1 - span * part_s_[q];
                const double c = std::exp(t);
                const double s2 = (1.0 - c) * (1.0 + c);
                const double s = std::sqrt(s2);
                const double ls2 = std::log1p(-c * c);
                const double a = 2.0 * c * sv * s, b = mu * (c * c - s2);
                const double cos_max = a > 0.0 ? clamp(-b / a, -1.0, 1.0) : 1.0;
                const double phi_max = std::acos(cos_max);
                double inner = 0.0;
                for (std::size_t j = 0; j < part_phi_.x.size(); ++j)
                    inner += part_phi_.w[j] * g(a * std::cos(phi_max * part_phi_.x[j]) + b);
                inner *= phi_max;
                part += part_w_[q] * span * 0.5 * spow(ls2, e) * inner;
            }
        }
        return (k * inv_pi_v<double>) * (full + part);
    }

private:
    sheen_quadrature_nodes nodes_;
    gauss_legendre_rule full_theta_, part_phi_;
    std::vector<double> full_cos_, part_s_, part_w_;
};

/// The default rule, built once (thread-safe static initialisation).
inline const sheen_quadrature_rule& default_sheen_quadrature_rule() {
    static const sheen_quadrature_rule rule{};
    return rule;
}

/// Sheen albedo E(n.v, r) = int D_charlie V_neubelt (n.l) d(omega_l) by quadrature (double inside).
template <class T> T sheen_albedo(T n_dot_v, T roughness) {
    return T(default_sheen_quadrature_rule().albedo(double(n_dot_v), double(roughness)));
}

/// sheen_albedo with explicit node counts.
template <class T> T sheen_albedo(T n_dot_v, T roughness, sheen_quadrature_nodes nodes) {
    return T(sheen_quadrature_rule(nodes).albedo(double(n_dot_v), double(roughness)));
}

/// Node counts used for tables (the accuracy figures of the header comment).
inline constexpr sheen_quadrature_nodes sheen_lut_default_nodes{24, 16, 64, 16};

/// The sheen albedo table: channels = 1 (E), DFG layout (header comment), float.
template <class Executor = thread_executor>
dfg_lut make_sheen_lut(std::uint32_t size, sheen_quadrature_nodes nodes = sheen_lut_default_nodes, Executor&& ex = Executor{}) {
    dfg_lut lut{size, 1u, {}};
    lut.data.assign(std::size_t(size) * size, 0.0f);
    const sheen_quadrature_rule rule(nodes);
    ex(std::size_t(size), [&](std::size_t begin, std::size_t end) {
        for (std::size_t j = begin; j < end; ++j) {
            const double r = lut.roughness(std::uint32_t(j));
            for (std::uint32_t i = 0; i < size; ++i) lut.data[j * size + i] = float(rule.albedo(lut.n_dot_v(i), r));
        }
    });
    return lut;
}

/// The Charlie-prefiltered chain: prefilter<charlie_lobe>(env, opt, ex).
template <class Env, class Executor = thread_executor>
cubemap<float> prefilter_sheen(const Env& env, const prefilter_options& opt = {}, Executor&& ex = Executor{}) {
    return prefilter<charlie_lobe>(env, opt, ex);
}

} // namespace ibl

#endif // IBL_DETAIL_CXX20
