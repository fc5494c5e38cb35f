// tools/viewer/numeric.frag.glsl — evaluates the library's GLSL functions on a fixed grid of
// inputs: output pixel (i, j) of a 64 x 18 RGBA32F target holds case i of row j. The same grid
// evaluated by the C++ library is tests/browser/glsl_reference.cpp; the two must agree (the
// inputs are built only from exact operations: multiples of 1/64, small integers).

out vec4 o_color;

float u64(int i) { return i == 63 ? 1.0 : float(i) * 0.015625; } // i / 64, and 1 at the end

vec3 dir_of(int i) { // a deterministic unit vector per case (normalised in float on both sides)
    float a = float(i % 8) * 0.25 - 0.875, b = float(i / 8) * 0.25 - 0.875;
    return normalize(vec3(a, 0.5 + 0.0625 * float(i % 5), b));
}

vec4 row_value(int j, int i) {
    float x = u64(i);
    if (j == 0) { // default taps in 6 levels
        ibl_specular_taps t = ibl_specular_lookup_taps(x, 6, ibl_specular_default(6, 0, 6));
        return vec4(t.lod, t.weight.x, t.weight.y, float(t.level.x));
    }
    if (j == 1) { // textbook taps in 5 levels
        ibl_specular_taps t = ibl_specular_lookup_taps(x, 5, ibl_specular_textbook(5, 0, 5));
        return vec4(t.lod, t.weight.x, t.weight.y, float(t.level.x));
    }
    if (j == 2) { // filament mapping, power 2 weight, Catmull-Rom, 5 levels
        ibl_specular_desc d = ibl_specular_desc(5, 0, 5, IBL_MAPPING_FILAMENT, IBL_WEIGHT_POWER, 2.0, IBL_INTERP_CATMULL_ROM);
        ibl_specular_taps t = ibl_specular_lookup_taps(x, 5, d);
        return t.weight;
    }
    if (j == 3) { // geometric blend of two values (one channel 0: linear there)
        ibl_specular_desc d = ibl_specular_default(6, 0, 6);
        ibl_specular_taps t = ibl_specular_lookup_taps(x, 6, d);
        vec3 a = vec3(0.25 + float(i) * 0.03125, 3.0, 0.0), b = vec3(1.5, 0.125 + float(i) * 0.015625, 2.0);
        return vec4(ibl_specular_blend(t, a, b, vec3(0.0), vec3(0.0), d), t.weight.y);
    }
    if (j == 4) { // DFG sampler coordinates, default and uniform layouts, N = 128
        float r = 1.0 - x;
        return vec4(ibl_dfg_lut_coord(x, r, 128, ibl_dfg_layout_default()),
                    ibl_dfg_lut_coord(x, r, 128, ibl_dfg_layout_uniform()));
    }
    if (j == 5) { // SH: E/pi from nine constants
        vec3 c[9];
        for (int k = 0; k < 9; ++k) c[k] = vec3(0.5 - 0.125 * float(k), 0.25 * float(k % 3), 0.0625 * float(k)) ;
        vec3 n = dir_of(i);
        return vec4(ibl_sh_evaluate9(c, n), ibl_sh_irradiance_over_pi(c, n).x);
    }
    float a = float(i % 8) * 0.125, bb = float(i / 8) * 0.0625; // (A, B) grid
    vec3 f0 = vec3(0.04 + 0.0625 * float(i % 8), 0.5, 1.0);
    if (j == 6) { // multiscatter terms
        ibl_multiscatter_terms ms = ibl_multiscatter(f0, vec3(1.0), vec2(a, bb));
        return vec4(ms.fss_ess.x, ms.fms_ems.x, ms.diffuse_fraction.x, ms.fms_ems.z);
    }
    ibl_material mat = ibl_make_material(vec3(0.75, 0.5, 0.25), float(i % 2), x);
    ibl_material_terms m = ibl_resolve_material(mat);
    ibl_sample s = ibl_sample(vec3(2.0, 1.0, 0.5), vec3(0.25, 0.5, 1.0), vec2(a, bb));
    float nv = 1.0 - x;
    if (j == 7) return vec4(ibl_ambient(m, nv, s, true), 0.0);
    if (j == 8) return vec4(ibl_ambient(m, nv, s, false), ibl_fresnel_schlick_roughness(nv, m.f0, m.roughness).x);
    vec3 n = vec3(0.0, 1.0, 0.0), v = dir_of(i), l = dir_of(63 - i);
    if (j == 9) return vec4(ibl_shade_directional(n, v, l, vec3(1.0, 2.0, 3.0), m), 0.0);
    if (j == 10) {
        ibl_light_cosines c = ibl_make_light_cosines(n, v, l);
        return vec4(c.n_dot_l, c.n_dot_h, c.v_dot_h, ibl_v_smith_schlick_ggx(v.y, c.n_dot_l, ibl_k_direct(x)));
    }
    if (j == 11) return vec4(ibl_ndf_ggx(1.0 - 0.5 * x, x * x), ibl_ndf_ggx(0.875, x * x), ibl_k_direct(x), 0.0);
    if (j == 13) { // cap irradiance E / L at cos theta in [-1, 1]: three caps and the hemisphere (r = pi/2)
        float ct = 2.0 * x - 1.0;
        return vec4(ibl_cap_irradiance(ct, ibl_cap_sin2(0.01)), ibl_cap_irradiance(ct, ibl_cap_sin2(0.25)),
                    ibl_cap_irradiance(ct, ibl_cap_sin2(1.0)), ibl_cap_irradiance(ct, 1.0));
    }
    if (j == 14) { // disk light specular (omega 0.25 sr), roughness x, and its irradiance
        ibl_disk_light dl = ibl_disk_light(l, 0.25, vec3(1.0, 2.0, 3.0));
        return vec4(ibl_disk_light_specular(n, v, dl, m.f0, m.f90, x), ibl_disk_light_irradiance(n, dl).x);
    }
    if (j == 15) { // shade_disk of a sun-sized disk (6.8e-5 sr), roughness 0.25 + 0.75 x
        ibl_disk_light sun = ibl_disk_light(l, 6.8e-5, vec3(1.0e4, 2.0e4, 3.0e4));
        ibl_material_terms ms = ibl_resolve_material(ibl_make_material(vec3(0.75, 0.5, 0.25), float(i % 2), 0.25 + 0.75 * x));
        return vec4(ibl_shade_disk(n, v, sun, ms), 0.0);
    }
    if (j == 16) { // lerp direction, s in [-0.5, 1.5] (clamped)
        vec3 a = dir_of(i), b = dir_of(63 - i);
        return vec4(ibl_lerp_direction(a, b, 2.0 * x - 0.5), 0.0);
    }
    if (j == 17) { // the lobe model's direction: R about n = dir_of(i) seen from v = dir_of(63 - i), s = x
        vec3 a = dir_of(i), b = dir_of(63 - i);
        return vec4(ibl_lobe_direction(a, b, x), dot(ibl_lobe_direction(a, b, x), a));
    }
    if (j == 12) return vec4(ibl_roughness_from_lod(IBL_MAPPING_FILAMENT, x * 4.0, 4.0), ibl_lod_from_roughness(IBL_MAPPING_FILAMENT, x, 4.0),
                             ibl_dfg_axis_coord(IBL_DFG_AXIS_CBRT, x), ibl_dfg_axis_coord(IBL_DFG_AXIS_SQRT, x));
    return vec4(0.0);
}

void main() {
    o_color = row_value(int(gl_FragCoord.y), int(gl_FragCoord.x));
}
