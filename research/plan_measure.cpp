// research/plan_measure.cpp — the measurements behind the bake plan's data,
// include/ibl/bake/plan_tables.hpp, which it writes (--write-header). Run it after changing an
// integrator, write the header and run the tests (tests/test_plan.cpp pins plans that follow from
// the tables).
//
//   1. dfg: the largest bilinear-interpolation error of an exact N^2 table (clamp-to-edge, as a
//      GPU samples it) against dfg_exact at off-grid points, N = 16 .. 256. The points are a
//      257 x 257 grid over [0, 1]^2 offset by half a cell of the finest table (so no point is a
//      texel centre), every domain edge included (n.v = 0 and r = 0 lie outside the texel centres:
//      clamp-to-edge extrapolates there, which is what a shader reads). The table: n.v >= 0.1.
//   2. sh: 2 and 3 bands, error of the irradiance against a brute-force cosine integral of the
//      same 64^2 cubemap (every texel, exact solid angles), at the texel centres of a 16 x 16-per-
//      face cube, normalised by the RMS / the largest irradiance (see sh_err); the built-in sky +
//      sun and tests/data/{courtyard,studio}.exr. The table: the worst RMS error of the shipped
//      (automatically windowed) SH.
//   3. prefilter: the chain layouts the plan produces (see measure_prefilter), filtered importance
//      sampling at N = 64 .. 4096, nearest-level and trilinear reads, against the converged level.
//      The table: the non-increasing upper envelope over N' >= N and both layouts.
//
// usage: ibl_plan_measure [dfg] [sh] [prefilter]     print the measurements (default: all)
//        ibl_plan_measure --check [dfg] [sh] [prefilter]
//                        measure and compare with the compiled-in tables (exit 1 if one differs)
//        ibl_plan_measure --write-header PATH      measure all three and write the header
// Regenerate the header (release preset; the prefilter part takes minutes, dfg and sh seconds):
//   cmake --preset release && cmake --build --preset release --target ibl_plan_measure
//   ./build/release/research/ibl_plan_measure --write-header include/ibl/bake/plan_tables.hpp
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <span>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "stages/check_texels.hpp"

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
#include <ibl/bake/plan.hpp>
#include <ibl/bake/prefilter.hpp>
#include <ibl/reference/ld_irradiance.hpp>
#include <ibl/sh/convolve.hpp>
#include <ibl/sh/project.hpp>
#include <ibl/sh/window.hpp>

#include "io/image_io.hpp"

