// ibl/glsl/ibl_lookup.glsl — the runtime lookups of the baked products (GLSL mirror of
// ibl/runtime/lookup.hpp and runtime/roughness_mip.hpp): the prefiltered specular chain at any
// roughness (level taps + blend; the default log-geometric two-level blend and the textbook
// textureLod), the DFG table at any (n.v, r) in its layout (dfg_lut_coord), and the lobe LUT of
// ibl/runtime/specular_models.hpp (lobe_lut_lookup, lerp_direction) read in the same layout. Needs
// ibl_common.glsl first (conventions there).

#ifndef IBL_GLSL_LOOKUP
#define IBL_GLSL_LOOKUP 1
#ifndef IBL_GLSL_COMMON
#error "ibl_lookup.glsl: concatenate ibl_common.glsl before it"
#endif

// ---- roughness <-> lod (roughness_mapping) -----------------------------------------------------
const int IBL_MAPPING_LINEAR = 0;   // r = lod / m
const int IBL_MAPPING_FILAMENT = 1; // lod = r (2 - r) m

float ibl_roughness_from_lod(int mapping, float lod, float max_lod) {
    if (!(max_lod > 0.0)) return 0.0;
    float x = ibl_saturate(lod / max_lod);
    if (mapping == IBL_MAPPING_FILAMENT) return x / (1.0 + sqrt(max(1.0 - x, 0.0)));
    return x;
}

float ibl_lod_from_roughness(int mapping, float roughness, float max_lod) {
    if (!(max_lod > 0.0)) return 0.0;
    float r = ibl_saturate(roughness);
    if (mapping == IBL_MAPPING_FILAMENT) return r * (2.0 - r) * max_lod;
    return r * max_lod;
}

// ---- specular ------------------------------------------------------------------------------------
const int IBL_WEIGHT_LOD = 0;   // t = frac(lod(r))                      (level_weight::lod)
const int IBL_WEIGHT_POWER = 1; // t linear in r^p between the levels    (level_weight::power)
const int IBL_WEIGHT_LOG = 2;   // t linear in log r (lod below level 1) (level_weight::log)
const int IBL_INTERP_LINEAR = 0;      // (1 - t) L_l + t L_{l+1}: one trilinear textureLod
const int IBL_INTERP_CATMULL_ROM = 1; // four levels, uniform Catmull-Rom in the level index
const int IBL_INTERP_GEOMETRIC = 2;   // L_l^(1 - t) L_{l+1}^t per channel (linear where one <= 0)

// How the chain is read (specular_lookup_desc plus the stored range of the file).
struct ibl_specular_desc {
    int virtual_levels;    // V: levels of the chain the policy is defined on (plan.runtime)
    int first_level;       // virtual level held by stored level 0
    int stored_levels;     // levels in the texture
    int mapping;           // IBL_MAPPING_*: what the bake stored per level
    int weight;            // IBL_WEIGHT_*
    float weight_exponent; // p of IBL_WEIGHT_POWER (clamped to [1/16, 16])
    int interpolation;     // IBL_INTERP_*
};

// The accurate lookup (specular_lookup_desc::accurate(), ibl-bake --preset accurate): t linear in
// log r, geometric blend. The library's default is ibl_specular_textbook.
ibl_specular_desc ibl_specular_accurate(int virtual_levels, int first_level, int stored_levels) {
    return ibl_specular_desc(virtual_levels, first_level, stored_levels, IBL_MAPPING_LINEAR, IBL_WEIGHT_LOG, 2.0,
                             IBL_INTERP_GEOMETRIC);
}

// The textbook lookup: textureLod(chain, R, lod(r) - first_level) (linear mapping).
ibl_specular_desc ibl_specular_textbook(int virtual_levels, int first_level, int stored_levels) {
    return ibl_specular_desc(virtual_levels, first_level, stored_levels, IBL_MAPPING_LINEAR, IBL_WEIGHT_LOD, 1.0,
                             IBL_INTERP_LINEAR);
}

// The (virtual) levels and weights of one lookup: sum_k weight[k] L(level[k]), count 2 or 4.
struct ibl_specular_taps {
    ivec4 level;
    vec4 weight;
    int count;
    float lod; // l + t of a two-level lookup (what textureLod takes for the linear blend)
};

