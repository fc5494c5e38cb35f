#pragma once
// ibl/bake/specular_occlusion_lut.hpp — the host builder of the visible-fraction table that
// runtime/specular_occlusion.hpp reads (host only, double). The occluded reference that measures
// it is reference/occluded_specular.hpp.
//
// ---- The visible fraction of the lobe (specular_lobe_visible_fraction, the table) --------------
//   For b = n: so(n.v, r, theta_o) = integral_{l.z >= cos theta_o} D V (n.l) dl / integral D V (n.l) dl
//   over the GGX visible normals (h = sample_ggx_vndf(v, u), l = reflect(-v, h), weight
//   V (n.l) up to a constant), a midpoint rule of nodes^2 points in u: the indicator makes it a
//   first-order rule at the cone's boundary (error O(1 / nodes) at worst; the table builder's
//   default 256 nodes agrees with 512 within 1e-3: tests/test_occlusion.cpp). The builder sorts a
//   cell's samples by l.z once and reads every ao threshold cos theta_o = sqrt(1 - ao) from the
//   prefix sums.
//
// Domains: n.v and roughness clamped to [0, 1]; half-angle in [0, pi] (clamped); ao in [0, 1] (clamped).

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <numeric>
#include <stdexcept>
#include <utility>
#include <vector>

#include "../brdf/model.hpp"
#include "../core/executor.hpp"
#include "../core/math.hpp"
#include "../core/vec.hpp"
#include "../runtime/specular_occlusion.hpp"
#include "lobe_moments.hpp"

namespace ibl {

// ---- the visible fraction of the lobe and its table --------------------------------------------

namespace detail {
/// A cell's lobe samples (l.z, weight V (n.l)) sorted by l.z descending, with prefix sums.
struct lobe_height_samples {
    std::vector<double> z, prefix; ///< prefix[k] = sum of the weights of samples 0..k-1
};

template <class Model> lobe_height_samples lobe_heights(double n_dot_v, double roughness, std::uint32_t nodes) {
    const std::uint32_t q = nodes < 1 ? 1 : (nodes > 4096 ? 4096 : nodes);
    const double mu = saturate(n_dot_v), r = saturate(roughness);
    std::vector<std::pair<double, double>> s;
    s.reserve(std::size_t(q) * q);
    for_each_lobe_draw<Model>(mu, r, q, [&](const vec3<double>& l, const vec3<double>&, double vis) {
        s.emplace_back(l.z, vis * l.z);
    });
    std::sort(s.begin(), s.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
    lobe_height_samples out;
    out.z.resize(s.size());
    out.prefix.assign(s.size() + 1, 0.0);
    for (std::size_t k = 0; k < s.size(); ++k) {
        out.z[k] = s[k].first;
        out.prefix[k + 1] = out.prefix[k] + s[k].second;
    }
    return out;
}

/// Share of the weight with l.z >= c.
inline double visible_share(const lobe_height_samples& h, double c) noexcept {
    if (h.prefix.back() <= 0.0) return 1.0;
    const auto it = std::upper_bound(h.z.begin(), h.z.end(), c, [](double x, double z) { return z < x; });
    return h.prefix[std::size_t(it - h.z.begin())] / h.prefix.back();
}
} // namespace detail

/// The visible fraction so(n.v, r, theta_o) of the specular lobe of model M in a cone of
/// half-angle theta_o about n (header); nodes^2 VNDF points (nodes clamped to [1, 4096]).
template <class Model = ggx_height_correlated>
double specular_lobe_visible_fraction(double n_dot_v, double roughness, double half_angle, std::uint32_t nodes = 256) {
    const double to = clamp(half_angle, 0.0, pi_v<double>);
    return detail::visible_share(detail::lobe_heights<Model>(n_dot_v, roughness, nodes), std::cos(to));
}

/// The size^3 table of ibl/runtime/specular_occlusion.hpp for model M (size in [2, 256]; nodes^2 VNDF points per
/// (n.v, r) cell). Throws std::invalid_argument for a size outside [2, 256].
template <class Model = ggx_height_correlated, class Executor = thread_executor>
specular_occlusion_lut make_specular_occlusion_lut(std::uint32_t size, std::uint32_t nodes = 256,
                                                   Executor&& ex = Executor{}) {
    if (size < 2 || size > 256)
        throw std::invalid_argument("ibl::make_specular_occlusion_lut: size must be in [2, 256]");
    specular_occlusion_lut lut;
    lut.size = size;
    lut.data.assign(std::size_t(size) * size * size, 0.0f);
    const double step = 1.0 / double(size - 1);
    ex(std::size_t(size) * size, [&](std::size_t begin, std::size_t end) {
        for (std::size_t c = begin; c < end; ++c) {
            const std::size_t i = c % size, j = c / size;
            const detail::lobe_height_samples h = detail::lobe_heights<Model>(double(i) * step, double(j) * step, nodes);
            for (std::size_t k = 0; k < size; ++k) {
                const double ao = double(k) * step;
                const double so = k == 0 ? 0.0 : (k + 1 == size ? 1.0 : detail::visible_share(h, std::sqrt(1.0 - ao)));
                lut.data[(k * size + j) * size + i] = float(so);
            }
        }
    });
    return lut;
}

} // namespace ibl

#endif // IBL_DETAIL_CXX20
