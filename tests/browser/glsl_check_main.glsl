// tests/browser/glsl_check_main.glsl — a fragment shader body that calls every function of
// include/ibl/glsl/*.glsl; check_glsl.py compiles it after the include files as GLSL ES 3.00 and
// as GLSL 4.50 (glslangValidator).

uniform samplerCube u_chain;
uniform samplerCube u_irradiance;
uniform sampler2D u_lut;
uniform sampler2D u_taps_a, u_taps_b;
uniform highp sampler3D u_so;
uniform int u_taps;
uniform vec3 u_sh[9];
uniform vec3 u_n, u_v, u_l;
uniform float u_r;
#ifdef GL_ES
out vec4 o_color;
#else
layout(location = 0) out vec4 o_color;
#endif

void main() {
    ibl_specular_desc sd = ibl_specular_accurate(6, 0, 6);
    ibl_specular_desc tb = ibl_specular_textbook(6, 0, 6);
    ibl_specular_desc cr = ibl_specular_desc(6, 1, 5, IBL_MAPPING_FILAMENT, IBL_WEIGHT_POWER, 2.0, IBL_INTERP_CATMULL_ROM);
    ibl_specular_taps t = ibl_specular_lookup_taps(u_r, 6, cr);
    vec3 b = ibl_specular_blend(t, u_n, u_v, u_l, u_n, cr);
    vec3 ld = ibl_specular_lookup(u_chain, u_n, u_r, sd) + ibl_specular_lookup(u_chain, u_n, u_r, tb);
    ibl_dfg_layout lay = ibl_dfg_layout_remapped();
    vec3 abk = ibl_dfg_lookup(u_lut, dot(u_n, u_v), u_r, lay) + ibl_dfg_lookup(u_lut, 0.5, u_r, ibl_dfg_layout_uniform());
    vec3 e = ibl_sh_irradiance_over_pi(u_sh, u_n) + ibl_irradiance_map_over_pi(u_irradiance, u_n);
    ibl_material_terms m = ibl_resolve_material(ibl_make_material(vec3(0.8), 0.0, u_r));
    ibl_sample s = ibl_lookup_sample(u_chain, sd, u_lut, lay, u_n, u_v, u_r, e);
    vec3 a = ibl_ambient(m, dot(u_n, u_v), s, true) + ibl_ambient(m, dot(u_n, u_v), s, false);
    ibl_multiscatter_terms ms = ibl_multiscatter(m.f0, m.f90, abk.xy);
    vec3 sp = ibl_specular_ibl_multiscatter(ms, ld, e);
    vec3 d = ibl_shade_directional(u_n, u_v, u_l, vec3(1.0), m) + ibl_shade_point(vec3(0.0), u_n, u_v, u_l, vec3(1.0), m);
    vec3 br = ibl_specular_brdf_direct(0.5, ibl_make_light_cosines(u_n, u_v, u_l), m.f0, m.f90, u_r);
    ibl_disk_light sun = ibl_disk_light(u_l, 6.8e-5, vec3(1.0e4));
    vec3 dk = ibl_shade_disk(u_n, u_v, sun, m) + ibl_disk_light_irradiance(u_n, sun) +
              ibl_disk_light_specular(u_n, u_v, sun, m.f0, m.f90, u_r) + ibl_disk_light_normal_irradiance(sun);
    float cap = ibl_cap_irradiance(dot(u_n, u_l), ibl_cap_sin2(0.5)) + ibl_cap_one_minus_cos(0.5) + ibl_atan_minus_identity(u_r);
    float rt = ibl_dominant_lerp_frostbite(u_r) + ibl_horizon_fade(u_n, u_v) + ibl_specular_occlusion_lagarde(0.5, 0.75, u_r);
    ibl_frame fr = ibl_make_frame(u_n);
    vec3 vl = ibl_frame_to_local(fr, u_v);
    vec3 h = ibl_sample_ggx_vndf(vl, ibl_fis_tap_point(3u, 8u), u_r * u_r);
    rt += ibl_ggx_vndf_reflected_pdf(vl, h, u_r) + ibl_ggx_g1_over_n_dot_v(vl.z, u_r) + ibl_ndf_ggx_local(h, u_r) +
          ibl_g2_over_g1_height_correlated(0.5, 0.25, u_r) + ibl_fis_footprint_roughness(0.5) + ibl_radical_inverse(5u) +
          float(ibl_reverse_bits(7u) >> 28u) + ibl_normalize_scaled(u_l).x;
    ibl_runtime_tap tap = ibl_fis_tap(fr, vl, u_r, 1u, 4u, 1.0, m.f0, m.f90);
    vec3 fis = ibl_specular_fis(u_chain, tb, u_taps, 1.0, true, u_n, u_v, u_r, m.f0, m.f90, abk.xy) +
               ibl_fis_combine(tap.weight, tap.weight, 4, false, m.f0, ld) + ibl_frame_to_world(fr, tap.dir) * tap.roughness;
    vec3 it = ibl_incidence_tangent(u_n, u_l);
    vec3 lt = ibl_specular_lobe_taps2(u_chain, sd, u_taps_a, u_taps_b, lay, u_n, u_v, u_r, m.f0, m.f90) +
              ibl_lobe_tap_direction(u_n, it, ibl_lobe_tap_angle(0.5, u_r));
    float so = ibl_specular_occlusion_table(u_so, dot(u_n, u_v), u_r, 0.5) +
               ibl_specular_occlusion_bent(u_so, u_n, u_v, it, u_r, 0.5) + ibl_specular_occlusion_coord(0.5, u_r, 0.5, 8).z;
    int pf_face;
    float pf_s, pf_t;
    ibl_cube_face_st(u_l, pf_face, pf_s, pf_t);
    vec3 pf = ibl_prefilter_texel(u_taps_a, u_taps_b, u_taps, 1.0, u_n) + ibl_cube_texel_direction(pf_face, 1, 2, 8) +
              ibl_prefilter_peaks(u_taps_b, u_taps, u_r, u_taps > 2, u_n) +
              ibl_packed_texel(u_taps_a, 3).xyz * (pf_s + pf_t);
    ibl_probe_box pb = ibl_probe_box_axis_aligned(vec3(-2.0), vec3(3.0));
    ibl_parallax_lookup pl = ibl_parallax_box(pb, vec3(0.5), u_n, u_l);
    ibl_parallax_lookup ps = ibl_parallax_sphere(vec3(0.0), 4.0, vec3(0.5), u_n, u_l);
    vec4 contrib;
    float fb = ibl_blend_probe_weights4(vec4(ibl_influence_box(pb, 0.5, u_n), ibl_influence_sphere(vec3(0.0), 4.0, 0.5, u_n), 0.5, 0.25),
                                        ivec4(1, 0, 0, 2), 4, contrib);
    vec3 lp = pl.direction + ibl_parallax_split_tap_sphere(vec3(0.0), 4.0, vec3(0.5), u_n, u_l, u_r, 2).xyz +
              ibl_parallax_split_tap_box(pb, vec3(0.5), u_n, u_l, u_r, 1).w + ps.direction * (ibl_corrected_roughness(u_r, pl.d_shading, pl.d_probe) + ibl_corrected_roughness(u_r, ps)) +
              vec3(ibl_proxy_exit_sphere(vec3(0.0), 2.0, u_n, u_l) + fb + contrib.x + ps.d_probe);
    o_color = vec4(b + ld + a + sp + d + br + dk + t.lod + cap + rt + fis + lt + so + pf + lp, 1.0);
}
