#pragma once
// ibl/brdf/charlie.hpp — the sheen lobe: the "Charlie" distribution of A. Estevez, C. Kulla,
// "Production Friendly Microfacet Sheen BRDF" (SIGGRAPH 2017 course), with the visibility term of
// D. Neubelt, M. Pettineo, "Crafting a Next-Gen Material Pipeline for The Order: 1886" (2013).
//
// Parameter: alpha = r^2 (r = perceptual sheen roughness in [0, 1]), as for GGX.
//   D(h) = (2 + 1/alpha) sin(theta_h)^(1/alpha) / (2 pi)                        [Estevez-Kulla eq. 2]
//   Normalisation: integral over the hemisphere of D(h) (n.h) d(omega_h) = 1, since with
//   s = sin(theta_h), k = 2 + 1/alpha:  2 pi int_0^{pi/2} D s cos d(theta) = k int_0^1 s^(k - 1) ds = 1.
//   The CDF of s under D (n.h) d(omega_h) is s^k, so s = u^(1/k) samples it in closed form
//   (sampling/charlie.hpp).
//   sin^(1/alpha) is evaluated as exp(log(sin^2) / (2 alpha)) with sin^2 from whichever of
//   1 - cos^2 (log1p(-cos^2), accurate near the peak sin -> 1) or h.x^2 + h.y^2 (accurate near
//   the normal) is exact: no cancellation near either end.
//
//   V(v, l) = 1 / (4 (n.l + n.v - n.l n.v))                            [Neubelt-Pettineo 2013]
//   written as 1 / (4 (n.l + n.v (1 - n.l))): a sum of non-negative terms (no cancellation). It is
//   not derived from a masking function, so the sheen albedo it gives is not bounded by 1 near
//   grazing view (bake/sheen.hpp).
//
// Limits (the stability contract).
//   r -> 0: the lobe concentrates on the great circle theta_h = pi/2 (its peak value
//     (2 + 1/alpha)/(2 pi) grows without bound and D -> 0 for every n.h > 0). alpha is clamped to
//     [charlie_min_alpha_v<T>, 1] (2^-31 in float, 2^-255 in double, as ggx_min_alpha_v): 1/alpha
//     and the peak (<= 3.5e8 in float) stay finite and exp(log(s^2) / (2 alpha)) underflows to 0
//     instead of producing 0 * inf. So D is finite for every input, 0 for n.h = 1 (s = 0) and for
//     n.h < 0, and equal to the peak at n.h = 0.
//   r = 1: D = 3 sin(theta_h) / (2 pi).
//   V: finite on [0, 1]^2 except at the corner. V(1, 1) = 1/4; V >= 1/4 everywhere;
//     V(0, l) = 1 / (4 n.l) and V(v, 0) = 1 / (4 n.v) (the exact limits); V n.l <= 1/4 and
//     V n.l = 1/4 at n.v = 0 (n.l > 0). At the corner n.v = n.l = 0 the denominator is floored at
//     min_normal_v<T>: V = 1 / (4 min_normal_v) (2^124 in float, 2^1020 in double), so V n.l and
//     V n.v are 0 there.
//   Cosines are clamped to [0, 1] (NaN -> 0); roughness to [0, 1] (NaN -> 0).

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <cmath>

#include "../core/constants.hpp"
#include "../core/math.hpp"
#include "../core/vec.hpp"
#include "ggx.hpp"

namespace ibl {

/// Smallest Charlie alpha (reason: header comment): the GGX minimum, 2^-31 (float), 2^-255 (double).
template <class T> inline constexpr T charlie_min_alpha_v = ggx_min_alpha_v<T>;

/// alpha clamped to [charlie_min_alpha_v<T>, 1] (NaN -> the minimum).
template <class T> IBL_FUNC constexpr T charlie_clamp_alpha(T alpha) noexcept {
    return clamp(alpha, charlie_min_alpha_v<T>, T(1));
}

/// The Charlie exponent k = 2 + 1/alpha (alpha clamped): D's normaliser is k / (2 pi) and the CDF
/// of sin(theta_h) is sin^k.
template <class T> IBL_FUNC T charlie_exponent(T alpha) noexcept { return T(2) + T(1) / charlie_clamp_alpha(alpha); }

namespace detail {
/// log(sin^2(theta)) from cos^2 and the tangential part x^2 + y^2 (whichever form is exact).
template <class T> IBL_FUNC T charlie_log_sin2(T cos2, T sin2) noexcept {
    using std::log;
    using std::log1p;
    return cos2 < T(0.5) ? log1p(-cos2) : log(sin2);
}
/// D from log(sin^2) and alpha (clamped by the caller).
template <class T> IBL_FUNC T charlie_from_log_sin2(T log_sin2, T alpha) noexcept {
    using std::exp;
    return (T(2) + T(1) / alpha) * inv_two_pi_v<T> * exp(log_sin2 * (T(0.5) / alpha));
}
} // namespace detail

/// Charlie D(h) from n.h = cos(theta_h) in [-1, 1] and alpha: (2 + 1/alpha) sin^(1/alpha) / (2 pi);
/// 0 for n.h < 0, for n.h = 1 and for NaN. Measure: per unit solid angle of h; integral of
/// D (n.h) over the hemisphere = 1.
template <class T> IBL_FUNC T ndf_charlie(T n_dot_h, T alpha) noexcept {
    const T a = charlie_clamp_alpha(alpha);
    const T c = saturate(n_dot_h);
    const T c2 = c * c;
    return n_dot_h >= T(0) ? detail::charlie_from_log_sin2(detail::charlie_log_sin2(c2, (T(1) - c) * (T(1) + c)), a)
                           : T(0);
}

/// Charlie D(h) from a unit half vector in tangent space (z = normal); sin^2 = h.x^2 + h.y^2 near
/// the normal, 1 - h.z^2 near the horizon (the peak).
template <class T> IBL_FUNC T ndf_charlie(const vec3<T>& h, T alpha) noexcept {
    const T a = charlie_clamp_alpha(alpha);
    const T c2 = h.z * h.z;
    return h.z >= T(0) ? detail::charlie_from_log_sin2(detail::charlie_log_sin2(c2, h.x * h.x + h.y * h.y), a) : T(0);
}

/// Neubelt-Pettineo visibility V = 1 / (4 (n.l + n.v (1 - n.l))), cosines clamped to [0, 1]; the
/// denominator is floored at min_normal_v<T> (the corner; header comment).
template <class T> IBL_FUNC T v_neubelt(T n_dot_v, T n_dot_l) noexcept {
    const T v = saturate(n_dot_v);
    const T l = saturate(n_dot_l);
    const T d = l + v * (T(1) - l);
    return T(0.25) / (d > min_normal_v<T> ? d : min_normal_v<T>);
}

} // namespace ibl

#endif // IBL_DETAIL_CXX20