namespace {

using dvec3 = ibl::vec3<double>;
using model = ibl::ggx_height_correlated;

/// What the header holds: the grids the measurements ran on and the measured values (written with 3
/// decimals, the DFG errors with 3 significant digits: the text --check compares).
struct plan_tables {
    std::array<std::uint32_t, 5> dfg_sizes{16u, 32u, 64u, 128u, 256u};
    std::array<double, 5> dfg_error{};
    double sh2 = 0.0, sh3 = 0.0;
    std::array<double, 5> prefilter_r{0.2, 0.4, 0.6, 0.8, 1.0};
    std::array<std::uint32_t, 7> prefilter_n{64u, 128u, 256u, 512u, 1024u, 2048u, 4096u};
    double nearest[5][7] = {}, trilinear[5][7] = {};
};

std::array<double, 5> measure_dfg() {
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
    std::array<double, 5> inner{};
    const std::array<std::uint32_t, 5> sizes = plan_tables{}.dfg_sizes;
    for (std::size_t row = 0; row < sizes.size(); ++row) {
        const std::uint32_t n = sizes[row];
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
        inner[row] = mx_inner;
    }
    return inner;
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

/// The worst RMS error of the shipped 2- and 3-band SH over the environments.
std::array<double, 2> measure_sh() {
    std::printf("\nSH irradiance vs brute force (64^2 cube, 1536 normals): RMS(dE)/RMS(E), max|dE|/max E\n"
                "raw: the projection; shipped: with the automatic window (E >= 0), what ibl-bake writes\n");
    std::printf("%-22s %-8s %10s %10s %10s %10s\n", "environment", "", "2b nrmse", "2b max", "3b nrmse", "3b max");
    std::array<double, 2> worst{};
    auto row = [&](const char* name, const ibl::cubemap<float>& cube) {
        for (bool w : {false, true}) {
            const sh_err e = sh_errors(cube, w);
            std::printf("%-22s %-8s %10.4f %10.4f %10.4f %10.4f\n", name, w ? "shipped" : "raw", e.nrmse2, e.max2, e.nrmse3, e.max3);
            if (w) worst = {std::max(worst[0], e.nrmse2), std::max(worst[1], e.nrmse3)};
        }
    };
    row("default sky + sun", ibl::bake_cubemap<float>(ibl::make_default_sky<float>(), 64, 16, ibl::thread_executor{}, 1));
    for (const char* file : {"courtyard.exr", "studio.exr"}) {
        const ibl_bake::image_rgb32f img = ibl_bake::read_latlong(std::string(IBL_RESEARCH_DATA_DIR) + "/" + file);
        const ibl::latlong<float> ll(img.width, img.height, std::span<const float>(img.rgb), 1);
        row(file, ibl::latlong_to_cubemap(ll, 64, 4, ibl::thread_executor{}, 1));
    }
    return worst;
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
/// The table (nearest = 0, trilinear = 1): per level and N the largest conv error over N' >= N
/// and both layouts; trilinear at 4096 is the converged set itself, its entry nearest-4096's.
void measure_prefilter(plan_tables& out) {
    constexpr int levels = 6;
    const std::vector<std::uint32_t> ns(out.prefilter_n.begin(), out.prefilter_n.end());
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
                const double tri = i + 1 == ns.size() ? nc : tc; // the converged set against itself: 0
                for (std::size_t k = 0; k <= i; ++k) {             // the envelope over N' >= N
                    out.nearest[v - 1][k] = std::max(out.nearest[v - 1][k], nc);
                    out.trilinear[v - 1][k] = std::max(out.trilinear[v - 1][k], tri);
                }
            }
            std::fflush(stdout);
        }
    }
}

// ---- the header ---------------------------------------------------------------------------------

/// The decimal text of a table value: 3 decimals, or 3 significant digits as "3.84e-2" (e).
std::string number(double x, bool e = false) {
    char buf[32];
    std::snprintf(buf, sizeof buf, e ? "%.2e" : "%.3f", x);
    std::string s = buf;
    if (const auto p = s.find("e-0"); p != std::string::npos) s.erase(p + 2, 1);
    return s;
}
/// A recorded value as a double literal ("1.0", not "1").
std::string recorded(double x) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", x);
    std::string s = buf;
    return s.find_first_of(".e") == std::string::npos ? s + ".0" : s;
}
template <class T, std::size_t N> std::string list(const std::array<T, N>& a, bool e = false) {
    std::string s;
    for (std::size_t i = 0; i < N; ++i) {
        if constexpr (std::is_integral_v<T>) s += std::to_string(a[i]);
        else s += e ? number(double(a[i]), true) : recorded(double(a[i]));
        s += i + 1 < N ? ", " : "";
    }
    return s;
}
std::string rows(const double (&t)[5][7]) {
    std::string s;
    for (int i = 0; i < 5; ++i) {
        s += i % 2 == 0 ? "\n    {" : " {";
        for (int j = 0; j < 7; ++j) s += number(t[i][j]) + (j < 6 ? ", " : "}");
        s += i < 4 ? "," : "";
    }
    return s;
}

