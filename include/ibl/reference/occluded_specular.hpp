#pragma once
// ibl/reference/occluded_specular.hpp — specular occlusion measured against an occluded reference
// (host only, double). The visible-fraction table of runtime/specular_occlusion.hpp is built by
// bake/specular_occlusion_lut.hpp.
//
// ---- The visibility model -----------------------------------------------------------------------
//   A shading point at normal n sees the environment only inside a cone of half-angle theta_o in
//   [0, pi] about a unit axis b (the bent normal): V(l) = 1 if b.l >= cos theta_o, else 0.
//   b = cos(beta) n + sin(beta) t, |beta| <= pi/2 the tilt and t a unit tangent (make_bent_cone
//   takes t in the plane of incidence towards the mirror direction R: beta > 0 tilts the cone
//   towards R, beta < 0 away from it, towards v). The ambient occlusion depends on |beta| only.
//
// ---- Ambient occlusion of the cone (ambient_occlusion_cone) -----------------------------------
//   ao = (1/pi) integral_{cone, n.l > 0} (n.l) dl, the cosine-weighted visible fraction.
//   In the frame of b with n = (sin beta, 0, cos beta) and l = (sin t cos p, sin t sin p, cos t):
//       n.l = a + c cos p,   a = cos beta cos t,  c = sin beta sin t >= 0,
//       I(t) = integral_0^{2 pi} max(0, a + c cos p) dp
//            = 2 pi a                                   (a >= c: the ring is above the horizon)
//            = 0                                        (a <= -c: below)
//            = 2 (a p0 + sqrt(c^2 - a^2)), p0 = acos(-a / c)   (the ring crosses it)
//       ao = (1/pi) integral_0^{theta_o} I(t) sin t dt.
//   I is smooth except at the horizon contacts t1 = pi/2 - beta (a = c) and t2 = pi/2 + beta
//   (a = -c), where it has (t - t_k)^(3/2) terms: on [0, t1] the integral is pi cos(beta) sin^2 t1,
//   on [t2, pi] it is 0, and [t1, min(t2, theta_o)] is integrated by Gauss-Legendre (nodes points)
//   in s after t = t1 + (hi - t1)(3 s^2 - 2 s^3), which makes those terms smooth. Closed form
//   where the cone does not reach the horizon (theta_o <= pi/2 - beta): ao = cos(beta) sin^2 theta_o
//   (in particular ao = sin^2 theta_o for b = n); ao = 1 once theta_o >= pi/2 + beta.
//   cone_half_angle_for_ao inverts ao(theta_o) (increasing on [0, pi/2 + beta]) by bisection.
//
// ---- The occluded reference (occluded_reference_specular) ---------------------------------------
//   Lo_s^occ(n, v) = integral f_s(v, l) L(l) V(l) (n.l) dl,  f_s as in reference_radiance
//   (reference/radiance.hpp): GGX D, the model's V, Schlick F per channel. Estimated by
//   integrate_product_mis with the product_lobe occluded_specular_lobe: the specular part of
//   brdf_lobe (diffuse albedo 0, so its sampler is the GGX VNDF alone) with two parts,
//       parts[0] = f_s (n.l)           (the unoccluded specular, exactly reference_radiance's)
//       parts[1] = f_s (n.l) V(l)      (the occluded specular)
//   drawn from the same samples (the ratio occ / unocc has a correlated, smaller error). The
//   proposals are those of the unoccluded integrand: the VNDF covers every l with f_s > 0, so the
//   estimate stays unbiased although samples (BRDF or environment) fall outside the cone and
//   contribute 0. Mirror regime (ggx_effectively_smooth): the exact term F(n.v) L(R) V(R).
//
// Domains: unit n, v (n.v clamped to [0, 1] as in reference_radiance); tilt in [-pi/2, pi/2],
// half-angle in [0, pi] (clamped); ao in [0, 1] (clamped).

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <numeric>
#include <utility>
#include <stdexcept>
#include <vector>

