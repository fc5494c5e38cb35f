// tools/ibl-bake/stages/probe_bake.cpp — see probe_bake.hpp.

#include "stages/probe_bake.hpp"

#include <chrono>
#include <filesystem>
#include <string>
#include <vector>

#include <ibl/bake/plan.hpp>
#include <ibl/bake/prefilter.hpp>
#include <ibl/sh/convolve.hpp>
#include <ibl/sh/project.hpp>

#include "io/cube_layout.hpp"
#include "io/json.hpp"
#include "io/probes_reader.hpp"
#include "io/source_input.hpp"
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

struct baked_probe {
    cubemap_rgb32f chain;
    sh3 radiance{}, irradiance{};
    double ms = 0.0;
    int input_width = 0, input_height = 0;
};

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
        const ibl::cubemap<float> chain = bake_chain(source, plan.specular, opt.ld_weight, ex, opt.prefilter);
        baked[i].radiance = ibl::project_cube<3>(
            source.size(0), [&](int f, int x, int y) { return dvec3(source.texel(f, x, y, 0)); }, ex);
        baked[i].irradiance = ibl::sh_irradiance(baked[i].radiance);
        layers.push_back(cubemap_to_rgb32f(chain));
        baked[i].ms = ms_since(tp);
        baked[i].input_width = src.width;
        baked[i].input_height = src.height;
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
                            "r' = corrected_roughness(r, d_shading, d_probe); no proxy hit: R and r unchanged");
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

    output_stage stage(opt.out);
    write_file_atomic(stage.file("probes.ktx2"), ktx);
    write_text(stage.file("probes.json"), j.str() + "\n");
    stage.commit();

    std::fprintf(out, "ibl-bake %s: probe set %s -> %s\n", version_string().c_str(), opt.probes.c_str(), opt.out.c_str());
    for (std::size_t i = 0; i < probes.size(); ++i)
        std::fprintf(out, "  probe %-3zu %-32s %dx%d -> %d^2 x %zu levels, priority %d, %.0f ms\n", i,
                     std::filesystem::path(probes[i].input).filename().string().c_str(), baked[i].input_width,
                     baked[i].input_height, layers[i].size, layers[i].levels.size(), probes[i].priority, baked[i].ms);
    std::fprintf(out, "  probes.ktx2  %s cubemap array, %zu layers x 6 faces, %zu levels, %zu bytes, encoded in %.0f ms\n",
                 to_string(opt.ktx2_format), layers.size(), layers.front().levels.size(), ktx.size(), encode_ms);
    if (clamps.above_range + clamps.negative + clamps.nan > 0)
        std::fprintf(out, "  note: the format clamped %zu values above its range, %zu negatives, %zu NaN\n", clamps.above_range,
                     clamps.negative, clamps.nan);
    std::fprintf(out, "  probes.json  positions, proxies, influences, SH3, conventions\n  total %.0f ms\n", ms_since(t0));
}

} // namespace ibl_bake
