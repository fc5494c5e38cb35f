// tools/ibl-bake/stages/probe_bake.cpp — see probe_bake.hpp.

#include "stages/probe_bake.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <filesystem>
#include <string>
#include <type_traits>
#include <vector>

#include <ibl/bake/plan.hpp>
#include <ibl/bake/prefilter.hpp>
#include <ibl/core/color.hpp>
#include <ibl/env/convert.hpp>
#include <ibl/env/cube_geometry.hpp>
#include <ibl/reference/ld_irradiance.hpp>
#include <ibl/reference/metrics.hpp>
#include <ibl/sh/convolve.hpp>
#include <ibl/sh/project.hpp>

#include "io/cube_layout.hpp"
#include "io/json.hpp"
#include "io/probes_reader.hpp"
#include "io/source_input.hpp"
#include "stages/check_texels.hpp"
#include "stages/output_stage.hpp"
#include "stages/stages.hpp"

namespace ibl_bake {

namespace {

/// The default full bake's plan (stage_plan.cpp): the tool's chain with the quality's samples,
/// doubled per coarser level.
ibl::bake_plan probe_plan(const bake_options& opt, const quality_settings& qs) {
    ibl::plan_settings set;
    set.levels = opt.levels > 0 ? opt.levels : auto_levels(opt.size);
    set.max_base_size = opt.size;
    set.policy = opt.policy;
    ibl::bake_plan p = ibl::full_bake_plan(set, qs.prefilter_samples, qs.trilinear, opt.lut_size);
    for (std::size_t l = 1; l < p.specular.levels.size(); ++l)
        p.specular.levels[l].samples = ibl::doubling_prefilter_samples(qs.prefilter_samples, int(l));
    return p;
}

/// One level's check (the full bake's specular check, stage_specular.cpp, with --checks fast's
/// settings): the chain's texels at check_texels against the level's reference.
struct probe_level_check {
    int size = 0;
    double roughness = 0.0;
    std::uint32_t samples = 0; ///< the plan's (filtered importance sampling's); chain_samples gives the filter's
    int level = 0;             ///< the level in the chain
    std::size_t texels = 0;
    ibl::error_metrics m;
    double ref_ms = 0.0;
};

struct baked_probe {
    cubemap_rgb32f chain;
    sh3 radiance{}, irradiance{};
    double ms = 0.0, check_ms = 0.0;
    int input_width = 0, input_height = 0;
    bool analytic = false;
    double floor = 0.0; ///< the checks' relative-error floor: 1e-3 x the capture's mean luminance
    std::vector<probe_level_check> levels;
    std::vector<ktx2_quantisation_level> quantisation;
};


/// Solid-angle-weighted mean luminance of level 0.
double mean_luminance(const ibl::cubemap<float>& cube) {
    const int n = cube.size(0);
    double sum = 0.0, wsum = 0.0;
    for (int f = 0; f < 6; ++f)
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
                const double w = ibl::cube_texel_solid_angle<double>(x, y, n);
                sum += w * ibl::luminance(dvec3(cube.texel(f, x, y, 0)));
                wsum += w;
            }
    return sum / wsum;
}

/// Every level of `chain` against its reference (level 0: the 16^2 sub-sampled texel mean of the
/// capture; rougher levels: ibl::reference_ld_sky, or ibl::ld_texel_sum over the capture's cube,
/// the chain's LD weight), at the full bake's check texels with --checks fast's grid and samples.
std::vector<probe_level_check> check_chain(const source_env& src, const ibl::cubemap<float>& source, const ibl::cubemap<float>& chain,
                                           const ibl::specular_plan& sp, ibl::ld_weight weight, const quality_settings& qc,
                                           double floor, pool_executor& ex) {
    const dvec3 light = brightest_direction(source, 0);
    std::vector<probe_level_check> out;
    for (int k = 0; k < chain.levels() && k < int(sp.levels.size()); ++k) {
        const auto t0 = std::chrono::steady_clock::now();
        const ibl::specular_level_plan& lp = sp.levels[std::size_t(k)];
        probe_level_check lc;
        lc.size = chain.size(k);
        lc.roughness = lp.roughness;
        lc.samples = lp.samples;
        lc.level = lp.level;
        const std::vector<std::array<int, 3>> texels = check_texels(lc.size, qc.ref_grid, light);
        const std::vector<dvec3> ref = chain_check_references(src, source, texels, lc.size, lp.level == 0, lc.roughness, qc, weight, ex);
        ibl::error_accumulator acc(floor);
        for (std::size_t i = 0; i < texels.size(); ++i)
            acc.add(dvec3(chain.texel(texels[i][0], texels[i][1], texels[i][2], k)), ref[i]);
        lc.m = acc.finish();
        lc.texels = texels.size();
        lc.ref_ms = ms_since(t0);
        out.push_back(lc);
    }
    return out;
}

void json_vec3(json_writer& j, const std::array<double, 3>& v) { j.begin_array().value(v[0]).value(v[1]).value(v[2]).end_array(); }

void json_volume(json_writer& j, const probe_volume_desc& v) {
    j.begin_object();
    if (v.sphere) {
        j.key("sphere").begin_object().key("center");
        json_vec3(j, v.center);
        j.key("radius").value(v.radius).end_object();
    } else if (v.oriented) {
        j.key("box").begin_object().key("center");
        json_vec3(j, v.center);
        j.key("half_extents");
        json_vec3(j, v.half_extents);
        j.key("axes").begin_array();
        for (const auto& a : v.axes) json_vec3(j, a);
        j.end_array().end_object();
    } else {
        j.key("box").begin_object().key("min");
        json_vec3(j, v.min);
        j.key("max");
        json_vec3(j, v.max);
        j.end_object();
    }
}

void json_sh(json_writer& j, const sh3& c) {
    j.begin_array();
    for (int k = 0; k < 9; ++k) j.begin_array().value(c[k].x).value(c[k].y).value(c[k].z).end_array();
    j.end_array();
}

} // namespace

