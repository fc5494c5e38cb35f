// ibl/glsl/ibl_runtime.glsl — the runtime variants of the specular term (GLSL mirror of
// ibl/runtime/specular_models.hpp, with the pieces of core/frame.hpp, sampling/sequence.hpp and
// sampling/ggx.hpp they use): Frostbite's dominant direction, horizon fading and Lagarde's
// specular occlusion; the specular-occlusion table of ibl/runtime/specular_occlusion.hpp (a 3-D texture,
// ibl_common.glsl) read about n or about a bent normal; runtime filtered importance sampling of
// the chain (K taps along the GGX visible-normal lobe, each read at its footprint's roughness);
// the fitted-taps model of bake/lobe_fit.hpp in its two-tap form (two RGBA tables,
// ibl_common.glsl); the two-part lobe model (the lobe LUT plus the B part's kernel table). The formulas and their derivations are in runtime/specular_models.hpp's and runtime/specular_occlusion.hpp's
// headers; every function here is the same expression in the same order. Needs
// ibl_common.glsl, ibl_lookup.glsl and ibl_shade.glsl first.
//
// Differences from the C++: make_frame's sign(n.z) is copysign(1, n.z) in the C++ and
// (n.z >= 0 ? 1 : -1) here (they differ only at n.z = -0); ibl_specular_fis takes at most
// IBL_FIS_MAX_TAPS taps (the C++ has no cap). The bent-normal reading of the occlusion table has
// no C++ function: it is the expression docs/occlusion.md measures as "lobe LUT, bent"
// (research/occlusion_error.cpp). The table is read by the texture unit's trilinear filter, not
// by the C++'s float weights (docs/shaders.md bounds the difference).

#ifndef IBL_GLSL_RUNTIME
#define IBL_GLSL_RUNTIME 1
#ifndef IBL_GLSL_COMMON
#error "ibl_runtime.glsl: concatenate ibl_common.glsl before it"
#endif
#ifndef IBL_GLSL_LOOKUP
#error "ibl_runtime.glsl: concatenate ibl_lookup.glsl before it"
#endif
#ifndef IBL_GLSL_SHADE
#error "ibl_runtime.glsl: concatenate ibl_shade.glsl before it"
#endif

// ---- dominant direction, horizon, occlusion ------------------------------------------------------

// Frostbite's lerp factor s = (1 - alpha)(sqrt(1 - alpha) + alpha), alpha = r^2 (r clamped to
// [0, 1]): 1 at r = 0 (the mirror direction), 0 at r = 1 (the normal) (dominant_lerp_frostbite).
// The lookup direction is ibl_lobe_direction(n, v, s).
float ibl_dominant_lerp_frostbite(float roughness) {
    float r = ibl_saturate(roughness);
    float a = r * r;
    float s = 1.0 - a;
    return s * (sqrt(s) + a);
}

// Horizon fading saturate(1 + dir.n_g)^2 of a lookup direction against the geometric normal
// (horizon_fade): 1 whenever dir is above the geometric surface.
float ibl_horizon_fade(vec3 dir, vec3 geometric_normal) {
    float h = ibl_saturate(1.0 + dot(dir, geometric_normal));
    return h * h;
}

// Lagarde's specular occlusion saturate((n.v + ao)^(2^(-16 alpha - 1)) - 1 + ao), alpha = r^2;
// n.v, ao, r clamped to [0, 1] (specular_occlusion_lagarde).
float ibl_specular_occlusion_lagarde(float n_dot_v, float ambient_occlusion, float roughness) {
    float ao = ibl_saturate(ambient_occlusion);
    float r = ibl_saturate(roughness);
    float a = r * r;
    return ibl_saturate(pow(ibl_saturate(n_dot_v) + ao, exp2(-16.0 * a - 1.0)) - 1.0 + ao);
}

// ---- specular occlusion table (ibl/runtime/specular_occlusion.hpp) ------------------------------------------------

