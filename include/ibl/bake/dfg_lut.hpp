#pragma once
// ibl/bake/dfg_lut.hpp — the DFG look-up table: generation (exact or Monte Carlo) through the
// batch kernels and an executor, layout, and bilinear lookup (host only).
//
// Layout (float32, interleaved channels, row-major): data[(j * size + i) * channels + c], row j
// one roughness, row 0 first in memory (uploaded as is, row 0 is the texture's first row, v = 0
// in GL/Vulkan/D3D texel addressing). Which (n.v, r) a texel holds is the table's `layout`
// (runtime/dfg_layout.hpp), recorded in the table and read from it by every lookup:
//   the default, dfg_lut_layout::uniform() (the textbook table):
//     texel (i, j): n.v = (i + 0.5) / size, r = (j + 0.5) / size (texel centres: r = 0 and n.v = 0
//     themselves are half a texel outside, as in a GPU texture sampled with clamp-to-edge), so a
//     shader samples texture(lut, vec2(n.v, r));
//   dfg_lut_layout::remapped() (the accurate table): cbrt(n.v) x sqrt(r), edge aligned, sampled at
//     dfg_lut_coord(n.v, r, size, layout).
// The table also records the BRDF model it integrates (`model`: Model::name, "custom" for a
// model without one).
//   channel 0 = A (scale of F0), 1 = B (bias, scale of F90), 2 (optional) = k = (1 - E)/E,
//   E = A + B: Turquin's multiple-scattering compensation (bake/dfg_multiscatter.hpp).
//
// Work: rows are independent and go through the executor (core/executor.hpp); within a row the
// batch kernels take W texels at a time (W = 8 doubles for the quadrature, 16 floats for Monte
// Carlo), the remainder at W = 1. Which texels share a kernel call depends only on size, never on
// the executor, so the table is bit-identical for every partition and thread count.

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "../batch/dfg_kernel.hpp"
#include "../core/executor.hpp"
#include "../core/limits.hpp"
#include "../core/math.hpp"
#include "../core/vec.hpp"
#include "dfg.hpp"
#include "../runtime/dfg_layout.hpp"
#include "dfg_multiscatter.hpp"
#include "../runtime/tables.hpp"

