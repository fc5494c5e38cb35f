#pragma once
// ibl/reference/lookup_error.hpp — what a renderer gets: the error of the runtime lookups of
// ibl/runtime/lookup.hpp at any roughness and n.v, against exact references (host only), plus the tables
// of the non-uniform DFG layouts and the storage-format rounding.
//
// Specular (specular_lookup_error). For each roughness r of a list and each direction of a set,
// three comparisons of luminance Y (core/color.hpp) with exact LD values ref(dir, r) supplied by
// the caller (reference_ld_sky for an analytic sky, reference_ld_texel_sum below for a cubemap,
// reference_ld for anything):
//   total          the lookup of the chain, specular_lookup(chain, dir, r, desc), against
//                  ref(dir, r): what a renderer sees;
//   interpolation  sum_k w_k ref(dir, r_k) over the lookup's taps (levels k, weights w_k, r_k the
//                  roughness level k holds) against ref(dir, r): the error of blending levels
//                  alone, as if every level were exact (and read without reconstruction error);
//   levels         the lookup of the chain against sum_k w_k ref(dir, r_k): the levels' own
//                  error (prefilter noise and bias, bilinear reconstruction, storage rounding)
//                  seen through the same weights; 0 at r = r_k for an exact level.
// Metrics are reference/metrics.hpp's over the scalar Y per direction; the relative ones use a
// floor of floor_rel x the mean reference luminance over the directions at that roughness (the
// tool's convention), so that dark directions are judged against the environment's brightness.
//
// Directions (lookup_error_directions): the texel centres of a grid x grid-per-face cube (6 grid^2
// directions spread over the sphere) and a (2k + 1)^2 block about the brightest direction, spaced
// `spacing` radians in its tangent plane (the neighbourhood of the sun, where the error peaks).
//
// Exact LD of a cubemap (reference_ld_texel_sum). Deterministic quadrature over every texel t of
// one level (midpoint rule with exact texel solid angles Omega_t, double):
//   LD(R) = sum_t L_t w_t / sum_t w_t,   w_t = Omega_t D(n.h_t) max(c_t, 0),  c_t = R . d_t,
// with n = v = R, so n.h = |R + d| / 2 and n.h^2 = (1 + c)/2: D depends on the texel only through
// c. Dividing by the weights' sum (not the closed-form normaliser) makes a constant environment
// exact. The LD weight of the chain under test (runtime/ld_weight.hpp) is a parameter:
// ld_weight::g1 multiplies each texel's weight by G1(c_t) / c_t (w_t = Omega_t D G1(c_t)), as
// the prefilter's G1 samples are weighted. The midpoint rule is accurate when the lobe spans several texels: the lobe of l has an
// angular half-width of about 2 alpha, and reference_ld_texel_level picks the coarsest level
// whose texel (pi / (2 n) radians at the face centre) is at most alpha / 2 (ideally 4 or more
// texels per half-width), level 0 if none is. Comparing two levels bounds its error (the example
// research/lookup_error.cpp prints that check).
//
// DFG (dfg_lookup_error). Over a grid of (n.v, r) points, max and RMS of |A - A_exact| and
// |B - B_exact| of dfg_lookup(lut, n.v, r) (the table's own layout) against exact values (dfg_exact_grid: the
// converged quadrature dfg_exact in double), with the location of the largest error.
//
// Storage rounding: round_through_half (IEEE binary16, round to nearest even; finite values beyond
// 65504 clamp to +-65504, NaN and inf kept, as the KTX2 writer of ibl-bake stores them), applied
// to every texel of a chain (quantize_half) or a table (quantize_half_lut): measure the rounded
// copy with the same functions.

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <span>
#include <vector>