// Sampler coordinate of (n.v, r, ao) in a size^3 edge-aligned table (ibl_common.glsl, SO LUT):
// (x (size - 1) + 0.5) / size per axis, inputs clamped to [0, 1]; with clamp-to-edge and linear
// filtering, texture() at it is specular_occlusion_table's trilinear read.
vec3 ibl_specular_occlusion_coord(float n_dot_v, float roughness, float ambient_occlusion, int size) {
    vec3 x = ibl_saturate(vec3(n_dot_v, roughness, ambient_occlusion));
    return (x * float(size - 1) + 0.5) / float(size);
}

// The visible fraction of the specular lobe in the cone about n that ao implies, read from the
// table (specular_occlusion_table): inputs clamped to [0, 1], result clamped to [0, 1]; a table
// smaller than 2^3 reads 1 (no occlusion). Multiplies the specular term (Fresnel free).
float ibl_specular_occlusion_table(highp sampler3D so, float n_dot_v, float roughness, float ambient_occlusion) {
    int size = textureSize(so, 0).x;
    if (size < 2) return 1.0;
    return ibl_saturate(textureLod(so, ibl_specular_occlusion_coord(n_dot_v, roughness, ambient_occlusion, size), 0.0).r);
}

// The same table read about a bent normal b (the visible cone's axis; unit n, v, b): the lobe's
// direction measured from b and the aperture from ao without the horizon clip,
// so(saturate(b.R), r, b.n > 0 ? min(1, ao / b.n) : 1), R = 2 (n.v) n - v. At b = n it is
// ibl_specular_occlusion_table(so, n.v, r, ao) for n.v >= 0.
float ibl_specular_occlusion_bent(highp sampler3D so, vec3 n, vec3 v, vec3 bent_normal, float roughness,
                                  float ambient_occlusion) {
    vec3 r = 2.0 * dot(n, v) * n - v;
    float b_r = ibl_saturate(dot(bent_normal, r));
    float b_n = dot(bent_normal, n);
    return ibl_specular_occlusion_table(so, b_r, roughness, b_n > 0.0 ? min(1.0, ambient_occlusion / b_n) : 1.0);
}

// ---- tangent frame (core/frame.hpp) ----------------------------------------------------------------

// Right-handed orthonormal frame (t, b, n), cross(t, b) = n, of a unit n (Duff et al. 2017; make_frame).
struct ibl_frame {
    vec3 t; // tangent (local x)
    vec3 b; // bitangent (local y)
    vec3 n; // normal (local z)
};

ibl_frame ibl_make_frame(vec3 n) {
    float s = n.z >= 0.0 ? 1.0 : -1.0;
    float a = -1.0 / (s + n.z);
    float b = n.x * n.y * a;
    return ibl_frame(vec3(1.0 + s * n.x * n.x * a, s * b, -s * n.x), vec3(b, s + n.y * n.y * a, -n.y), n);
}

// Components of a world vector in the frame; the world vector of local components.
vec3 ibl_frame_to_local(ibl_frame f, vec3 w) { return vec3(dot(w, f.t), dot(w, f.b), dot(w, f.n)); }
vec3 ibl_frame_to_world(ibl_frame f, vec3 l) { return l.x * f.t + l.y * f.b + l.z * f.n; }

// ---- GGX visible normals (sampling/ggx.hpp) -------------------------------------------------------

// w / |w| computed after scaling by the largest |component|; (0, 0, 1) for the zero vector
// (detail::normalize_scaled).
vec3 ibl_normalize_scaled(vec3 w) {
    vec3 aw = abs(w);
    float m = aw.x > aw.y ? (aw.x > aw.z ? aw.x : aw.z) : (aw.y > aw.z ? aw.y : aw.z);
    if (!(m > 0.0)) return vec3(0.0, 0.0, 1.0);
    vec3 s = w * (1.0 / m);
    return s * (1.0 / sqrt(dot(s, s)));
}

