#pragma once
// check_texels.hpp — the texels at which ibl-bake (report), ibl-bake --scene --compare-full and
// ibl_plan_measure compare a prefiltered level against its reference: a g x g grid per face
// (g = min(grid, n)) plus the 3 x 3 block around the brightest direction (the sun), each texel
// once. One definition, so the report, the scene check and the plan's measured tables agree.

#include <algorithm>
#include <array>
#include <vector>

#include <ibl/env/cube_geometry.hpp>

namespace ibl_bake {

/// (face, x, y) of the checked texels of an n x n face.
inline std::vector<std::array<int, 3>> check_texels(int n, int grid, const ibl::vec3<double>& light) {
    std::vector<std::array<int, 3>> t;
    const int g = std::min(grid, n);
    for (int f = 0; f < 6; ++f)
        for (int j = 0; j < g; ++j)
            for (int i = 0; i < g; ++i) t.push_back({f, int((i + 0.5) * n / g), int((j + 0.5) * n / g)});
    const ibl::cube_coord<double> c = ibl::cube_lookup(light);
    const int cx = std::min(int(c.s * n), n - 1), cy = std::min(int(c.t * n), n - 1);
    for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
            const std::array<int, 3> id{c.face, std::clamp(cx + dx, 0, n - 1), std::clamp(cy + dy, 0, n - 1)};
            if (std::find(t.begin(), t.end(), id) == t.end()) t.push_back(id);
        }
    return t;
}

} // namespace ibl_bake
