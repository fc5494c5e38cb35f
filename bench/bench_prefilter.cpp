// bake/prefilter and irradiance: the cost of the prefiltered mip chain (256^2 source -> 5
// levels, linear roughness policy) against its error, sweeping samples per texel for plain GGX
// importance sampling (IS), filtered importance sampling (FIS) and the fast filter, on
//   env 0: the default sky without its sun (smooth), baked to 256^2 (k = 2);
//   env 1: the default sky with its 1-degree sun (3e4), baked to 256^2 with k = 4 sub-samples.
// Counters per level l = 1..4 (level 0 is the source copy): rel_l (RMS of per-element relative
// error), nrmse_l (RMSE / RMS of the reference), ratio_l (largest element / reference). The
// reference is reference_ld_sky on the analytic sky (2048 sky samples + 16 x 64 sun-cap nodes,
// converged to ~3e-3 relative near the horizon step, ~1e-4 elsewhere), computed once per process.
// Timing uses thread_executor{2} (the 2-core target machine).
#include <benchmark/benchmark.h>

#include <ibl/env/analytic.hpp>
#include <ibl/env/convert.hpp>
#include <ibl/bake/irradiance.hpp>
#include <ibl/reference/metrics.hpp>
#include <ibl/bake/prefilter.hpp>
#include <ibl/bake/prefilter_update.hpp>
#include <ibl/reference/ld_irradiance.hpp>
#if defined(IBL_BENCH_XSIMD)
#include "convolve_xsimd.hpp"
#endif

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

