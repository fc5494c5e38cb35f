// tools/ibl-bake/plan_measure.cpp — the measurements behind the decision tables of
// include/ibl/bake/plan.hpp. Run it after changing an integrator and update the tables.
//
//   1. DFG LUT: the largest bilinear-interpolation error of an exact N^2 table (clamp-to-edge, as
//      a GPU samples it) against dfg_exact at off-grid points, N = 16 .. 256. The points are a
//      257 x 257 grid over [0, 1]^2 offset by half a cell of the finest table (so no point is a
//      texel centre), every domain edge included (n.v = 0 and r = 0 lie outside the texel centres:
//      clamp-to-edge extrapolates there, which is what a shader reads).
//   2. SH irradiance: 2 bands against 3 bands, error of the irradiance against a brute-force
//      cosine integral of the same 64^2 cubemap (every texel, exact solid angles), at the texel
//      centres of a 16 x 16-per-face cube, normalised by the RMS / the largest irradiance (see
//      sh_err); default sky + sun and the test HDRs.
//   3. Specular prefilter (filtered importance sampling, nearest-level reads, lod bias 0.5): the
//      normalised RMSE (RMSE / RMS of the reference) of levels of roughness r against
//      reference_ld_sky on the default sky + sun, for N = 16 .. 1024 samples, at a 64^2 base
//      (bench/bench_prefilter.cpp has the 256^2-base sweep; both feed plan.hpp's constant).
//
// usage: ibl_plan_measure [dfg] [sh] [prefilter]     (default: all)
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <span>
#include <string>
#include <vector>

#include "check_texels.hpp"

#include <ibl/brdf/model.hpp>
#include <ibl/core/color.hpp>
#include <ibl/core/executor.hpp>
#include <ibl/env/cube_geometry.hpp>
#include <ibl/env/analytic.hpp>
#include <ibl/env/convert.hpp>
#include <ibl/env/latlong.hpp>
#include <ibl/bake/dfg.hpp>
#include <ibl/bake/dfg_lut.hpp>
#include <ibl/reference/metrics.hpp>
#include <ibl/bake/prefilter.hpp>
#include <ibl/reference/ld_irradiance.hpp>
#include <ibl/sh/convolve.hpp>
#include <ibl/sh/project.hpp>
#include <ibl/sh/window.hpp>

#include "image_io.hpp"

