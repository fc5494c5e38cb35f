#pragma once
// ibl/brdf/lambert.hpp — the Lambertian (ideal diffuse) BRDF f = albedo / pi.
//
// Its directional albedo is the albedo: integral over the hemisphere of (albedo / pi) cos(theta_l)
// d(omega_l) = albedo, independent of the view direction. Albedo is used as given (linear).

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include "../core/constants.hpp"
#include "../core/vec.hpp"

namespace ibl {

/// Lambert BRDF value albedo / pi (per steradian), one channel.
template <class T> IBL_FUNC constexpr T lambert(T albedo) noexcept { return albedo * inv_pi_v<T>; }

/// Lambert BRDF value albedo / pi (per steradian), RGB.
template <class T> IBL_FUNC vec3<T> lambert(const vec3<T>& albedo) noexcept { return albedo * inv_pi_v<T>; }

} // namespace ibl

#endif // IBL_DETAIL_CXX20
