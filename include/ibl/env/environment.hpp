#pragma once
// ibl/env/environment.hpp — the environment concept: what integrators need from a light source
// at infinity.
//
//   e.radiance(dir, lod) -> vec3<T>   linear RGB radiance arriving from direction `dir`.
//       dir:  a UNIT vector (|dir| = 1 within a few ulps), pointing from the shaded point towards
//             the environment. cubemap and latlong happen to be scale-invariant and analytic
//             sources may not be; generic code must pass unit vectors.
//       lod:  continuous level of detail, 0 = finest. Values below 0 act as 0, values above
//             env_max_lod(e) as env_max_lod(e), NaN as 0. Analytic sources ignore it.
//   e.texel_solid_angle(lod) -> T     the (average) solid angle in steradians of one texel at
//       that lod; 0 for analytic sources (they have no texels: every sample is exact).
//       Non-decreasing in lod. For a cube of face size n at a level it is the average
//       4 pi / (6 n^2); between integer levels it is interpolated geometrically (log-linear),
//       so for power-of-two chains texel_solid_angle(lod) = texel_solid_angle(0) * 4^lod.
//
// Optional members, detected by the free functions below (user types need not provide them):
//   e.max_lod() -> T                     the largest useful lod (levels - 1); default 0.
//   e.lod_for_solid_angle(omega) -> T    inverse of texel_solid_angle on [0, max_lod], clamped.
//       Filtered importance sampling (Krivanek & Colbert 2008) reads a sample from the lod whose
//       texel solid angle equals the sample's solid angle 1 / (N pdf); this is that lod.

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <cmath>
#include <concepts>
#include <type_traits>

#include "../core/vec.hpp"

namespace ibl {

template <class E, class T = float>
concept environment = requires(const E& e, vec3<T> dir, T lod) {
    { e.radiance(dir, lod) } -> std::convertible_to<vec3<T>>;
    { e.texel_solid_angle(lod) } -> std::convertible_to<T>;
};

/// Largest lod of an environment: e.max_lod() when it exists, else 0.
template <class T, class E> [[nodiscard]] inline T env_max_lod(const E& e) {
    if constexpr (requires { { e.max_lod() } -> std::convertible_to<T>; })
        return T(e.max_lod());
    else
        return T(0);
}

/// The lod whose texel solid angle is omega (steradians), clamped to [0, env_max_lod(e)].
/// Uses e.lod_for_solid_angle(omega) when it exists; otherwise assumes the power-of-two law
/// texel_solid_angle(lod) = texel_solid_angle(0) * 4^lod. Returns 0 for analytic sources
/// (texel_solid_angle(0) = 0), for omega <= 0 and for NaN.
template <class T, class E> [[nodiscard]] inline T env_lod_for_solid_angle(const E& e, T omega) {
    if constexpr (requires { { e.lod_for_solid_angle(omega) } -> std::convertible_to<T>; }) {
        return T(e.lod_for_solid_angle(omega));
    } else {
        using std::log2;
        const T omega0 = T(e.texel_solid_angle(T(0)));
        if (!(omega0 > T(0)) || !(omega > omega0)) return T(0);
        const T lod = T(0.5) * log2(omega / omega0);
        const T hi = env_max_lod<T>(e);
        return lod < hi ? lod : hi;
    }
}

namespace detail {
template <class E> struct environment_scalar {
    // GLM vectors convert implicitly, so environment<E, float> also holds for a double
    // environment: prefer double, and let an explicit scalar_type member decide first.
    using type = std::conditional_t<environment<E, double>, double, float>;
};
template <class E>
    requires requires { typename E::scalar_type; }
struct environment_scalar<E> {
    using type = typename E::scalar_type;
};
} // namespace detail

/// The scalar type an environment computes in: its `scalar_type` member when it has one (every
/// library environment does), else double when it models environment<E, double>, else float.
/// Reference integrators evaluate radiance in this type so that a double environment is never
/// silently evaluated in float.
template <class E> using environment_scalar_t = typename detail::environment_scalar<E>::type;

} // namespace ibl

#endif // IBL_DETAIL_CXX20
