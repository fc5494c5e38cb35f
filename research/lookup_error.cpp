// research/lookup_error.cpp — what a renderer gets: the error of the runtime lookups (ibl/runtime/lookup.hpp)
// at roughness between the baked levels and at n.v, r between the DFG table's texels, measured by
// reference/lookup_error.hpp against exact references.
// Produces: every table of docs/lookup.md (pasted from its output). Regenerate with
//   cmake --preset release && cmake --build --preset release --target lookup_error
//   ./build/release/research/lookup_error [dfg|spec|spec-quick]    (spec: about 6 minutes on 2 cores)
//
//   lookup_error            both parts
//   lookup_error dfg        DFG table sizes x layouts x storage (float / half)
//   lookup_error spec       specular chains (level count, spacing, base size) x lookup schemes on
//                           the built-in sky + sun and tests/data/{courtyard,studio}.exr
//   lookup_error spec-quick the tool's chain only (256, 6 levels) and the chosen scheme
//   lookup_error spec-fast  the chains of `spec` filtered by the fast filter (bake/prefilter_fast.hpp,
//                           128 samples at level 1 doubled per level: ibl-bake --prefilter fast
//                           --quality high) with their bake time, two schemes (the spacing study:
//                           more levels cost the fast filter little, so what do they buy?)
//
// Specular: each environment is baked to a 512^2 source cube (full exact-box mip chain); each chain
// is ibl::prefilter of that cube as ibl-bake does at its default quality (filtered importance
// sampling, trilinear reads, lod bias 0.5, 512 samples at level 1 doubled per coarser level, at most
// 16384). The exact LD: ibl::reference_ld_sky (sky: GGX IS of the sky without its sun, 4096
// samples, plus quadrature over the sun cap, 32 radial nodes), ibl::reference_ld_texel_sum over the
// source cube (lat-long inputs; level by reference_ld_texel_level; the column "ref" is the largest
// relative RMSE between that level and the next finer one over the roughness list: a bound on the
// reference's own error). Directions: texel centres of an 8 x 8-per-face cube (384) and a 7 x 7 block
// about the brightest source texel at 0.025 rad spacing (49). Metric: relative RMSE of luminance
// (floor 1e-3 x the mean), over r = 0.25, 0.30, ..., 1.00; "worst" is the largest over that list.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include <ibl/brdf/model.hpp>
#include <ibl/core/executor.hpp>
#include <ibl/env/analytic.hpp>
#include <ibl/env/convert.hpp>
#include <ibl/env/latlong.hpp>
#include <ibl/reference/lookup_error.hpp>
#include <ibl/bake/prefilter.hpp>
#include <ibl/reference/ld_irradiance.hpp>
#include <ibl/runtime/lookup.hpp>

#if defined(IBL_RESEARCH_DATA_DIR)
#include "io/image_io.hpp"
#endif

