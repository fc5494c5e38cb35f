#pragma once
// ibl/runtime/local_probe.hpp — local reflection probes: a cubemap captured at a point, looked up
// with parallax correction against a proxy volume, blended with its neighbours by influence
// volumes (Lagarde & Zanuttini, "Local image-based lighting with parallax-corrected cubemaps",
// SIGGRAPH 2012). Mirrored by glsl/ibl_local_probe.glsl.
//
// Proxies. A box (axis-aligned, or oriented: a centre, three orthonormal axes and the half
// extents along them) or a sphere: the geometry the capture is assumed to show. A shading point P
// reflecting along the unit direction R sees the proxy where the ray P + t R leaves it:
//   proxy_exit_distance   t_far, the far intersection of the ray's line with the proxy (> 0 when
//                         the ray leaves the proxy ahead of P: always for P inside it); a value
//                         <= 0 (P outside and the proxy behind or missed: -1) means "no correction".
//   parallax_direction    the direction from the capture point C to that hit, normalize(P + t R -
//                         C): the direction to read the probe at. Without a hit, or with the hit at
//                         C, R itself. P = C gives R exactly (t R / t).
// Glossy lookups (distance-based roughness). The reflection lobe around R has a footprint on the
// proxy of radius d_s tan(w) at the hit distance d_s = t from P; read from C at distance d_p =
// |hit - C| the same footprint subtends w' with tan(w') = (d_s / d_p) tan(w). With the lobe's width
// written tan(w) = c alpha (the GGX NDF's angular width is proportional to alpha = r^2 in tangent
// space, whatever the constant c), the footprint-preserving alpha is alpha' = alpha d_s / d_p:
//   corrected_roughness   r' = sqrt(clamp(r^2 d_s / d_p, 0, 1)); r' = r when d_s = d_p (P at C),
//                         sharper when P is nearer the wall than C is, blurrier when farther.
// Oblique walls (the proxy's surface slope at the hit). The footprint above is taken across the
// rays; on the proxy's surface, with unit normal n at the hit, the solid angle dw around R covers
// the area dA = d_s^2 dw / cos_s (cos_s = |R.n|), which C sees as dw' = dA cos_p / d_p^2 (cos_p =
// |u.n|, u the corrected direction). The map from P's directions to C's is therefore, to first
// order, linear with determinant
//   dw' / dw = (d_s / d_p)^2 cos_p / cos_s,
// anisotropic: d_s / d_p across the planes of incidence, (d_s / d_p)(cos_p / cos_s) within them.
// One isotropic lobe of solid angle ~ alpha^2 (small alpha) covering the same area of the proxy
// takes the geometric mean of the two stretches:
//   alpha' = alpha (d_s / d_p) sqrt(cos_p / cos_s)      (corrected_roughness with the cosines;
//                         parallax_lookup carries them; both 1 reduces it to the distance-only form)
// It is the distance-only form when both points see the hit at the same slope (P at C, or C and P
// on one line through the hit), sharper where C looks at the wall more obliquely than P does (its
// texels cover more wall), blurrier where P does. The first-order map is what is exact; wide lobes
// (alpha -> 1) keep the clamp to [0, 1], and a zero cosine on one side sends alpha' to 0 or 1.
// Measured in docs/local_probes.md: it lowers the single probe's glossy error at every roughness
// of the empty room's study against the distance-only form.
// Wide lobes (the lobe split, an option). The factor above is the map's first order: exact for a
// narrow lobe, while a wide one (r -> 1) covers walls at many distances and slopes around the hit.
// The split reads the lobe as five narrower sub-lobes, each corrected on its own (its own hit,
// distances and slopes): sub-lobes of alpha / 2 (roughness r / sqrt 2), one along R and four on a
// ring around it at the reflected angle theta = 2 atan(alpha / 2) (the GGX lobe of alpha / 2 puts
// half its half vectors within atan(alpha / 2) of the normal), in the directions +-t, +-b of a
// branchless tangent frame of R (Duff et al. 2017), weights 1/5 each:
//   parallax_split_tap(proxy, C, P, R, r, i), i = 0..4 -> {direction, roughness, weight = 1/5}
//                         tap i's lookup; the caller sums weight x lookup(direction, roughness).
// cos theta = (1 - q^2) / (1 + q^2), sin theta = 2 q / (1 + q^2) with q = alpha / 2. Contract: the
// weights sum to 1; r = 0 gives five copies of the mirror lookup (parallax_correct's direction,
// roughness 0); without a hit each tap is its own direction at r / sqrt 2 (the split of a distant
// lookup, not the single lookup itself). The sub-lobe roughness and the ring's angle were chosen
// on a small grid of the empty room's study (docs/local_probes.md), not derived: a five-tap
// quadrature of the lobe, costing five proxy intersections and five reads.
// Influence volumes. Each probe has an influence box or sphere and a fade width f > 0: its weight
// at P is the distance from P to the volume's boundary inside the volume over f, clamped to [0, 1]
// (0 outside and on the boundary, 1 deeper than f). The weight is continuous and changes by at
// most |dP| / f between two points.
// Blending (blend_probe_weights). Probes are taken by priority, highest first (equal priorities
// together): a group of weights w_i with sum S gets the contributions c_i = remaining w_i /
// max(S, 1) and leaves remaining - sum c_i for the groups after it; what remains at the end is the
// distant environment's (the fallback). The contributions and the fallback are >= 0 and sum to 1
// exactly up to rounding; each is a continuous function of the weights, so blended lookups are
// continuous across influence boundaries. The same weights blend the probes' diffuse products
// (irradiance maps or SH evaluated at the normal).
//
// Domains: directions need not be unit for the intersections (R is normalised inside; a zero or
// NaN R gives "no correction"); fade widths <= 0 or NaN are treated as the smallest positive
// width (a hard edge); roughness is clamped to [0, 1], distances <= 0 or NaN leave it unchanged.

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <cmath>
#include <cstddef>
#include <limits>

