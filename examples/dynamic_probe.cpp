// examples/dynamic_probe.cpp — a probe re-filtered at run time, a bounded amount of work per frame:
// a sky whose sun moves with the time of day is baked to a source cube, and prefilter_update
// filters it with the fast filter (bake/prefilter_fast.hpp) over several frames, a budget of taps
// per frame, while the renderer keeps reading the last finished chain. When a pass finishes, the
// next time of day's cube is moved in (set_source(std::move(...)): no copy). Checks, each printed
// (exit status 1 and "FAILED" if one is off): no frame spends more than max(budget, the dearest
// work unit); every finished chain equals the one-shot prefilter of its source bit for bit; the
// renderer reads a complete chain in every frame after the first pass. The time of each call is
// printed, not checked (bench/bench_prefilter.cpp, BM_prefilter_update_step, measures it).
#include <ibl/bake.hpp> // prefilter, prefilter_update
#include <ibl/env.hpp>  // the analytic sky, the cube bake

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <utility>

static int failures = 0;
static void check(const char* what, bool ok) {
    std::printf("  %-66s %s\n", what, ok ? "ok" : "FAILED");
    failures += ok ? 0 : 1;
}

// The source cube at a time of day (hours): the built-in sky with its sun on an east-west arc.
static ibl::cubemap<float> sky_at(double hours) {
    auto sky = ibl::make_default_sky<float>();
    const double a = (hours - 6.0) / 12.0 * 3.14159265358979; // 0 at sunrise, pi at sunset
    sky.set_sun(ibl::vec3<float>(float(std::cos(a)), float(std::max(0.05, std::sin(a))), 0.3f), sky.sun_radiance,
                sky.sun_angular_radius);
    return ibl::bake_cubemap<float>(sky, 64, 2);
}

static bool same_bits(const ibl::cubemap<float>& a, const ibl::cubemap<float>& b) {
    if (a.levels() != b.levels()) return false;
    for (int l = 0; l < a.levels(); ++l)
        for (int f = 0; f < 6; ++f)
            for (int y = 0; y < a.size(l); ++y)
                for (int x = 0; x < a.size(l); ++x)
                    if (std::memcmp(&a.texel(f, x, y, l), &b.texel(f, x, y, l), sizeof(ibl::vec3<float>)) != 0) return false;
    return true;
}

int main() {
    ibl::prefilter_options opt;
    opt.method = ibl::prefilter_method::fast; // the real-time filter: 64 x 4^(l-1) samples, peak split, coarse tail
    ibl::cubemap<float> source = sky_at(8.0);
    ibl::prefilter_update<> probe(source, opt); // a copy: `source` is kept for the check below

    // A frame's budget: a twentieth of a pass, so a pass spans about 20 frames.
    const std::uint64_t budget = probe.total_taps() / 20;
    std::uint64_t dearest_unit = probe.setup_unit_taps();
    for (std::size_t k = 0; k < probe.plan().size(); ++k) dearest_unit = std::max(dearest_unit, probe.unit_taps(k));
    std::printf("fast filter, %d^2 source, %zu levels: %llu taps a pass, budget %llu taps a frame\n", source.size(0),
                probe.plan().size(), (unsigned long long)probe.total_taps(), (unsigned long long)budget);

    bool within_budget = true, identical = true, readable = true;
    double slowest_ms = 0.0, total_ms = 0.0;
    int frames = 0;
    for (int pass = 0; pass < 3; ++pass) {
        int pass_frames = 0;
        while (!probe.done()) {
            const auto t0 = std::chrono::steady_clock::now();
            const std::uint64_t spent = probe.step(budget); // this frame's share of the filtering
            const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
            slowest_ms = std::max(slowest_ms, ms);
            total_ms += ms;
            within_budget = within_budget && spent <= std::max(budget, dearest_unit);
            // ... render with probe.result() (the last finished chain) ...
            if (pass > 0) readable = readable && probe.result().has_value();
            ++pass_frames;
            ++frames;
        }
        identical = identical && same_bits(*probe.result(), ibl::prefilter(source, opt, ibl::serial_executor{}));
        std::printf("  pass %d (%.0f h): %d frames\n", pass, 8.0 + 2.0 * pass, pass_frames);
        source = sky_at(10.0 + 2.0 * pass);     // the next time of day
        probe.set_source(ibl::cubemap<float>(source)); // moved in (the example keeps `source` to check)
    }
    std::printf("  a call: %.3f ms on average, %.3f ms at most (one thread; not checked)\n", total_ms / frames, slowest_ms);
    check("every frame within max(budget, the dearest work unit)", within_budget);
    check("every finished chain equals the one-shot prefilter, bit for bit", identical);
    check("after the first pass every frame reads a finished chain", readable);
    return failures == 0 ? 0 : 1;
}
