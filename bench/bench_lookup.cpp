// bench_lookup: cost of the runtime lookups of ibl/runtime/lookup.hpp against their error.
//   BM_specular_lookup/<scheme>: one lookup of a 256^2 x 6-level prefiltered chain of the default
//     sky + sun (ibl-bake's default bake: filtered IS, trilinear, 512 spp at level 1 doubled per
//     level) at a random direction and roughness in [0.25, 1]; counters: rel_rmse_worst = the
//     largest relative RMSE of luminance over r = 0.25, 0.30, ..., 1 against reference_ld_sky at
//     64 texel-centre directions + the 5 x 5 block about the sun (research/lookup_error.cpp does
//     the full study), taps = bilinear reads per lookup.
//     schemes: 0 textbook (lod linear), 1 default (log r, geometric), 2 Catmull-Rom in lod.
//   BM_dfg_lookup/<layout>: one DFG table lookup (128^2, ggx_height_correlated) at a random
//     (n.v, r); counter max_abs_err = largest |A|, |B| error over a dense grid (r >= 0.05).
//     layouts: 0 uniform (dfg_lut.hpp), 1 default (cbrt n.v, sqrt r, edge-aligned centres).
// Run: ./build/release/bench/bench_lookup --benchmark_min_time=0.1
#include <benchmark/benchmark.h>

#include <ibl/env/analytic.hpp>
#include <ibl/env/convert.hpp>
#include <ibl/reference/lookup_error.hpp>
#include <ibl/bake/prefilter.hpp>
#include <ibl/reference/ld_irradiance.hpp>
#include <ibl/runtime/lookup.hpp>
#include <ibl/sampling/sequence.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace {

using d3 = ibl::vec3<double>;

const ibl::specular_lookup_desc& scheme(int k) {
    static const ibl::specular_lookup_desc s[3] = {
        ibl::specular_lookup_desc::textbook(), ibl::specular_lookup_desc::accurate(),
        {ibl::roughness_mapping::linear, ibl::level_weight::lod, 1.0, ibl::level_interpolation::catmull_rom}};
    return s[k];
}

struct spec_fixture {
    ibl::cubemap<float> chain{1};
    std::vector<d3> dirs;
    ibl::sky_environment<double> sky = ibl::make_default_sky<double>();
};

const spec_fixture& spec() {
    static const spec_fixture f = [] {
        spec_fixture x;
        const ibl::cubemap<float> src = ibl::bake_cubemap<float>(x.sky, 256, 4, ibl::thread_executor{});
        ibl::prefilter_options o;
        o.levels = 6;
        o.trilinear = true;
        o.samples_per_level = {0, 512, 1024, 2048, 4096, 8192};
        x.chain = ibl::prefilter(src, o, ibl::thread_executor{});
        x.dirs = ibl::lookup_error_directions(3, ibl::brightest_direction(src, 0), 2, 0.025);
        return x;
    }();
    return f;
}

void BM_specular_lookup(benchmark::State& state) {
    const spec_fixture& f = spec();
    const ibl::specular_lookup_desc& d = scheme(int(state.range(0)));
    std::vector<double> rs;
    for (int k = 5; k <= 20; ++k) rs.push_back(0.05 * k);
    auto ref = [&](std::span<const d3> dirs, double r) {
        std::vector<d3> out(dirs.size());
        ibl::thread_executor{}(dirs.size(), [&](std::size_t b, std::size_t e) {
            for (std::size_t i = b; i < e; ++i) out[i] = ibl::reference_ld_sky(f.sky, dirs[i], r, 2048, 24);
        });
        return out;
    };
    double worst = 0.0;
    for (const auto& x : ibl::specular_lookup_error(f.chain, d, rs, f.dirs, ref)) worst = std::max(worst, x.total.rel_rmse);
    std::vector<ibl::vec3<float>> dir(1024);
    std::vector<float> rough(1024);
    for (std::uint32_t i = 0; i < 1024; ++i) {
        const ibl::vec2<double> u = ibl::hammersley<double>(i, 1024);
        const double z = 1.0 - 2.0 * u.x, s = std::sqrt(1.0 - z * z), ph = 6.283185307179586 * u.y;
        dir[i] = ibl::vec3<float>(float(s * std::cos(ph)), float(s * std::sin(ph)), float(z));
        const double g = double(i) * 0.6180339887498949; // golden-ratio sequence in [0, 1)
        rough[i] = 0.25f + 0.75f * float(g - std::floor(g));
    }
    std::size_t i = 0;
    for (auto _ : state) {
        benchmark::DoNotOptimize(ibl::specular_lookup(f.chain, dir[i & 1023], rough[i & 1023], d));
        ++i;
    }
    state.SetItemsProcessed(std::int64_t(state.iterations()));
    state.counters["rel_rmse_worst"] = worst;
    state.counters["taps"] = d.interpolation == ibl::level_interpolation::catmull_rom ? 4 : 2;
}
BENCHMARK(BM_specular_lookup)->DenseRange(0, 2)->Unit(benchmark::kNanosecond);

void BM_dfg_lookup(benchmark::State& state) {
    const ibl::dfg_lut_layout lay = state.range(0) == 0 ? ibl::dfg_lut_layout::uniform() : ibl::dfg_lut_layout::remapped();
    const ibl::dfg_lut lut = ibl::make_dfg_lut_exact<ibl::ggx_height_correlated>(128, lay, 2);
    static const ibl::dfg_error_grid g = ibl::dfg_error_grid::dense(129, 96, 0.05);
    static const std::vector<ibl::vec2<double>> exact = ibl::dfg_exact_grid<ibl::ggx_height_correlated>(g);
    const double err = ibl::dfg_lookup_error(lut, g, exact).max_abs;
    std::vector<ibl::vec2<float>> p(1024);
    for (std::uint32_t i = 0; i < 1024; ++i) p[i] = ibl::vec2<float>(ibl::hammersley<double>(i, 1024));
    std::size_t i = 0;
    for (auto _ : state) {
        const ibl::vec2<float>& q = p[i & 1023];
        benchmark::DoNotOptimize(ibl::dfg_lookup(lut, q.x, q.y));
        ++i;
    }
    state.SetItemsProcessed(std::int64_t(state.iterations()));
    state.counters["max_abs_err"] = err;
}
BENCHMARK(BM_dfg_lookup)->DenseRange(0, 1)->Unit(benchmark::kNanosecond);

} // namespace
