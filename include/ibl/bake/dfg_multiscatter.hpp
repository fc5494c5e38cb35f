#pragma once
// ibl/bake/dfg_multiscatter.hpp — the directional albedo E(mu, r) of a microfacet model and
// the multiple-scattering energy compensation built on it (the optional third DFG LUT channel).
//
// Single scattering loses energy at high roughness: the albedo for F = 1,
//   E(mu, r) = int D V (n.l) d(omega_l) = A + B      (the DFG terms with F0 = F90 = 1),
// is below 1 and decreases with r. Two published compensations use E:
//
//  * C. Turquin, "Practical multiple scattering compensation for microfacet models", 2019:
//      f_ms = f_ss (1 + F0 (1 - E) / E).
//    With F = 1 the compensated albedo is E (1 + (1 - E)/E) = 1 (the white furnace). The third
//    channel of the DFG LUT holds exactly  k(mu, r) = (1 - E) / E = 1/E - 1  (>= 0), computed from
//    the quadrature's E in double before rounding to float. A shader does
//        vec3 dfg = texture(lut, vec2(NoV, roughness)).rgb;          // A, B, k
//        vec3 spec = prefiltered * (F0 * dfg.x + F90 * dfg.y) * (1.0 + F0 * dfg.z);
//    (specular_dfg_turquin below). Filament's "energyCompensation = 1 + f0 (1/dfg.y - 1)" is the
//    same factor, with E read from its second channel.
//
//  * C. Fdez-Aguera, "A Multiple-Scattering Microfacet Model for Real-Time Image-based
//    Lighting", JCGT 8(1), 2019: from A and B alone (F90 = 1),
//      FssEss = F0 A + B;  Ess = A + B;  Ems = 1 - Ess;  Favg = F0 + (1 - F0) / 21;
//      Fms = FssEss Favg / (1 - Ems Favg);  specular = FssEss + Fms Ems
//    (specular_dfg_fdez_aguera). With F0 = 1 it is Ess + 1 - Ess = 1. It needs no third channel.

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include "../core/math.hpp"
#include "../core/vec.hpp"
#include "dfg.hpp"

namespace ibl {

/// Directional albedo E(mu, r) = A + B of model M by quadrature (double inside).
template <class Model, class T> T dfg_albedo(T n_dot_v, T roughness) {
    return dfg_exact_abe<Model>(n_dot_v, roughness, default_dfg_quadrature_rule()).z;
}

/// Turquin's compensation k = (1 - E) / E (the third LUT channel). E is clamped to
/// [min_normal, 1] so k is finite and >= 0 (E > 0.4 for both shipped models on [0, 1]^2).
template <class T> IBL_FUNC T dfg_energy_compensation(T albedo) noexcept {
    const T e = clamp(albedo, min_normal_v<T>, T(1));
    return (T(1) - e) / e;
}

/// Split-sum specular factor without compensation: F0 A + F90 B.
template <class T> IBL_FUNC vec3<T> specular_dfg(const vec2<T>& ab, const vec3<T>& f0, T f90 = T(1)) noexcept {
    return f0 * ab.x + vec3<T>(f90 * ab.y);
}

/// Turquin 2019 through the LUT: (F0 A + F90 B) (1 + F0 k), k = the third channel.
template <class T>
IBL_FUNC vec3<T> specular_dfg_turquin(const vec3<T>& abk, const vec3<T>& f0, T f90 = T(1)) noexcept {
    return specular_dfg(vec2<T>(abk.x, abk.y), f0, f90) * (vec3<T>(T(1)) + f0 * abk.z);
}

/// Fdez-Aguera 2019 (F90 = 1): FssEss + Fms Ems from A, B and F0 (see the header comment).
template <class T> IBL_FUNC vec3<T> specular_dfg_fdez_aguera(const vec2<T>& ab, const vec3<T>& f0) noexcept {
    const vec3<T> fss_ess = f0 * ab.x + vec3<T>(ab.y);
    const T ess = ab.x + ab.y;
    const T ems = T(1) - ess;
    const vec3<T> favg = f0 + (vec3<T>(T(1)) - f0) * (T(1) / T(21));
    const vec3<T> fms = fss_ess * favg / (vec3<T>(T(1)) - ems * favg);
    return fss_ess + fms * ems;
}

} // namespace ibl

#endif // IBL_DETAIL_CXX20
