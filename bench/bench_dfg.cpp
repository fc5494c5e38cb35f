// bench_dfg: cost against error of every way to compute the split-sum DFG LUT (128^2, both
// models), and per texel. Every benchmark reports, next to its time, the largest and RMS absolute
// error of (A, B) against a converged double-precision reference table (computed once, static):
//   max_abs_err, rms_err, first_col_err (the n.v = 0.5/128 column, the hardest).
// Sweeps: quadrature nodes (level n = {n/2, n/2, n, n/2} nodes), Monte Carlo samples 16..4096
// (GGX-NDF sampling as in the literature, and visible normals), the literature's plain scalar loop
// next to the batch kernel on the same work, and Karis' analytic fit.
// Run: ./build/release/bench/bench_dfg --benchmark_min_time=0.1
#include <benchmark/benchmark.h>

#include <ibl/ibl.hpp>

#include <cmath>
#include <cstdint>
#include <vector>

namespace {

constexpr std::uint32_t lut_size = 128;

/// Reference (A, B) per texel, row-major like dfg_lut: the double-evaluated quadrature with
/// {64, 64, 160, 64} nodes (its distance to {96, 96, 256, 96} is 1.3e-10 on a 64^2 grid; an
/// independent brute-force 2D midpoint sum with the n.l > 0 indicator agrees to its own O(h^2) error).
template <class M> const std::vector<double>& reference() {
    static const std::vector<double> ref = [] {
        std::vector<double> out(std::size_t(2) * lut_size * lut_size);
        const ibl::dfg_quadrature_rule rule({64, 64, 160, 64});
        ibl::thread_executor{}(lut_size, [&](std::size_t b, std::size_t e) {
            for (std::size_t j = b; j < e; ++j)
                for (std::uint32_t i = 0; i < lut_size; ++i) {
                    const ibl::vec3<double> v = ibl::dfg_exact_abe<M>((i + 0.5) / lut_size, (j + 0.5) / lut_size, rule);
                    out[2 * (j * lut_size + i)] = v.x;
                    out[2 * (j * lut_size + i) + 1] = v.y;
                }
        });
        return out;
    }();
    return ref;
}

/// Error counters of a table given as a callable (i, j, c) -> value.
template <class M, class Get> void report_errors(benchmark::State& state, Get&& get) {
    const std::vector<double>& ref = reference<M>();
    double mx = 0.0, sq = 0.0, first = 0.0;
    for (std::uint32_t j = 0; j < lut_size; ++j)
        for (std::uint32_t i = 0; i < lut_size; ++i)
            for (std::uint32_t c = 0; c < 2; ++c) {
                const double e = std::fabs(double(get(i, j, c)) - ref[2 * (j * lut_size + i) + c]);
                mx = std::fmax(mx, e);
                sq += e * e;
                if (i == 0) first = std::fmax(first, e);
            }
    state.counters["max_abs_err"] = mx;
    state.counters["rms_err"] = std::sqrt(sq / (2.0 * lut_size * lut_size));
    state.counters["first_col_err"] = first;
}

template <class M> void report_lut(benchmark::State& state, const ibl::dfg_lut& lut) {
    report_errors<M>(state, [&](std::uint32_t i, std::uint32_t j, std::uint32_t c) { return lut.at(i, j, c); });
    state.SetItemsProcessed(std::int64_t(state.iterations()) * lut_size * lut_size);
}

// ---- exact (quadrature) table: node sweep ------------------------------------------------------

template <class M> void BM_exact_table(benchmark::State& state) {
    const auto nodes = ibl::dfg_quadrature_nodes::level(std::uint32_t(state.range(0)));
    reference<M>();
    ibl::dfg_lut lut;
    for (auto _ : state) {
        lut = ibl::make_dfg_lut_exact<M>(lut_size, 3, nodes);
        benchmark::DoNotOptimize(lut.data.data());
    }
    report_lut<M>(state, lut);
    state.counters["evals_per_texel"] = double(nodes.evaluations());
}
BENCHMARK(BM_exact_table<ibl::ggx_height_correlated>)->ArgName("level")->DenseRange(8, 32, 4)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_exact_table<ibl::ggx_schlick_ibl>)->ArgName("level")->DenseRange(8, 32, 4)->Unit(benchmark::kMillisecond)->UseRealTime();