namespace {

using d3 = ibl::vec3<double>;
using model = ibl::ggx_height_correlated;

double seconds_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// ---- DFG -----------------------------------------------------------------------------------------

const char* axis_name(ibl::dfg_axis a) {
    return a == ibl::dfg_axis::sqrt ? "sqrt" : (a == ibl::dfg_axis::cbrt ? "cbrt" : "lin");
}

void run_dfg() {
    std::printf("== DFG lookup (ggx_height_correlated): max |A - A_exact|, |B - B_exact| over a dense grid\n");
    std::printf("   grid: n.v uniform and quadratic (257 each, 0 and 1 included) x r in [0.05, 1] (191)\n\n");
    const auto t0 = std::chrono::steady_clock::now();
    const ibl::dfg_error_grid grid = ibl::dfg_error_grid::dense();
    const std::vector<ibl::vec2<double>> exact = ibl::dfg_exact_grid<model>(grid);
    // The same grid split at n.v = 0.1 (the grazing band where the uniform table is worst).
    ibl::dfg_error_grid graze = grid, rest = grid;
    graze.n_dot_v.clear();
    rest.n_dot_v.clear();
    for (double x : grid.n_dot_v) (x < 0.1 ? graze : rest).n_dot_v.push_back(x);
    const std::vector<ibl::vec2<double>> exact_graze = ibl::dfg_exact_grid<model>(graze);
    const std::vector<ibl::vec2<double>> exact_rest = ibl::dfg_exact_grid<model>(rest);
    std::printf("exact grid: %zu points, %.1f s\n\n", exact.size() + exact_graze.size() + exact_rest.size(), seconds_since(t0));

    std::printf("| size | n.v axis | r axis | centres | bytes RG16F | max err (f32) | at (n.v, r) | n.v < 0.1 | n.v >= 0.1 | RMS | max err (f16) |\n");
    std::printf("|---|---|---|---|---|---|---|---|---|---|---|\n");
    const ibl::dfg_lut_layout layouts[] = {ibl::dfg_lut_layout::uniform(),
                                           {ibl::dfg_axis::linear, ibl::dfg_axis::linear, true},
                                           {ibl::dfg_axis::sqrt, ibl::dfg_axis::linear, false},
                                           {ibl::dfg_axis::sqrt, ibl::dfg_axis::linear, true},
                                           {ibl::dfg_axis::sqrt, ibl::dfg_axis::sqrt, true},
                                           {ibl::dfg_axis::cbrt, ibl::dfg_axis::linear, true},
                                           {ibl::dfg_axis::cbrt, ibl::dfg_axis::sqrt, true}};
    for (const std::uint32_t size : {32u, 64u, 128u, 256u}) {
        for (const auto& lay : layouts) {
            const ibl::dfg_lut lut = ibl::make_dfg_lut_exact<model>(size, lay, 2);
            const ibl::dfg_lookup_report e = ibl::dfg_lookup_error(lut, grid, exact);
            const ibl::dfg_lookup_report eg = ibl::dfg_lookup_error(lut, graze, exact_graze);
            const ibl::dfg_lookup_report er = ibl::dfg_lookup_error(lut, rest, exact_rest);
            const ibl::dfg_lut lut_h = ibl::quantize_half_lut(lut);
            const ibl::dfg_lookup_report eh = ibl::dfg_lookup_error(lut_h, grid, exact);
            std::printf("| %u | %s | %s | %s | %u | %.2e | (%.4f, %.3f) | %.2e | %.2e | %.1e | %.2e |\n", size,
                        axis_name(lay.n_dot_v), axis_name(lay.roughness), lay.edge_aligned ? "edge" : "sampler", size * size * 4u, e.max_abs,
                        e.worst_n_dot_v, e.worst_roughness, eg.max_abs, er.max_abs, e.rms, eh.max_abs);
        }
    }
    std::printf("\n");
}

// ---- specular ------------------------------------------------------------------------------------

struct chain_config {
    const char* name;
    ibl::roughness_mapping mapping;
    int base;
    int levels;
};

struct scheme {
    const char* name;
    ibl::specular_lookup_desc desc = ibl::specular_lookup_desc::accurate(); // mapping is overwritten by the chain's
};

std::vector<std::uint32_t> tool_samples(int levels) {
    std::vector<std::uint32_t> s(std::size_t(levels), 0u);
    for (int l = 1; l < levels; ++l) s[std::size_t(l)] = std::min<std::uint32_t>(512u << (l - 1), 16384u);
    return s;
}

ibl::cubemap<float> bake_chain(const ibl::cubemap<float>& src, const chain_config& c, bool fast = false) {
    ibl::prefilter_options o;
    o.levels = c.levels;
    o.base_size = c.base;
    o.policy = ibl::roughness_mip_policy{c.mapping};
    o.trilinear = true;
    o.samples_per_level = tool_samples(c.levels);
    if (fast) { // 128 at level 1 doubled per level: the fast filter at ibl-bake's --quality high
        o.method = ibl::prefilter_method::fast;
        for (std::uint32_t& n : o.samples_per_level) n /= 4;
    }
    return ibl::prefilter(src, o, ibl::thread_executor{});
}

using ref_fn = std::function<std::vector<d3>(std::span<const d3>, double)>;

struct environment_case {
    std::string name;
    ibl::cubemap<float> source{1};
    ref_fn ref;
    double ref_self_error = 0.0; // texel-sum references: largest level-vs-finer-level rel RMSE
    std::map<double, std::vector<d3>> cache; // exact LD per roughness at the directions
    /// The memoised reference (one evaluation per distinct roughness over the whole run).
    ref_fn cached() {
        return [this](std::span<const d3> dirs, double r) {
            auto it = cache.find(r);
            if (it == cache.end()) it = cache.emplace(r, ref(dirs, r)).first;
            return it->second;
        };
    }
};

std::vector<double> target_roughness() {
    std::vector<double> r;
    for (int k = 5; k <= 20; ++k) r.push_back(0.05 * double(k));
    return r;
}

struct worst {
    double total = 0, interp = 0, levels = 0, r_total = 0;
};

worst summarise(const std::vector<ibl::specular_lookup_report>& rep) {
    worst w;
    for (const auto& x : rep) {
        if (x.total.rel_rmse > w.total) {
            w.total = x.total.rel_rmse;
            w.r_total = x.roughness;
        }
        w.interp = std::max(w.interp, x.interpolation.rel_rmse);
        w.levels = std::max(w.levels, x.levels.rel_rmse);
    }
    return w;
}

double chain_bytes_half(const ibl::cubemap<float>& c) {
    double b = 0;
    for (int l = 0; l < c.levels(); ++l) b += 6.0 * double(c.size(l)) * double(c.size(l)) * 8.0; // RGBA16F
    return b;
}

void run_spec(bool quick, bool fast = false) {
    std::vector<environment_case> envs;
    envs.reserve(3);
    const auto t0 = std::chrono::steady_clock::now();
    const int src_n = 512;
    {
        const ibl::sky_environment<double> sky = ibl::make_default_sky<double>();
        environment_case e;
        e.name = "sky + sun";
        e.source = ibl::bake_cubemap<float>(sky, src_n, 4, ibl::thread_executor{});
        e.ref = [sky](std::span<const d3> dirs, double r) {
            std::vector<d3> out(dirs.size());
            ibl::thread_executor{}(dirs.size(), [&](std::size_t b, std::size_t en) {
                for (std::size_t i = b; i < en; ++i) out[i] = ibl::reference_ld_sky(sky, dirs[i], r, 4096, 32);
            });
            return out;
        };
        envs.push_back(std::move(e));
    }
#if defined(IBL_RESEARCH_DATA_DIR)
    for (const char* file : {"courtyard.exr", "studio.exr"}) {
        const std::string path = std::string(IBL_RESEARCH_DATA_DIR) + "/" + file;
        try {
            const ibl_bake::image_rgb32f img = ibl_bake::read_latlong(path, {});
            ibl::latlong<float> map(img.width, img.height, std::span<const float>(img.rgb), 1);
            map.update_borders();
            environment_case e;
            e.name = file;
            e.source = ibl::bake_cubemap<float>(map, src_n, 2, ibl::thread_executor{});
            envs.push_back(std::move(e));
        } catch (const std::exception& ex) {
            std::printf("%s skipped: %s\n", file, ex.what());
        }
    }
    for (auto& e : envs) {
        if (e.ref) continue;
        const ibl::cubemap<float>* src = &e.source;
        e.ref = [src](std::span<const d3> dirs, double r) {
            return ibl::reference_ld_texel_sum(*src, ibl::reference_ld_texel_level(*src, r), dirs, r, ibl::thread_executor{});
        };
    }
#endif
    std::printf("sources baked (%d^2): %.1f s\n", src_n, seconds_since(t0));

    const std::vector<double> rs = target_roughness();
    std::vector<std::vector<d3>> dirs;
    for (auto& e : envs) {
        dirs.push_back(ibl::lookup_error_directions(8, ibl::brightest_direction(e.source, 0), 3, 0.025));
        if (e.name == "sky + sun") continue;
        // Reference self-check: the chosen level against the next finer one.
        const ibl::cubemap<float>& src = e.source;
        double worst_ref = 0.0;
        std::printf("reference self-check, %s: r, level size, rel RMSE against the next finer level:", e.name.c_str());
        for (const double r : rs) {
            const int l = ibl::reference_ld_texel_level(src, r);
            if (l == 0) continue;
            const auto a = ibl::reference_ld_texel_sum(src, l, dirs.back(), r, ibl::thread_executor{});
            const auto b = ibl::reference_ld_texel_sum(src, l - 1, dirs.back(), r, ibl::thread_executor{});
            double mean = 0;
            for (const auto& v : b) mean += ibl::luminance(v);
            mean /= double(b.size());
            ibl::error_accumulator acc2(1e-3 * mean);
            for (std::size_t i = 0; i < a.size(); ++i) acc2.add(ibl::luminance(a[i]), ibl::luminance(b[i]));
            worst_ref = std::max(worst_ref, acc2.finish().rel_rmse);
            std::printf(" %.2f/%d/%.4f", r, src.size(l), acc2.finish().rel_rmse);
        }
        std::printf("\n");
        e.ref_self_error = worst_ref;
    }

    std::vector<chain_config> chains = {{"linear 256 x 6 (tool)", ibl::roughness_mapping::linear, 256, 6},
                                        {"linear 256 x 8", ibl::roughness_mapping::linear, 256, 8},
                                        {"filament 256 x 6", ibl::roughness_mapping::filament, 256, 6},
                                        {"filament 256 x 8", ibl::roughness_mapping::filament, 256, 8},
                                        {"linear 512 x 9", ibl::roughness_mapping::linear, 512, 9},
                                        {"filament 512 x 9", ibl::roughness_mapping::filament, 512, 9}};
    std::vector<scheme> schemes = {
        {"lod (textbook)", ibl::specular_lookup_desc::textbook()},
        {"power 2", {ibl::roughness_mapping::linear, ibl::level_weight::power, 2.0, ibl::level_interpolation::linear}},
        {"log r, linear", {ibl::roughness_mapping::linear, ibl::level_weight::log, 1.0, ibl::level_interpolation::linear}},
        {"log r, geometric", {ibl::roughness_mapping::linear, ibl::level_weight::log, 1.0, ibl::level_interpolation::geometric}},
        {"catmull-rom lod", {ibl::roughness_mapping::linear, ibl::level_weight::lod, 1.0, ibl::level_interpolation::catmull_rom}},
        {"catmull-rom log r", {ibl::roughness_mapping::linear, ibl::level_weight::log, 1.0, ibl::level_interpolation::catmull_rom}},
    };
    if (quick) chains.resize(1);
    if (quick || fast) schemes = {schemes[0], schemes[3]};

    std::printf("\n== specular lookup: worst relative RMSE of luminance over r = 0.25..1 (total / interpolation only / levels only)\n");
    std::printf("| environment | chain | taps | scheme | total | at r | interpolation | levels | total, f16 chain | MB (f16) | bake s |\n");
    std::printf("|---|---|---|---|---|---|---|---|---|---|---|\n");
    std::vector<std::string> details;
    for (std::size_t ei = 0; ei < envs.size(); ++ei) {
        const environment_case& e = envs[ei];
        for (const auto& cc : chains) {
            const auto tb = std::chrono::steady_clock::now();
            const ibl::cubemap<float> chain = bake_chain(e.source, cc, fast);
            const ibl::cubemap<float> chain_h = ibl::quantize_half(chain);
            const double bake_s = seconds_since(tb);
            for (const auto& s : schemes) {
                ibl::specular_lookup_desc d = s.desc;
                d.mapping = cc.mapping;
                const auto rep = ibl::specular_lookup_error(chain, d, rs, dirs[ei], envs[ei].cached());
                const auto rep_h = ibl::specular_lookup_error(chain_h, d, rs, dirs[ei], envs[ei].cached());
                const worst w = summarise(rep), wh = summarise(rep_h);
                std::printf("| %s | %s | %d | %s | %.4f | %.2f | %.4f | %.4f | %.4f | %.2f | %.2f |\n", e.name.c_str(), cc.name,
                            d.interpolation == ibl::level_interpolation::catmull_rom ? 4 : 2, s.name, w.total, w.r_total,
                            w.interp, w.levels, wh.total, chain_bytes_half(chain) / 1048576.0, bake_s);
                std::fflush(stdout);
                if (&cc == &chains[0] && (&s == &schemes[0] || std::strcmp(s.name, "log r, geometric") == 0)) {
                    std::string t = "\n" + e.name + ", " + cc.name + ", " + s.name + ":\n| r | total | interpolation | levels | max overshoot |\n|---|---|---|---|---|\n";
                    for (const auto& x : rep) {
                        char buf[160];
                        std::snprintf(buf, sizeof buf, "| %.2f | %.4f | %.4f | %.4f | %.2f |\n", x.roughness, x.total.rel_rmse,
                                      x.interpolation.rel_rmse, x.levels.rel_rmse, x.total.max_ratio);
                        t += buf;
                    }
                    details.push_back(t);
                }
            }
            std::fprintf(stderr, "%s / %s: bake %.1f s, total %.1f s\n", e.name.c_str(), cc.name, bake_s, seconds_since(t0));
        }
    }
    for (const auto& e : envs)
        if (e.ref_self_error > 0) std::printf("\nreference self-check (%s): level vs finer level, worst rel RMSE %.4f", e.name.c_str(), e.ref_self_error);
    std::printf("\n");
    for (const auto& t : details) std::printf("%s", t.c_str());
}

} // namespace

int main(int argc, char** argv) {
    const std::string mode = argc > 1 ? argv[1] : "all";
    if (mode == "all" || mode == "dfg") run_dfg();
    if (mode == "all" || mode == "spec" || mode == "spec-quick") run_spec(mode == "spec-quick");
    if (mode == "spec-fast") run_spec(false, true);
    return 0;
}