// The visible normal h for the tangent-space view v (v.z in [0, 1]) at u in [0, 1)^2, alpha in
// [0, 1] (clamped; alpha <= 0 returns (0, 0, 1)): Dupuy & Benyoub 2023 in the cancellation-free
// form of sampling/ggx.hpp (sample_ggx_vndf, the same expressions in the same order).
vec3 ibl_sample_ggx_vndf(vec3 v, vec2 u, float alpha) {
    if (!(alpha > 0.0)) return vec3(0.0, 0.0, 1.0);
    float a = clamp(alpha, IBL_GGX_MIN_ALPHA, 1.0);
    vec3 vs = ibl_normalize_scaled(vec3(a * v.x, a * v.y, ibl_saturate(v.z)));
    float rho2 = vs.x * vs.x + vs.y * vs.y;
    float rho = sqrt(rho2);
    float e1x = rho > 0.0 ? vs.x / rho : 1.0;
    float e1y = rho > 0.0 ? vs.y / rho : 0.0;
    float one_plus_vz = 1.0 + vs.z;
    float one_minus_vz = rho2 / one_plus_vz;
    float w = 1.0 - u.y;
    float sin_c = sqrt(max(u.y * one_plus_vz * (one_minus_vz + w * one_plus_vz), 0.0));
    float den = rho + sin_c;
    float q = vs.z < 0.5 ? w - vs.z * (1.0 + u.y) : one_minus_vz - u.y * one_plus_vz;
    float rho_minus_sin_c = den > 0.0 ? one_plus_vz * w * q / den : 0.0;
    float psi = 2.0 * IBL_PI * (u.x - 0.5);
    float s_half = sin(0.5 * psi);
    float x1 = rho_minus_sin_c + 2.0 * sin_c * s_half * s_half;
    float x2 = -sin_c * sin(psi);
    vec3 hs = vec3(x1 * e1x - x2 * e1y, x1 * e1y + x2 * e1x, w * one_plus_vz);
    return ibl_normalize_scaled(vec3(a * hs.x, a * hs.y, hs.z));
}

// G1(v) / (n.v) = 2 / (mu + sqrt(mu^2 + alpha^2 (1 - mu^2))), mu = n.v clamped (ggx_g1_over_n_dot_v).
float ibl_ggx_g1_over_n_dot_v(float n_dot_v, float alpha) {
    float mu = ibl_saturate(n_dot_v);
    float a = clamp(alpha, IBL_GGX_MIN_ALPHA, 1.0);
    float a2 = a * a;
    return 2.0 / (mu + sqrt(max(mu * mu + a2 * (1.0 - mu) * (1.0 + mu), 0.0)));
}

// GGX D(h) of a unit tangent-space half vector (sin^2 = h.x^2 + h.y^2; ndf_ggx(vec3)).
float ibl_ndf_ggx_local(vec3 h, float alpha) {
    float a = clamp(alpha, IBL_GGX_MIN_ALPHA, 1.0);
    float a2 = a * a;
    float d = (h.x * h.x + h.y * h.y) + a2 * (h.z * h.z);
    return h.z >= 0.0 && d > 0.0 ? a2 / (IBL_PI * d * d) : 0.0;
}

// Density per unit solid angle of l = reflect(-v, h), h ~ the VNDF: G1(v) D(h) / (4 n.v); 0 where
// v.h <= 0 (ggx_vndf_reflected_pdf).
float ibl_ggx_vndf_reflected_pdf(vec3 v, vec3 h, float alpha) {
    return dot(v, h) > 0.0 ? 0.25 * ibl_ggx_g1_over_n_dot_v(v.z, alpha) * ibl_ndf_ggx_local(h, alpha) : 0.0;
}

// ---- filtered importance sampling at run time ------------------------------------------------------

// The most taps ibl_specular_fis takes (more are clamped to it).
const int IBL_FIS_MAX_TAPS = 64;

