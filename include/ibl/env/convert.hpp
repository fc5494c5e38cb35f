#pragma once
// ibl/env/convert.hpp — any environment -> cubemap by supersampled evaluation (host only).
//
// Each texel of level 0 is the solid-angle-weighted mean of the radiance at k x k sub-sample
// points: the centres of a regular k x k grid over the texel in (s, t). The weight of a sub-sample
// is the solid-angle density of the face at its centre, d(omega)/d(sc)d(tc) = (1 + sc^2 + tc^2)^-3/2
// (the midpoint rule for the texel's integral; the exact texel solid angle divides it out). The
// mean is accumulated in double as ref + sum w (L - ref) / sum w with ref the first sample, so a
// constant environment bakes to exactly that constant. Then the mip chain is generated
// (cubemap::generate_mips). Every texel is computed independently of the others and of the
// partition of the work: the result is deterministic for any executor.
//
// Cost: 6 n^2 k^2 radiance evaluations. Accuracy: the texel mean of a smooth environment, with a
// quadrature error O((1 / (n k))^2) per texel; a hard-edged feature (a sun disk) is resolved to
// 1 / k^2 of a texel's area.

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "../core/executor.hpp"
#include "../core/limits.hpp"
#include "../core/vec.hpp"
#include "cube_geometry.hpp"
#include "cubemap.hpp"
#include "environment.hpp"

namespace ibl {

namespace detail {
/// The arguments of a bake of face size n with k x k sub-samples, checked for function `fn`:
/// n in [1, limits::max_face_size], k in [1, limits::max_subsamples], 6 n^2 k^2 <= limits::max_work.
inline void check_bake_args(const char* fn, int n, int k) {
    check_arg(fn, "face size n", n, 1, limits::max_face_size, "limits::max_face_size");
    check_arg(fn, "sub-samples per axis k", k, 1, limits::max_subsamples, "limits::max_subsamples");
    const std::uint64_t nn = std::uint64_t(n), kk = std::uint64_t(k);
    check_total(fn, "sub-samples 6 n^2 k^2", 6 * nn * nn * kk * kk, limits::max_work, "limits::max_work");
}
} // namespace detail

/// Mean radiance over texel (x, y) of face `face` of an n x n cube: k x k sub-samples on a regular
/// grid in (sc, tc), weighted by the face's solid-angle density (1 + sc^2 + tc^2)^(-3/2), the
/// environment evaluated at `lod` in its own scalar type (environment_scalar_t), sums in double.
/// Accumulated as ref + sum w (L - ref) / sum w with ref the first sub-sample, so a constant
/// environment comes back bit for bit. Throws std::invalid_argument / std::length_error for n or
/// k outside [1, limits::max_face_size] / [1, limits::max_subsamples], face outside [0, 6) or
/// (x, y) outside the face.
template <class Env>
vec3<double> cube_texel_mean(const Env& env, int face, int x, int y, int n, int k, double lod = 0.0) {
    detail::check_arg("cube_texel_mean", "n", n, 1, limits::max_face_size, "limits::max_face_size");
    detail::check_arg("cube_texel_mean", "k", k, 1, limits::max_subsamples, "limits::max_subsamples");
    if (face < 0 || face > 5 || x < 0 || x >= n || y < 0 || y >= n)
        throw std::invalid_argument("ibl::cube_texel_mean: texel (face " + std::to_string(face) + ", " +
                                    std::to_string(x) + ", " + std::to_string(y) + ") outside a cube of face size " +
                                    std::to_string(n));
    using Te = environment_scalar_t<Env>;
    const double inv_nk = 1.0 / (double(n) * double(k));
    vec3<double> ref(0.0), acc(0.0);
    double wsum = 0.0;
    for (int j = 0; j < k; ++j) {
        const double tc = 2.0 * (double(y * k + j) + 0.5) * inv_nk - 1.0;
        for (int i = 0; i < k; ++i) {
            const double sc = 2.0 * (double(x * k + i) + 0.5) * inv_nk - 1.0;
            const double r2 = 1.0 + sc * sc + tc * tc;
            const double w = 1.0 / (r2 * std::sqrt(r2));
            const vec3<double> d = cube_face_point(face, sc, tc) / std::sqrt(r2);
            const vec3<double> l(vec3<Te>(env.radiance(vec3<Te>(d), Te(lod))));
            if (i == 0 && j == 0) ref = l;
            acc += w * (l - ref);
            wsum += w;
        }
    }
    return ref + acc / wsum;
}

/// Bakes `env` (evaluated at `lod`) into a cubemap of face size n with `levels` mip levels
/// (0 = full chain) using k x k sub-samples per level-0 texel. Throws std::invalid_argument for
/// n < 1, k < 1 or a bad level count, std::length_error for n > limits::max_face_size,
/// k > limits::max_subsamples, 6 n^2 k^2 > limits::max_work or a cube above limits::max_texels.
template <class T, class Env, class Executor = thread_executor>
    requires environment<Env, T>
cubemap<T> bake_cubemap(const Env& env, int n, int k, Executor&& ex = Executor{}, int levels = 0, T lod = T(0)) {
    detail::check_bake_args("bake_cubemap", n, k);
    cubemap<T> cube(n, levels); // validates levels and the storage
    // Rows are written to a scratch buffer (not to the cubemap) so workers share no state.
    std::vector<vec3<T>> base(std::size_t(6) * std::size_t(n) * std::size_t(n));
    ex(std::size_t(6 * n), [&](std::size_t row_begin, std::size_t row_end) {
        for (std::size_t row = row_begin; row < row_end; ++row) {
            const int face = int(row) / n, y = int(row) % n;
            for (int x = 0; x < n; ++x) {
                base[row * std::size_t(n) + std::size_t(x)] = vec3<T>(cube_texel_mean(env, face, x, y, n, k, double(lod)));
            }
        }
    });
    cube.fill(0, [&](int face, int x, int y) { return base[cube_texel_index(face, x, y, n)]; });
    cube.generate_mips(ex);
    return cube;
}

} // namespace ibl

#endif // IBL_DETAIL_CXX20
