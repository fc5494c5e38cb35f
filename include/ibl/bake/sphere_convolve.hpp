#pragma once
// ibl/bake/sphere_convolve.hpp — the machinery shared by the prefilter (bake/prefilter.hpp)
// and the irradiance convolution (bake/irradiance.hpp): a spherical convolution of an
// environment with a kernel that is rotationally symmetric about the output direction, evaluated
// from a sample table in tangent space (host only).
//
//   estimate(dir) = scale * sum_i w_i L(F(dir) l_i, lod_i) / norm,   norm = sum_i w_i if normalised
//                                                                          = 1       otherwise
// l_i: unit sample directions in the tangent space of dir (z = dir), F(dir) = make_frame(dir) the
// rotation to world space (Duff et al. 2017; it is discontinuous across the plane dir.z = 0, which
// only permutes the sample pattern's azimuths). w_i > 0: the estimator's weights (samples of weight
// 0 are dropped from the table). lod_i: the source level to read (0 = finest), the same for every
// output texel because a kernel symmetric about dir has pdfs that do not depend on dir.
//
// Two evaluators:
//  * convolve_direction(env, table, dir): any environment (the environment concept), one
//    direction, scalar, double accumulation; env.radiance(dir, lod_i) does the filtering.
//  * the cubemap fast path: the structure-of-arrays kernel of batch/sphere_kernel.hpp over a
//    packed copy of the source (detail::pack_cube). Here each sample with fractional lod is split
//    into two bilinear "taps" on the levels floor(lod) and floor(lod) + 1 with weights w (1 - f)
//    and w f (this is the trilinear lookup; detail::make_taps), so the kernel reads exactly one
//    level per tap; the kernel accumulates in float in blocks of taps, and the normaliser is the
//    sum of the tap weights in the same blocked order, so a source of ones returns exactly 1.
//    convolve_faces hands the face rows to the executor.
//
// Non-finite radiance: the packed copy stores non-finite components as 0; the generic evaluator
// skips non-finite samples (their radiance counts as 0). Outputs are finite for finite weights.
// Determinism: every output texel is a fixed sequence of operations on the table and the source;
// the work partition (executor) never changes a result.

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <type_traits>
#include <vector>

#include "../batch/sphere_kernel.hpp"
#include "../core/executor.hpp"
#include "../core/frame.hpp"
#include "../core/limits.hpp"
#include "../core/math.hpp"
#include "../core/vec.hpp"
#include "../env/cube_geometry.hpp"
#include "../env/cubemap.hpp"
#include "../env/environment.hpp"

