// tools/viewer/numeric.frag.glsl — evaluates the library's GLSL functions on a fixed grid of
// inputs: output pixel (i, j) of a 64 x 34 RGBA32F target holds case i of row j. The same grid
// evaluated by the C++ library is tests/browser/glsl_reference.cpp; the two must agree (the
// inputs are built only from exact operations: multiples of 1/64, small integers). The runtime
// rows read the reference's fixtures (glsl_reference --fixtures, uploaded by the page): an 8^2
// RGBA32F chain of 4 levels and the two RGBA32F halves of a 4^2 two-tap table; the occlusion
// rows an 8^3 R32F specular-occlusion table (linear filtering).

uniform samplerCube u_chain;
uniform sampler2D u_taps_a, u_taps_b;
uniform highp sampler3D u_so;
out vec4 o_color;

float u64(int i) { return i == 63 ? 1.0 : float(i) * 0.015625; } // i / 64, and 1 at the end

vec3 dir_of(int i) { // a deterministic unit vector per case (normalised in float on both sides)
    float a = float(i % 8) * 0.25 - 0.875, b = float(i / 8) * 0.25 - 0.875;
    return normalize(vec3(a, 0.5 + 0.0625 * float(i % 5), b));
}

// ---- the runtime rows (glsl_reference.cpp: the same inputs) ----

vec3 fis_n(int i) { return dir_of(i); }
vec3 fis_v(int i) { return dir_of((7 * i + 3) % 64); }
vec3 fis_view_local(ibl_frame fr, vec3 v) { // as ibl_specular_fis forms it
    vec3 vl = ibl_frame_to_local(fr, v);
    vl.z = vl.z > 0.0 ? vl.z : 0.0;
    float len2 = dot(vl, vl);
    return len2 > 0.0 ? vl / sqrt(len2) : vec3(0.0, 0.0, 1.0);
}
vec3 vndf_v(int i) {
    return normalize(vec3(float(i % 8) * 0.25 - 0.875, float(i % 3) * 0.25 - 0.25, float(i / 8) * 0.125 + 0.0625));
}
vec2 vndf_u(int i) { return ibl_fis_tap_point(uint(i % 16), 16u); }
float vndf_alpha(int i) {
    float r = 0.25 * float(1 + i / 16);
    return r * r;
}
float taps_r(int i) { return i % 4 == 0 ? 0.0 : u64(i); }
vec2 fis_dfg(int i) { return vec2(0.125 + float(i % 8) * 0.0625, float(i / 8) * 0.03125); }
vec3 fis_f0(int i) { return vec3(0.04 + 0.0625 * float(i % 8), 0.5, 1.0); }
ibl_specular_desc chain_desc(bool textbook) {
    if (textbook) return ibl_specular_textbook(4, 0, 4);
    return ibl_specular_accurate(4, 0, 4);
}

// ---- the occlusion rows (glsl_reference.cpp: so_point, bent_case_of, probe_texel) ----

vec3 so_point(int i, int c) {
    if (c == 0) return vec3(u64(i), u64((17 * i + 5) % 64), u64((29 * i + 11) % 64));
    if (c == 1) return vec3(u64((41 * i + 7) % 64), u64((13 * i + 3) % 64), u64((7 * i + 1) % 64));
    if (c == 2) { // one axis at an edge
        vec3 p = vec3(u64((23 * i + 9) % 64), u64((37 * i + 2) % 64), u64((11 * i + 6) % 64));
        float e = (i / 3) % 2 == 0 ? 0.0 : 1.0;
        if (i % 3 == 0) p.x = e;
        else if (i % 3 == 1) p.y = e;
        else p.z = e;
        return p;
    }
    float o = i % 2 == 0 ? -0.25 : 1.5; // outside [0, 1]: clamped
    vec3 p = vec3(u64((19 * i + 4) % 64), u64((31 * i + 8) % 64), u64((43 * i + 10) % 64));
    if (i % 3 == 0) p.x = o;
    if (i % 5 < 2) p.y = o;
    if (i % 7 < 3) p.z = o;
    return p;
}

