// ibl/glsl/ibl_shade.glsl — the runtime combination of the products (GLSL mirror of
// ibl/runtime/shade.hpp): material terms (metallic workflow), the single-scattering ambient (Karis 2013,
// kD = (1 - F_roughness)(1 - metallic)), the multiple-scattering ambient (Fdez-Aguera 2019:
// FssEss LD + (FmsEms + diffuse_albedo Edss) E/pi), direct Cook-Torrance lights (directional,
// point) and disk lights (a sun: exact cap irradiance, widened-lobe specular). The formulas and
// their derivations are in runtime/shade.hpp's header; every function here is the same expression in the
// same order. Needs ibl_common.glsl first;
// ibl_lookup_sample, ibl_lobe_sample and ibl_specular_lobe additionally need ibl_lookup.glsl
// before this file.

#ifndef IBL_GLSL_SHADE
#define IBL_GLSL_SHADE 1
#ifndef IBL_GLSL_COMMON
#error "ibl_shade.glsl: concatenate ibl_common.glsl before it"
#endif

// ---- material -------------------------------------------------------------------------------------

// A metallic-roughness material (glTF 2.0; pbr_material). roughness is perceptual.
struct ibl_material {
    vec3 base_color;
    float metallic;
    float roughness;
    float ambient_occlusion;
    float dielectric_f0; // F0 of the non-metal part (0.04 = IOR 1.5)
    vec3 f90;            // Schlick's F90 (1 for physical Fresnel)
};

// A material with the library's defaults (dielectric F0 0.04, F90 1, ao 1).
ibl_material ibl_make_material(vec3 base_color, float metallic, float roughness) {
    return ibl_material(base_color, metallic, roughness, 1.0, 0.04, vec3(1.0));
}

// The derived coefficients (material_terms).
struct ibl_material_terms {
    vec3 f0;             // mix(dielectric_f0, base_color, metallic)
    vec3 f90;            // as given
    vec3 base_color;     // as given
    vec3 diffuse_albedo; // base_color (1 - metallic)
    float metallic;      // clamped to [0, 1]
    float roughness;     // clamped to [0, 1]
    float ambient_occlusion; // clamped to [0, 1]
};

float ibl_lerp(float a, float b, float t) { return a + t * (b - a); } // exact at t = 0 and 1
vec3 ibl_lerp(vec3 a, vec3 b, float t) { return a + t * (b - a); }
vec3 ibl_lerp(vec3 a, vec3 b, vec3 t) { return a + t * (b - a); }

ibl_material_terms ibl_resolve_material(ibl_material m) {
    float metal = ibl_saturate(m.metallic);
    vec3 f0 = ibl_lerp(vec3(m.dielectric_f0), m.base_color, metal);
    return ibl_material_terms(f0, m.f90, m.base_color, m.base_color * (1.0 - metal), metal,
                              ibl_saturate(m.roughness), ibl_saturate(m.ambient_occlusion));
}

// ---- Fresnel -------------------------------------------------------------------------------------

float ibl_pow5(float x) {
    float x2 = x * x;
    return x2 * x2 * x;
}

// Schlick: F0 + (F90 - F0)(1 - cos)^5 per channel (F(1) = F0, F(0) = F90 exactly).
vec3 ibl_fresnel_schlick(float cos_theta, vec3 f0, vec3 f90) {
    return ibl_lerp(f0, f90, ibl_pow5(1.0 - ibl_saturate(cos_theta)));
}

// Roughness-aware Schlick (Lagarde 2011): F90 = max(1 - r, F0) per channel.
vec3 ibl_fresnel_schlick_roughness(float cos_theta, vec3 f0, float roughness) {
    return ibl_fresnel_schlick(cos_theta, f0, max(vec3(1.0 - ibl_saturate(roughness)), f0));
}

// ---- ambient: single scattering --------------------------------------------------------------------

// kD = (1 - F)(1 - metallic), F the ambient Fresnel ibl_fresnel_schlick_roughness(n.v, F0, r).
vec3 ibl_ambient_kd(vec3 fresnel, float metallic) { return (vec3(1.0) - fresnel) * (1.0 - ibl_saturate(metallic)); }

// (A, B) clamped to [0, 1].
vec2 ibl_saturate_dfg(vec2 dfg) { return clamp(dfg, vec2(0.0), vec2(1.0)); }

// F0 A + F90 B: the directional albedo of the specular lobe with Schlick's Fresnel.
vec3 ibl_split_sum_albedo(vec3 f0, vec3 f90, vec2 dfg) {
    vec2 ab = ibl_saturate_dfg(dfg);
    return f0 * ab.x + f90 * ab.y;
}

