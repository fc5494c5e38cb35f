// tools/viewer/viewer.frag.glsl — the viewer's fragment shader, appended to the library's GLSL
// (include/ibl/glsl/ibl_common, ibl_lookup, ibl_sh, ibl_shade) by viewer.js.
//   u_mode 0  ibl-bake's preview.png, mirrored exactly (tools/ibl-bake/stages/stage_preview.cpp): a 5 x 2
//             grid of 128-pixel cells, orthographic spheres of radius 0.45 cell, roughness 0.25 i
//             (column i), dielectric base 0.8 on top, metal (0.95, 0.64, 0.54) below,
//             multiple-scattering ambient (the bake's runtime model: the lobe LUT, the two-tap
//             table or the split sum) plus the bake's sun (lights.json) as a disk light;
//             background = level 0 (the residual) plus the sun's disk, through a 90-degree pinhole;
//             u_ss x u_ss sub-pixel samples averaged in linear radiance; exposure, Reinhard, sRGB.
//   u_mode 1  the interactive view: two spheres (dielectric, metal) of one roughness seen through
//             a perspective camera over the environment (with the sun), optional directional light.

uniform samplerCube u_chain;
uniform samplerCube u_irradiance;
uniform sampler2D u_lut;
uniform sampler2D u_lobe;  // the lobe LUT (A, B, s, r_eff) in the DFG layout (u_runtime 1 and 3)
uniform sampler2D u_lobe_b; // the lobe model's B-part table (f_B, r_B, 0, 0) (u_runtime 3)
uniform sampler2D u_taps_a; // the two-tap table, channels 0..3 (A, B, angle0, roughness0) (u_runtime 2)
uniform sampler2D u_taps_b; // channels 4..7 (weight0, angle1, roughness1, weight1)
uniform int u_runtime;     // 0 split sum (LD(R, r), DFG), 1 the one-kernel lobe model, 2 taps2, 3 the two-part lobe model (report.json runtime_model)
uniform vec3 u_sh[9];
uniform int u_diffuse;     // 0 none, 1 SH, 2 irradiance map
uniform ivec4 u_spec_levels; // virtual_levels, first_level, stored_levels, mapping
uniform ivec3 u_spec_rule;   // weight, interpolation, multiple scattering (1) or single (0)
uniform float u_spec_exponent;
uniform ivec3 u_dfg_layout;  // n.v axis, r axis, edge aligned
uniform vec3 u_fwd, u_right, u_up;
uniform vec2 u_size;       // image size in pixels
uniform float u_exposure;
uniform int u_ss;
uniform int u_mode;
uniform float u_roughness;
uniform float u_tan_half_fov;
uniform vec3 u_eye;
uniform vec3 u_sphere_offset; // the spheres sit at -offset (dielectric) and +offset (metal)
uniform vec3 u_light_dir;
uniform vec3 u_light_irradiance; // 0: no direct light
uniform int u_sun_on;            // 1: the bake extracted a sun (lights.json), added back as a disk light
uniform vec3 u_sun_dir;          // unit, towards the sun
uniform float u_sun_solid_angle; // sr
uniform vec3 u_sun_radiance;

out vec4 o_color;

ibl_specular_desc spec_desc() {
    return ibl_specular_desc(u_spec_levels.x, u_spec_levels.y, u_spec_levels.z, u_spec_levels.w, u_spec_rule.x,
                             u_spec_exponent, u_spec_rule.y);
}

ibl_dfg_layout dfg_layout() { return ibl_dfg_layout(u_dfg_layout.x, u_dfg_layout.y, u_dfg_layout.z != 0); }

vec3 diffuse_over_pi(vec3 n) {
    if (u_diffuse == 1) return ibl_sh_irradiance_over_pi(u_sh, n);
    if (u_diffuse == 2) return ibl_irradiance_map_over_pi(u_irradiance, n);
    return vec3(0.0);
}

vec3 shade_sphere(vec3 n, vec3 v, ibl_material mat) {
    ibl_material_terms m = ibl_resolve_material(mat);
    ibl_sample s; // (WebGL forbids ?: on structures)
    if (u_runtime == 2) s = ibl_lobe_taps2_sample(u_chain, spec_desc(), u_taps_a, u_taps_b, dfg_layout(), n, v, m.roughness, diffuse_over_pi(n));
    else if (u_runtime == 3) s = ibl_lobe_pair_sample(u_chain, spec_desc(), u_lobe, u_lobe_b, dfg_layout(), n, v, m.roughness, m.f0, m.f90, diffuse_over_pi(n));
    else if (u_runtime == 1) s = ibl_lobe_sample(u_chain, spec_desc(), u_lobe, dfg_layout(), n, v, m.roughness, diffuse_over_pi(n));
    else s = ibl_lookup_sample(u_chain, spec_desc(), u_lut, dfg_layout(), n, v, m.roughness, diffuse_over_pi(n));
    vec3 c = ibl_ambient(m, clamp(dot(n, v), 0.0, 1.0), s, u_spec_rule.z != 0);
    if (u_sun_on != 0) c += ibl_shade_disk(n, v, ibl_disk_light(u_sun_dir, u_sun_solid_angle, u_sun_radiance), m);
    if (dot(u_light_irradiance, u_light_irradiance) > 0.0)
        c += ibl_shade_directional(n, v, u_light_dir, u_light_irradiance, m);
    return c;
}

