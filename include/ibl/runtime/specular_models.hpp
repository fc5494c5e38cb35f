#pragma once
// ibl/runtime/specular_models.hpp — runtime approximations of the specular image-based lighting integral
//   Lo_s(n, v) = integral f_s(v, l) L(l) (n.l) dl,   f_s = D(h) V(v, l) F(v.h)   (GGX, Smith)
// from a prefiltered chain (runtime/lookup.hpp) and small tables, beyond the split sum's LD(R) (F0 A + F90 B).
// docs/runtime.md measures every variant against the full integral (reference_radiance) and
// names the default; research/runtime_error.cpp produces its tables.
//
// ---- Dominant direction (S. Lagarde, C. de Rousiers, "Moving Frostbite to PBR", 2014, 4.9.3) ----
//   The GGX lobe f_s (n.l) is not centred on R = reflect(-v, n): masking and the n.l factor pull
//   its mass towards n, more so for rough surfaces and grazing views. Frostbite reads the chain at
//       d = normalize(lerp(n, R, s)),   s = (1 - alpha) (sqrt(1 - alpha) + alpha)   (alpha = r^2)
//   (dominant_lerp_frostbite), a fit of the lobe's peak that ignores n.v.
//
// ---- The lobe LUT (derived here; bake/lobe_fit.hpp builds it) -------------------------------
//   The one-tap model read at (n.v, r) from a four-channel table (A, B, s, r_eff):
//       Lo_s ~ LD(normalize(lerp(n, R, s)), r_eff) (F0 A + F90 B)
//   s and r_eff match the first moment of the normalised lobe p(l) = D V (n.l) / E:
//     * its mean m = integral l p(l) dl gives the direction (s is the lerp factor whose
//       normalize(lerp(n, R, s)) is m / |m|: view dependent, unlike Frostbite's);
//     * its mean resultant length |m| (1 - |m| ~ half the angular variance) is matched by the
//       chain's own kernel: r_eff solves |m_LD(r_eff)| = |m| where m_LD is the mean of the
//       normalised LD kernel of the bake's weight (D n.l or D G1, bake/prefilter.hpp).
//   Nothing is fitted to an environment: both moments are integrals of the BRDF alone. At n.v = 1
//   with a G1-weighted chain the lobe IS the LD kernel, so s is irrelevant and r_eff = r: the
//   lookup is exact there. Cost: one chain lookup and one RGBA table tap, the split sum's.
//
// ---- Filtered importance sampling at run time (Colbert & Krivanek, GPU Gems 3 ch. 20) -----------
//   K taps of the chain along the true, view-dependent lobe: GGX visible normals h_k
//   (sample_ggx_vndf at a fixed shifted Hammersley set u_k = (phi_2(k) + 1/(2K), (k + 1/2)/K)),
//   l_k = reflect(-v, h_k), taps below n's horizon (n.l_k <= 0) dropped (their weight is 0).
//   Each tap's weight is the full BRDF over the density,
//       w_k = f_s (n.l) / pdf_l = F(v.h) G2(v, l) / G1(v)     (pdf_l = G1(v) D / (4 n.v))
//   and it reads the chain at the roughness whose LD kernel covers the tap's solid angle
//       Omega_k = c / (K pdf_l)   (c = footprint_scale)
//   The normalised LD kernel of roughness alpha' peaks at 1 / (pi alpha'^2 W(alpha')),
//   W(alpha) = integral D (n.l) dl, so its solid angle is pi alpha'^2 W; W falls from 4 (alpha -> 0)
//   to 1 (alpha = 1) and 4 / (1 + 3 alpha^2) follows it within 10%, which inverts in closed form:
//       alpha'^2 = Omega / (4 pi - 3 Omega)   (Omega >= pi: alpha' = 1)      (fis_footprint_roughness)
//   Two estimators (runtime_fis_desc::normalise):
//       plain       Lo_s ~ (1/K) sum_k w_k LD_k                      (unbiased as blur -> 0)
//       normalised  Lo_s ~ (F0 A + F90 B) sum_k w_k LD_k / sum_k w_k  (per channel)
//   The normalised one takes the albedo from the DFG table and only the shape of the radiance
//   from the taps: exact for a constant environment for every K (the ratio is the constant) and
//   the plain one's noise in sum w_k / K (the albedo estimate) is gone.
//
// ---- Horizon fading and specular occlusion (Lagarde & de Rousiers 2014, 4.10.2 and 4.10.3) ---
//   horizon_fade(d, n_g) = saturate(1 + d.n_g)^2: fades a lookup direction that a normal map sent
//   below the geometric surface (1 whenever d is above it: no effect without normal maps).
//   specular_occlusion_lagarde(n.v, ao, r) = saturate((n.v + ao)^(2^(-16 alpha - 1)) - 1 + ao): the
//   specular visibility from an ambient-occlusion value (1 at ao = 1; tends to ao for rough
//   surfaces, to 1 for smooth ones at normal view, to ao at grazing).
//
// Domains: unit n, v; n.v clamped to [0, 1] (v below the surface is projected onto the tangent
// plane by the frame code: n.v = 0); roughness clamped to [0, 1]; ao to [0, 1]. Value functions
// are IBL_FUNC; the functions that read a cubemap<float> or a table in host memory are host
// functions (a shader mirrors them: docs/runtime.md).

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <cmath>
#include <concepts>
#include <cstdint>

