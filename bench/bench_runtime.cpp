// bench_runtime: cost of the runtime approximations of ibl/runtime/specular_models.hpp next to their error.
//   BM_runtime_specular/<variant>: one specular evaluation (metal F0 = (0.95, 0.64, 0.54)) at a
//     random (n, v, r) of a fixed set, on a 256^2 x 6-level chain of the default sky + sun
//     (ibl-bake's default bake, G1 weight for the variants that say so). Counters:
//       rel_rmse = relative RMSE of luminance against reference_radiance (MIS, 2^14 samples) over
//                  48 points (r in {0.3, 0.5, 0.8} x n.v in {0.25, 0.5, 1} x 16 random normals / views;
//                  computed once in the fixture, not timed); research/runtime_error.cpp does the
//                  full study on the HDRIs.
//       taps     = chain textureLod reads per evaluation (the LUT tap comes on top where used).
//     variants: 0 split sum (n.l chain), 1 split sum (G1 chain), 2 Frostbite dominant direction
//     (n.l chain), 3 lobe LUT (G1 chain), 4 FIS 8 taps, 5 FIS 16 taps, 6 FIS 64 taps (normalised,
//     G1 chain), 7 fitted lobe LUT (one tap, L1 fit; bake/lobe_fit.hpp), 8 fitted 2 taps,
//     9 fitted 3 taps (G1 chain; 32^2 tables).
//   BM_lobe_fit_table/<taps>: building the fitted table (make_lobe_taps_lut) of 1 tap (default fit
//     options, what make_lobe_lut_fitted runs), 2 or 3 taps (make_lobe_taps_lut, 32 nodes, 150 iterations) at 32^2, 2 threads;
//     counter mean_l1 = the fits' mean L1 distance to the lobe.
// Run: ./build/release/bench/bench_runtime --benchmark_min_time=0.1
#include <benchmark/benchmark.h>

#include <ibl/core/color.hpp>
#include <ibl/env/analytic.hpp>
#include <ibl/env/convert.hpp>
#include <ibl/reference/env_importance.hpp>
#include <ibl/bake/lobe_fit.hpp>
#include <ibl/bake/lobe_moments.hpp>
#include "../research/lobe_moment_baseline.hpp" // make_lobe_lut: the moment-matched baseline
#include <ibl/reference/lookup_error.hpp>
#include <ibl/bake/prefilter.hpp>
#include <ibl/reference/radiance.hpp>
#include <ibl/runtime/specular_models.hpp>

#include <cmath>
#include <cstdint>
#include <vector>