namespace {

constexpr int base = 256;
constexpr int levels = 5;

ibl::sky_environment<float> sky_f(int env) {
    auto s = ibl::make_default_sky<float>();
    if (env == 0) s.sun_radiance = ibl::vec3<float>(0.f);
    return s;
}

const ibl::cubemap<float>& source(int env, int size = base) {
    static std::array<ibl::cubemap<float>*, 4> cache{};
    const std::size_t k = std::size_t(env) + (size == base ? 0 : 2);
    if (!cache[k])
        cache[k] = new ibl::cubemap<float>(ibl::bake_cubemap<float>(sky_f(env), size, env == 0 ? 2 : 4, ibl::thread_executor{2}));
    return *cache[k];
}

/// Reference LD per level (index l = 1..levels-1), texels in cubemap order.
const std::vector<std::vector<ibl::vec3<double>>>& reference(int env, int size = base) {
    static std::array<std::vector<std::vector<ibl::vec3<double>>>*, 4> cache{};
    const std::size_t k = std::size_t(env) + (size == base ? 0 : 2);
    if (!cache[k]) {
        auto s = ibl::make_default_sky<double>();
        if (env == 0) s.sun_radiance = ibl::vec3<double>(0.0);
        auto* ref = new std::vector<std::vector<ibl::vec3<double>>>(levels);
        const ibl::roughness_mip_policy policy{};
        for (int l = 1; l < levels; ++l) {
            const double r = policy.roughness(double(l), levels);
            (*ref)[std::size_t(l)] = ibl::reference_faces(
                size >> l, [&](const ibl::vec3<double>& d) { return ibl::reference_ld_sky(s, d, r, 2048, 16); },
                ibl::thread_executor{2});
        }
        cache[k] = ref;
    }
    return *cache[k];
}

void report(benchmark::State& state, const ibl::cubemap<float>& out, int env, int size = base) {
    const auto& ref = reference(env, size);
    for (int l = 1; l < levels; ++l) {
        const ibl::error_metrics m = ibl::compare_level(out, l, std::span<const ibl::vec3<double>>(ref[std::size_t(l)]));
        state.counters["rel_" + std::to_string(l)] = m.rel_rmse;
        state.counters["nrmse_" + std::to_string(l)] = m.nrmse;
        state.counters["ratio_" + std::to_string(l)] = m.max_ratio;
    }
}

void run_chain(benchmark::State& state, const ibl::prefilter_options& o, int env, int size = base) {
    const ibl::cubemap<float>& src = source(env, size);
    (void)reference(env, size); // outside the timed loop
    ibl::cubemap<float> out(1);
    for (auto _ : state) {
        out = ibl::prefilter(src, o, ibl::thread_executor{2});
        benchmark::DoNotOptimize(out.texel(0, 0, 0, 1));
    }
    std::size_t texels = 0;
    for (int l = 1; l < out.levels(); ++l) texels += std::size_t(6) * std::size_t(out.size(l)) * std::size_t(out.size(l));
    state.SetItemsProcessed(std::int64_t(state.iterations()) * std::int64_t(texels));
    report(state, out, env, size);
}

/// A sweep point: `levels` levels, range(1) samples at every level >= 1, nearest-level reads.
void run_sweep(benchmark::State& state, ibl::prefilter_method method) {
    ibl::prefilter_options o;
    o.levels = levels;
    o.method = method;
    o.samples = std::uint32_t(state.range(1));
    o.trilinear = false;
    run_chain(state, o, int(state.range(0)));
}

/// args: env, samples per texel (every level >= 1). The FIS sweeps read the nearest level (one
/// tap per sample, as docs/results was measured); the default options read trilinearly.
void BM_prefilter_is(benchmark::State& state) {
    ibl::prefilter_options o;
    o.levels = levels;
    o.method = ibl::prefilter_method::importance;
    o.samples = std::uint32_t(state.range(1));
    run_chain(state, o, int(state.range(0)));
}

void BM_prefilter_fis(benchmark::State& state) { run_sweep(state, ibl::prefilter_method::filtered_importance); }

/// The fast filter (bake/prefilter_fast.hpp) at the same samples per texel and the same
/// nearest-level reads as the FIS sweep: the error-vs-time frontier of the two side by side.
void BM_prefilter_fast(benchmark::State& state) { run_sweep(state, ibl::prefilter_method::fast); }

/// The fast filter's tap sets on every level (sh_rough off) with and without its peak split
/// (bake/prefilter_peaks.hpp) and its coarse tail (prefilter_options::coarse_tail), nearest reads, range(1) samples at level 1 doubled per level
/// (the default schedule's shape), at face size range(3) (256 or 128): the real-time end of the
/// frontier. args: env, spp, peaks, size, tail.
void BM_prefilter_fast_split(benchmark::State& state) {
    ibl::prefilter_options o;
    o.levels = levels;
    o.method = ibl::prefilter_method::fast;
    for (int l = 0; l < levels; ++l) o.samples_per_level.push_back(std::uint32_t(state.range(1)) << (l > 0 ? l - 1 : 0));
    o.peaks.enabled = state.range(2) != 0;
    o.coarse_tail = state.range(4) != 0;
    o.sh_rough.enabled = false; // the tap sets on every level (BM_prefilter_fast_sh: the rough levels by SH)
    run_chain(state, o, int(state.range(0)), int(state.range(3)));
}

/// The fast filter's default (equal-cost schedule from range(1) samples, peak split, coarse tail)
/// with and without its rough levels by spherical harmonics (range(2); bake/prefilter_sh.hpp), at
/// face size range(3). args: env, spp, sh, size.
void BM_prefilter_fast_sh(benchmark::State& state) {
    ibl::prefilter_options o;
    o.levels = levels;
    o.method = ibl::prefilter_method::fast;
    for (int l = 0; l < levels; ++l) o.samples_per_level.push_back(ibl::equal_cost_prefilter_samples(std::uint32_t(state.range(1)), l));
    o.sh_rough.enabled = state.range(2) != 0;
    run_chain(state, o, int(state.range(0)), int(state.range(3)));
}

/// The default schedules at the sweeps' `levels` levels (the references' roughness per level):
/// FIS (bias 0.5, trilinear reads, 512 samples at level 1 doubled per level) and the fast filter
/// (its default: 64 x 4^(l-1) nearest-level samples, the coarse tail and the peak split); the ratio
/// of the two is measured in one run.
void run_default(benchmark::State& state, ibl::prefilter_method method) {
    ibl::prefilter_options o;
    o.levels = levels;
    o.method = method;
    run_chain(state, o, int(state.range(0)));
}
void BM_prefilter_fast_default(benchmark::State& state) { run_default(state, ibl::prefilter_method::fast); }
void BM_prefilter_default(benchmark::State& state) { run_default(state, ibl::prefilter_method::filtered_importance); }

/// FIS at 128 nearest-level samples, sweeping the lod bias (in tenths).
void BM_prefilter_fis_bias(benchmark::State& state) {
    ibl::prefilter_options o;
    o.samples = 128;
    o.trilinear = false;
    o.lod_bias = double(state.range(1)) / 10.0;
    run_chain(state, o, int(state.range(0)));
}

/// Irradiance cubemap 32^2 from the 256^2 source, against reference_irradiance_sky.
void BM_irradiance(benchmark::State& state) {
    const int env = int(state.range(0));
    const ibl::cubemap<float>& src = source(env);
    ibl::irradiance_options o;
    o.method = state.range(1) == 0 ? ibl::irradiance_method::riemann : ibl::irradiance_method::cosine_importance;
    o.filtered = state.range(1) != 0;
    auto s = ibl::make_default_sky<double>();
    if (env == 0) s.sun_radiance = ibl::vec3<double>(0.0);
    const auto ref = ibl::reference_faces(o.size, [&](const ibl::vec3<double>& d) { return ibl::reference_irradiance_sky(s, d, 4096, 16); });
    ibl::cubemap<float> out(1);
    for (auto _ : state) {
        out = ibl::irradiance_cubemap(src, o, ibl::thread_executor{2});
        benchmark::DoNotOptimize(out.texel(0, 0, 0));
    }
    const ibl::error_metrics m = ibl::compare_level(out, 0, std::span<const ibl::vec3<double>>(ref));
    state.counters["rel"] = m.rel_rmse;
    state.counters["nrmse"] = m.nrmse;
    state.counters["ratio"] = m.max_ratio;
}

/// The largest difference of a prefilter_update's finished chain from the one-shot prefilter of
/// the same source and options (0: bit for bit).
double max_abs_vs_oneshot(const ibl::prefilter_update<>& up, const ibl::cubemap<float>& src, const ibl::prefilter_options& o) {
    const ibl::specular_chain ref = ibl::prefilter(src, o, ibl::thread_executor{2});
    double diff = 0.0;
    for (int l = 0; l < ref.levels(); ++l)
        for (int f = 0; f < 6; ++f)
            for (int y = 0; y < ref.size(l); ++y)
                for (int x = 0; x < ref.size(l); ++x)
                    for (int c = 0; c < 3; ++c)
                        diff = std::max(diff, double(std::abs(up.result()->texel(f, x, y, l)[c] - ref.texel(f, x, y, l)[c])));
    return diff;
}

/// A dynamic probe's slice: one prefilter_update::step of a budget of 2^k taps (k = range(1)) on
/// the 256^2 source with the default options of filtered importance sampling (range(2) = 0) or of
/// the fast filter (1), one thread, the pass restarted when it finishes. Counters: taps per call,
/// taps per second, the dearest call's taps over the budget (> 1 only where one work unit, a tap of
/// a chunk of 16 lanes or a row's last tap with the row's finish, costs more than the budget), the slowest call's
/// time and the 99th percentile of the calls' times over the budget's time at the run's mean rate, the mean time of
/// set_source (work outside the budget: its copy of the source, and the fast filter's peak split), and the largest difference of the finished
/// chain from the one-shot prefilter (0: bit for bit).
void BM_prefilter_update_step(benchmark::State& state) {
    const ibl::cubemap<float>& src = source(int(state.range(0)));
    const std::uint64_t budget = std::uint64_t(1) << state.range(1);
    ibl::prefilter_options o;
    if (state.range(2) == 1) o.method = ibl::prefilter_method::fast;
    ibl::prefilter_update<> up(src, o);
    std::uint64_t taps = 0, calls = 0, most = 0;
    double slowest = 0.0, total_s = 0.0;
    std::vector<double> times;
    double source_s = 0.0;
    std::uint64_t sources = 0;
    for (auto _ : state) {
        if (up.done()) { // a new pass: set_source's own time (its copy of the source and the peak split)
            const auto s0 = std::chrono::steady_clock::now();
            up.set_source(src);
            source_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - s0).count();
            ++sources;
        }
        const auto t0 = std::chrono::steady_clock::now();
        const std::uint64_t t = up.step(budget);
        const double dt = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        slowest = std::max(slowest, dt);
        times.push_back(dt);
        total_s += dt;
        taps += t;
        most = std::max(most, t);
        ++calls;
    }
    up.finish();
    const double diff = max_abs_vs_oneshot(up, src, o);
    state.counters["taps_per_call"] = double(taps) / double(std::max<std::uint64_t>(calls, 1));
    state.counters["taps_per_s"] = benchmark::Counter(double(taps), benchmark::Counter::kIsRate);
    state.counters["max_abs_vs_oneshot"] = diff;
    state.counters["pass_taps"] = double(up.total_taps());
    state.counters["max_call_over_budget"] = double(most) / double(budget);
    // the budget's time at the mean rate: budget * total_s / taps
    const double budget_s = taps > 0 ? double(budget) * total_s / double(taps) : 0.0;
    state.counters["slowest_call_over_budget_time"] = budget_s > 0.0 ? slowest / budget_s : 0.0;
    if (sources > 0) state.counters["set_source_ms"] = 1e3 * source_s / double(sources);
    if (!times.empty() && budget_s > 0.0) { // the 99th percentile of the calls' times over the budget's time
        const auto p99 = times.begin() + std::ptrdiff_t((times.size() - 1) * 99 / 100);
        std::nth_element(times.begin(), p99, times.end());
        state.counters["p99_call_over_budget_time"] = *p99 / budget_s;
    }
}

