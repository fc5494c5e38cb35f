#pragma once
// ibl/reference/analytic_room.hpp — an exact reference for local probes: a closed box room whose
// walls carry known radiance patterns, plus a small bright emitter on the ceiling. Any point
// inside sees the room along any direction exactly (one ray-box exit and a closed-form pattern),
// so a probe can be captured from any point (bake_cubemap over room_view: k x k rays per texel)
// and the true reflected radiance at any point and roughness is reference_ld over the room_view
// at that point (GGX importance sampling with ray casting, converged by the sample count); the
// true irradiance is reference_irradiance over it.
//
// Walls: 0 -X, 1 +X, 2 -Y (floor), 3 +Y (ceiling), 4 -Z, 5 +Z, each with a base colour times the
// smooth pattern 1 + a sin(2 pi u / period) sin(2 pi v / period) in the wall's two coordinates (u,
// v in metres, world axes). The emitter: on the ceiling, centred at (emitter_x, hi.y, emitter_z),
// radiance emitter * (1 - (d / emitter_radius)^2)^2 for d < emitter_radius (a smooth bump, so that
// a cubemap of the room is band-limited at the scale of its texels' footprint a few metres away).
// Points outside the room see black (trace returns 0 and no wall).

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <cmath>
#include <limits>

#include "../core/constants.hpp"
#include "../core/vec.hpp"

namespace ibl {

template <class T> struct analytic_room {
    vec3<T> lo{T(-4), T(0), T(-3)};
    vec3<T> hi{T(4), T(3), T(5)};
    vec3<T> base[6] = {vec3<T>(T(0.8), T(0.3), T(0.2)), vec3<T>(T(0.2), T(0.5), T(0.8)), vec3<T>(T(0.4), T(0.35), T(0.3)),
                       vec3<T>(T(0.9), T(0.9), T(0.85)), vec3<T>(T(0.3), T(0.7), T(0.3)), vec3<T>(T(0.7), T(0.6), T(0.2))};
    T amplitude = T(0.6);
    T period = T(1.5);
    vec3<T> emitter{T(40), T(38), T(34)};
    T emitter_x = T(1), emitter_z = T(2), emitter_radius = T(0.6);

    /// The radiance leaving wall `wall` at the point x on it.
    vec3<T> wall_radiance(const vec3<T>& x, int wall) const noexcept {
        const int axis = wall / 2;
        const T u = axis == 0 ? x.y : x.x, v = axis == 2 ? x.y : x.z;
        const T k = T(2) * pi_v<T> / period;
        vec3<T> l = base[wall] * (T(1) + amplitude * std::sin(k * u) * std::sin(k * v));
        if (wall == 3) {
            const T dx = x.x - emitter_x, dz = x.z - emitter_z;
            const T q = (dx * dx + dz * dz) / (emitter_radius * emitter_radius);
            if (q < T(1)) l += emitter * ((T(1) - q) * (T(1) - q));
        }
        return l;
    }

    /// Distance from p (inside) along the unit direction d to the wall it meets, and that wall;
    /// -1 when p is outside the room or d is not finite.
    T exit(const vec3<T>& p, const vec3<T>& d, int& wall) const noexcept {
        wall = -1;
        T best = std::numeric_limits<T>::infinity();
        for (int k = 0; k < 3; ++k) {
            if (!(p[k] >= lo[k] && p[k] <= hi[k])) return T(-1);
            if (d[k] > T(0)) {
                const T t = (hi[k] - p[k]) / d[k];
                if (t < best) best = t, wall = 2 * k + 1;
            } else if (d[k] < T(0)) {
                const T t = (lo[k] - p[k]) / d[k];
                if (t < best) best = t, wall = 2 * k;
            }
        }
        return wall >= 0 ? best : T(-1);
    }

    /// What p sees along d (normalised here): the radiance of the wall point the ray meets.
    vec3<T> trace(const vec3<T>& p, vec3<T> d) const noexcept {
        const T len = std::sqrt(glm::dot(d, d));
        if (!(len > T(0))) return vec3<T>(T(0));
        d /= len;
        int wall = -1;
        const T t = exit(p, d, wall);
        if (!(t >= T(0))) return vec3<T>(T(0));
        vec3<T> x = p + t * d;
        x[wall / 2] = (wall % 2) ? hi[wall / 2] : lo[wall / 2]; // exactly on the wall
        return wall_radiance(x, wall);
    }
};

/// The room as an environment seen from one point (the environment concept: radiance(dir, lod),
/// lod ignored; texel_solid_angle 0: a point evaluation, no prefiltered levels).
template <class T> struct room_view {
    using scalar_type = T;
    const analytic_room<T>* room = nullptr;
    vec3<T> at{T(0)};
    vec3<T> radiance(const vec3<T>& dir, T /*lod*/) const noexcept { return room->trace(at, dir); }
    T texel_solid_angle(T /*lod*/) const noexcept { return T(0); }
};

} // namespace ibl

#endif // IBL_DETAIL_CXX20