// The preview's materials: 0 = dielectric, base 0.8; 1 = metal (0.95, 0.64, 0.54). (WebGL forbids
// ?: on structures.)
ibl_material sphere_material(int k, float roughness) {
    if (k == 0) return ibl_make_material(vec3(0.8), 0.0, roughness);
    return ibl_make_material(vec3(0.95, 0.64, 0.54), 1.0, roughness);
}

// The environment seen along unit d: level 0 of the chain (the residual source when first_level
// is 0) plus the sun's disk drawn analytically: its radiance where d is inside the cap,
// d.dir >= cos r with 1 - cos r = omega / (2 pi) (stage_preview.cpp does the same).
vec3 background(vec3 d) {
    vec3 c = textureLod(u_chain, d, 0.0).rgb;
    if (u_sun_on != 0 && dot(d, u_sun_dir) >= 1.0 - ibl_cap_one_minus_cos(u_sun_solid_angle)) c += u_sun_radiance;
    return c;
}

// stage_preview.cpp's preview_renderer::at at image position (fx, fy) (y down, pixels).
vec3 preview_at(float fx, float fy) {
    const float cell = 128.0;
    float radius = 0.45 * cell;
    int ci = min(int(fx) / 128, 4), cj = min(int(fy) / 128, 1);
    float lx = (fx - (float(ci) + 0.5) * cell) / radius, ly = -(fy - (float(cj) + 0.5) * cell) / radius;
    float d2 = lx * lx + ly * ly;
    if (d2 < 1.0) {
        vec3 n = lx * u_right + ly * u_up - sqrt(1.0 - d2) * u_fwd;
        return shade_sphere(n, -u_fwd, sphere_material(cj, 0.25 * float(ci)));
    }
    float tan_v = u_tan_half_fov * u_size.y / u_size.x;
    float ndc_x = 2.0 * fx / u_size.x - 1.0, ndc_y = 1.0 - 2.0 * fy / u_size.y;
    return background(normalize(u_fwd + ndc_x * u_tan_half_fov * u_right + ndc_y * tan_v * u_up));
}

// The interactive view: a pinhole camera at u_eye, spheres of radius 1 at -/+ u_sphere_offset.
vec3 view_at(float fx, float fy) {
    float tan_v = u_tan_half_fov * u_size.y / u_size.x;
    float ndc_x = 2.0 * fx / u_size.x - 1.0, ndc_y = 1.0 - 2.0 * fy / u_size.y;
    vec3 d = normalize(u_fwd + ndc_x * u_tan_half_fov * u_right + ndc_y * tan_v * u_up);
    float best = 1e30;
    vec3 hit_n = vec3(0.0);
    int hit = -1;
    for (int k = 0; k < 2; ++k) {
        vec3 c = k == 0 ? -u_sphere_offset : u_sphere_offset;
        vec3 oc = u_eye - c;
        float b = dot(oc, d), q = dot(oc, oc) - 1.0, disc = b * b - q;
        if (disc < 0.0) continue;
        float t = -b - sqrt(disc);
        if (t > 0.0 && t < best) {
            best = t;
            hit = k;
            hit_n = normalize(oc + t * d);
        }
    }
    if (hit < 0) return background(d);
    return shade_sphere(hit_n, -d, sphere_material(hit, u_roughness));
}

// tools/ibl-bake/io/image_png.cpp tonemap_png: x = L exposure, Reinhard x / (1 + x), sRGB OETF (the
// framebuffer's 8-bit conversion rounds to nearest, as the PNG writer's floor(y 255 + 0.5)).
float srgb_oetf(float x) { return x <= 0.0031308 ? 12.92 * x : 1.055 * pow(x, 1.0 / 2.4) - 0.055; }
vec3 tonemap(vec3 l) {
    vec3 x = l * u_exposure;
    vec3 y;
    for (int c = 0; c < 3; ++c) {
        float v = x[c];
        y[c] = v > 0.0 ? srgb_oetf(isinf(v) ? 1.0 : v / (1.0 + v)) : 0.0;
    }
    return y;
}

void main() {
    float px = floor(gl_FragCoord.x), py = u_size.y - 1.0 - floor(gl_FragCoord.y); // image row 0 = top
    vec3 acc = vec3(0.0);
    for (int sy = 0; sy < u_ss; ++sy)
        for (int sx = 0; sx < u_ss; ++sx) {
            float fx = px + (float(sx) + 0.5) / float(u_ss), fy = py + (float(sy) + 0.5) / float(u_ss);
            acc += u_mode == 0 ? preview_at(fx, fy) : view_at(fx, fy);
        }
    acc /= float(u_ss * u_ss);
    o_color = vec4(tonemap(acc), 1.0);
}
