#pragma once
// ibl/runtime/lookup.hpp — the runtime lookups of the baked products, as a renderer performs them: the
// prefiltered specular chain at any roughness, the DFG table at any (n.v, roughness). Shader code
// mirrors these functions; reference/lookup_error.hpp measures them against the exact LD and DFG
// (docs/lookup.md has the measurements and the derivation of the defaults).
//
// ---- Specular: which levels, which weights ---------------------------------------------------
// A chain of L levels (m = L - 1) holds at level l the roughness r_l = roughness_from_lod(mapping,
// l, m) (runtime/roughness_mip.hpp: the bake's policy). A lookup at roughness r finds the
// bracketing levels l <= lod(r) < l + 1 (lod(r) = lod_from_roughness(mapping, r, m), l clamped to
// [0, m - 1]) and a fraction t in [0, 1] by one of
//   level_weight::lod     t = lod(r) - l                     (the textbook lookup: textureLod at
//                                                            lod(r); for the linear mapping t is
//                                                            linear in r)
//   level_weight::power   t = (r^p - r_l^p) / (r_{l+1}^p - r_l^p),  p = weight_exponent
//                         (linear in r^p between the two levels' roughness; p = 1 with the linear
//                         mapping is the textbook lookup). Why a power: away from a bright source
//                         the GGX lobe's tail is D ~ alpha^2 / tan^4(theta), linear in alpha^2 =
//                         r^4, while near it the peak ~ 1 / alpha^2 falls steeply; a blend that is
//                         linear in r overweights the sharper level everywhere in between. The
//                         exponent that minimises the blend error is measured (docs/lookup.md).
//   level_weight::log     t = log(r / r_l) / log(r_{l+1} / r_l)  (the lod fraction below level 1,
//                         where r_0 = 0)
// and then interpolates across levels by
//   level_interpolation::linear       (1 - t) L_l + t L_{l+1}: two bilinear taps, i.e. ONE
//                                     trilinear textureLod(chain, R, l + t) on a GPU;
//   level_interpolation::catmull_rom  the uniform Catmull-Rom cubic in the level index through
//                                     L_{l-1}, L_l, L_{l+1}, L_{l+2} (indices clamped to [0, m]):
//                                     four bilinear taps (textureLod at the four integer lods).
//                                     Its weights can be negative: the result is clamped to >= 0
//                                     per channel.
//   level_interpolation::geometric    L_l^(1 - t) L_{l+1}^t per channel (linear where either is
//                                     <= 0): two taps at integer lods. With level_weight::log it
//                                     is exact where LD is a power law in r (specular_lookup_desc::accurate()).
// Both reproduce a level exactly at its own roughness (t = 0 gives weight 1 on level l, 0 on the
// others; the interpolation is written so that the weights are exactly 1 and 0 there), and both
// reproduce a constant environment exactly (the weights sum to 1).
//
// ---- DFG ----------------------------------------------------------------------------------------
// The table's layout (runtime/dfg_layout.hpp) is part of the table: dfg_lookup reads it from the
// table (member `layout`), so a table is never read in another layout than its own. The default
// (textbook) layout is read by texture(lut, vec2(n.v, r)); dfg_lut_layout::remapped() tables by
// texture(lut, dfg_lut_coord(n.v, r, N, layout)).
//
// ---- Shading -------------------------------------------------------------------------------------
// ibl_lookup_sample() gathers an ibl_sample (runtime/shade.hpp) from a chain and a table at a shading
// point, so pbr_shader::ambient runs on exactly these lookups.
//
// Domains: roughness clamped to [0, 1] and n.v to [0, 1] (NaN -> 0). A chain of one level returns
// level 0 for every roughness. Weight exponent p is clamped to [1/16, 16] (NaN -> 1).
// Value functions (weights, coordinates) are IBL_FUNC; the lookups that read a cubemap<float> or a
// table in host memory are host functions.

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <cmath>
#include <concepts>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "../core/math.hpp"
#include "../core/vec.hpp"
#include "../env/cubemap.hpp"
#include "dfg_layout.hpp"
#include "roughness_mip.hpp"
#include "shade.hpp"

namespace ibl {

// ---- specular ------------------------------------------------------------------------------------

enum class level_weight : int {
    lod = 0,   ///< t = fractional part of lod(r) (textureLod at the policy's lod)
    power = 1, ///< t linear in r^p between the bracketing levels' roughness
    log = 2,   ///< t linear in log r between them (lod's t between level 0, r = 0, and level 1)
};

enum class level_interpolation : int {
    linear = 0,      ///< two levels (one trilinear tap)
    catmull_rom = 1, ///< four levels, uniform Catmull-Rom in the level index
    geometric = 2,   ///< two levels, L_l^(1 - t) L_{l+1}^t per channel (linear where one is <= 0)
};

/// How a renderer reads the specular chain at a roughness (see the header). The default is the
/// textbook lookup, textureLod(chain, R, lod(r)) under the bake's mapping (one trilinear tap).
/// accurate() is the best two-tap scheme measured (docs/lookup.md): t linear in log r, geometric
/// blend (per channel L_l^(1 - t) L_{l+1}^t), which is exact wherever LD follows a power law in r:
/// in a bright source's GGX tail (LD ~ alpha^2 = r^4) and at its peak (LD ~ 1 / alpha^2 = r^-4).
/// GPU cost: two textureLod at integer lods, one log per lookup for t, one exp2/log2 pair per
/// channel.
struct specular_lookup_desc {
    roughness_mapping mapping = roughness_mapping::linear; ///< what the bake stored per level
    level_weight weight = level_weight::lod;
    double weight_exponent = 1.0; ///< p of level_weight::power (unused by the others)
    level_interpolation interpolation = level_interpolation::linear;

