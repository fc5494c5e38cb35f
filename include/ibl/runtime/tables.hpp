#pragma once
// ibl/runtime/tables.hpp — the tables a renderer reads, indexed by (n.v, roughness): the DFG table,
// the lobe LUT, the fitted-taps table and the two-part lobe tables. Each records the conventions it
// was built in (`layout`, and for the lobe tables the chain's LD `weight`), and the lookups of
// runtime/lookup.hpp and runtime/specular_models.hpp read them from the table. The builders are in
// bake/ (bake/dfg_lut.hpp, bake/lobe_fit.hpp); a renderer that loads a table
// from a file fills these structs and needs none of them.
//
// Layout of data (float32, interleaved channels, row-major): data[(j * size + i) * channels + c],
// row j one roughness, row 0 first in memory; which (n.v, r) texel (i, j) holds is `layout`
// (runtime/dfg_layout.hpp).

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "../core/vec.hpp"
#include "dfg_layout.hpp"
#include "ld_weight.hpp"

namespace ibl {

struct dfg_lut {
    std::uint32_t size = 0;     ///< texels per side
    std::uint32_t channels = 0; ///< 2 (A, B) or 3 (A, B, k)
    std::vector<float> data;    ///< (j * size + i) * channels + c
    dfg_lut_layout layout{};    ///< which (n.v, r) each texel holds (default: the textbook table)
    std::string model = "custom"; ///< the BRDF model integrated (Model::name)

    /// n.v at the centre of column i.
    double n_dot_v(std::uint32_t i) const noexcept {
        return dfg_texel_value<double>(layout.n_dot_v, i, size, layout.edge_aligned);
    }
    /// Roughness at the centre of row j.
    double roughness(std::uint32_t j) const noexcept {
        return dfg_texel_value<double>(layout.roughness, j, size, layout.edge_aligned);
    }
    /// Texel value. Precondition (noexcept, IBL_ASSERT in debug builds): i, j < size, c < channels,
    /// data holds size^2 channels floats.
    float at(std::uint32_t i, std::uint32_t j, std::uint32_t c) const noexcept {
        IBL_ASSERT(i < size && j < size && c < channels);
        return data[(std::size_t(j) * size + i) * channels + c];
    }
    /// True when data holds size^2 * channels floats of a non-empty table (what sample() needs).
    bool valid() const noexcept {
        return size > 0 && channels > 0 && data.size() == std::size_t(size) * size * channels;
    }
    /// Bilinear lookup at (n.v, r) in the table's layout with clamp-to-edge, as a GPU sampler does
    /// (channel 2 is 0 for a two-channel table; the same read as runtime/lookup.hpp's dfg_lookup). A table
    /// that is not valid() (empty, or data of the wrong length) samples as 0 instead of reading out
    /// of bounds.
    vec3<float> sample(float n_dot_v, float rough) const noexcept {
        if (!valid()) return vec3<float>(0.0f);
        const vec2<float> st = dfg_lut_coord(n_dot_v, rough, size, layout);
        return dfg_sample_st(*this, st.x, st.y);
    }
};

/// A four-channel table (A, B, s, r_eff) in a DFG layout (runtime/lookup.hpp): texel (i, j) at
/// n.v = dfg_texel_value(layout.n_dot_v, i), r = dfg_texel_value(layout.roughness, j).
struct lobe_lut {
    std::uint32_t size = 0;
    std::uint32_t channels = 4;
    std::vector<float> data; ///< (j * size + i) * 4 + c
    ld_weight weight = ld_weight::n_dot_l; ///< the chain kernel r_eff was matched to
    dfg_lut_layout layout{};               ///< which (n.v, r) each texel holds (read by the lookups)
};

/// A table of fitted mixtures in a DFG layout (runtime/lookup.hpp): texel (i, j) at
/// n.v = dfg_texel_value(layout.n_dot_v, i), r = dfg_texel_value(layout.roughness, j); channels
/// 2 + 3 taps: A, B (make_dfg_lut_exact), then per tap (ascending angle) the angle from n towards
/// R over the view angle acos(n.v) (1 = at R, 0 = at n; runtime/specular_models.hpp's lobe_tap_angle), the
/// roughness (or lod over levels - 1 for a fit of stored levels) and the weight. Relative angles
/// interpolate between texels where absolute ones cannot: a narrow lobe sits at R, whose angle
/// changes fast near n.v = 1 (a bilinear read of absolute angles missed it by 6 degrees there).
/// The mirror row r = 0 holds one tap at R (1) of roughness 0.
struct lobe_taps_lut {
    std::uint32_t size = 0;
    std::uint32_t channels = 0;
    int taps = 0;
    std::vector<float> data; ///< (j * size + i) * channels + c
    ld_weight weight = ld_weight::n_dot_l;
    dfg_lut_layout layout{};             ///< which (n.v, r) each texel holds (read by the lookups)
    std::vector<double> level_roughness; ///< empty: taps hold roughness
    double max_l1 = 0.0, mean_l1 = 0.0; ///< of the fits at the texels with r >= 0.05 and A + B > 0
};

/// The two-part lobe model's tables (ibl::specular_lobe_pair, runtime/specular_models.hpp). The specular lobe
/// with Schlick's Fresnel is F0 times its A part (weight 1 - (1 - v.h)^5) plus F90 times its B
/// part (weight (1 - v.h)^5). The B part has another shape and direction (it leans beyond R
/// towards grazing reflection: at n.v = 0.9, r = 0.5 its fitted kernel sits 2.7 view angles from
/// n, and the whole lobe's kernel is at L1 distance 1.5 of it, 2 being disjoint), and a
/// dielectric's specular is mostly B; the A part is the whole lobe but for a small grazing
/// share (the whole lobe's kernel is within 0.013 in L1 of the A part's own fit).
///   a: (A, B, s, r_eff)  make_lobe_lut_fitted's table (the whole lobe's kernel, read for the A
///                        part; the same file a one-kernel consumer reads);
///   b: (f_B, r_B, 0, 0)  the B part's kernel (o.part = b): its angle from n towards R over the
///                        view angle acos(n.v) (as the fitted taps' angles: runtime/specular_models.hpp
///                        lobe_tap_angle; the B kernel may lie beyond R, which no lerp factor in
///                        [0, 1] reaches) and its chain roughness. The mirror row: at R, 0.
/// Both in the same DFG layout and size; o.taps is ignored (1), o.part is set per table.
struct lobe_pair_lut {
    lobe_lut a, b;
};

} // namespace ibl

#endif // IBL_DETAIL_CXX20