template <class M> void BM_exact_table_1thread(benchmark::State& state) {
    reference<M>();
    ibl::dfg_lut lut;
    for (auto _ : state) {
        lut = ibl::make_dfg_lut_exact<M>(lut_size, 3, ibl::dfg_lut_default_nodes, ibl::serial_executor{});
        benchmark::DoNotOptimize(lut.data.data());
    }
    report_lut<M>(state, lut);
}
BENCHMARK(BM_exact_table_1thread<ibl::ggx_height_correlated>)->Unit(benchmark::kMillisecond)->UseRealTime();

// ---- Monte Carlo tables: sample sweep ------------------------------------------------------------

template <class M> void BM_mc_table(benchmark::State& state) {
    const auto n = std::uint32_t(state.range(0));
    reference<M>();
    ibl::dfg_lut lut;
    for (auto _ : state) {
        lut = ibl::make_dfg_lut_mc<M>(lut_size, n);
        benchmark::DoNotOptimize(lut.data.data());
    }
    report_lut<M>(state, lut);
}
BENCHMARK(BM_mc_table<ibl::ggx_schlick_ibl>)->ArgName("spp")->RangeMultiplier(4)->Range(16, 4096)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_mc_table<ibl::ggx_height_correlated>)->ArgName("spp")->RangeMultiplier(4)->Range(16, 4096)->Unit(benchmark::kMillisecond)->UseRealTime();

/// The batch kernel on one thread: the same work as the scalar loop below.
template <class M> void BM_mc_table_batch_1thread(benchmark::State& state) {
    const auto n = std::uint32_t(state.range(0));
    reference<M>();
    ibl::dfg_lut lut;
    for (auto _ : state) {
        lut = ibl::make_dfg_lut_mc<M>(lut_size, n, 2, ibl::serial_executor{});
        benchmark::DoNotOptimize(lut.data.data());
    }
    report_lut<M>(state, lut);
}
BENCHMARK(BM_mc_table_batch_1thread<ibl::ggx_schlick_ibl>)->ArgName("spp")->Arg(256)->Arg(1024)->Unit(benchmark::kMillisecond)->UseRealTime();

/// The literature's loop (LearnOpenGL IntegrateBRDF), texel by texel, one thread.
template <class M> void BM_mc_table_scalar_loop(benchmark::State& state) {
    const auto n = std::uint32_t(state.range(0));
    reference<M>();
    std::vector<float> t(std::size_t(2) * lut_size * lut_size);
    for (auto _ : state) {
        for (std::uint32_t j = 0; j < lut_size; ++j)
            for (std::uint32_t i = 0; i < lut_size; ++i) {
                const ibl::vec2<float> ab = ibl::dfg_mc_scalar_loop<M>((float(i) + 0.5f) / float(lut_size),
                                                                       (float(j) + 0.5f) / float(lut_size), n);
                t[2 * (j * lut_size + i)] = ab.x;
                t[2 * (j * lut_size + i) + 1] = ab.y;
            }
        benchmark::DoNotOptimize(t.data());
    }
    report_errors<M>(state, [&](std::uint32_t i, std::uint32_t j, std::uint32_t c) { return t[2 * (j * lut_size + i) + c]; });
    state.SetItemsProcessed(std::int64_t(state.iterations()) * lut_size * lut_size);
}
BENCHMARK(BM_mc_table_scalar_loop<ibl::ggx_schlick_ibl>)->ArgName("spp")->Arg(256)->Arg(1024)->Unit(benchmark::kMillisecond)->UseRealTime();