// G2(v, l) / G1(v) of height-correlated Smith GGX for cosines in [0, 1]
// (g2_over_g1_height_correlated): 1 at n.v = 0, 0 at n.l = 0.
float ibl_g2_over_g1_height_correlated(float n_dot_v, float n_dot_l, float alpha) {
    float a = clamp(alpha, IBL_GGX_MIN_ALPHA, 1.0);
    float a2 = a * a;
    float mv = ibl_saturate(n_dot_v), ml = ibl_saturate(n_dot_l);
    float sv = sqrt(max(mv * mv + a2 * (1.0 - mv) * (1.0 + mv), 0.0));
    float sl = sqrt(max(ml * ml + a2 * (1.0 - ml) * (1.0 + ml), 0.0));
    float num = (sv + mv) * ml;
    float den = num + a2 * (1.0 - ml) * (1.0 + ml) / (sl + ml) * mv;
    return den > 0.0 ? num / den : 0.0;
}

// The roughness whose normalised LD kernel covers a solid angle omega (sr):
// alpha'^2 = omega / (4 pi - 3 omega); 1 for omega >= pi, 0 for omega <= 0 (fis_footprint_roughness).
float ibl_fis_footprint_roughness(float omega) {
    if (!(omega > 0.0)) return 0.0;
    if (omega >= IBL_PI) return 1.0;
    float a2 = omega / (4.0 * IBL_PI - 3.0 * omega);
    return sqrt(sqrt(a2));
}

// The bits of x in reverse order (reverse_bits; bitfieldReverse is not in GLSL ES 3.00).
uint ibl_reverse_bits(uint x) {
    x = (x << 16u) | (x >> 16u);
    x = ((x & 0x00FF00FFu) << 8u) | ((x & 0xFF00FF00u) >> 8u);
    x = ((x & 0x0F0F0F0Fu) << 4u) | ((x & 0xF0F0F0F0u) >> 4u);
    x = ((x & 0x33333333u) << 2u) | ((x & 0xCCCCCCCCu) >> 2u);
    x = ((x & 0x55555555u) << 1u) | ((x & 0xAAAAAAAAu) >> 1u);
    return x;
}

// Base-2 radical inverse of i as float: the top 24 bits of the mirrored fraction, k / 2^24 exactly
// (radical_inverse<float>).
float ibl_radical_inverse(uint i) { return float(ibl_reverse_bits(i) >> 8u) * 5.9604644775390625e-8; }

// Point k of the runtime tap set of `count` points: (phi_2(k) + 1/(2K) mod 1, (k + 1/2)/K) (fis_tap_point).
vec2 ibl_fis_tap_point(uint k, uint count) {
    float n = float(count > 0u ? count : 1u);
    float x = ibl_radical_inverse(k) + 0.5 / n;
    if (x >= 1.0) x -= 1.0;
    return vec2(x, (float(k) + 0.5) / n);
}

// One tap (runtime_tap): world direction, per-channel weight F G2 / G1 (0 below the horizon) and the
// roughness to read the chain at.
struct ibl_runtime_tap {
    vec3 dir;
    vec3 weight;
    float roughness;
};

// Tap k of `count` along the GGX lobe of roughness r seen from v_local (tangent space of fr,
// v_local.z = n.v >= 0), Schlick F(F0, F90); footprint_scale = c of runtime/specular_models.hpp (fis_tap).
ibl_runtime_tap ibl_fis_tap(ibl_frame fr, vec3 v_local, float roughness, uint k, uint count, float footprint_scale,
                            vec3 f0, vec3 f90) {
    ibl_runtime_tap t = ibl_runtime_tap(vec3(0.0, 0.0, 1.0), vec3(0.0), 0.0);
    float r = ibl_saturate(roughness);
    float alpha = clamp(r * r, IBL_GGX_MIN_ALPHA, 1.0);
    vec3 h = ibl_sample_ggx_vndf(v_local, ibl_fis_tap_point(k, count), alpha);
    float v_dot_h = dot(v_local, h);
    vec3 l = 2.0 * v_dot_h * h - v_local;
    t.dir = ibl_frame_to_world(fr, l);
    if (!(l.z > 0.0) || !(v_dot_h > 0.0)) return t; // clipped at the horizon: weight 0
    float pdf = ibl_ggx_vndf_reflected_pdf(v_local, h, alpha);
    float n = float(count > 0u ? count : 1u);
    t.roughness = pdf > 0.0 ? ibl_fis_footprint_roughness(footprint_scale / (n * pdf)) : 1.0;
    t.weight = ibl_fresnel_schlick(ibl_saturate(v_dot_h), f0, f90) * ibl_g2_over_g1_height_correlated(v_local.z, l.z, alpha);
    return t;
}