/// A dynamic probe's slice by time: one prefilter_update::step_for of range(1) microseconds (the
/// time form of BM_prefilter_update_step: about 2^14, 2^16, 2^18 and 2^20 taps on one thread) on
/// the 256^2 source, FIS (range(2) = 0) or the fast filter (1), one thread, the pass restarted when
/// it finishes (set_source outside the timed call). Counters: the 99th percentile, the slowest and
/// the mean of the calls' times over the budget, taps per call, and the largest difference of the
/// finished chain from the one-shot prefilter (0: bit for bit).
void BM_prefilter_update_time(benchmark::State& state) {
    const ibl::cubemap<float>& src = source(int(state.range(0)));
    const std::chrono::microseconds budget(state.range(1));
    ibl::prefilter_options o;
    if (state.range(2) == 1) o.method = ibl::prefilter_method::fast;
    ibl::prefilter_update<> up(src, o);
    std::uint64_t taps = 0, calls = 0;
    std::vector<double> times;
    for (auto _ : state) {
        if (up.done()) {
            state.PauseTiming();
            up.set_source(src);
            state.ResumeTiming();
        }
        const auto t0 = std::chrono::steady_clock::now();
        taps += up.step_for(budget);
        times.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
        ++calls;
    }
    up.finish();
    const double diff = max_abs_vs_oneshot(up, src, o);
    const double b = std::chrono::duration<double>(budget).count();
    double mean = 0.0;
    for (const double t : times) mean += t / double(times.size());
    state.counters["taps_per_call"] = double(taps) / double(std::max<std::uint64_t>(calls, 1));
    state.counters["max_abs_vs_oneshot"] = diff;
    state.counters["mean_call_over_budget"] = mean / b;
    state.counters["slowest_call_over_budget"] = *std::max_element(times.begin(), times.end()) / b;
    const auto p99 = times.begin() + std::ptrdiff_t((times.size() - 1) * 99 / 100);
    std::nth_element(times.begin(), p99, times.end());
    state.counters["p99_call_over_budget"] = *p99 / b;
    state.counters["ns_per_tap"] = up.seconds_per_tap() * 1e9;
}

