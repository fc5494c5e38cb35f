#pragma once
// ibl/bake/lobe_moments.hpp — the moments of the specular lobe and of the chain's LD kernel, and the
// chain roughness whose kernel matches a lobe's spread (host only). bake/lobe_fit.hpp starts its
// L1 fits from them; the first-moment table built from them alone (make_lobe_lut, the lobe LUT's
// baseline) is research/lobe_moment_baseline.hpp.
//
// Moments of the specular lobe (Fresnel excluded). In the tangent frame of n with
// v = (sin theta, 0, cos theta), R = (-sin theta, 0, cos theta), the normalised lobe
// p(l) = D V (n.l) / E is integrated over the GGX visible normals: h = sample_ggx_vndf(v, u),
// l = reflect(-v, h), weight f (n.l) / pdf_l = 4 V (n.l) (n.v) / G1(v) (written with
// ggx_g1_over_n_dot_v: finite at n.v = 0), a midpoint rule of nodes^2 points in u. Outputs:
//   E      the mean weight = A + B (a check against dfg_exact)
//   m      the mean direction (m.y = 0 by symmetry), rho = |m|
//   phi    atan2(-m.x, m.z), the angle of m from n towards R
//   s      the lerp factor with normalize(lerp(n, R, s)) = m / rho:
//          s = tan phi / (sin theta + tan phi (1 - cos theta)); theta is floored at
//          lobe_min_theta (at n.v = 1 every s gives n; the floor keeps s continuous there)
//   var_major, var_minor  second moments of p in the tangent plane of m / rho, in and across the
//          plane of incidence (the lobe's stretch; reported, not stored)
// The LD kernel of a chain (bake/prefilter.hpp, N = V = R): weight k(R.l) = R.l (Karis) or
// G1(R.l), density D(h) over l. Its mean resultant length is
//   rho_LD(alpha) = int k(mu) mu D dl / int k(mu) D dl,  mu = R.l = 2 cos^2 theta_h - 1,
// integrated over the GGX NDF variable u (cos^2 theta_h = (1 - u) / (1 + (alpha^2 - 1) u), the
// horizon mu = 0 at u = 1 / (1 + alpha^2)) with a midpoint rule of kernel_nodes points;
// rho_LD decreases with alpha, and r_eff solves rho_LD(r_eff^2) = rho by bisection (r_eff = 1 when
// the lobe is wider than the r = 1 kernel). The mirror row (r = 0) holds s = 1, r_eff = 0.

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include "../brdf/ggx.hpp"
#include "../brdf/model.hpp"
#include "../core/executor.hpp"
#include "../core/limits.hpp"
#include "../core/math.hpp"
#include "../core/vec.hpp"
#include "../runtime/lookup.hpp"
#include "../sampling/ggx.hpp"
#include "dfg_lut.hpp"
#include "prefilter.hpp"
#include "../runtime/tables.hpp"