// The taps' combination (fis_combine): normalised, albedo times the weighted mean of the tap values
// per channel (albedo fallback where a channel's weights are all 0), or plain, sum w LD / K.
vec3 ibl_fis_combine(vec3 weighted_sum, vec3 weight_sum, int count, bool normalise, vec3 albedo, vec3 fallback) {
    if (!normalise) return weighted_sum / float(count > 0 ? count : 1);
    bvec3 pos = greaterThan(weight_sum, vec3(0.0));
    vec3 q = vec3(pos.x ? weighted_sum.x / weight_sum.x : fallback.x, pos.y ? weighted_sum.y / weight_sum.y : fallback.y,
                  pos.z ? weighted_sum.z / weight_sum.z : fallback.z);
    return albedo * q;
}

// Specular radiance by runtime filtered importance sampling of the chain (specular_fis): `taps`
// taps (clamped to [1, IBL_FIS_MAX_TAPS]) read by the lookup d (the C++ default: textbook),
// footprint scale c, the normalised or the plain estimator; n, v unit, dfg = (A, B) at (n.v, r)
// (used by the normalised estimator only). Where every weight of a channel is 0 (normalised)
// the chain at R and r stands in for the taps' mean.
vec3 ibl_specular_fis(samplerCube chain, ibl_specular_desc d, int taps, float footprint_scale, bool normalise, vec3 n,
                      vec3 v, float roughness, vec3 f0, vec3 f90, vec2 dfg) {
    ibl_frame fr = ibl_make_frame(n);
    vec3 vl = ibl_frame_to_local(fr, v);
    vl.z = vl.z > 0.0 ? vl.z : 0.0;
    float len2 = dot(vl, vl);
    vl = len2 > 0.0 ? vl / sqrt(len2) : vec3(0.0, 0.0, 1.0);
    int count = clamp(taps, 1, IBL_FIS_MAX_TAPS);
    vec3 sum = vec3(0.0), wsum = vec3(0.0);
    for (int k = 0; k < IBL_FIS_MAX_TAPS; ++k) {
        if (k >= count) break;
        ibl_runtime_tap t = ibl_fis_tap(fr, vl, roughness, uint(k), uint(count), footprint_scale, f0, f90);
        if (t.weight == vec3(0.0)) continue;
        sum += t.weight * ibl_specular_lookup(chain, t.dir, t.roughness, d);
        wsum += t.weight;
    }
    vec3 albedo = ibl_split_sum_albedo(f0, f90, dfg);
    bool need_fallback = normalise && !(wsum.x > 0.0 && wsum.y > 0.0 && wsum.z > 0.0);
    vec3 fb = vec3(0.0);
    if (need_fallback) fb = ibl_specular_lookup(chain, ibl_frame_to_world(fr, vec3(-vl.x, -vl.y, vl.z)), roughness, d);
    return ibl_fis_combine(sum, wsum, count, normalise, albedo, fb);
}

// ---- fitted taps (bake/lobe_fit.hpp, two taps) -------------------------------------------------

// The unit tangent of n in the plane of incidence, towards R; make_frame(n).t when R is (nearly)
// n (incidence_tangent).
vec3 ibl_incidence_tangent(vec3 n, vec3 r_dir) {
    vec3 t = r_dir - dot(n, r_dir) * n;
    float len2 = dot(t, t);
    return len2 > 1e-12 ? t * (1.0 / sqrt(len2)) : ibl_make_frame(n).t;
}

// A fitted tap's angle from n towards R (radians) from its table value f: f acos(n.v)
// (lobe_tap_angle: 1 = at R, 0 = at n).
float ibl_lobe_tap_angle(float stored, float n_dot_v) { return stored * acos(ibl_saturate(n_dot_v)); }

