#pragma once
// ibl/brdf/blinn_phong.hpp — the normalised Blinn-Phong microfacet distribution, for comparison
// with GGX as in the literature (Walter et al. 2007, sec. 5.2; Karis's "Specular BRDF Reference").
//
//   D(h) = (e + 2) / (2 pi) (n.h)^e                 exponent e >= 0
//   Normalisation: integral over the hemisphere of D(h) (n.h) d(omega_h)
//                  = (e + 2) / (2 pi) * 2 pi / (e + 2) = 1.
//   Alpha mapping (Walter et al. 2007, eq. 31): e = 2 / alpha^2 - 2, alpha = sqrt(2 / (e + 2)).
//   With it the peak D(n) = (e + 2) / (2 pi) = 1 / (pi alpha^2) equals GGX's and Beckmann's, and
//   the lobes agree near the normal (D ~ exp(-tan^2 / alpha^2) / (pi alpha^2) for small alpha).
//
// Clamps: alpha as GGX (clamp_alpha: [ggx_min_alpha_v, 1], so e <= 2^63 in float, 2^511 in double
// and the peak stays finite); exponent to [0, blinn_phong_max_exponent_v] (NaN -> 0); n.h to [0, 1]
// with D = 0 for n.h < 0, as ndf_ggx.

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <cmath>

#include "../core/constants.hpp"
#include "../core/math.hpp"
#include "../core/vec.hpp"
#include "ggx.hpp"

namespace ibl {

/// Blinn-Phong exponent from alpha: e = 2 / alpha^2 - 2, computed as 2 (1 - alpha)(1 + alpha) / alpha^2
/// (exactly 0 at alpha = 1). alpha clamped by clamp_alpha.
template <class T> IBL_FUNC constexpr T blinn_phong_exponent_from_alpha(T alpha) noexcept {
    const T a = clamp_alpha(alpha);
    return T(-2) * sqr_minus_one(a) / (a * a);
}

/// The exponent of the smallest alpha (2^63 in float): the upper clamp of exponents.
/// Reason: keeps (e + 2) / (2 pi) finite and matches the GGX alpha clamp.
template <class T> inline constexpr T blinn_phong_max_exponent_v = blinn_phong_exponent_from_alpha(ggx_min_alpha_v<T>);

/// alpha from a Blinn-Phong exponent: sqrt(2 / (e + 2)), e clamped to [0, blinn_phong_max_exponent_v].
template <class T> IBL_FUNC T alpha_from_blinn_phong_exponent(T exponent) noexcept {
    using std::sqrt;
    return sqrt(T(2) / (clamp(exponent, T(0), blinn_phong_max_exponent_v<T>) + T(2)));
}

/// Normalised Blinn-Phong D(h) = (e + 2)/(2 pi) (n.h)^e from n.h and the exponent e.
/// Measure: per unit solid angle of h; integral of D (n.h) over the hemisphere = 1.
/// 0 for n.h < 0 and NaN; at e = 0 it is 1/pi everywhere on the hemisphere (pow(0, 0) = 1).
template <class T> IBL_FUNC T ndf_blinn_phong_exponent(T n_dot_h, T exponent) noexcept {
    using std::pow;
    const T e = clamp(exponent, T(0), blinn_phong_max_exponent_v<T>);
    return n_dot_h >= T(0) ? (e + T(2)) * inv_two_pi_v<T> * pow(saturate(n_dot_h), e) : T(0);
}

/// Normalised Blinn-Phong D(h) from n.h and alpha (e = 2 / alpha^2 - 2): the same signature as
/// ndf_ggx, so the two are interchangeable in a BRDF model.
template <class T> IBL_FUNC T ndf_blinn_phong(T n_dot_h, T alpha) noexcept {
    return ndf_blinn_phong_exponent(n_dot_h, blinn_phong_exponent_from_alpha(alpha));
}

/// Normalised Blinn-Phong D(h) from a unit half vector in tangent space (z = normal) and alpha.
/// (n.h)^e = exp(e/2 log(1 - sin^2)) with sin^2 = x^2 + y^2 and log1p: accurate for half vectors
/// within float resolution of the normal, where n.h rounds to 1 and pow(n.h, e) cannot resolve
/// the lobe (the relative error of the n.h form is about e eps / 2 = eps / alpha^2).
template <class T> IBL_FUNC T ndf_blinn_phong(const vec3<T>& h, T alpha) noexcept {
    using std::exp;
    using std::log1p;
    const T e = blinn_phong_exponent_from_alpha(alpha);
    const T sin2 = saturate(h.x * h.x + h.y * h.y);
    // e = 0 (alpha = 1): constant lobe; skipping the log avoids 0 * log(0) = NaN at sin2 = 1.
    const T cos_pow = e > T(0) ? exp(T(0.5) * e * log1p(-sin2)) : T(1);
    return h.z >= T(0) ? (e + T(2)) * inv_two_pi_v<T> * cos_pow : T(0);
}

} // namespace ibl

#endif // IBL_DETAIL_CXX20
