#pragma once
// ibl/brdf/fresnel.hpp — Schlick's Fresnel approximation and the ways to obtain F0.
//
//   F(cos) = F0 + (F90 - F0) (1 - cos)^5                       [Schlick 1994, eq. 24]
//   evaluated as the interpolation (1 - w) F0 + w F90 with w = (1 - cos)^5, which is exact at both
//   ends: F(1) = F0 and F(0) = F90 bit for bit. (F0 + (F90 - F0) w rounds F90 - F0 first and misses
//   F90 by an ulp in about 10% of random float pairs.) Between the ends F is monotone in cos up to
//   the rounding of the two products (relative 2 eps).
//
//   Roughness-aware Schlick for the ambient (split-sum) term, after S. Lagarde's
//   "Adopting a physically based shading model" (2011) / LearnOpenGL's fresnelSchlickRoughness:
//   F(cos, r) = F0 + (max(1 - r, F0) - F0) (1 - cos)^5, i.e. Schlick with F90 = max(1 - r, F0)
//   componentwise: at r = 0 it is fresnel_schlick with F90 = 1, at r = 1 it is F0 for every cos.
//
//   F0 of a dielectric from its index of refraction at normal incidence (Fresnel equations):
//   F0 = ((n_t - n_i) / (n_t + n_i))^2, with n_i = 1 (vacuum/air) by default; 1.5 gives 0.04.
//   Metallic workflow (glTF 2.0, Burley 2012): F0 = mix(0.04, base_color, metallic).
//
// Domain clamps: cos_theta to [0, 1] (NaN -> 0, i.e. F90); roughness and metallic to [0, 1]
// (NaN -> 0); IORs to [0, ior_max_v] (NaN -> 0). F0, F90 and colours are used as given (the results
// are affine in them, so finite inputs give finite results).

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <limits>

#include "../core/math.hpp"
#include "../core/vec.hpp"

namespace ibl {

/// F0 of a typical dielectric (IOR 1.5 against air): the metallic workflow's non-metal F0.
template <class T> inline constexpr T dielectric_f0_v = T(0.04);

/// Largest index of refraction accepted by f0_from_ior (a quarter of the largest finite T).
/// Reason: n_t + n_i must not overflow; beyond it F0 rounds to 1 anyway.
template <class T> inline constexpr T ior_max_v = std::numeric_limits<T>::max() / T(4);

/// Schlick's weight w = (1 - cos)^5 with cos clamped to [0, 1]: w(1) = 0, w(0) = 1 exactly.
template <class T> IBL_FUNC constexpr T schlick_weight(T cos_theta) noexcept {
    return pow5(T(1) - saturate(cos_theta));
}

/// Scalar Schlick Fresnel F = F0 + (F90 - F0)(1 - cos)^5; F(1) = F0, F(0) = F90 exactly.
template <class T> IBL_FUNC constexpr T fresnel_schlick(T cos_theta, T f0, T f90 = T(1)) noexcept {
    return lerp(f0, f90, schlick_weight(cos_theta));
}

/// RGB Schlick Fresnel F = F0 + (F90 - F0)(1 - cos)^5 per channel; F(1) = F0, F(0) = F90 exactly.
template <class T>
IBL_FUNC vec3<T> fresnel_schlick(T cos_theta, const vec3<T>& f0, const vec3<T>& f90 = vec3<T>(T(1))) noexcept {
    const T w = schlick_weight(cos_theta);
    return {lerp(f0.x, f90.x, w), lerp(f0.y, f90.y, w), lerp(f0.z, f90.z, w)};
}

/// The roughness-aware F90 = max(1 - r, F0) (one channel), r clamped to [0, 1].
template <class T> IBL_FUNC constexpr T f90_from_roughness(T f0, T roughness) noexcept {
    const T g = T(1) - saturate(roughness);
    return f0 > g ? f0 : g;
}

/// Scalar roughness-aware Schlick: F0 + (max(1 - r, F0) - F0)(1 - cos)^5.
template <class T> IBL_FUNC constexpr T fresnel_schlick_roughness(T cos_theta, T f0, T roughness) noexcept {
    return fresnel_schlick(cos_theta, f0, f90_from_roughness(f0, roughness));
}

/// RGB roughness-aware Schlick: F0 + (max(1 - r, F0) - F0)(1 - cos)^5, max taken per channel.
/// Equals fresnel_schlick(cos, f0) (F90 = 1) bit for bit at r = 0 when F0 <= 1; equals F0 at r = 1.
template <class T>
IBL_FUNC vec3<T> fresnel_schlick_roughness(T cos_theta, const vec3<T>& f0, T roughness) noexcept {
    const vec3<T> f90(f90_from_roughness(f0.x, roughness), f90_from_roughness(f0.y, roughness),
                      f90_from_roughness(f0.z, roughness));
    return fresnel_schlick(cos_theta, f0, f90);
}

/// Normal-incidence reflectance between media of indices n_t (the surface) and n_i (outside):
/// F0 = ((n_t - n_i) / (n_t + n_i))^2. IORs clamped to [0, ior_max_v] (NaN -> 0); 0 when both are 0.
template <class T> IBL_FUNC constexpr T f0_from_ior(T ior, T ior_outside) noexcept {
    const T nt = clamp(ior, T(0), ior_max_v<T>);
    const T ni = clamp(ior_outside, T(0), ior_max_v<T>);
    const T sum = nt + ni;
    return sum > T(0) ? sqr((nt - ni) / sum) : T(0);
}

/// Normal-incidence reflectance of a dielectric of index n against vacuum: ((n - 1) / (n + 1))^2.
/// f0_from_ior(1.5) = 0.04; f0_from_ior(1) = 0.
template <class T> IBL_FUNC constexpr T f0_from_ior(T ior) noexcept { return f0_from_ior(ior, T(1)); }

/// Metallic workflow F0 = mix(dielectric_f0, base_color, metallic), metallic clamped to [0, 1]:
/// exactly dielectric_f0 at metallic = 0 and exactly base_color at metallic = 1.
template <class T>
IBL_FUNC vec3<T> f0_from_metallic(const vec3<T>& base_color, T metallic, T dielectric_f0 = dielectric_f0_v<T>) noexcept {
    const T m = saturate(metallic);
    return {lerp(dielectric_f0, base_color.x, m), lerp(dielectric_f0, base_color.y, m),
            lerp(dielectric_f0, base_color.z, m)};
}

/// Metallic workflow diffuse albedo = base_color (1 - metallic) (metals have no diffuse lobe).
template <class T> IBL_FUNC vec3<T> diffuse_from_metallic(const vec3<T>& base_color, T metallic) noexcept {
    return base_color * (T(1) - saturate(metallic));
}

} // namespace ibl

#endif // IBL_DETAIL_CXX20