#include "../batch/dfg_kernel.hpp"
#include "../brdf/ggx.hpp"
#include "../core/color.hpp"
#include "../core/constants.hpp"
#include "../core/executor.hpp"
#include "../core/frame.hpp"
#include "../core/math.hpp"
#include "../core/vec.hpp"
#include "../env/cube_geometry.hpp"
#include "../env/cubemap.hpp"
#include "../runtime/lookup.hpp"
#include "../sampling/lobe.hpp"
#include "../bake/dfg.hpp"
#include "../bake/dfg_lut.hpp"
#include "../runtime/ld_weight.hpp"
#include "metrics.hpp"
#include "../runtime/roughness_mip.hpp"

namespace ibl {

// ---- storage rounding ----------------------------------------------------------------------------

/// x rounded to the nearest IEEE half (ties to even) and back; finite values beyond the largest
/// half (65504) clamp to +-65504; NaN and inf are kept; results below the half's normal range
/// are rounded to its subnormals (multiples of 2^-24).
inline float round_through_half(float x) noexcept {
    if (!std::isfinite(x)) return x;
    const float ax = std::fabs(x);
    if (ax >= 65504.0f) return std::copysign(65504.0f, x);
    if (ax < 6.103515625e-05f) { // below 2^-14: the subnormal grid 2^-24
        const float q = std::nearbyint(ax * 16777216.0f) / 16777216.0f;
        return std::copysign(q, x);
    }
    // Keep 10 mantissa bits: add half an ulp of the half (plus the tie-to-even bit), truncate.
    const std::uint32_t u = std::bit_cast<std::uint32_t>(x);
    const std::uint32_t lsb = (u >> 13) & 1u;
    const std::uint32_t r = (u + 0x0fffu + lsb) & ~0x1fffu;
    return std::bit_cast<float>(r);
}

/// A copy of the chain with every texel rounded through half (borders rebuilt).
inline cubemap<float> quantize_half(const cubemap<float>& c) {
    cubemap<float> q(c.size(0), c.levels());
    for (int l = 0; l < c.levels(); ++l)
        q.fill(l, [&](int f, int x, int y) {
            const vec3<float> v = c.texel(f, x, y, l);
            return vec3<float>(round_through_half(v.x), round_through_half(v.y), round_through_half(v.z));
        });
    q.update_borders();
    return q;
}

/// A copy of the table with every value rounded through half.
inline dfg_lut quantize_half_lut(const dfg_lut& lut) {
    dfg_lut q = lut;
    for (float& v : q.data) v = round_through_half(v);
    return q;
}

// ---- DFG -------------------------------------------------------------------------------------------

/// A grid of (n.v, r) points: every n.v of one list against every r of another (row-major: r
/// outer). The default: n.v at 0, 1 and both uniform and quadratic spacing (dense near grazing),
/// r uniform in [r_min, 1].
struct dfg_error_grid {
    std::vector<double> n_dot_v;
    std::vector<double> roughness;