namespace {

using dvec3 = ibl::vec3<double>;
using model = ibl::ggx_height_correlated;

void measure_dfg() {
    std::printf("DFG LUT (%s): bilinear error of an exact N^2 table against dfg_exact, 257^2 off-grid points\n",
                model::name);
    std::printf("%6s %12s %12s %14s\n", "N", "max |dA|,|dB|", "rms", "max (n.v>=0.1)");
    constexpr int g = 257;
    std::vector<ibl::vec2<double>> ref(std::size_t(g) * g);
    std::vector<double> xs(g);
    for (int i = 0; i < g; ++i) xs[std::size_t(i)] = std::min(1.0, (double(i) + 0.5 / 256.0) / double(g - 1));
    ibl::thread_executor{}(std::size_t(g) * g, [&](std::size_t b, std::size_t e) {
        for (std::size_t k = b; k < e; ++k) ref[k] = ibl::dfg_exact<model>(xs[k % g], xs[k / g]);
    });
    for (std::uint32_t n : {16u, 32u, 64u, 128u, 256u}) {
        const ibl::dfg_lut lut = ibl::make_dfg_lut_exact<model>(n, 2);
        double mx = 0, ss = 0, mx_inner = 0;
        for (std::size_t k = 0; k < ref.size(); ++k) {
            const ibl::vec3<float> s = lut.sample(float(xs[k % g]), float(xs[k / g]));
            const double d = std::max(std::fabs(s.x - ref[k].x), std::fabs(s.y - ref[k].y));
            mx = std::max(mx, d);
            ss += d * d;
            if (xs[k % g] >= 0.1) mx_inner = std::max(mx_inner, d);
        }
        std::printf("%6u %12.3e %12.3e %14.3e\n", n, mx, std::sqrt(ss / double(ref.size())), mx_inner);
    }
}

/// Per band count: nrmse = RMS(E_sh - E) / RMS(E) and max = max |E_sh - E| / max E (channel
/// sums): the error relative to the scale of the irradiance, not to each normal's own E (which
/// is tiny facing away from a sun, where a relative error says nothing about what is seen).
struct sh_err {
    double nrmse2 = 0, max2 = 0, nrmse3 = 0, max3 = 0;
};

/// The SH irradiance ibl-bake ships by default: the weakest Hanning window keeping E >= 0
/// (sh_auto_window; unchanged when E is already non-negative).
template <int B> ibl::sh_coeffs<double, B> shipped(const ibl::sh_coeffs<double, B>& c) {
    const auto w = ibl::sh_auto_window(c);
    return w.ok ? w.radiance : c;
}

sh_err sh_errors(const ibl::cubemap<float>& cube, bool windowed) {
    std::vector<dvec3> normals;
    for (int f = 0; f < 6; ++f)
        for (int y = 0; y < 16; ++y)
            for (int x = 0; x < 16; ++x) normals.push_back(ibl::cube_texel_direction<double>(f, x, y, 16));
    const int n = cube.size(0);
    const std::vector<dvec3> ref = ibl::irradiance_texel_sum(cube, 0, std::span<const dvec3>(normals), ibl::thread_executor{});
    auto c3 = ibl::project_cube<3>(
        n, [&](int f, int x, int y) { return dvec3(cube.texel(f, x, y, 0)); }, ibl::thread_executor{});
    auto c2 = ibl::project_cube<2>(
        n, [&](int f, int x, int y) { return dvec3(cube.texel(f, x, y, 0)); }, ibl::thread_executor{});
    if (windowed) {
        c3 = shipped(c3);
        c2 = shipped(c2);
    }
    sh_err r;
    double ss_ref = 0, max_ref = 0;
    for (std::size_t i = 0; i < normals.size(); ++i) {
        const double er = ref[i].x + ref[i].y + ref[i].z;
        const dvec3 e2 = ibl::sh_irradiance_at(c2, normals[i]), e3 = ibl::sh_irradiance_at(c3, normals[i]);
        const double d2 = e2.x + e2.y + e2.z - er, d3 = e3.x + e3.y + e3.z - er;
        ss_ref += er * er;
        max_ref = std::max(max_ref, er);
        r.nrmse2 += d2 * d2;
        r.nrmse3 += d3 * d3;
        r.max2 = std::max(r.max2, std::fabs(d2));
        r.max3 = std::max(r.max3, std::fabs(d3));
    }
    r.nrmse2 = std::sqrt(r.nrmse2 / ss_ref);
    r.nrmse3 = std::sqrt(r.nrmse3 / ss_ref);
    r.max2 /= max_ref;
    r.max3 /= max_ref;
    return r;
}

void measure_sh() {
    std::printf("\nSH irradiance vs brute force (64^2 cube, 1536 normals): RMS(dE)/RMS(E), max|dE|/max E\n"
                "raw: the projection; shipped: with the automatic window (E >= 0), what ibl-bake writes\n");
    std::printf("%-22s %-8s %10s %10s %10s %10s\n", "environment", "", "2b nrmse", "2b max", "3b nrmse", "3b max");
    auto row = [](const char* name, const ibl::cubemap<float>& cube) {
        for (bool w : {false, true}) {
            const sh_err e = sh_errors(cube, w);
            std::printf("%-22s %-8s %10.4f %10.4f %10.4f %10.4f\n", name, w ? "shipped" : "raw", e.nrmse2, e.max2, e.nrmse3, e.max3);
        }
    };
    row("default sky + sun", ibl::bake_cubemap<float>(ibl::make_default_sky<float>(), 64, 16, ibl::thread_executor{}, 1));
    for (const char* file : {"courtyard.exr", "studio.exr"}) {
        const ibl_bake::image_rgb32f img = ibl_bake::read_latlong(std::string(IBL_RESEARCH_DATA_DIR) + "/" + file);
        const ibl::latlong<float> ll(img.width, img.height, std::span<const float>(img.rgb), 1);
        row(file, ibl::latlong_to_cubemap(ll, 64, 4, ibl::thread_executor{}, 1));
    }
}


double nrmse_at(const std::vector<dvec3>& a, const std::vector<dvec3>& ref) {
    ibl::error_accumulator acc(1e-3);
    for (std::size_t i = 0; i < a.size(); ++i) acc.add(a[i], ref[i]);
    return acc.finish().nrmse;
}

/// 3. The chain layouts the plan produces (ibl-bake: 6 virtual levels, linear policy; the plan's
/// virtual base is 256 when r = 0.2 is read, else 128 for a 256 source), levels r = 0.2 .. 1 at
/// face size base >> v, source cube baked at the base size with 4 x 4 sub-samples (as ibl-bake).
/// Per level, read mode (nearest / trilinear) and N: nrmse at the check texels against
///   conv  the converged level of the same layout (N = 4096, trilinear): what the product target
///         of the plan refers to (ibl-bake --compare-full's converged set);
///   ref   reference_ld_sky (the true LD; the floor of filtered IS itself shows here).
void measure_prefilter() {
    constexpr int levels = 6;
    const std::vector<std::uint32_t> ns = {64u, 128u, 256u, 512u, 1024u, 2048u, 4096u};
    const auto sky = ibl::make_default_sky<double>();
    const ibl::roughness_mip_policy policy = ibl::roughness_mip_policy::linear();
    ibl::thread_executor ex{};
    for (int base : {256, 128}) {
        const ibl::cubemap<float> src = ibl::bake_cubemap<float>(ibl::make_default_sky<float>(), base, 4, ex, 0);
        dvec3 light(0, 1, 0);
        double best = -1;
        for (int f = 0; f < 6; ++f)
            for (int y = 0; y < base; ++y)
                for (int x = 0; x < base; ++x)
                    if (const double l = ibl::luminance(dvec3(src.texel(f, x, y, 0))); l > best)
                        best = l, light = ibl::cube_texel_direction<double>(f, x, y, base);
        std::printf("\nPrefilter FIS (bias 0.5), base %d, %d levels (linear), default sky + sun: nrmse per level at the\n"
                    "--compare-full check texels vs converged (4096 trilinear, same layout) and vs reference_ld_sky\n",
                    base, levels);
        for (int v = 1; v < levels; ++v) {
            const double r = policy.roughness(double(v), levels);
            const int n = base >> v;
            const auto tex = ibl_bake::check_texels(n, 6, light);
            std::vector<dvec3> ref(tex.size());
            ex(tex.size(), [&](std::size_t b, std::size_t e) {
                for (std::size_t i = b; i < e; ++i)
                    ref[i] = ibl::reference_ld_sky(sky, ibl::cube_texel_direction<double>(tex[i][0], tex[i][1], tex[i][2], n), r, 2048, 16);
            });
            std::vector<std::vector<dvec3>> got[2];
            for (int tri = 0; tri < 2; ++tri)
                for (std::uint32_t N : ns) {
                    ibl::sphere_sample_table<float> table =
                        ibl::make_ld_table_for<float>(src, r, N, ibl::prefilter_method::filtered_importance, 0.5);
                    table.trilinear = tri == 1;
                    const std::vector<ibl::vec3<float>> t = ibl::convolve_faces(src, table, n, ex);
                    std::vector<dvec3> at;
                    for (const auto& k : tex)
                        at.push_back(dvec3(t[(std::size_t(k[0]) * std::size_t(n) + std::size_t(k[2])) * std::size_t(n) + std::size_t(k[1])]));
                    got[tri].push_back(std::move(at));
                }
            const std::vector<dvec3>& conv = got[1].back();
            std::printf("level %d r=%.2f size %d: conv-vs-ref %.4f\n  %6s %9s %9s %9s %9s %8s %8s\n", v, r, n, nrmse_at(conv, ref), "N",
                        "near conv", "tri conv", "near ref", "tri ref", "nc*sqrtN", "tc*sqrtN");
            for (std::size_t i = 0; i < ns.size(); ++i) {
                const double nc = nrmse_at(got[0][i], conv), tc = nrmse_at(got[1][i], conv);
                std::printf("  %6u %9.4f %9.4f %9.4f %9.4f %8.2f %8.2f\n", ns[i], nc, tc, nrmse_at(got[0][i], ref),
                            nrmse_at(got[1][i], ref), nc * std::sqrt(double(ns[i])), tc * std::sqrt(double(ns[i])));
            }
            std::fflush(stdout);
        }
    }
}

} // namespace

int main(int argc, char** argv) {
    std::vector<std::string> what(argv + 1, argv + argc);
    auto want = [&](const char* w) { return what.empty() || std::find(what.begin(), what.end(), w) != what.end(); };
    if (want("dfg")) measure_dfg();
    if (want("sh")) measure_sh();
    if (want("prefilter")) measure_prefilter();
    return 0;
}
