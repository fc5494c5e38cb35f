#pragma once
// ibl/brdf/model.hpp — the BRDF *model* concept that the split-sum integrators are templated on,
// and the two GGX models the library ships.
//
// A model is the specular microfacet lobe  f(v, l) = D(h) V(v, l) F(v.h)  without its Fresnel
// factor: an NDF, a visibility term and the roughness -> alpha map. It is a type with static member
// functions (templates over the scalar T, or overloads per T), so a model costs nothing at run time
// and works in CUDA device code. The contract, for T in {float, double}; r is perceptual roughness,
// all cosines are of unit vectors about the normal n, and every function must be finite for
// r in [0, 1] and cosines in [0, 1] (the library's stability sweep, tests/test_stability_brdf.cpp,
// shows how to check a model):
//
//   M::alpha(T roughness) -> T
//       The NDF parameter for roughness r, as passed to M::ndf and to the GGX half-vector sampler.
//       Need not be clamped (ndf and the sampler clamp alpha); both shipped models return r^2.
//   M::ndf(T n_dot_h, T alpha) -> T
//       D(h) per unit solid angle of h, normalised so that the integral over the hemisphere of
//       D(h) (n.h) d(omega_h) = 1; 0 for n.h < 0.
//   M::visibility(T n_dot_v, T n_dot_l, T roughness) -> T
//       V = G2 / (4 n.v n.l), so that f = D V F (per steradian of l). Finite on all of [0, 1]^2,
//       also at n.v = 0 and n.l = 0 (write it with the cosines cancelled, as the Smith forms in
//       masking.hpp; at the corner n.v = n.l = 0 return a finite value so V * n.l = 0 there).
//   M::sample_weight(T n_dot_v, T n_dot_l, T n_dot_h, T v_dot_h, T roughness) -> T
//       The split-sum integrand weight of one direction l = reflect(-v, h) whose half vector h was
//       drawn from the GGX NDF with alpha = M::alpha(r), i.e. with pdf_h = D_ggx(h) (n.h) per unit
//       solid angle of h and pdf_l = pdf_h / (4 v.h) per unit solid angle of l; Fresnel excluded:
//           weight = f(v, l) (n.l) / pdf_l / F.
//       For a model whose NDF is GGX, D cancels: weight = 4 V (n.l) (v.h) / (n.h)
//       (= G (v.h) / ((n.h) (n.v)) for a separable G); use weight_ggx_sampled below. A model with
//       another NDF D_M (Beckmann, Blinn-Phong) sampled by the same GGX sampler multiplies by
//       D_M / D_ggx. Must return 0 when n.l <= 0 (below the horizon; no NaN from V there) and be
//       finite for every n.h > 0 (the sampler never draws n.h <= 0; the shipped models return 0).
//       The Monte Carlo estimate of the directional albedo int f n.l d(omega_l) with F = 1 is the
//       mean of this weight; the split-sum DFG terms are its means with factors (1 - Fc), Fc,
//       Fc = (1 - v.h)^5.
//
// Optionally, a model has `static constexpr const char* name` (used in reports).
//
// Writing a model: copy ggx_height_correlated, change ndf / visibility / sample_weight, and
// static_assert(ibl::brdf_model<my_model, float> && ibl::brdf_model<my_model, double>).

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <concepts>

#include "../core/math.hpp"
#include "ggx.hpp"
#include "masking.hpp"