#include "../core/math.hpp"
#include "../core/vec.hpp"

namespace ibl {

/// A box: centre, three orthonormal axes (world directions of the box's x, y, z) and half extents
/// along them. axis_aligned(min, max) gives the box of the world's axes.
template <class T> struct probe_box {
    vec3<T> center{T(0)};
    vec3<T> half{T(1)};
    vec3<T> axis[3] = {vec3<T>(T(1), T(0), T(0)), vec3<T>(T(0), T(1), T(0)), vec3<T>(T(0), T(0), T(1))};

    IBL_FUNC static probe_box axis_aligned(const vec3<T>& lo, const vec3<T>& hi) noexcept {
        probe_box b;
        b.center = (lo + hi) * T(0.5);
        b.half = (hi - lo) * T(0.5);
        return b;
    }
    /// P in the box's frame (coordinates along its axes, relative to its centre).
    IBL_FUNC vec3<T> to_local(const vec3<T>& p) const noexcept {
        const vec3<T> d = p - center;
        return {glm::dot(d, axis[0]), glm::dot(d, axis[1]), glm::dot(d, axis[2])};
    }
    IBL_FUNC vec3<T> direction_to_local(const vec3<T>& r) const noexcept {
        return {glm::dot(r, axis[0]), glm::dot(r, axis[1]), glm::dot(r, axis[2])};
    }
};

template <class T> struct probe_sphere {
    vec3<T> center{T(0)};
    T radius = T(1);
};

namespace detail {
template <class T> IBL_FUNC bool unit_or_zero(vec3<T>& r) noexcept {
    const T len2 = glm::dot(r, r);
    if (!(len2 > T(0)) || !(len2 < std::numeric_limits<T>::infinity())) return false;
    r /= std::sqrt(len2);
    return true;
}
} // namespace detail

/// Distance t along the unit direction of r from p to where the ray leaves the box (the far
/// intersection of the line); -1 when the line misses the box or the far intersection is not
/// ahead of p.
template <class T> IBL_FUNC T proxy_exit_distance(const probe_box<T>& box, const vec3<T>& p, vec3<T> r) noexcept {
    if (!detail::unit_or_zero(r)) return T(-1);
    const vec3<T> o = box.to_local(p), d = box.direction_to_local(r);
    T t_near = -std::numeric_limits<T>::infinity(), t_far = std::numeric_limits<T>::infinity();
    for (int k = 0; k < 3; ++k) {
        if (d[k] == T(0)) {
            if (std::fabs(o[k]) > box.half[k]) return T(-1); // parallel to the slab and outside it
            continue;
        }
        const T inv = T(1) / d[k];
        T a = (-box.half[k] - o[k]) * inv, b = (box.half[k] - o[k]) * inv;
        if (a > b) {
            const T s = a;
            a = b;
            b = s;
        }
        t_near = a > t_near ? a : t_near;
        t_far = b < t_far ? b : t_far;
    }
    if (!(t_near <= t_far) || !(t_far > T(0))) return T(-1);
    return t_far;
}

/// The same for a sphere.
template <class T> IBL_FUNC T proxy_exit_distance(const probe_sphere<T>& s, const vec3<T>& p, vec3<T> r) noexcept {
    if (!detail::unit_or_zero(r)) return T(-1);
    const vec3<T> o = p - s.center;
    const T b = glm::dot(o, r), c = glm::dot(o, o) - s.radius * s.radius;
    const T disc = b * b - c;
    if (!(disc >= T(0))) return T(-1);
    const T t_far = -b + std::sqrt(disc);
    return t_far > T(0) ? t_far : T(-1);
}

/// The parallax-corrected lookup of a probe captured at c: the direction from c to where the
/// reflection ray from p along r leaves the proxy, and what the roughness correction takes
/// (d_shading = from p to the hit, d_probe = from c to the hit; both 0 without a hit;
/// cos_shading = |R.n|, cos_probe = |direction.n| with n the proxy's normal at the hit, both 1
/// without a hit).
template <class T> struct parallax_lookup {
    vec3<T> direction;
    T d_shading = T(0);
    T d_probe = T(0);
    T cos_shading = T(1);
    T cos_probe = T(1);
    bool hit = false;
};

/// The proxy's unit outward normal at a point x on its surface: the box's face x is nearest to
/// (the largest |local coordinate| / half extent), the sphere's radial direction.
template <class T> IBL_FUNC vec3<T> proxy_normal(const probe_box<T>& box, const vec3<T>& x) noexcept {
    const vec3<T> q = box.to_local(x);
    int k = 0;
    T best = T(-1);
    for (int i = 0; i < 3; ++i) {
        const T e = box.half[i] > T(0) ? std::fabs(q[i]) / box.half[i] : std::numeric_limits<T>::infinity();
        if (e > best) best = e, k = i;
    }
    return q[k] < T(0) ? -box.axis[k] : box.axis[k];
}

template <class T> IBL_FUNC vec3<T> proxy_normal(const probe_sphere<T>& s, const vec3<T>& x) noexcept {
    vec3<T> n = x - s.center;
    if (!detail::unit_or_zero(n)) return vec3<T>(T(0), T(0), T(1));
    return n;
}

template <class T, class Proxy>
IBL_FUNC parallax_lookup<T> parallax_correct(const Proxy& proxy, const vec3<T>& c, const vec3<T>& p, const vec3<T>& r) noexcept {
    parallax_lookup<T> out;
    vec3<T> ru = r;
    if (!detail::unit_or_zero(ru)) {
        out.direction = r;
        return out;
    }
    out.direction = ru;
    const T t = proxy_exit_distance(proxy, p, ru);
    if (!(t > T(0))) return out;
    const vec3<T> d = (p - c) + t * ru; // hit - c, formed without cancelling p's magnitude
    const T len = std::sqrt(glm::dot(d, d));
    if (!(len > T(0)) || !(len < std::numeric_limits<T>::infinity())) return out;
    out.direction = d / len;
    out.d_shading = t;
    out.d_probe = len;
    const vec3<T> n = proxy_normal(proxy, p + t * ru);
    out.cos_shading = std::fabs(glm::dot(ru, n));
    out.cos_probe = std::fabs(glm::dot(out.direction, n));
    out.hit = true;
    return out;
}

/// The direction part alone.
template <class T, class Proxy>
IBL_FUNC vec3<T> parallax_direction(const Proxy& proxy, const vec3<T>& c, const vec3<T>& p, const vec3<T>& r) noexcept {
    return parallax_correct(proxy, c, p, r).direction;
}

/// Distance-based roughness (see the header comment): r' = sqrt(clamp(r^2 d_shading / d_probe, 0, 1)).
template <class T> IBL_FUNC T corrected_roughness(T roughness, T d_shading, T d_probe) noexcept {
    const T r = saturate(roughness);
    if (!(d_shading > T(0)) || !(d_probe > T(0)) || !(d_shading < std::numeric_limits<T>::infinity()) ||
        !(d_probe < std::numeric_limits<T>::infinity()))
        return r;
    const T a = saturate(r * r * (d_shading / d_probe));
    return std::sqrt(a);
}

/// Distance-based roughness on oblique walls (see the header comment):
/// r' = sqrt(clamp(r^2 (d_shading / d_probe) sqrt(cos_probe / cos_shading), 0, 1)). Cosines outside
/// [0, 1] are clamped to it; both 0 (or NaN) gives the distance-only form; cos_shading = 0 alone
/// gives 1, cos_probe = 0 alone 0.
template <class T> IBL_FUNC T corrected_roughness(T roughness, T d_shading, T d_probe, T cos_shading, T cos_probe) noexcept {
    const T r = saturate(roughness);
    if (!(d_shading > T(0)) || !(d_probe > T(0)) || !(d_shading < std::numeric_limits<T>::infinity()) ||
        !(d_probe < std::numeric_limits<T>::infinity()))
        return r;
    const T cs = saturate(cos_shading), cp = saturate(cos_probe);
    if (!(cs > T(0)) && !(cp > T(0))) return corrected_roughness(roughness, d_shading, d_probe);
    if (!(cs > T(0))) return r > T(0) ? T(1) : T(0);
    const T a = saturate(r * r * (d_shading / d_probe) * std::sqrt(cp / cs));
    return std::sqrt(a);
}

/// The same from a parallax_lookup (its distances and cosines): the library's glossy default.
template <class T> IBL_FUNC T corrected_roughness(T roughness, const parallax_lookup<T>& l) noexcept {
    return corrected_roughness(roughness, l.d_shading, l.d_probe, l.cos_shading, l.cos_probe);
}

/// The lobe split (see the header comment): tap i (0..4) of parallax_split_taps.
inline constexpr int parallax_split_taps = 5;

template <class T> struct parallax_tap {
    vec3<T> direction;
    T roughness = T(0);
    T weight = T(0);
};

/// The reflection direction of tap i (clamped to 0..4) for the unit direction r and roughness.
template <class T> IBL_FUNC vec3<T> parallax_split_direction(const vec3<T>& r, T roughness, int i) noexcept {
    if (i <= 0) return r;
    const T rr = saturate(roughness), q = T(0.5) * rr * rr, q2 = q * q;
    const T ct = (T(1) - q2) / (T(1) + q2), st = T(2) * q / (T(1) + q2);
    const T sg = r.z >= T(0) ? T(1) : T(-1), a = T(-1) / (sg + r.z), b = r.x * r.y * a;
    const vec3<T> t(T(1) + sg * r.x * r.x * a, sg * b, -sg * r.x), bt(b, sg + r.y * r.y * a, -r.y);
    const vec3<T> side = i == 1 ? t : i == 2 ? bt : i == 3 ? -t : -bt;
    return ct * r + st * side;
}

template <class T, class Proxy>
IBL_FUNC parallax_tap<T> parallax_split_tap(const Proxy& proxy, const vec3<T>& c, const vec3<T>& p, const vec3<T>& r, T roughness,
                                            int i) noexcept {
    parallax_tap<T> out;
    out.weight = T(1) / T(parallax_split_taps);
    vec3<T> ru = r;
    if (!detail::unit_or_zero(ru)) {
        out.direction = r;
        out.roughness = saturate(roughness);
        return out;
    }
    const T rr = saturate(roughness);
    const parallax_lookup<T> l = parallax_correct(proxy, c, p, parallax_split_direction(ru, rr, i));
    out.direction = l.direction;
    out.roughness = corrected_roughness(rr * std::sqrt(T(0.5)), l);
    return out;
}

/// An influence volume's weight at p: the distance from p to the boundary inside it over the fade
/// width, clamped to [0, 1].
template <class T> IBL_FUNC T influence_weight(const probe_box<T>& box, T fade, const vec3<T>& p) noexcept {
    const vec3<T> o = box.to_local(p);
    T inside = std::numeric_limits<T>::infinity();
    for (int k = 0; k < 3; ++k) {
        const T d = box.half[k] - std::fabs(o[k]);
        inside = d < inside ? d : inside;
    }
    const T f = fade > std::numeric_limits<T>::min() ? fade : std::numeric_limits<T>::min();
    return saturate(inside / f);
}

template <class T> IBL_FUNC T influence_weight(const probe_sphere<T>& s, T fade, const vec3<T>& p) noexcept {
    const vec3<T> o = p - s.center;
    const T inside = s.radius - std::sqrt(glm::dot(o, o));
    const T f = fade > std::numeric_limits<T>::min() ? fade : std::numeric_limits<T>::min();
    return saturate(inside / f);
}

/// Blends n probes (see the header comment): weights[i] in [0, 1] (NaN counts as 0), priorities[i]
/// higher first; writes contributions[i] and returns the fallback's share. Any n; O(n^2) without
/// allocating (probe sets are small).
template <class T>
IBL_FUNC T blend_probe_weights(const T* weights, const int* priorities, std::size_t n, T* contributions) noexcept {
    T remaining = T(1);
    for (std::size_t i = 0; i < n; ++i) contributions[i] = T(0);
    // Walk the distinct priorities from the highest down.
    bool have_prev = false;
    int prev = 0;
    for (;;) {
        bool found = false;
        int level = 0;
        for (std::size_t i = 0; i < n; ++i)
            if ((!have_prev || priorities[i] < prev) && (!found || priorities[i] > level)) {
                level = priorities[i];
                found = true;
            }
        if (!found) break;
        T sum = T(0);
        for (std::size_t i = 0; i < n; ++i)
            if (priorities[i] == level) sum += saturate(weights[i]);
        const T scale = remaining / (sum > T(1) ? sum : T(1));
        T used = T(0);
        for (std::size_t i = 0; i < n; ++i)
            if (priorities[i] == level) {
                contributions[i] = saturate(weights[i]) * scale;
                used += contributions[i];
            }
        remaining = remaining - used > T(0) ? remaining - used : T(0);
        have_prev = true;
        prev = level;
    }
    return remaining;
}

} // namespace ibl

#endif // IBL_DETAIL_CXX20
