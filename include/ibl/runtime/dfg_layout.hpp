#pragma once
// ibl/runtime/dfg_layout.hpp — how a table indexed by (n.v, roughness) lays out its texels (the
// DFG table, the lobe LUT, the fitted-taps table), and the one bilinear read of such a table.
// Every table struct records its layout (member `layout`); the lookups read it from the table,
// so a table cannot be read in another layout than the one it was built in.
//
// A table of N x N texels (row j, column i, channels interleaved: data[(j N + i) channels + c])
// whose texel (i, j) holds the value at n.v = x(c_i), roughness = y(c_j), where c_i is the axis
// coordinate of texel i's centre and x, y are the axis maps of a dfg_lut_layout:
//   centres    sampler       c_i = (i + 0.5) / N (a GPU sampler's centres, s = c: the half texel
//                                                at each end is clamped to the edge texel)
//              edge aligned  c_i = i / (N - 1)   (first and last centres on 0 and 1: nothing is
//                                                clamped; the shader remaps s = (c (N-1) + 0.5)/N)
//   axis map   dfg_axis::linear  value = c       (the textbook table: n.v, r)
//              dfg_axis::sqrt    value = c^2     (c = sqrt(value): texels crowd near 0)
//              dfg_axis::cbrt    value = c^3     (c = cbrt(value): more so)
// The default layout is the textbook one (linear axes, sampler centres: texture(lut, vec2(n.v, r))
// reads it). dfg_lut_layout::remapped() (cbrt n.v, sqrt r, edge aligned) is the accurate one: at
// low roughness the DFG terms change over a range of n.v ~ alpha = r^2 next to grazing (the
// masking of a nearly smooth surface), and over a range of r ~ sqrt(n.v) there; a uniform axis
// puts under one texel of n.v in that range at r = 0.05 on a 128 table (docs/lookup.md).
// A shader samples a table with clamp-to-edge and bilinear filtering at
// (s, t) = dfg_lut_coord(n.v, r, N, layout).
//
// Value functions are IBL_FUNC (GLSL mirror: glsl/ibl_lookup.glsl); the table reads are host code.

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "../core/math.hpp"
#include "../core/vec.hpp"

namespace ibl {

enum class dfg_axis : int {
    linear = 0, ///< texel coordinate = value
    sqrt = 1,   ///< texel coordinate = sqrt(value)
    cbrt = 2,   ///< texel coordinate = cbrt(value)
};

/// Parameterisation of a table indexed by (n.v, roughness) (see the header). The default is the
/// textbook table, uniform(): texel centres (i + 0.5) / N in n.v and r, read by
/// texture(lut, vec2(n.v, r)). remapped() is the more accurate layout of docs/lookup.md.
struct dfg_lut_layout {
    dfg_axis n_dot_v = dfg_axis::linear;
    dfg_axis roughness = dfg_axis::linear;
    /// true: the first and last texel centres sit on axis coordinates 0 and 1 (c_i = i / (N - 1));
    /// false: a sampler's centres c_i = (i + 0.5) / N, with the half texel at each end clamped.
    bool edge_aligned = false;

    /// The textbook table (the default): linear axes, sampler centres.
    static constexpr dfg_lut_layout uniform() noexcept { return {dfg_axis::linear, dfg_axis::linear, false}; }
    /// The accurate table: cbrt(n.v) x sqrt(r), edge aligned (bilinear lookup error 2.8e-4 at
    /// 128^2 against 8.5e-2 for uniform(), docs/lookup.md).
    static constexpr dfg_lut_layout remapped() noexcept { return {dfg_axis::cbrt, dfg_axis::sqrt, true}; }

    friend constexpr bool operator==(const dfg_lut_layout&, const dfg_lut_layout&) noexcept = default;

    /// "uniform", "remapped", or "n.v <axis>, r <axis>, <centres>" for any other layout: the name
    /// files record (ibl-bake's EXR attributes, KTX2 keys and report.json) and parse_dfg_lut_layout reads.
    std::string name() const {
        if (*this == uniform()) return "uniform";
        if (*this == remapped()) return "remapped";
        auto axis = [](dfg_axis a) { return a == dfg_axis::cbrt ? "cbrt" : (a == dfg_axis::sqrt ? "sqrt" : "linear"); };
        return std::string("n.v ") + axis(n_dot_v) + ", r " + axis(roughness) + (edge_aligned ? ", edge-aligned" : ", sampler centres");
    }
};

/// The layout a name of dfg_lut_layout::name() stands for. Throws std::invalid_argument for any
/// other text (a reader never guesses a table's layout).
inline dfg_lut_layout parse_dfg_lut_layout(const std::string& name) {
    if (name == "uniform") return dfg_lut_layout::uniform();
    if (name == "remapped") return dfg_lut_layout::remapped();
    for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b)
            for (int e = 0; e < 2; ++e) {
                const dfg_lut_layout l{dfg_axis(a), dfg_axis(b), e == 1};
                if (l.name() == name) return l;
            }
    throw std::invalid_argument("ibl::parse_dfg_lut_layout: unknown DFG table layout '" + name + "'");
}