namespace ibl {

/// A kernel's sample table in tangent space (z = the output direction). Structure of arrays.
template <class T> struct sphere_sample_table {
    std::vector<T> x, y, z;   ///< unit directions
    std::vector<T> weight;    ///< w_i > 0
    std::vector<T> lod;       ///< source lod to read
    T scale = T(1);           ///< the estimate's constant factor
    bool normalised = true;   ///< divide by sum of weights (else by 1)
    bool trilinear = true;    ///< fast path: blend floor(lod) and floor(lod) + 1 (else round(lod) only)
    std::uint32_t drawn = 0;  ///< samples drawn, including those dropped (weight 0)

    [[nodiscard]] std::size_t size() const noexcept { return weight.size(); }
    void push(const vec3<T>& d, T w, T l) {
        x.push_back(d.x);
        y.push_back(d.y);
        z.push_back(d.z);
        weight.push_back(w);
        lod.push_back(l);
    }
};

/// The estimate at one unit direction for any environment: scale * sum w L / norm, in double.
template <class T, class Env, class S>
    requires environment<Env, T>
[[nodiscard]] vec3<T> convolve_direction(const Env& env, const sphere_sample_table<S>& table, const vec3<T>& dir) {
    const frame<T> fr = make_frame(dir);
    vec3<double> acc(0.0);
    double wsum = 0.0;
    for (std::size_t i = 0; i < table.size(); ++i) {
        const vec3<T> l = fr.to_world(vec3<T>(T(table.x[i]), T(table.y[i]), T(table.z[i])));
        const vec3<double> L(vec3<T>(env.radiance(l, T(table.lod[i]))));
        const double w = double(table.weight[i]);
        wsum += w;
        if (is_finite(L.x) && is_finite(L.y) && is_finite(L.z)) acc += w * L;
    }
    const double norm = table.normalised ? wsum : 1.0;
    return norm > 0.0 ? vec3<T>(acc * (double(table.scale) / norm)) : vec3<T>(T(0));
}

namespace detail {

/// Splits each sample into taps on floor(lod) and floor(lod) + 1 (lod clamped to the chain).
template <class S> tap_table make_taps(const sphere_sample_table<S>& table, int levels) {
    tap_table t;
    const double max_lod = double(levels - 1);
    auto push = [&](std::size_t i, int level, double w) {
        if (!(w > 0.0)) return;
        t.x.push_back(float(table.x[i]));
        t.y.push_back(float(table.y[i]));
        t.z.push_back(float(table.z[i]));
        t.w.push_back(float(w));
        t.level.push_back(level);
    };
    for (std::size_t i = 0; i < table.size(); ++i) {
        const double lod = clamp(double(table.lod[i]), 0.0, max_lod);
        const int l0 = int(lod);
        const double f = lod - double(l0);
        const double w = double(table.weight[i]);
        if (!table.trilinear) {
            push(i, f < 0.5 ? l0 : l0 + 1, w);
            continue;
        }
        push(i, l0, w * (1.0 - f));
        if (f > 0.0) push(i, l0 + 1, w * f);
    }
    const float total = tap_weight_sum(t); // the kernel's blocked order
    const float norm = table.normalised ? total : 1.f;
    t.factor = norm > 0.f ? float(table.scale) / norm : 0.f;
    t.scale = float(table.scale);
    t.normalised = table.normalised;
    return t;
}

} // namespace detail

/// Convolves every texel of an n x n-per-face output (texel centres) with a table, through the
/// executor (work items: face rows). Returns the texels in cubemap order (face, y, x).
/// Cubemap sources take the fast path; other environments the generic evaluator. Throws
/// std::invalid_argument for n < 1, std::length_error for n > limits::max_face_size or
/// 6 n^2 table.size() (x 2 for trilinear tables) > limits::max_work.
template <class Env, class S, class Executor = serial_executor>
std::vector<vec3<float>> convolve_faces(const Env& env, const sphere_sample_table<S>& table, int n,
                                        Executor&& ex = Executor{}) {
    detail::check_arg("convolve_faces", "n", n, 1, limits::max_face_size, "limits::max_face_size");
    detail::check_total("convolve_faces", "taps 6 n^2 samples",
                        detail::work_add(0, 6 * std::uint64_t(n) * std::uint64_t(n),
                                         std::uint64_t(table.size()) * (table.trilinear ? 2u : 1u)),
                        limits::max_work, "limits::max_work");
    std::vector<vec3<float>> out(std::size_t(6) * std::size_t(n) * std::size_t(n));
    if constexpr (requires { detail::pack_cube(env); }) {
        const detail::packed_cube src = detail::pack_cube(env);
        const detail::tap_table taps = detail::make_taps(table, int(src.levels.size()));
        ex(std::size_t(6 * n), [&](std::size_t b, std::size_t e) {
            for (std::size_t row = b; row < e; ++row)
                detail::convolve_row(src, taps, int(row) / n, int(row) % n, n, out.data() + row * std::size_t(n));
        });
    } else {
        using Te = std::conditional_t<environment<Env, float>, float, double>;
        ex(std::size_t(6 * n), [&](std::size_t b, std::size_t e) {
            for (std::size_t row = b; row < e; ++row) {
                const int face = int(row) / n, y = int(row) % n;
                for (int x = 0; x < n; ++x)
                    out[row * std::size_t(n) + std::size_t(x)] =
                        vec3<float>(convolve_direction<Te>(env, table, cube_texel_direction<Te>(face, x, y, n)));
            }
        });
    }
    return out;
}

} // namespace ibl

#endif // IBL_DETAIL_CXX20
