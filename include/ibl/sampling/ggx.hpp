#pragma once
// ibl/sampling/ggx.hpp — importance sampling of the GGX (Trowbridge-Reitz) distribution, as
// sample / pdf / invert triplets, isotropic, in tangent space (z = the normal).
//
// Two samplers of the half vector h (the microfacet normal):
//
//  * sample_ggx_ndf: h with density D(h) (n.h) per unit solid angle of h (B. Walter, S. Marschner,
//    H. Li, K. Torrance, "Microfacet Models for Refraction through Rough Surfaces", EGSR 2007,
//    eqs. 35-36). Inverting the marginal CDF of theta_h,
//        F(theta) = 1 - 1 / (1 + tan^2(theta) / alpha^2)  =>  tan^2(theta) = alpha^2 u / (1 - u),
//    and written as a ratio of two sums of non-negative terms (no cancellation anywhere):
//        cos^2(theta) = (1 - u) / ((1 - u) + alpha^2 u),   sin^2(theta) = alpha^2 u / (same),
//    which is the stable form of cos^2 = (1 - u) / (1 + (alpha^2 - 1) u). phi = 2 pi u.y.
//
//  * sample_ggx_vndf: the distribution of visible normals for the view direction v,
//        D_v(h) = G1(v) max(0, v.h) D(h) / (n.v)      per unit solid angle of h
//    (E. Heitz, "Understanding the Masking-Shadowing Function", JCGT 3(2), 2014, eq. 38), sampled
//    with J. Dupuy, A. Benyoub, "Sampling Visible GGX Normals with Spherical Caps", HPG 2023
//    (arXiv:2306.05044): stretch v to the alpha = 1 configuration, v_s = normalize(alpha v.x,
//    alpha v.y, v.z); draw c uniformly on the spherical cap {c.z > -v_s.z} (phi = 2 pi u.x,
//    c.z = (1 - u.y)(1 + v_s.z) - v_s.z); the visible normal of the unit hemisphere is
//    h_s = normalize(c + v_s); unstretch h = normalize(alpha h_s.x, alpha h_s.y, h_s.z).
//    The cap point is recovered from h_s as c = 2 (h_s . v_s) h_s - v_s, which makes the warp
//    invertible. Quantities that cancel in the textbook form are computed directly:
//        c.z + v_s.z = (1 - u.y)(1 + v_s.z),   1 - c.z = u.y (1 + v_s.z),
//        1 + c.z = (1 - v_s.z) + (1 - u.y)(1 + v_s.z),  1 - v_s.z = (v_s.x^2 + v_s.y^2)/(1 + v_s.z).
//
// alpha (= roughness^2) is clamped with clamp_alpha (brdf/ggx.hpp) everywhere, so densities stay
// finite; the one exception is the stability contract's mirror limit: the samplers return the
// normal (0, 0, 1) exactly when alpha <= 0 (or NaN). The densities at alpha = 0 are those of the
// clamped alpha (finite, peaked at the normal).
//
// Every function is finite for u in [0, 1)^2 (including the corner 1 - eps/2), alpha in [0, 1]
// and unit v with v.z in [0, 1], including v.z = 0 exactly.

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <cmath>
#include <limits>

#include "../brdf/ggx.hpp"
#include "../core/constants.hpp"
#include "../core/math.hpp"
#include "../core/vec.hpp"
#include "hemisphere.hpp"

