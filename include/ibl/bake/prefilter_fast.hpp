#pragma once
// ibl/bake/prefilter_fast.hpp — the fast filter: a small deterministic tap set per roughness,
// shaped offline against the exact LD kernel, read from the source's exact-solid-angle mip chain
// (host only). prefilter() runs it with prefilter_options::method = prefilter_method::fast; it
// shares the chain, the level plan, the LD weights, the lobes and the kernel of filtered
// importance sampling (bake/prefilter.hpp), and only the table differs.
//
// Derivation. The LD kernel of a lobe L about R (bake/prefilter.hpp) depends only on the angle
// theta between l and R: with h = (sin(theta/2), 0, cos(theta/2)) in tangent space,
//     K(theta) = pdf_l(h) w(cos theta) L::ld_weight(h),   w = n.l (Karis) or G1(n.l) (ld_weight::g1),
// and LD(R) = integral L(l) K dl / integral K dl over theta < pi/2. The fast table is a spiral
// quadrature of K with N samples: sample i sits at the radius where the radial CDF
//     C(theta) = integral_0^theta K sin / integral_0^(pi/2) K sin
// reaches g((i + 1/2) / N), g(x) = 1 - (1 - x)^tail (tail > 1 moves samples into the heavy GGX
// tail), at azimuth i times the golden angle; its weight is its kernel mass g((i + 1)/N) - g(i/N)
// and it reads the source at the lod of its share of the sphere, mass / density,
//     lod = 0.5 log2(Omega_i 4^lod_bias / Omega_0),
// the filtered importance sampling rule (Krivanek-Colbert) with the quadrature's cells. Unlike
// Hammersley draws, the spiral has no noise: every radius of the CDF is visited once, in order.
// The CDF is tabulated on 4097 geometric radii (trapezoid rule in double).
//
// The shape (tail, lod_bias) per LD weight, roughness and N is fitted offline
// (research/fast_filter_fit.cpp, which writes bake/prefilter_fast_tables.hpp) on natural
// illumination: synthetic environments with the statistics of real illumination maps (Dror,
// Willsky & Adelson 2004: log-luminance of about 1 / f^2 power spectrum, a bright sky over a
// darker ground, compact lights), the objective being the relative RMSE of the filtered luminance
// against the exact LD of each source (ibl::ld_texel_sum) at random texels, read from the nearest
// level as the default plan reads. fast_shape() picks the row of the nearest tabulated roughness
// and the largest tabulated N within the level's samples; the table is then built with the level's
// samples. Each row records filtered importance sampling's error at the same N (twice the taps:
// trilinear reads): 359 of the 360 rows are below it, the other 3.2% above. A first fit on a
// point light (one bright texel on a darker surround; fast_filter_fit --objective point) chose
// coarser reads, which real HDRIs punish (docs/ibl-bake.md, "Fast filter").
//
// Coarse tail (prefilter_options::coarse_tail, on by default). The GGX LD kernel's tail is heavy
// (K ~ alpha^2 / theta^4 for theta >> alpha: at r = 0.2 a sixth of its mass lies beyond 0.2 rad),
// so a small tap set either spends most of its samples far from the core or reads the tail from
// coarse mips that leak whatever is bright nearby (a sky into a dark ground). The next level of
// the chain, LD_next = integral L K_next / Z_next, already holds that tail: with
//     c = min over theta in (0, pi/2] of K(theta) / K_next(theta),     K_rest = K - c K_next >= 0,
//     LD(R) = (Z_rest / Z) [integral L K_rest / Z_rest](R) + (c Z_next / Z) LD_next(R),
// (Z the integrals over the hemisphere; the two weights add to 1, share = c Z_next / Z), and
// for n.l the minimum is at theta = pi/2, c = (a^2 / b^2) ((1 + b^2) / (1 + a^2))^2 (a, b the two
// alphas), so K_rest falls as a^2 b^2 / theta^6: its mass beyond theta is O(a^2 b^2 / theta^4)
// against O(a^2 / theta^2) for K. The tap set is the spiral of K_rest (its radial CDF, the same
// shapes) with scale 1 - share, and LD_next is one bilinear read of the finished next level at the
// texel centre (the levels are filtered coarse to fine). With the peak split (prefilter_peaks.hpp)
// L = base + peaks: the tail reads the next level before its peaks were added (its base part) and
// every level adds the peaks through its own whole kernel in closed form, so a sun is never
// interpolated from a coarser level (reading the next level with its sun smoothed the kink of its
// n.l cut-off: the sky's level 3 of a 256^2 chain went 0.0038 -> 0.016). A level reads its tail
// only from a next level of face >= 16 (prefilter_coarse_tail_min_face): the bilinear read of
// coarser texels costs more than the tail saves. Measured (research/fast_tap_study.cpp,
// docs/ibl-bake.md "Fast filter"): on two HDRIs it lowers levels 1-3 of a 256^2 chain by 1.1-2x at
// the same samples.
//
// Intermediate coarse tail (prefilter_options::mid_tail, on by default; cubemap sources, GGX).
// The next level's kernel lies under a sharp level's for little of its mass (c Z_next / Z = 5.8 %
// at r = 0.2 under r = 0.4), so the rest kernel keeps most of the tail. The split above holds for
// any wider kernel: a level at r <= mid_tail.max_roughness reads its tail from an intermediate
// level at r_m = r + position (r_next - r) (0.22 for 0.2 and 0.4), with c and the rest kernel of
// K and K_m (a larger share of K), and the intermediate level is filtered like any level (its tap
// set of mid times the level's samples, its own coarse tail from the next level, no peaks: the
// level that reads it adds them through its own kernel) on the next level's face, a quarter of
// the level's texels. The level's own tap set covers the narrower rest with own times its samples
// (24 + 64 / 4 = 40 taps a texel for the default 64). The intermediate level is read bilinearly
// at the level's texel centres, which needs its face to resolve K_m: only where the full width at
// half maximum of K_m (ggx_ld_fwhm) spans at least min_texels (3) texels of the face centre
// (2 / face radians): a 256^2 chain's level 1 (64^2, 4 texels), not a 128^2 one's (2 texels,
// where it raised level 1's error on two of three sources; docs/ibl-bake.md "Fast filter", and
// research/fast_mid_tail_study). It is not part of the output; prefilter_update computes it as
// work units just before the level that reads it, so the two still give the same bits.
//
// Cost: N samples per texel (one bilinear tap each from the nearest level, the default plan's
// reads; two with trilinear reads). The default schedule is fast_default_samples * 4^(l - 1), at
// most prefilter_max_scheduled_samples (equal_cost_prefilter_samples: every level costs the taps of
// level 1, since level l has a quarter of the texels of level l - 1), against 512 * 2^(l - 1)
// trilinear samples for filtered importance sampling. Doubling (as filtered importance sampling
// does) left levels 2-5 of real HDRIs 1.9-2.5x above the default filter's error; quadrupling puts
// every level below it for about 2.5x the taps of doubling (docs/ibl-bake.md, "Fast filter").
// Error and time: docs/ibl-bake.md ("Fast filter") and bench/bench_prefilter.cpp.
//
// Determinism: the table depends only on the roughness, N, the weight and the source's lod
// mapping; the kernel and the work partition are those of the filtered importance sampling path,
// so prefilter and prefilter_update give the same bits.

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <span>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