    /// n.v = k / (count - 1) and (k / (count - 1))^2 for k < count (duplicates kept: harmless);
    /// r = r_min + (1 - r_min) k / (r_count - 1).
    static dfg_error_grid dense(std::uint32_t count = 257, std::uint32_t r_count = 191, double r_min = 0.05) {
        dfg_error_grid g;
        const double dn = double(count > 1 ? count - 1 : 1), dr = double(r_count > 1 ? r_count - 1 : 1);
        for (std::uint32_t k = 0; k < count; ++k) {
            g.n_dot_v.push_back(double(k) / dn);
            g.n_dot_v.push_back(sqr(double(k) / dn));
        }
        for (std::uint32_t k = 0; k < r_count; ++k) g.roughness.push_back(r_min + (1.0 - r_min) * double(k) / dr);
        return g;
    }
};

/// Exact (A, B) of model M at every grid point (dfg_exact, double), r outer.
template <class Model, class Executor = thread_executor>
std::vector<vec2<double>> dfg_exact_grid(const dfg_error_grid& g, Executor&& ex = Executor{}) {
    const std::size_t nx = g.n_dot_v.size();
    std::vector<vec2<double>> out(nx * g.roughness.size());
    ex(g.roughness.size(), [&](std::size_t b, std::size_t e) {
        for (std::size_t j = b; j < e; ++j)
            for (std::size_t i = 0; i < nx; ++i) out[j * nx + i] = dfg_exact<Model>(g.n_dot_v[i], g.roughness[j]);
    });
    return out;
}

struct dfg_lookup_report {
    double max_abs = 0;   ///< largest |A - A_exact| or |B - B_exact|
    double max_abs_a = 0; ///< largest |A - A_exact|
    double max_abs_b = 0; ///< largest |B - B_exact|
    double rms = 0;       ///< RMS over both terms and every point
    double worst_n_dot_v = 0, worst_roughness = 0; ///< where max_abs occurs
    std::size_t count = 0;                         ///< points compared
};

/// Error of dfg_lookup(lut, n.v, r) (the table's own layout) over the grid against exact values (dfg_exact_grid).
template <class Table>
dfg_lookup_report dfg_lookup_error(const Table& lut, const dfg_error_grid& g,
                                   std::span<const vec2<double>> exact) {
    dfg_lookup_report rep;
    const std::size_t nx = g.n_dot_v.size();
    double sq = 0.0;
    for (std::size_t j = 0; j < g.roughness.size(); ++j)
        for (std::size_t i = 0; i < nx; ++i) {
            const std::size_t k = j * nx + i;
            if (k >= exact.size()) break;
            const vec3<float> v = dfg_lookup(lut, float(g.n_dot_v[i]), float(g.roughness[j]));
            const double da = std::fabs(double(v.x) - exact[k].x), db = std::fabs(double(v.y) - exact[k].y);
            sq += da * da + db * db;
            rep.max_abs_a = std::fmax(rep.max_abs_a, da);
            rep.max_abs_b = std::fmax(rep.max_abs_b, db);
            const double d = std::fmax(da, db);
            if (d > rep.max_abs || !std::isfinite(d)) {
                rep.max_abs = d;
                rep.worst_n_dot_v = g.n_dot_v[i];
                rep.worst_roughness = g.roughness[j];
            }
            ++rep.count;
        }
    rep.rms = rep.count > 0 ? std::sqrt(sq / (2.0 * double(rep.count))) : 0.0;
    return rep;
}

// ---- specular ------------------------------------------------------------------------------------

/// Direction of the texel of largest luminance of a cubemap level (first one on ties).
template <class T> vec3<double> brightest_direction(const cubemap<T>& c, int level = 0) {
    const int n = c.size(level);
    double best = -std::numeric_limits<double>::infinity();
    vec3<double> dir(0.0, 1.0, 0.0);
    for (int f = 0; f < 6; ++f)
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
                const double yv = luminance(vec3<double>(c.texel(f, x, y, level)));
                if (yv > best) {
                    best = yv;
                    dir = cube_texel_direction<double>(f, x, y, n);
                }
            }
    return dir;
}

/// The directions of the specular checks (see the header): texel centres of a grid^2-per-face
/// cube, then the (2 k + 1)^2 block about `bright` with angular spacing `spacing` (radians).
inline std::vector<vec3<double>> lookup_error_directions(int grid, const vec3<double>& bright, int k = 2,
                                                         double spacing = 0.02) {
    std::vector<vec3<double>> d;
    const int g = grid > 0 ? grid : 1;
    for (int f = 0; f < 6; ++f)
        for (int y = 0; y < g; ++y)
            for (int x = 0; x < g; ++x) d.push_back(cube_texel_direction<double>(f, x, y, g));
    const vec3<double> b = glm::normalize(bright);
    const frame<double> fr = make_frame(b);
    for (int j = -k; j <= k; ++j)
        for (int i = -k; i <= k; ++i)
            d.push_back(glm::normalize(b + std::tan(double(i) * spacing) * fr.t + std::tan(double(j) * spacing) * fr.b));
    return d;
}

