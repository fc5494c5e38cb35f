#pragma once
// research/lobe_moment_baseline.hpp — the lobe LUT by first-moment matching: per (n.v, r) the DFG
// terms A, B, the lerp factor s towards the lobe's mean direction and the chain roughness r_eff
// whose LD kernel has the lobe's mean resultant length (ibl/bake/lobe_moments.hpp). It ignores
// the horizon; the shipped table is the L1 fit of ibl/bake/lobe_fit.hpp (make_lobe_lut_fitted),
// and this one is kept as the baseline the fit is measured against (docs/runtime.md; produced by
// research/runtime_error.cpp). Not installed, not included by any header under include/.

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <stdexcept>

#include <ibl/bake/dfg_lut.hpp>
#include <ibl/bake/lobe_moments.hpp>
#include <ibl/core/executor.hpp>
#include <ibl/core/limits.hpp>
#include <ibl/runtime/tables.hpp>

namespace ibl {

/// The lobe LUT of model M for a chain baked with weight w (header). A, B from
/// make_dfg_lut_exact (bake/dfg_lut.hpp) in the same layout. size in [1, 1024].
template <class Model = ggx_height_correlated, class Executor = thread_executor>
lobe_lut make_lobe_lut(std::uint32_t size, const dfg_lut_layout& layout, ld_weight w, std::uint32_t nodes = 96,
                       Executor&& ex = Executor{}) {
    detail::check_total("make_lobe_lut", "size", size, 1024u, "1024");
    if (size < 1) throw std::invalid_argument("ibl::make_lobe_lut: size must be >= 1");
    const dfg_lut ab = make_dfg_lut_exact<Model>(size, layout, 2);
    lobe_lut lut;
    lut.size = size;
    lut.weight = w;
    lut.layout = layout;
    lut.data.assign(std::size_t(size) * size * 4, 0.0f);
    ex(std::size_t(size), [&](std::size_t begin, std::size_t end) {
        for (std::size_t j = begin; j < end; ++j) {
            const double r = dfg_texel_value<double>(layout.roughness, std::uint32_t(j), size, layout.edge_aligned);
            for (std::uint32_t i = 0; i < size; ++i) {
                const double mu = dfg_texel_value<double>(layout.n_dot_v, i, size, layout.edge_aligned);
                float* t = &lut.data[(j * size + i) * 4];
                t[0] = ab.data[(j * size + i) * 2];
                t[1] = ab.data[(j * size + i) * 2 + 1];
                if (r <= 0.0) {
                    t[2] = 1.0f;
                    t[3] = 0.0f;
                    continue;
                }
                const lobe_moments m = specular_lobe_moments<Model>(std::min(mu, std::cos(lobe_min_theta)), r, nodes);
                t[2] = float(m.lerp);
                t[3] = float(ld_matched_roughness(m.rho, w));
            }
        }
    });
    return lut;
}

} // namespace ibl