/// Measured against compiled-in: equal when the measured value's text reads as the constant.
bool check_tables(const plan_tables& t, bool dfg, bool sh, bool prefilter) {
    int bad = 0;
    auto same = [&](const char* what, const std::string& measured, double compiled) {
        if (std::strtod(measured.c_str(), nullptr) == compiled) return;
        std::printf("plan_tables.hpp: %s is %.17g, measured %s\n", what, compiled, measured.c_str());
        ++bad;
    };
    for (std::size_t i = 0; dfg && i < 5; ++i) same("dfg_interp_error", number(t.dfg_error[i], true), ibl::dfg_interp_error[i]);
    if (sh) {
        same("sh2_irradiance_error", number(t.sh2), ibl::sh2_irradiance_error);
        same("sh3_irradiance_error", number(t.sh3), ibl::sh3_irradiance_error);
    }
    for (int i = 0; prefilter && i < 5; ++i)
        for (int j = 0; j < 7; ++j) {
            same("prefilter_error_nearest", number(t.nearest[i][j]), ibl::prefilter_error_nearest[i][j]);
            same("prefilter_error_trilinear", number(t.trilinear[i][j]), ibl::prefilter_error_trilinear[i][j]);
        }
    std::printf(bad == 0 ? "plan_tables.hpp: the measured tables equal the compiled-in ones\n"
                         : "plan_tables.hpp: %d value(s) differ: FAILED\n", bad);
    return bad == 0;
}