/// The coarsest level of c whose texel (pi / (2 n) radians) is at most alpha / 2, level 0 if
/// none is (see the header).
template <class T> int reference_ld_texel_level(const cubemap<T>& c, double roughness, double texels_per_alpha = 8.0,
                                                int min_size = 64) {
    const double alpha = alpha_from_roughness(roughness);
    int level = 0;
    while (level + 1 < c.levels() && c.size(level + 1) >= min_size &&
           pi_v<double> / (2.0 * double(c.size(level + 1))) <= alpha / texels_per_alpha)
        ++level;
    return level;
}

namespace detail {
/// Every texel of one cubemap level: centre direction, radiance (non-finite components as 0),
/// exact solid angle.
struct level_texels {
    std::vector<vec3<double>> dir, radiance;
    std::vector<double> solid_angle;
};
template <class T> level_texels gather_level_texels(const cubemap<T>& c, int level) {
    const int n = c.size(level);
    level_texels t;
    t.dir.reserve(std::size_t(6) * std::size_t(n) * std::size_t(n));
    for (int f = 0; f < 6; ++f)
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
                vec3<double> L(c.texel(f, x, y, level));
                for (int k = 0; k < 3; ++k)
                    if (!std::isfinite(L[k])) L[k] = 0.0;
                t.dir.push_back(cube_texel_direction<double>(f, x, y, n));
                t.radiance.push_back(L);
                t.solid_angle.push_back(cube_texel_solid_angle<double>(x, y, n));
            }
    return t;
}
} // namespace detail

/// Exact LD of cubemap level `level` at each direction (texel-sum quadrature, see the header)
/// with the LD weight of the chain it is compared with. Non-finite texel components read as 0.
/// Work items: directions.
template <class T, class Executor = serial_executor>
std::vector<vec3<double>> reference_ld_texel_sum(const cubemap<T>& c, int level, std::span<const vec3<double>> dirs,
                                                 double roughness, Executor&& ex = Executor{},
                                                 ld_weight weight = ld_weight::n_dot_l) {
    const detail::level_texels tex = detail::gather_level_texels(c, level);
    const std::vector<vec3<double>>&td = tex.dir, &tl = tex.radiance;
    const std::vector<double>& tw = tex.solid_angle;
    const double alpha = alpha_from_roughness(roughness), a2 = sqr(clamp_alpha(alpha));
    std::vector<vec3<double>> out(dirs.size());
    ex(dirs.size(), [&](std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i) {
            const vec3<double> R = glm::normalize(dirs[i]);
            vec3<double> s(0.0);
            double w = 0.0;
            for (std::size_t t = 0; t < td.size(); ++t) {
                const double cl = glm::dot(R, td[t]);
                if (!(cl > 0.0)) continue;
                const double nh2 = 0.5 * (1.0 + cl);
                const double den = nh2 * (a2 - 1.0) + 1.0;
                const double k = weight == ld_weight::g1 ? g1_smith_ggx(cl, alpha) : cl;
                const double wt = tw[t] * k * a2 / (pi_v<double> * den * den);
                s += wt * tl[t];
                w += wt;
            }
            out[i] = w > 0.0 ? s / w : vec3<double>(0.0);
        }
    });
    return out;
}

/// The texel-sum LD of any lobe L (sampling/lobe.hpp) at each direction: sum_t L_t w_t / sum_t w_t
/// with w_t = Omega_t (n.l_t) D(h_t) (n.h_t) / (n.h_t), D (n.h) taken as L::pdf x L::ld_weight (the
/// lobe's contract: equal up to a factor of r alone, which cancels), h_t the half vector of R and
/// the texel direction (n = v = R); only n.l > 0 counts, as in the prefilter. Isotropic lobes (the
/// lobe functions are evaluated at h = (sin theta_h, 0, cos theta_h)). For GGX it is
/// reference_ld_texel_sum up to rounding; reference_ld_texel_level picks a fine enough level.
template <class Lobe, class T, class Executor = serial_executor>
    requires ld_lobe<Lobe>
