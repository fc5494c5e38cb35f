// examples/quickstart.cpp — README.md's "Start here": bake the three products a renderer reads
// (prefiltered specular chain, SH irradiance, DFG table) from an environment with the library
// alone, then shade a pixel from them as a renderer does.
//
// The lines between a "// [readme:NAME]" marker and the next are README.md's C++ snippets,
// verbatim (the quickstart_readme test compares them). The rest checks the result and prints it:
//   1. white furnace: a constant lat-long image (through the same wrapper a loaded HDRI takes)
//      lighting a white material must come back as the image's radiance, metal and dielectric, at
//      several (n.v, r): the default shading (multiple scattering) conserves energy exactly,
//      F_ss E_ss + F_ms E_ms + albedo E_dss = 1, whatever the table holds.
//   2. the lat-long wrapper's orientation: the built-in sky (without its sun) written as a
//      lat-long image and wrapped gives the SH irradiance of the same sky baked directly.
//   3. the built-in sky + sun (ibl::make_default_sky): each product against the library's own
//      reference (reference_ld_sky, reference_irradiance_sky, dfg_exact), and the shaded pixel
//      against the outgoing radiance without the split sum (reference_radiance, MIS).
// Exit status 0 = every check within its bound. Sizes are small (64^2 faces, a 32^2 table): the
// whole run takes well under a second with the dev preset.

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <span>
#include <vector>

// [readme:bake]
#include <ibl/ibl.hpp>

// The three products a renderer reads.
struct ibl_products {
    ibl::cubemap<float> chain;   // prefiltered specular: level l holds roughness l / (levels - 1)
    ibl::sh_coeffs<float, 3> sh; // radiance SH, 3 bands: the diffuse irradiance
    ibl::dfg_lut dfg;            // (A, B) on the uniform (n.v, roughness) grid
};

// Bakes them from an environment cube (its mips generated, as bake_cubemap leaves it).
ibl_products bake_products(const ibl::cubemap<float>& cube, std::uint32_t dfg_size) {
    return {ibl::prefilter(cube),        // n.l-weighted chain, automatic level count (64 -> 5 levels)
            ibl::project_cube<3>(cube),  // radiance SH of the cube's texels
            ibl::make_dfg_lut_exact<ibl::ggx_height_correlated>(dfg_size)};
}

// Your HDRI loader's float RGB lat-long image (w x h, row 0 = the top, +Y up) as a cube.
ibl::cubemap<float> cube_from_latlong(int w, int h, std::span<const float> rgb, int face_size) {
    ibl::latlong<float> image(w, h, rgb);
    image.sanitize(); // NaN, inf and negative texels -> 0
    image.generate_mips();
    return ibl::bake_cubemap<float>(image, face_size, 2); // 2 x 2 samples per texel, mips generated
}
// [readme:bake]

// [readme:shade]
// The ambient (image-based) radiance leaving a point towards the eye: unit normal n, unit
// direction to the eye v. What a fragment shader computes from the three products.
ibl::vec3<float> shade(const ibl_products& p, const ibl::pbr_material<float>& mat, ibl::vec3<float> n,
                       ibl::vec3<float> v) {
    const ibl::vec3<float> e_over_pi = glm::max(ibl::sh_irradiance_at(p.sh, n) * ibl::inv_pi_v<float>, 0.0f);
    const ibl::ibl_sample<float> s =
        ibl::ibl_lookup_sample(p.chain, ibl::specular_lookup_desc{}, p.dfg, n, v, mat.roughness, e_over_pi);
    return ibl::pbr_shader<float>::from(mat).ambient(glm::dot(n, v), s);
}
// [readme:shade]

