// ibl/glsl/ibl_sh.glsl — diffuse irradiance at runtime (GLSL mirror of sh/convolve.hpp's
// sh_shader_evaluate and of an irradiance cubemap read): E(n)/pi, the cosine-weighted mean
// radiance that multiplies the diffuse albedo. Needs ibl_common.glsl first.

#ifndef IBL_GLSL_SH
#define IBL_GLSL_SH 1
#ifndef IBL_GLSL_COMMON
#error "ibl_sh.glsl: concatenate ibl_common.glsl before it"
#endif

// The nine unnormalised polynomial terms p_k(n) of the 3-band basis (sh_poly_terms):
// (1, y, z, x, xy, yz, 3z^2 - 1, xz, x^2 - y^2).
void ibl_sh_poly9(vec3 n, out float p[9]) {
    float x2 = n.x * n.x, y2 = n.y * n.y, z2 = n.z * n.z;
    p[0] = 1.0;
    p[1] = n.y;
    p[2] = n.z;
    p[3] = n.x;
    p[4] = n.x * n.y;
    p[5] = n.y * n.z;
    p[6] = 3.0 * z2 - 1.0;
    p[7] = n.x * n.z;
    p[8] = x2 - y2;
}

// sum_k c_k p_k(n) (sh_shader_evaluate, nine multiply-adds). With the constants of sh.json
// "irradiance_over_pi_shader" (sh_shader_coeffs(..., irradiance_over_pi)) this is E(n)/pi;
// with "irradiance" shader constants E(n). n unit.
vec3 ibl_sh_evaluate9(vec3 c[9], vec3 n) {
    float p[9];
    ibl_sh_poly9(n, p);
    vec3 r = vec3(0.0);
    for (int k = 0; k < 9; ++k) r += p[k] * c[k];
    return r;
}

// E(n)/pi from the shader constants, clamped to >= 0 per channel (what ibl-bake's preview and
// checks use: a band-limited irradiance can dip below 0 where the source is dark).
vec3 ibl_sh_irradiance_over_pi(vec3 c[9], vec3 n) { return max(ibl_sh_evaluate9(c, n), vec3(0.0)); }

// E(n)/pi from an irradiance cubemap whose texels hold E (irradiance.ktx2 of a scene bake):
// one bilinear read of level 0 at the normal, divided by pi.
vec3 ibl_irradiance_map_over_pi(samplerCube irradiance, vec3 n) {
    return textureLod(irradiance, n, 0.0).rgb * IBL_INV_PI;
}

#endif // IBL_GLSL_SH