// Split-sum specular LD (F0 A + F90 B).
vec3 ibl_specular_ibl(vec3 ld, vec3 f0, vec3 f90, vec2 dfg) { return ld * ibl_split_sum_albedo(f0, f90, dfg); }

// Lambert diffuse from E/pi: albedo (E/pi).
vec3 ibl_diffuse_ibl_over_pi(vec3 albedo, vec3 irradiance_over_pi) { return albedo * irradiance_over_pi; }

// (kD diffuse + specular) ao.
vec3 ibl_ambient_single_scatter(vec3 kd, vec3 diffuse, vec3 specular, float ambient_occlusion) {
    return (kd * diffuse + specular) * ibl_saturate(ambient_occlusion);
}

// ---- ambient: multiple scattering (Fdez-Aguera 2019) ------------------------------------------------

// Cosine-weighted hemispherical mean of Schlick's Fresnel: F0 + (F90 - F0) / 21.
vec3 ibl_fresnel_schlick_average(vec3 f0, vec3 f90) { return f0 + (f90 - f0) * (1.0 / 21.0); }

struct ibl_multiscatter_terms {
    vec3 fss_ess;          // F0 A + F90 B (weights LD)
    vec3 fms_ems;          // Ems FssEss Favg / (1 - Favg Ems) (weights E/pi)
    vec3 diffuse_fraction; // Edss = 1 - (FssEss + FmsEms), clamped (times diffuse_albedo, weights E/pi)
};

// FmsEms = Ems FssEss Favg / (Ess + Ems (1 - Favg)) per channel (multiscatter_fms_ems).
vec3 ibl_multiscatter_fms_ems(vec3 fss_ess, float ess, vec3 f_avg) {
    float ems = 1.0 - ess;
    vec3 den = ess + ems * (vec3(1.0) - f_avg);
    return ems * fss_ess * f_avg / max(den, vec3(IBL_MIN_NORMAL));
}

ibl_multiscatter_terms ibl_multiscatter(vec3 f0, vec3 f90, vec2 dfg) {
    vec2 ab = ibl_saturate_dfg(dfg);
    float ess = ibl_saturate(ab.x + ab.y);
    vec3 fss_ess = f0 * ab.x + f90 * ab.y;
    vec3 fms_ems = ibl_multiscatter_fms_ems(fss_ess, ess, ibl_fresnel_schlick_average(f0, f90));
    return ibl_multiscatter_terms(fss_ess, fms_ems, ibl_saturate(vec3(1.0) - (fss_ess + fms_ems)));
}

// FssEss LD + FmsEms E/pi (no diffuse lobe).
vec3 ibl_specular_ibl_multiscatter(ibl_multiscatter_terms ms, vec3 ld, vec3 irradiance_over_pi) {
    return ms.fss_ess * ld + ms.fms_ems * irradiance_over_pi;
}

// (FssEss LD + (FmsEms + diffuse_albedo Edss) E/pi) ao.
vec3 ibl_ambient_multiscatter(ibl_multiscatter_terms ms, vec3 diffuse_albedo, vec3 ld, vec3 irradiance_over_pi,
                              float ambient_occlusion) {
    vec3 diffuse_weight = ms.fms_ems + diffuse_albedo * ms.diffuse_fraction;
    return (ms.fss_ess * ld + diffuse_weight * irradiance_over_pi) * ibl_saturate(ambient_occlusion);
}

// ---- the products at one point, and the ambient of a material (ibl_sample, pbr_shader::ambient) ----

struct ibl_sample {
    vec3 ld;                 // prefiltered radiance at (R, r)
    vec3 irradiance_over_pi; // E(n)/pi
    vec2 dfg;                // (A, B) at (n.v, r)
};

// Ambient outgoing radiance at view cosine n.v: multiple scattering (the bake preview's) or single.
vec3 ibl_ambient(ibl_material_terms m, float n_dot_v, ibl_sample s, bool multiple_scattering) {
    if (multiple_scattering)
        return ibl_ambient_multiscatter(ibl_multiscatter(m.f0, m.f90, s.dfg), m.diffuse_albedo, s.ld,
                                        s.irradiance_over_pi, m.ambient_occlusion);
    vec3 f = ibl_fresnel_schlick_roughness(ibl_saturate(n_dot_v), m.f0, m.roughness);
    return ibl_ambient_single_scatter(ibl_ambient_kd(f, m.metallic),
                                      ibl_diffuse_ibl_over_pi(m.base_color, s.irradiance_over_pi),
                                      ibl_specular_ibl(s.ld, m.f0, m.f90, s.dfg), m.ambient_occlusion);
}

