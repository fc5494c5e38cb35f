#pragma once
// ibl/runtime/shade.hpp — the runtime combination of the baked products: ambient (image-based) diffuse
// and split-sum specular, with the single-scattering and the multiple-scattering variants, and
// direct Cook-Torrance lights (directional, point). Small functions, one per product, so that a
// scene pays only for what it bakes (no diffuse IBL: call only specular_ibl; no DFG LUT: no
// specular IBL), plus the convenience struct `pbr_shader` that wires them together.
//
// ---- Quantities the caller provides (state which one you hold!) -------------------------------
//   ld          prefiltered radiance LD(R, r): the specular prefilter of the environment sampled
//               at the reflection direction R = reflect(-v, n) and the roughness r (its mip).
//               A constant environment of radiance L gives LD = L at every r.
//   irradiance  E(n) = integral of L(w) max(0, n.w) dw  (W/m^2 for L in W/(m^2 sr)); a constant
//               environment L gives E = pi L. The functions taking E divide by pi.
//   irradiance_over_pi
//               E(n) / pi, the cosine-weighted mean radiance: what LearnOpenGL's irradiance map
//               and sh_shader_coeffs(..., irradiance_over_pi) hold; a constant environment L gives
//               L. The *_over_pi functions take it and do not divide.
//   dfg         the split-sum DFG LUT value at (n.v, r): dfg.x = A (scale), dfg.y = B (bias), so
//               that the directional albedo of the specular lobe with Schlick's Fresnel
//               F = F0 + (F90 - F0)(1 - v.h)^5 is  F0 A + F90 B  exactly (Karis 2013, "Real Shading
//               in Unreal Engine 4"). E_ss = A + B is that albedo with F = 1. For a BRDF that
//               conserves energy, A, B >= 0 and A + B <= 1.
//
// ---- Single scattering (the common runtime; LearnOpenGL "IBL: specular", Karis 2013) ----------
//   F         = fresnel_schlick_roughness(n.v, F0, r)        (brdf/fresnel.hpp, Lagarde 2011)
//   kD        = (1 - F)(1 - metallic)
//   diffuse   = base_color E / pi
//   specular  = LD (F0 A + F90 B)
//   ambient   = (kD diffuse + specular) ao
//   Note: this kD is a heuristic, not an energy balance. With L = 1 (LD = 1, E/pi = 1), albedo 1,
//   metallic 0 and F90 = 1:  ambient = 1 - F + F0 A + B  <=  1 + B - F0 (1 - A)  (since F >= F0),
//   which exceeds 1 when B > F0 (1 - A), e.g. F0 = 0 at n.v = 1 (F = 0, ambient = 1 + B). The
//   multiple-scattering variant below balances the energy exactly.
//
// ---- Multiple scattering (C. J. Fdez-Agüera, "A Multiple-Scattering Microfacet Model for
//      Real-Time Image-based Lighting", JCGT 8(1), 2019, section 4 and its listing) ------------
//   FssEss = F0 A + F90 B               single-scattering albedo with Fresnel (the paper's listing
//                                       uses k_S A + B with k_S = fresnel_schlick_roughness; we
//                                       keep the exact split-sum weight F0 A + F90 B of the single
//                                       scattering path, which agrees at F90 = 1 up to that k_S)
//   Ess    = A + B,  Ems = 1 - Ess      albedo lost by single scattering (F = 1)
//   Favg   = F0 + (F90 - F0) / 21       cosine-weighted hemispherical mean of Schlick's Fresnel:
//                                       2 int_0^1 (1 - mu)^5 mu dmu = 2 (1/6 - 1/7) = 1/21
//   The energy Ems that the first bounce leaves on the surface scatters again; each further
//   bounce reflects a fraction Favg and lets a fraction (approximately Ess, the albedo of the
//   current direction standing in for its hemispherical mean) escape, the rest (Ems) going on.
//   The geometric series over bounces gives the paper's
//     FmsEms = Ems FssEss Favg / (1 - Favg Ems)
//   evaluated here with the denominator written as Ess + Ems (1 - Favg) (a sum of non-negative
//   terms, no cancellation; it vanishes only at Ess = 0 and Favg = 1, where it is floored at
//   min_normal_v and the numerator is 0 whenever FssEss = 0).
//   Diffuse (dielectric) part: the energy neither reflected once nor by multiple scattering,
//     Edss   = 1 - (FssEss + FmsEms)    (clamped to [0, 1])
//     kD     = diffuse_albedo Edss      (diffuse_albedo = base_color (1 - metallic))
//   ambient  = (FssEss LD + (FmsEms + kD) E/pi) ao
//   The multiple-scattering lobe is treated as diffuse: it multiplies the cosine-weighted mean
//   radiance E/pi, not LD. (A scene without diffuse IBL may pass LD at r = 1 in its place.)
//   Energy: with F0, F90 in [0, 1], FssEss <= Ess and FmsEms <= Favg Ems <= Ems, so
//   FssEss + FmsEms <= 1; white furnace (L = 1, albedo 1): ambient = FssEss + FmsEms + Edss = 1
//   for every F0, A, B; with F0 = F90 = 1 (white metal), FssEss + FmsEms = Ess + Ems = 1.
//
// ---- Direct lights (Cook-Torrance; Karis 2013; LearnOpenGL "PBR: lighting") -------------------
//   f(v, l)   = kD base_color / pi + D(h) V(v, l) F(v.h)
//   D         = ndf_ggx(n.h, alpha = r^2); V = Schlick-GGX visibility with k = k_direct(r) =
//               (r + 1)^2 / 8, written with the cosines cancelled (v_smith_schlick_ggx), so
//               G / (4 n.v n.l) is finite at n.v = 0; F = fresnel_schlick(v.h, F0, F90);
//               kD = (1 - F(v.h))(1 - metallic)
//   L_o       = f(v, l) E_perp n.l, where E_perp is the irradiance the light delivers on a surface
//               facing it: a directional light's `irradiance`; a point light's intensity / d^2
//               (d^2 floored at point_light_min_distance_sqr_v).
//
// ---- Disk lights (a sun: a uniform spherical cap of solid angle Omega, radiance L, centre d) ---
//   Diffuse, exact: the irradiance of a uniform cap of angular radius r (cos r = 1 - Omega/(2 pi))
//   at a normal n with cos(theta) = n.d (J. Snyder, "Area light sources for real-time graphics",
//   Microsoft Research MSR-TR-96-11, 1996; the form of S. Lagarde, C. de Rousiers, "Moving
//   Frostbite to PBR", 2014):
//     cos^2 theta >= sin^2 r:  E = L pi sin^2 r max(0, cos theta)     (whole cap above or below)
//     otherwise (the cap straddles the horizon), with x = cot r, y = -x cot theta,
//       u = sin theta sqrt(1 - y^2) / x:
//       E / L = sin^2 r (cos theta acos y + u) + (atan u - u)
//   (Frostbite's (cos theta acos y - x sin theta sqrt(1 - y^2)) sin^2 r + atan(u) rewritten with
//   x t sin^2 r = u - u sin^2 r: every term is O(r^3) there, while the original cancels O(r)
//   terms; atan u - u by its series below u = 1/4). Continuous at both ends of the band; at
//   theta = pi/2 it is r - sin r cos r (half the cap).
//   Specular, cheap: the GGX lobe widened by the cap, evaluated at the cap centre d:
//       f = D(n.h; alpha') V(n.v, n.l; alpha) F(v.h),  h = normalize(v + d),
//   V the height-correlated Smith visibility (v_smith_ggx_correlated), the model of the DFG
//   table and of every reference: a disk light is a part of the environment (an extracted sun),
//   so it is shaded by the BRDF the image-based products assume, not by the punctual lights'
//   Schlick-GGX k_direct convention (that remap makes the sun's glint darker than the full
//   integral of the environment: docs/sun.md, section 3).
//       alpha'^2 = alpha^2 + tan^2(r/2) / max(v.h, 1/20),   tan^2(r/2) = (1 - cos r)/(1 + cos r)
//       L_o = f E_perp n.d,  E_perp = L pi sin^2 r.
//   Derivation: the cap seen through the half vector is an ellipse of semi-axes r/2 (in the plane
//   of incidence) and r/(2 v.h) (across it: dh = (I - h h^T) dl / (2 v.h)); convolving the GGX
//   lobe with it adds its spread to alpha^2 like variances add, with the ellipse's area-equivalent
//   radius^2 tan^2(r/2) / v.h. Head-on with R at the cap centre this is exact for every alpha:
//   the cap holds the fraction t^2 / (alpha^2 + t^2) (t = tan(r/2)) of D n.h, which
//   D(n; alpha') = 1 / (pi alpha'^2) reproduces. Off axis its error against the exact cap
//   integral of the same BRDF (reference/disk_light.hpp) grows as r falls (docs/sun.md, section
//   3): below r ~ 0.2 the lobe is narrower than the sun and the shape of the highlight (a flat
//   disk seen obliquely) is beyond one widened lobe. Karis's representative point (Real Shading
//   in Unreal Engine 4, 2013) with the same normalisation is worse at every roughness: it keeps
//   the peak over the whole cap, while the true profile is the cap convolved with a lobe of
//   comparable width.
//
// ---- Domains, clamps and NaN ------------------------------------------------------------------
//   Cosines are clamped to [0, 1] (NaN -> 0: no light), roughness and metallic to [0, 1]
//   (NaN -> 0), ao to [0, 1] (NaN -> 0), A and B to [0, 1] and Ess to [0, 1] in the multiscatter
//   path. Colours (base_color, F0, F90, LD, E, light intensities) are used as given: every result
//   is a sum of products of them with bounded weights, so finite colours give finite results and
//   a NaN colour gives NaN in that channel only. The energy statements above need F0, F90 and
//   base_color in [0, 1]. Vectors n, v, l must be unit (not checked); a zero half vector (l = -v)
//   and a light at the shading point give 0, never NaN. For finite inputs every function here
//   returns finite values for r in {0, 1} and n.v in {0, 1} included.

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include "../brdf/fresnel.hpp"
#include "../brdf/ggx.hpp"
#include "../brdf/lambert.hpp"
#include "../brdf/masking.hpp"
#include "../core/constants.hpp"
#include "../core/math.hpp"
#include "../core/vec.hpp"