std::vector<vec3<double>> reference_ld_texel_sum_lobe(const cubemap<T>& c, int level, std::span<const vec3<double>> dirs,
                                                      double roughness, Executor&& ex = Executor{}) {
    const detail::level_texels tex = detail::gather_level_texels(c, level);
    std::vector<vec3<double>> out(dirs.size());
    ex(dirs.size(), [&](std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i) {
            const vec3<double> R = glm::normalize(dirs[i]);
            vec3<double> s(0.0);
            double w = 0.0;
            for (std::size_t t = 0; t < tex.dir.size(); ++t) {
                const double cl = glm::dot(R, tex.dir[t]);
                if (!(cl > 0.0)) continue;
                const double ch = std::sqrt(0.5 * (1.0 + cl)), sh = std::sqrt(0.5 * (1.0 - cl));
                const vec3<double> h(sh, 0.0, ch);
                const double wt = tex.solid_angle[t] * cl * Lobe::pdf(h, roughness) * Lobe::ld_weight(h, roughness) / ch;
                s += wt * tex.radiance[t];
                w += wt;
            }
            out[i] = w > 0.0 ? s / w : vec3<double>(0.0);
        }
    });
    return out;
}

/// The specular lookup's error at one roughness (see the header).
struct specular_lookup_report {
    double roughness = 0;
    error_metrics total;         ///< lookup against the exact LD
    error_metrics interpolation; ///< blend of exact levels against the exact LD
    error_metrics levels;        ///< lookup against the blend of exact levels
};

/// The error of specular_lookup(chain, dir, r, desc) for each r and each direction, with its two
/// parts (see the header). ref(std::span<const vec3<double>> dirs, double r) returns the exact LD
/// at every direction (a std::vector<vec3<double>>); it is called once per distinct roughness
/// (the list's and the levels' that the lookups touch).
template <class Ref>
std::vector<specular_lookup_report> specular_lookup_error(const cubemap<float>& chain, const specular_lookup_desc& desc,
                                                          std::span<const double> roughness,
                                                          std::span<const vec3<double>> dirs, Ref&& ref,
                                                          double floor_rel = 1e-3) {
    const int levels = chain.levels();
    std::map<double, std::vector<vec3<double>>> cache;
    auto exact = [&](double r) -> const std::vector<vec3<double>>& {
        auto it = cache.find(r);
        if (it == cache.end()) it = cache.emplace(r, ref(dirs, r)).first;
        return it->second;
    };
    std::vector<specular_lookup_report> out;
    for (const double r : roughness) {
        const specular_taps<double> taps = specular_lookup_taps(r, levels, desc);
        const std::vector<vec3<double>>& e = exact(r);
        std::vector<const std::vector<vec3<double>>*> lev;
        for (int k = 0; k < taps.count; ++k)
            lev.push_back(&exact(roughness_from_lod(desc.mapping, double(taps.level[k]), double(levels - 1))));
        double mean = 0.0;
        for (const auto& v : e) mean += luminance(v);
        mean = dirs.empty() ? 0.0 : mean / double(dirs.size());
        const double floor = floor_rel * mean > 1e-30 ? floor_rel * mean : 1e-30;
        error_accumulator tot(floor), itp(floor), lvl(floor);
        for (std::size_t i = 0; i < dirs.size(); ++i) {
            const vec3<float> d(glm::normalize(dirs[i]));
            const double y_look = luminance(vec3<double>(specular_lookup(chain, d, float(r), desc)));
            vec3<double> v[4];
            for (int k = 0; k < taps.count; ++k) v[k] = (*lev[std::size_t(k)])[i];
            const double y_blend = luminance(specular_blend(taps, v, desc));
            const double y_ref = luminance(e[i]);
            tot.add(y_look, y_ref);
            itp.add(y_blend, y_ref);
            lvl.add(y_look, y_blend);
        }
        out.push_back({r, tot.finish(), itp.finish(), lvl.finish()});
    }
    return out;
}

} // namespace ibl

#endif // IBL_DETAIL_CXX20
