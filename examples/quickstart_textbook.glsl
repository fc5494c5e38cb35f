// examples/quickstart_textbook.glsl — README.md's "Start here" GLSL for a textbook renderer that
// reads ibl-bake's default files without the library: the marked region is the README's snippet,
// verbatim (the quickstart_readme test compares them). tests/quickstart/check_quickstart.py
// compiles this file alone as GLSL ES 3.00 and 4.50 (glslangValidator).

// [readme:glsl-textbook]
uniform samplerCube u_specular; // specular.ktx2: mip l holds roughness l / (levels - 1)
uniform sampler2D u_dfg;        // dfg.exr: R = A, G = B at (n.v, roughness); clamp to edge, LINEAR
uniform vec3 u_sh[9];           // sh.json "irradiance_over_pi_shader" (E/pi, its "convention")
uniform float u_max_lod;        // levels - 1

vec3 shade_textbook(vec3 n, vec3 v, vec3 base_color, float metallic, float roughness) {
    float nv = clamp(dot(n, v), 0.0, 1.0);
    vec3 ld = textureLod(u_specular, reflect(-v, n), roughness * u_max_lod).rgb;
    vec2 ab = texture(u_dfg, vec2(nv, roughness)).rg;
    vec3 e_over_pi = max(u_sh[0] + u_sh[1] * n.y + u_sh[2] * n.z + u_sh[3] * n.x + u_sh[4] * (n.x * n.y) +
                         u_sh[5] * (n.y * n.z) + u_sh[6] * (3.0 * n.z * n.z - 1.0) + u_sh[7] * (n.x * n.z) +
                         u_sh[8] * (n.x * n.x - n.y * n.y), vec3(0.0));
    vec3 f0 = mix(vec3(0.04), base_color, metallic);
    vec3 f = f0 + (max(vec3(1.0 - roughness), f0) - f0) * pow(1.0 - nv, 5.0); // Fresnel with roughness
    vec3 kd = (1.0 - f) * (1.0 - metallic);
    return kd * base_color * e_over_pi + ld * (f0 * ab.x + ab.y); // Karis 2013, single scattering
}
// [readme:glsl-textbook]

uniform vec3 u_n, u_v, u_base_color;
uniform float u_metallic, u_roughness;
#ifdef GL_ES
out vec4 o_color;
#else
layout(location = 0) out vec4 o_color;
#endif

void main() { o_color = vec4(shade_textbook(u_n, u_v, u_base_color, u_metallic, u_roughness), 1.0); }
