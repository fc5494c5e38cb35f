#pragma once
// ibl/brdf/masking.hpp — Smith masking-shadowing for GGX: the Schlick-GGX approximation with its
// two k policies, and the exact height-correlated form, each also as a visibility term
//   V = G2 / (4 n.v n.l),   so that the microfacet specular BRDF is  f = D V F.
//
// Schlick-GGX (Schlick 1994, adapted to GGX by Karis 2013, "Real Shading in UE4"):
//   G1(mu) = mu / (mu (1 - k) + k) = mu / (mu + k (1 - mu))      (second form: exactly 1 at mu = 1,
//                                                                 never above 1, no cancellation)
//   G(v, l) = G1(n.v) G1(n.l)                                     (separable)
//   V       = G / (4 n.v n.l) = 1 / (4 (n.v + k (1 - n.v)) (n.l + k (1 - n.l)))
//             (the factors mu cancel algebraically: finite at n.v = 0 and n.l = 0, no epsilon)
//   k policies (perceptual roughness r):
//     k_ibl(r)    = r^2 / 2 = alpha / 2      for image-based lighting (Karis 2013; LearnOpenGL)
//     k_direct(r) = (r + 1)^2 / 8            for analytic lights ("Disney remapping", Karis 2013)
//
// Height-correlated Smith for GGX (Heitz 2014, "Understanding the Masking-Shadowing Function in
// Microfacet-Based BRDFs", eq. 99; Filament's V_SmithGGXCorrelated):
//   G2 = 1 / (1 + Lambda(n.v) + Lambda(n.l))
//   With Lambda(mu) = (s(mu)/mu - 1)/2 and s(mu) = sqrt(mu^2 + alpha^2 (1 - mu^2)) (ggx_smith_root):
//   1 + Lambda(v) + Lambda(l) = (n.l s(n.v) + n.v s(n.l)) / (2 n.v n.l), hence
//   G2 = 2 n.v n.l / (n.l s(n.v) + n.v s(n.l)),   V = 0.5 / (n.l s(n.v) + n.v s(n.l)).
//   The denominator is >= alpha (n.v + n.l) > 0 except at the corner n.v = n.l = 0.
//
// Domain clamps (the stability contract): cosines are clamped to [0, 1] (NaN -> 0); roughness to
// [0, 1] (NaN -> 0); alpha to [ggx_min_alpha_v, 1] (clamp_alpha); k to [schlick_min_k_v, 1].

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include "../core/constants.hpp"
#include "../core/math.hpp"
#include "ggx.hpp"