#ifdef IBL_GLSL_LOOKUP
// The products at a shading point, looked up as ibl_lookup_sample does: LD at R = reflect(-v, n)
// and r, (A, B) at (n.v, r); E/pi passed through (ibl_sh_irradiance_over_pi or an irradiance map).
ibl_sample ibl_lookup_sample(samplerCube chain, ibl_specular_desc sd, sampler2D lut, ibl_dfg_layout lay, vec3 n,
                             vec3 v, float roughness, vec3 irradiance_over_pi) {
    float n_dot_v = ibl_saturate(dot(n, v));
    vec3 r_dir = 2.0 * dot(n, v) * n - v;
    vec3 dfg = ibl_dfg_lookup(lut, n_dot_v, roughness, lay);
    return ibl_sample(ibl_specular_lookup(chain, r_dir, roughness, sd), irradiance_over_pi, dfg.xy);
}

// The products at a shading point through the lobe LUT (ibl/runtime/specular_models.hpp specular_lobe): with
// (A, B, s, r_eff) = ibl_lobe_lut_lookup(lobe_lut, n.v, r), LD at normalize(lerp(n, R, s)) and
// r_eff, (A, B) as the sample's dfg; E/pi passed through. ibl_ambient on it is the lobe model.
ibl_sample ibl_lobe_sample(samplerCube chain, ibl_specular_desc sd, sampler2D lobe_lut, ibl_dfg_layout lay, vec3 n,
                           vec3 v, float roughness, vec3 irradiance_over_pi) {
    vec4 p = ibl_lobe_lut_lookup(lobe_lut, ibl_saturate(dot(n, v)), roughness, lay);
    vec3 ld = ibl_specular_lookup(chain, ibl_lobe_direction(n, v, p.z), p.w, sd);
    return ibl_sample(ld, irradiance_over_pi, p.xy);
}

// The lobe model's specular LD(normalize(lerp(n, R, s)), r_eff) (F0 A + F90 B) (specular_lobe).
vec3 ibl_specular_lobe(samplerCube chain, ibl_specular_desc sd, sampler2D lobe_lut, ibl_dfg_layout lay, vec3 n, vec3 v,
                       float roughness, vec3 f0, vec3 f90) {
    ibl_sample s = ibl_lobe_sample(chain, sd, lobe_lut, lay, n, v, roughness, vec3(0.0));
    return ibl_specular_ibl(s.ld, f0, f90, s.dfg);
}
#endif

// ---- direct lights (Cook-Torrance) ---------------------------------------------------------------

struct ibl_light_cosines {
    float n_dot_l, n_dot_h, v_dot_h; // clamped to [0, 1]
};

// The cosines of l seen from v about n (unit vectors); l = -v gives n.h = v.h = 0.
ibl_light_cosines ibl_make_light_cosines(vec3 n, vec3 v, vec3 l) {
    vec3 s = v + l;
    float len2 = dot(s, s);
    vec3 h = s * (1.0 / sqrt(max(len2, IBL_MIN_NORMAL)));
    return ibl_light_cosines(ibl_saturate(dot(n, l)), ibl_saturate(dot(n, h)), ibl_saturate(dot(v, h)));
}

// GGX D(h) from n.h and alpha = r^2 (alpha clamped to [2^-31, 1]); 0 for n.h < 0.
float ibl_ndf_ggx(float n_dot_h, float alpha) {
    float a = clamp(alpha, IBL_GGX_MIN_ALPHA, 1.0);
    float a2 = a * a;
    float c = ibl_saturate(n_dot_h);
    float sin2 = (1.0 - c) * (1.0 + c);
    float d = sin2 + a2 * c * c;
    return n_dot_h >= 0.0 ? a2 / (IBL_PI * d * d) : 0.0;
}

// Schlick-GGX k for analytic lights: (r + 1)^2 / 8.
float ibl_k_direct(float roughness) {
    float r = ibl_saturate(roughness);
    return (r + 1.0) * (r + 1.0) / 8.0;
}