float so_bent_case(int i, int c) {
    vec3 n = dir_of(i), v = dir_of((7 * i + 3) % 64);
    float ao = c == 3 ? 0.96875 : u64((13 * i + 3) % 64);
    vec3 b = c == 1 ? n : (c == 2 ? -n : normalize(n + 0.5 * dir_of(63 - i)));
    return ibl_specular_occlusion_bent(u_so, n, v, b, u64(i), ao);
}

vec3 probe_texel(int i, int a) { // texel-space position, exact in float
    float f = float((4099 * i) % 65536) / 65536.0, f2 = float((1237 * i + 77) % 65536) / 65536.0,
          f3 = float((3011 * i + 5) % 65536) / 65536.0;
    float p = float(i % 7), q = float((3 * i + 1) % 8), r = float((5 * i + 2) % 8);
    if (a == 0) return vec3(p + f, q, r);
    if (a == 1) return vec3(q, p + f, r);
    if (a == 2) return vec3(q, r, p + f);
    return vec3(float(i % 7) + f, float((3 * i + 2) % 7) + f2, float((5 * i + 3) % 7) + f3);
}

vec4 occlusion_row(int j, int i) {
    if (j == 28) {
        vec3 p = so_point(i, 0), q = so_point(i, 3);
        return vec4(ibl_specular_occlusion_coord(p.x, p.y, p.z, 8), ibl_specular_occlusion_coord(q.x, q.y, q.z, 32).x);
    }
    if (j == 29) {
        vec4 o;
        for (int c = 0; c < 4; ++c) {
            vec3 p = so_point(i, c);
            o[c] = ibl_specular_occlusion_table(u_so, p.x, p.y, p.z);
        }
        return o;
    }
    if (j == 30) return vec4(so_bent_case(i, 0), so_bent_case(i, 1), so_bent_case(i, 2), so_bent_case(i, 3));
    if (j == 31) { // the sampler alone at exact texel-space positions (its filter weights)
        vec4 o;
        for (int a = 0; a < 4; ++a) o[a] = textureLod(u_so, (probe_texel(i, a) + 0.5) / 8.0, 0.0).r;
        return o;
    }
    return vec4(0.0);
}

vec4 runtime_row(int j, int i) {
    if (j >= 28) return occlusion_row(j, i);
    float x = u64(i);
    if (j == 18) {
        vec3 g = dir_of(63 - i) * vec3(1.0, -1.0, 1.0);
        return vec4(ibl_dominant_lerp_frostbite(x), ibl_horizon_fade(dir_of(i), g),
                    ibl_specular_occlusion_lagarde(1.0 - x, float(i % 8) * 0.125, x),
                    ibl_specular_occlusion_lagarde(x, float(i / 8) * 0.125 + 0.0625, 1.0 - x));
    }
    if (j == 19) {
        vec2 tp = ibl_fis_tap_point(uint(i), uint(8 + i % 24));
        return vec4(ibl_g2_over_g1_height_correlated(1.0 - x, float(i % 8) * 0.125, x), ibl_fis_footprint_roughness(4.0 * x),
                    tp);
    }
    if (j == 20) { // sin / cos at the VNDF row's azimuths and at angles x pi/2
        float psi = 2.0 * IBL_PI * (vndf_u(i).x - 0.5), a = x * (0.5 * IBL_PI);
        return vec4(sin(0.5 * psi), sin(psi), cos(a), sin(a));
    }
    if (j == 21) {
        vec3 v = vndf_v(i);
        vec3 h = ibl_sample_ggx_vndf(v, vndf_u(i), vndf_alpha(i));
        return vec4(h, ibl_ggx_vndf_reflected_pdf(v, h, vndf_alpha(i)));
    }
    if (j == 22 || j == 23) { // tap i mod 8 of 8, roughness 0.125 (1 + i / 8), c = 1
        ibl_frame fr = ibl_make_frame(fis_n(i));
        ibl_runtime_tap t = ibl_fis_tap(fr, fis_view_local(fr, fis_v(i)), 0.125 * float(1 + i / 8), uint(i % 8), 8u, 1.0,
                                        vec3(0.04, 0.5, 1.0), vec3(1.0));
        return j == 22 ? vec4(t.dir, t.roughness) : vec4(t.weight, 0.0);
    }
    if (j == 24) return vec4(ibl_specular_fis(u_chain, chain_desc(true), 8, 1.0, true, fis_n(i), fis_v(i), x, fis_f0(i),
                                              vec3(1.0), fis_dfg(i)), 0.0);
    if (j == 25) return vec4(ibl_specular_fis(u_chain, chain_desc(false), 16, 2.0, false, fis_n(i), fis_v(i), x, fis_f0(i),
                                              vec3(1.0), fis_dfg(i)), 0.0);
    if (j == 26) return vec4(ibl_specular_lobe_taps2(u_chain, chain_desc(false), u_taps_a, u_taps_b, ibl_dfg_layout_remapped(),
                                                     fis_n(i), fis_v(i), taps_r(i), fis_f0(i), vec3(1.0)), 0.0);
    if (j == 27) { // incidence tangent; every fourth case R = n (the frame's tangent)
        vec3 n = dir_of(i), r = i % 4 == 0 ? n : dir_of(63 - i);
        return vec4(ibl_incidence_tangent(n, r), 0.0);
    }
    return vec4(0.0);
}

