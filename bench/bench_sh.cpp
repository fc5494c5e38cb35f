// Benchmarks of sh/: cube -> SH projection (serial and threaded), lat-long projection, batch basis
// evaluation. Every projection reports max_err: the max abs error of the projected coefficients of
// a band-limited input (a known 3-band expansion sampled at texel centres) against the exact ones.
#include <benchmark/benchmark.h>

#include <ibl/core/executor.hpp>
#include <ibl/sh.hpp>

#include <cmath>
#include <random>
#include <vector>

namespace {

using ibl::vec3;

template <int B> ibl::sh_coeffs<float, B> reference_coeffs() {
    std::mt19937 g(42);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    ibl::sh_coeffs<float, B> c;
    for (int k = 0; k < B * B; ++k) c[k] = vec3<float>(u(g), u(g), u(g));
    c[0] += vec3<float>(4.0f); // keep the radiance mostly positive, like a real map
    return c;
}

struct cube_input {
    int n;
    std::vector<vec3<float>> texels; // face-major, then row, then column
};

template <int B> cube_input make_cube(int n, const ibl::sh_coeffs<float, B>& c) {
    cube_input in{n, std::vector<vec3<float>>(std::size_t(6) * std::size_t(n) * std::size_t(n))};
    for (int f = 0; f < 6; ++f)
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x)
                in.texels[(std::size_t(f) * n + y) * n + x] = ibl::sh_evaluate(c, ibl::cube_texel_direction<float>(f, x, y, n));
    return in;
}

template <int B> double max_err(const ibl::sh_coeffs<float, B>& a, const ibl::sh_coeffs<float, B>& b) {
    double m = 0;
    for (int k = 0; k < B * B; ++k)
        for (int ch = 0; ch < 3; ++ch) m = std::max(m, std::fabs(double(a[k][ch]) - double(b[k][ch])));
    return m;
}

template <int B, class Executor> void project_cube_bench(benchmark::State& state, Executor ex) {
    const int n = int(state.range(0));
    const auto ref = reference_coeffs<B>();
    const cube_input in = make_cube<B>(n, ref);
    auto fetch = [&](int f, int x, int y) -> const vec3<float>& {
        return in.texels[(std::size_t(f) * std::size_t(n) + std::size_t(y)) * std::size_t(n) + std::size_t(x)];
    };
    ibl::sh_coeffs<float, B> out;
    for (auto _ : state) {
        out = ibl::project_cube<B>(n, fetch, ex);
        benchmark::DoNotOptimize(out);
    }
    state.SetItemsProcessed(state.iterations() * 6 * std::int64_t(n) * n);
    state.counters["max_err"] = max_err(out, ref);
    state.counters["ms"] = benchmark::Counter(double(state.iterations()) * 1e-3,
                                              benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

void BM_sh_project_cube_serial_B3(benchmark::State& s) { project_cube_bench<3>(s, ibl::serial_executor{}); }
void BM_sh_project_cube_threads2_B3(benchmark::State& s) { project_cube_bench<3>(s, ibl::thread_executor{2}); }
void BM_sh_project_cube_serial_B5(benchmark::State& s) { project_cube_bench<5>(s, ibl::serial_executor{}); }
BENCHMARK(BM_sh_project_cube_serial_B3)->ArgName("n")->Arg(64)->Arg(128)->Arg(256)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_sh_project_cube_threads2_B3)->ArgName("n")->Arg(256)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_sh_project_cube_serial_B5)->ArgName("n")->Arg(256)->Unit(benchmark::kMillisecond);

void BM_sh_project_latlong_B3(benchmark::State& state) {
    const int h = int(state.range(0)), w = 2 * h;
    const auto ref = reference_coeffs<3>();
    std::vector<vec3<float>> img(std::size_t(w) * std::size_t(h));
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const double phi = ibl::two_pi_v<double> * (x + 0.5) / w - ibl::pi_v<double>;
            const double lat = ibl::half_pi_v<double> - ibl::pi_v<double> * (y + 0.5) / h;
            const vec3<float> d(float(std::cos(lat) * std::cos(phi)), float(std::sin(lat)), float(std::cos(lat) * std::sin(phi)));
            img[std::size_t(y) * w + x] = ibl::sh_evaluate(ref, d);
        }
    auto fetch = [&](int x, int y) -> const vec3<float>& { return img[std::size_t(y) * std::size_t(w) + std::size_t(x)]; };
    ibl::sh_coeffs<float, 3> out;
    for (auto _ : state) {
        out = ibl::project_latlong<3>(w, h, fetch);
        benchmark::DoNotOptimize(out);
    }
    state.SetItemsProcessed(state.iterations() * std::int64_t(w) * h);
    state.counters["max_err"] = max_err(out, ref);
}
BENCHMARK(BM_sh_project_latlong_B3)->ArgName("H")->Arg(256)->Arg(512)->Unit(benchmark::kMillisecond);

template <int B> void basis_batch_bench(benchmark::State& state) {
    const std::size_t n = std::size_t(state.range(0));
    std::mt19937 g(1);
    std::normal_distribution<float> nd;
    std::vector<float> x(n), y(n), z(n), out(std::size_t(B * B) * n);
    for (std::size_t i = 0; i < n; ++i) {
        vec3<float> d = glm::normalize(vec3<float>(nd(g), nd(g), nd(g)));
        x[i] = d.x, y[i] = d.y, z[i] = d.z;
    }
    for (auto _ : state) {
        ibl::sh_basis_batch<B>(x.data(), y.data(), z.data(), n, out.data(), n);
        benchmark::DoNotOptimize(out.data());
        benchmark::ClobberMemory();
    }
    state.SetItemsProcessed(state.iterations() * std::int64_t(n)); // directions per second
    // lane-by-lane agreement with the scalar basis (max abs difference)
    double diff = 0;
    for (std::size_t i = 0; i < n; ++i) {
        const auto s = ibl::sh_basis<B>(vec3<float>(x[i], y[i], z[i]));
        for (int k = 0; k < B * B; ++k) diff = std::max(diff, double(std::fabs(out[std::size_t(k) * n + i] - s[k])));
    }
    state.counters["max_err_vs_scalar"] = diff;
}
BENCHMARK(basis_batch_bench<3>)->Name("BM_sh_basis_batch_B3")->ArgName("dirs")->Arg(500)->Arg(4000); // not powers of two: planes 2^k bytes apart alias in L1
BENCHMARK(basis_batch_bench<5>)->Name("BM_sh_basis_batch_B5")->ArgName("dirs")->Arg(500)->Arg(4000); // not powers of two: planes 2^k bytes apart alias in L1

} // namespace