/// The batch kernel against its width-1 form: one level of the default chain (level 2 of the
/// 256^2 sky with a sun: 64^2 faces, 1024 samples, trilinear reads), every face row computed by
/// convolve_lanes<W> in chunks of W lanes (W = range(0): 16 is the library's convolve_width, 1 the
/// scalar form). Counters: taps per second, and the largest difference from the width-1 result
/// (the lanes are independent: the same arithmetic per texel).
template <std::size_t W> void convolve_level(const ibl::detail::packed_cube& src, const ibl::detail::tap_table& taps, int n,
                                             std::vector<ibl::vec3<float>>& out) {
    for (int row = 0; row < 6 * n; ++row) {
        const int face = row / n, y = row % n;
        for (int x = 0; x < n; x += int(W)) {
            ibl::detail::lane_frames<W> fr;
            ibl::detail::load_row_frames<W>(fr, face, x, y, n);
            ibl::detail::convolve_lanes<W>(src, taps, fr, out.data() + std::size_t(row) * std::size_t(n) + std::size_t(x));
        }
    }
}

/// The case of BM_convolve_width and BM_convolve_xsimd: level 2 of the default chain on the sky
/// with a sun, packed once per process.
struct convolve_case {
    int n = 0;
    std::size_t samples = 0;
    ibl::detail::packed_cube src;
    ibl::detail::tap_table taps;
};