/// A table read with a layout other than its own is refused: every lookup of a table checks the
/// layout it is asked for against the one the table records. Throws std::invalid_argument naming
/// both.
inline void check_table_layout(const char* fn, const dfg_lut_layout& table, const dfg_lut_layout& asked) {
    if (!(table == asked))
        throw std::invalid_argument(std::string("ibl::") + fn + ": the table was built in the " + table.name() +
                                    " layout, read as " + asked.name());
}

/// The axis coordinate in [0, 1] of a value in [0, 1] (clamped, NaN -> 0).
template <class T> IBL_FUNC T dfg_axis_coord(dfg_axis a, T value) noexcept {
    using std::cbrt;
    using std::sqrt;
    const T v = saturate(value);
    return a == dfg_axis::sqrt ? sqrt(v) : (a == dfg_axis::cbrt ? cbrt(v) : v);
}

/// The value at axis coordinate c (the inverse of dfg_axis_coord).
template <class T> IBL_FUNC T dfg_axis_value(dfg_axis a, T coord) noexcept {
    const T c = saturate(coord);
    return a == dfg_axis::sqrt ? c * c : (a == dfg_axis::cbrt ? c * c * c : c);
}

/// The axis coordinate of the centre of texel i of an axis of `size` texels: i / (size - 1) when
/// edge aligned (0.5 for a single texel), (i + 0.5) / size otherwise.
template <class T> IBL_FUNC T dfg_texel_coord(std::uint32_t i, std::uint32_t size, bool edge_aligned) noexcept {
    if (edge_aligned) return size > 1 ? T(i) / T(size - 1) : T(0.5);
    return (T(i) + T(0.5)) / T(size);
}

/// The value held by texel i of an axis of `size` texels.
template <class T>
IBL_FUNC T dfg_texel_value(dfg_axis a, std::uint32_t i, std::uint32_t size, bool edge_aligned) noexcept {
    return dfg_axis_value(a, dfg_texel_coord<T>(i, size, edge_aligned));
}

/// The sampler coordinate (GPU convention: texel i's centre at (i + 0.5) / size) of axis
/// coordinate c: c itself, or c (size - 1) / size + 0.5 / size when edge aligned.
template <class T> IBL_FUNC T dfg_sampler_coord(T c, std::uint32_t size, bool edge_aligned) noexcept {
    if (!edge_aligned || size == 0) return c;
    return (c * T(size - 1) + T(0.5)) / T(size);
}

/// Sampler coordinates (s, t) of (n.v, r) in a table of `size` texels per side and the layout:
/// what a shader passes to texture(lut, st) with clamp-to-edge and bilinear filtering.
template <class T>
IBL_FUNC vec2<T> dfg_lut_coord(T n_dot_v, T roughness, std::uint32_t size, const dfg_lut_layout& layout = {}) noexcept {
    return {dfg_sampler_coord(dfg_axis_coord(layout.n_dot_v, n_dot_v), size, layout.edge_aligned),
            dfg_sampler_coord(dfg_axis_coord(layout.roughness, roughness), size, layout.edge_aligned)};
}

namespace detail {
/// Bilinear read with clamp-to-edge at sampler coordinates (s, t) of a table with members size,
/// channels and data (row-major, interleaved): channels 0 .. min(channels, count) - 1 into out
/// (the others untouched). The one texel filter of every LUT lookup (DFG, sheen, lobe tables).
template <class Table> void table_bilinear(const Table& lut, float s, float t, float* out, std::uint32_t count) {
    const std::uint32_t n = lut.size;
    if (n == 0) return;
    const float fx = clamp(s * float(n) - 0.5f, 0.0f, float(n - 1));
    const float fy = clamp(t * float(n) - 0.5f, 0.0f, float(n - 1));
    const auto i0 = std::uint32_t(fx), j0 = std::uint32_t(fy);
    const std::uint32_t i1 = i0 + 1 < n ? i0 + 1 : i0, j1 = j0 + 1 < n ? j0 + 1 : j0;
    const float tx = fx - float(i0), ty = fy - float(j0);
    const std::uint32_t ch = lut.channels;
    auto at = [&](std::uint32_t i, std::uint32_t j, std::uint32_t c) {
        return float(lut.data[(std::size_t(j) * n + i) * ch + c]);
    };
    for (std::uint32_t c = 0; c < ch && c < count; ++c) {
        const float top = lerp(at(i0, j0, c), at(i1, j0, c), tx);
        const float bottom = lerp(at(i0, j1, c), at(i1, j1, c), tx);
        out[c] = lerp(top, bottom, ty);
    }
}
} // namespace detail

/// Bilinear lookup with clamp-to-edge at sampler coordinates (s, t) of a table with members
/// size, channels and data (dfg_lut): channels 0..2 (channel 2 is 0 for a two-channel table).
template <class Table> vec3<float> dfg_sample_st(const Table& lut, float s, float t) {
    float v[3] = {0.0f, 0.0f, 0.0f};
    detail::table_bilinear(lut, s, t, v, 3);
    return vec3<float>(v[0], v[1], v[2]);
}

} // namespace ibl

#endif // IBL_DETAIL_CXX20
