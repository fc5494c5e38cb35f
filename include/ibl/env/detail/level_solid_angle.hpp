#pragma once
// ibl/env/detail/level_solid_angle.hpp — what cubemap and latlong share: the continuous
// lod <-> texel-solid-angle map, and the per-texel sanitize policy.
//
// `levels` is a contiguous range of per-level records with members `omega` (mean texel solid
// angle of the level) and `log2_omega`; between whole levels the solid angle is
// interpolated log-linearly, so Omega(lod) = Omega_0 4^lod for a power-of-two chain, and
// lod_for_solid_angle is its exact inverse.

#include "../../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <cmath>
#include <cstddef>

#include "../../core/math.hpp"

namespace ibl::detail {

/// Mean texel solid angle at a continuous lod, clamped to [0, max_lod]; NaN -> level 0.
template <class T, class Levels> T level_texel_solid_angle(const Levels& levels, T lod, T max_lod) noexcept {
    const T l = clamp(lod, T(0), max_lod);
    const int l0 = int(l);
    const T f = l - T(l0);
    if (!(f > T(0))) return levels[std::size_t(l0)].omega;
    const T a = levels[std::size_t(l0)].log2_omega, b = levels[std::size_t(l0) + 1].log2_omega;
    return std::exp2(a + f * (b - a));
}

/// The lod whose mean texel solid angle is omega, clamped to [0, max_lod]; 0 for NaN.
template <class T, class Levels> T level_lod_for_solid_angle(const Levels& levels, T omega, T max_lod) noexcept {
    if (!(omega > levels[0].omega)) return T(0);
    const T x = std::log2(omega);
    for (std::size_t l = 0; l + 1 < levels.size(); ++l) {
        const T a = levels[l].log2_omega, b = levels[l + 1].log2_omega;
        if (x <= b) return T(l) + (x - a) / (b - a);
    }
    return max_lod;
}

/// Zeroes the non-finite components of a texel (and the negative ones when zero_negative);
/// returns whether it changed. The texel policy of cubemap::sanitize and latlong::sanitize.
template <class V> bool sanitize_texel(V& v, bool zero_negative) noexcept {
    bool bad = false;
    for (int k = 0; k < 3; ++k)
        if (!is_finite(v[k]) || (zero_negative && v[k] < decltype(+v[k])(0))) {
            v[k] = 0;
            bad = true;
        }
    return bad;
}

} // namespace ibl::detail

#endif // IBL_DETAIL_CXX20