namespace ibl {

/// The BRDF-model concept (see the contract above). Each member must return exactly T when called
/// with arguments of type T, so that float and double code never mix silently.
template <class M, class T>
concept brdf_model = std::floating_point<T> && requires(T x) {
    { M::alpha(x) } -> std::same_as<T>;
    { M::ndf(x, x) } -> std::same_as<T>;
    { M::visibility(x, x, x) } -> std::same_as<T>;
    { M::sample_weight(x, x, x, x, x) } -> std::same_as<T>;
};

/// Split-sum weight of a GGX-NDF-sampled direction for a model with a GGX NDF, Fresnel excluded:
/// 4 V (n.l) (v.h) / (n.h), from the model's visibility V. Returns 0 when n.l <= 0 or n.h <= 0
/// (pdf 0; never drawn) or for NaN; v.h is clamped to [0, 1]. (V n.l) is formed first, so the
/// corner value of V (finite, large) meets n.l = 0 and gives 0.
template <class T> IBL_FUNC T weight_ggx_sampled(T visibility, T n_dot_l, T n_dot_h, T v_dot_h) noexcept {
    const bool valid = n_dot_l > T(0) && n_dot_h > T(0);
    return valid ? T(4) * (visibility * n_dot_l) * saturate(v_dot_h) / n_dot_h : T(0);
}

/// GGX NDF + separable Schlick-GGX masking with k = k_ibl(r) = r^2 / 2: the convention of Karis
/// 2013 ("Real Shading in Unreal Engine 4") and LearnOpenGL's split-sum BRDF LUT.
struct ggx_schlick_ibl {
    static constexpr const char* name = "ggx_schlick_ibl";

    /// alpha = r^2, r clamped to [0, 1] (NaN -> 0).
    template <class T> IBL_FUNC static T alpha(T roughness) noexcept { return alpha_from_roughness(roughness); }
    /// GGX D(h) (ndf_ggx).
    template <class T> IBL_FUNC static T ndf(T n_dot_h, T alpha) noexcept { return ndf_ggx(n_dot_h, alpha); }
    /// V = G / (4 n.v n.l) with G = Schlick-GGX, k = r^2 / 2 (v_smith_schlick_ggx); at most
    /// 1 / (4 k^2) at the corner, 1/4 at n.v = n.l = 1.
    template <class T> IBL_FUNC static T visibility(T n_dot_v, T n_dot_l, T roughness) noexcept {
        return v_smith_schlick_ggx(n_dot_v, n_dot_l, k_ibl(roughness));
    }
    /// 4 V (n.l) (v.h) / (n.h) = G (v.h) / ((n.h) (n.v)); 0 when n.l <= 0 or n.h <= 0.
    template <class T>
    IBL_FUNC static T sample_weight(T n_dot_v, T n_dot_l, T n_dot_h, T v_dot_h, T roughness) noexcept {
        return weight_ggx_sampled(visibility(n_dot_v, n_dot_l, roughness), n_dot_l, n_dot_h, v_dot_h);
    }
};

/// GGX NDF + height-correlated Smith GGX masking (Heitz 2014): Filament's convention
/// (V_SmithGGXCorrelated), and the exact single-scattering GGX microfacet model.
struct ggx_height_correlated {
    static constexpr const char* name = "ggx_height_correlated";

    /// alpha = r^2, r clamped to [0, 1] (NaN -> 0).
    template <class T> IBL_FUNC static T alpha(T roughness) noexcept { return alpha_from_roughness(roughness); }
    /// GGX D(h) (ndf_ggx).
    template <class T> IBL_FUNC static T ndf(T n_dot_h, T alpha) noexcept { return ndf_ggx(n_dot_h, alpha); }
    /// V = G2 / (4 n.v n.l), height-correlated (v_smith_ggx_correlated): 1/4 at n.v = n.l = 1,
    /// 0.5 / min_normal_v<T> at the corner n.v = n.l = 0.
    template <class T> IBL_FUNC static T visibility(T n_dot_v, T n_dot_l, T roughness) noexcept {
        return v_smith_ggx_correlated(n_dot_v, n_dot_l, alpha_from_roughness(roughness));
    }
    /// 4 V (n.l) (v.h) / (n.h); 0 when n.l <= 0 or n.h <= 0.
    template <class T>
    IBL_FUNC static T sample_weight(T n_dot_v, T n_dot_l, T n_dot_h, T v_dot_h, T roughness) noexcept {
        return weight_ggx_sampled(visibility(n_dot_v, n_dot_l, roughness), n_dot_l, n_dot_h, v_dot_h);
    }
};

static_assert(brdf_model<ggx_schlick_ibl, float> && brdf_model<ggx_schlick_ibl, double>);
static_assert(brdf_model<ggx_height_correlated, float> && brdf_model<ggx_height_correlated, double>);

} // namespace ibl

#endif // IBL_DETAIL_CXX20
