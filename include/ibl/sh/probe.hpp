#pragma once
// ibl/sh/probe.hpp — irradiance at a point from nearby SH probes.
//
// SH coefficients are linear in the radiance, so interpolating coefficients interpolates the
// irradiance (and the radiance) with the same weights; the weights below are non-negative and sum
// to 1, so non-negative probes give non-negative blends and a constant field is reproduced exactly.
//
//   Regular grid (probe_grid):  probe (i, j, k) sits at origin + (i, j, k) * spacing, stored at
//       linear index i + nx (j + ny k). Trilinear weights of the 8 probes of the cell containing p;
//       p outside the grid box is clamped to it (clamp-to-edge), an axis with a single probe has
//       weight 1 on it. Reproduces fields linear in position exactly inside the box.
//   Scattered probes: inverse-distance weights w_i = d_i^-power / sum_j d_j^-power (Shepard);
//       a probe at distance 0 (exactly) takes the whole weight. Interpolates the probe values.

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <cmath>

#include "../core/math.hpp"
#include "../core/vec.hpp"
#include "basis.hpp"

namespace ibl {

template <class T> struct probe_grid {
    vec3<T> origin;  ///< position of probe (0, 0, 0)
    vec3<T> spacing; ///< distance between neighbouring probes along x, y, z (> 0)
    int nx = 1, ny = 1, nz = 1;
};

/// The (at most) 8 probes of a trilinear lookup and their weights (sum 1).
template <class T> struct probe_weights {
    int index[8];
    T weight[8];
};

/// Trilinear weights of position p on the grid (clamped to the grid box).
template <class T> IBL_FUNC probe_weights<T> probe_grid_weights(const probe_grid<T>& g, const vec3<T>& p) noexcept {
    using std::floor;
    int i0[3], i1[3];
    T f[3];
    const int dims[3] = {g.nx, g.ny, g.nz};
    for (int a = 0; a < 3; ++a) {
        const int n = dims[a];
        const T u = n > 1 ? clamp((p[a] - g.origin[a]) / g.spacing[a], T(0), T(n - 1)) : T(0);
        int base = int(floor(u));
        if (base > n - 2) base = n > 1 ? n - 2 : 0; // u = n - 1 exactly: last cell, fraction 1
        i0[a] = base;
        i1[a] = n > 1 ? base + 1 : base;
        f[a] = n > 1 ? u - T(base) : T(0);
    }
    probe_weights<T> w;
    for (int c = 0; c < 8; ++c) {
        const int ix = c & 1 ? i1[0] : i0[0], iy = c & 2 ? i1[1] : i0[1], iz = c & 4 ? i1[2] : i0[2];
        w.index[c] = ix + g.nx * (iy + g.ny * iz);
        w.weight[c] = (c & 1 ? f[0] : T(1) - f[0]) * (c & 2 ? f[1] : T(1) - f[1]) * (c & 4 ? f[2] : T(1) - f[2]);
    }
    return w;
}

/// sum_i weight[i] probes[index[i]] over `count` entries.
template <class T, int B>
IBL_FUNC sh_coeffs<T, B> sh_blend(const sh_coeffs<T, B>* probes, const int* index, const T* weight, int count) noexcept {
    sh_coeffs<T, B> r;
    for (int i = 0; i < count; ++i)
        for (int k = 0; k < B * B; ++k) r.c[k] += weight[i] * probes[index[i]].c[k];
    return r;
}

/// Trilinear interpolation of the grid's probes (probes[i + nx (j + ny k)]) at p.
template <class T, int B>
IBL_FUNC sh_coeffs<T, B> sh_interpolate_grid(const probe_grid<T>& g, const sh_coeffs<T, B>* probes, const vec3<T>& p) noexcept {
    const probe_weights<T> w = probe_grid_weights(g, p);
    return sh_blend(probes, w.index, w.weight, 8);
}

/// Inverse-distance (Shepard) interpolation of `count` >= 1 scattered probes at p. The weights are
/// formed as (d_min / d_i)^power <= 1, so no power of a tiny distance overflows.
template <class T, int B>
IBL_FUNC sh_coeffs<T, B> sh_interpolate_idw(const vec3<T>& p, const vec3<T>* positions, const sh_coeffs<T, B>* probes,
                                            int count, T power = T(2)) noexcept {
    using std::pow;
    auto dist2 = [&](int i) {
        const vec3<T> d = positions[i] - p;
        return glm::dot(d, d);
    };
    int nearest = 0;
    for (int i = 1; i < count; ++i)
        if (dist2(i) < dist2(nearest)) nearest = i;
    const T d2_min = dist2(nearest);
    if (!(d2_min > T(0))) return probes[nearest];
    sh_coeffs<T, B> r;
    T total = T(0);
    for (int i = 0; i < count; ++i) {
        const T w = pow(d2_min / dist2(i), T(0.5) * power);
        total += w;
        for (int k = 0; k < B * B; ++k) r.c[k] += w * probes[i].c[k];
    }
    return (T(1) / total) * r; // total >= 1 (the nearest probe has weight 1)
}

} // namespace ibl

#endif // IBL_DETAIL_CXX20
