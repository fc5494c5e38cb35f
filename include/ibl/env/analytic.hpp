#pragma once
// ibl/env/analytic.hpp — analytic environments: exact radiance everywhere, texel_solid_angle = 0,
// and closed-form integrals that tests use as oracles. All are small value types whose radiance
// is a few flops, deterministic and device-compatible.
//
// constant_environment   L everywhere (the white furnace when L = 1).
//     Irradiance for any normal: E = integral over the hemisphere of L cos = pi L.
//
// sky_environment        a sky gradient, a ground, and a sun disk added on top:
//     sky (dir.y >= 0):    L = horizon + (zenith - horizon) * dir.y        (linear in cos(zenith angle))
//     ground (dir.y < 0):  L = ground
//     sun: + sun_radiance for directions within the angular radius r of sun_dir (a hard-edged cap:
//          the stiff case, 1e4..1e5 times the sky). The test is on the chord, |dir - sun_dir|^2 <=
//          4 sin^2(r/2), which keeps full relative precision for small r (cos r would round to 1 in
//          float for r below 2.4e-4 rad).
//     Exact integrals (static helpers; sun and sky superpose, so each is given separately):
//       sun cap solid angle                  Omega = 2 pi (1 - cos r) = 4 pi sin^2(r/2)
//       sun integral over the sphere         sun_radiance * Omega
//       sun irradiance on a normal n with n.sun_dir = cos(theta) >= sin(r) (cap fully above n's
//         horizon): the integral of cos over the cap is pi sin^2(r) cos(theta), so
//         E_sun = sun_radiance * pi sin^2(r) * cos(theta)   (pi sin^2 r for a normal facing the sun)
//       sky+ground integral over the sphere  2 pi ground + 2 pi horizon + pi (zenith - horizon)
//       sky irradiance on n = +Y             pi horizon + (2 pi / 3)(zenith - horizon)
//       ground irradiance on n = -Y          pi ground
//
// lambda_environment     adapts a callable dir -> vec3<T> (radiance only; texel_solid_angle 0).

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <cmath>
#include <type_traits>
#include <utility>

#include "../core/constants.hpp"
#include "../core/math.hpp"
#include "../core/vec.hpp"
#include "environment.hpp"

