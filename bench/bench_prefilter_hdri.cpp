// bench/bench_prefilter_hdri.cpp — the prefilter on a real HDRI: the courtyard of tests/data
// (1024 x 512 OpenEXR) baked to a 256^2 or 128^2 cube, its full chain (the automatic levels: 6,
// r = l / 5, as ibl-bake), filtered by the default filter (FIS, 512 x 2^(l-1) trilinear samples)
// and by the fast filter (range(1) x 4^(l-1) samples where a level keeps its tap set, the peak
// split, the coarse tail, and the rough levels by spherical harmonics when range(2) = 1).
// Counters rel_l (l = 1..5): the relative RMSE of luminance at 400 texels per level against the
// exact LD of the cube (ibl::ld_texel_sum at ibl::ld_texel_sum_level, ibl-bake's check),
// computed once per process outside the timed loop. Two threads (thread_executor{2}).
// BM_hdri_update_set_source: prefilter_update::set_source on the same cube (one thread).
#include <benchmark/benchmark.h>

#include <ibl/bake/prefilter.hpp>
#include <ibl/bake/prefilter_update.hpp>
#include <ibl/core/executor.hpp>
#include <ibl/env/convert.hpp>
#include <ibl/env/latlong.hpp>
#include <ibl/reference/ld_irradiance.hpp>
#include <ibl/reference/radiance.hpp>

#include "io/image_io.hpp"

#include <cmath>
#include <map>
#include <string>
#include <vector>

namespace {

const ibl::cubemap<float>& courtyard(int size) {
    static std::map<int, ibl::cubemap<float>> cache;
    auto it = cache.find(size);
    if (it == cache.end()) {
        const ibl_bake::image_rgb32f img = ibl_bake::read_latlong(std::string(IBL_BENCH_DATA_DIR) + "/courtyard.exr", {});
        ibl::latlong<float> map(img.width, img.height, std::span<const float>(img.rgb), 1);
        map.update_borders();
        const int k = std::max(2, int(std::ceil(double(img.width) / (4.0 * size))));
        it = cache.emplace(size, ibl::bake_cubemap<float>(map, size, k, ibl::thread_executor{2}, 0)).first;
    }
    return it->second;
}

struct level_ref {
    std::vector<int> f, x, y;
    std::vector<ibl::vec3<double>> ld;
};

/// Per chain level (index l, 1..levels-1): 400 texels and their exact LD.
const std::vector<level_ref>& references(int size) {
    static std::map<int, std::vector<level_ref>> cache;
    auto it = cache.find(size);
    if (it != cache.end()) return it->second;
    const ibl::cubemap<float>& cube = courtyard(size);
    ibl::prefilter_options o;
    const std::vector<ibl::prefilter_level> plan = ibl::prefilter_plan(o, size);
    std::vector<level_ref> refs(plan.size());
    for (std::size_t l = 1; l < plan.size(); ++l) {
        const int n = std::max(1, size >> l);
        level_ref& r = refs[l];
        std::vector<ibl::vec3<double>> dirs;
        for (std::uint32_t i = 0; i < 400; ++i) {
            const std::uint32_t h = ibl::detail::rr_hash(i * 0x9e3779b9u + std::uint32_t(l) * 7919u);
            r.f.push_back(int(h % 6u));
            r.x.push_back(int((h >> 3) % std::uint32_t(n)));
            r.y.push_back(int((h >> 13) % std::uint32_t(n)));
            dirs.push_back(ibl::cube_texel_direction<double>(r.f.back(), r.x.back(), r.y.back(), n));
        }
        r.ld = ibl::ld_texel_sum(cube, ibl::ld_texel_sum_level(cube, plan[l].roughness), std::span<const ibl::vec3<double>>(dirs),
                                 plan[l].roughness, o.weight, ibl::thread_executor{2});
    }
    return cache.emplace(size, std::move(refs)).first->second;
}

void run(benchmark::State& state, const ibl::prefilter_options& o, int size) {
    const ibl::cubemap<float>& src = courtyard(size);
    const std::vector<level_ref>& refs = references(size);
    ibl::cubemap<float> out(1);
    for (auto _ : state) {
        out = ibl::prefilter(src, o, ibl::thread_executor{2});
        benchmark::DoNotOptimize(out.texel(0, 0, 0, 1));
    }
    for (std::size_t l = 1; l < refs.size() && int(l) < out.levels(); ++l) {
        const level_ref& r = refs[l];
        double s = 0.0;
        for (std::size_t i = 0; i < r.ld.size(); ++i) {
            const double a = ibl::luminance(ibl::vec3<double>(out.texel(r.f[i], r.x[i], r.y[i], int(l)))), b = ibl::luminance(r.ld[i]);
            s += (a - b) * (a - b) / (b * b);
        }
        state.counters["rel_" + std::to_string(l)] = std::sqrt(s / double(r.ld.size()));
    }
}

/// args: size. The default filter (filtered importance sampling, ibl-bake's default).
void BM_hdri_fis_default(benchmark::State& state) { run(state, ibl::prefilter_options{}, int(state.range(0))); }

/// args: size, samples at level 1 (x 4 per level), sh (the rough levels by spherical harmonics).
void BM_hdri_fast(benchmark::State& state) {
    ibl::prefilter_options o;
    o.method = ibl::prefilter_method::fast;
    const int size = int(state.range(0));
    const std::size_t levels = ibl::prefilter_plan(o, size).size();
    for (std::size_t l = 0; l < levels; ++l) o.samples_per_level.push_back(ibl::equal_cost_prefilter_samples(std::uint32_t(state.range(1)), int(l)));
    o.sh_rough.enabled = state.range(2) != 0;
    run(state, o, size);
}

/// args: size. prefilter_update::set_source on the courtyard with the fast default: the work a
/// new source costs outside the update's budget (its copy of the source, the peak split and the
/// levels' merged peaks). Counter peaks: the split's peaks.
void BM_hdri_update_set_source(benchmark::State& state) {
    ibl::prefilter_options o;
    o.method = ibl::prefilter_method::fast;
    const ibl::cubemap<float>& src = courtyard(int(state.range(0)));
    ibl::prefilter_update<> up(src, o);
    for (auto _ : state) up.set_source(src);
    ibl::serial_executor one;
    state.counters["peaks"] = double(ibl::detail::find_cube_peaks(src, o.peaks, one).peaks.size());
}

} // namespace

BENCHMARK(BM_hdri_update_set_source)->ArgName("size")->Arg(256)->Arg(128)->Unit(benchmark::kMicrosecond)->UseRealTime();
BENCHMARK(BM_hdri_fis_default)->ArgName("size")->Arg(256)->Arg(128)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_hdri_fast)
    ->ArgNames({"size", "spp", "sh"})
    ->ArgsProduct({{256, 128}, {32, 48, 64}, {0, 1}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