// The direction of a fitted tap at angle a (radians) from n towards the tangent t:
// normalize(cos(a) n + sin(a) t).
vec3 ibl_lobe_tap_direction(vec3 n, vec3 t, float a) { return normalize(cos(a) * n + sin(a) * t); }

// The products at a shading point through the two-tap fitted model (specular_lobe_taps of a 2-tap
// lobe_taps_lut): at (n.v, r) one bilinear read of each table (taps_a = A, B, f0, roughness0;
// taps_b = weight0, f1, roughness1, weight1; f = angle / acos(n.v); ibl_common.glsl), then
//     LD = sum_k w_k LD(d_k, r_k) / sum_k w_k,   d_k = ibl_lobe_tap_direction(n, t, f_k acos(n.v))
// with t = ibl_incidence_tangent(n, R), each LD by the chain lookup sd (LD(R, r) where no weight
// is > 0), and (A, B) as the sample's dfg; E/pi passed through. ibl_ambient on it is the two-tap
// model. Cost: two chain lookups and two RGBA table reads.
ibl_sample ibl_lobe_taps2_sample(samplerCube chain, ibl_specular_desc sd, sampler2D taps_a, sampler2D taps_b,
                                 ibl_dfg_layout lay, vec3 n, vec3 v, float roughness, vec3 irradiance_over_pi) {
    vec3 r_dir = 2.0 * dot(n, v) * n - v;
    float n_dot_v = ibl_saturate(dot(n, v));
    vec2 st = ibl_dfg_lut_coord(n_dot_v, roughness, textureSize(taps_a, 0).x, lay);
    vec4 pa = textureLod(taps_a, st, 0.0);
    vec4 pb = textureLod(taps_b, st, 0.0);
    vec3 t = ibl_incidence_tangent(n, r_dir);
    vec3 sum = vec3(0.0);
    float wsum = 0.0;
    if (pb.x > 0.0) {
        sum += pb.x * ibl_specular_lookup(chain, ibl_lobe_tap_direction(n, t, ibl_lobe_tap_angle(pa.z, n_dot_v)), pa.w, sd);
        wsum += pb.x;
    }
    if (pb.w > 0.0) {
        sum += pb.w * ibl_specular_lookup(chain, ibl_lobe_tap_direction(n, t, ibl_lobe_tap_angle(pb.y, n_dot_v)), pb.z, sd);
        wsum += pb.w;
    }
    vec3 ld = wsum > 0.0 ? sum / wsum : ibl_specular_lookup(chain, r_dir, roughness, sd);
    return ibl_sample(ld, irradiance_over_pi, pa.xy);
}

// The two-tap model's specular (F0 A + F90 B) LD of ibl_lobe_taps2_sample.
vec3 ibl_specular_lobe_taps2(samplerCube chain, ibl_specular_desc sd, sampler2D taps_a, sampler2D taps_b,
                             ibl_dfg_layout lay, vec3 n, vec3 v, float roughness, vec3 f0, vec3 f90) {
    ibl_sample s = ibl_lobe_taps2_sample(chain, sd, taps_a, taps_b, lay, n, v, roughness, vec3(0.0));
    return ibl_specular_ibl(s.ld, f0, f90, s.dfg);
}

// ---- the two-part lobe model (runtime/specular_models.hpp specular_lobe_pair; ibl-bake --runtime lobe) ---------

// The effective LD (F0 A LD_a + F90 B LD_b) / (F0 A + F90 B) per channel (LD_a where that albedo
// is 0): LD (F0 A + F90 B) of it, e.g. ibl_ambient, is the two-part model (lobe_pair_ld).
vec3 ibl_lobe_pair_ld(vec3 ld_a, vec3 ld_b, vec3 f0, vec3 f90, vec2 ab) {
    vec3 wa = f0 * ab.x, wb = f90 * ab.y, den = wa + wb;
    vec3 mixed = (wa * ld_a + wb * ld_b) / max(den, vec3(1e-30));
    return vec3(den.x > 0.0 ? mixed.x : ld_a.x, den.y > 0.0 ? mixed.y : ld_a.y, den.z > 0.0 ? mixed.z : ld_a.z);
}

