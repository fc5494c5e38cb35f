#pragma once
// ibl/reference/disk_light.hpp — host quadratures of a disk light (runtime/shade.hpp's disk_light<T>, a
// sun that env/sun_extract.hpp removed from an environment), in double (host only).
//
// * disk_light_ld(light, R, r, nodes): the disk's exact contribution to the prefiltered LD term
//   (bake/prefilter.hpp: w(l) = D(h) max(R.l, 0), h = normalize(R + l), N = V = R),
//       LD_disk(R) = L * integral over the cap of w(l) dl / W(alpha)
//   with W from ggx_ld_normaliser, so that the LD of the original environment is the residual's LD
//   plus this (LD is linear in L with a common denominator). Quadrature in polar coordinates
//   (rho, psi) about R with the GGX variable u in place of rho: with theta_h = rho / 2 and
//   tan^2 theta_h = alpha^2 u / (1 - u) (u the GGX NDF's CDF variable),
//       w dl = D(h) cos(rho) 4 cos(theta_h) dw_h = (2 / pi) cos(rho(u)) du dpsi,
//       cos(rho(u)) = (1 - (1 + alpha^2) u) / (1 - (1 - alpha^2) u),
//   so the NDF peak is flat for every alpha (no lobe is too sharp for the rule). Along each psi
//   the ray from R meets the cap in one interval of rho, in closed form: l.d = C cos(rho - phi0),
//   |rho - phi0| <= acos(cos r / C), clipped to [0, pi/2] (R's horizon), and the u integral
//   over it is closed: with a = 1 + alpha^2, b = 1 - alpha^2,
//       integral (1 - a u)/(1 - b u) du = (a / b) u + (2 alpha^2 / b^2) ln(1 - b u)
//   (used for b >= 1/2; for alpha^2 > 1/2, where it cancels, `nodes` Gauss-Legendre nodes in u,
//   the pole 1/b > 2 being far from [0, u* = 1/a]). In psi: when R is inside the cap every psi hits and the inner integral is
//   smooth and periodic (midpoint rule, 4 nodes nodes); otherwise psi hits only within Delta of
//   the direction towards the sun, cos^2(psi - psi_c) >= (cos^2 r - cos^2 gamma) / sin^2 gamma,
//   where the inner integral vanishes like a square root: psi = psi_c + Delta sin(s) with
//   Gauss-Legendre in s in [-pi/2, pi/2] removes it. Cost 4 nodes inner integrals.
//   LD weight (runtime/ld_weight.hpp): with ld_weight::g1 the weight is D(h) G1(R.l), so the
//   inner integrand cos(rho(u)) becomes G1(cos rho(u)) (no closed form: `nodes` Gauss-Legendre
//   nodes in u over the interval, 1 - u interpolated between its ends, which are exact in
//   tau = tan^2(rho/2), so a sharp lobe keeps its resolution) and W is ggx_ld_normaliser_g1.
// * disk_light_specular_reference(n, v, light, f0, f90, r, nodes): the exact cap integral of the
//   disk light's specular BRDF of runtime/shade.hpp (GGX D, height-correlated Smith V, Schlick F: the
//   image-based products' model), integral L f(v, l) max(n.l, 0) dl, by the midpoint rule in polar
//   coordinates about the disk centre (nodes radial x 4 nodes azimuthal): the reference that
//   disk_light_specular (the widened lobe of runtime/shade.hpp) is measured against.
// * disk_light_irradiance_reference(n, light, nodes): integral L max(n.l, 0) dl over the cap by
//   the same rule (a check of the closed form of disk_light_irradiance).

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <algorithm>
#include <cmath>
#include <cstddef>

#include "../brdf/ggx.hpp"
#include "../core/constants.hpp"
#include "../core/frame.hpp"
#include "../core/gauss_legendre.hpp"
#include "../core/math.hpp"
#include "../core/sum.hpp"
#include "../core/vec.hpp"
#include "../runtime/shade.hpp"
#include "ld_irradiance.hpp"