#include "../brdf/fresnel.hpp"
#include "../brdf/ggx.hpp"
#include "../core/constants.hpp"
#include "../core/frame.hpp"
#include "../core/math.hpp"
#include "../core/vec.hpp"
#include "../env/cubemap.hpp"
#include "lookup.hpp"
#include "../sampling/ggx.hpp"
#include "../sampling/sequence.hpp"
#include "shade.hpp"

namespace ibl {

// ---- dominant direction, horizon, occlusion ------------------------------------------------------

/// Frostbite's lerp factor s(alpha) = (1 - alpha)(sqrt(1 - alpha) + alpha), alpha = r^2
/// (r clamped to [0, 1]): 1 at r = 0 (the mirror direction), 0 at r = 1 (the normal).
template <class T> IBL_FUNC T dominant_lerp_frostbite(T roughness) noexcept {
    using std::sqrt;
    const T a = alpha_from_roughness(roughness);
    const T s = T(1) - a;
    return s * (sqrt(s) + a);
}

/// normalize(lerp(n, r_dir, s)) for unit n, r_dir (s clamped to [0, 1]); n where the lerp vanishes.
template <class T> IBL_FUNC vec3<T> lerp_direction(const vec3<T>& n, const vec3<T>& r_dir, T s) noexcept {
    using std::sqrt;
    const vec3<T> d = n + saturate(s) * (r_dir - n);
    const T len2 = glm::dot(d, d);
    return len2 > min_normal_v<T> ? d * (T(1) / sqrt(len2)) : n;
}

/// Horizon fading saturate(1 + dir.n_g)^2 of a lookup direction against the geometric normal.
template <class T> IBL_FUNC T horizon_fade(const vec3<T>& dir, const vec3<T>& geometric_normal) noexcept {
    const T h = saturate(T(1) + glm::dot(dir, geometric_normal));
    return h * h;
}

/// Lagarde's specular occlusion from an ambient-occlusion value:
/// saturate((n.v + ao)^(2^(-16 alpha - 1)) - 1 + ao), alpha = r^2; n.v, ao, r clamped to [0, 1].
template <class T> IBL_FUNC T specular_occlusion_lagarde(T n_dot_v, T ambient_occlusion, T roughness) noexcept {
    using std::exp2;
    using std::pow;
    const T ao = saturate(ambient_occlusion);
    const T a = alpha_from_roughness(roughness);
    return saturate(pow(saturate(n_dot_v) + ao, exp2(T(-16) * a - T(1))) - T(1) + ao);
}

// ---- filtered importance sampling at run time --------------------------------------------------

/// G2(v, l) / G1(v) of height-correlated Smith GGX for cosines in [0, 1]:
/// (s_v + n.v) n.l / ((s_v + n.v) n.l + (s_l - n.l) n.v), s = ggx_smith_root. 1 at n.v = 0
/// (the limit), 0 at n.l = 0; no cancellation (s_l - n.l = alpha^2 (1 - n.l^2) / (s_l + n.l)).
template <class T> IBL_FUNC T g2_over_g1_height_correlated(T n_dot_v, T n_dot_l, T alpha) noexcept {
    const T a2 = sqr(clamp_alpha(alpha));
    const T mv = saturate(n_dot_v), ml = saturate(n_dot_l);
    const T sv = ggx_smith_root(mv, a2), sl = ggx_smith_root(ml, a2);
    const T num = (sv + mv) * ml;
    const T den = num + a2 * (T(1) - ml) * (T(1) + ml) / (sl + ml) * mv;
    return den > T(0) ? num / den : T(0);
}

/// The roughness r' whose normalised LD kernel covers a solid angle omega (sr):
/// alpha'^2 = omega / (4 pi - 3 omega), 1 for omega >= pi, 0 for omega <= 0 or NaN (header).
template <class T> IBL_FUNC T fis_footprint_roughness(T omega) noexcept {
    using std::sqrt;
    if (!(omega > T(0))) return T(0);
    if (omega >= pi_v<T>) return T(1);
    const T a2 = omega / (T(4) * pi_v<T> - T(3) * omega);
    return sqrt(sqrt(a2));
}

/// Point k of the runtime tap set of `count` points: (phi_2(k) + 1/(2K) mod 1, (k + 1/2)/K).
template <class T> IBL_FUNC vec2<T> fis_tap_point(std::uint32_t k, std::uint32_t count) noexcept {
    const T n = T(count > 0 ? count : 1);
    T x = radical_inverse<T>(k) + T(0.5) / n;
    if (x >= T(1)) x -= T(1);
    return {x, (T(k) + T(0.5)) / n};
}

/// One tap: world direction, per-channel weight F G2 / G1 (0 below the horizon) and the
/// roughness to read the chain at.
template <class T> struct runtime_tap {
    vec3<T> dir{T(0), T(0), T(1)};
    vec3<T> weight{T(0)};
    T roughness = T(0);
};

/// Tap k of `count` along the GGX lobe of roughness r seen from v_local (tangent space of fr,
/// v_local.z = n.v >= 0) with Schlick F(F0, F90); footprint_scale = c of the header.
template <class T>
IBL_FUNC runtime_tap<T> fis_tap(const frame<T>& fr, const vec3<T>& v_local, T roughness, std::uint32_t k,
                                std::uint32_t count, T footprint_scale, const vec3<T>& f0, const vec3<T>& f90) noexcept {
    runtime_tap<T> t;
    const T alpha = clamp_alpha(alpha_from_roughness(roughness));
    const vec3<T> h = sample_ggx_vndf(v_local, fis_tap_point<T>(k, count), alpha);
    const T v_dot_h = glm::dot(v_local, h);
    const vec3<T> l = T(2) * v_dot_h * h - v_local;
    t.dir = fr.to_world(l);
    if (!(l.z > T(0)) || !(v_dot_h > T(0))) return t; // clipped at the horizon: weight 0
    const T pdf = ggx_vndf_reflected_pdf(v_local, h, alpha);
    const T n = T(count > 0 ? count : 1);
    t.roughness = pdf > T(0) ? fis_footprint_roughness(footprint_scale / (n * pdf)) : T(1);
    t.weight = fresnel_schlick(saturate(v_dot_h), f0, f90) * g2_over_g1_height_correlated(v_local.z, l.z, alpha);
    return t;
}

/// Runtime filtered importance sampling (header). lookup: how each tap reads the chain (its
/// mapping MUST match the bake); the default reads one trilinear tap per sample (lod weight,
/// linear blend: one textureLod).
struct runtime_fis_desc {
    std::uint32_t taps = 8;
    float footprint_scale = 1.0f;
    bool normalise = true;
    specular_lookup_desc lookup = specular_lookup_desc::textbook();
};

/// The taps' combination (header): normalised (albedo (F0 A + F90 B) times the weighted mean of
/// the tap values; the value `fallback` where every weight is 0) or plain (sum w LD / K).
template <class T>
IBL_FUNC vec3<T> fis_combine(const vec3<T>& weighted_sum, const vec3<T>& weight_sum, std::uint32_t count, bool normalise,
                             const vec3<T>& albedo, const vec3<T>& fallback) noexcept {
    if (!normalise) return weighted_sum / T(count > 0 ? count : 1);
    vec3<T> out;
    for (int c = 0; c < 3; ++c)
        out[c] = weight_sum[c] > T(0) ? albedo[c] * weighted_sum[c] / weight_sum[c] : albedo[c] * fallback[c];
    return out;
}

/// Specular radiance by runtime filtered importance sampling of the chain (header): n, v unit,
/// dfg = (A, B) at (n.v, r) (used by the normalised estimator only).
template <class Chain>
    requires std::derived_from<Chain, cubemap<float>>
vec3<float> specular_fis(const Chain& chain, const runtime_fis_desc& d, const vec3<float>& n,
                                const vec3<float>& v, float roughness, const vec3<float>& f0, const vec3<float>& f90,
                                const vec2<float>& dfg) {
    const frame<float> fr = make_frame(n);
    vec3<float> vl = fr.to_local(v);
    vl.z = vl.z > 0.0f ? vl.z : 0.0f;
    const float len2 = glm::dot(vl, vl);
    vl = len2 > 0.0f ? vl / std::sqrt(len2) : vec3<float>(0.0f, 0.0f, 1.0f);
    const std::uint32_t count = d.taps > 0 ? d.taps : 1;
    vec3<float> sum(0.0f), wsum(0.0f);
    for (std::uint32_t k = 0; k < count; ++k) {
        const runtime_tap<float> t = fis_tap(fr, vl, roughness, k, count, d.footprint_scale, f0, f90);
        if (t.weight == vec3<float>(0.0f)) continue;
        sum += t.weight * specular_lookup(chain, t.dir, t.roughness, d.lookup);
        wsum += t.weight;
    }
    const vec3<float> albedo = split_sum_albedo(f0, f90, dfg);
    const bool need_fallback = d.normalise && !(wsum.x > 0.0f && wsum.y > 0.0f && wsum.z > 0.0f);
    const vec3<float> r_dir = fr.to_world(vec3<float>(-vl.x, -vl.y, vl.z));
    const vec3<float> fb = need_fallback ? specular_lookup(chain, r_dir, roughness, d.lookup) : vec3<float>(0.0f);
    return fis_combine(sum, wsum, count, d.normalise, albedo, fb);
}

// ---- the lobe LUT ------------------------------------------------------------------------------

/// Bilinear lookup with clamp-to-edge of channels 0..3 of a table with members size, channels and
/// data (runtime/tables.hpp's lobe_lut) at the coordinates of the table's own layout
/// (member layout, runtime/dfg_layout.hpp).
template <class Table> vec4<float> lobe_lut_lookup(const Table& lut, float n_dot_v, float roughness) {
    const vec2<float> st = dfg_lut_coord(n_dot_v, roughness, lut.size, lut.layout);
    float v[4] = {0.0f, 0.0f, 0.0f, 0.0f};
    detail::table_bilinear(lut, st.x, st.y, v, 4);
    return vec4<float>(v[0], v[1], v[2], v[3]);
}

/// The one-tap lobe model (header): LD(normalize(lerp(n, R, s)), r_eff) (F0 A + F90 B) with
/// (A, B, s, r_eff) = lobe_lut_lookup(lut, n.v, r). sd: the chain's lookup.
template <class Chain, class Table>
    requires std::derived_from<Chain, cubemap<float>>
vec3<float> specular_lobe(const Chain& chain, const specular_lookup_desc& sd, const Table& lut,
                          const vec3<float>& n, const vec3<float>& v, float roughness, const vec3<float>& f0,
                          const vec3<float>& f90) {
    detail::check_chain_weight("specular_lobe", chain, lut);
    const float n_dot_v = saturate(glm::dot(n, v));
    const vec3<float> r_dir = 2.0f * glm::dot(n, v) * n - v;
    const vec4<float> p = lobe_lut_lookup(lut, n_dot_v, roughness);
    const vec3<float> d = lerp_direction(n, r_dir, p.z);
    return specular_lookup(chain, d, p.w, sd) * split_sum_albedo(f0, f90, vec2<float>(p.x, p.y));
}

// ---- fitted taps ----------------------------------------------------------------------------------

/// The unit tangent of n in the plane of incidence, towards R (header); any tangent of n when
/// R is (nearly) n.
template <class T> IBL_FUNC vec3<T> incidence_tangent(const vec3<T>& n, const vec3<T>& r_dir) noexcept {
    using std::sqrt;
    const vec3<T> t = r_dir - glm::dot(n, r_dir) * n;
    const T len2 = glm::dot(t, t);
    return len2 > T(1e-12) ? t * (T(1) / sqrt(len2)) : make_frame(n).t;
}

/// A fitted tap's angle from n towards R (radians) from its table value f: f acos(n.v) (f = 1 at
/// R, 0 at n; bake/lobe_fit.hpp stores angles relative to the view angle).
template <class T> IBL_FUNC T lobe_tap_angle(T stored, T n_dot_v) noexcept {
    using std::acos;
    return stored * acos(saturate(n_dot_v));
}

/// The fitted-taps model (bake/lobe_fit.hpp) from a table with members size, channels, taps
/// and data (lobe_taps_lut fitted with kernels of any roughness, i.e. empty level_roughness: a
/// table of stored levels holds lods there, which this does not read): at (n.v, r) one bilinear
/// read of the channels
/// (A, B, then angle / acos(n.v), roughness, weight per tap), then
///     Lo_s ~ (F0 A + F90 B) sum_k w_k LD(cos(a_k) n + sin(a_k) t, r_k)
/// with t = incidence_tangent(n, R) and each LD by the chain lookup sd. Cost: taps chain lookups
/// and ceil((2 + 3 taps) / 4) RGBA table reads.
template <class Chain, class Table>
    requires std::derived_from<Chain, cubemap<float>>
vec3<float> specular_lobe_taps(const Chain& chain, const specular_lookup_desc& sd, const Table& lut,
                               const vec3<float>& n, const vec3<float>& v, float roughness, const vec3<float>& f0,
                               const vec3<float>& f90) {
    detail::check_chain_weight("specular_lobe_taps", chain, lut);
    constexpr std::uint32_t max_channels = 2 + 3 * 8;
    const float n_dot_v = saturate(glm::dot(n, v));
    const vec3<float> r_dir = 2.0f * glm::dot(n, v) * n - v;
    const vec2<float> st = dfg_lut_coord(n_dot_v, roughness, lut.size, lut.layout);
    float p[max_channels] = {};
    detail::table_bilinear(lut, st.x, st.y, p, lut.channels < max_channels ? lut.channels : max_channels);
    const vec3<float> t = incidence_tangent(n, r_dir);
    const int taps = int((std::min(lut.channels, max_channels) - 2) / 3);
    vec3<float> sum(0.0f);
    float wsum = 0.0f;
    for (int k = 0; k < taps; ++k) {
        const float a = lobe_tap_angle(p[2 + 3 * k], n_dot_v), w = p[4 + 3 * k];
        if (!(w > 0.0f)) continue;
        const vec3<float> d = glm::normalize(std::cos(a) * n + std::sin(a) * t);
        sum += w * specular_lookup(chain, d, p[3 + 3 * k], sd);
        wsum += w;
    }
    const vec3<float> ld = wsum > 0.0f ? sum / wsum : specular_lookup(chain, r_dir, roughness, sd);
    return ld * split_sum_albedo(f0, f90, vec2<float>(p[0], p[1]));
}

// ---- the two-part lobe model ----------------------------------------------------------------------

/// The effective LD of the two-part model for a material (header): per channel
/// (F0 A LD_a + F90 B LD_b) / (F0 A + F90 B) (LD_a where that albedo is 0), so that the split
/// sum's form LD (F0 A + F90 B), e.g. runtime/shade.hpp's ambient, gives F0 A LD_a + F90 B LD_b.
template <class T>
IBL_FUNC vec3<T> lobe_pair_ld(const vec3<T>& ld_a, const vec3<T>& ld_b, const vec3<T>& f0, const vec3<T>& f90,
                              const vec2<T>& ab) noexcept {
    vec3<T> out;
    for (int c = 0; c < 3; ++c) {
        const T wa = f0[c] * ab.x, wb = f90[c] * ab.y, den = wa + wb;
        out[c] = den > T(0) ? (wa * ld_a[c] + wb * ld_b[c]) / den : ld_a[c];
    }
    return out;
}

/// The direction of the two-part model's B kernel (header): at angle f acos(n.v) from n towards R
/// in the plane of incidence, cos(a) n + sin(a) t with t = incidence_tangent(n, R) (a clamped to
/// [0, pi/2]: the kernel stays above n's horizon).
template <class T> IBL_FUNC vec3<T> lobe_pair_direction_b(const vec3<T>& n, const vec3<T>& r_dir, T stored, T n_dot_v) noexcept {
    using std::cos;
    using std::sin;
    using std::sqrt;
    T a = lobe_tap_angle(stored, n_dot_v);
    a = a < T(0) ? T(0) : (a > half_pi_v<T> ? half_pi_v<T> : a);
    const vec3<T> d = cos(a) * n + sin(a) * incidence_tangent(n, r_dir);
    return d * (T(1) / sqrt(glm::dot(d, d)));
}

/// The two-part lobe model (header): with (A, B, s_A, r_A) = lobe_lut_lookup(a, n.v, r) and
/// (f_B, r_B) = lobe_lut_lookup(b, n.v, r) (bake/lobe_fit.hpp make_lobe_pair_lut)
///     Lo_s ~ F0 A LD(normalize(lerp(n, R, s_A)), r_A) + F90 B LD(d_B, r_B)
/// d_B = lobe_pair_direction_b(n, R, f_B, n.v). Cost: two chain lookups and two RGBA table taps.
template <class Chain, class Table>
    requires std::derived_from<Chain, cubemap<float>>
vec3<float> specular_lobe_pair(const Chain& chain, const specular_lookup_desc& sd, const Table& a, const Table& b,
                               const vec3<float>& n, const vec3<float>& v, float roughness, const vec3<float>& f0,
                               const vec3<float>& f90) {
    detail::check_chain_weight("specular_lobe_pair", chain, a);
    detail::check_chain_weight("specular_lobe_pair", chain, b);
    const float n_dot_v = saturate(glm::dot(n, v));
    const vec3<float> r_dir = 2.0f * glm::dot(n, v) * n - v;
    const vec4<float> pa = lobe_lut_lookup(a, n_dot_v, roughness);
    const vec4<float> pb = lobe_lut_lookup(b, n_dot_v, roughness);
    const vec3<float> ld_a = specular_lookup(chain, lerp_direction(n, r_dir, pa.z), pa.w, sd);
    const vec3<float> ld_b = specular_lookup(chain, lobe_pair_direction_b(n, r_dir, pb.x, n_dot_v), pb.y, sd);
    return f0 * pa.x * ld_a + f90 * pa.y * ld_b;
}

} // namespace ibl

#endif // IBL_DETAIL_CXX20
