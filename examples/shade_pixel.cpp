// examples/shade_pixel.cpp — one pixel shaded from baked products step by step, as a fragment
// shader does it: the lod of the chain and the coordinates of the DFG table come from the
// conventions the products record (chain.mapping, dfg.layout), and the split-sum functions of
// runtime/shade.hpp combine the reads. quickstart.cpp does the same in one call
// (ibl_lookup_sample + pbr_shader); the checks here (exit status 1, "FAILED") are that the steps
// give that call's colour, and that reading with another convention gives another colour.
#include <ibl/bake.hpp>    // bake.hpp, env.hpp, sh.hpp: to bake the products here (a renderer loads
#include <ibl/env.hpp>     // them instead and needs only runtime.hpp and sh.hpp)
#include <ibl/runtime.hpp> // the reads and the shading
#include <ibl/sh.hpp>

#include <cmath>
#include <cstdio>

using v3 = ibl::vec3<float>;

static float rel_diff(const v3& a, const v3& b) { return glm::length(a - b) / glm::length(b); }

int main() {
    // The products (bake_library.cpp explains each choice): a Filament-mapped chain, a remapped table.
    const auto sky = ibl::make_default_sky<float>();
    const ibl::cubemap<float> source = ibl::bake_cubemap<float>(sky, 32, 2);
    ibl::prefilter_options opt;
    opt.policy = ibl::roughness_mip_policy::filament();
    opt.samples = 128;
    const ibl::specular_chain chain = ibl::prefilter(source, opt);
    const ibl::dfg_lut dfg = ibl::make_dfg_lut_exact<ibl::ggx_height_correlated>(32, ibl::dfg_lut_layout::remapped(), 2);
    const ibl::sh_coeffs<float, 3> sh = ibl::sh_auto_window(ibl::project_cube<3>(source)).radiance;

    // The pixel: unit normal n, unit direction to the eye v, a half-metallic orange material.
    ibl::pbr_material<float> mat;
    mat.base_color = {0.9f, 0.5f, 0.2f};
    mat.metallic = 0.5f;
    mat.roughness = 0.35f;
    const v3 n = glm::normalize(v3(0.2f, 0.9f, 0.1f)), v = glm::normalize(v3(-0.5f, 0.6f, 0.6f));

    // 1. Geometry: n.v and the reflection direction R = reflect(-v, n).
    const float n_dot_v = ibl::saturate(glm::dot(n, v));
    const v3 r_dir = 2.0f * glm::dot(n, v) * n - v;
    // 2. LD = textureLod(chain, R, lod), the lod of the roughness in the chain's own mapping.
    const float lod = ibl::lod_from_roughness(chain.mapping, mat.roughness, float(chain.levels() - 1));
    const v3 ld = chain.radiance(r_dir, lod);
    // 3. (A, B) = texture(dfg, st), st from the table's own layout (clamp-to-edge, bilinear).
    const ibl::vec2<float> st = ibl::dfg_lut_coord(n_dot_v, mat.roughness, dfg.size, dfg.layout);
    const v3 ab = ibl::dfg_sample_st(dfg, st.x, st.y);
    // 4. E(n)/pi from the SH, clamped at 0.
    const v3 e_over_pi = glm::max(ibl::sh_irradiance_at(sh, n) * ibl::inv_pi_v<float>, 0.0f);
    // 5. Combine: multiple scattering (Fdez-Aguera; pbr_shader's default) and the textbook single scattering.
    const ibl::material_terms<float> m = ibl::resolve_material(mat);
    const ibl::vec2<float> dfg_ab(ab.x, ab.y);
    const v3 color = ibl::ambient_multiscatter(ibl::multiscatter(m.f0, m.f90, dfg_ab), m.diffuse_albedo, ld, e_over_pi,
                                               m.ambient_occlusion);
    const v3 fresnel = ibl::fresnel_schlick_roughness(n_dot_v, m.f0, m.roughness);
    const v3 color_ss = ibl::ambient_single_scatter(ibl::ambient_kd(fresnel, m.metallic), ibl::diffuse_ibl_over_pi(m.base_color, e_over_pi),
                                                    ibl::specular_ibl(ld, m.f0, m.f90, dfg_ab), m.ambient_occlusion);
    std::printf("n.v %.3f, lod %.3f of %d levels, dfg st (%.3f, %.3f) -> A %.4f B %.4f\n", double(n_dot_v), double(lod),
                chain.levels(), double(st.x), double(st.y), double(ab.x), double(ab.y));
    std::printf("LD (%.4f, %.4f, %.4f), E/pi (%.4f, %.4f, %.4f)\n", double(ld.x), double(ld.y), double(ld.z),
                double(e_over_pi.x), double(e_over_pi.y), double(e_over_pi.z));
    std::printf("colour (%.4f, %.4f, %.4f), single scattering (%.4f, %.4f, %.4f)\n", double(color.x), double(color.y),
                double(color.z), double(color_ss.x), double(color_ss.y), double(color_ss.z));

    // The one-call path reads the same conventions from the products.
    const ibl::ibl_sample<float> s = ibl::ibl_lookup_sample(chain, {}, dfg, n, v, mat.roughness, e_over_pi);
    const float d_ms = rel_diff(color, ibl::pbr_shader<float>::from(mat).ambient(n_dot_v, s));
    const float d_ss = rel_diff(color_ss, ibl::pbr_shader<float>::from(mat, false).ambient(n_dot_v, s));
    // Another convention (the linear mapping's lod, the uniform table's coordinates) reads other texels.
    const float lod_linear = ibl::lod_from_roughness(ibl::roughness_mapping::linear, mat.roughness, float(chain.levels() - 1));
    const ibl::vec2<float> st_uniform = ibl::dfg_lut_coord(n_dot_v, mat.roughness, dfg.size, ibl::dfg_lut_layout::uniform());
    const float d_lod = rel_diff(chain.radiance(r_dir, lod_linear), ld);
    const float d_st = rel_diff(ibl::dfg_sample_st(dfg, st_uniform.x, st_uniform.y), ab);
    const bool ok = d_ms < 1e-5f && d_ss < 1e-5f && d_lod > 0.02f && d_st > 0.02f;
    std::printf("steps vs one call: %.2g (multiple), %.2g (single); other conventions move LD by %.3f, (A, B) by %.3f%s\n",
                double(d_ms), double(d_ss), double(d_lod), double(d_st), ok ? "" : "  FAILED");
    return ok ? 0 : 1;
}