// Height-correlated Smith visibility G2 / (4 n.v n.l) for GGX (the image-based products' model):
// 0.5 / (n.l sqrt(n.v^2 + a^2 (1 - n.v^2)) + n.v sqrt(n.l^2 + a^2 (1 - n.l^2))), the denominator
// floored at IBL_MIN_NORMAL (finite at the corner n.v = n.l = 0).
float ibl_v_smith_ggx_correlated(float n_dot_v, float n_dot_l, float alpha) {
    float a = clamp(alpha, IBL_GGX_MIN_ALPHA, 1.0);
    float a2 = a * a;
    float mv = ibl_saturate(n_dot_v), ml = ibl_saturate(n_dot_l);
    float den = ml * sqrt(max(mv * mv + a2 * (1.0 - mv) * (1.0 + mv), 0.0)) +
                mv * sqrt(max(ml * ml + a2 * (1.0 - ml) * (1.0 + ml), 0.0));
    return 0.5 / max(den, IBL_MIN_NORMAL);
}

// Schlick-GGX visibility G / (4 n.v n.l) with the cosines cancelled: 1 / (4 dv dl).
float ibl_v_smith_schlick_ggx(float n_dot_v, float n_dot_l, float k) {
    float kc = clamp(k, IBL_SCHLICK_MIN_K, 1.0);
    float mv = ibl_saturate(n_dot_v), ml = ibl_saturate(n_dot_l);
    float dv = mv + kc * (1.0 - mv);
    float dl = ml + kc * (1.0 - ml);
    return 1.0 / (4.0 * dv * dl);
}

// Cook-Torrance specular D V F (per steradian).
vec3 ibl_specular_brdf_direct(float n_dot_v, ibl_light_cosines c, vec3 f0, vec3 f90, float roughness) {
    float r = ibl_saturate(roughness);
    float d = ibl_ndf_ggx(c.n_dot_h, r * r);
    float vis = ibl_v_smith_schlick_ggx(n_dot_v, c.n_dot_l, ibl_k_direct(roughness));
    return (d * vis) * ibl_fresnel_schlick(c.v_dot_h, f0, f90);
}

// Full BRDF: kD base_color / pi + D V F, kD = (1 - F(v.h))(1 - metallic).
vec3 ibl_brdf_direct(float n_dot_v, ibl_light_cosines c, ibl_material_terms m) {
    vec3 f = ibl_fresnel_schlick(c.v_dot_h, m.f0, m.f90);
    vec3 kd = ibl_ambient_kd(f, m.metallic);
    float d = ibl_ndf_ggx(c.n_dot_h, m.roughness * m.roughness);
    float vis = ibl_v_smith_schlick_ggx(n_dot_v, c.n_dot_l, ibl_k_direct(m.roughness));
    return kd * (m.base_color * IBL_INV_PI) + (d * vis) * f;
}

// f(v, l) E_perp n.l for unit n, v, l.
vec3 ibl_shade_light(vec3 n, vec3 v, vec3 l, vec3 e_perp, ibl_material_terms m) {
    ibl_light_cosines c = ibl_make_light_cosines(n, v, l);
    float n_dot_v = ibl_saturate(dot(n, v));
    return ibl_brdf_direct(n_dot_v, c, m) * e_perp * c.n_dot_l;
}

// A directional light: unit direction TOWARDS the light, irradiance on a surface facing it.
vec3 ibl_shade_directional(vec3 n, vec3 v, vec3 direction, vec3 irradiance, ibl_material_terms m) {
    return ibl_shade_light(n, v, direction, irradiance, m);
}

// A point light of intensity I at `position`: E_perp = I / max(d^2, 1e-4) (0 at the light itself).
vec3 ibl_shade_point(vec3 p, vec3 n, vec3 v, vec3 position, vec3 intensity, ibl_material_terms m) {
    vec3 to_light = position - p;
    float d2 = dot(to_light, to_light);
    vec3 l = d2 > 0.0 ? to_light * (1.0 / sqrt(d2)) : vec3(0.0);
    return ibl_shade_light(n, v, l, intensity * (1.0 / max(d2, 1e-4)), m);
}

// ---- disk lights (a sun: a uniform spherical cap; runtime/shade.hpp's "Disk lights" section) ---------------

// A distant uniform disk: unit direction TOWARDS its centre, solid angle Omega = 2 pi (1 - cos r)
// in [0, 2 pi] sr, radiance L (lights.json of ibl-bake: "direction", "solid_angle", "radiance").
struct ibl_disk_light {
    vec3 direction;
    float solid_angle;
    vec3 radiance;
};

// 1 - cos r of a cap of solid angle omega (clamped to [0, 1]: at most a hemisphere).
float ibl_cap_one_minus_cos(float omega) { return ibl_saturate(omega * (0.5 * IBL_INV_PI)); }

// sin^2 r = c (2 - c), c = 1 - cos r (no cancellation for small r).
float ibl_cap_sin2(float omega) {
    float c = ibl_cap_one_minus_cos(omega);
    return c * (2.0 - c);
}

