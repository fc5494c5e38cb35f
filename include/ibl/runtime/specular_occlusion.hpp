#pragma once
// ibl/runtime/specular_occlusion.hpp — specular occlusion at run time from the visible fraction of the specular
// lobe (value functions; the table is built by reference/occluded_specular.hpp).
//
// ---- The quantity -------------------------------------------------------------------------------
//   A shading point at normal n sees the environment inside a cone of half-angle theta_o about n
//   (the visibility model of reference/occluded_specular.hpp with the bent normal b = n). Its ambient
//   occlusion, the cosine-weighted visible fraction, is ao = sin^2 theta_o, so the cone is known
//   from ao alone: cos theta_o = sqrt(1 - ao). The specular occlusion factor is the share of the
//   specular lobe p(l) = D V (n.l) (Fresnel excluded) that falls inside the cone,
//       so(n.v, r, ao) = integral_{l.n >= cos theta_o} D V (n.l) dl / integral_H D V (n.l) dl,
//   and the occluded specular is so times the unoccluded one (split sum or any other model): it is
//   exact for a constant environment up to the lobe's Fresnel weighting (the table is Fresnel
//   free), and for any environment whose radiance is uncorrelated with the lobe's shape inside it.
//   so rises from 0 (ao = 0) to 1 (ao = 1), is 1 for a mirror whose reflection n.v >= cos theta_o,
//   and tends to the lobe's cosine-weighted share ~ ao for wide lobes.
//
// ---- The table --------------------------------------------------------------------------------
//   specular_occlusion_lut: size^3 samples on an edge-aligned grid: texel (i, j, k) holds so at
//   n.v = i / (size - 1), r = j / (size - 1), ao = k / (size - 1) (perceptual roughness r,
//   alpha = r^2). specular_occlusion_table reads it trilinearly (a 3-D texture with clamp-to-edge
//   and linear filtering at coordinate (x (size - 1) + 0.5) / size does the same in a shader).
//   Inputs are clamped to [0, 1]; the result is clamped to [0, 1].
//
// Domains: n.v, r, ao in [0, 1] (clamped); a null or smaller than 2^3 table reads 1 (no occlusion). IBL_FUNC on a raw pointer (device code may read a
// table in its own memory); the overload on specular_occlusion_lut is a host function.

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <cstddef>
#include <cstdint>
#include <vector>

#include "../core/math.hpp"
#include "../core/vec.hpp"

namespace ibl {

/// The visible fraction of the specular lobe per (n.v, r, ao) (header).
struct specular_occlusion_lut {
    std::uint32_t size = 0;  ///< samples per axis (>= 2)
    std::vector<float> data; ///< so at index (k * size + j) * size + i (i: n.v, j: r, k: ao)
};

/// Trilinear read of a size^3 specular-occlusion table (header); size >= 2, inputs clamped to [0, 1].
template <class T>
IBL_FUNC T specular_occlusion_table(const float* data, std::uint32_t size, T n_dot_v, T roughness,
                                    T ambient_occlusion) noexcept {
    if (data == nullptr || size < 2) return T(1); // no table: no occlusion
    const T s = T(size - 1);
    const T x[3] = {saturate(n_dot_v) * s, saturate(roughness) * s, saturate(ambient_occlusion) * s};
    std::uint32_t i0[3];
    T f[3];
    for (int a = 0; a < 3; ++a) {
        std::uint32_t i = std::uint32_t(x[a]);
        if (i > size - 2) i = size - 2;
        i0[a] = i;
        f[a] = x[a] - T(i);
    }
    T out = T(0);
    for (int c = 0; c < 8; ++c) {
        const std::uint32_t di = std::uint32_t(c & 1), dj = std::uint32_t((c >> 1) & 1), dk = std::uint32_t((c >> 2) & 1);
        const T w = (di ? f[0] : T(1) - f[0]) * (dj ? f[1] : T(1) - f[1]) * (dk ? f[2] : T(1) - f[2]);
        const std::size_t idx = (std::size_t(i0[2] + dk) * size + (i0[1] + dj)) * size + (i0[0] + di);
        out += w * T(data[idx]);
    }
    return saturate(out);
}

/// The bent-normal reading (header of docs/occlusion.md: "lobe LUT, bent"): the table at
/// (saturate(b.R), r, min(1, ao / b.n)) for a visibility cone about the unit bent normal b, R =
/// reflect(-v, n): the lobe's direction measured from the cone's axis and the cone's own aperture
/// (ao = cos(beta) sin^2 theta_o inverted without the horizon clip); b.n <= 0 reads ao' = 1.
/// Equal to the plain table for b = n. GLSL: ibl_specular_occlusion_bent.
template <class T>
IBL_FUNC T specular_occlusion_bent(const float* data, std::uint32_t size, const vec3<T>& n, const vec3<T>& v,
                                   const vec3<T>& bent_normal, T roughness, T ambient_occlusion) noexcept {
    const vec3<T> r_dir = T(2) * glm::dot(n, v) * n - v;
    const T b_r = saturate(glm::dot(bent_normal, r_dir));
    const T b_n = glm::dot(bent_normal, n);
    const T a = b_n > T(0) ? saturate(ambient_occlusion) / b_n : T(1);
    return specular_occlusion_table(data, size, b_r, roughness, a < T(1) ? a : T(1));
}

/// specular_occlusion_table on a host table (host function).
template <class T>
T specular_occlusion_lookup(const specular_occlusion_lut& lut, T n_dot_v, T roughness, T ambient_occlusion) noexcept {
    return specular_occlusion_table(lut.data.data(), lut.size, n_dot_v, roughness, ambient_occlusion);
}

} // namespace ibl

#endif // IBL_DETAIL_CXX20
