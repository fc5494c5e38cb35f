// research/fast_mid_tail_study.cpp — a candidate for the fast filter's first convolved level: its
// coarse tail read from an intermediate level instead of the next chain level. The table
// "An intermediate coarse tail" of docs/ibl-bake.md ("Fast filter").
//
//   build/release/research/fast_mid_tail_study [--texels N] [FILE.exr ...]   (default: the courtyard and
//                                                                             studio of tests/data, 400)
//   build/release/research/fast_mid_tail_study --quick                        (ctest: one file, 32 texels)
//
// Why. Level 1 of the fast default (r = 0.2, 64 samples) is the chain's dearest level and its
// largest error; its coarse tail (bake/prefilter_fast.hpp) reads level 2 (r = 0.4), whose kernel
// lies under level 1's for only 5.8 % of its mass. A level at r_mid between them takes a larger
// share of level 1's kernel (19 - 40 % at r_mid = 0.24 - 0.3), so level 1's own tap set covers a
// narrower rest kernel; the intermediate level has a quarter of level 1's texels (the face of
// level 2), so its taps cost a quarter.
//
// How. Each candidate is ibl::prefilter itself (method fast, every default: peak split, coarse
// tail, rough levels by spherical harmonics) with a level plan (prefilter_options::level_plan):
// levels 0 (mirror), 1 (r = 0.2, N samples), 2 (r_mid, M samples), then r = 0.4, 0.6, 0.8, 1 on
// levels 3 - 6. Level 1 then reads its tail from level 2 as the library does for any plan. The
// baseline is the default chain (levels 0 - 5 at r = l / 5, ibl-bake's plan for 128^2 and 256^2) at N samples. Only level 1 is compared:
// the relative RMSE of luminance at `texels` random texels against the exact LD of the source cube
// (ibl::ld_texel_sum at ibl::ld_texel_sum_level, ibl-bake's check), on 128^2 and 256^2 sources of
// each HDRI and of the built-in sky (its sun is taken out by the peak split). The cost column is
// level 1's taps per texel plus the intermediate level's per level-1 texel (M / 4), the reads of
// the coarse tail and the peaks left out (the same in every row). Filtered importance sampling's
// default (512 trilinear samples) is the row the fast default must stay at or below.
//
// The plan form is a measurement device, not the product: it also moves r = 0.4 .. 1 one face
// coarser and adds the peaks to the intermediate level, so its wall time is not the candidate's.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <span>
#include <string>
#include <vector>

#include <ibl/bake/prefilter.hpp>
#include <ibl/core/executor.hpp>
#include <ibl/env/analytic.hpp>
#include <ibl/env/convert.hpp>
#include <ibl/reference/ld_irradiance.hpp>

#include "ld_study.hpp"

namespace {

using ld_study::texel_ref;

struct candidate {
    std::uint32_t n = 64;     ///< level 1's samples
    double r_mid = -1.0;      ///< < 0: the default plan
    std::uint32_t m = 0;      ///< the intermediate level's samples
    bool fis = false;         ///< filtered importance sampling's default instead
};

/// The candidate's plan: the default chain (r = l / 5 on levels 0 - 5, the equal-cost schedule
/// from N) or the chain with the intermediate level.
std::vector<ibl::prefilter_level> plan_of(const candidate& c) {
    std::vector<ibl::prefilter_level> p;
    if (c.r_mid < 0.0) {
        for (int l = 0; l < 6; ++l) {
            ibl::prefilter_level lv;
            lv.level = l;
            lv.roughness = double(l) / 5.0;
            lv.samples = ibl::equal_cost_prefilter_samples(c.n, l);
            lv.trilinear = false;
            p.push_back(lv);
        }
        return p;
    }
    const double r[] = {0.0, 0.2, c.r_mid, 0.4, 0.6, 0.8, 1.0};
    for (int l = 0; l < 7; ++l) {
        ibl::prefilter_level lv;
        lv.level = l;
        lv.roughness = r[l];
        lv.samples = l == 1 ? c.n : l == 2 ? c.m : std::uint32_t(std::min<std::uint64_t>(16384, std::uint64_t(64) << (2 * (l - 2))));
        lv.trilinear = false;
        p.push_back(lv);
    }
    return p;
}

/// Level 1's relative RMSE for one candidate on one source.
double level1_error(const ibl::cubemap<float>& cube, const candidate& c, const std::vector<texel_ref>& refs, ibl::thread_executor& ex) {
    ibl::prefilter_options o;
    if (!c.fis) {
        o.method = ibl::prefilter_method::fast;
        o.level_plan = plan_of(c);
    } else {
        o.levels = 6; // r = l / 5, as the fast plans
    }
    const ibl::specular_chain ch = ibl::prefilter(cube, o, ex);
    return ld_study::rel_rmse(refs, [&](int f, int x, int y) { return ch.texel(f, x, y, 1); });
}

} // namespace