// atan(u) - u for u >= 0 without cancellation for small u (series below 1/4, 13 terms).
float ibl_atan_minus_identity(float u) {
    if (u >= 0.25) return atan(u) - u;
    float u2 = u * u;
    float s = 0.0;
    for (int k = 12; k >= 0; --k) s = 1.0 / float(2 * k + 3) - u2 * s;
    return -u * u2 * s;
}

// E / L of a uniform cap of unit radiance at cos(theta) = n.d from its centre, sin^2 r = sin2_r
// (Snyder 1996 in Frostbite's form, rewritten without cancellation; exact, also when the cap
// straddles the horizon). 0 for sin2_r <= 0.
float ibl_cap_irradiance(float cos_theta, float sin2_r) {
    if (!(sin2_r > 0.0)) return 0.0;
    float ct = clamp(cos_theta, -1.0, 1.0);
    if (ct * ct >= sin2_r) return IBL_PI * sin2_r * (ct > 0.0 ? ct : 0.0);
    float s2 = sin2_r < 1.0 ? sin2_r : 1.0;
    float st = sqrt((1.0 - ct) * (1.0 + ct)); // >= cos r > 0 in this band (or r = pi/2)
    float x = sqrt((1.0 - s2) / s2);          // cot r
    float y = clamp(-x * ct / (st > IBL_MIN_NORMAL ? st : IBL_MIN_NORMAL), -1.0, 1.0);
    float t = st * sqrt((1.0 - y) * (1.0 + y));
    float u = x > 0.0 ? t / x : 0.0;
    // r = pi/2 (x = 0): the limit s2 ct acos(y) + pi/2.
    float e = x > 0.0 ? s2 * (ct * acos(y) + u) + ibl_atan_minus_identity(u) : s2 * ct * acos(y) + 0.5 * IBL_PI;
    return e > 0.0 ? e : 0.0;
}

// E(n) of a disk light at unit normal n (exact for a uniform cap).
vec3 ibl_disk_light_irradiance(vec3 n, ibl_disk_light light) {
    return light.radiance * ibl_cap_irradiance(dot(n, light.direction), ibl_cap_sin2(light.solid_angle));
}

// The irradiance it delivers on a surface facing it: L pi sin^2 r.
vec3 ibl_disk_light_normal_irradiance(ibl_disk_light light) {
    return light.radiance * (IBL_PI * ibl_cap_sin2(light.solid_angle));
}

// Cook-Torrance specular of a disk light by the widened lobe: D(n.h; alpha') V F(v.h) E_perp n.d at
// the cap centre d, alpha'^2 = alpha^2 + tan^2(r/2) / max(v.h, 1/20) (alpha' <= 1).
vec3 ibl_disk_light_specular(vec3 n, vec3 v, ibl_disk_light light, vec3 f0, vec3 f90, float roughness) {
    float r = ibl_saturate(roughness);
    ibl_light_cosines c = ibl_make_light_cosines(n, v, light.direction);
    float c1 = ibl_cap_one_minus_cos(light.solid_angle);
    float tan2_half = c1 / (2.0 - c1); // tan^2(r/2)
    float vh = c.v_dot_h > 0.05 ? c.v_dot_h : 0.05;
    float a = clamp(r * r, IBL_GGX_MIN_ALPHA, 1.0);
    float alpha_w = sqrt(a * a + tan2_half / vh);
    float d = ibl_ndf_ggx(c.n_dot_h, alpha_w < 1.0 ? alpha_w : 1.0);
    float vis = ibl_v_smith_ggx_correlated(ibl_saturate(dot(n, v)), c.n_dot_l, a);
    return (d * vis * c.n_dot_l) * ibl_fresnel_schlick(c.v_dot_h, f0, f90) * ibl_disk_light_normal_irradiance(light);
}

// Outgoing radiance from a disk light: the exact cap irradiance times kD base_color / pi
// (kD = (1 - F(v.h))(1 - metallic), h towards the cap centre) plus ibl_disk_light_specular.
vec3 ibl_shade_disk(vec3 n, vec3 v, ibl_disk_light light, ibl_material_terms m) {
    ibl_light_cosines c = ibl_make_light_cosines(n, v, light.direction);
    vec3 kd = ibl_ambient_kd(ibl_fresnel_schlick(c.v_dot_h, m.f0, m.f90), m.metallic);
    return kd * (m.base_color * IBL_INV_PI) * ibl_disk_light_irradiance(n, light) +
           ibl_disk_light_specular(n, v, light, m.f0, m.f90, m.roughness);
}

#endif // IBL_GLSL_SHADE