#include "../brdf/ggx.hpp"
#include "../core/constants.hpp"
#include "../core/limits.hpp"
#include "../core/vec.hpp"
#include "../runtime/ld_weight.hpp"
#include "../sampling/lobe.hpp"
#include "prefilter_fast_tables.hpp"
#include "sphere_convolve.hpp"

namespace ibl {

/// The lobe's angular scale s(r) = 2 atan(max(r^2, 1e-3)): the angle of l where GGX falls to a
/// quarter of its peak (the radial CDF's grid starts at 1e-6 s(r)).
inline double fast_lobe_scale(double roughness) noexcept {
    return 2.0 * std::atan(std::max(alpha_from_roughness(roughness), 1e-3));
}

/// Samples per texel at level 1 of the fast filter's default schedule (four times as many per
/// coarser level: equal_cost_prefilter_samples, default_prefilter_samples): an eighth of filtered
/// importance sampling's default, read from the nearest level (one tap each: a sixteenth of its
/// taps at level 1). At equal taps, nearest reads of twice the samples are the more accurate
/// (docs/ibl-bake.md, "Fast filter", has the error and time).
inline constexpr std::uint32_t fast_default_samples = 64;

/// The tabulated shape (bake/prefilter_fast_tables.hpp) for a weight, a roughness and a sample
/// budget: among the rows of that weight, those of the largest tabulated budget <= samples (the
/// smallest budget when none is), at the tabulated roughness nearest to r (r clamped to [0, 1];
/// ties to the smaller). An empty table gives the default shape.
inline fast_tap_shape fast_shape(double roughness, std::uint32_t samples, ld_weight weight = ld_weight::n_dot_l,
                                 std::span<const fast_shape_row> rows = fast_shape_rows) noexcept {
    const double r = std::clamp(std::isfinite(roughness) ? roughness : 0.0, 0.0, 1.0);
    std::uint32_t budget = 0, smallest = 0xffffffffu;
    for (const fast_shape_row& row : rows) {
        if (row.weight != weight) continue;
        smallest = std::min(smallest, row.budget);
        if (row.budget <= samples) budget = std::max(budget, row.budget);
    }
    if (budget == 0) budget = smallest;
    const fast_shape_row* best = nullptr;
    for (const fast_shape_row& row : rows)
        if (row.weight == weight && row.budget == budget &&
            (!best || std::fabs(row.roughness - r) < std::fabs(best->roughness - r)))
            best = &row;
    return best ? best->shape : fast_tap_shape{};
}

namespace detail {
/// The LD kernel of lobe L at angle theta from R (per unit solid angle of l, not normalised).
template <class Lobe> double fast_kernel(double theta, double roughness, ld_weight weight) noexcept {
    const double n_dot_l = std::cos(theta);
    if (!(n_dot_l > 0.0)) return 0.0;
    const vec3<double> h(std::sin(0.5 * theta), 0.0, std::cos(0.5 * theta));
    const double w = weight == ld_weight::g1 ? g1_smith_ggx(n_dot_l, alpha_from_roughness(roughness)) : n_dot_l;
    const double k = lobe_ld_pdf<Lobe>(h, roughness) * w * Lobe::ld_weight(h, roughness);
    return std::isfinite(k) && k > 0.0 ? k : 0.0;
}


/// The radial CDF of the LD kernel: C(theta) = integral_0^theta K sin / integral_0^(pi/2) K sin on
/// a grid (theta_0 = 0, then geometric from 1e-6 s(r) to pi/2), by the trapezoid rule in theta.
/// total = integral_0^(pi/2) K sin (the kernel's integral over the sphere is 2 pi total).
struct fast_radial_cdf {
    std::vector<double> theta, cdf;
    double total = 0.0;
};
/// The grid of make_fast_radial_cdf for roughness r without its leading 0: theta_i = lo (hi /
/// lo)^(i / m), i = 0..m, lo = 1e-6 s(r), hi = pi / 2.
inline constexpr int fast_radial_grid_steps = 4096;
inline std::vector<double> fast_radial_grid(double roughness) {
    constexpr int m = fast_radial_grid_steps;
    const double lo = 1e-6 * fast_lobe_scale(roughness), hi = 0.5 * pi_v<double>;
    std::vector<double> t(std::size_t(m) + 1);
    for (int i = 0; i <= m; ++i) t[std::size_t(i)] = lo * std::pow(hi / lo, double(i) / m);
    return t;
}
/// The radial CDF of kernel values kv[i] >= 0 (negative values read as 0) at grid[i]
/// (fast_radial_grid), with sin(grid[i]) given: the trapezoid rule in theta from theta = 0.
inline fast_radial_cdf radial_cdf_from_values(const std::vector<double>& grid, const std::vector<double>& sin_grid,
                                              const std::vector<double>& kv) {
    fast_radial_cdf c;
    c.theta.reserve(grid.size() + 1);
    c.cdf.reserve(grid.size() + 1);
    c.theta.push_back(0.0);
    c.cdf.push_back(0.0);
    double prev_t = 0.0, prev_f = 0.0, acc = 0.0;
    for (std::size_t i = 0; i < grid.size(); ++i) {
        const double t = grid[i];
        const double f = (kv[i] > 0.0 ? kv[i] : 0.0) * sin_grid[i];
        acc += 0.5 * (f + prev_f) * (t - prev_t);
        c.theta.push_back(t);
        c.cdf.push_back(acc);
        prev_t = t, prev_f = f;
    }
    c.total = acc;
    for (double& v : c.cdf) v = acc > 0.0 ? v / acc : 0.0;
    return c;
}
inline std::vector<double> sin_of(const std::vector<double>& t) {
    std::vector<double> s(t.size());
    for (std::size_t i = 0; i < t.size(); ++i) s[i] = std::sin(t[i]);
    return s;
}
/// The radial CDF of any kernel k(theta) >= 0 (negative values read as 0) on the grid of
/// make_fast_radial_cdf for roughness r.
template <class KernelFn> fast_radial_cdf make_radial_cdf_of(double roughness, KernelFn&& k) {
    const std::vector<double> grid = fast_radial_grid(roughness);
    std::vector<double> kv(grid.size());
    for (std::size_t i = 0; i < grid.size(); ++i) kv[i] = k(grid[i]);
    return radial_cdf_from_values(grid, sin_of(grid), kv);
}
template <class Lobe> fast_radial_cdf make_fast_radial_cdf(double roughness, ld_weight weight) {
    return make_radial_cdf_of(roughness, [&](double t) { return fast_kernel<Lobe>(t, roughness, weight); });
}

/// The GGX lobe's radial CDF, memoised per (roughness, weight): a process-wide cache of at most 64
/// entries (cleared when full) behind a mutex, so that a real-time caller who filters the same
/// levels every frame does not rebuild the 4097-node quadrature per level and per call. Only the
/// built-in GGX lobe is cached (its kernel depends on nothing else); the values are those of
/// make_fast_radial_cdf.
/// A process-wide memo of at most 64 values, one per call site (its lambda type), cleared when full, behind a
/// mutex: make() runs outside the lock, so two threads may compute the same entry once each (the
/// same value: the first stored wins).
template <class Key, class Value, class Make> std::shared_ptr<const Value> fast_memo(const Key& key, Make&& make) {
    static std::mutex mutex;
    static std::map<Key, std::shared_ptr<const Value>> cache;
    {
        const std::lock_guard<std::mutex> lock(mutex);
        const auto it = cache.find(key);
        if (it != cache.end()) return it->second;
    }
    auto v = std::make_shared<const Value>(make());
    const std::lock_guard<std::mutex> lock(mutex);
    if (cache.size() >= 64) cache.clear();
    return cache.emplace(key, v).first->second;
}
inline std::shared_ptr<const fast_radial_cdf> ggx_fast_radial_cdf(double roughness, ld_weight weight) {
    return fast_memo<std::pair<double, int>, fast_radial_cdf>(std::pair<double, int>(roughness, int(weight)), [&] {
        return make_fast_radial_cdf<ggx_lobe>(roughness, weight);
    });
}

/// The coarse tail of a level (header: "Coarse tail"): LD = (1 - share) [the tap set of
/// K - c K_next] + share LD_next, c the largest multiple of the next level's kernel under this
/// level's on the hemisphere (the minimum of K / K_next over the CDF's grid), share = 1 - the
/// rest's integral / K's integral. c = share = 0 when the kernels give no bound.
struct fast_coarse_tail {
    double c = 0.0;
    double share = 0.0;
};
/// A level's kernel with its coarse tail removed: the rest's radial CDF and the tail.
struct fast_rest_kernel {
    fast_radial_cdf cdf;
    fast_coarse_tail tail;
};
template <class Lobe> fast_rest_kernel make_fast_rest_kernel(double roughness, double next_roughness, ld_weight weight) {
    // Each kernel once per node of the grid (the whole CDF, the bound c and the rest's CDF read
    // the same values).
    const std::vector<double> grid = fast_radial_grid(roughness), sin_grid = sin_of(grid);
    std::vector<double> k(grid.size()), kn(grid.size());
    for (std::size_t i = 0; i < grid.size(); ++i) {
        k[i] = fast_kernel<Lobe>(grid[i], roughness, weight);
        kn[i] = fast_kernel<Lobe>(grid[i], next_roughness, weight);
    }
    const fast_radial_cdf whole = radial_cdf_from_values(grid, sin_grid, k);
    double c = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < grid.size(); ++i) // every node but theta = 0
        if (k[i] > 0.0 && kn[i] > 0.0) c = std::min(c, k[i] / kn[i]);
    fast_rest_kernel r;
    if (!std::isfinite(c) || !(c > 0.0) || !(whole.total > 0.0)) {
        r.cdf = whole;
        return r;
    }
    std::vector<double> rest(grid.size());
    for (std::size_t i = 0; i < grid.size(); ++i) rest[i] = k[i] - c * kn[i];
    r.cdf = radial_cdf_from_values(grid, sin_grid, rest);
    r.tail.c = c;
    r.tail.share = std::clamp(1.0 - r.cdf.total / whole.total, 0.0, 1.0);
    return r;
}
/// make_fast_rest_kernel of the GGX lobe, memoised per (roughness, next roughness, weight) as
/// ggx_fast_radial_cdf.
inline std::shared_ptr<const fast_rest_kernel> ggx_fast_rest_kernel(double roughness, double next_roughness, ld_weight weight) {
    using key = std::tuple<double, double, int>;
    return fast_memo<key, fast_rest_kernel>(key(roughness, next_roughness, int(weight)), [&] {
        return make_fast_rest_kernel<ggx_lobe>(roughness, next_roughness, weight);
    });
}
/// The coarse tail of lobe L between two roughnesses (memoised for GGX).
template <class Lobe> fast_coarse_tail fast_tail_of(double roughness, double next_roughness, ld_weight weight) {
    if constexpr (std::is_same_v<Lobe, ggx_lobe>) return ggx_fast_rest_kernel(roughness, next_roughness, weight)->tail;
    else return make_fast_rest_kernel<Lobe>(roughness, next_roughness, weight).tail;
}

/// The radius where the CDF reaches u (linear between grid points).
inline double fast_cdf_at(const fast_radial_cdf& c, double u) noexcept {
    const auto it = std::lower_bound(c.cdf.begin(), c.cdf.end(), u);
    if (it == c.cdf.begin()) return 0.0;
    if (it == c.cdf.end()) return c.theta.back();
    const std::size_t k = std::size_t(it - c.cdf.begin());
    const double d = c.cdf[k] - c.cdf[k - 1];
    const double f = d > 0.0 ? (u - c.cdf[k - 1]) / d : 0.0;
    return c.theta[k - 1] + f * (c.theta[k] - c.theta[k - 1]);
}
} // namespace detail