// The B kernel's direction: at a = clamp(f_B acos(n.v), 0, pi/2) from n towards R,
// cos(a) n + sin(a) t, t = ibl_incidence_tangent(n, R) (lobe_pair_direction_b).
vec3 ibl_lobe_pair_direction_b(vec3 n, vec3 r_dir, float stored, float n_dot_v) {
    float a = clamp(ibl_lobe_tap_angle(stored, n_dot_v), 0.0, 1.5707963267948966);
    vec3 d = cos(a) * n + sin(a) * ibl_incidence_tangent(n, r_dir);
    return d * (1.0 / sqrt(dot(d, d)));
}

// The reads of the two-part lobe model at (n.v, r): pa = (A, B, s, r_eff) of lobe_lut, ld_a the LD
// of the A part's kernel, ld_b that of the B part's (lobe_lut_b). Shared by the two functions below.
void ibl_lobe_pair_reads(samplerCube chain, ibl_specular_desc sd, sampler2D lobe_lut, sampler2D lobe_lut_b,
                         ibl_dfg_layout lay, vec3 n, vec3 v, float roughness, out vec4 pa, out vec3 ld_a, out vec3 ld_b) {
    float n_dot_v = ibl_saturate(dot(n, v));
    vec3 r_dir = 2.0 * dot(n, v) * n - v;
    pa = ibl_lobe_lut_lookup(lobe_lut, n_dot_v, roughness, lay);
    vec4 pb = ibl_lobe_lut_lookup(lobe_lut_b, n_dot_v, roughness, lay);
    ld_a = ibl_specular_lookup(chain, ibl_lerp_direction(n, r_dir, pa.z), pa.w, sd);
    ld_b = ibl_specular_lookup(chain, ibl_lobe_pair_direction_b(n, r_dir, pb.x, n_dot_v), pb.y, sd);
}

// The products at a shading point through the two-part lobe model for a material (F0, F90): at
// (n.v, r) (A, B, s, r_eff) = ibl_lobe_lut_lookup(lobe_lut) and (f_B, r_B) = ibl_lobe_lut_lookup(
// lobe_lut_b) (lobe_lut.hpp, lobe_lut_b.hpp), LD_a at ibl_lobe_direction(n, v, s) and r_eff, LD_b at
// ibl_lobe_pair_direction_b and r_B; the sample's ld is ibl_lobe_pair_ld of them, its dfg (A, B);
// E/pi passed through. ibl_ambient on it (with the same F0, F90) is the two-part model:
// F0 A LD_a + F90 B LD_b. Cost: two chain lookups and two RGBA table reads.
ibl_sample ibl_lobe_pair_sample(samplerCube chain, ibl_specular_desc sd, sampler2D lobe_lut, sampler2D lobe_lut_b,
                                ibl_dfg_layout lay, vec3 n, vec3 v, float roughness, vec3 f0, vec3 f90,
                                vec3 irradiance_over_pi) {
    vec4 pa;
    vec3 ld_a, ld_b;
    ibl_lobe_pair_reads(chain, sd, lobe_lut, lobe_lut_b, lay, n, v, roughness, pa, ld_a, ld_b);
    return ibl_sample(ibl_lobe_pair_ld(ld_a, ld_b, f0, f90, pa.xy), irradiance_over_pi, pa.xy);
}

// The two-part model's specular F0 A LD(d_A, r_eff) + F90 B LD(d_B, r_B) (specular_lobe_pair).
vec3 ibl_specular_lobe_pair(samplerCube chain, ibl_specular_desc sd, sampler2D lobe_lut, sampler2D lobe_lut_b,
                            ibl_dfg_layout lay, vec3 n, vec3 v, float roughness, vec3 f0, vec3 f90) {
    vec4 pa;
    vec3 ld_a, ld_b;
    ibl_lobe_pair_reads(chain, sd, lobe_lut, lobe_lut_b, lay, n, v, roughness, pa, ld_a, ld_b);
    return f0 * pa.x * ld_a + f90 * pa.y * ld_b;
}

#endif // IBL_GLSL_RUNTIME