namespace ibl {

namespace detail {
template <class Model> std::string model_name() {
    if constexpr (requires { Model::name; }) return std::string(Model::name);
    else return "custom";
}
} // namespace detail

/// Node counts used for tables (weights evaluated in float, see dfg_quadrature_lanes): 432 weight
/// evaluations per texel, a 128^2 float table inside the 1e-5 target against a converged double
/// reference (figures: docs/ARCHITECTURE.md, "Split-sum DFG").
inline constexpr dfg_quadrature_nodes dfg_lut_default_nodes{12, 12, 24, 12};

namespace detail {
template <class T> void dfg_store(dfg_lut& lut, std::uint32_t i, std::uint32_t j, double e, double b) {
    float* p = &lut.data[(std::size_t(j) * lut.size + i) * lut.channels];
    p[0] = float(e - b);
    p[1] = float(b);
    if (lut.channels > 2) p[2] = float(dfg_energy_compensation(e));
}
} // namespace detail

namespace detail {
/// size in [1, limits::max_dfg_lut_size], channels 2 or 3, size^2 * per_texel <= limits::max_work.
inline void check_dfg_lut_args(const char* fn, std::uint32_t size, std::uint32_t channels, std::uint64_t per_texel,
                               const char* per_texel_name) {
    check_arg(fn, "size", size, 1u, limits::max_dfg_lut_size, "limits::max_dfg_lut_size");
    if (channels != 2 && channels != 3)
        throw std::invalid_argument(std::string("ibl::") + fn + ": channels must be 2 or 3, got " +
                                    std::to_string(channels));
    check_total(fn, per_texel_name, work_add(0, std::uint64_t(size) * size, per_texel), limits::max_work,
                "limits::max_work");
}
} // namespace detail

/// The exact table of model M (quadrature in double) in a layout, channels 2 or 3: texel (i, j)
/// holds the quadrature at n.v = dfg_texel_value(layout.n_dot_v, i, ...), r =
/// dfg_texel_value(layout.roughness, j, ...); the table records the layout and Model::name.
/// Throws std::invalid_argument for size 0, channels other than 2 or 3 or a zero node count,
/// std::length_error for size > limits::max_dfg_lut_size, a node count above
/// limits::max_quadrature_nodes or size^2 * nodes.evaluations() > limits::max_work.
template <class Model, class Executor = thread_executor>
dfg_lut make_dfg_lut_exact(std::uint32_t size, const dfg_lut_layout& layout, std::uint32_t channels = 3,
                           dfg_quadrature_nodes nodes = dfg_lut_default_nodes, Executor&& ex = Executor{}) {
    detail::check_dfg_nodes("make_dfg_lut_exact", nodes);
    detail::check_dfg_lut_args("make_dfg_lut_exact", size, channels, nodes.evaluations(), "evaluations size^2 * nodes");
    constexpr std::size_t W = 16;
    dfg_lut lut{size, channels, {}, layout, detail::model_name<Model>()};
    lut.data.assign(std::size_t(size) * size * lut.channels, 0.0f);
    const dfg_quadrature_rule rule(nodes);
    const dfg_quadrature_view q = rule.view();
    ex(std::size_t(size), [&](std::size_t begin, std::size_t end) {
        for (std::size_t j = begin; j < end; ++j) {
            const double r = lut.roughness(std::uint32_t(j));
            if (r <= 0.0) { // the mirror row of an edge-aligned table: the r -> 0 limit in closed form,
                            // E = 1 and B = (1 - n.v)^5 (the quadrature degenerates at n.v = r = 0)
                for (std::uint32_t i = 0; i < size; ++i)
                    detail::dfg_store<double>(lut, i, std::uint32_t(j), 1.0, pow5(1.0 - lut.n_dot_v(i)));
                continue;
            }
            std::uint32_t i = 0;
            for (; i + W <= size; i += W) {
                double mu[W], e[W], b[W];
                for (std::size_t l = 0; l < W; ++l) mu[l] = lut.n_dot_v(i + std::uint32_t(l));
                dfg_quadrature_lanes<Model, W, float>(q, r, mu, e, b);
                for (std::size_t l = 0; l < W; ++l) detail::dfg_store<double>(lut, i + std::uint32_t(l), std::uint32_t(j), e[l], b[l]);
            }
            for (; i < size; ++i) {
                const double mu = lut.n_dot_v(i);
                double e, b;
                dfg_quadrature_lanes<Model, 1, float>(q, r, &mu, &e, &b);
                detail::dfg_store<double>(lut, i, std::uint32_t(j), e, b);
            }
        }
    });
    return lut;
}

/// The exact table of model M in the default (textbook) layout, dfg_lut_layout::uniform().
template <class Model, class Executor = thread_executor>
dfg_lut make_dfg_lut_exact(std::uint32_t size, std::uint32_t channels = 3, dfg_quadrature_nodes nodes = dfg_lut_default_nodes,
                           Executor&& ex = Executor{}) {
    return make_dfg_lut_exact<Model>(size, dfg_lut_layout::uniform(), channels, nodes, std::forward<Executor>(ex));
}

/// The Monte Carlo table of model M: `samples` Hammersley points with GGX-NDF sampling per texel
/// (the literature's estimator, float), one sample table per row shared by its texels, in the
/// default (textbook) layout.
/// Channels 2 or 3 (k from the Monte Carlo E). Throws std::invalid_argument for size 0, samples 0
/// (E = 0: k = inf) or channels other than 2 or 3, std::length_error for size >
/// limits::max_dfg_lut_size, samples > limits::max_samples or size^2 * samples > limits::max_work.
template <class Model, class Executor = thread_executor>
dfg_lut make_dfg_lut_mc(std::uint32_t size, std::uint32_t samples, std::uint32_t channels = 2, Executor&& ex = Executor{}) {
    detail::check_arg("make_dfg_lut_mc", "samples", samples, 1u, limits::max_samples, "limits::max_samples");
    detail::check_dfg_lut_args("make_dfg_lut_mc", size, channels, samples, "evaluations size^2 * samples");
    constexpr std::size_t W = 16;
    dfg_lut lut{size, channels, {}, dfg_lut_layout::uniform(), detail::model_name<Model>()};
    lut.data.assign(std::size_t(size) * size * lut.channels, 0.0f);
    ex(std::size_t(size), [&](std::size_t begin, std::size_t end) {
        for (std::size_t j = begin; j < end; ++j) {
            const float r = float(lut.roughness(std::uint32_t(j)));
            const dfg_sample_table<float> tab = make_dfg_sample_table(Model::alpha(r), samples);
            std::uint32_t i = 0;
            for (; i + W <= size; i += W) {
                float mu[W], e[W], b[W];
                for (std::size_t l = 0; l < W; ++l) mu[l] = float(lut.n_dot_v(i + std::uint32_t(l)));
                dfg_mc_lanes<Model, W>(tab.hx.data(), tab.hz.data(), samples, r, mu, e, b);
                for (std::size_t l = 0; l < W; ++l) detail::dfg_store<float>(lut, i + std::uint32_t(l), std::uint32_t(j), e[l], b[l]);
            }
            for (; i < size; ++i) {
                const float mu = float(lut.n_dot_v(i));
                float e, b;
                dfg_mc_lanes<Model, 1>(tab.hx.data(), tab.hz.data(), samples, r, &mu, &e, &b);
                detail::dfg_store<float>(lut, i, std::uint32_t(j), e, b);
            }
        }
    });
    return lut;
}

} // namespace ibl

#endif // IBL_DETAIL_CXX20