/// The fast filter's table of lobe L (GGX by default) for one roughness, sample count and shape
/// (the header's spiral quadrature): tangent-space tap directions, kernel masses as weights, lods
/// from lod_of_solid_angle(Omega_i 4^lod_bias). Computed in double, stored as S. samples = 0 reads
/// as 1; a tail exponent that is not finite and > 0 reads as 1. With a next roughness (finite,
/// >= 0; the header's "Coarse tail") the spiral is that of the kernel with its coarse tail
/// removed and the table's scale is 1 - share: the caller adds share times the next level.
template <class S, class Lobe = ggx_lobe, class LodFn>
    requires ld_lobe<Lobe>
sphere_sample_table<S> make_fast_ld_table(double roughness, std::uint32_t samples, const fast_tap_shape& shape,
                                          LodFn&& lod_of_solid_angle, ld_weight weight = ld_weight::n_dot_l,
                                          double next_roughness = -1.0) {
    detail::check_total("make_fast_ld_table", "samples", samples, limits::max_samples, "limits::max_samples");
    const double r = std::clamp(std::isfinite(roughness) ? roughness : 0.0, 0.0, 1.0);
    const bool tail_on = std::isfinite(next_roughness) && next_roughness >= 0.0;
    const double rn = tail_on ? std::min(next_roughness, 1.0) : 0.0;
    const std::uint32_t n = std::max<std::uint32_t>(1, samples);
    const double tail = std::isfinite(shape.tail) && shape.tail > 0.0 ? shape.tail : 1.0;
    const double bias4 = std::exp2(2.0 * (std::isfinite(shape.lod_bias) ? shape.lod_bias : 0.0));
    std::shared_ptr<const detail::fast_radial_cdf> cdf_ptr;
    std::shared_ptr<const detail::fast_rest_kernel> rest_ptr;
    detail::fast_coarse_tail ct{};
    if (tail_on) {
        if constexpr (std::is_same_v<Lobe, ggx_lobe>) rest_ptr = detail::ggx_fast_rest_kernel(r, rn, weight);
        else rest_ptr = std::make_shared<const detail::fast_rest_kernel>(detail::make_fast_rest_kernel<Lobe>(r, rn, weight));
        ct = rest_ptr->tail;
    } else if constexpr (std::is_same_v<Lobe, ggx_lobe>) {
        cdf_ptr = detail::ggx_fast_radial_cdf(r, weight);
    } else {
        cdf_ptr = std::make_shared<const detail::fast_radial_cdf>(detail::make_fast_radial_cdf<Lobe>(r, weight));
    }
    const detail::fast_radial_cdf& cdf = tail_on ? rest_ptr->cdf : *cdf_ptr;
    auto kernel = [&](double theta) {
        const double k = detail::fast_kernel<Lobe>(theta, r, weight);
        return ct.c > 0.0 ? k - ct.c * detail::fast_kernel<Lobe>(theta, rn, weight) : k;
    };
    const double norm = 2.0 * pi_v<double> * cdf.total; // integral of the (rest) kernel over the sphere
    constexpr double golden = 2.399963229728653;         // pi (3 - sqrt 5)
    auto warp = [&](double x) { return 1.0 - std::pow(1.0 - x, tail); };
    sphere_sample_table<S> t;
    t.drawn = n;
    t.scale = S(1.0 - ct.share);
    for (std::uint32_t i = 0; i < n; ++i) {
        const double u0 = warp(double(i) / double(n)), u1 = i + 1 == n ? 1.0 : warp(double(i + 1) / double(n));
        const double mass = u1 - u0;
        const double theta = detail::fast_cdf_at(cdf, warp((double(i) + 0.5) / double(n)));
        const double k = kernel(theta);
        if (!(mass > 0.0) || !(k > 0.0) || !(norm > 0.0)) continue;
        const double omega = mass / (k / norm); // the sample's share of the sphere: its mass / density
        const double phi = golden * double(i);
        const double st = std::sin(theta), ct_ = std::cos(theta);
        t.push(vec3<S>(S(st * std::cos(phi)), S(st * std::sin(phi)), S(ct_)), S(mass), S(lod_of_solid_angle(omega * bias4)));
    }
    if (t.size() == 0) t.push(vec3<S>(S(0), S(0), S(1)), S(1), S(lod_of_solid_angle(0.0))); // a kernel with no mass: the mirror
    return t;
}

} // namespace ibl

#endif // IBL_DETAIL_CXX20
