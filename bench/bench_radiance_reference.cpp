// reference/radiance.hpp: cost against error of the outgoing-radiance reference on the
// stiff case (the default sky's 1-degree sun reflected by a dielectric, n = +Y, R at the sun),
// for MIS and for BRDF sampling alone, swept over the sample count. Counters: rel_err = |estimate
// / converged - 1| (converged: MIS at 2^22 samples, computed once), rel_se = the estimator's own
// relative standard error. Also the environment distribution's build and sampling throughput.
#include <benchmark/benchmark.h>

#include <ibl/env/analytic.hpp>
#include <ibl/reference/env_importance.hpp>
#include <ibl/reference/radiance.hpp>

#include <cmath>
#include <cstdint>

namespace {

using d3 = ibl::vec3<double>;

struct sun_case {
    ibl::sky_environment<double> sky = ibl::make_default_sky<double>();
    ibl::cube_env_distribution dist = ibl::make_cube_env_distribution<double>(sky, 128, 4);
    d3 n{0.0, 1.0, 0.0};
    d3 v{-sky.sun_dir.x, sky.sun_dir.y, -sky.sun_dir.z}; // reflect(-v, n) = the sun centre
    ibl::reference_material m = ibl::make_reference_material(d3(0.8), 0.0, 0.3);
    double converged = 0.0;

    sun_case() {
        ibl::radiance_reference_options opt;
        opt.samples = 1u << 22;
        converged = ibl::reference_radiance(sky, dist, n, v, m, opt, ibl::thread_executor{}).value.x;
    }
};

const sun_case& the_case() {
    static const sun_case c;
    return c;
}

void run(benchmark::State& state, ibl::radiance_strategy strategy) {
    const sun_case& c = the_case();
    ibl::radiance_reference_options opt;
    opt.samples = std::uint32_t(state.range(0));
    opt.strategy = strategy;
    ibl::radiance_estimate e;
    for (auto _ : state) {
        e = ibl::reference_radiance(c.sky, c.dist, c.n, c.v, c.m, opt);
        benchmark::DoNotOptimize(e);
    }
    state.SetItemsProcessed(std::int64_t(state.iterations()) * std::int64_t(e.samples));
    state.counters["rel_err"] = std::fabs(e.value.x / c.converged - 1.0);
    state.counters["rel_se"] = e.std_error.x / e.value.x;
}

void BM_radiance_mis(benchmark::State& state) { run(state, ibl::radiance_strategy::mis); }
void BM_radiance_brdf(benchmark::State& state) { run(state, ibl::radiance_strategy::brdf); }
BENCHMARK(BM_radiance_mis)->ArgName("spp")->RangeMultiplier(4)->Range(1 << 10, 1 << 18)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_radiance_brdf)->ArgName("spp")->RangeMultiplier(4)->Range(1 << 10, 1 << 18)->Unit(benchmark::kMillisecond);

void BM_env_distribution_build(benchmark::State& state) {
    const ibl::cubemap<float> cube = ibl::bake_cubemap<float>(the_case().sky, int(state.range(0)), 1);
    for (auto _ : state) {
        ibl::cube_env_distribution d(cube);
        benchmark::DoNotOptimize(d);
    }
    state.SetItemsProcessed(std::int64_t(state.iterations()) * 6 * state.range(0) * state.range(0));
}
BENCHMARK(BM_env_distribution_build)->ArgName("face")->Arg(64)->Arg(256)->Unit(benchmark::kMillisecond);

void BM_env_distribution_sample(benchmark::State& state) {
    const ibl::cube_env_distribution& d = the_case().dist;
    std::uint32_t i = 0;
    double acc = 0.0;
    for (auto _ : state) {
        const ibl::env_sample s = d.sample({ibl::radical_inverse<double>(i), (i + 0.5) * 0x1p-20});
        acc += s.pdf;
        i = (i + 1) & 0xFFFFFu;
    }
    benchmark::DoNotOptimize(acc);
    state.SetItemsProcessed(std::int64_t(state.iterations()));
}
BENCHMARK(BM_env_distribution_sample);

} // namespace