namespace ibl {

// ---- k policies -------------------------------------------------------------------------------

/// Smallest Schlick k used: k_ibl of the smallest GGX alpha (ggx_min_alpha_v / 2; 2^-32 in float).
/// Reason: at k = 0 (roughness 0) G1 = mu/mu is 0/0 at mu = 0; with k >= this the denominators
/// mu + k (1 - mu) are >= k > 0 and the largest V, 1/(4 k^2) (2^62 in float), is finite.
template <class T> inline constexpr T schlick_min_k_v = ggx_min_alpha_v<T> / T(2);

/// k for image-based lighting: k = r^2 / 2 (= alpha / 2), r clamped to [0, 1] (NaN -> 0).
template <class T> IBL_FUNC constexpr T k_ibl(T roughness) noexcept {
    const T r = saturate(roughness);
    return r * r / T(2);
}

/// k for analytic (punctual) lights: k = (r + 1)^2 / 8, r clamped to [0, 1] (NaN -> 0).
template <class T> IBL_FUNC constexpr T k_direct(T roughness) noexcept {
    const T r = saturate(roughness);
    return sqr(r + T(1)) / T(8);
}

// ---- Schlick-GGX --------------------------------------------------------------------------------

/// The Schlick-GGX denominator mu + k (1 - mu) for mu in [0, 1], k in [schlick_min_k_v, 1]:
/// >= k > 0, exactly 1 at mu = 1.
template <class T> IBL_FUNC constexpr T schlick_ggx_denominator(T mu, T k) noexcept {
    return mu + k * (T(1) - mu);
}

/// Schlick-GGX G1(mu) = mu / (mu (1 - k) + k), mu = n.w. G1(0) = 0, G1(1) = 1 exactly, 0 <= G1 <= 1.
template <class T> IBL_FUNC constexpr T g1_schlick_ggx(T n_dot_w, T k) noexcept {
    const T mu = saturate(n_dot_w);
    return mu / schlick_ggx_denominator(mu, clamp(k, schlick_min_k_v<T>, T(1)));
}

/// Separable Schlick-GGX G(v, l) = G1(n.v) G1(n.l). Pass k = k_ibl(r) or k_direct(r).
/// G(1, 1) = 1 exactly; 0 when either cosine is 0.
template <class T> IBL_FUNC constexpr T g_smith_schlick_ggx(T n_dot_v, T n_dot_l, T k) noexcept {
    return g1_schlick_ggx(n_dot_v, k) * g1_schlick_ggx(n_dot_l, k);
}

/// Schlick-GGX visibility V = G / (4 n.v n.l) = 1 / (4 (n.v + k(1 - n.v)) (n.l + k(1 - n.l))),
/// with the cosines cancelled algebraically: finite on all of [0, 1]^2, largest at n.v = n.l = 0
/// where it is 1 / (4 k^2) (<= 2^62 in float at the smallest k). V(1, 1) = 1/4 exactly.
template <class T> IBL_FUNC constexpr T v_smith_schlick_ggx(T n_dot_v, T n_dot_l, T k) noexcept {
    const T kc = clamp(k, schlick_min_k_v<T>, T(1));
    const T dv = schlick_ggx_denominator(saturate(n_dot_v), kc);
    const T dl = schlick_ggx_denominator(saturate(n_dot_l), kc);
    return T(1) / (T(4) * dv * dl);
}

// ---- height-correlated Smith GGX -------------------------------------------------------------

/// The height-correlated denominator n.l s(n.v) + n.v s(n.l) (see the header comment), floored at
/// min_normal_v<T>. Reason for the floor: it vanishes only at the exact corner n.v = n.l = 0, where
/// V is infinite in exact arithmetic; the floor keeps V finite (at most 0.5 / FLT_MIN = 2^125 in
/// float) so that products with the vanishing cosines give 0 instead of NaN. It changes no value
/// whose exact V is below 2^125 (float) / 2^1021 (double).
template <class T> IBL_FUNC T smith_ggx_correlated_denominator(T n_dot_v, T n_dot_l, T alpha) noexcept {
    const T a2 = sqr(clamp_alpha(alpha));
    const T mu_v = saturate(n_dot_v);
    const T mu_l = saturate(n_dot_l);
    const T den = mu_l * ggx_smith_root(mu_v, a2) + mu_v * ggx_smith_root(mu_l, a2);
    return den > min_normal_v<T> ? den : min_normal_v<T>;
}

/// Height-correlated Smith G2 for GGX = 1 / (1 + Lambda(n.v) + Lambda(n.l))
///   = 2 n.v n.l / (n.l s(n.v) + n.v s(n.l)).
/// G2(1, 1) = 1 exactly; 0 when either cosine is 0 (including the corner, via the floor).
template <class T> IBL_FUNC T g2_smith_ggx_correlated(T n_dot_v, T n_dot_l, T alpha) noexcept {
    const T mu_v = saturate(n_dot_v);
    const T mu_l = saturate(n_dot_l);
    return T(2) * mu_v * mu_l / smith_ggx_correlated_denominator(mu_v, mu_l, alpha);
}

/// Height-correlated Smith visibility for GGX, V = G2 / (4 n.v n.l)
///   = 0.5 / (n.l sqrt(n.v^2 + a^2 (1 - n.v^2)) + n.v sqrt(n.l^2 + a^2 (1 - n.l^2))),  a = alpha.
/// Finite everywhere: V(1, 1) = 1/4; V(0, l) = 0.5 / (alpha n.l) for n.l > 0 (the exact limit);
/// at the corner n.v = n.l = 0 it returns 0.5 / min_normal_v<T> (2^125 in float, 2^1021 in
/// double), so V * n.l and V * n.v are exactly 0 there.
template <class T> IBL_FUNC T v_smith_ggx_correlated(T n_dot_v, T n_dot_l, T alpha) noexcept {
    return T(0.5) / smith_ggx_correlated_denominator(n_dot_v, n_dot_l, alpha);
}

} // namespace ibl

#endif // IBL_DETAIL_CXX20
