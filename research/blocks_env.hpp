#pragma once
// research/blocks_env.hpp — a synthetic source with hard edges, shared by the intermediate coarse
// tail's study (fast_mid_tail_study) and its unit test (tests/test_prefilter_fast.cpp): a sky of
// 30 with blocks of 60 over a ground of 0.5 with stripes of 2, the pattern in units of 1/64 of a
// face (the same angular pattern at every size), with its mip chain.

#include <algorithm>

#include <ibl/env/cube_geometry.hpp>
#include <ibl/env/cubemap.hpp>

namespace study {

inline ibl::cubemap<float> blocks_env(int n) {
    const int sc = std::max(1, n / 64);
    ibl::cubemap<float> src(n);
    src.fill(0, [&](int f, int x, int y) {
        const ibl::vec3<float> d = ibl::cube_texel_direction<float>(f, x, y, n);
        const int X = x / sc, Y = y / sc;
        const bool stripe = ((X / 3 + Y / 2) % 3 == 0), cloud = ((X / 5 + 2 * (Y / 4)) % 4 == 0);
        return ibl::vec3<float>(d.y > 0.f ? (cloud ? 60.f : 30.f) : (stripe ? 2.f : 0.5f));
    });
    src.generate_mips();
    return src;
}

} // namespace study
