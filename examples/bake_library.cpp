// examples/bake_library.cpp — a bake configured as a production bake, with the library alone (no
// image files): an analytic sky -> a source cube -> the prefiltered specular chain, the diffuse
// irradiance as a cubemap and as windowed SH, and the DFG table. quickstart.cpp bakes with the
// defaults; this one makes each choice explicit and prints what the products record of their
// conventions (what a renderer must read them with). Checks, each printed (exit status 1 and
// "FAILED" if one is off): the chain records its mapping and weight; the SH window keeps E >= 0
// where the raw projection rings negative under the sun; the irradiance map and the windowed SH
// agree with the sky's reference irradiance; the table conserves energy (A + B <= 1).
#include <ibl/bake.hpp>      // the producers (with the runtime/ parts they use)
#include <ibl/env.hpp>       // the analytic sky, the cube bake
#include <ibl/sh.hpp>        // SH projection and window
#include <ibl/reference.hpp> // only for the checks: reference_irradiance_sky

#include <algorithm>
#include <cmath>
#include <cstdio>

static int failures = 0;
static void check(const char* what, bool ok) {
    std::printf("  %-66s %s\n", what, ok ? "ok" : "FAILED");
    failures += ok ? 0 : 1;
}

int main() {
    // 1. The environment: the built-in sky with its 1-degree sun, baked to a 64^2 source cube with
    //    4 x 4 samples per texel and its mip chain (filtered importance sampling reads the mips).
    const auto sky = ibl::make_default_sky<float>();
    const ibl::cubemap<float> source = ibl::bake_cubemap<float>(sky, 64, 4);

    // 2. Specular: 5 levels (64^2 .. 4^2), Filament's roughness mapping (lod = r (2 - r) (levels - 1)),
    //    the D G1 weight, 256 filtered-IS samples per texel.
    ibl::prefilter_options opt;
    opt.levels = 5;
    opt.policy = ibl::roughness_mip_policy::filament();
    opt.weight = ibl::ld_weight::g1;
    opt.samples = 256;
    const ibl::specular_chain chain = ibl::prefilter(source, opt);

    // 3. Diffuse: an irradiance cubemap (16^2; it holds E, not E/pi) by texel moments, the method
    //    that holds under a sun (sampled estimators miss it), or 3-band SH with the weakest window
    //    that keeps E >= 0 (sh/window.hpp).
    ibl::irradiance_options io;
    io.size = 16;
    io.method = ibl::irradiance_method::texel_moments;
    const ibl::cubemap<float> irradiance = ibl::irradiance_cubemap(source, io);
    const ibl::sh_auto_window_result<float, 3> sh = ibl::sh_auto_window(ibl::project_cube<3>(source));

    // 4. DFG: 64^2 in the remapped layout (cbrt(n.v) x sqrt(r), edge aligned), 3 channels: (A, B)
    //    and the multiple-scattering channel k.
    const ibl::dfg_lut dfg = ibl::make_dfg_lut_exact<ibl::ggx_height_correlated>(64, ibl::dfg_lut_layout::remapped(), 3);

    std::printf("chain: %d levels from %d^2, mapping %s, LD weight %s\n", chain.levels(), chain.size(0),
                chain.mapping == ibl::roughness_mapping::filament ? "filament" : "linear",
                chain.weight == ibl::ld_weight::g1 ? "G1" : "n.l");
    std::printf("sh: window width %.3g, smallest E (red) %.4g raw, %.4g windowed\n", double(sh.width),
                double(sh.min_before.x), double(sh.min_after.x));
    std::printf("dfg: %u^2, %u channels, layout %s, model %s\n", dfg.size, dfg.channels, dfg.layout.name().c_str(),
                dfg.model.c_str());

    check("the chain records the mapping and the weight it was baked with",
          chain.mapping == opt.policy.mapping && chain.weight == opt.weight && chain.levels() == 5);
    check("raw SH irradiance < 0 somewhere; windowed >= 0 everywhere",
          sh.min_before.x < 0.0f && sh.ok && sh.min_after.x >= 0.0f && sh.min_after.y >= 0.0f && sh.min_after.z >= 0.0f);
    // Irradiance at the six axes against the sky's reference: RMS(dE) / RMS(E), as the plan measures.
    double ss_ref = 0.0, ss_map = 0.0, ss_sh = 0.0;
    for (int axis = 0; axis < 6; ++axis) {
        ibl::vec3<float> n(0.0f);
        n[axis / 2] = axis % 2 ? -1.0f : 1.0f;
        const ibl::vec3<double> ref = ibl::reference_irradiance_sky(sky, ibl::vec3<double>(n));
        const ibl::vec3<double> map(irradiance.radiance(n)), e_sh(ibl::sh_irradiance_at(sh.radiance, n));
        ss_ref += glm::dot(ref, ref);
        ss_map += glm::dot(map - ref, map - ref);
        ss_sh += glm::dot(e_sh - ref, e_sh - ref);
    }
    const double map_err = std::sqrt(ss_map / ss_ref), sh_err = std::sqrt(ss_sh / ss_ref);
    std::printf("irradiance at the six axes vs reference, RMS(dE)/RMS(E): map %.4f, windowed SH %.4f\n", map_err, sh_err);
    check("irradiance map within 4% of the reference", map_err < 0.04);
    check("windowed SH within 15% of the reference (3 bands under a sun)", sh_err < 0.15);
    float albedo = 0.0f;
    for (std::uint32_t j = 0; j < dfg.size; ++j)
        for (std::uint32_t i = 0; i < dfg.size; ++i) albedo = std::max(albedo, dfg.at(i, j, 0) + dfg.at(i, j, 1));
    check("DFG table: A + B <= 1 at every texel", albedo <= 1.0f + 1e-5f);
    std::printf(failures == 0 ? "bake_library: all checks passed\n" : "bake_library: %d check(s) FAILED\n", failures);
    return failures == 0 ? 0 : 1;
}