void run_probe_bake(const bake_options& opt, std::FILE* out) {
    const auto t0 = std::chrono::steady_clock::now();
    const std::vector<probe_desc> probes = read_probes(opt.probes);
    check_output_dir(opt.out);
    const quality_settings qs = settings_for(opt.q);
    const ibl::bake_plan plan = probe_plan(opt, qs);
    const quality_settings qc = check_settings_for(qs, check_mode::fast); // report.json's checks
    pool_executor ex(opt.threads, nullptr);
    const bool filament = std::string(to_string(opt.policy)) == "filament";

    std::vector<baked_probe> baked(probes.size());
    std::vector<cubemap_rgb32f> layers;
    for (std::size_t i = 0; i < probes.size(); ++i) {
        const auto tp = std::chrono::steady_clock::now();
        bake_options po = opt;
        po.input = probes[i].input;
        source_env src;
        read_source(po, src);
        if (opt.mirror) mirror_source(src);
        const ibl::cubemap<float> source = bake_source(src, plan.source_size, qs.bake_k, ex);
        const ibl::cubemap<float> chain = bake_chain(source, plan.specular, opt.ld_weight, ex, opt.prefilter, opt.fast_peaks, opt.fast_sh_bands,
                                                     opt.fast_mid_tail);
        baked[i].radiance = ibl::project_cube<3>(
            source.size(0), [&](int f, int x, int y) { return dvec3(source.texel(f, x, y, 0)); }, ex);
        baked[i].irradiance = ibl::sh_irradiance(baked[i].radiance);
        layers.push_back(cubemap_to_rgb32f(chain));
        baked[i].ms = ms_since(tp);
        baked[i].input_width = src.width;
        baked[i].input_height = src.height;
        baked[i].analytic = src.analytic;
        const auto tc = std::chrono::steady_clock::now();
        baked[i].floor = 1e-3 * std::max(mean_luminance(source), 1e-30);
        baked[i].levels = check_chain(src, source, chain, plan.specular, opt.ld_weight, qc, baked[i].floor, ex);
        baked[i].check_ms = ms_since(tc);
    }

    const auto te = std::chrono::steady_clock::now();
    const std::string conventions =
        "cubemap array: layer = probes[i].layer, faces +X -X +Y -Y +Z -Z (GL), row 0 = t = 0; each layer a GGX-prefiltered chain "
        "read by textureLod(probes, vec4(dir, layer), lod(r)) (the textbook lookup under `mapping`)";
    ktx2_clamp_counts clamps;
    const std::vector<unsigned char> ktx = encode_ktx2_cubemap_array(
        layers, ktx2_format_of(opt.ktx2_format), "ibl-bake " + version_string(), "probes.ktx2", &clamps,
        {{"ibl.conventions", conventions}, {"ibl.product", "probe_set"}}, ktx2_encoding_of(opt));
    const double encode_ms = ms_since(te);
    // the storage's rounding per probe: each layer as the file decodes it against the float chain
    const std::vector<cubemap_rgb32f> decoded = decode_ktx2_cubemap_array(ktx, "probes.ktx2");
    for (std::size_t i = 0; i < layers.size(); ++i)
        baked[i].quantisation = ktx2_quantisation_report(layers[i], ktx2_format_of(opt.ktx2_format), &decoded[i]);

    json_writer j;
    j.begin_object();
    j.key("format").value("ibl-bake probe set").key("version").value(1);
    j.key("generator").value("ibl-bake " + version_string());
    j.key("texture").value("probes.ktx2");
    j.key("ktx2_format").value(to_string(opt.ktx2_format));
    j.key("face_size").value(layers.front().size);
    j.key("levels").value(int(layers.front().levels.size()));
    j.key("conventions").begin_object();
    j.key("cubemap").value(conventions);
    j.key("specular_lookup").value("textbook");
    j.key("mapping").value(filament ? "filament" : "linear");
    j.key("ld_weight").value(to_string(opt.ld_weight));
    j.key("level_roughness").begin_array();
    for (const ibl::specular_level_plan& l : plan.specular.levels) j.value(l.roughness);
    j.end_array();
    j.key("parallax").value("per probe: R' = parallax_correct(proxy, position, P, R) (ibl/runtime/local_probe.hpp), roughness "
                            "r' = corrected_roughness(r, d_shading, d_probe, cos_shading, cos_probe); no proxy hit: R and r unchanged");
    j.key("blend").value("w_i = influence_weight(influence, fade, P); contributions c_i = blend_probe_weights(w, priority) "
                         "(higher priority first); a probe set has no distant environment: the c_i are divided by their "
                         "sum when it is > 0, and when every w_i is 0 the nearest probe (distance to its position) is read "
                         "without parallax correction");
    j.key("irradiance").value("E(n) = max(0, sum_k sh_irradiance[k] Y_k(n)) (irradiance, not E/pi; SH3 real basis of "
                              "ibl/sh/basis.hpp, k = l (l + 1) + m); sh_radiance: the raw projection of the capture");
    j.end_object();
    j.key("probes").begin_array();
    for (std::size_t i = 0; i < probes.size(); ++i) {
        const probe_desc& p = probes[i];
        j.begin_object();
        j.key("layer").value(int(i));
        j.key("input").value(p.input);
        j.key("position");
        json_vec3(j, p.position);
        j.key("proxy");
        json_volume(j, p.proxy);
        j.end_object();
        j.key("influence");
        json_volume(j, p.influence);
        j.key("fade").value(p.fade).end_object();
        j.key("fade").value(p.fade);
        j.key("priority").value(p.priority);
        j.key("sh_radiance");
        json_sh(j, baked[i].radiance);
        j.key("sh_irradiance");
        json_sh(j, baked[i].irradiance);
        j.end_object();
    }
    j.end_array();
    j.end_object();

    // report.json: per probe its input, times, each level's check and the storage's rounding
    json_writer rj;
    rj.begin_object();
    rj.key("format").value(probe_report_format).key("version").value(1);
    rj.key("generator").value("ibl-bake " + version_string());
    rj.key("probes_file").value(opt.probes);
    rj.key("settings").begin_object();
    rj.key("face_size").value(layers.front().size).key("levels").value(int(layers.front().levels.size()));
    rj.key("quality").value(to_string(opt.q)).key("prefilter").value(to_string(opt.prefilter));
    rj.key("ld_weight").value(to_string(opt.ld_weight)).key("mapping").value(filament ? "filament" : "linear");
    rj.key("ktx2_format").value(to_string(opt.ktx2_format)).key("mirror").value(opt.mirror);
    rj.end_object();
    rj.key("check").begin_object();
    rj.key("reference").value("level 0: texel mean (16x16 sub-samples) of the capture; levels >= 1: ibl::reference_ld_sky "
                              "(built-in sky) or ibl::ld_texel_sum, the exact LD of the capture's cube (a texel sum in "
                              "double), with the chain's LD weight");
    rj.key("texels").value("per level: a grid per face plus the 3x3 block around the brightest direction (the full bake's "
                           "specular check with --checks fast's grid and samples)");
    rj.key("grid").value(qc.ref_grid);
    rj.key("sky_reference_samples").value(qc.sky_ref_samples);
    rj.end_object();
    rj.key("probes").begin_array();
    for (std::size_t i = 0; i < probes.size(); ++i) {
        const baked_probe& b = baked[i];
        rj.begin_object();
        rj.key("layer").value(int(i)).key("input").value(probes[i].input);
        rj.key("input_size").begin_array().value(b.input_width).value(b.input_height).end_array();
        rj.key("time_ms").value(b.ms).key("check_time_ms").value(b.check_ms);
        rj.key("relative_error_floor").value(b.floor);
        rj.key("levels").begin_array();
        for (std::size_t k = 0; k < b.levels.size(); ++k) {
            const probe_level_check& c = b.levels[k];
            rj.begin_object();
            rj.key("level").value(int(k)).key("size").value(c.size).key("roughness").value(c.roughness);
            rj.key("samples").value(chain_samples(c.samples, opt.prefilter, c.level));
            rj.key("texels_compared").value(c.texels).key("rel_rmse").value(c.m.rel_rmse).key("nrmse").value(c.m.nrmse);
            rj.key("max_overshoot").value(c.m.max_ratio).key("max_rel").value(c.m.max_rel);
            rj.key("reference_time_ms").value(c.ref_ms);
            rj.end_object();
        }
        rj.end_array();
        rj.key("ktx2_quantisation");
        json_quantisation(rj, b.quantisation, opt.ktx2_format);
        rj.end_object();
    }
    rj.end_array();
    rj.key("ktx2").begin_object().key("file").value("probes.ktx2").key("bytes").value(ktx.size()).key("encode_ms").value(encode_ms);
    rj.key("clamped").begin_object().key("above_range").value(clamps.above_range).key("negative").value(clamps.negative);
    rj.key("nan").value(clamps.nan).end_object().end_object();
    rj.key("time_ms").value(ms_since(t0));
    rj.end_object();

    output_stage stage(opt.out);
    write_file_atomic(stage.file("probes.ktx2"), ktx);
    write_text(stage.file("probes.json"), j.str() + "\n");
    write_text(stage.file("report.json"), rj.str() + "\n");
    stage.commit();

    std::fprintf(out, "ibl-bake %s: probe set %s -> %s\n", version_string().c_str(), opt.probes.c_str(), opt.out.c_str());
    for (std::size_t i = 0; i < probes.size(); ++i) {
        double worst = 0.0;
        for (std::size_t k = 1; k < baked[i].levels.size(); ++k) worst = std::max(worst, baked[i].levels[k].m.rel_rmse);
        std::fprintf(out, "  probe %-3zu %-32s %dx%d -> %d^2 x %zu levels, priority %d, %.0f ms, worst level rel RMSE %.3g\n", i,
                     std::filesystem::path(probes[i].input).filename().string().c_str(), baked[i].input_width,
                     baked[i].input_height, layers[i].size, layers[i].levels.size(), probes[i].priority, baked[i].ms, worst);
    }
    std::fprintf(out, "  probes.ktx2  %s cubemap array, %zu layers x 6 faces, %zu levels, %zu bytes, encoded in %.0f ms\n",
                 to_string(opt.ktx2_format), layers.size(), layers.front().levels.size(), ktx.size(), encode_ms);
    if (clamps.above_range + clamps.negative + clamps.nan > 0)
        std::fprintf(out, "  note: the format clamped %zu values above its range, %zu negatives, %zu NaN\n", clamps.above_range,
                     clamps.negative, clamps.nan);
    std::fprintf(out, "  probes.json  positions, proxies, influences, SH3, conventions\n");
    std::fprintf(out, "  report.json  per probe: input, times, each level's error against its reference, the storage's rounding\n");
    std::fprintf(out, "  total %.0f ms\n", ms_since(t0));
}

} // namespace ibl_bake
