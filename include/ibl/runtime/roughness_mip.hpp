#pragma once
// ibl/runtime/roughness_mip.hpp — the roughness <-> mip level policy of a prefiltered chain.
//
// A prefiltered environment stores the split-sum LD term for one perceptual roughness r per mip
// level. Which r a level holds is an explicit, invertible policy; a renderer that samples the
// chain must use the same policy to pick its lod (lod = policy.lod(r)). Both directions take the
// chain's largest lod m = levels - 1 (level 0 is always r = 0, the mirror copy of the source):
//
//   linear    r = lod / m                       lod = r m
//             the literature's choice (LearnOpenGL, Khronos glTF-IBL-Sampler, UE4 notes).
//   filament  lod = r (2 - r) m                 r = 1 - sqrt(1 - lod / m)
//             Filament's (libs/ibl, the runtime's lod from roughness): quadratic near r = 1 so
//             that the coarse (cheap, low-resolution) levels hold a narrower range of r.
//             The inverse is evaluated as x / (1 + sqrt(1 - x)), x = lod / m, which has no
//             cancellation near r = 0 (1 - sqrt(1 - x) loses all digits for x below eps).
//
// Domains: r in [0, 1] (clamped, NaN -> 0); lod in [0, m] (clamped, NaN -> 0). A chain of one
// level (m = 0) holds r = 0 only: roughness() returns 0 and lod() returns 0.

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <cmath>

#include "../core/math.hpp"

namespace ibl {

enum class roughness_mapping : int {
    linear = 0,   ///< r = lod / m
    filament = 1, ///< lod = r (2 - r) m
};

/// The roughness stored at continuous lod in a chain whose largest lod is max_lod.
template <class T> IBL_FUNC T roughness_from_lod(roughness_mapping mapping, T lod, T max_lod) noexcept {
    if (!(max_lod > T(0))) return T(0);
    const T x = saturate(lod / max_lod);
    if (mapping == roughness_mapping::filament) return x / (T(1) + safe_sqrt(T(1) - x));
    return x;
}

/// The continuous lod that holds roughness r in a chain whose largest lod is max_lod.
template <class T> IBL_FUNC T lod_from_roughness(roughness_mapping mapping, T roughness, T max_lod) noexcept {
    if (!(max_lod > T(0))) return T(0);
    const T r = saturate(roughness);
    if (mapping == roughness_mapping::filament) return r * (T(2) - r) * max_lod;
    return r * max_lod;
}

/// The policy as a value: a mapping and the chain length it applies to.
struct roughness_mip_policy {
    roughness_mapping mapping = roughness_mapping::linear;

    static constexpr roughness_mip_policy linear() noexcept { return {roughness_mapping::linear}; }
    static constexpr roughness_mip_policy filament() noexcept { return {roughness_mapping::filament}; }

    /// Roughness held by (continuous) level `lod` of a chain of `levels` levels.
    template <class T> IBL_FUNC T roughness(T lod, int levels) const noexcept {
        return roughness_from_lod(mapping, lod, T(levels - 1));
    }
    /// Level (continuous lod) that holds roughness r in a chain of `levels` levels.
    template <class T> IBL_FUNC T lod(T roughness, int levels) const noexcept {
        return lod_from_roughness(mapping, roughness, T(levels - 1));
    }
};

} // namespace ibl

#endif // IBL_DETAIL_CXX20