namespace ibl {

namespace detail {
/// integral of G1(cos rho(u)) du over the u interval of rho in [lo, hi] (the g1 weight's inner
/// integral, see the header): Gauss-Legendre in u, tau = tan^2(rho/2) = alpha^2 u / (1 - u).
inline double disk_inner_g1(double lo, double hi, double alpha, const gauss_legendre_rule& gu) {
    const double a2 = alpha * alpha;
    const double t0 = sqr(std::tan(0.5 * lo)), t1 = sqr(std::tan(0.5 * hi));
    const double u0 = t0 / (a2 + t0), u1 = t1 / (a2 + t1), v0 = a2 / (a2 + t0), v1 = a2 / (a2 + t1); // v = 1 - u
    double s = 0.0;
    for (std::size_t k = 0; k < gu.x.size(); ++k) {
        const double x = gu.x[k];
        const double u = u0 + (u1 - u0) * x, v = v0 + (v1 - v0) * x;
        const double tau = v > 0.0 ? a2 * u / v : 0.0;
        s += gu.w[k] * g1_smith_ggx((1.0 - tau) / (1.0 + tau), alpha);
    }
    return s * (a2 * (t1 - t0) / ((a2 + t1) * (a2 + t0)));
}

/// The n.l weight's inner integral over rho in [lo, hi] for b = 1 - alpha^2 >= 1/2 (aq = 1 +
/// alpha^2, bq = b): the closed form in tau = tan^2(rho/2) (u = tau / (alpha^2 + tau)): 1 - b u =
/// alpha^2 (1 + tau) / (alpha^2 + tau), finite where u rounds to 1 (a mirror).
inline double disk_inner_nl_closed(double lo, double hi, double a2, double aq, double bq) {
    const double t0 = sqr(std::tan(0.5 * lo)), t1 = sqr(std::tan(0.5 * hi));
    const double du = a2 * (t1 - t0) / ((a2 + t1) * (a2 + t0));
    // ln((1 + t1)/(1 + t0)) + ln((a2 + t0)/(a2 + t1)), by log1p where the ratio is near 1
    auto log_ratio_of = [](double num, double den) {
        return std::fabs(num - den) <= 0.5 * den ? std::log1p((num - den) / den) : std::log(num) - std::log(den);
    };
    const double log_ratio = log_ratio_of(1.0 + t1, 1.0 + t0) + log_ratio_of(a2 + t0, a2 + t1);
    return (aq / bq) * du + (2.0 * a2 / (bq * bq)) * log_ratio;
}

/// The inner integral of disk_light_ld_weight at azimuth psi about R: the rho interval of the cap
/// at psi, then the weight's integral over it (G1: disk_inner_g1; n.l: the closed form, or
/// Gauss-Legendre in u for alpha^2 > 1/2, where the pole 1/b > 2 is far from [0, u*]).
struct disk_cap_inner {
    double sin_g, cos_g, psi_c, cos_r, alpha, a2, aq, bq;
    ld_weight weight;
    const gauss_legendre_rule& gu;

