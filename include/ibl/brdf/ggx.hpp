#pragma once
// ibl/brdf/ggx.hpp — the GGX / Trowbridge-Reitz microfacet distribution, isotropic.
//
// Parameter: alpha = roughness^2 (roughness = perceptual roughness in [0, 1]).
//   D(h)    = alpha^2 / (pi ((n.h)^2 (alpha^2 - 1) + 1)^2)              [Walter et al. 2007, eq. 33]
//           = alpha^2 / (pi (sin^2 + alpha^2 cos^2)^2)        (the form used here: no cancellation)
//   Normalisation: integral over the hemisphere of D(h) (n.h) d(omega_h) = 1.
//   Lambda(mu) = (-1 + sqrt(1 + alpha^2 tan^2(theta))) / 2,  mu = cos(theta)    [Heitz 2014, eq. 72]
//   G1(mu)  = 1 / (1 + Lambda(mu)) = 2 mu / (mu + sqrt(mu^2 + alpha^2 (1 - mu^2)))
//             (the second form is finite at mu = 0, where G1 = 0, and needs no tan).
//
// Alpha clamp (the stability contract): alpha is clamped to [ggx_min_alpha_v<T>, 1]. At alpha = 0
// the distribution is a Dirac delta and has no finite value; ggx_min_alpha_v<T> is the smallest
// power of two whose fourth power is still a normal number of T (2^-31 for float, 2^-255 for
// double), so no intermediate of D underflows and the peak D = 1/(pi alpha^2) stays finite
// (at most 1.5e18 in float). Integrators detect the mirror regime with ggx_effectively_smooth.

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include "../core/constants.hpp"
#include "../core/math.hpp"
#include "../core/vec.hpp"

#include <limits>

namespace ibl {

template <class T> inline constexpr T ggx_min_alpha_v = T(0x1p-31);
template <> inline constexpr double ggx_min_alpha_v<double> = 0x1p-255;

/// alpha = roughness^2 with roughness clamped to [0, 1] (NaN -> 0).
template <class T> IBL_FUNC constexpr T alpha_from_roughness(T roughness) noexcept {
    const T r = saturate(roughness);
    return r * r;
}

/// alpha clamped to [ggx_min_alpha_v<T>, 1] (NaN -> the minimum).
template <class T> IBL_FUNC constexpr T clamp_alpha(T alpha) noexcept {
    return clamp(alpha, ggx_min_alpha_v<T>, T(1));
}

/// GGX normal distribution D(h) from n.h = cos(theta_h) in [-1, 1] and alpha; 0 for n.h < 0
/// and for NaN, alpha^2 / pi at n.h = 0 (the continuous limit).
/// Measure: per unit solid angle of h; integral of D (n.h) over the hemisphere = 1.
template <class T> IBL_FUNC T ndf_ggx(T n_dot_h, T alpha) noexcept {
    const T a2 = sqr(clamp_alpha(alpha));
    const T c = saturate(n_dot_h);
    const T sin2 = (T(1) - c) * (T(1) + c);
    const T d = sin2 + a2 * c * c;
    // d >= a2 c^2 + (1 - c^2) >= a2 > 0 for every c in [0, 1].
    return n_dot_h >= T(0) ? a2 / (pi_v<T> * d * d) : T(0);
}

/// GGX D(h) from a unit half vector in tangent space (z = normal). sin^2 = x^2 + y^2 is
/// accurate for directions within float resolution of the normal, where n.h rounds to 1.
template <class T> IBL_FUNC T ndf_ggx(const vec3<T>& h, T alpha) noexcept {
    const T a2 = sqr(clamp_alpha(alpha));
    const T c2 = h.z * h.z;
    const T d = (h.x * h.x + h.y * h.y) + a2 * c2;
    return h.z >= T(0) && d > T(0) ? a2 / (pi_v<T> * d * d) : T(0);
}

/// The root shared by the GGX Smith terms (Lambda, G1, the height-correlated V):
///   s(mu) = sqrt(mu^2 + alpha^2 (1 - mu^2)) = mu sqrt(1 + alpha^2 tan^2(theta)),  mu = n.w in [0, 1].
/// Written as a sum of two non-negative terms: no cancellation anywhere, s(1) = 1 exactly (the
/// second term is exactly 0) and s(0) = sqrt(alpha2). The textbook mu^2 (1 - alpha^2) + alpha^2
/// rounds 1 - alpha^2 first, so its s(1) is 1 only up to rounding, and sqrt(1 + a^2 tan^2) needs
/// tan, infinite at mu = 0. s(mu) >= max(mu, alpha) for alpha <= 1.
/// Takes alpha2 = alpha^2 (already clamped) and mu already in [0, 1].
template <class T> IBL_FUNC T ggx_smith_root(T mu, T alpha2) noexcept {
    return safe_sqrt(mu * mu + alpha2 * (T(1) - mu) * (T(1) + mu));
}

/// Smith G1 for GGX from mu = n.w in [0, 1] (clamped). G1(0) = 0, G1(1) = 1.
template <class T> IBL_FUNC T g1_smith_ggx(T n_dot_w, T alpha) noexcept {
    const T mu = saturate(n_dot_w);
    const T s = ggx_smith_root(mu, sqr(clamp_alpha(alpha)));
    return T(2) * mu / (mu + s); // mu + s >= alpha > 0
}

/// Smith Lambda for GGX from mu = n.w in (0, 1]. Lambda(mu) ~ alpha / (2 mu) as mu -> 0; at
/// mu = 0 it is +infinity in exact arithmetic and the largest finite T is returned.
template <class T> IBL_FUNC T lambda_ggx(T n_dot_w, T alpha) noexcept {
    const T a2 = sqr(clamp_alpha(alpha));
    const T mu = saturate(n_dot_w);
    const T s = ggx_smith_root(mu, a2);
    // Lambda = (s - mu) / (2 mu) = a2 (1 - mu^2) / (2 mu (s + mu)): no cancellation for small alpha.
    const T num = a2 * (T(1) - mu) * (T(1) + mu);
    const T den = T(2) * mu * (s + mu);
    return den > T(0) ? num / den : std::numeric_limits<T>::max();
}

/// Below this alpha the GGX lobe is narrower than the angular resolution of a unit vector of T
/// near the normal (the smallest angle whose cosine differs from 1 is about sqrt(eps(T)):
/// 2^-12 for float, 2^-26 for double), so D cannot be resolved by directions stored in T.
template <class T> inline constexpr T ggx_smooth_alpha_v = T(0x1p-12);
template <> inline constexpr double ggx_smooth_alpha_v<double> = 0x1p-26;

/// True when alpha < ggx_smooth_alpha_v<T>: integrators may treat the lobe as a mirror (h = n).
template <class T> IBL_FUNC bool ggx_effectively_smooth(T alpha) noexcept {
    return alpha < ggx_smooth_alpha_v<T>;
}

} // namespace ibl

#endif // IBL_DETAIL_CXX20