const convolve_case& convolve_setup() {
    static const convolve_case* c = nullptr;
    if (!c) {
        const ibl::cubemap<float>& env = source(1);
        const int level = 2;
        auto* k = new convolve_case;
        k->n = base >> level; // n = 64: a multiple of every lane width measured
        const ibl::sphere_sample_table<float> table = ibl::make_ld_table_for<float>(
            env, ibl::roughness_mip_policy{}.roughness(double(level), 6),
            ibl::default_prefilter_samples(ibl::prefilter_method::filtered_importance, level),
            ibl::prefilter_method::filtered_importance, 0.5);
        k->samples = table.size();
        k->src = ibl::detail::pack_cube(env);
        k->taps = ibl::detail::make_taps(table, int(k->src.levels.size()));
        c = k;
    }
    return *c;
}

/// The machine's own spread of call times, the control of BM_prefilter_update_step: every call
/// does the same amount of work, 2^range(0) taps of the batch kernel (chunks of 16 lanes of level 2
/// of the sky with a sun, 32 trilinear samples: about 1024 taps a chunk, cycling through the
/// level's texels), so the calls differ only by what the machine does around them (interrupts,
/// other processes, a virtual machine's host, caches). A tap here is a tap of the update: one
/// bilinear read, two to a trilinear sample, about 2.4 ns on one thread as the update's, so a call
/// lasts as long as one of the update's at the same budget. Counters: the 99th percentile and the
/// slowest call over the mean call, and the mean call's time a tap.
void BM_fixed_call_spread(benchmark::State& state) {
    static const convolve_case* c = nullptr;
    if (!c) {
        const ibl::cubemap<float>& env = source(1);
        auto* k = new convolve_case;
        k->n = base >> 2;
        const ibl::sphere_sample_table<float> table = ibl::make_ld_table_for<float>(
            env, ibl::roughness_mip_policy{}.roughness(2.0, 6), 32, ibl::prefilter_method::filtered_importance, 0.5);
        k->samples = table.size();
        k->src = ibl::detail::pack_cube(env);
        k->taps = ibl::detail::make_taps(table, int(k->src.levels.size()));
        c = k;
    }
    const int n = c->n, chunks_per_row = n / 16;
    const std::uint64_t chunk_taps = 16 * c->taps.w.size(); // a tap: one bilinear read (a trilinear sample has two)
    const std::uint64_t chunks = std::max<std::uint64_t>(1, (std::uint64_t(1) << state.range(0)) / chunk_taps);
    std::vector<ibl::vec3<float>> out(16);
    std::vector<double> times;
    std::uint64_t next = 0;
    for (auto _ : state) {
        const auto t0 = std::chrono::steady_clock::now();
        for (std::uint64_t i = 0; i < chunks; ++i, ++next) {
            const int chunk = int(next % std::uint64_t(6 * n * chunks_per_row)), row = chunk / chunks_per_row;
            ibl::detail::lane_frames<16> fr;
            ibl::detail::load_row_frames<16>(fr, row / n, (chunk % chunks_per_row) * 16, row % n, n);
            ibl::detail::convolve_lanes<16>(c->src, c->taps, fr, out.data());
            benchmark::DoNotOptimize(out.data());
        }
        times.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    }
    double mean = 0.0;
    for (const double t : times) mean += t / double(times.size());
    const auto p99 = times.begin() + std::ptrdiff_t((times.size() - 1) * 99 / 100);
    std::nth_element(times.begin(), p99, times.end());
    state.counters["taps_per_call"] = double(chunks * chunk_taps);
    state.counters["p99_call_over_mean"] = *p99 / mean;
    state.counters["slowest_call_over_mean"] = *std::max_element(times.begin(), times.end()) / mean;
    state.counters["ns_per_tap"] = 1e9 * mean / double(chunks * chunk_taps);
}

