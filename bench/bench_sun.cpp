// Benchmarks of a sun: the texel-moment irradiance map per block-grid bound (counters: mean_rel,
// max_rel against the brute-force texel sum over level 0 of the same source), sun extraction
// (counters: direction error in degrees, E_sun relative error against the exact cap), the disk
// light's LD quadrature and its runtime diffuse / specular forms.
#include <benchmark/benchmark.h>

#include <ibl/core/executor.hpp>
#include <ibl/env/analytic.hpp>
#include <ibl/env/convert.hpp>
#include <ibl/env/sun_extract.hpp>
#include <ibl/reference/disk_light.hpp>
#include <ibl/bake/irradiance.hpp>
#include <ibl/reference/ld_irradiance.hpp>
#include <ibl/runtime/shade.hpp>

#include <algorithm>
#include <cmath>
#include <span>
#include <vector>

namespace {

using dv = ibl::vec3<double>;

struct sky_fixture {
    ibl::sky_environment<double> sky = ibl::make_default_sky<double>();
    ibl::cubemap<float> cube;
    std::vector<dv> normals;
    std::vector<dv> brute;
    explicit sky_fixture(int n) : cube(ibl::bake_cubemap<float>(sky, n, 4, ibl::thread_executor{})) {
        for (int f = 0; f < 6; ++f)
            for (int y = 0; y < 32; ++y)
                for (int x = 0; x < 32; ++x) normals.push_back(ibl::cube_texel_direction<double>(f, x, y, 32));
        brute = ibl::irradiance_texel_sum(cube, 0, std::span<const dv>(normals), ibl::thread_executor{});
    }
};

const sky_fixture& sky256() {
    static const sky_fixture f(256);
    return f;
}

// The exact LD reference of ibl-bake's specular check: ld_texel_sum of 64 directions over the 256^2
// sky + sun cube. args: roughness x 10, coarse (1: at ld_texel_sum_level, 0: level 0). Counters:
// kernel terms per second (one thread), and the largest relative difference of the coarse level's sum
// from level 0's (0 for level 0).
void BM_ld_texel_sum(benchmark::State& state) {
    const sky_fixture& fx = sky256();
    const double r = double(state.range(0)) / 10.0;
    const int level = state.range(1) ? ibl::ld_texel_sum_level(fx.cube, r) : 0;
    std::vector<dv> d64; // every 97th of the 32^2-per-face texel directions: 64 spread over the faces
    for (std::size_t i = 0; i < 64; ++i) d64.push_back(fx.normals[97 * i]);
    std::vector<dv> out;
    for (auto _ : state) {
        out = ibl::ld_texel_sum(fx.cube, level, std::span<const dv>(d64), r);
        benchmark::DoNotOptimize(out);
    }
    const std::vector<dv> l0 = ibl::ld_texel_sum(fx.cube, 0, std::span<const dv>(d64), r);
    double mx = 0.0;
    for (std::size_t i = 0; i < d64.size(); ++i) mx = std::max(mx, std::fabs(out[i].y - l0[i].y) / l0[i].y);
    const double terms = double(d64.size()) * 6.0 * ibl::sqr(double(fx.cube.size(level)));
    state.counters["terms_per_s"] = benchmark::Counter(terms * double(state.iterations()), benchmark::Counter::kIsRate);
    state.counters["level"] = level;
    state.counters["max_rel_vs_level0"] = mx;
}
BENCHMARK(BM_ld_texel_sum)->ArgNames({"r10", "coarse"})->ArgsProduct({{2, 6}, {0, 1}})->Unit(benchmark::kMillisecond);

// args: block-grid bound max_face; output 32^2 per face; source 256 (sky + sun)
void BM_irradiance_texel_moments(benchmark::State& state) {
    const sky_fixture& fx = sky256();
    const int max_face = int(state.range(0));
    ibl::cubemap<float> out(1, 1);
    for (auto _ : state) {
        out = ibl::irradiance_cubemap_texel_moments(fx.cube, 32, max_face);
        benchmark::DoNotOptimize(out);
    }
    double mean = 0.0, mx = 0.0;
    for (std::size_t i = 0; i < fx.normals.size(); ++i) {
        const int f = int(i / 1024), y = int(i / 32 % 32), x = int(i % 32);
        for (int k = 0; k < 3; ++k) {
            const double r = std::fabs(double(out.texel(f, x, y)[k]) - fx.brute[i][k]) / fx.brute[i][k];
            mean += r;
            mx = std::max(mx, r);
        }
    }
    state.counters["mean_rel"] = mean / (3.0 * double(fx.normals.size()));
    state.counters["max_rel"] = mx;
    state.counters["terms_per_texel"] = 6.0 * ibl::sqr(double(ibl::irradiance_moment_face(256, max_face)));
}
BENCHMARK(BM_irradiance_texel_moments)->Arg(8)->Arg(16)->Arg(32)->Arg(64)->Unit(benchmark::kMillisecond);

// args: source face size
void BM_extract_sun(benchmark::State& state) {
    const auto sky = ibl::make_default_sky<double>();
    const ibl::cubemap<float> cube = ibl::bake_cubemap<float>(sky, int(state.range(0)), 4, ibl::thread_executor{});
    ibl::sun_extraction<float> s;
    for (auto _ : state) {
        auto split = ibl::extract_sun(cube);
        s = split.sun;
        benchmark::DoNotOptimize(split);
    }
    const double e_true = sky.sun_radiance.x * ibl::sky_environment<double>::cap_cosine_integral(sky.sun_angular_radius);
    state.counters["found"] = s.found() ? 1.0 : 0.0;
    state.counters["dir_err_deg"] = std::acos(std::min(1.0, glm::dot(dv(s.direction), sky.sun_dir))) * 180.0 / ibl::pi_v<double>;
    state.counters["esun_rel"] = std::fabs(double(s.irradiance.x) - e_true) / e_true;
}
BENCHMARK(BM_extract_sun)->Arg(128)->Arg(256)->Arg(512)->Unit(benchmark::kMillisecond);

// args: quadrature nodes; counter: relative difference to 128 nodes
void BM_disk_light_ld(benchmark::State& state) {
    const auto sky = ibl::make_default_sky<double>();
    const ibl::disk_light<double> sun{sky.sun_dir, ibl::sky_environment<double>::cap_solid_angle(sky.sun_angular_radius), sky.sun_radiance};
    const dv R = glm::normalize(sky.sun_dir + dv(0.02, 0.0, 0.0));
    const int nodes = int(state.range(0));
    for (auto _ : state) benchmark::DoNotOptimize(ibl::disk_light_ld(sun, R, 0.3, nodes));
    // (the read-modify-write DoNotOptimize of a double lvalue read back wrong values here under
    // g++ 12 -O2 with Debian's Google Benchmark; the rvalue form and a separate call are used)
    const double v = ibl::disk_light_ld(sun, R, 0.3, nodes).x, ref = ibl::disk_light_ld(sun, R, 0.3, 128).x;
    state.counters["rel_vs_128"] = std::fabs(v - ref) / ref;
}
BENCHMARK(BM_disk_light_ld)->Arg(8)->Arg(16)->Arg(32)->Unit(benchmark::kMicrosecond);

void BM_shade_disk(benchmark::State& state) {
    const ibl::disk_light<float> sun{ibl::vec3<float>(0.6f, 0.5f, 0.62f), 9.57e-4f, ibl::vec3<float>(3e4f)};
    const auto m = ibl::resolve_material(ibl::pbr_material<float>{});
    std::vector<ibl::vec3<float>> ns;
    for (int i = 0; i < 1024; ++i) {
        const float a = 0.006f * float(i);
        ns.push_back(glm::normalize(ibl::vec3<float>(std::cos(a), 1.0f, std::sin(a))));
    }
    const ibl::vec3<float> v = glm::normalize(ibl::vec3<float>(0.2f, 1.0f, 0.1f));
    for (auto _ : state)
        for (const auto& n : ns) benchmark::DoNotOptimize(ibl::shade_disk(glm::normalize(n), v, sun, m));
    state.SetItemsProcessed(state.iterations() * 1024);
}
BENCHMARK(BM_shade_disk);

} // namespace