// The bracketing level l (out) and the fraction t in [0, 1] of roughness r in a chain of
// `levels` levels (specular_level_fraction).
float ibl_specular_level_fraction(float roughness, int levels, ibl_specular_desc d, out int lower) {
    lower = 0;
    if (levels < 2) return 0.0;
    float m = float(levels - 1);
    float r = ibl_saturate(roughness);
    float x = ibl_lod_from_roughness(d.mapping, r, m);
    int l = int(x); // x >= 0: truncation is floor
    if (l > levels - 2) l = levels - 2;
    lower = l;
    if (d.weight == IBL_WEIGHT_LOG && l > 0) {
        float r0 = ibl_roughness_from_lod(d.mapping, float(l), m);
        float r1 = ibl_roughness_from_lod(d.mapping, float(l + 1), m);
        float den = log(r1 / r0);
        return den > 0.0 && r > 0.0 ? ibl_saturate(log(r / r0) / den) : 0.0;
    }
    if (d.weight == IBL_WEIGHT_POWER) {
        float p = clamp(d.weight_exponent, 1.0 / 16.0, 16.0);
        float r0 = ibl_roughness_from_lod(d.mapping, float(l), m);
        float r1 = ibl_roughness_from_lod(d.mapping, float(l + 1), m);
        float g0 = r0 > 0.0 ? pow(r0, p) : 0.0, g1 = r1 > 0.0 ? pow(r1, p) : 0.0;
        float den = g1 - g0;
        float g = r > 0.0 ? pow(r, p) : 0.0;
        return den > 0.0 ? ibl_saturate((g - g0) / den) : 0.0;
    }
    return ibl_saturate(x - float(l));
}

// Levels and weights of a lookup at roughness r in a chain of `levels` levels (specular_lookup_taps).
ibl_specular_taps ibl_specular_lookup_taps(float roughness, int levels, ibl_specular_desc d) {
    ibl_specular_taps s = ibl_specular_taps(ivec4(0), vec4(0.0), 2, 0.0);
    int l = 0;
    float t = ibl_specular_level_fraction(roughness, levels, d, l);
    if (levels < 2) {
        s.weight.x = 1.0;
        return s;
    }
    s.lod = float(l) + t;
    if (d.interpolation == IBL_INTERP_CATMULL_ROM) {
        int m = levels - 1;
        float t2 = t * t, t3 = t2 * t;
        s.count = 4;
        s.level = ivec4(l > 0 ? l - 1 : 0, l, l + 1, l + 2 < m ? l + 2 : m);
        // Uniform Catmull-Rom basis; at t = 0 the weights are exactly (0, 1, 0, 0).
        s.weight = vec4(0.5 * (2.0 * t2 - t3 - t), 0.5 * (3.0 * t3 - 5.0 * t2) + 1.0, 0.5 * (4.0 * t2 - 3.0 * t3 + t),
                        0.5 * (t3 - t2));
        return s;
    }
    s.level = ivec4(l, l + 1, 0, 0);
    s.weight = vec4(1.0 - t, t, 0.0, 0.0);
    return s;
}

// The lookup's combination of its taps' values v0..v3 (read from levels taps.level; v2, v3 are
// used only by a four-tap lookup) (specular_blend).
vec3 ibl_specular_blend(ibl_specular_taps s, vec3 v0, vec3 v1, vec3 v2, vec3 v3, ibl_specular_desc d) {
    if (s.count == 2) {
        vec3 a = v0;
        if (!(s.weight.y > 0.0)) return a;
        vec3 b = v1;
        float t = s.weight.y;
        vec3 v = a + t * (b - a);
        if (d.interpolation == IBL_INTERP_GEOMETRIC) {
            // Per channel a (b / a)^t where both are > 0 (the division is guarded by the select).
            bvec3 pos = bvec3(a.x > 0.0 && b.x > 0.0, a.y > 0.0 && b.y > 0.0, a.z > 0.0 && b.z > 0.0);
            vec3 q = vec3(pos.x ? b.x / a.x : 1.0, pos.y ? b.y / a.y : 1.0, pos.z ? b.z / a.z : 1.0);
            vec3 g = a * exp(t * log(q));
            v = vec3(pos.x ? g.x : v.x, pos.y ? g.y : v.y, pos.z ? g.z : v.z);
        }
        return v;
    }
    vec3 v = s.weight.x * v0 + s.weight.y * v1 + s.weight.z * v2 + s.weight.w * v3;
    return max(v, vec3(0.0));
}

// The texture lod of virtual level v: v - first_level clamped to the stored levels.
float ibl_specular_stored_lod(int level, ibl_specular_desc d) {
    return float(clamp(level - d.first_level, 0, d.stored_levels - 1));
}

// The prefiltered radiance LD at direction dir (normally R = reflect(-v, n)) and roughness r:
// the taps of ibl_specular_lookup_taps, each a bilinear read at an integer lod, blended. What
// ibl-bake's product_view::ld computes on the CPU.
vec3 ibl_specular_lookup(samplerCube chain, vec3 dir, float roughness, ibl_specular_desc d) {
    ibl_specular_taps s = ibl_specular_lookup_taps(roughness, d.virtual_levels, d);
    vec3 v0 = textureLod(chain, dir, ibl_specular_stored_lod(s.level.x, d)).rgb;
    vec3 v1 = vec3(0.0), v2 = vec3(0.0), v3 = vec3(0.0);
    if (s.weight.y != 0.0) v1 = textureLod(chain, dir, ibl_specular_stored_lod(s.level.y, d)).rgb;
    if (s.count == 4) {
        if (s.weight.z != 0.0) v2 = textureLod(chain, dir, ibl_specular_stored_lod(s.level.z, d)).rgb;
        if (s.weight.w != 0.0) v3 = textureLod(chain, dir, ibl_specular_stored_lod(s.level.w, d)).rgb;
    }
    return ibl_specular_blend(s, v0, v1, v2, v3, d);
}