void set_tap_rate(benchmark::State& state, const convolve_case& c) {
    state.counters["taps_per_s"] = benchmark::Counter(double(state.iterations()) * 6.0 * c.n * c.n * double(c.samples) * 2.0,
                                                      benchmark::Counter::kIsRate);
}

void BM_convolve_width(benchmark::State& state) {
    const convolve_case& c = convolve_setup();
    const int n = c.n;
    std::vector<ibl::vec3<float>> out(std::size_t(6 * n * n)), scalar(out.size());
    convolve_level<1>(c.src, c.taps, n, scalar);
    for (auto _ : state) {
        if (state.range(0) == 16) convolve_level<16>(c.src, c.taps, n, out);
        else if (state.range(0) == 8) convolve_level<8>(c.src, c.taps, n, out);
        else if (state.range(0) == 4) convolve_level<4>(c.src, c.taps, n, out);
        else convolve_level<1>(c.src, c.taps, n, out);
        benchmark::DoNotOptimize(out.data());
    }
    double diff = 0.0;
    for (std::size_t i = 0; i < out.size(); ++i)
        for (int c3 = 0; c3 < 3; ++c3) diff = std::max(diff, double(std::abs(out[i][c3] - scalar[i][c3])));
    set_tap_rate(state, c);
    state.counters["max_abs_vs_width1"] = diff;
}

#if defined(IBL_BENCH_XSIMD)
/// The same level with the kernel written in explicit xsimd batches (bench/convolve_xsimd.hpp, a
/// bench-only alternative): range(0) the texel reads (0: gathers, 1: per-lane float4 rows),
/// range(1) the instruction set (0: xsimd's default for the build, 1: AVX2, 8 lanes). Counters:
/// taps per second, and the largest absolute and relative differences from the library's
/// auto-vectorised convolve_row.
template <class Arch, ibl_bench::xsimd_read Read>
void xsimd_level(const convolve_case& c, std::vector<ibl::vec3<float>>& out) {
    for (int row = 0; row < 6 * c.n; ++row)
        ibl_bench::xsimd_convolve_row<Arch, Read>(c.src, c.taps, row / c.n, row % c.n, c.n,
                                                  out.data() + std::size_t(row) * std::size_t(c.n));
}

template <class Arch> void run_xsimd(benchmark::State& state, const convolve_case& c, std::vector<ibl::vec3<float>>& out) {
    const bool rows = state.range(0) != 0;
    state.SetLabel(std::string(Arch::name()) + (rows ? " rows" : " gather") + ", " +
                   std::to_string(xsimd::batch<float, Arch>::size) + " lanes");
#if !defined(IBL_BENCH_XSIMD_ROWS)
    if (rows) {
        state.SkipWithError("no 4-wide float batches in this build");
        return;
    }
#endif
    for (auto _ : state) {
#if defined(IBL_BENCH_XSIMD_ROWS)
        if (rows) xsimd_level<Arch, ibl_bench::xsimd_read::rows>(c, out);
        else
#endif
            xsimd_level<Arch, ibl_bench::xsimd_read::gather>(c, out);
        benchmark::DoNotOptimize(out.data());
    }
}

