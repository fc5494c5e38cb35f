// research/fast_mid_tail_study.cpp — the fast filter's intermediate coarse tail
// (prefilter_options::mid_tail, bake/prefilter_fast.hpp "Intermediate coarse tail") against the
// coarse tail read from the next level: the table "Intermediate coarse tail" of docs/ibl-bake.md
// ("Fast filter").
//
//   build/release/research/fast_mid_tail_study [--texels N] [FILE.exr ...]   (default: the courtyard and
//                                                                             studio of tests/data, 400)
//   build/release/research/fast_mid_tail_study --quick                        (ctest: one file, 32 texels)
//
// What it measures. ibl::prefilter itself (method fast, every other default: peak split, coarse
// tails, rough levels by spherical harmonics) on 128^2 and 256^2 sources of the built-in sky, a
// synthetic sky of blocks over a striped ground (hard edges at 1/64 of a face: the unit test's
// source) and each HDRI, to the 6-level chain (r = l / 5). Per setting of mid_tail: level 1's
// relative RMSE of luminance at `texels` random texels against the exact LD of the source
// (ibl::ld_texel_sum at ibl::ld_texel_sum_level, ibl-bake's check), and the whole chain's time
// (median of 5 calls, 2 threads). The cost column is level 1's taps per texel: own samples plus
// the intermediate level's a quarter (its face is half the level's). At 128^2 the default rule
// (min_texels = 3) leaves the intermediate level out; there every setting sets min_texels = 0 to
// show what it would do.

#include <algorithm>
#include <chrono>
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

#include "blocks_env.hpp"
#include "ld_study.hpp"

namespace {

using ld_study::texel_ref;

struct setting {
    bool on = true;
    double position = 0.1, own = 0.375, mid = 1.0;
    [[nodiscard]] std::string name() const {
        if (!on) return "off: the tail from the next level (64 samples)";
        char b[160];
        std::snprintf(b, sizeof b, "position %.2f, own %.3g (%d samples), mid %.3g (%d)%s", position, own, int(std::lround(64 * own)),
                      mid, int(std::lround(64 * mid)), position == 0.1 && own == 0.375 && mid == 1.0 ? " (the default)" : "");
        return b;
    }
    [[nodiscard]] double taps() const { return on ? 64.0 * own + 16.0 * mid : 64.0; }
};

} // namespace

int main(int argc, char** argv) {
    const ld_study::args args = ld_study::parse(argc, argv);
    ibl::thread_executor ex{2};
    std::vector<setting> settings;
    settings.push_back({false});
    for (const double pos : {0.05, 0.1, 0.2})
        for (const double mid : {1.0, 1.5, 2.0}) {
            if (args.quick && (pos != 0.1 || mid != 1.0)) continue;
            settings.push_back({true, pos, 0.375, mid});
        }
    if (!args.quick)
        for (const double own : {0.25, 0.5}) settings.push_back({true, 0.1, own, 1.0});
    struct column {
        std::string name;
        std::vector<double> err, ms;
    };
    std::vector<column> cols;
    const int reps = args.quick ? 1 : 5;
    auto measure = [&](const std::string& name, const ibl::cubemap<float>& cube) {
        const int n = cube.size(0);
        const std::vector<texel_ref> refs =
            ld_study::level_refs(cube, ibl::ld_texel_sum_level(cube, 0.2), 1, n / 2, args.texels, 0.2, ibl::ld_weight::n_dot_l, ex);
        column c;
        c.name = name + " " + std::to_string(n) + "^2";
        for (const setting& s : settings) {
            ibl::prefilter_options o;
            o.method = ibl::prefilter_method::fast;
            o.levels = 6;
            o.mid_tail.enabled = s.on;
            o.mid_tail.position = s.position;
            o.mid_tail.own = s.own;
            o.mid_tail.mid = s.mid;
            if (n < 256) o.mid_tail.min_texels = 0.0; // forced where the rule leaves it out
            std::vector<double> t;
            ibl::specular_chain ch = ibl::prefilter(cube, o, ex);
            for (int i = 0; i < reps; ++i) {
                const auto t0 = std::chrono::steady_clock::now();
                ch = ibl::prefilter(cube, o, ex);
                t.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
            }
            std::sort(t.begin(), t.end());
            c.ms.push_back(t[t.size() / 2]);
            c.err.push_back(ld_study::rel_rmse(refs, [&](int f, int x, int y) { return ch.texel(f, x, y, 1); }));
        }
        cols.push_back(std::move(c));
    };
    const std::vector<int> sizes = args.quick ? std::vector<int>{64} : std::vector<int>{128, 256};
    for (const int size : sizes) {
        if (!args.quick) {
            measure("sky + sun", ibl::bake_cubemap<float>(ibl::make_default_sky<double>(), size, 4, ex));
            measure("blocks", study::blocks_env(size));
        }
        for (const std::string& file : args.files) {
            const ibl::latlong<float> map = ld_study::load_latlong(file);
            measure(file.substr(file.find_last_of('/') + 1), ld_study::source_cube(map, size, ex));
        }
    }
    std::printf("Level 1 (r = 0.2) of the fast filter's 6-level chain, n.l weight: relative RMSE of luminance at %d texels "
                "against ibl::ld_texel_sum / the chain's time (ms, median of %d, 2 threads). At 128^2 every setting is forced "
                "(min_texels = 0: the default leaves the intermediate level out there).\n\n| mid_tail | level 1 taps per texel |",
                args.texels, reps);
    for (const column& c : cols) std::printf(" %s |", c.name.c_str());
    std::printf("\n|---|---|");
    for (std::size_t i = 0; i < cols.size(); ++i) std::printf("---|");
    std::printf("\n");
    int bad = 0;
    for (std::size_t s = 0; s < settings.size(); ++s) {
        std::printf("| %s | %.0f |", settings[s].name().c_str(), settings[s].taps());
        for (const column& c : cols) {
            std::printf(" %.4f / %.1f |", c.err[s], c.ms[s]);
            bad += std::isfinite(c.err[s]) ? 0 : 1;
        }
        std::printf("\n");
    }
    // --quick (ctest): every figure finite.
    return args.quick && bad ? 1 : 0;
}