namespace {

int failures = 0;

void check(const char* what, double error, double bound) {
    const bool ok = error <= bound;
    std::printf("  %-58s %.3g (bound %.3g)%s\n", what, error, bound, ok ? "" : "  FAILED");
    if (!ok) ++failures;
}

double max_rel(const ibl::vec3<double>& got, const ibl::vec3<double>& want) {
    double e = 0.0;
    for (int c = 0; c < 3; ++c) e = std::max(e, std::abs(got[c] - want[c]) / std::abs(want[c]));
    return e;
}

ibl::vec3<float> view_at(const ibl::vec3<float>& n, float n_dot_v) {
    // a direction at angle acos(n_dot_v) from n, tilted towards +X (n is never +-X here)
    const ibl::vec3<float> t = glm::normalize(glm::cross(glm::cross(n, ibl::vec3<float>(1, 0, 0)), n));
    return glm::normalize(n_dot_v * n + std::sqrt(1.0f - n_dot_v * n_dot_v) * t);
}

void white_furnace() {
    std::printf("white furnace: a constant 32 x 16 lat-long image of radiance (0.5, 1, 2)\n");
    const int w = 32, h = 16;
    std::vector<float> rgb(std::size_t(3 * w * h));
    for (std::size_t i = 0; i < rgb.size(); i += 3) rgb[i] = 0.5f, rgb[i + 1] = 1.0f, rgb[i + 2] = 2.0f;
    const ibl::vec3<double> L(0.5, 1.0, 2.0);
    const ibl_products p = bake_products(cube_from_latlong(w, h, rgb, 32), 32);
    double worst = 0.0;
    const ibl::vec3<float> n = glm::normalize(ibl::vec3<float>(0.3f, 0.8f, -0.5f));
    for (float metallic : {0.0f, 1.0f})
        for (float r : {0.0f, 0.1f, 0.37f, 0.8f, 1.0f})
            for (float nv : {0.05f, 0.4f, 1.0f}) {
                ibl::pbr_material<float> mat;
                mat.base_color = ibl::vec3<float>(1.0f);
                mat.metallic = metallic;
                mat.roughness = r;
                worst = std::max(worst, max_rel(ibl::vec3<double>(shade(p, mat, n, view_at(n, nv))), L));
            }
    check("white material, 30 (metal, r, n.v): max relative error", worst, 1e-4);
}

void sky_and_sun() {
    std::printf("built-in sky + sun: 64^2 cube, chain 64^2 (5 levels), 32^2 DFG table\n");
    // [readme:sky]
    const auto sky = ibl::make_default_sky<float>(); // a blue sky with a sun (env/analytic.hpp)
    const ibl_products products = bake_products(ibl::bake_cubemap<float>(sky, 64, 4), 32);

    ibl::pbr_material<float> mat;
    mat.base_color = {0.8f, 0.5f, 0.3f};
    mat.roughness = 0.5f;
    const ibl::vec3<float> n(0.0f, 1.0f, 0.0f), v = glm::normalize(ibl::vec3<float>(-0.6f, 0.8f, -0.2f));
    const ibl::vec3<float> color = shade(products, mat, n, v);
    // For a shader (ibl_sh.glsl, sh.json "irradiance_over_pi_shader"): nine vec3 constants c_k
    // with E(n)/pi = c0 + c1 y + c2 z + c3 x + c4 xy + c5 yz + c6 (3z^2 - 1) + c7 xz + c8 (x^2 - y^2).
    const ibl::sh_coeffs<float, 3> sh_uniforms =
        ibl::sh_shader_coeffs(products.sh, ibl::sh_shader_output::irradiance_over_pi);
    // [readme:sky]
    std::printf("  shaded pixel (r 0.5, n.v %.2f): (%.4f, %.4f, %.4f); chain levels %d\n", double(glm::dot(n, v)),
                double(color.x), double(color.y), double(color.z), products.chain.levels());

    // The shader constants give the same E/pi as the SH.
    const ibl::vec3<double> e_sh(ibl::sh_irradiance_at(products.sh, n) * ibl::inv_pi_v<float>);
    check("shader SH constants vs sh_irradiance_at / pi", max_rel(ibl::vec3<double>(ibl::sh_shader_evaluate(sh_uniforms, n)), e_sh),
          1e-5);

    // Each product against the library's references.
    const ibl::vec3<double> nd(n), vd(v);
    const ibl::vec3<double> rd = 2.0 * glm::dot(nd, vd) * nd - vd;
    const ibl::vec3<double> e_ref = ibl::reference_irradiance_sky(sky, nd) * ibl::inv_pi_v<double>;
    // Bounds: what these sizes measure here, with margin; a wrong convention (a flipped axis, a
    // factor pi, the table read transposed) is off by far more. 3-band SH irradiance under a sun
    // errs by its band limit (5.2% here); filtered importance sampling near a sun at 64^2 by
    // 2-14% per level (docs/ibl-bake.md: larger bakes and higher quality reduce it).
    check("diffuse E/pi (3-band SH) vs reference_irradiance_sky", max_rel(e_sh, e_ref), 0.08);
    const int levels = products.chain.levels();
    double ld_err = 0.0;
    for (int l = 1; l < levels; ++l) { // at each level's own roughness, where the lookup reads one level
        const double r = double(l) / double(levels - 1);
        const ibl::vec3<double> ld(ibl::specular_lookup(products.chain, ibl::vec3<float>(rd), float(r)));
        ld_err = std::max(ld_err, max_rel(ld, ibl::reference_ld_sky(sky, rd, r)));
    }
    check("specular LD at R, each level's r, vs reference_ld_sky", ld_err, 0.2);
    const float nv = glm::dot(n, v);
    const ibl::vec3<float> ab = ibl::dfg_lookup(products.dfg, nv, mat.roughness);
    const ibl::vec2<double> ab_ref = ibl::dfg_exact<ibl::ggx_height_correlated, double>(nv, mat.roughness);
    check("DFG (A, B) at (n.v, r) vs dfg_exact",
          std::max(std::abs(ab.x - ab_ref.x), std::abs(ab.y - ab_ref.y)), 2e-3);

    // The shaded pixel against the outgoing radiance without the split sum (MIS of the BRDF and
    // the environment, single scattering; the diffuse weighted by 1 - F_roughness(n.v) as in the
    // split sum's kD). Bound: the split sum's own error at this point plus the products' errors
    // above (docs/ibl-bake.md measures the split sum's error per material: up to 78% for a
    // grazing metal under a sun; this rough dielectric seen at n.v 0.78 is a mild case).
    const ibl::cube_env_distribution dist = ibl::make_cube_env_distribution<float>(sky, 64, 4);
    const ibl::reference_material rm = ibl::make_reference_material(
        ibl::vec3<double>(mat.base_color), 0.0, mat.roughness, ibl::diffuse_weighting::one_minus_fresnel_roughness);
    const ibl::radiance_estimate ref = ibl::reference_radiance(sky, dist, nd, vd, rm);
    std::printf("  reference (MIS, %llu samples): (%.4f, %.4f, %.4f) +- (%.1e, %.1e, %.1e)\n",
                static_cast<unsigned long long>(ref.samples), ref.value.x, ref.value.y, ref.value.z, ref.std_error.x,
                ref.std_error.y, ref.std_error.z);
    check("shaded pixel vs reference_radiance (split sum + bake)", max_rel(ibl::vec3<double>(color), ref.value), 0.1);
}

// cube_from_latlong's orientation: the sky without its sun written as a lat-long image in the
// convention of env/latlong.hpp (row 0 = +Y, column 0 = -X), wrapped, against the same sky baked
// directly. A flipped or rotated image moves the sky and the dark ground: E/pi changes by far more.
void latlong_orientation() {
    std::printf("lat-long wrapper: the sky without its sun as a 128 x 64 image vs baked directly\n");
    auto sky = ibl::make_default_sky<float>();
    sky.sun_radiance = ibl::vec3<float>(0.0f);
    const int w = 128, h = 64;
    std::vector<float> rgb(std::size_t(3 * w * h));
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const double phi = 2.0 * ibl::pi_v<double> * ((x + 0.5) / w - 0.5);
            const double lat = ibl::pi_v<double> * (0.5 - (y + 0.5) / h);
            const ibl::vec3<float> d(float(std::cos(lat) * std::cos(phi)), float(std::sin(lat)),
                                     float(std::cos(lat) * std::sin(phi)));
            const ibl::vec3<float> L = sky.radiance(d);
            for (int c = 0; c < 3; ++c) rgb[std::size_t(3 * (y * w + x) + c)] = L[c];
        }
    const ibl::sh_coeffs<float, 3> from_image = ibl::project_cube<3>(cube_from_latlong(w, h, rgb, 32));
    const ibl::sh_coeffs<float, 3> direct = ibl::project_cube<3>(ibl::bake_cubemap<float>(sky, 32, 4));
    double worst = 0.0;
    for (const ibl::vec3<float> n : {ibl::vec3<float>(1, 0, 0), ibl::vec3<float>(-1, 0, 0), ibl::vec3<float>(0, 1, 0),
                                     ibl::vec3<float>(0, -1, 0), ibl::vec3<float>(0, 0, 1), ibl::vec3<float>(0, 0, -1)})
        worst = std::max(worst, max_rel(ibl::vec3<double>(ibl::sh_irradiance_at(from_image, n)),
                                        ibl::vec3<double>(ibl::sh_irradiance_at(direct, n))));
    check("SH irradiance at the six axes: max relative difference", worst, 0.01);
}

} // namespace

int main() {
    white_furnace();
    latlong_orientation();
    sky_and_sun();
    std::printf(failures == 0 ? "quickstart: all checks passed\n" : "quickstart: %d check(s) FAILED\n", failures);
    return failures == 0 ? 0 : 1;
}
