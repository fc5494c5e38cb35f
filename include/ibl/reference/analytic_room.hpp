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
//
// The inner-box variant (inner = true): an opaque block standing in the room (inner_lo..inner_hi,
// by default 2.4 x 1.1 x 1.8 m on the floor near the centre, below the study's capture points),
// its faces carrying the same pattern with the base colour inner_base. A ray from a point outside
// the block stops where it meets it (trace: the slab test against the block before the walls), so
// captures (bake_cubemap) and the truth (reference_ld, reference_irradiance) both see it, while a
// box proxy of the room does not know it. Points inside the block see black.

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
    bool inner = false; ///< the inner-box variant
    vec3<T> inner_lo{T(-1.2), T(0), T(-1.2)};
    vec3<T> inner_hi{T(1.2), T(1.1), T(0.6)};
    vec3<T> inner_base{T(0.85), T(0.8), T(0.9)};

    /// The pattern 1 + a sin sin on a face perpendicular to `axis` at x (u, v: the face's two world axes).
    T pattern(const vec3<T>& x, int axis) const noexcept {
        const T u = axis == 0 ? x.y : x.x, v = axis == 2 ? x.y : x.z;
        const T k = T(2) * pi_v<T> / period;
        return T(1) + amplitude * std::sin(k * u) * std::sin(k * v);
    }

    /// The radiance leaving wall `wall` at the point x on it.
    vec3<T> wall_radiance(const vec3<T>& x, int wall) const noexcept {
        vec3<T> l = base[wall] * pattern(x, wall / 2);
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

    /// True when p lies strictly inside the inner box (never without the variant).
    bool inside_inner(const vec3<T>& p) const noexcept {
        if (!inner) return false;
        for (int k = 0; k < 3; ++k)
            if (!(p[k] > inner_lo[k] && p[k] < inner_hi[k])) return false;
        return true;
    }

    /// Distance from p (outside the inner box) along the unit direction d to where the ray enters
    /// it, and the face entered (0 -X ... 5 +Z); -1 when it misses the box or the box is behind.
    T inner_entry(const vec3<T>& p, const vec3<T>& d, int& face) const noexcept {
        face = -1;
        if (!inner) return T(-1);
        T t_near = -std::numeric_limits<T>::infinity(), t_far = std::numeric_limits<T>::infinity();
        for (int k = 0; k < 3; ++k) {
            if (d[k] == T(0)) {
                if (!(p[k] >= inner_lo[k] && p[k] <= inner_hi[k])) return T(-1);
                continue;
            }
            const T a = (inner_lo[k] - p[k]) / d[k], b = (inner_hi[k] - p[k]) / d[k];
            const T t0 = a < b ? a : b, t1 = a < b ? b : a;
            if (t0 > t_near) t_near = t0, face = d[k] > T(0) ? 2 * k : 2 * k + 1; // entering the lo face going +
            if (t1 < t_far) t_far = t1;
        }
        if (!(t_near <= t_far) || !(t_near > T(0)) || face < 0) {
            face = -1;
            return T(-1);
        }
        return t_near;
    }

    /// What p sees along d (normalised here): the radiance of the wall point the ray meets, or of
    /// the inner box's face when the variant's block is nearer.
    vec3<T> trace(const vec3<T>& p, vec3<T> d) const noexcept {
        const T len = std::sqrt(glm::dot(d, d));
        if (!(len > T(0))) return vec3<T>(T(0));
        d /= len;
        int wall = -1;
        const T t = exit(p, d, wall);
        if (!(t >= T(0)) || inside_inner(p)) return vec3<T>(T(0));
        int face = -1;
        const T ti = inner_entry(p, d, face);
        if (ti > T(0) && ti < t) {
            vec3<T> x = p + ti * d;
            x[face / 2] = (face % 2) ? inner_hi[face / 2] : inner_lo[face / 2]; // exactly on the face
            return inner_base * pattern(x, face / 2);
        }
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