namespace {

using d3 = ibl::vec3<double>;
using f3 = ibl::vec3<float>;
using model = ibl::ggx_height_correlated;

struct point {
    f3 n, v;
    float n_dot_v, roughness;
    double ref;
};

struct fixture {
    ibl::cubemap<float> chain_nl{1}, chain_g1{1};
    ibl::dfg_lut dfg;
    ibl::lobe_lut lobe, lobe_fitted;
    ibl::lobe_taps_lut taps2, taps3;
    std::vector<point> points;
};

const f3 k_f0(0.95f, 0.64f, 0.54f);

double hash_unit(std::uint32_t a, std::uint32_t b) {
    std::uint32_t x = a * 0x9e3779b9u + b * 0x85ebca6bu + 17u;
    x ^= x >> 16;
    x *= 0x7feb352du;
    x ^= x >> 15;
    x *= 0x846ca68bu;
    x ^= x >> 16;
    return double(x >> 8) * 0x1p-24;
}

ibl::cubemap<float> chain(const ibl::cubemap<float>& src, ibl::ld_weight w) {
    ibl::prefilter_options o;
    o.levels = 6;
    o.trilinear = true;
    o.samples_per_level = {0, 512, 1024, 2048, 4096, 8192};
    o.weight = w;
    return ibl::prefilter(src, o, ibl::thread_executor{});
}

ibl::lobe_fit_options multi_tap_options(int taps) {
    ibl::lobe_fit_options o;
    o.taps = taps;
    o.nodes = 32;
    o.iterations = 150;
    return o;
}

const fixture& fix() {
    static const fixture f = [] {
        fixture x;
        const ibl::sky_environment<double> sky = ibl::make_default_sky<double>();
        const ibl::cubemap<float> src = ibl::bake_cubemap<float>(sky, 256, 4, ibl::thread_executor{});
        x.chain_nl = chain(src, ibl::ld_weight::n_dot_l);
        x.chain_g1 = chain(src, ibl::ld_weight::g1);
        x.dfg = ibl::make_dfg_lut_exact<model>(128, ibl::dfg_lut_layout::remapped(), 2);
        x.lobe = ibl::make_lobe_lut<model>(64, ibl::dfg_lut_layout::remapped(), ibl::ld_weight::g1);
        x.lobe_fitted = ibl::make_lobe_lut_fitted<model>(32, ibl::dfg_lut_layout::remapped(), ibl::ld_weight::g1);
        x.taps2 = ibl::make_lobe_taps_lut<model>(32, ibl::dfg_lut_layout::remapped(), ibl::ld_weight::g1, multi_tap_options(2));
        x.taps3 = ibl::make_lobe_taps_lut<model>(32, ibl::dfg_lut_layout::remapped(), ibl::ld_weight::g1, multi_tap_options(3));
        const ibl::cube_env_distribution dist = ibl::make_cube_env_distribution<double>(sky, 64, 4);
        std::uint32_t k = 0;
        for (double r : {0.3, 0.5, 0.8})
            for (double mu : {0.25, 0.5, 1.0})
                for (int i = 0; i < 16; ++i, ++k) {
                    const double z = 1.0 - 2.0 * hash_unit(k, 1), ph = 2.0 * ibl::pi_v<double> * hash_unit(k, 2);
                    const double s = std::sqrt(std::max(0.0, 1.0 - z * z));
                    const d3 n(s * std::cos(ph), z, s * std::sin(ph));
                    const ibl::frame<double> fr = ibl::make_frame(n);
                    const double az = 2.0 * ibl::pi_v<double> * hash_unit(k, 3), st = std::sqrt((1.0 - mu) * (1.0 + mu));
                    const d3 v = fr.to_world(d3(st * std::cos(az), st * std::sin(az), mu));
                    ibl::reference_material m;
                    m.diffuse_albedo = d3(0.0);
                    m.f0 = d3(k_f0);
                    m.roughness = r;
                    ibl::radiance_reference_options opt;
                    opt.samples = 1u << 14;
                    const double ref = ibl::luminance(ibl::reference_radiance<model>(sky, dist, n, v, m, opt).specular);
                    x.points.push_back({f3(n), f3(v), float(mu), float(r), ref});
                }
        return x;
    }();
    return f;
}

f3 evaluate(int variant, const fixture& f, const point& p) {
    const f3 abk = ibl::dfg_lookup(f.dfg, p.n_dot_v, p.roughness);
    const ibl::vec2<float> ab(abk.x, abk.y);
    const f3 r_dir = 2.0f * glm::dot(p.n, p.v) * p.n - p.v;
    const f3 albedo = ibl::split_sum_albedo(k_f0, f3(1.0f), ab);
    switch (variant) {
    case 0: return ibl::specular_lookup(f.chain_nl, r_dir, p.roughness, ibl::specular_lookup_desc::accurate()) * albedo;
    case 1: return ibl::specular_lookup(f.chain_g1, r_dir, p.roughness, ibl::specular_lookup_desc::accurate()) * albedo;
    case 2:
        return ibl::specular_lookup(f.chain_nl,
                                    ibl::lerp_direction(p.n, r_dir, ibl::dominant_lerp_frostbite(p.roughness)),
                                    p.roughness, ibl::specular_lookup_desc::accurate()) *
               albedo;
    case 3:
        return ibl::specular_lobe(f.chain_g1, ibl::specular_lookup_desc::accurate(), f.lobe, p.n, p.v,
                                  p.roughness, k_f0, f3(1.0f));
    case 7:
        return ibl::specular_lobe(f.chain_g1, ibl::specular_lookup_desc::accurate(), f.lobe_fitted, p.n, p.v,
                                  p.roughness, k_f0, f3(1.0f));
    case 8:
    case 9:
        return ibl::specular_lobe_taps(f.chain_g1, ibl::specular_lookup_desc::accurate(), variant == 8 ? f.taps2 : f.taps3, p.n, p.v, p.roughness, k_f0, f3(1.0f));
    default: {
        ibl::runtime_fis_desc d;
        d.taps = variant == 4 ? 8 : (variant == 5 ? 16 : 64);
        return ibl::specular_fis(f.chain_g1, d, p.n, p.v, p.roughness, k_f0, f3(1.0f), ab);
    }
    }
}

void BM_runtime_specular(benchmark::State& state) {
    const int variant = int(state.range(0));
    const fixture& f = fix();
    double sq = 0.0;
    for (const point& p : f.points) {
        const double y = ibl::luminance(d3(evaluate(variant, f, p)));
        sq += p.ref > 0.0 ? (y / p.ref - 1.0) * (y / p.ref - 1.0) : 0.0;
    }
    std::size_t i = 0;
    for (auto _ : state) {
        benchmark::DoNotOptimize(evaluate(variant, f, f.points[i]));
        i = i + 1 < f.points.size() ? i + 1 : 0;
    }
    state.SetItemsProcessed(state.iterations());
    state.counters["rel_rmse"] = std::sqrt(sq / double(f.points.size()));
    const double taps[] = {2, 2, 2, 2, 8, 16, 64, 2, 4, 6};
    state.counters["taps"] = taps[variant];
}
BENCHMARK(BM_runtime_specular)->DenseRange(0, 9);

void BM_lobe_fit_table(benchmark::State& state) {
    const int taps = int(state.range(0));
    const ibl::lobe_fit_options o = taps == 1 ? ibl::lobe_fit_options{} : multi_tap_options(taps);
    double l1 = 0.0;
    for (auto _ : state) {
        const ibl::lobe_taps_lut l = ibl::make_lobe_taps_lut<model>(32, ibl::dfg_lut_layout::remapped(), ibl::ld_weight::g1, o,
                                                                    ibl::thread_executor{2});
        benchmark::DoNotOptimize(l.data.data());
        l1 = l.mean_l1;
    }
    state.counters["mean_l1"] = l1;
}
BENCHMARK(BM_lobe_fit_table)->DenseRange(1, 3)->Unit(benchmark::kMillisecond)->Iterations(1);

} // namespace
