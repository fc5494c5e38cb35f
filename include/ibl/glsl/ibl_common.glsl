// ibl/glsl/ibl_common.glsl — conventions and helpers shared by the GLSL mirror of the library's
// runtime (ibl/runtime/lookup.hpp, ibl/runtime/shade.hpp, ibl/sh/convolve.hpp). Valid as GLSL ES 3.00 (WebGL2)
// and GLSL 4.50; no #version line: the including shader writes it (and, in ES, the precision
// statements: `precision highp float; precision highp int; precision highp samplerCube;`, and
// `precision highp sampler3D;` where a shader declares the occlusion table's sampler).
// Concatenate in this order (GLSL has no #include): ibl_common.glsl, then any of
// ibl_lookup.glsl, ibl_sh.glsl, ibl_shade.glsl, ibl_runtime.glsl (each guards itself against a
// second inclusion; ibl_runtime.glsl needs ibl_lookup.glsl and ibl_shade.glsl).
// docs/shaders.md has the API, a usage example and what the browser test measures.
//
// ---- Conventions (the library's, stated once) ---------------------------------------------------
// Frame     right-handed, +Y up; directions are unit vectors in world space. v points from the
//           surface to the eye, l towards the light, n is the unit normal; R = reflect(-v, n)
//           = 2 (n.v) n - v is where the specular chain is read.
// Cubemaps  faces +X, -X, +Y, -Y, +Z, -Z with the OpenGL orientation (the GL spec's sc / tc / ma
//           table, env/cube_geometry.hpp), face row 0 = t = 0. KTX2 stores rows from t = 0 and
//           OpenGL / WebGL take the first row of texImage2D at t = 0, so a face uploads as it is
//           stored (no flip) and a samplerCube lookup at direction d reads what the library's
//           cubemap<T>::bilinear(d, level) reads. Seamless filtering across faces (always on in
//           GLES 3 / WebGL2; GL 4.x: glEnable(GL_TEXTURE_CUBE_MAP_SEAMLESS)) matches the
//           library's one-texel borders; at a cube corner both use the mean of the three texels.
// Lod       lod 0 = the finest STORED level. A chain of V virtual levels (level v holds roughness
//           roughness_from_lod(mapping, v, V - 1)) of which the file stores levels
//           first_level .. first_level + stored - 1 (report.json plan.runtime: virtual_levels,
//           first_level, stored_levels) reads virtual level v at textureLod lod v - first_level,
//           clamped to [0, stored - 1]. The sampler needs MIN_FILTER LINEAR_MIPMAP_LINEAR (or
//           _NEAREST: every tap here is at an integer lod), MAG_FILTER LINEAR, BASE_LEVEL 0 and
//           MAX_LEVEL stored - 1 (a chain that stops above 1x1 is otherwise incomplete).
// Roughness perceptual r in [0, 1]; alpha = r^2.
// DFG LUT   N x N texels, texel (i, j) = row j (texture t), column i (texture s); channel R = A
//           (scale of F0), G = B (scale of F90), B = k = (1 - E)/E (multiscatter, 0 in a
//           two-channel table). Row 0 (uploaded first, t = 0) holds the smallest roughness,
//           column 0 the smallest n.v. Axis maps per the table's layout (ibl_dfg_layout):
//           the bake's default puts texel centres at n.v = (i/(N-1))^3, r = (j/(N-1))^2
//           (cbrt(n.v) x sqrt(r), edge aligned). Clamp to edge, bilinear.
// Lobe LUT  the lobe model of ibl/runtime/specular_models.hpp (ibl-bake --runtime lobe, its default): an N x N
//           RGBA table in the DFG table's layout and orientation (row 0 = the smallest
//           roughness), R = A, G = B, B = s (the lerp factor of the lookup direction
//           normalize(lerp(n, R, s))), A = r_eff (the chain roughness to read there); specular =
//           LD(d, r_eff) (F0 A + F90 B) with this table alone (one kernel); ibl-bake's lobe
//           model reads it with the B-part table below (two parts).
// Lobe LUT B  the lobe model's second table (lobe_lut_b.exr / lobe_lut_b.hpp, same size, layout
//           and orientation): R = f_B (the Fresnel B part's kernel angle from n towards R over
//           acos(n.v)), G = r_B, B = A = 0; specular = F0 A LD(normalize(lerp(n, R, s)), r_eff) +
//           F90 B LD(cos(a) n + sin(a) t, r_B), a = min(f_B acos(n.v), pi/2), t the tangent of n
//           towards R (ibl_runtime.glsl ibl_specular_lobe_pair). Clamp to edge, bilinear (RGBA32F).
// Taps LUT  the two-tap fitted model of ibl/runtime/specular_models.hpp (specular_lobe_taps; lobe_fit.hpp's
//           make_lobe_taps_lut with taps = 2): its eight channels per texel, in the DFG table's
//           layout and orientation, as two RGBA textures of the same size: taps_a = channels
//           0..3 (R = A, G = B, B = angle0 / acos(n.v), A = roughness0), taps_b = channels 4..7
//           (R = weight0, G = angle1 / acos(n.v), B = roughness1, A = weight1); tap k reads the
//           chain at cos(angle_k) n + sin(angle_k) t (t: the tangent of n towards R) and roughness_k.
//           Clamp to edge, bilinear (RGBA32F: the table's floats).
// SO LUT    the specular-occlusion table of ibl/runtime/specular_occlusion.hpp (specular_occlusion_lut, size^3
//           floats at index (k size + j) size + i) as a size^3 3-D texture, one channel (R32F;
//           R16F where OES_texture_float_linear is missing), uploaded as stored: texImage3D's x =
//           i = n.v, y = j = r, z = k = ao (layer k = the k-th size^2 slice), texel (i, j, k) at
//           n.v = i / (size - 1), r = j / (size - 1), ao = k / (size - 1) (edge aligned).
//           Clamp to edge (S, T and R), MIN and MAG_FILTER LINEAR, one level. The functions take
//           a highp sampler3D (GLSL ES has no default precision for sampler3D: declare the
//           uniform highp or add `precision highp sampler3D;`).
// SH        nine shader constants c_k (sh.json "irradiance_over_pi_shader") with
//           E(n)/pi = sum c_k p_k(n), p = (1, y, z, x, xy, yz, 3z^2 - 1, xz, x^2 - y^2).
// Radiance  linear, the units of the source; E/pi is the cosine-weighted mean radiance (a
//           constant environment L gives LD = L and E/pi = L).
// Clamps    as in the C++: roughness, metallic, ao and cosines clamped to [0, 1]. Unlike the
//           C++ (NaN -> 0), GLSL's clamp of a NaN is undefined: pass finite values.

#ifndef IBL_GLSL_COMMON
#define IBL_GLSL_COMMON 1

const float IBL_PI = 3.14159265358979;
const float IBL_INV_PI = 0.318309886183791;
// Smallest normal float (min_normal_v<float>): floor of denominators that vanish only at a corner.
const float IBL_MIN_NORMAL = 1.17549435e-38;
// ggx_min_alpha_v<float> = 2^-31 and schlick_min_k_v<float> = 2^-32 (brdf/ggx.hpp, masking.hpp).
const float IBL_GGX_MIN_ALPHA = 4.656612873077393e-10;
const float IBL_SCHLICK_MIN_K = 2.3283064365386963e-10;

float ibl_saturate(float x) { return clamp(x, 0.0, 1.0); }
vec3 ibl_saturate(vec3 x) { return clamp(x, vec3(0.0), vec3(1.0)); }

#endif // IBL_GLSL_COMMON