/// The header: the measured tables, and the recorded values carried over from the compiled-in one.
bool write_header(const std::string& path, const plan_tables& t) {
    std::string h = R"(#pragma once
// ibl/bake/plan_tables.hpp — the bake plan's data (bake/plan.hpp holds the model and the rules):
// the measured relations it decides with. GENERATED by research/plan_measure.cpp: regenerate it,
// do not edit the measured values by hand.
//
// Written by:  ibl_plan_measure --write-header include/ibl/bake/plan_tables.hpp
//              (research/plan_measure.cpp, target ibl_plan_measure; its top comment has the method)
// Regenerate:  cmake --preset release && cmake --build --preset release --target ibl_plan_measure
//              ./build/release/research/ibl_plan_measure --write-header include/ibl/bake/plan_tables.hpp
//              (dfg and sh take seconds, prefilter minutes on 2 cores), then run the tests:
//              tests/test_plan.cpp pins plans that follow from these values, and the ctest
//              plan_tables (ibl_plan_measure --check dfg sh) re-measures the DFG and SH rows.
@STATUS@
// Inputs:
//   prefilter  the built-in sky + 1-degree sun of 3e4 (ibl::make_default_sky): source cubes of 256^2
//              and 128^2 (4 x 4 sub-samples), the plan's chain layouts (6 virtual levels, linear
//              policy, level v at base >> v), filtered importance sampling (lod bias 0.5); nrmse at
//              the ibl-bake --compare-full check texels against the converged level (4096 samples,
//              trilinear); the non-increasing upper envelope over N' >= N and both layouts.
//   sh         the built-in sky + sun, tests/data/courtyard.exr and studio.exr as 64^2 cubes: RMS
//              error of the shipped (automatically windowed) SH irradiance against the brute-force
//              cosine integral at 1536 normals; the worst of the three.
//   dfg        ggx_height_correlated: exact N^2 tables read bilinearly (clamp-to-edge) against
//              dfg_exact at 257^2 off-grid points with n.v >= 0.1; the largest |dA|, |dB|.
// The errors do not depend on timing or threads: two runs of one build write the same header
// (another compiler may move a value at a rounding edge by 0.001). One sky is one sky: a scene lit
// otherwise may need other margins (docs/scene-format.md).
// Recorded, not measured by plan_measure (the writer carries them over from the header it
// replaces; edit them here, with their source):
//   prefilter_product_margin_*  product error per unit of a level's error: ibl-bake --scene
//                               --compare-full on the built-in sky (glossy_metals at targets
//                               0.05 - 0.2 and the full bake: 0.72 - 1.83; rough_plastics: 0.49)
//   plan_cost_ns_*              times per unit of an ibl-bake default run (release, 2 loaded
//                               cores, built-in sky): machine-dependent, only ratios are used

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <cstdint>

namespace ibl {

// ---- specular: filtered-IS error of one level (nrmse against the converged level) ---------------
/// Roughness rows and sample-count columns of the tables.
inline constexpr double prefilter_table_r[5] = {@R@};
inline constexpr std::uint32_t prefilter_table_n[7] = {@N@};
/// Nearest-level reads of the source.
inline constexpr double prefilter_error_nearest[5][7] = {@NEAREST@};
/// Trilinear reads of the source.
inline constexpr double prefilter_error_trilinear[5][7] = {@TRILINEAR@};
/// Recorded: product error per unit of a needed level's error (a level of roughness r must meet
/// target / margin(r)): levels r < 0.5 (sharp) and r >= 0.5 (rough; no credit taken for dilution).
inline constexpr double prefilter_product_margin_sharp = @SHARP@;
inline constexpr double prefilter_product_margin_rough = @ROUGH@;

// ---- DFG: largest bilinear error of an exact N^2 table (n.v >= 0.1) ------------------------------
inline constexpr int dfg_sizes[5] = {@DFGN@};
inline constexpr double dfg_interp_error[5] = {@DFGE@};

// ---- diffuse: worst RMS(E_SH - E) / RMS(E) of 2 and 3 shipped SH bands ---------------------------
inline constexpr double sh2_irradiance_error = @SH2@;
inline constexpr double sh3_irradiance_error = @SH3@;

// ---- recorded: the cost model's times per unit, in ns ---------------------------------------------
/// Source cube, per sub-sample
inline constexpr double plan_cost_ns_source_subsample = @NS_SOURCE@;
/// Prefilter / irradiance map, per bilinear tap
inline constexpr double plan_cost_ns_prefilter_tap = @NS_TAP@;
/// SH projection, per source texel
inline constexpr double plan_cost_ns_sh_texel = @NS_SH@;
/// DFG quadrature, per evaluation
inline constexpr double plan_cost_ns_dfg_evaluation = @NS_DFG@;

} // namespace ibl

#endif // IBL_DETAIL_CXX20
)";
    const std::pair<const char*, std::string> fields[] = {
        {"@STATUS@", "// This version: every table below written by one run of the command above."},
        {"@R@", list(t.prefilter_r)},
        {"@N@", list(t.prefilter_n)},
        {"@NEAREST@", rows(t.nearest)},
        {"@TRILINEAR@", rows(t.trilinear)},
        {"@SHARP@", recorded(ibl::prefilter_product_margin_sharp)},
        {"@ROUGH@", recorded(ibl::prefilter_product_margin_rough)},
        {"@DFGN@", list(t.dfg_sizes)},
        {"@DFGE@", list(t.dfg_error, true)},
        {"@SH2@", number(t.sh2)},
        {"@SH3@", number(t.sh3)},
        {"@NS_SOURCE@", recorded(ibl::plan_cost_ns_source_subsample)},
        {"@NS_TAP@", recorded(ibl::plan_cost_ns_prefilter_tap)},
        {"@NS_SH@", recorded(ibl::plan_cost_ns_sh_texel)},
        {"@NS_DFG@", recorded(ibl::plan_cost_ns_dfg_evaluation)}};
    for (const auto& [key, value] : fields) h.replace(h.find(key), std::string(key).size(), value);
    std::ofstream out(path, std::ios::binary);
    out << h;
    std::printf("wrote %s\n", path.c_str());
    return bool(out);
}

} // namespace

int main(int argc, char** argv) {
    std::vector<std::string> what;
    std::string header;
    bool check = false;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "--write-header" && i + 1 < argc) header = argv[++i];
        else if (a == "--check") check = true;
        else if (a == "dfg" || a == "sh" || a == "prefilter") what.push_back(a);
        else return std::fprintf(stderr, "usage: ibl_plan_measure [--check | --write-header PATH] [dfg] [sh] [prefilter]\n"), 2;
    }
    if (!header.empty()) what.clear(); // the header needs every table
    auto want = [&](const char* w) { return what.empty() || std::find(what.begin(), what.end(), w) != what.end(); };
    plan_tables t;
    if (want("dfg")) t.dfg_error = measure_dfg();
    if (want("sh")) {
        const std::array<double, 2> sh = measure_sh();
        t.sh2 = sh[0];
        t.sh3 = sh[1];
    }
    if (want("prefilter")) measure_prefilter(t);
    if (check) return check_tables(t, want("dfg"), want("sh"), want("prefilter")) ? 0 : 1;
    if (!header.empty()) return write_header(header, t) ? 0 : 1;
    return 0;
}