namespace ibl {

namespace detail {

/// The samplers' mirror regime: alpha = 0 exactly (or NaN, or negative) returns the normal.
template <class T> IBL_FUNC bool ggx_sampling_is_mirror(T alpha) noexcept { return !(alpha > T(0)); }

/// w / |w| computed after scaling by the largest |component|, so that neither the squares of
/// tiny components (alpha down to 2^-255 multiplies them) underflow to a zero length nor large
/// ones overflow. The zero vector, outside every caller's domain, maps to the normal (0, 0, 1).
template <class T> IBL_FUNC vec3<T> normalize_scaled(const vec3<T>& w) noexcept {
    using std::fabs;
    using std::sqrt;
    const T ax = fabs(w.x), ay = fabs(w.y), az = fabs(w.z);
    const T m = ax > ay ? (ax > az ? ax : az) : (ay > az ? ay : az);
    if (!(m > T(0))) return vec3<T>(T(0), T(0), T(1));
    const vec3<T> s = w * (T(1) / m);
    return s * (T(1) / sqrt(glm::dot(s, s)));
}

/// The view direction stretched to the alpha = 1 configuration: normalize(a v.x, a v.y, v.z),
/// with v.z clamped to [0, 1] (the domain of the VNDF).
template <class T> IBL_FUNC vec3<T> ggx_stretch_view(const vec3<T>& v, T alpha) noexcept {
    return normalize_scaled(vec3<T>(alpha * v.x, alpha * v.y, saturate(v.z)));
}

} // namespace detail

/// G1(v) / (n.v) for GGX in the finite closed form 2 / (mu + sqrt(mu^2 + alpha^2 (1 - mu^2))),
/// mu = n.v clamped to [0, 1]; equals 2/alpha at mu = 0 and 1 at mu = 1 (Heitz 2014, eq. 72
/// divided by mu; the root is brdf/ggx.hpp's ggx_smith_root). alpha is clamped with clamp_alpha,
/// so the value is at most 2/ggx_min_alpha_v.
template <class T> IBL_FUNC T ggx_g1_over_n_dot_v(T n_dot_v, T alpha) noexcept {
    const T mu = saturate(n_dot_v);
    return T(2) / (mu + ggx_smith_root(mu, sqr(clamp_alpha(alpha)))); // mu + root >= alpha > 0
}

// ---------------------------------------------------------------------------------------------
// Distribution of normals: pdf(h) = D(h) (n.h).
// ---------------------------------------------------------------------------------------------

/// Half vector h distributed with density D(h) (n.h) per unit solid angle of h (Walter et al.
/// 2007, eqs. 35-36, in the cancellation-free form of the header comment). Domain: u in [0, 1)^2
/// (theta from u.x, phi = 2 pi u.y), alpha in [0, 1] (clamped; alpha <= 0 returns (0, 0, 1)
/// exactly). Range: unit vectors with h.z in (0, 1].
template <class T> IBL_FUNC vec3<T> sample_ggx_ndf(const vec2<T>& u, T alpha) noexcept {
    if (detail::ggx_sampling_is_mirror(alpha)) return vec3<T>(T(0), T(0), T(1));
    const T a = clamp_alpha(alpha);
    const T one_minus_u = T(1) - u.x;             // > 0 on the domain
    const T den = one_minus_u + a * a * u.x;       // = 1 + (alpha^2 - 1) u, positive
    const T cos_theta = safe_sqrt(one_minus_u / den);
    const T sin_theta = a * safe_sqrt(u.x / den);
    return detail::spherical_direction(sin_theta, cos_theta, two_pi_v<T> * u.y);
}

/// Density of sample_ggx_ndf: D(h) max(0, n.h) per unit solid angle of h; 0 for h.z <= 0.
/// Domain: unit h, alpha in [0, 1] (clamped). Finite: at most 1 / (pi clamp_alpha(alpha)^2).
template <class T> IBL_FUNC T ggx_ndf_pdf(const vec3<T>& h, T alpha) noexcept {
    return ndf_ggx(h, alpha) * saturate(h.z);
}

/// Inverse of sample_ggx_ndf: u.x = sin^2 / (sin^2 + alpha^2 cos^2) (= tan^2 / (tan^2 + alpha^2),
/// with sin^2 = h.x^2 + h.y^2 accurate near the normal), u.y = phi / (2 pi). Domain: unit h with
/// h.z >= 0, alpha in (0, 1] (clamped; at alpha = 0 the sampler is not invertible and the clamped
/// alpha is used). Range: [0, 1)^2.
template <class T> IBL_FUNC vec2<T> invert_ggx_ndf(const vec3<T>& h, T alpha) noexcept {
    const T a = clamp_alpha(alpha);
    const T sin2 = h.x * h.x + h.y * h.y;
    const T den = sin2 + a * a * (h.z * h.z);
    const T ux = den > T(0) ? sin2 / den : T(0);
    return vec2<T>(ux < T(1) ? ux : one_minus_epsilon_v<T>, detail::unit_from_azimuth(h.y, h.x));
}

/// Density of the reflected direction l = 2 (v.h) h - v per unit solid angle of l, given the
/// density pdf_h of h per unit solid angle: pdf_h / (4 v.h) (the Jacobian d omega_h / d omega_l
/// = 1 / (4 v.h); K. Torrance, E. Sparrow 1967; Walter et al. 2007, eq. 14).
/// Domain: pdf_h >= 0, v_dot_h in [-1, 1]. Returns 0 for v.h <= 0 (no reflection), and saturates
/// at the largest finite T where the true density, pdf_h / (4 v.h), exceeds it (v.h -> 0+).
template <class T> IBL_FUNC T ggx_reflected_pdf(T pdf_h, T v_dot_h) noexcept {
    if (!(v_dot_h > T(0))) return T(0);
    const T q = pdf_h / (T(4) * v_dot_h);
    return q < std::numeric_limits<T>::max() ? q : std::numeric_limits<T>::max();
}

/// Density per unit solid angle of l = reflect(v, h) when h ~ sample_ggx_ndf:
/// D(h) (n.h) / (4 v.h). Domain: unit v, h; alpha in [0, 1] (clamped). Finite (see
/// ggx_reflected_pdf).
template <class T> IBL_FUNC T ggx_ndf_reflected_pdf(const vec3<T>& v, const vec3<T>& h, T alpha) noexcept {
    return ggx_reflected_pdf(ggx_ndf_pdf(h, alpha), glm::dot(v, h));
}

// ---------------------------------------------------------------------------------------------
// Distribution of visible normals: pdf(h) = G1(v) max(0, v.h) D(h) / (n.v).
// ---------------------------------------------------------------------------------------------

/// Visible normal h for the view direction v (Dupuy & Benyoub 2023, spherical caps).
/// Domain: unit v in tangent space with v.z in [0, 1] (v.z = 0, grazing, included; v.z < 0 is
/// clamped to 0), u in [0, 1)^2 (cap azimuth from u.x, cap height from u.y), alpha in [0, 1]
/// (clamped; alpha <= 0 returns (0, 0, 1) exactly). Range: unit vectors with h.z > 0 and
/// v.h >= 0. Density ggx_vndf_pdf(v, h, alpha) per unit solid angle of h.
///
/// The cap azimuth is measured from -v_s (psi = 2 pi (u.x - 1/2), exact subtraction), in the
/// frame e1 = v_s,xy / rho, e2 = z x e1 (rho = |v_s,xy|), because h_s = c + v_s vanishes at the
/// cap point c = -v_s (u.y -> 1, psi -> 0): there both components of h_s are formed without
/// cancellation,
///   h_s . e1 = (rho - sin_c) + 2 sin_c sin^2(psi/2),
///       rho - sin_c = (1 + v_s.z) (1 - u.y) ((1 - u.y) - v_s.z (1 + u.y)) / (rho + sin_c),
///   h_s . e2 = -sin_c sin(psi),    h_s . z = (1 - u.y)(1 + v_s.z),
/// so h keeps its relative accuracy up to the corner u = (1/2, 1 - eps/2). That corner maps to
/// the support edge (v.h -> 0, where the density vanishes): there v.h is ~eps^2 in exact
/// arithmetic and its computed value is the rounding noise of h, |v.h| <= a few eps.
template <class T> IBL_FUNC vec3<T> sample_ggx_vndf(const vec3<T>& v, const vec2<T>& u, T alpha) noexcept {
    using std::sin;
    using std::sqrt;
    if (detail::ggx_sampling_is_mirror(alpha)) return vec3<T>(T(0), T(0), T(1));
    const T a = clamp_alpha(alpha);
    const vec3<T> vs = detail::ggx_stretch_view(v, a);
    const T rho2 = vs.x * vs.x + vs.y * vs.y;
    const T rho = sqrt(rho2);
    // Azimuth of v_s; at normal view (rho = 0) any unit vector, +x.
    const T e1x = rho > T(0) ? vs.x / rho : T(1);
    const T e1y = rho > T(0) ? vs.y / rho : T(0);
    const T one_plus_vz = T(1) + vs.z;       // in [1, 2]
    const T one_minus_vz = rho2 / one_plus_vz; // 1 - vs.z, no cancellation
    const T w = T(1) - u.y;                    // in (0, 1]
    // Cap point c: 1 - c.z = u.y (1 + vs.z), 1 + c.z = (1 - vs.z) + w (1 + vs.z).
    const T sin_c = safe_sqrt(u.y * one_plus_vz * (one_minus_vz + w * one_plus_vz));
    const T den = rho + sin_c;
    // q = (1 - vs.z) - u.y (1 + vs.z) = w - vs.z (1 + u.y). Towards grazing view the second form
    // (exact at vs.z = 0, where the first would subtract |vs|^2 ~ 1 +- eps from u.y ~ 1); towards
    // normal view the first (accurate for small u.y, where the second subtracts two numbers ~ 1).
    // Either cancels only where q is far from the corner's q, with absolute error ~eps.
    const T q = vs.z < T(0.5) ? w - vs.z * (T(1) + u.y) : one_minus_vz - u.y * one_plus_vz;
    const T rho_minus_sin_c = den > T(0) ? one_plus_vz * w * q / den : T(0);
    const T psi = two_pi_v<T> * (u.x - T(0.5));
    const T s_half = sin(T(0.5) * psi);
    const T x1 = rho_minus_sin_c + T(2) * sin_c * s_half * s_half; // h_s . e1
    const T x2 = -sin_c * sin(psi);                                  // h_s . e2
    const vec3<T> hs(x1 * e1x - x2 * e1y, x1 * e1y + x2 * e1x, w * one_plus_vz);
    return detail::normalize_scaled(vec3<T>(a * hs.x, a * hs.y, hs.z));
}

/// Density of sample_ggx_vndf: G1(v) max(0, v.h) D(h) / (n.v) per unit solid angle of h
/// (Heitz 2014, eq. 38), with G1(v)/(n.v) in the closed form ggx_g1_over_n_dot_v, so it is finite
/// at n.v = 0 (where it tends to 2 max(0, v.h) D(h) / alpha). Domain: unit v with v.z in [0, 1],
/// unit h; alpha in [0, 1] (clamped). 0 for h.z <= 0 or v.h <= 0.
template <class T> IBL_FUNC T ggx_vndf_pdf(const vec3<T>& v, const vec3<T>& h, T alpha) noexcept {
    return ggx_g1_over_n_dot_v(v.z, alpha) * saturate(glm::dot(v, h)) * ndf_ggx(h, alpha);
}

/// Density per unit solid angle of l = reflect(v, h) when h ~ sample_ggx_vndf:
/// G1(v) D(h) / (4 n.v) — the v.h of the VNDF cancels the Jacobian 1/(4 v.h). 0 where v.h <= 0.
/// Finite for n.v = 0 (G1/(n.v) closed form). Domain as ggx_vndf_pdf.
template <class T> IBL_FUNC T ggx_vndf_reflected_pdf(const vec3<T>& v, const vec3<T>& h, T alpha) noexcept {
    const T v_dot_h = glm::dot(v, h);
    return v_dot_h > T(0) ? T(0.25) * ggx_g1_over_n_dot_v(v.z, alpha) * ndf_ggx(h, alpha) : T(0);
}

/// Inverse of sample_ggx_vndf: unstretch h to h_s = normalize(h.x, h.y, alpha h.z) (the same
/// direction as (h.x/alpha, h.y/alpha, h.z)), recover the cap point c = 2 (h_s . v_s) h_s - v_s,
/// then u.y = (1 - c.z) / (1 + v_s.z) and u.x = 1/2 + psi / (2 pi), psi the azimuth of c measured
/// from -v_s (see sample_ggx_vndf). Domain: v as sample_ggx_vndf, unit h with h.z > 0 and
/// v.h > 0 (the support), alpha in (0, 1] (clamped; at alpha = 0 the sampler is not invertible and
/// the clamped alpha is used). Range: [0, 1)^2.
template <class T> IBL_FUNC vec2<T> invert_ggx_vndf(const vec3<T>& v, const vec3<T>& h, T alpha) noexcept {
    using std::atan2;
    using std::sqrt;
    const T a = clamp_alpha(alpha);
    const vec3<T> vs = detail::ggx_stretch_view(v, a);
    const T rho = sqrt(vs.x * vs.x + vs.y * vs.y);
    const T e1x = rho > T(0) ? vs.x / rho : T(1);
    const T e1y = rho > T(0) ? vs.y / rho : T(0);
    const vec3<T> hs = detail::normalize_scaled(vec3<T>(h.x, h.y, a * h.z));
    const vec3<T> c = (T(2) * glm::dot(hs, vs)) * hs - vs;
    const T uy = saturate((T(1) - c.z) / (T(1) + vs.z));
    // psi = the azimuth of c measured from -v_s, in (-pi, pi]: the angle of (-c.e1, -c.e2).
    const T psi = atan2(c.x * e1y - c.y * e1x, -(c.x * e1x + c.y * e1y));
    const T ux = saturate(T(0.5) + psi * inv_two_pi_v<T>);
    return vec2<T>(ux < T(1) ? ux : T(0), uy < T(1) ? uy : one_minus_epsilon_v<T>); // psi = pi is u.x = 0
}

} // namespace ibl

#endif // IBL_DETAIL_CXX20