namespace ibl {

/// Floor of the view angle theta = acos(n.v) used for the lerp factor (radians).
inline constexpr double lobe_min_theta = 0.01;

struct lobe_moments {
    double albedo = 0.0;   ///< E = A + B
    vec3<double> mean{0.0}; ///< m (tangent frame of n, v in the x-z plane at +x)
    double rho = 0.0;      ///< |m|
    double phi = 0.0;      ///< angle of m from n towards R (radians)
    double lerp = 1.0;     ///< s
    double var_major = 0.0, var_minor = 0.0;
};

namespace detail {
/// The specular lobe's visible-normal draws at (n.v, r) in the tangent frame of n with
/// v = (sin theta, 0, cos theta) (header): a midpoint grid of q^2 points u, h = sample_ggx_vndf,
/// l = reflect(-v, h); fn(l, h, V(n.v, n.l)) for each draw with l above the horizon (and v.h > 0).
/// The estimator weight of a draw is f (n.l) / pdf_l = 4 V (n.l) (n.v) / G1(v).
template <class Model, class Fn> void for_each_lobe_draw(double mu, double roughness, std::uint32_t q, Fn&& fn) {
    const double alpha = clamp_alpha(Model::alpha(roughness));
    const vec3<double> v(std::sqrt((1.0 - mu) * (1.0 + mu)), 0.0, mu);
    for (std::uint32_t j = 0; j < q; ++j)
        for (std::uint32_t i = 0; i < q; ++i) {
            const vec2<double> u((double(i) + 0.5) / double(q), (double(j) + 0.5) / double(q));
            const vec3<double> h = sample_ggx_vndf(v, u, alpha);
            const double vh = glm::dot(v, h);
            const vec3<double> l = 2.0 * vh * h - v;
            if (!(l.z > 0.0) || !(vh > 0.0)) continue;
            fn(l, h, Model::visibility(mu, l.z, roughness));
        }
}
} // namespace detail

/// Moments of the lobe of model M at (n.v, r) (header); nodes^2 points (nodes clamped to
/// [1, 4096]).
template <class Model = ggx_height_correlated>
lobe_moments specular_lobe_moments(double n_dot_v, double roughness, std::uint32_t nodes = 128) {
    const std::uint32_t q = nodes < 1 ? 1 : (nodes > 4096 ? 4096 : nodes);
    const double mu = saturate(n_dot_v), r = saturate(roughness);
    const double alpha = clamp_alpha(Model::alpha(r));
    const double g1_over_nv = ggx_g1_over_n_dot_v(mu, alpha);
    double sw = 0.0;
    vec3<double> sm(0.0);
    std::vector<vec3<double>> ls;
    std::vector<double> ws;
    ls.reserve(std::size_t(q) * q);
    ws.reserve(std::size_t(q) * q);
    detail::for_each_lobe_draw<Model>(mu, r, q, [&](const vec3<double>& l, const vec3<double>&, double vis) {
        const double w = 4.0 * vis * l.z / g1_over_nv;
        sw += w;
        sm += w * l;
        ls.push_back(l);
        ws.push_back(w);
    });
    lobe_moments out;
    const double n = double(q) * double(q);
    out.albedo = sw / n;
    if (!(sw > 0.0)) return out;
    out.mean = sm / sw;
    out.rho = glm::length(out.mean);
    out.phi = std::atan2(-out.mean.x, out.mean.z);
    const double theta = std::max(std::acos(mu), lobe_min_theta);
    const double tp = std::tan(out.phi);
    out.lerp = clamp(tp / (std::sin(theta) + tp * (1.0 - std::cos(theta))), 0.0, 1.0);
    const vec3<double> e1(std::cos(out.phi), 0.0, std::sin(out.phi)); // in-plane, perpendicular to m
    double s1 = 0.0, s2 = 0.0;
    for (std::size_t k = 0; k < ls.size(); ++k) {
        const double a = glm::dot(ls[k], e1);
        s1 += ws[k] * a * a;
        s2 += ws[k] * ls[k].y * ls[k].y;
    }
    out.var_major = s1 / sw;
    out.var_minor = s2 / sw;
    return out;
}

/// Mean resultant length of the normalised LD kernel of roughness r and weight w (header).
inline double ld_kernel_rho(double roughness, ld_weight w, std::uint32_t kernel_nodes = 2048) {
    const double alpha = clamp_alpha(alpha_from_roughness(saturate(roughness)));
    const double a2 = alpha * alpha;
    const double u_max = 1.0 / (1.0 + a2);
    const std::uint32_t q = kernel_nodes > 0 ? kernel_nodes : 1;
    double num = 0.0, den = 0.0;
    for (std::uint32_t i = 0; i < q; ++i) {
        const double u = u_max * (double(i) + 0.5) / double(q);
        const double c2 = (1.0 - u) / (1.0 + (a2 - 1.0) * u);
        const double m = 2.0 * c2 - 1.0;
        if (!(m > 0.0)) continue;
        const double k = w == ld_weight::g1 ? g1_smith_ggx(m, alpha) : m;
        num += k * m;
        den += k;
    }
    return den > 0.0 ? num / den : 1.0;
}

/// The roughness whose LD kernel (weight w) has mean resultant length rho (bisection, 48 steps).
inline double ld_matched_roughness(double rho, ld_weight w, std::uint32_t kernel_nodes = 2048) {
    if (!(rho < 1.0)) return 0.0;
    if (rho <= ld_kernel_rho(1.0, w, kernel_nodes)) return 1.0;
    double lo = 0.0, hi = 1.0;
    for (int it = 0; it < 48; ++it) {
        const double mid = 0.5 * (lo + hi);
        (ld_kernel_rho(mid, w, kernel_nodes) > rho ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
}


} // namespace ibl

#endif // IBL_DETAIL_CXX20