namespace ibl {

/// Floor of the squared distance to a point light, in the scene's length unit squared (1e-4:
/// 1 cm^2 in metres, Filament's choice). Reason: intensity / d^2 is infinite at d = 0.
template <class T> inline constexpr T point_light_min_distance_sqr_v = T(1e-4);

// ---- material helpers ------------------------------------------------------------------------

/// A metallic-roughness material (glTF 2.0). roughness is perceptual; ao multiplies the ambient.
template <class T> struct pbr_material {
    vec3<T> base_color{T(1)};
    T metallic{0};
    T roughness{T(0.5)};
    T ambient_occlusion{1};
    T dielectric_f0{dielectric_f0_v<T>}; ///< F0 of the non-metal part (0.04 = IOR 1.5)
    vec3<T> f90{T(1)};                   ///< Schlick's F90 (1 for physical Fresnel)
};

/// The derived coefficients of a material: what the shading functions take.
template <class T> struct material_terms {
    vec3<T> f0;             ///< mix(dielectric_f0, base_color, metallic)
    vec3<T> f90;            ///< as given
    vec3<T> base_color;     ///< as given (multiplied by kD in the single-scattering path)
    vec3<T> diffuse_albedo; ///< base_color (1 - metallic) (the multiscatter path's albedo)
    T metallic;             ///< clamped to [0, 1]
    T roughness;            ///< clamped to [0, 1]
    T ambient_occlusion;    ///< clamped to [0, 1]
};

/// Material terms of the metallic workflow (f0_from_metallic, diffuse_from_metallic of
/// brdf/fresnel.hpp). Scalars are clamped to [0, 1] (NaN -> 0).
template <class T> IBL_FUNC material_terms<T> resolve_material(const pbr_material<T>& m) noexcept {
    return {f0_from_metallic(m.base_color, m.metallic, m.dielectric_f0),
            m.f90,
            m.base_color,
            diffuse_from_metallic(m.base_color, m.metallic),
            saturate(m.metallic),
            saturate(m.roughness),
            saturate(m.ambient_occlusion)};
}

// ---- ambient: diffuse ------------------------------------------------------------------------

/// Lambert diffuse under image-based lighting from the irradiance E (not E/pi): albedo E / pi.
template <class T> IBL_FUNC vec3<T> diffuse_ibl(const vec3<T>& albedo, const vec3<T>& irradiance) noexcept {
    return albedo * (irradiance * inv_pi_v<T>);
}

/// Lambert diffuse from the cosine-weighted mean radiance E/pi: albedo (E/pi).
template <class T>
IBL_FUNC vec3<T> diffuse_ibl_over_pi(const vec3<T>& albedo, const vec3<T>& irradiance_over_pi) noexcept {
    return albedo * irradiance_over_pi;
}

/// The single-scattering diffuse weight kD = (1 - F)(1 - metallic), F the ambient Fresnel
/// (fresnel_schlick_roughness(n.v, F0, r)); metallic clamped to [0, 1]. metallic = 1 gives 0.
template <class T> IBL_FUNC vec3<T> ambient_kd(const vec3<T>& fresnel, T metallic) noexcept {
    return (vec3<T>(T(1)) - fresnel) * (T(1) - saturate(metallic));
}

// ---- ambient: specular (split sum) -------------------------------------------------------------

/// The DFG value (A, B) with both terms clamped to [0, 1] (NaN -> 0).
template <class T> IBL_FUNC vec2<T> saturate_dfg(const vec2<T>& dfg) noexcept {
    return {saturate(dfg.x), saturate(dfg.y)};
}

/// Directional albedo of the specular lobe with Schlick's Fresnel: F0 A + F90 B
/// (A = dfg.x, B = dfg.y, clamped to [0, 1]).
template <class T>
IBL_FUNC vec3<T> split_sum_albedo(const vec3<T>& f0, const vec3<T>& f90, const vec2<T>& dfg) noexcept {
    const vec2<T> ab = saturate_dfg(dfg);
    return f0 * ab.x + f90 * ab.y;
}

/// Split-sum specular LD (F0 A + F90 B).
template <class T>
IBL_FUNC vec3<T> specular_ibl(const vec3<T>& ld, const vec3<T>& f0, const vec3<T>& f90, const vec2<T>& dfg) noexcept {
    return ld * split_sum_albedo(f0, f90, dfg);
}

/// Split-sum specular with F90 = 1: LD (F0 A + B).
template <class T> IBL_FUNC vec3<T> specular_ibl(const vec3<T>& ld, const vec3<T>& f0, const vec2<T>& dfg) noexcept {
    return specular_ibl(ld, f0, vec3<T>(T(1)), dfg);
}

/// Single-scattering ambient (kD diffuse + specular) ao from the products (see the header).
/// `diffuse` is diffuse_ibl(base_color, E) or diffuse_ibl_over_pi(base_color, E/pi); pass 0 for a
/// scene without diffuse IBL. ao clamped to [0, 1].
template <class T>
IBL_FUNC vec3<T> ambient_single_scatter(const vec3<T>& kd, const vec3<T>& diffuse, const vec3<T>& specular,
                                        T ambient_occlusion) noexcept {
    return (kd * diffuse + specular) * saturate(ambient_occlusion);
}

// ---- ambient: multiple scattering (Fdez-Agüera 2019) -------------------------------------------

/// Cosine-weighted hemispherical mean of Schlick's Fresnel: F0 + (F90 - F0) / 21.
template <class T> IBL_FUNC vec3<T> fresnel_schlick_average(const vec3<T>& f0, const vec3<T>& f90) noexcept {
    return f0 + (f90 - f0) * (T(1) / T(21));
}

/// The energy split of Fdez-Agüera's model at one (n.v, r): fss_ess weights LD, fms_ems and
/// diffuse_fraction weight E/pi (the latter times the diffuse albedo). fss_ess + fms_ems +
/// diffuse_fraction = 1 up to rounding when F0, F90 are in [0, 1].
template <class T> struct multiscatter_terms {
    vec3<T> fss_ess;          ///< F0 A + F90 B
    vec3<T> fms_ems;          ///< Ems FssEss Favg / (1 - Favg Ems)
    vec3<T> diffuse_fraction; ///< Edss = 1 - (FssEss + FmsEms), clamped to [0, 1]
};

/// One channel of FmsEms = Ems FssEss Favg / (Ess + Ems (1 - Favg)) (see the header).
template <class T> IBL_FUNC T multiscatter_fms_ems(T fss_ess, T ess, T f_avg) noexcept {
    const T ems = T(1) - ess;
    const T den = ess + ems * (T(1) - f_avg);
    return ems * fss_ess * f_avg / (den > min_normal_v<T> ? den : min_normal_v<T>);
}

/// Fdez-Agüera's multiple-scattering split from F0, F90 and the DFG value (A, B). A, B and
/// Ess = A + B are clamped to [0, 1]; F0, F90 are used as given (the bounds need [0, 1]).
template <class T>
IBL_FUNC multiscatter_terms<T> multiscatter(const vec3<T>& f0, const vec3<T>& f90, const vec2<T>& dfg) noexcept {
    const vec2<T> ab = saturate_dfg(dfg);
    const T ess = saturate(ab.x + ab.y);
    const vec3<T> fss_ess = f0 * ab.x + f90 * ab.y;
    const vec3<T> f_avg = fresnel_schlick_average(f0, f90);
    const vec3<T> fms_ems(multiscatter_fms_ems(fss_ess.x, ess, f_avg.x), multiscatter_fms_ems(fss_ess.y, ess, f_avg.y),
                          multiscatter_fms_ems(fss_ess.z, ess, f_avg.z));
    const vec3<T> rest = vec3<T>(T(1)) - (fss_ess + fms_ems);
    return {fss_ess, fms_ems, vec3<T>(saturate(rest.x), saturate(rest.y), saturate(rest.z))};
}

/// Multiple-scattering specular: FssEss LD + FmsEms E/pi (no diffuse lobe).
template <class T>
IBL_FUNC vec3<T> specular_ibl_multiscatter(const multiscatter_terms<T>& ms, const vec3<T>& ld,
                                           const vec3<T>& irradiance_over_pi) noexcept {
    return ms.fss_ess * ld + ms.fms_ems * irradiance_over_pi;
}

/// Multiple-scattering ambient: (FssEss LD + (FmsEms + diffuse_albedo Edss) E/pi) ao.
template <class T>
IBL_FUNC vec3<T> ambient_multiscatter(const multiscatter_terms<T>& ms, const vec3<T>& diffuse_albedo, const vec3<T>& ld,
                                      const vec3<T>& irradiance_over_pi, T ambient_occlusion) noexcept {
    const vec3<T> diffuse_weight = ms.fms_ems + diffuse_albedo * ms.diffuse_fraction;
    return (ms.fss_ess * ld + diffuse_weight * irradiance_over_pi) * saturate(ambient_occlusion);
}

// ---- direct lights -----------------------------------------------------------------------------

/// The cosines of one light direction: n.l, n.h, v.h (clamped to [0, 1]) for unit n, v, l.
/// A zero half vector (l = -v) gives n.h = v.h = 0 (never NaN).
template <class T> struct light_cosines {
    T n_dot_l, n_dot_h, v_dot_h;
};

/// The cosines of l seen from v about n (unit vectors).
template <class T>
IBL_FUNC light_cosines<T> make_light_cosines(const vec3<T>& n, const vec3<T>& v, const vec3<T>& l) noexcept {
    using std::sqrt;
    const vec3<T> s = v + l;
    const T len2 = glm::dot(s, s);
    // |v + l|^2 vanishes only for l = -v; the floor keeps h = s / |s| finite (h = 0 there).
    const vec3<T> h = s * (T(1) / sqrt(len2 > min_normal_v<T> ? len2 : min_normal_v<T>));
    return {saturate(glm::dot(n, l)), saturate(glm::dot(n, h)), saturate(glm::dot(v, h))};
}

/// Cook-Torrance specular BRDF D V F for analytic lights (per steradian): GGX D with
/// alpha = r^2, Schlick-GGX V with k_direct(r), Schlick F(v.h, F0, F90). Finite at n.v = 0,
/// n.l = 0 and r = 0 (peak D <= 1/(pi ggx_min_alpha^2), V <= 16).
template <class T>
IBL_FUNC vec3<T> specular_brdf_direct(T n_dot_v, const light_cosines<T>& c, const vec3<T>& f0, const vec3<T>& f90,
                                      T roughness) noexcept {
    const T d = ndf_ggx(c.n_dot_h, alpha_from_roughness(roughness));
    const T vis = v_smith_schlick_ggx(n_dot_v, c.n_dot_l, k_direct(roughness));
    return (d * vis) * fresnel_schlick(c.v_dot_h, f0, f90);
}

/// Full BRDF for analytic lights: kD base_color / pi + D V F, kD = (1 - F(v.h))(1 - metallic).
template <class T>
IBL_FUNC vec3<T> brdf_direct(T n_dot_v, const light_cosines<T>& c, const material_terms<T>& m) noexcept {
    const vec3<T> f = fresnel_schlick(c.v_dot_h, m.f0, m.f90);
    const vec3<T> kd = ambient_kd(f, m.metallic);
    const T d = ndf_ggx(c.n_dot_h, alpha_from_roughness(m.roughness));
    const T vis = v_smith_schlick_ggx(n_dot_v, c.n_dot_l, k_direct(m.roughness));
    return kd * lambert(m.base_color) + (d * vis) * f;
}

/// A directional light: unit direction *towards* the light and the irradiance it delivers on a
/// surface facing it (the illuminance for photometric units).
template <class T> struct directional_light {
    vec3<T> direction{T(0), T(1), T(0)};
    vec3<T> irradiance{T(1)};
};

/// A point light: position and radiant intensity (W/sr, or candela for photometric units).
template <class T> struct point_light {
    vec3<T> position{T(0)};
    vec3<T> intensity{T(1)};
};

/// Outgoing radiance f(v, l) E_perp n.l for unit n, v, l (the shared step of both light types).
template <class T>
IBL_FUNC vec3<T> shade_light(const vec3<T>& n, const vec3<T>& v, const vec3<T>& l, const vec3<T>& e_perp,
                             const material_terms<T>& m) noexcept {
    const light_cosines<T> c = make_light_cosines(n, v, l);
    const T n_dot_v = saturate(glm::dot(n, v));
    return brdf_direct(n_dot_v, c, m) * e_perp * c.n_dot_l;
}

/// Outgoing radiance from a directional light.
template <class T>
IBL_FUNC vec3<T> shade_directional(const vec3<T>& n, const vec3<T>& v, const directional_light<T>& light,
                                   const material_terms<T>& m) noexcept {
    return shade_light(n, v, light.direction, light.irradiance, m);
}

/// Outgoing radiance from a point light at squared distance d^2 (floored at
/// point_light_min_distance_sqr_v) from the shaded position p: E_perp = intensity / d^2.
/// A light exactly at p contributes 0.
template <class T>
IBL_FUNC vec3<T> shade_point(const vec3<T>& p, const vec3<T>& n, const vec3<T>& v, const point_light<T>& light,
                             const material_terms<T>& m) noexcept {
    using std::sqrt;
    const vec3<T> to_light = light.position - p;
    const T d2 = glm::dot(to_light, to_light);
    const vec3<T> l = d2 > T(0) ? to_light * (T(1) / sqrt(d2)) : vec3<T>(T(0));
    const T d2_floor = d2 > point_light_min_distance_sqr_v<T> ? d2 : point_light_min_distance_sqr_v<T>;
    return shade_light(n, v, l, light.intensity * (T(1) / d2_floor), m);
}

// ---- disk lights (a sun) ------------------------------------------------------------------------

/// A distant uniform disk (spherical cap): unit direction *towards* its centre, solid angle
/// Omega = 2 pi (1 - cos r) in [0, 2 pi] (steradians), radiance L.
template <class T> struct disk_light {
    vec3<T> direction{T(0), T(1), T(0)};
    T solid_angle{T(0)};
    vec3<T> radiance{T(0)};
};

/// 1 - cos r of a cap of solid angle omega (clamped to [0, 1]: at most a hemisphere).
template <class T> IBL_FUNC T cap_one_minus_cos(T omega) noexcept { return saturate(omega * (T(0.5) * inv_pi_v<T>)); }

/// sin^2 r of a cap of solid angle omega: c (2 - c), c = 1 - cos r (no cancellation for small r).
template <class T> IBL_FUNC T cap_sin2(T omega) noexcept {
    const T c = cap_one_minus_cos(omega);
    return c * (T(2) - c);
}

/// atan(u) - u for u >= 0, without cancellation for small u (series below 1/4).
template <class T> IBL_FUNC T atan_minus_identity(T u) noexcept {
    using std::atan;
    if (u >= T(0.25)) return atan(u) - u;
    // -u^3 sum_k (-u^2)^k / (2k + 3): 13 terms leave < (1/16)^13 / 29 relative (below double eps).
    const T u2 = u * u;
    T s = T(0);
    for (int k = 12; k >= 0; --k) s = T(1) / T(2 * k + 3) - u2 * s;
    return -u * u2 * s;
}

/// Irradiance of a uniform cap of unit radiance (E / L) at angle theta from its centre
/// (cos_theta = n.d, clamped to [-1, 1]) for sin^2 r = sin2_r in [0, 1] (see the header). Exact,
/// also when the cap straddles the horizon. 0 for sin2_r <= 0; NaN cos_theta gives 0.
template <class T> IBL_FUNC T cap_irradiance(T cos_theta, T sin2_r) noexcept {
    using std::acos;
    using std::sqrt;
    if (!(sin2_r > T(0))) return T(0);
    const T ct = clamp(cos_theta, T(-1), T(1));
    if (!(ct == ct)) return T(0);
    if (ct * ct >= sin2_r) return pi_v<T> * sin2_r * (ct > T(0) ? ct : T(0));
    const T s2 = sin2_r < T(1) ? sin2_r : T(1);
    const T st = sqrt((T(1) - ct) * (T(1) + ct)); // >= cos r > 0 in this band (or r = pi/2)
    const T x = sqrt((T(1) - s2) / s2);            // cot r
    const T y = clamp(-x * ct / (st > min_normal_v<T> ? st : min_normal_v<T>), T(-1), T(1));
    const T t = st * sqrt((T(1) - y) * (T(1) + y));
    const T u = x > T(0) ? t / x : T(0);
    // r = pi/2 (x = 0): u -> inf, atan u - u + u s2 -> pi/2; the limit is taken explicitly.
    const T e = x > T(0) ? s2 * (ct * acos(y) + u) + atan_minus_identity(u) : s2 * ct * acos(y) + half_pi_v<T>;
    return e > T(0) ? e : T(0);
}

/// Irradiance E(n) of a disk light at unit normal n (exact for a uniform cap, see the header).
template <class T> IBL_FUNC vec3<T> disk_light_irradiance(const vec3<T>& n, const disk_light<T>& light) noexcept {
    return light.radiance * cap_irradiance(glm::dot(n, light.direction), cap_sin2(light.solid_angle));
}

/// Irradiance a disk light delivers on a surface facing it: L pi sin^2 r.
template <class T> IBL_FUNC vec3<T> disk_light_normal_irradiance(const disk_light<T>& light) noexcept {
    return light.radiance * (pi_v<T> * cap_sin2(light.solid_angle));
}

/// Cook-Torrance specular of a disk light by the widened lobe of the header:
/// D(n.h; alpha') V F(v.h) E_perp n.d at the cap centre d, unit n, v.
template <class T>
IBL_FUNC vec3<T> disk_light_specular(const vec3<T>& n, const vec3<T>& v, const disk_light<T>& light, const vec3<T>& f0,
                                     const vec3<T>& f90, T roughness) noexcept {
    using std::sqrt;
    const T r = saturate(roughness);
    const light_cosines<T> c = make_light_cosines(n, v, light.direction);
    const T c1 = cap_one_minus_cos(light.solid_angle);
    const T tan2_half = c1 / (T(2) - c1); // tan^2(r/2)
    const T vh = c.v_dot_h > T(0.05) ? c.v_dot_h : T(0.05);
    const T alpha_w = sqrt(sqr(clamp_alpha(alpha_from_roughness(r))) + tan2_half / vh);
    const T d = ndf_ggx(c.n_dot_h, alpha_w < T(1) ? alpha_w : T(1));
    const T vis = v_smith_ggx_correlated(saturate(glm::dot(n, v)), c.n_dot_l, clamp_alpha(alpha_from_roughness(r)));
    return (d * vis * c.n_dot_l) * fresnel_schlick(c.v_dot_h, f0, f90) * disk_light_normal_irradiance(light);
}

/// Outgoing radiance from a disk light: the exact cap irradiance times kD base_color / pi
/// (kD = (1 - F(v.h))(1 - metallic), h towards the cap centre) plus disk_light_specular.
template <class T>
IBL_FUNC vec3<T> shade_disk(const vec3<T>& n, const vec3<T>& v, const disk_light<T>& light, const material_terms<T>& m) noexcept {
    const light_cosines<T> c = make_light_cosines(n, v, light.direction);
    const vec3<T> kd = ambient_kd(fresnel_schlick(c.v_dot_h, m.f0, m.f90), m.metallic);
    return kd * lambert(m.base_color) * disk_light_irradiance(n, light) +
           disk_light_specular(n, v, light, m.f0, m.f90, m.roughness);
}

// ---- convenience --------------------------------------------------------------------------------

/// What the baked products give at one shading point. Leave a product at 0 when the scene does
/// not bake it; `irradiance_over_pi` is E/pi (see the header; E = pi * this).
template <class T> struct ibl_sample {
    vec3<T> ld{T(0)};                 ///< prefiltered radiance at (R, r)
    vec3<T> irradiance_over_pi{T(0)}; ///< E(n) / pi
    vec2<T> dfg{T(0)};                ///< (A, B) at (n.v, r)
};

/// Ambient and direct shading of one material, single or multiple scattering.
template <class T> struct pbr_shader {
    material_terms<T> m;
    bool multiple_scattering = true;

    IBL_FUNC static pbr_shader from(const pbr_material<T>& mat, bool multiscatter_ibl = true) noexcept {
        return {resolve_material(mat), multiscatter_ibl};
    }

    /// Ambient (image-based) outgoing radiance at view cosine n.v (clamped to [0, 1]).
    IBL_FUNC vec3<T> ambient(T n_dot_v, const ibl_sample<T>& s) const noexcept {
        if (multiple_scattering)
            return ambient_multiscatter(multiscatter(m.f0, m.f90, s.dfg), m.diffuse_albedo, s.ld, s.irradiance_over_pi,
                                        m.ambient_occlusion);
        const vec3<T> f = fresnel_schlick_roughness(saturate(n_dot_v), m.f0, m.roughness);
        return ambient_single_scatter(ambient_kd(f, m.metallic), diffuse_ibl_over_pi(m.base_color, s.irradiance_over_pi),
                                      specular_ibl(s.ld, m.f0, m.f90, s.dfg), m.ambient_occlusion);
    }

    IBL_FUNC vec3<T> directional(const vec3<T>& n, const vec3<T>& v, const directional_light<T>& light) const noexcept {
        return shade_directional(n, v, light, m);
    }

    IBL_FUNC vec3<T> point(const vec3<T>& p, const vec3<T>& n, const vec3<T>& v, const point_light<T>& light) const noexcept {
        return shade_point(p, n, v, light, m);
    }
};

} // namespace ibl

#endif // IBL_DETAIL_CXX20