#include "../brdf/model.hpp"
#include "../core/constants.hpp"
#include "../core/executor.hpp"
#include "../core/frame.hpp"
#include "../core/gauss_legendre.hpp"
#include "../core/math.hpp"
#include "../core/vec.hpp"
#include "../runtime/specular_occlusion.hpp"
#include "../sampling/ggx.hpp"
#include "../bake/specular_occlusion_lut.hpp"
#include "radiance.hpp"

namespace ibl {

// ---- the visibility cone ----------------------------------------------------------------------

/// The cone of directions a shading point sees: V(l) = 1 iff axis.l >= cos(half_angle).
struct visibility_cone {
    vec3<double> axis{0.0, 0.0, 1.0}; ///< unit bent normal b
    double half_angle = 0.5 * pi_v<double>; ///< theta_o in [0, pi]

    [[nodiscard]] bool visible(const vec3<double>& l) const noexcept {
        return glm::dot(axis, l) >= std::cos(clamp(half_angle, 0.0, pi_v<double>));
    }
};

/// The cone about b = cos(tilt) n + sin(tilt) t, t the unit tangent of n in the plane of incidence
/// towards R = reflect(-v, n) (the frame's tangent when v = n). tilt clamped to [-pi/2, pi/2].
inline visibility_cone make_bent_cone(const vec3<double>& n, const vec3<double>& v, double tilt, double half_angle) {
    vec3<double> t = -(v - glm::dot(n, v) * n);
    const double len = glm::length(t);
    t = len > 1e-12 ? t / len : make_frame(n).t;
    const double b = clamp(tilt, -0.5 * pi_v<double>, 0.5 * pi_v<double>);
    return {std::cos(b) * n + std::sin(b) * t, clamp(half_angle, 0.0, pi_v<double>)};
}

namespace detail {
/// integral_0^{2 pi} max(0, a + c cos p) dp for c >= 0 (header).
inline double clipped_ring(double a, double c) noexcept {
    if (a >= c) return 2.0 * pi_v<double> * a;
    if (a <= -c) return 0.0;
    const double p0 = std::acos(clamp(-a / c, -1.0, 1.0));
    return 2.0 * (a * p0 + std::sqrt(std::max(0.0, c * c - a * a)));
}
} // namespace detail

/// Ambient occlusion (cosine-weighted visible fraction, header) of a cone of half-angle theta_o
/// whose axis is tilted by |tilt| (clamped to pi/2) from the normal; nodes Gauss-Legendre points.
inline double ambient_occlusion_cone(double tilt, double half_angle, std::uint32_t nodes = 32) {
    const double beta = std::min(std::fabs(tilt), 0.5 * pi_v<double>);
    const double to = clamp(half_angle, 0.0, pi_v<double>);
    if (to <= 0.5 * pi_v<double> - beta) return std::cos(beta) * sqr(std::sin(to));
    if (to >= 0.5 * pi_v<double> + beta) return 1.0;
    // [0, t1]: the whole ring is visible, closed form; [t2, theta_o]: nothing; [t1, min(t2, theta_o)]
    // by Gauss-Legendre after t = t1 + (hi - t1) (3 s^2 - 2 s^3) (the (t - t1)^(3/2) terms at the
    // contacts become smooth in s).
    const gauss_legendre_rule g = make_gauss_legendre(nodes > 0 ? nodes : 1);
    const double cb = std::cos(beta), sb = std::sin(beta);
    const double t1 = 0.5 * pi_v<double> - beta, hi = std::min(0.5 * pi_v<double> + beta, to);
    double sum = pi_v<double> * cb * sqr(std::sin(t1));
    for (std::size_t i = 0; i < g.x.size(); ++i) {
        const double u = g.x[i];
        const double t = t1 + (hi - t1) * u * u * (3.0 - 2.0 * u);
        const double dt = (hi - t1) * 6.0 * u * (1.0 - u);
        sum += g.w[i] * dt * detail::clipped_ring(cb * std::cos(t), sb * std::sin(t)) * std::sin(t);
    }
    return clamp(sum * inv_pi_v<double>, 0.0, 1.0);
}

/// The half-angle theta_o in [0, pi/2 + |tilt|] whose cone has ambient occlusion ao (bisection,
/// 60 steps; closed form asin(sqrt(ao)) at tilt 0). ao clamped to [0, 1].
inline double cone_half_angle_for_ao(double ao, double tilt = 0.0, std::uint32_t nodes = 32) {
    const double a = saturate(ao);
    const double beta = std::min(std::fabs(tilt), 0.5 * pi_v<double>);
    if (beta == 0.0) return std::asin(std::sqrt(a));
    double lo = 0.0, hi = 0.5 * pi_v<double> + beta;
    for (int it = 0; it < 60; ++it) {
        const double mid = 0.5 * (lo + hi);
        (ambient_occlusion_cone(beta, mid, nodes) < a ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
}

// ---- the occluded reference ---------------------------------------------------------------------

/// The specular f_s (n.l) of a reference material, unoccluded (parts[0]) and times V(l) (parts[1]).
template <class Model = ggx_height_correlated> class occluded_specular_lobe {
public:
    occluded_specular_lobe(const vec3<double>& n, const vec3<double>& v, reference_material m,
                           const visibility_cone& cone)
        : base_(n, v, specular_only(m)), cone_(cone) {}

    [[nodiscard]] lobe_sample sample(const vec2<double>& u) const noexcept { return base_.sample(u); }
    [[nodiscard]] double pdf(const vec3<double>& d) const noexcept { return base_.pdf(d); }
    [[nodiscard]] lobe_value eval(const vec3<double>& d) const noexcept {
        const lobe_value g = base_.eval(d);
        lobe_value out;
        out.parts[0] = g.parts[1];
        out.parts[1] = cone_.visible(d) ? g.parts[1] : vec3<double>(0.0);
        return out;
    }
    [[nodiscard]] const brdf_lobe<Model>& base() const noexcept { return base_; }

private:
    static reference_material specular_only(reference_material m) noexcept {
        m.diffuse_albedo = vec3<double>(0.0);
        return m;
    }
    brdf_lobe<Model> base_;
    visibility_cone cone_;
};

static_assert(product_lobe<occluded_specular_lobe<ggx_height_correlated>>);

/// Occluded and unoccluded specular radiance from the same samples, with standard errors.
struct occluded_specular_estimate {
    vec3<double> occluded{0.0};              ///< integral f_s L V (n.l)
    vec3<double> unoccluded{0.0};            ///< integral f_s L (n.l) (= reference_radiance's specular)
    vec3<double> std_error_occluded{0.0};
    vec3<double> std_error_unoccluded{0.0};
    std::uint64_t samples = 0;
};

/// The occluded reference (header) of material m's specular lobe under env, cone `cone`, model M,
/// MIS with `dist` (nullptr: BRDF sampling only); options and errors as reference_radiance.
template <class Model = ggx_height_correlated, class Env, class Executor = serial_executor>
    requires brdf_model<Model, double>
occluded_specular_estimate occluded_reference_specular(const Env& env, const cube_env_distribution* dist,
                                                       const vec3<double>& n, const vec3<double>& v,
                                                       const reference_material& m, const visibility_cone& cone,
                                                       const radiance_reference_options& opt = {},
                                                       Executor&& ex = Executor{}) {
    const occluded_specular_lobe<Model> lobe(n, v, m, cone);
    const product_estimate p = integrate_product_mis(env, dist, lobe, opt, ex);
    occluded_specular_estimate out;
    out.unoccluded = p.parts[0];
    out.occluded = p.parts[1];
    out.std_error_unoccluded = p.parts_std_error[0];
    out.std_error_occluded = p.parts_std_error[1];
    out.samples = p.samples;
    const vec3<double> fm = lobe.base().mirror_weight();
    if (fm != vec3<double>(0.0)) {
        const vec3<double> r = lobe.base().reflected();
        const vec3<double> l = fm * detail::rr_radiance(env, r);
        out.unoccluded += l;
        if (cone.visible(r)) out.occluded += l;
        out.samples += 1;
    }
    return out;
}

} // namespace ibl

#endif // IBL_DETAIL_CXX20