// ---- the local-probe rows (glsl_reference.cpp: probe_room, probe_point, probe_dir) ----
ibl_probe_box probe_room() { return ibl_probe_box_axis_aligned(vec3(-2.0, -1.0, -1.5), vec3(2.5, 1.5, 3.0)); }
vec3 probe_point(int i) { return vec3(float(i % 8) * 0.5 - 1.75, float(i / 8) * 0.25 - 0.875, float(i % 5) * 0.5 - 1.0); }
vec3 probe_dir(int i) { return dir_of(i) * vec3(i % 2 == 1 ? 1.0 : -1.0, i % 3 == 0 ? -1.0 : 1.0, 1.0); }

vec4 local_probe_row(int j, int i) {
    float x = u64(i);
    ibl_probe_box b = probe_room();
    vec3 c = vec3(0.25, 0.5, -0.25), p = probe_point(i), r = probe_dir(i);
    if (j == 32) {
        ibl_parallax_lookup l = ibl_parallax_box(b, c, p, r);
        vec4 tap = ibl_parallax_split_tap_box(b, c, p, r, x, i % IBL_PARALLAX_SPLIT_TAPS);
        return vec4(l.direction + 0.5 * tap.xyz, l.d_shading + tap.w);
    }
    ibl_parallax_lookup s = ibl_parallax_sphere(vec3(0.25, 0.0, 0.5), 3.0, c, p, r);
    vec4 contrib;
    float fb = ibl_blend_probe_weights4(vec4(ibl_influence_box(b, 0.5, p), ibl_influence_sphere(vec3(0.25, 0.0, 0.5), 3.0, 0.75, p), x,
                                             1.0 - x),
                                        ivec4(i % 3, 1, 0, i % 2), 4, contrib);
    float ro = ibl_corrected_roughness(x, ibl_parallax_box(b, c, p, r)) + ibl_corrected_roughness(1.0 - x, s);
    return vec4(ibl_corrected_roughness(x, s.d_shading, s.d_probe), s.d_probe + ro, fb, contrib.x + 2.0 * contrib.y);
}

vec4 row_value(int j, int i) {
    if (j >= 32) return local_probe_row(j, i);
    if (j >= 18) return runtime_row(j, i);
    float x = u64(i);
    if (j == 0) { // default taps in 6 levels
        ibl_specular_taps t = ibl_specular_lookup_taps(x, 6, ibl_specular_accurate(6, 0, 6));
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
        ibl_specular_desc d = ibl_specular_accurate(6, 0, 6);
        ibl_specular_taps t = ibl_specular_lookup_taps(x, 6, d);
        vec3 a = vec3(0.25 + float(i) * 0.03125, 3.0, 0.0), b = vec3(1.5, 0.125 + float(i) * 0.015625, 2.0);
        return vec4(ibl_specular_blend(t, a, b, vec3(0.0), vec3(0.0), d), t.weight.y);
    }
    if (j == 4) { // DFG sampler coordinates, default and uniform layouts, N = 128
        float r = 1.0 - x;
        return vec4(ibl_dfg_lut_coord(x, r, 128, ibl_dfg_layout_remapped()),
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