    /// The textbook lookup (the default): textureLod(chain, R, lod(r)) under the bake's mapping.
    static constexpr specular_lookup_desc textbook(roughness_mapping m = roughness_mapping::linear) noexcept {
        return {m, level_weight::lod, 1.0, level_interpolation::linear};
    }
    /// The accurate two-tap lookup: t linear in log r, geometric blend.
    static constexpr specular_lookup_desc accurate(roughness_mapping m = roughness_mapping::linear) noexcept {
        return {m, level_weight::log, 2.0, level_interpolation::geometric};
    }
    /// "textbook", "accurate", or a description of another combination (what files record).
    const char* name() const noexcept {
        if (weight == level_weight::lod && interpolation == level_interpolation::linear) return "textbook";
        if (weight == level_weight::log && interpolation == level_interpolation::geometric) return "accurate";
        return "custom";
    }
};

/// The levels and weights of one specular lookup: sum_k weight[k] * level[k] (count 2 or 4).
template <class T> struct specular_taps {
    int level[4] = {0, 0, 0, 0};
    T weight[4] = {T(0), T(0), T(0), T(0)};
    int count = 0;
    /// The continuous lod l + t of a two-level lookup (what textureLod takes on a GPU).
    T lod = T(0);
};

/// The bracketing level l and fraction t in [0, 1] of roughness r in a chain of `levels` levels.
template <class T> IBL_FUNC T specular_level_fraction(T roughness, int levels, const specular_lookup_desc& d,
                                                      int& lower) noexcept {
    using std::pow;
    lower = 0;
    if (levels < 2) return T(0);
    const T m = T(levels - 1);
    const T r = saturate(roughness);
    const T x = lod_from_roughness(d.mapping, r, m);
    int l = int(x); // x >= 0: truncation is floor
    if (l > levels - 2) l = levels - 2;
    lower = l;
    if (d.weight == level_weight::log && l > 0) {
        using std::log;
        const T r0 = roughness_from_lod(d.mapping, T(l), m), r1 = roughness_from_lod(d.mapping, T(l + 1), m);
        const T den = log(r1 / r0);
        return den > T(0) && r > T(0) ? saturate(log(r / r0) / den) : T(0);
    }
    if (d.weight == level_weight::power) {
        const T p0 = T(d.weight_exponent);
        // Clamped to [1/16, 16]; NaN fails every comparison and gives 1.
        const T p = p0 > T(16) ? T(16) : (p0 >= T(1.0 / 16) ? p0 : (p0 < T(1.0 / 16) ? T(1.0 / 16) : T(1)));
        const T r0 = roughness_from_lod(d.mapping, T(l), m), r1 = roughness_from_lod(d.mapping, T(l + 1), m);
        const T g0 = pow(r0, p), g1 = pow(r1, p);
        const T den = g1 - g0;
        return den > T(0) ? saturate((pow(r, p) - g0) / den) : T(0);
    }
    return saturate(x - T(l));
}

/// Levels and weights of a lookup at roughness r in a chain of `levels` levels (see the header).
template <class T>
IBL_FUNC specular_taps<T> specular_lookup_taps(T roughness, int levels, const specular_lookup_desc& d = {}) noexcept {
    specular_taps<T> s;
    int l = 0;
    const T t = specular_level_fraction(roughness, levels, d, l);
    if (levels < 2) {
        s.count = 2;
        s.weight[0] = T(1);
        return s;
    }
    s.lod = T(l) + t;
    if (d.interpolation == level_interpolation::catmull_rom) {
        const int m = levels - 1;
        const T t2 = t * t, t3 = t2 * t;
        s.count = 4;
        s.level[0] = l > 0 ? l - 1 : 0;
        s.level[1] = l;
        s.level[2] = l + 1;
        s.level[3] = l + 2 < m ? l + 2 : m;
        // Uniform Catmull-Rom basis; at t = 0 the weights are exactly (0, 1, 0, 0).
        s.weight[0] = T(0.5) * (T(2) * t2 - t3 - t);
        s.weight[1] = T(0.5) * (T(3) * t3 - T(5) * t2) + T(1);
        s.weight[2] = T(0.5) * (T(4) * t2 - T(3) * t3 + t);
        s.weight[3] = T(0.5) * (t3 - t2);
        return s;
    }
    s.count = 2;
    s.level[0] = l;
    s.level[1] = l + 1;
    s.weight[0] = T(1) - t;
    s.weight[1] = t;
    return s;
}

/// The lookup's combination of the values of its taps (values[k] read from level taps.level[k]).
template <class T>
IBL_FUNC vec3<T> specular_blend(const specular_taps<T>& s, const vec3<T>* values, const specular_lookup_desc& d) noexcept {
    using std::exp;
    using std::log;
    if (s.count == 2) {
        const vec3<T> a = values[0];
        if (!(s.weight[1] > T(0))) return a;
        const vec3<T> b = values[1];
        const T t = s.weight[1];
        vec3<T> v = a + t * (b - a);
        if (d.interpolation == level_interpolation::geometric)
            for (int c = 0; c < 3; ++c)
                if (a[c] > T(0) && b[c] > T(0)) v[c] = a[c] * exp(t * log(b[c] / a[c]));
        return v;
    }
    vec3<T> v(T(0));
    for (int k = 0; k < s.count; ++k) v += s.weight[k] * values[k];
    return {v.x > T(0) ? v.x : T(0), v.y > T(0) ? v.y : T(0), v.z > T(0) ? v.z : T(0)};
}

namespace detail {
/// The description a chain is read with: d, with the chain's own mapping when the chain records
/// one (runtime/chain.hpp's specular_chain).
template <class Chain> specular_lookup_desc chain_desc(const Chain& chain, specular_lookup_desc d) noexcept {
    if constexpr (requires { chain.mapping; }) d.mapping = chain.mapping;
    return d;
}
/// A lobe table fitted to another LD weight than the chain's is refused (std::invalid_argument),
/// when both record theirs.
template <class Chain, class Table> void check_chain_weight(const char* fn, const Chain& chain, const Table& t) {
    if constexpr (requires { chain.weight == t.weight; })
        if (!(chain.weight == t.weight))
            throw std::invalid_argument(std::string("ibl::") + fn + ": the lobe table was fitted to the " +
                                        (int(t.weight) == 0 ? "n.l" : "G1") + " chain weight, the chain is " +
                                        (int(chain.weight) == 0 ? "n.l" : "G1") + "-weighted");
}
} // namespace detail

/// The specular chain at unit direction dir (the reflection direction R) and roughness r: the taps
/// of specular_lookup_taps, each a seamless bilinear read of its level, summed; negative channels
/// (Catmull-Rom) clamped to 0. A two-level lookup is computed as lerp(L_l, L_{l+1}, t), i.e.
/// exactly the trilinear chain.radiance(dir, l + t) a GPU's textureLod gives. A specular_chain
/// (what prefilter returns, runtime/chain.hpp) is read with its own mapping (d.mapping is
/// replaced by the chain's); a plain cubemap with d as given.
template <class Chain>
    requires std::derived_from<Chain, cubemap<float>>
vec3<float> specular_lookup(const Chain& chain_in, const vec3<float>& dir, float roughness, const specular_lookup_desc& d_in = {}) {
    const cubemap<float>& chain = chain_in;
    const specular_lookup_desc d = detail::chain_desc(chain_in, d_in);
    const specular_taps<float> s = specular_lookup_taps(roughness, chain.levels(), d);
    vec3<float> v[4];
    for (int k = 0; k < s.count; ++k)
        v[k] = s.weight[k] != 0.0f || k == 0 ? chain.bilinear(dir, s.level[k]) : vec3<float>(0.0f);
    return specular_blend(s, v, d);
}

/// The DFG table at (n.v, r): (A, B, k) by one bilinear tap at dfg_lut_coord in the table's own
/// layout (lut.layout).
template <class Table> vec3<float> dfg_lookup(const Table& lut, float n_dot_v, float roughness) {
    const vec2<float> st = dfg_lut_coord(n_dot_v, roughness, lut.size, lut.layout);
    return dfg_sample_st(lut, st.x, st.y);
}

// ---- shading -------------------------------------------------------------------------------------

/// The baked products at one shading point, looked up as a renderer does: LD from the chain at
/// R = reflect(-v, n) and the material's roughness, (A, B) from the table at (n.v, r). n, v unit.
/// irradiance_over_pi is passed through (E(n)/pi from SH or an irradiance map; 0 if not baked).
template <class Chain, class Table>
    requires std::derived_from<Chain, cubemap<float>>
ibl_sample<float> ibl_lookup_sample(const Chain& chain, const specular_lookup_desc& sd, const Table& lut,
                                    const vec3<float>& n, const vec3<float>& v, float roughness,
                                    const vec3<float>& irradiance_over_pi = vec3<float>(0.0f)) {
    const float n_dot_v = saturate(glm::dot(n, v));
    const vec3<float> r_dir = 2.0f * glm::dot(n, v) * n - v;
    ibl_sample<float> s;
    s.ld = specular_lookup(chain, r_dir, roughness, sd);
    const vec3<float> dfg = dfg_lookup(lut, n_dot_v, roughness);
    s.dfg = vec2<float>(dfg.x, dfg.y);
    s.irradiance_over_pi = irradiance_over_pi;
    return s;
}

} // namespace ibl

#endif // IBL_DETAIL_CXX20
