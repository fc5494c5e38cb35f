// examples/quickstart_library.glsl — README.md's "Start here" GLSL through the library's includes:
// the marked region is the README's snippet, verbatim (the quickstart_readme test compares them).
// tests/quickstart/check_quickstart.py compiles this file after include/ibl/glsl/ibl_common.glsl,
// ibl_lookup.glsl, ibl_sh.glsl and ibl_shade.glsl as GLSL ES 3.00 and 4.50 (glslangValidator).

// [readme:glsl-library]
// After `#version 300 es` and the precision statements (docs/shaders.md), concatenate
// include/ibl/glsl/ibl_common.glsl, ibl_lookup.glsl, ibl_sh.glsl, ibl_shade.glsl (GLSL has no
// #include), then:
uniform samplerCube u_specular; // the chain: level l = mip l (LINEAR_MIPMAP_LINEAR, MAX_LEVEL levels - 1)
uniform sampler2D u_dfg;        // the DFG table: R = A, G = B (clamp to edge, LINEAR)
uniform vec3 u_sh[9];           // sh_shader_coeffs(sh, irradiance_over_pi) / sh.json
uniform int u_levels;           // levels of the chain

vec3 shade(vec3 n, vec3 v, vec3 base_color, float metallic, float roughness) {
    ibl_specular_desc sd = ibl_specular_textbook(u_levels, 0, u_levels); // textureLod at lod(r)
    vec3 e_over_pi = ibl_sh_irradiance_over_pi(u_sh, n);
    ibl_sample s = ibl_lookup_sample(u_specular, sd, u_dfg, ibl_dfg_layout_uniform(), n, v, roughness, e_over_pi);
    ibl_material_terms m = ibl_resolve_material(ibl_make_material(base_color, metallic, roughness));
    return ibl_ambient(m, dot(n, v), s, true); // multiple scattering: pbr_shader's default
}
// [readme:glsl-library]

uniform vec3 u_n, u_v, u_base_color;
uniform float u_metallic, u_roughness;
#ifdef GL_ES
out vec4 o_color;
#else
layout(location = 0) out vec4 o_color;
#endif

void main() { o_color = vec4(shade(u_n, u_v, u_base_color, u_metallic, u_roughness), 1.0); }