void BM_convolve_xsimd(benchmark::State& state) {
    const convolve_case& c = convolve_setup();
    const int n = c.n;
    std::vector<ibl::vec3<float>> out(std::size_t(6 * n * n)), lib(out.size());
    for (int row = 0; row < 6 * n; ++row)
        ibl::detail::convolve_row(c.src, c.taps, row / n, row % n, n, lib.data() + std::size_t(row) * std::size_t(n));
    if (state.range(1) == 0) run_xsimd<xsimd::default_arch>(state, c, out);
    else {
#if XSIMD_WITH_AVX2
        run_xsimd<xsimd::avx2>(state, c, out);
#else
        state.SkipWithError("AVX2 is not enabled in this build");
        return;
#endif
    }
    double abs_diff = 0.0, rel_diff = 0.0;
    for (std::size_t i = 0; i < out.size(); ++i)
        for (int c3 = 0; c3 < 3; ++c3) {
            const double d = std::abs(double(out[i][c3]) - double(lib[i][c3]));
            abs_diff = std::max(abs_diff, d);
            if (lib[i][c3] != 0.f) rel_diff = std::max(rel_diff, d / std::abs(double(lib[i][c3])));
        }
    set_tap_rate(state, c);
    state.counters["max_abs_vs_row"] = abs_diff;
    state.counters["max_rel_vs_row"] = rel_diff;
}
#endif

} // namespace

BENCHMARK(BM_convolve_width)->ArgName("W")->Arg(1)->Arg(4)->Arg(8)->Arg(16)->Unit(benchmark::kMillisecond)->UseRealTime();
#if defined(IBL_BENCH_XSIMD)
BENCHMARK(BM_convolve_xsimd)
    ->ArgNames({"rows", "avx2"})
    ->ArgsProduct({{0, 1}, {0, 1}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
#endif
BENCHMARK(BM_prefilter_update_step)->ArgNames({"env", "log2_budget", "fast"})->ArgsProduct({{1}, {14, 16, 18, 20}, {0, 1}})->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_prefilter_update_time)->ArgNames({"env", "us", "fast"})->ArgsProduct({{1}, {50, 200, 800, 3200}, {0, 1}})->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_fixed_call_spread)->ArgName("log2_taps")->DenseRange(14, 20, 2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_prefilter_default)->ArgName("env")->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_prefilter_fis)
    ->ArgNames({"env", "spp"})
    ->ArgsProduct({{0, 1}, {16, 32, 64, 128, 256}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_prefilter_fast)
    ->ArgNames({"env", "spp"})
    ->ArgsProduct({{0, 1}, {16, 32, 64, 128, 256}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_prefilter_fast_default)->ArgName("env")->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_prefilter_fast_split)
    ->ArgNames({"env", "spp", "peaks", "size", "tail"})
    ->ArgsProduct({{1}, {4, 8, 16, 32, 64}, {0, 1}, {128, 256}, {0, 1}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_prefilter_fast_sh)
    ->ArgNames({"env", "spp", "sh", "size"})
    ->ArgsProduct({{1}, {16, 32, 64}, {0, 1}, {128, 256}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_prefilter_is)
    ->ArgNames({"env", "spp"})
    ->ArgsProduct({{0, 1}, {64, 256, 1024}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_prefilter_fis_bias)
    ->ArgNames({"env", "bias10"})
    ->ArgsProduct({{1}, {0, 5, 10}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_irradiance)->ArgNames({"env", "cosine"})->ArgsProduct({{1}, {0, 1}})->Unit(benchmark::kMillisecond)->UseRealTime();