/// Visible-normal Monte Carlo (per texel, scalar), through the executor.
template <class M> void BM_mc_vndf_table(benchmark::State& state) {
    const auto n = std::uint32_t(state.range(0));
    reference<M>();
    std::vector<float> t(std::size_t(2) * lut_size * lut_size);
    for (auto _ : state) {
        ibl::thread_executor{}(lut_size, [&](std::size_t b, std::size_t e) {
            for (std::size_t j = b; j < e; ++j)
                for (std::uint32_t i = 0; i < lut_size; ++i) {
                    const ibl::vec2<float> ab = ibl::dfg_mc_vndf<M>((float(i) + 0.5f) / float(lut_size),
                                                                    (float(j) + 0.5f) / float(lut_size), n);
                    t[2 * (j * lut_size + i)] = ab.x;
                    t[2 * (j * lut_size + i) + 1] = ab.y;
                }
        });
        benchmark::DoNotOptimize(t.data());
    }
    report_errors<M>(state, [&](std::uint32_t i, std::uint32_t j, std::uint32_t c) { return t[2 * (j * lut_size + i) + c]; });
    state.SetItemsProcessed(std::int64_t(state.iterations()) * lut_size * lut_size);
}
BENCHMARK(BM_mc_vndf_table<ibl::ggx_height_correlated>)->ArgName("spp")->RangeMultiplier(4)->Range(16, 4096)->Unit(benchmark::kMillisecond)->UseRealTime();

// ---- per texel -------------------------------------------------------------------------------------

void BM_exact_texel(benchmark::State& state) {
    const auto nodes = ibl::dfg_quadrature_nodes::level(std::uint32_t(state.range(0)));
    const ibl::dfg_quadrature_rule rule(nodes);
    double mu = 0.3;
    for (auto _ : state) {
        benchmark::DoNotOptimize(ibl::dfg_exact_abe<ibl::ggx_height_correlated>(mu, 0.4, rule));
        mu = mu < 0.9 ? mu + 0.01 : 0.3;
    }
    state.counters["evals_per_texel"] = double(nodes.evaluations());
}
BENCHMARK(BM_exact_texel)->ArgName("level")->Arg(16)->Arg(24)->Arg(32);

void BM_mc_texel(benchmark::State& state) {
    const auto n = std::uint32_t(state.range(0));
    float mu = 0.3f;
    for (auto _ : state) {
        benchmark::DoNotOptimize(ibl::dfg_mc<ibl::ggx_height_correlated>(mu, 0.4f, n));
        mu = mu < 0.9f ? mu + 0.01f : 0.3f;
    }
}
BENCHMARK(BM_mc_texel)->ArgName("spp")->Arg(64)->Arg(1024);

// ---- analytic fit ------------------------------------------------------------------------------------

template <class M> void BM_karis_fit_table(benchmark::State& state) {
    reference<M>();
    std::vector<float> t(std::size_t(2) * lut_size * lut_size);
    for (auto _ : state) {
        for (std::uint32_t j = 0; j < lut_size; ++j)
            for (std::uint32_t i = 0; i < lut_size; ++i) {
                const ibl::vec2<float> ab = ibl::dfg_karis_mobile((float(i) + 0.5f) / float(lut_size),
                                                                  (float(j) + 0.5f) / float(lut_size));
                t[2 * (j * lut_size + i)] = ab.x;
                t[2 * (j * lut_size + i) + 1] = ab.y;
            }
        benchmark::DoNotOptimize(t.data());
    }
    report_errors<M>(state, [&](std::uint32_t i, std::uint32_t j, std::uint32_t c) { return t[2 * (j * lut_size + i) + c]; });
}
BENCHMARK(BM_karis_fit_table<ibl::ggx_schlick_ibl>)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_karis_fit_table<ibl::ggx_height_correlated>)->Unit(benchmark::kMillisecond);

} // namespace
