#pragma once
// ibl/sampling/hemisphere.hpp — warps from the unit square to the disk and the hemisphere,
// each as a triplet sample_x(u) / x_pdf(...) / invert_x(...).
//
// Conventions: u in [0, 1)^2 (uniform variates); directions are unit vectors in tangent space,
// z = the normal, so the hemisphere is z >= 0. phi is measured from +x towards +y.
// Measures: disk pdfs are per unit AREA of the unit disk; hemisphere pdfs are per unit SOLID
// ANGLE (steradian).
//
// References: P. Shirley, K. Chiu, "A Low Distortion Map Between Disk and Square", JGT 2(3), 1997
// (concentric mapping; the single-branch form with the |a| > |b| test is D. Cline's, as in
// M. Pharr, W. Jakob, G. Humphreys, "Physically Based Rendering", 4th ed., 2023, sec. A.5.1);
// Malley's method for the cosine lobe (PBR 4th ed., sec. A.5.3).

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <cmath>

#include "../core/constants.hpp"
#include "../core/math.hpp"
#include "../core/vec.hpp"

namespace ibl {

namespace detail {
/// atan2(y, x) / (2 pi) wrapped into [0, 1): the inverse of phi = 2 pi u. (0, 0) maps to 0.
/// A tiny negative angle wraps to a value that may round to 1; that is the same point of the
/// circle as 0, which is returned instead.
template <class T> IBL_FUNC T unit_from_azimuth(T y, T x) noexcept {
    using std::atan2;
    T u = atan2(y, x) * inv_two_pi_v<T>;
    u = u < T(0) ? u + T(1) : u;
    return u < T(1) ? u : T(0);
}

/// Direction in tangent space from sin(theta), cos(theta) and phi.
template <class T> IBL_FUNC vec3<T> spherical_direction(T sin_theta, T cos_theta, T phi) noexcept {
    using std::cos;
    using std::sin;
    return vec3<T>(sin_theta * cos(phi), sin_theta * sin(phi), cos_theta);
}
} // namespace detail

// ---------------------------------------------------------------------------------------------
// Concentric disk (Shirley & Chiu 1997).
// ---------------------------------------------------------------------------------------------

/// Radius of the concentric image of u: max(|2 u.x - 1|, |2 u.y - 1|), exactly the value the
/// disk point has (used by the cosine warp to form z = sqrt((1 - r)(1 + r)) without rounding r).
template <class T> IBL_FUNC T concentric_disk_radius(const vec2<T>& u) noexcept {
    using std::fabs;
    const T a = fabs(T(2) * u.x - T(1));
    const T b = fabs(T(2) * u.y - T(1));
    return a > b ? a : b;
}

/// Concentric map of the square onto the unit disk. Domain: u in [0, 1]^2 (the whole closed
/// square is valid). Range: the closed unit disk. Area-preserving up to the constant pi/4, so the
/// density is uniform: concentric_disk_pdf() per unit area. Shirley & Chiu 1997.
template <class T> IBL_FUNC vec2<T> sample_concentric_disk(const vec2<T>& u) noexcept {
    using std::cos;
    using std::fabs;
    using std::sin;
    const T a = T(2) * u.x - T(1);
    const T b = T(2) * u.y - T(1);
    if (a == T(0) && b == T(0)) return vec2<T>(T(0), T(0));
    // Square ring of half-width r = max(|a|, |b|) onto the circle of radius r; within each of
    // the four wedges the angle is linear in the other coordinate.
    const bool horizontal = fabs(a) > fabs(b);
    const T r = horizontal ? a : b;
    const T phi = horizontal ? (pi_v<T> / T(4)) * (b / a) : half_pi_v<T> - (pi_v<T> / T(4)) * (a / b);
    return vec2<T>(r * cos(phi), r * sin(phi));
}

/// Density of sample_concentric_disk: 1/pi per unit area of the unit disk.
template <class T> IBL_FUNC constexpr T concentric_disk_pdf() noexcept { return inv_pi_v<T>; }

/// Inverse of sample_concentric_disk. Domain: p in the closed unit disk. Range: [0, 1]^2 (the
/// closed square; u = 1 is reached only by points on the boundary wedges, as in the forward map).
/// In the wedge |x| >= |y|: a = sign(x) |p|, b = a (4/pi) atan(y/x); otherwise the same with
/// x and y exchanged and b = sign(y) |p|, a = b (4/pi) atan(x/y).
template <class T> IBL_FUNC vec2<T> invert_concentric_disk(const vec2<T>& p) noexcept {
    using std::atan;
    using std::fabs;
    using std::sqrt;
    const T r = sqrt(p.x * p.x + p.y * p.y);
    if (r == T(0)) return vec2<T>(T(0.5), T(0.5));
    const T k = T(4) * inv_pi_v<T>;
    const bool horizontal = fabs(p.x) >= fabs(p.y);
    T a, b;
    if (horizontal) {
        a = sign_not_zero(p.x) * r;
        b = a * k * atan(p.y / p.x);
    } else {
        b = sign_not_zero(p.y) * r;
        a = b * k * atan(p.x / p.y);
    }
    return vec2<T>(saturate((a + T(1)) * T(0.5)), saturate((b + T(1)) * T(0.5)));
}

// ---------------------------------------------------------------------------------------------
// Uniform hemisphere.
// ---------------------------------------------------------------------------------------------

/// Uniform direction on the hemisphere z >= 0: cos(theta) = u.x, phi = 2 pi u.y (Archimedes'
/// hat-box theorem; PBR 4th ed., sec. A.5.2). Domain: u in [0, 1)^2. Range: unit vectors with
/// z in [0, 1). Density uniform_hemisphere_pdf() per unit solid angle.
template <class T> IBL_FUNC vec3<T> sample_uniform_hemisphere(const vec2<T>& u) noexcept {
    const T cos_theta = u.x;
    return detail::spherical_direction(sin_from_cos(cos_theta), cos_theta, two_pi_v<T> * u.y);
}

/// Density of sample_uniform_hemisphere: 1 / (2 pi) per unit solid angle on z >= 0.
template <class T> IBL_FUNC constexpr T uniform_hemisphere_pdf() noexcept { return inv_two_pi_v<T>; }

/// Inverse of sample_uniform_hemisphere. Domain: unit w with w.z >= 0. Range: [0, 1)^2 (w.z is
/// clamped to [0, 1 - eps/2]: the pole itself, z = 1, is the limit u.x -> 1).
template <class T> IBL_FUNC vec2<T> invert_uniform_hemisphere(const vec3<T>& w) noexcept {
    const T ux = saturate(w.z);
    return vec2<T>(ux < T(1) ? ux : one_minus_epsilon_v<T>, detail::unit_from_azimuth(w.y, w.x));
}

// ---------------------------------------------------------------------------------------------
// Cosine-weighted hemisphere (Malley's method on the concentric disk).
// ---------------------------------------------------------------------------------------------

/// Cosine-weighted direction: the concentric disk point lifted to the hemisphere,
/// z = sqrt(1 - r^2) = sqrt((1 - r)(1 + r)) with the exact square-ring radius r. Domain:
/// u in [0, 1]^2 (the closed square, as the disk map). Range: unit vectors with z in [0, 1]. Density cosine_hemisphere_pdf(z) =
/// z / pi per unit solid angle. Shirley & Chiu 1997; Malley's method.
template <class T> IBL_FUNC vec3<T> sample_cosine_hemisphere(const vec2<T>& u) noexcept {
    const vec2<T> d = sample_concentric_disk(u);
    return vec3<T>(d.x, d.y, sin_from_cos(concentric_disk_radius(u)));
}

/// Density of sample_cosine_hemisphere: cos(theta) / pi per unit solid angle; 0 below the
/// horizon (cos_theta <= 0) and for NaN.
template <class T> IBL_FUNC T cosine_hemisphere_pdf(T cos_theta) noexcept {
    return saturate(cos_theta) * inv_pi_v<T>;
}

/// Inverse of sample_cosine_hemisphere: the projection (w.x, w.y) onto the disk, unwarped.
/// Domain: unit w with w.z >= 0. Range: [0, 1]^2 as invert_concentric_disk.
template <class T> IBL_FUNC vec2<T> invert_cosine_hemisphere(const vec3<T>& w) noexcept {
    return invert_concentric_disk(vec2<T>(w.x, w.y));
}

} // namespace ibl

#endif // IBL_DETAIL_CXX20