int main(int argc, char** argv) {
    const ld_study::args args = ld_study::parse(argc, argv);
    ibl::thread_executor ex{2};
    std::vector<candidate> cands;
    cands.push_back({512, -1.0, 0, true});
    for (const std::uint32_t n : {32u, 48u, 64u}) cands.push_back({n, -1.0, 0, false});
    for (const std::uint32_t n : {16u, 24u, 32u, 40u, 48u})
        for (const double rm : {0.22, 0.24, 0.26, 0.28})
            for (const std::uint32_t m : {32u, 64u, 128u}) {
                if (args.quick && (n != 32 || m != 64)) continue;
                cands.push_back({n, rm, m, false});
            }
    struct source {
        std::string name;
        ibl::cubemap<float> cube;
    };
    std::vector<std::string> columns;
    std::vector<std::vector<double>> err(cands.size());
    auto measure = [&](const std::string& name, const ibl::cubemap<float>& cube) {
        const int n1 = cube.size(0) / 2;
        const std::vector<texel_ref> refs = ld_study::level_refs(cube, ibl::ld_texel_sum_level(cube, 0.2), 1, n1, args.texels, 0.2,
                                                                 ibl::ld_weight::n_dot_l, ex);
        columns.push_back(name + " " + std::to_string(cube.size(0)) + "^2");
        for (std::size_t i = 0; i < cands.size(); ++i) {
            if (args.quick && cands[i].fis) {
                err[i].push_back(0.0);
                continue;
            }
            err[i].push_back(level1_error(cube, cands[i], refs, ex));
        }
    };
    const std::vector<int> sizes = args.quick ? std::vector<int>{64} : std::vector<int>{128, 256};
    for (const int size : sizes) {
        if (!args.quick) {
            const ibl::sky_environment<double> sky = ibl::make_default_sky<double>();
            measure("sky + sun", ibl::bake_cubemap<float>(sky, size, 4, ex));
        }
        for (const std::string& file : args.files) {
            const ibl::latlong<float> map = ld_study::load_latlong(file);
            measure(file.substr(file.find_last_of('/') + 1), ld_study::source_cube(map, size, ex));
        }
    }
    std::printf("Level 1 (r = 0.2) of the fast filter's chain, n.l weight, relative RMSE of luminance at %d texels against "
                "ibl::ld_texel_sum\n\n| level 1 | taps per level-1 texel |",
                args.texels);
    for (const std::string& c : columns) std::printf(" %s |", c.c_str());
    std::printf("\n|---|---|");
    for (std::size_t i = 0; i < columns.size(); ++i) std::printf("---|");
    std::printf("\n");
    int bad = 0;
    for (std::size_t i = 0; i < cands.size(); ++i) {
        const candidate& c = cands[i];
        if (c.fis) std::printf("| filtered importance sampling, default (512 trilinear) | 1024 |");
        else if (c.r_mid < 0.0) std::printf("| fast, %u samples, tail from r = 0.4%s | %u |", c.n, c.n == 64 ? " (the default)" : "", c.n);
        else std::printf("| fast, %u samples, tail from r_mid = %.2f (%u samples, face / 2) | %.0f |", c.n, c.r_mid, c.m, double(c.n) + double(c.m) / 4.0);
        for (const double e : err[i]) {
            std::printf(" %.4f |", e);
            bad += std::isfinite(e) ? 0 : 1;
        }
        std::printf("\n");
    }
    // --quick (ctest): every figure finite.
    return args.quick && bad ? 1 : 0;
}