// ---- DFG -----------------------------------------------------------------------------------------
const int IBL_DFG_AXIS_LINEAR = 0; // texel coordinate = value
const int IBL_DFG_AXIS_SQRT = 1;   // texel coordinate = sqrt(value)
const int IBL_DFG_AXIS_CBRT = 2;   // texel coordinate = cbrt(value)

// The table's parameterisation (dfg_lut_layout; report.json plan.runtime.dfg_layout).
struct ibl_dfg_layout {
    int n_dot_v;       // IBL_DFG_AXIS_*
    int roughness;     // IBL_DFG_AXIS_*
    bool edge_aligned; // true: first / last texel centres at axis coordinates 0 and 1
};

// The remapped table (dfg_lut_layout::remapped(), ibl-bake --preset accurate): cbrt(n.v) x sqrt(r),
// edge aligned.
ibl_dfg_layout ibl_dfg_layout_remapped() { return ibl_dfg_layout(IBL_DFG_AXIS_CBRT, IBL_DFG_AXIS_SQRT, true); }
// The textbook table (the default of the library and of ibl-bake): texture(lut, vec2(n.v, r)).
ibl_dfg_layout ibl_dfg_layout_uniform() { return ibl_dfg_layout(IBL_DFG_AXIS_LINEAR, IBL_DFG_AXIS_LINEAR, false); }

// The axis coordinate in [0, 1] of a value in [0, 1] (dfg_axis_coord).
float ibl_dfg_axis_coord(int axis, float value) {
    float v = ibl_saturate(value);
    if (axis == IBL_DFG_AXIS_SQRT) return sqrt(v);
    if (axis == IBL_DFG_AXIS_CBRT) return v > 0.0 ? pow(v, 1.0 / 3.0) : 0.0;
    return v;
}

// The sampler coordinate of axis coordinate c in an axis of `size` texels (dfg_sampler_coord).
float ibl_dfg_sampler_coord(float c, int size, bool edge_aligned) {
    if (!edge_aligned || size == 0) return c;
    return (c * float(size - 1) + 0.5) / float(size);
}

// Sampler coordinates (s, t) of (n.v, r) in a table of `size` texels per side (dfg_lut_coord).
vec2 ibl_dfg_lut_coord(float n_dot_v, float roughness, int size, ibl_dfg_layout lay) {
    return vec2(ibl_dfg_sampler_coord(ibl_dfg_axis_coord(lay.n_dot_v, n_dot_v), size, lay.edge_aligned),
                ibl_dfg_sampler_coord(ibl_dfg_axis_coord(lay.roughness, roughness), size, lay.edge_aligned));
}

// (A, B, k) of the table at (n.v, r): one bilinear tap (clamp to edge, LINEAR filtering, no
// mips; textureLod at 0, so it is defined in non-uniform control flow and in vertex shaders).
vec3 ibl_dfg_lookup(sampler2D lut, float n_dot_v, float roughness, ibl_dfg_layout lay) {
    return textureLod(lut, ibl_dfg_lut_coord(n_dot_v, roughness, textureSize(lut, 0).x, lay), 0.0).rgb;
}

// ---- the lobe LUT (ibl/runtime/specular_models.hpp: the one-tap lobe model) ----------------------------------------

// normalize(lerp(n, r_dir, s)) for unit n, r_dir, s clamped to [0, 1]; n where the lerp vanishes
// (lerp_direction).
vec3 ibl_lerp_direction(vec3 n, vec3 r_dir, float s) {
    vec3 d = n + ibl_saturate(s) * (r_dir - n);
    float len2 = dot(d, d);
    return len2 > IBL_MIN_NORMAL ? d * (1.0 / sqrt(len2)) : n;
}

// (A, B, s, r_eff) of the lobe LUT at (n.v, r): one bilinear tap in the DFG layout's coordinates
// (lobe_lut_lookup; the table's layout is the DFG table's, report.json plan.runtime.dfg_layout).
vec4 ibl_lobe_lut_lookup(sampler2D lut, float n_dot_v, float roughness, ibl_dfg_layout lay) {
    return textureLod(lut, ibl_dfg_lut_coord(n_dot_v, roughness, textureSize(lut, 0).x, lay), 0.0);
}

// Where the lobe model reads the chain: normalize(lerp(n, R, s)), R = 2 (n.v) n - v.
vec3 ibl_lobe_direction(vec3 n, vec3 v, float s) { return ibl_lerp_direction(n, 2.0 * dot(n, v) * n - v, s); }

#endif // IBL_GLSL_LOOKUP
