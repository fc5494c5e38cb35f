#pragma once
// research/ld_study.hpp — what the prefilter studies against the exact LD (fast_tap_study,
// sh_rough_study) share: their command line, the 256^2 source cube of an HDRI, and the random
// texels of each chain level with their relative RMSE of luminance.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <span>
#include <string>
#include <vector>

#include <ibl/core/executor.hpp>
#include <ibl/env/convert.hpp>
#include <ibl/env/latlong.hpp>
#include <ibl/reference/ld_irradiance.hpp>

#include "io/image_io.hpp"
#include "study_envs.hpp"

namespace ld_study {

using dvec3 = ibl::vec3<double>;

inline double lum(const dvec3& c) { return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z; }

/// [--texels N] [--quick] [FILE.exr ...]: default the courtyard and studio of tests/data, 400
/// texels a level; --quick (the ctests) one file, 32 texels.
struct args {
    int texels = 400;
    bool quick = false;
    std::vector<std::string> files;
};
inline args parse(int argc, char** argv) {
    args a;
    for (int i = 1; i < argc; ++i) {
        const std::string s = argv[i];
        if (s == "--texels" && i + 1 < argc) a.texels = std::max(16, std::atoi(argv[++i]));
        else if (s == "--quick") a.quick = true;
        else a.files.push_back(s);
    }
    if (a.files.empty()) a.files = {std::string(IBL_RESEARCH_DATA_DIR) + "/courtyard.exr", std::string(IBL_RESEARCH_DATA_DIR) + "/studio.exr"};
    if (a.quick) a.files.resize(1), a.texels = 32;
    return a;
}

/// The chain both studies filter: a 256^2 source to 6 levels at r = l / 5 (ibl-bake's automatic plan).
inline constexpr int chain_levels = 6;
inline constexpr int base_size = 256;
inline double level_r(int l) { return double(l) / double(chain_levels - 1); }

/// A lat-long HDRI with its borders.
inline ibl::latlong<float> load_latlong(const std::string& file) {
    const ibl_bake::image_rgb32f img = ibl_bake::read_latlong(file, {});
    ibl::latlong<float> map(img.width, img.height, std::span<const float>(img.rgb), 1);
    map.update_borders();
    return map;
}
/// Its source cube: face `size`, supersampled k = max(2, width / (4 size)).
inline ibl::cubemap<float> source_cube(const ibl::latlong<float>& map, int size, ibl::thread_executor& ex) {
    const int k = std::max(2, int(std::ceil(double(map.width()) / (4.0 * size))));
    return ibl::bake_cubemap<float>(map, size, k, ex, 0);
}

/// A texel of a chain level, its centre direction and its reference LD.
struct texel_ref {
    int f = 0, x = 0, y = 0;
    dvec3 dir{0.0}, ref{0.0};
};
/// `count` random texels of level l (face n), the same for every study and run.
inline std::vector<texel_ref> level_texels(int l, int n, int count) {
    std::vector<texel_ref> r(std::size_t(std::max(count, 0)));
    for (std::size_t i = 0; i < r.size(); ++i) {
        texel_ref& t = r[i];
        t.f = int(study::unit(std::uint32_t(i), std::uint32_t(1 + 7 * l)) * 6);
        t.x = int(study::unit(std::uint32_t(i), std::uint32_t(2 + 7 * l)) * n);
        t.y = int(study::unit(std::uint32_t(i), std::uint32_t(3 + 7 * l)) * n);
        t.dir = ibl::cube_texel_direction<double>(t.f, t.x, t.y, n);
    }
    return r;
}
/// Their centre directions.
inline std::vector<dvec3> directions(const std::vector<texel_ref>& refs) {
    std::vector<dvec3> d;
    for (const texel_ref& t : refs) d.push_back(t.dir);
    return d;
}
/// `count` random texels of level l (face n) with their reference: the exact LD of `cube` at
/// roughness r and weight w, ibl::ld_texel_sum over the cube's level `sum_level` (0: every texel
/// of level 0; ibl::ld_texel_sum_level: the coarser level ibl-bake's check sums).
inline std::vector<texel_ref> level_refs(const ibl::cubemap<float>& cube, int sum_level, int l, int n, int count, double r,
                                         ibl::ld_weight w, ibl::thread_executor& ex) {
    std::vector<texel_ref> refs = level_texels(l, n, count);
    const std::vector<dvec3> dirs = directions(refs);
    const std::vector<dvec3> ld = ibl::ld_texel_sum(cube, sum_level, std::span<const dvec3>(dirs), r, w, ex);
    for (std::size_t i = 0; i < refs.size(); ++i) refs[i].ref = ld[i];
    return refs;
}

/// Relative RMSE of luminance of texel(f, x, y) against the references.
template <class TexelFn> double rel_rmse(const std::vector<texel_ref>& refs, TexelFn&& texel) {
    double s = 0.0;
    for (const texel_ref& t : refs) {
        const double a = lum(dvec3(texel(t.f, t.x, t.y))), b = lum(t.ref);
        s += (a - b) * (a - b) / (b * b);
    }
    return std::sqrt(s / double(refs.size()));
}

} // namespace ld_study