    double u_of(double rho) const {
        const double tau = sqr(std::tan(0.5 * rho));
        return tau / (a2 + tau);
    }
    double operator()(double psi) const {
        const double B = sin_g * std::cos(psi - psi_c), C = std::hypot(cos_g, B);
        if (!(C > cos_r)) return 0.0;
        const double phi0 = std::atan2(B, cos_g), delta = std::acos(std::min(1.0, cos_r / C));
        const double lo = std::max(0.0, phi0 - delta), hi = std::min(half_pi_v<double>, phi0 + delta);
        if (!(hi > lo)) return 0.0;
        if (weight == ld_weight::g1) return disk_inner_g1(lo, hi, alpha, gu);
        if (bq >= 0.5) return disk_inner_nl_closed(lo, hi, a2, aq, bq);
        const double u0 = u_of(lo), u1 = u_of(hi);
        double s = 0.0;
        for (std::size_t k = 0; k < gu.x.size(); ++k) {
            const double u = u0 + (u1 - u0) * gu.x[k];
            s += gu.w[k] * std::max(0.0, (1.0 - aq * u) / (1.0 - bq * u));
        }
        return s * (u1 - u0);
    }
};

/// The outer integral over psi of inner(psi) (gamma: the angle from R to the cap's centre):
/// the midpoint rule over the whole circle when R is inside the cap, else Gauss-Legendre over the
/// cap's psi range psi_c -+ Delta with psi = psi_c + Delta sin(s).
inline double disk_cap_outer(const disk_cap_inner& inner, double gamma, double radius, int nq) {
    neumaier_sum<double> acc;
    if (gamma <= radius) {
        const int np = 4 * nq;
        const double dp = two_pi_v<double> / double(np);
        for (int j = 0; j < np; ++j) acc.add(inner((double(j) + 0.5) * dp) * dp);
    } else {
        const double q = (inner.cos_r * inner.cos_r - inner.cos_g * inner.cos_g) / (inner.sin_g * inner.sin_g);
        const double Delta = std::acos(std::sqrt(std::clamp(q, 0.0, 1.0)));
        const gauss_legendre_rule gp = make_gauss_legendre(std::size_t(4 * nq));
        for (std::size_t k = 0; k < gp.x.size(); ++k) {
            const double s = pi_v<double> * (gp.x[k] - 0.5); // [-pi/2, pi/2]
            acc.add(gp.w[k] * pi_v<double> * Delta * std::cos(s) * inner(inner.psi_c + Delta * std::sin(s)));
        }
    }
    return acc.value();
}
} // namespace detail

/// Integral over the cap of the disk light of D(h) k(R.l) dl (see the header; k = max(R.l, 0)
/// or G1(R.l) by the LD weight); unit R.
template <class T>
double disk_light_ld_weight(const disk_light<T>& light, const vec3<double>& dir, double roughness, int nodes = 32,
                            ld_weight weight = ld_weight::n_dot_l) {
    const int nq = nodes > 0 ? nodes : 1;
    const double alpha = clamp_alpha(alpha_from_roughness(saturate(roughness)));
    const double a2 = alpha * alpha, aq = 1.0 + a2, bq = (1.0 - alpha) * (1.0 + alpha);
    const double c = cap_one_minus_cos(double(light.solid_angle));
    if (!(c > 0.0)) return 0.0;
    const double cos_r = 1.0 - c, radius = std::acos(cos_r);
    const vec3<double> R = glm::normalize(dir), d = glm::normalize(vec3<double>(light.direction));
    const double cos_g = std::clamp(glm::dot(R, d), -1.0, 1.0), gamma = std::acos(cos_g);
    if (gamma - radius >= half_pi_v<double>) return 0.0; // the cap is below R's horizon
    const frame<double> fr = make_frame(R);
    const vec3<double> dl = fr.to_local(d);
    const double psi_c = std::atan2(dl.y, dl.x), sin_g = std::sqrt(std::max(0.0, 1.0 - cos_g * cos_g));
    const gauss_legendre_rule gu = make_gauss_legendre(std::size_t(nq));
    const detail::disk_cap_inner inner{sin_g, cos_g, psi_c, cos_r, alpha, a2, aq, bq, weight, gu};
    return (2.0 / pi_v<double>) * detail::disk_cap_outer(inner, gamma, radius, nq);
}

/// The disk light's contribution to LD at unit R and perceptual roughness r (see the header),
/// for a chain of LD weight w.
template <class T>
vec3<double> disk_light_ld(const disk_light<T>& light, const vec3<double>& dir, double roughness, int nodes = 32,
                           ld_weight weight = ld_weight::n_dot_l) {
    const double alpha = clamp_alpha(alpha_from_roughness(saturate(roughness)));
    return vec3<double>(light.radiance) *
           (disk_light_ld_weight(light, dir, roughness, nodes, weight) / ggx_ld_normaliser(alpha, weight));
}

/// Exact cap integral of L f_spec(v, l) max(n.l, 0) (GGX D, height-correlated V, Schlick F); unit n, v.
template <class T>
vec3<double> disk_light_specular_reference(const vec3<double>& n, const vec3<double>& v, const disk_light<T>& light,
                                           const vec3<double>& f0, const vec3<double>& f90, double roughness, int nodes = 256) {
    const double c = cap_one_minus_cos(double(light.solid_angle));
    if (!(c > 0.0)) return vec3<double>(0.0);
    const double n_dot_v = saturate(glm::dot(n, v));
    const vec3<double> s = detail::cap_integral(glm::normalize(vec3<double>(light.direction)), std::acos(1.0 - c), nodes,
                                                [&](const vec3<double>& l) {
                                                    const light_cosines<double> lc = make_light_cosines(n, v, l);
                                                    const double alpha = clamp_alpha(alpha_from_roughness(saturate(roughness)));
                                                    return fresnel_schlick(lc.v_dot_h, f0, f90) *
                                                           (ndf_ggx(lc.n_dot_h, alpha) *
                                                            v_smith_ggx_correlated(n_dot_v, lc.n_dot_l, alpha) * lc.n_dot_l);
                                                });
    return vec3<double>(light.radiance) * s;
}

/// Cap integral of L max(n.l, 0) by the midpoint rule (a check of disk_light_irradiance).
template <class T> vec3<double> disk_light_irradiance_reference(const vec3<double>& n, const disk_light<T>& light, int nodes = 256) {
    const double c = cap_one_minus_cos(double(light.solid_angle));
    if (!(c > 0.0)) return vec3<double>(0.0);
    const vec3<double> s = detail::cap_integral(glm::normalize(vec3<double>(light.direction)), std::acos(1.0 - c), nodes,
                                                [&](const vec3<double>& l) { return vec3<double>(std::max(0.0, glm::dot(n, l))); });
    return vec3<double>(light.radiance) * s.x;
}

} // namespace ibl

#endif // IBL_DETAIL_CXX20