namespace ibl {

template <class T> struct constant_environment {
    using scalar_type = T;
    vec3<T> value{T(1)};

    IBL_FUNC vec3<T> radiance(const vec3<T>& /*dir*/, T /*lod*/ = T(0)) const noexcept { return value; }
    IBL_FUNC T texel_solid_angle(T /*lod*/) const noexcept { return T(0); }

    /// Irradiance on any normal, pi L.
    IBL_FUNC static vec3<T> irradiance(const vec3<T>& radiance) noexcept { return pi_v<T> * radiance; }
    /// Integral of L over the sphere, 4 pi L.
    IBL_FUNC static vec3<T> sphere_integral(const vec3<T>& radiance) noexcept { return four_pi_v<T> * radiance; }
};

template <class T> struct sky_environment {
    using scalar_type = T;
    vec3<T> zenith{T(0.15), T(0.3), T(0.75)};  ///< sky radiance straight up
    vec3<T> horizon{T(0.7), T(0.8), T(0.95)};  ///< sky radiance at the horizon (dir.y = 0+)
    vec3<T> ground{T(0.2), T(0.18), T(0.15)};  ///< radiance of every direction below the horizon
    vec3<T> sun_dir{T(0), T(1), T(0)};         ///< unit direction towards the sun centre
    vec3<T> sun_radiance{T(0)};                ///< added to the sky inside the sun cap
    T sun_angular_radius = T(0);               ///< r in radians, [0, pi/2]
    T sun_chord2 = T(0);                       ///< 4 sin^2(r/2): squared chord of the cap edge

    /// Sets the sun (dir is normalised here) and its derived chord.
    IBL_FUNC_VOID void set_sun(const vec3<T>& dir, const vec3<T>& radiance, T angular_radius) noexcept {
        sun_dir = glm::normalize(dir);
        sun_radiance = radiance;
        sun_angular_radius = angular_radius;
        sun_chord2 = sun_cap_chord2(angular_radius);
    }

    /// Radiance in unit direction dir (lod ignored).
    IBL_FUNC vec3<T> radiance(const vec3<T>& dir, T /*lod*/ = T(0)) const noexcept {
        const vec3<T> sky = horizon + dir.y * (zenith - horizon);
        const vec3<T> base = dir.y >= T(0) ? sky : ground;
        const vec3<T> d = dir - sun_dir;
        return glm::dot(d, d) <= sun_chord2 ? base + sun_radiance : base;
    }
    IBL_FUNC T texel_solid_angle(T /*lod*/) const noexcept { return T(0); }

    // ---- exact integrals (oracles) ------------------------------------------------------------

    /// 4 sin^2(r/2) = 2 (1 - cos r), the squared chord between the cap centre and its edge.
    IBL_FUNC static T sun_cap_chord2(T angular_radius) noexcept {
        using std::sin;
        return T(4) * sqr(sin(T(0.5) * angular_radius));
    }
    /// Solid angle of a cap of angular radius r: 2 pi (1 - cos r) = 4 pi sin^2(r/2).
    IBL_FUNC static T cap_solid_angle(T angular_radius) noexcept {
        return pi_v<T> * sun_cap_chord2(angular_radius);
    }
    /// Integral of cos(angle to the cap axis) over the cap: pi sin^2 r.
    IBL_FUNC static T cap_cosine_integral(T angular_radius) noexcept {
        using std::sin;
        return pi_v<T> * sqr(sin(angular_radius));
    }
    /// Sun contribution to irradiance on unit normal n; exact when n.sun_dir >= sin(r) (the cap is
    /// entirely above n's horizon), 0 when n.sun_dir <= -sin(r); in between (the cap straddles the
    /// horizon) this returns the clamped cos(theta) form, which is not exact.
    IBL_FUNC vec3<T> sun_irradiance(const vec3<T>& n) const noexcept {
        const T c = glm::dot(n, sun_dir);
        return sun_radiance * (cap_cosine_integral(sun_angular_radius) * (c > T(0) ? c : T(0)));
    }
    /// Integral of the sun's radiance over the sphere, sun_radiance * cap solid angle.
    IBL_FUNC vec3<T> sun_sphere_integral() const noexcept {
        return sun_radiance * cap_solid_angle(sun_angular_radius);
    }
    /// Integral of the sky and ground (no sun) over the sphere.
    IBL_FUNC vec3<T> sky_sphere_integral() const noexcept {
        return two_pi_v<T> * (ground + horizon) + pi_v<T> * (zenith - horizon);
    }
    /// Irradiance of the sky (no sun) on the normal +Y.
    IBL_FUNC vec3<T> sky_irradiance_up() const noexcept {
        return pi_v<T> * horizon + (two_pi_v<T> / T(3)) * (zenith - horizon);
    }
    /// Irradiance of the ground on the normal -Y.
    IBL_FUNC vec3<T> ground_irradiance_down() const noexcept { return pi_v<T> * ground; }
};

/// The default environment of the bake tool: a blue sky over a dark ground with a sun at 30
/// degrees elevation (azimuth 40 degrees from +X towards +Z, so off every cube axis, edge and
/// face diagonal), angular radius 1 degree (a cap of 9.57e-4 sr), radiance 3e4 (about 4e4 times
/// the horizon radiance, 1.5e5 times the ground). Its irradiance on a normal facing it,
/// 3e4 pi sin^2(1 deg) = 28.7, is about 20 times the sky's on an upward normal (1.0 to 2.6 per
/// channel), the ratio of a clear day.
template <class T> sky_environment<T> make_default_sky() noexcept {
    sky_environment<T> s;
    const T elev = T(30) * pi_v<T> / T(180), az = T(40) * pi_v<T> / T(180);
    const vec3<T> dir(std::cos(elev) * std::cos(az), std::sin(elev), std::cos(elev) * std::sin(az));
    s.set_sun(dir, vec3<T>(T(3.0e4), T(2.85e4), T(2.6e4)), T(1) * pi_v<T> / T(180));
    return s;
}

/// Adapter: an environment from a callable f(vec3<T> unit dir) -> vec3<T> (lod ignored).
template <class T, class F> struct lambda_environment {
    using scalar_type = T;
    F fn;

    [[nodiscard]] vec3<T> radiance(const vec3<T>& dir, T /*lod*/ = T(0)) const { return vec3<T>(fn(dir)); }
    [[nodiscard]] T texel_solid_angle(T /*lod*/) const noexcept { return T(0); }
};

template <class T, class F> [[nodiscard]] lambda_environment<T, std::decay_t<F>> make_lambda_environment(F&& fn) {
    return {std::forward<F>(fn)};
}

static_assert(environment<constant_environment<float>, float>);
static_assert(environment<sky_environment<double>, double>);

} // namespace ibl

#endif // IBL_DETAIL_CXX20
