// research/peak_budget_study.cpp — the fast filter's peak split against its cost: how many
// level-0 texels the split may take out (peak_split_options::max_peaks) and what that does to the
// chain's time and its error, on the built-in sky + sun and the HDRIs of tests/data, at 256^2 and
// 128^2 (docs/ibl-bake.md, "Fast filter": the table "Peaks per texel").
//
// Why. Each output texel adds every merged peak in front of its row exactly (bake/prefilter_peaks.hpp),
// so the split's cost grows with the number of peaks. A sun is a few texels, but a source whose
// bright part is extended (a lit cloud, a window) has thousands of texels above ratio x its mean,
// and max_peaks caps them by raising the threshold: the rest stays in what the tap set and the
// projection read, at a contrast the threshold bounds. This study measures, per cap, the
// threshold over the mean, the merged peaks of level 1, the chain's time (prefilter, fast filter,
// 2 threads, median of `reps`) and each level's relative RMSE of luminance at 400 random texels
// against the exact LD of the source cube (ibl::ld_texel_sum, as ibl-bake's check), next to the
// default filter (FIS) the fast filter must not be worse than.
//
// Run: build/release/research/peak_budget_study [--reps N] [--quick] [FILE.exr ...] (a minute;
// --quick: the courtyard at 128^2, two caps, the ctest).

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include <ibl/bake/prefilter.hpp>
#include <ibl/env/analytic.hpp>
#include <ibl/reference/ld_irradiance.hpp>

#include "ld_study.hpp"

namespace {

struct variant {
    std::string name;
    ibl::prefilter_options opt;
};

void run_study(const std::string& name, const ibl::cubemap<float>& src, const std::vector<variant>& variants, int reps, int texels) {
    ibl::thread_executor ex{2};
    const int size = src.size(0);
    const ibl::prefilter_options base_opt;
    const std::vector<ibl::prefilter_level> plan = ibl::prefilter_plan(base_opt, size);
    std::vector<std::vector<ld_study::texel_ref>> refs(plan.size());
    for (std::size_t l = 1; l < plan.size(); ++l)
        refs[l] = ld_study::level_refs(src, ibl::ld_texel_sum_level(src, plan[l].roughness), int(l), std::max(1, size >> l), texels,
                                       plan[l].roughness, base_opt.weight, ex);
    std::printf("\n%s, %d^2, %zu levels\n\n", name.c_str(), size, plan.size());
    std::printf("| filter | threshold / mean | level-1 peaks | time | levels 1-%zu rel RMSE |\n|---|---|---|---|---|\n", plan.size() - 1);
    for (const variant& v : variants) {
        std::vector<double> t;
        ibl::specular_chain chain = ibl::prefilter(src, v.opt, ex); // warm: memoised tables
        for (int r = 0; r < reps; ++r) {
            const auto t0 = std::chrono::steady_clock::now();
            chain = ibl::prefilter(src, v.opt, ex);
            t.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
        }
        std::sort(t.begin(), t.end());
        std::string peaks = "-", ratio = "-";
        if (v.opt.method == ibl::prefilter_method::fast && v.opt.peaks.enabled) {
            const ibl::cube_peak_split<float> s = ibl::detail::find_cube_peaks(src, v.opt.peaks, ex);
            const ibl::peak_level pl = ibl::make_peak_level(s.peaks, size, src.levels(), plan[1].roughness, v.opt.weight,
                                                            v.opt.peaks.footprint, v.opt.peaks.max_merge_angle, s.mean_luminance,
                                                            v.opt.peaks.cut, v.opt.peaks.max_level_peaks, v.opt.peaks.max_level_steps);
            char b[64];
            std::snprintf(b, sizeof b, "%zu of %zu", pl.size(), s.peaks.size());
            peaks = b;
            std::snprintf(b, sizeof b, "%.3g", s.mean_luminance > 0.0 ? s.threshold / s.mean_luminance : 0.0);
            ratio = s.peaks.empty() ? "-" : b;
        }
        std::printf("| %s | %s | %s | %.1f ms |", v.name.c_str(), ratio.c_str(), peaks.c_str(), t[t.size() / 2]);
        for (std::size_t l = 1; l < plan.size(); ++l)
            std::printf(" %.3g", ld_study::rel_rmse(refs[l], [&](int f, int x, int y) { return chain.texel(f, x, y, int(l)); }));
        std::printf(" |\n");
        std::fflush(stdout);
    }
}

} // namespace

int main(int argc, char** argv) {
    int reps = 7;
    bool quick = false;
    std::vector<char*> rest{argv[0]};
    for (int i = 1; i < argc; ++i) {
        if (std::strcmp(argv[i], "--reps") == 0 && i + 1 < argc) reps = std::max(1, std::atoi(argv[++i]));
        else if (std::strcmp(argv[i], "--quick") == 0) quick = true;
        else rest.push_back(argv[i]);
    }
    const ld_study::args a = ld_study::parse(int(rest.size()), rest.data());
    std::vector<variant> variants;
    auto fast = [&](const std::string& what, auto&& set) {
        variant v{what, {}};
        v.opt.method = ibl::prefilter_method::fast;
        set(v.opt);
        variants.push_back(v);
    };
    if (!quick) variants.push_back({"FIS default", {}});
    fast("fast default (max_level_peaks 128, 2 steps)", [](ibl::prefilter_options&) {});
    fast("fast, max_level_peaks 128, 1 step", [](ibl::prefilter_options& o) { o.peaks.max_level_steps = 1; });
    fast("fast, every merged peak (max_level_peaks 0)", [](ibl::prefilter_options& o) { o.peaks.max_level_peaks = 0; });
    fast("fast, max_level_peaks 32", [](ibl::prefilter_options& o) { o.peaks.max_level_peaks = 32; });
    fast("fast, max_peaks 64 (threshold raised)", [](ibl::prefilter_options& o) { o.peaks.max_peaks = 64; });
    if (!quick) {
        fast("fast, max_peaks 256 (threshold raised)", [](ibl::prefilter_options& o) { o.peaks.max_peaks = 256; });
        for (const std::uint32_t spp : {48u, 56u})
            fast("fast, level 1 at " + std::to_string(spp) + " samples", [&](ibl::prefilter_options& o) { o.samples_per_level = {0, spp}; });
    }
    ibl::thread_executor ex{2};
    const std::vector<int> sizes = quick ? std::vector<int>{128} : std::vector<int>{256, 128};
    if (!quick) {
        const ibl::sky_environment<double> sky = ibl::make_default_sky<double>();
        for (const int size : sizes) run_study("sky + sun", ibl::bake_cubemap<float>(sky, size, 4, ex), variants, reps, a.texels);
    }
    for (const std::string& file : a.files) {
        const ibl::latlong<float> map = ld_study::load_latlong(file);
        const std::string name = file.substr(file.find_last_of('/') + 1);
        for (const int size : sizes) run_study(name, ld_study::source_cube(map, size, ex), variants, quick ? 1 : reps, a.quick ? 64 : a.texels);
    }
    return 0;
}
