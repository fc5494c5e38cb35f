// env/: lookup throughput of cubemap / latlong and the cost of conversions, each with an error
// counter against the analytic function that was baked (L(d) = d.x + 2 d.y + 3 d.z + 4).
#include <benchmark/benchmark.h>

#include <ibl/env.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <vector>

namespace {

using v3f = ibl::vec3<float>;

v3f linear_fn(const v3f& d) { return v3f(d.x + 2.f * d.y + 3.f * d.z + 4.f); }

std::vector<v3f> random_dirs(std::size_t count) {
    std::uint64_t s = 0x243F6A8885A308D3ull;
    auto uniform = [&] {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        return double(s >> 11) * 0x1p-53;
    };
    std::vector<v3f> dirs(count);
    for (auto& d : dirs) {
        const double z = 1.0 - 2.0 * uniform(), phi = ibl::two_pi_v<double> * uniform();
        const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
        d = v3f(float(r * std::cos(phi)), float(r * std::sin(phi)), float(z));
    }
    return dirs;
}

const ibl::cubemap<float>& linear_cube(int n) {
    static std::map<int, ibl::cubemap<float>> cache;
    auto it = cache.find(n);
    if (it == cache.end())
        it = cache.emplace(n, ibl::bake_cubemap<float>(ibl::make_lambda_environment<float>(linear_fn), n, 1)).first;
    return it->second;
}

const ibl::latlong<float>& linear_latlong(int w) {
    static std::map<int, ibl::latlong<float>> cache;
    auto it = cache.find(w);
    if (it == cache.end()) {
        ibl::latlong<float> m(w, w / 2);
        m.fill(0, [&](int x, int y) {
            return linear_fn(ibl::latlong_direction((float(x) + 0.5f) / float(w), 1.f - (float(y) + 0.5f) / float(w / 2)));
        });
        m.generate_mips();
        it = cache.emplace(w, std::move(m)).first;
    }
    return it->second;
}

constexpr std::size_t n_dirs = 1 << 14;

template <class Lookup> void lookup_loop(benchmark::State& state, Lookup&& lookup) {
    const std::vector<v3f> dirs = random_dirs(n_dirs);
    std::size_t i = 0;
    for (auto _ : state) {
        benchmark::DoNotOptimize(lookup(dirs[i], i));
        i = (i + 1) & (n_dirs - 1);
    }
    state.SetItemsProcessed(state.iterations());
    // Error of level-0 interpolation against the baked function (texel means, so O(h^2)).
    double max_err = 0;
    for (std::size_t k = 0; k < 4096; ++k) {
        const v3f got = lookup(dirs[k], std::size_t(-1));
        max_err = std::max(max_err, double(std::fabs(got.x - linear_fn(dirs[k]).x)));
    }
    state.counters["max_err"] = max_err;
}

void BM_cube_bilinear(benchmark::State& state) {
    const auto& c = linear_cube(int(state.range(0)));
    lookup_loop(state, [&](const v3f& d, std::size_t) { return c.bilinear(d, 0); });
}
BENCHMARK(BM_cube_bilinear)->ArgName("n")->Arg(64)->Arg(256)->Arg(1024);

void BM_cube_trilinear(benchmark::State& state) {
    const auto& c = linear_cube(int(state.range(0)));
    std::vector<float> lods(n_dirs);
    for (std::size_t i = 0; i < n_dirs; ++i) lods[i] = c.max_lod() * float((i * 2654435761u) % 1000) / 1000.f;
    lookup_loop(state, [&](const v3f& d, std::size_t i) { return c.radiance(d, i == std::size_t(-1) ? 0.f : lods[i]); });
}
BENCHMARK(BM_cube_trilinear)->ArgName("n")->Arg(256);

void BM_cube_nearest(benchmark::State& state) {
    const auto& c = linear_cube(int(state.range(0)));
    lookup_loop(state, [&](const v3f& d, std::size_t) { return c.nearest(d, 0.f); });
}
BENCHMARK(BM_cube_nearest)->ArgName("n")->Arg(256);

void BM_latlong_bilinear(benchmark::State& state) {
    const auto& m = linear_latlong(int(state.range(0)));
    lookup_loop(state, [&](const v3f& d, std::size_t) { return m.radiance(d, 0.f); });
}
BENCHMARK(BM_latlong_bilinear)->ArgName("w")->Arg(1024);

void BM_sky_radiance(benchmark::State& state) {
    const auto sky = ibl::make_default_sky<float>();
    const std::vector<v3f> dirs = random_dirs(n_dirs);
    std::size_t i = 0;
    for (auto _ : state) {
        benchmark::DoNotOptimize(sky.radiance(dirs[i]));
        i = (i + 1) & (n_dirs - 1);
    }
    state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_sky_radiance);

/// latlong 1024x512 -> cubemap 256^2 with k x k sub-samples; error against the analytic bake
/// with the same sub-samples (so only the latlong representation error remains).
void BM_latlong_to_cubemap(benchmark::State& state) {
    const int n = 256, k = int(state.range(0));
    const auto& m = linear_latlong(1024);
    const ibl::cubemap<float> exact = ibl::bake_cubemap<float>(ibl::make_lambda_environment<float>(linear_fn), n, k);
    double max_err = 0, sq = 0;
    for (auto _ : state) {
        ibl::cubemap<float> c = ibl::latlong_to_cubemap(m, n, k);
        state.PauseTiming();
        max_err = 0;
        sq = 0;
        for (int f = 0; f < 6; ++f)
            for (int y = 0; y < n; ++y)
                for (int x = 0; x < n; ++x) {
                    const double e = double(c.texel(f, x, y).x) - double(exact.texel(f, x, y).x);
                    max_err = std::max(max_err, std::fabs(e));
                    sq += e * e;
                }
        state.ResumeTiming();
    }
    state.counters["max_err"] = max_err;
    state.counters["rmse"] = std::sqrt(sq / (6.0 * n * n));
    state.SetItemsProcessed(state.iterations() * 6 * n * n);
}
BENCHMARK(BM_latlong_to_cubemap)->ArgName("k")->Arg(1)->Arg(2)->Arg(4)->Unit(benchmark::kMillisecond);

/// Mip chain of a 256^2 cubemap (exact spherical box filter); counter: relative change of the
/// spherical integral between level 0 and the 1x1 level.
void BM_cube_generate_mips(benchmark::State& state) {
    ibl::cubemap<float> c = linear_cube(int(state.range(0)));
    for (auto _ : state) {
        c.generate_mips();
        benchmark::ClobberMemory();
    }
    double i0 = 0, il = 0;
    const int n = c.size(0), last = c.levels() - 1;
    for (int f = 0; f < 6; ++f) {
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) i0 += double(c.texel(f, x, y).x) * double(c.exact_texel_solid_angle(x, y));
        il += double(c.texel(f, 0, 0, last).x) * double(c.exact_texel_solid_angle(0, 0, last));
    }
    state.counters["integral_rel_err"] = std::fabs(il - i0) / i0;
}
BENCHMARK(BM_cube_generate_mips)->ArgName("n")->Arg(256)->Unit(benchmark::kMillisecond);

} // namespace
