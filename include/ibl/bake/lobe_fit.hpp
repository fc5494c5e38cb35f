#pragma once
// ibl/bake/lobe_fit.hpp — the specular lobe as a mixture of a few chain kernels (host only).
//
// A prefiltered chain of weight w (bake/prefilter.hpp, N = V = R) read at direction d and
// roughness r' returns the environment convolved with its normalised kernel, a function of
// mu = d.l alone:
//     K(mu; r') = D(h) w(mu) / (4 W(r')),  D(h) = a^2 / (pi (c^2 (a^2 - 1) + 1)^2),
//     c^2 = (h.d)^2 = (1 + mu) / 2,  w(mu) = mu (n.l weight) or G1(mu) (G1 weight),  a = r'^2,
// zero for mu <= 0, with W(r') = int_0^u_max w(mu(u)) du over the GGX NDF variable u (the draws
// are uniform in u; u_max = 1 / (1 + a^2) is the kernel's horizon; ld_kernel_normaliser).
// The normalised specular lobe (Fresnel excluded) at (n.v, r) in the tangent frame of n,
// v = (sin theta, 0, cos theta), is p(l) = D V (n.l) / E (E = A + B). The fit seeks taps k
// (in-plane directions d_k = (-sin t_k, 0, cos t_k), t_k the angle from n towards R; roughness
// r_k; weights w_k >= 0 summing to 1) whose mixture q = sum_k w_k K(d_k.l; r_k) is closest to p
// in L1: |p - q|_1 bounds the error of the mixture's reading of ANY environment by
// |p - q|_1 max L (relative to the lobe's integral of a constant one). With both densities
// normalised, |p - q|_1 = 2 int (p - q)_+ = 2 E_p[(1 - q / p)_+]: only points where p lives
// matter, so the objective is estimated over the lobe's own visible-normal draws (a midpoint grid
// of nodes^2 points, weights f (n.l) / pdf_l). A kernel that reaches below the horizon loses
// that mass from the lobe's support, so the L1 fit trades width against leakage by itself; the
// first-moment match of bake/lobe_moments.hpp does not see the horizon at all.
// The fit is a Nelder-Mead search from the moment solution, k taps from the fitted k - 1 with the
// heaviest tap split in two; it is derived from the BRDF alone, nothing is fitted to an environment. Weights summing
// to 1 keep the white furnace: a constant environment gives exactly (F0 A + F90 B) L.

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <algorithm>
#include <stdexcept>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "../brdf/ggx.hpp"
#include "../brdf/model.hpp"
#include "../core/constants.hpp"
#include "../core/executor.hpp"
#include "../core/limits.hpp"
#include "../core/math.hpp"
#include "../core/vec.hpp"
#include "../sampling/ggx.hpp"
#include "lobe_moments.hpp"
#include "prefilter.hpp"
#include "../runtime/tables.hpp"

namespace ibl {

/// W(r') of the chain kernel of weight w (header): kernel_nodes midpoint nodes in x with
/// u = u_max (1 - (1 - x)^2) (nodes graded towards the horizon, where G1 turns within
/// mu ~ alpha: second-order convergence for every r').
inline double ld_kernel_normaliser(double roughness, ld_weight w, std::uint32_t kernel_nodes = 512) {
    const double alpha = clamp_alpha(alpha_from_roughness(saturate(roughness)));
    const double a2 = alpha * alpha;
    const double u_max = 1.0 / (1.0 + a2);
    const std::uint32_t q = kernel_nodes > 0 ? kernel_nodes : 1;
    double s = 0.0;
    for (std::uint32_t i = 0; i < q; ++i) {
        const double x = (double(i) + 0.5) / double(q);
        const double u = u_max * (1.0 - (1.0 - x) * (1.0 - x));
        const double c2 = (1.0 - u) / (1.0 + (a2 - 1.0) * u);
        const double m = 2.0 * c2 - 1.0;
        if (m > 0.0) s += 2.0 * (1.0 - x) * (w == ld_weight::g1 ? g1_smith_ggx(m, alpha) : m);
    }
    return s * u_max / double(q);
}

namespace detail {
/// W(r') tabulated at 1025 roughness values (linear interpolation; W is smooth in r', the
/// table's error is below 1e-7 of W).
inline double ld_kernel_normaliser_tabulated(double roughness, ld_weight w) {
    constexpr int n = 1024;
    static const std::array<std::vector<double>, 2> tab = [] {
        std::array<std::vector<double>, 2> t;
        for (int k = 0; k < 2; ++k) {
            t[std::size_t(k)].resize(n + 1);
            for (int i = 0; i <= n; ++i)
                t[std::size_t(k)][std::size_t(i)] =
                    ld_kernel_normaliser(double(i) / n, k == 1 ? ld_weight::g1 : ld_weight::n_dot_l, 2048);
        }
        return t;
    }();
    const std::vector<double>& t = tab[w == ld_weight::g1 ? 1 : 0];
    const double x = saturate(roughness) * n;
    const int i = std::min(int(x), n - 1);
    return t[std::size_t(i)] + (x - i) * (t[std::size_t(i) + 1] - t[std::size_t(i)]);
}
} // namespace detail

/// The normalised chain kernel K(mu; r') of the header (per steradian), W = its normaliser.
inline double ld_kernel_value(double mu, double alpha, double normaliser, ld_weight w) noexcept {
    if (!(mu > 0.0) || !(normaliser > 0.0)) return 0.0;
    const double a2 = alpha * alpha;
    const double c2 = 0.5 * (1.0 + mu);
    const double den = c2 * (a2 - 1.0) + 1.0;
    const double d = a2 / (pi_v<double> * den * den);
    const double k = w == ld_weight::g1 ? g1_smith_ggx(mu, alpha) : mu;
    return d * k / (4.0 * normaliser);
}

/// One tap of a fitted mixture: in-plane angle from n towards R (radians), where it reads the
/// chain (roughness r', or a level of detail when the fit is of stored levels), weight.
struct lobe_tap {
    double angle = 0.0;
    double roughness = 0.0; ///< r' (continuous kernels) or lod in [0, levels - 1] (stored levels)
    double weight = 0.0;
};

inline constexpr int lobe_max_taps = 8;

/// The fitted mixture at (n.v, r): taps (count of them), its L1 distance to the lobe, and the L1
/// distance of the one-tap moment match (bake/lobe_moments.hpp) for comparison.
struct lobe_mixture {
    int count = 0;
    std::array<lobe_tap, lobe_max_taps> taps{};
    double l1 = 2.0;
    double l1_moments = 2.0;
};

/// The part of the specular lobe a fit describes (lobe_fit_options::part).
enum class lobe_fresnel_part { whole, a, b };

/// The Schlick weight of a part at v.h: 1, 1 - (1 - v.h)^5 or (1 - v.h)^5 (header).
inline double lobe_fresnel_part_weight(lobe_fresnel_part part, double v_dot_h) noexcept {
    if (part == lobe_fresnel_part::whole) return 1.0;
    const double f = std::pow(1.0 - saturate(v_dot_h), 5.0);
    return part == lobe_fresnel_part::b ? f : 1.0 - f;
}

/// What the fit may use: `taps` kernels (1..lobe_max_taps); level_roughness empty: kernels of any
/// roughness (a tap's roughness is r', read by any lookup that approximates K(r')); otherwise the
/// chain's stored levels (level l prefiltered at level_roughness[l], ascending, level 0 may be the
/// mirror r = 0) read by one trilinear textureLod: a tap at lod x reads
/// (1 - t) K(r_floor(x)) + t K(r_floor(x) + 1), t = frac(x), exactly what the hardware returns.
struct lobe_fit_options {
    int taps = 1;
    std::uint32_t nodes = 16;  ///< lobe points nodes^2 (the default's accuracy: docs/runtime.md, "The fitted lobe")
    int iterations = 40;       ///< Nelder-Mead iterations per parameter (the default's accuracy: docs/runtime.md)
    std::vector<double> level_roughness;
    /// Extra cost per unit of the mixture's mass below n's horizon (0: the plain L1 distance, which
    /// already counts it once). Radiance below the horizon is unrelated to what the lobe sees, so
    /// a leak there is the mixture's most harmful error; leak_weight > 0 trades more misplacement
    /// inside the hemisphere for less leakage.
    double leak_weight = 0.0;
    /// Nelder-Mead stops once its simplex's objective values agree within this (L1 units; 0:
    /// always the full iteration count).
    double tolerance = 1e-5;
    /// A tap that lowers the objective by less than this is not placed: its weight goes to an
    /// identical copy of the heaviest tap. Tables then stay continuous where an extra tap has no
    /// use (at n.v = 1 one kernel of a G1 chain is exact, and any split of it fits as well).
    double min_gain = 5e-3;
    /// Which part of the Schlick-weighted lobe is fitted: whole (F = 1: the lobe of A + B), the A
    /// part (weight 1 - (1 - v.h)^5: the lobe that F0 multiplies) or the B part (weight
    /// (1 - v.h)^5: the lobe that F90 multiplies, dominant for a dielectric). The two parts have
    /// different shapes and directions: the B part leans further towards grazing reflection.
    lobe_fresnel_part part = lobe_fresnel_part::whole;
};

namespace detail {

/// The lobe's visible-normal draws at (n.v, r): directions and values p(l) (normalised), and
/// their estimator weights.
struct lobe_points {
    std::vector<vec3<double>> l;
    std::vector<double> p, weight;
    double weight_sum = 0.0;
};

template <class Model>
lobe_points make_lobe_points(double mu, double roughness, std::uint32_t nodes, lobe_fresnel_part part = lobe_fresnel_part::whole) {
    lobe_points out;
    const double alpha = clamp_alpha(Model::alpha(roughness));
    const double g1_over_nv = ggx_g1_over_n_dot_v(mu, alpha);
    const std::uint32_t q = std::max<std::uint32_t>(nodes, 1);
    const vec3<double> v(std::sqrt((1.0 - mu) * (1.0 + mu)), 0.0, mu);
    double e = 0.0;
    for_each_lobe_draw<Model>(mu, roughness, q, [&](const vec3<double>& l, const vec3<double>& h, double vis) {
        const double f = lobe_fresnel_part_weight(part, glm::dot(v, h));
        const double w = 4.0 * vis * l.z / g1_over_nv * f;
        if (!(w > 0.0)) return;
        out.l.push_back(l);
        out.weight.push_back(w);
        out.p.push_back(Model::ndf(h.z, alpha) * vis * l.z * f); // / E below
        e += w;
    });
    out.weight_sum = e;
    e /= double(q) * double(q);
    for (double& p : out.p) p = e > 0.0 ? p / e : 0.0;
    return out;
}

/// A tap's kernel as up to two weighted GGX kernels at one direction.
struct tap_kernel {
    vec3<double> d{0.0, 0.0, 1.0};
    double weight[2] = {0.0, 0.0}, alpha[2] = {1.0, 1.0}, norm[2] = {1.0, 1.0};
};

inline tap_kernel make_tap_kernel(const lobe_tap& t, ld_weight w, const std::vector<double>& levels) {
    tap_kernel k;
    k.d = vec3<double>(-std::sin(t.angle), 0.0, std::cos(t.angle));
    auto set = [&](int i, double r, double wt) {
        k.weight[i] = wt;
        k.alpha[i] = clamp_alpha(alpha_from_roughness(r));
        k.norm[i] = r > 0.0 ? ld_kernel_normaliser_tabulated(r, w) : 0.0; // r = 0: the mirror, a delta (no density)
        if (!(r > 0.0)) k.weight[i] = 0.0;
    };
    if (levels.empty()) {
        set(0, t.roughness, t.weight);
        return k;
    }
    const double x = clamp(t.roughness, 0.0, double(levels.size() - 1));
    const int l0 = std::min(int(x), int(levels.size()) - 1);
    const int l1 = std::min(l0 + 1, int(levels.size()) - 1);
    const double f = x - double(l0);
    set(0, levels[std::size_t(l0)], t.weight * (1.0 - f));
    set(1, levels[std::size_t(l1)], t.weight * f);
    return k;
}

/// Parameters (angle, roughness or lod, weight) per tap -> taps: angles clamped to
/// [-pi/2, pi/2], roughness to [0.01, 1] (lod to [0, levels - 1]), weights >= 0, normalised.
inline void taps_from_params(const double* x, int count, double value_max, std::array<lobe_tap, lobe_max_taps>& taps) {
    double ws = 0.0;
    const double value_min = value_max > 1.0 ? 0.0 : 0.01;
    for (int k = 0; k < count; ++k) {
        lobe_tap& t = taps[std::size_t(k)];
        t.angle = clamp(x[3 * k], -half_pi_v<double>, half_pi_v<double>);
        t.roughness = clamp(x[3 * k + 1], value_min, value_max);
        t.weight = count == 1 ? 1.0 : std::max(x[3 * k + 2], 0.0);
        ws += t.weight;
    }
    for (int k = 0; k < count; ++k) taps[std::size_t(k)].weight = ws > 0.0 ? taps[std::size_t(k)].weight / ws : 1.0 / count;
}

/// The mass of one chain kernel (direction at `angle` from n, roughness r' > 0) below n's horizon:
/// over the kernel's angle beta from its axis (graded midpoint nodes in u, as the normaliser),
/// the azimuthal fraction with l.z < 0 is acos(cot(angle) cot(beta)) / pi (clamped).
inline double ld_kernel_mass_below(double angle, double roughness, ld_weight w, std::uint32_t nodes = 64) {
    const double alpha = clamp_alpha(alpha_from_roughness(saturate(roughness)));
    const double a2 = alpha * alpha, u_max = 1.0 / (1.0 + a2);
    const double ca = std::cos(angle), sa = std::fabs(std::sin(angle));
    double below = 0.0, total = 0.0;
    for (std::uint32_t i = 0; i < nodes; ++i) {
        const double x = (double(i) + 0.5) / double(nodes);
        const double u = u_max * (1.0 - (1.0 - x) * (1.0 - x));
        const double c2 = (1.0 - u) / (1.0 + (a2 - 1.0) * u);
        const double mu = 2.0 * c2 - 1.0;
        if (!(mu > 0.0)) continue;
        const double wt = 2.0 * (1.0 - x) * (w == ld_weight::g1 ? g1_smith_ggx(mu, alpha) : mu);
        const double sb = std::sqrt(std::max(0.0, 1.0 - mu * mu)), den = sa * sb;
        const double frac = den > 1e-12 ? std::acos(clamp(ca * mu / den, -1.0, 1.0)) / pi_v<double> : (ca * mu < 0.0 ? 1.0 : 0.0);
        below += wt * frac;
        total += wt;
    }
    return total > 0.0 ? below / total : 0.0;
}

/// L1 distance 2 E_p[(1 - q / p)_+] of the mixture to the lobe.
inline double mixture_l1(const lobe_points& pts, const std::array<lobe_tap, lobe_max_taps>& taps, int count, ld_weight w,
                         const std::vector<double>& levels) {
    std::array<tap_kernel, lobe_max_taps> k;
    for (int i = 0; i < count; ++i) k[std::size_t(i)] = make_tap_kernel(taps[std::size_t(i)], w, levels);
    double s = 0.0;
    for (std::size_t i = 0; i < pts.l.size(); ++i) {
        if (!(pts.p[i] > 0.0)) continue;
        double q = 0.0;
        for (int j = 0; j < count; ++j) {
            const tap_kernel& t = k[std::size_t(j)];
            const double mu = glm::dot(t.d, pts.l[i]);
            for (int c = 0; c < 2; ++c)
                if (t.weight[c] > 0.0) q += t.weight[c] * ld_kernel_value(mu, t.alpha[c], t.norm[c], w);
        }
        const double g = 1.0 - q / pts.p[i];
        if (g > 0.0) s += pts.weight[i] * g;
    }
    return pts.weight_sum > 0.0 ? 2.0 * s / pts.weight_sum : 2.0;
}

/// Nelder-Mead minimisation of f from x0 with initial steps `step`: at most `iterations`
/// iterations, stopping early once the simplex's values agree within `tolerance`.
template <class F>
double nelder_mead(F&& f, std::vector<double>& x0, const std::vector<double>& step, int iterations, double tolerance) {
    const std::size_t n = x0.size();
    std::vector<std::vector<double>> s(n + 1, x0);
    std::vector<double> fv(n + 1);
    for (std::size_t i = 0; i < n; ++i) s[i + 1][i] += step[i];
    for (std::size_t i = 0; i <= n; ++i) fv[i] = f(s[i].data());
    std::vector<double> c(n), xr(n), xe(n);
    for (int it = 0; it < iterations; ++it) {
        std::size_t lo = 0, hi = 0;
        for (std::size_t i = 1; i <= n; ++i) {
            if (fv[i] < fv[lo]) lo = i;
            if (fv[i] > fv[hi]) hi = i;
        }
        if (fv[hi] - fv[lo] <= tolerance) break;
        std::size_t hi2 = lo;
        for (std::size_t i = 0; i <= n; ++i)
            if (i != hi && fv[i] > fv[hi2]) hi2 = i;
        std::fill(c.begin(), c.end(), 0.0);
        for (std::size_t i = 0; i <= n; ++i)
            if (i != hi)
                for (std::size_t j = 0; j < n; ++j) c[j] += s[i][j] / double(n);
        for (std::size_t j = 0; j < n; ++j) xr[j] = c[j] + (c[j] - s[hi][j]);
        const double fr = f(xr.data());
        if (fr < fv[lo]) {
            for (std::size_t j = 0; j < n; ++j) xe[j] = c[j] + 2.0 * (c[j] - s[hi][j]);
            const double fe = f(xe.data());
            if (fe < fr) s[hi] = xe, fv[hi] = fe;
            else s[hi] = xr, fv[hi] = fr;
        } else if (fr < fv[hi2]) {
            s[hi] = xr, fv[hi] = fr;
        } else {
            for (std::size_t j = 0; j < n; ++j) xr[j] = c[j] + 0.5 * (s[hi][j] - c[j]);
            const double fc = f(xr.data());
            if (fc < fv[hi]) {
                s[hi] = xr, fv[hi] = fc;
            } else {
                for (std::size_t i = 0; i <= n; ++i)
                    if (i != lo) {
                        for (std::size_t j = 0; j < n; ++j) s[i][j] = s[lo][j] + 0.5 * (s[i][j] - s[lo][j]);
                        fv[i] = f(s[i].data());
                    }
            }
        }
    }
    std::size_t lo = 0;
    for (std::size_t i = 1; i <= n; ++i)
        if (fv[i] < fv[lo]) lo = i;
    x0 = s[lo];
    return fv[lo];
}

/// A roughness as a tap parameter: itself, or with stored level roughness L (lobe_fit_options::
/// level_roughness) the fractional level where the piecewise-linear L reaches it.
inline double lobe_tap_value(const std::vector<double>& L, double rr) {
    if (L.empty()) return rr;
    if (rr <= L.front()) return 0.0;
    for (std::size_t i = 1; i < L.size(); ++i)
        if (rr <= L[i]) return double(i - 1) + (rr - L[i - 1]) / std::max(L[i] - L[i - 1], 1e-12);
    return double(L.size() - 1);
}

/// Splits the heaviest of the first nk - 1 taps of x (3 parameters per tap: angle, value, weight)
/// into two of half its weight at angles a -+ spread / 2; returns the split before the angles
/// move apart (the same mixture written with nk taps).
inline std::vector<double> split_heaviest_tap(std::vector<double>& x, int nk, double spread) {
    int h = 0;
    for (int k = 1; k < nk - 1; ++k)
        if (x[std::size_t(3 * k + 2)] > x[std::size_t(3 * h + 2)]) h = k;
    const double a = x[std::size_t(3 * h)], v = x[std::size_t(3 * h + 1)], wt = x[std::size_t(3 * h + 2)];
    x[std::size_t(3 * h + 2)] = 0.5 * wt;
    x.insert(x.end(), {a, v, 0.5 * wt});
    std::vector<double> same = x;
    x[std::size_t(3 * h)] = a - 0.5 * spread;
    x[x.size() - 3] = a + 0.5 * spread;
    return same;
}

/// Nelder-Mead on the L1 distance of nk taps from x (plus the leak penalty of the options);
/// returns the best value, x the best parameters.
inline double fit_taps(const lobe_points& pts, std::vector<double>& x, int nk, double vmax, double spread, ld_weight w,
                       const lobe_fit_options& o) {
    auto f = [&](const double* p) {
        std::array<lobe_tap, lobe_max_taps> t{};
        taps_from_params(p, nk, vmax, t);
        double e = mixture_l1(pts, t, nk, w, o.level_roughness);
        if (o.leak_weight > 0.0 && o.level_roughness.empty())
            for (int k = 0; k < nk; ++k)
                e += o.leak_weight * t[std::size_t(k)].weight * ld_kernel_mass_below(t[std::size_t(k)].angle, t[std::size_t(k)].roughness, w);
        return e;
    };
    std::vector<double> step(x.size());
    for (std::size_t j = 0; j < x.size(); ++j) step[j] = j % 3 == 0 ? spread : j % 3 == 1 ? 0.1 * vmax : 0.2;
    return nelder_mead(f, x, step, o.iterations * int(x.size()), o.tolerance);
}

/// Weights as parameters: clamped at 0 and renormalised to sum 1 (equal when all are <= 0).
inline void normalise_tap_weights(std::vector<double>& x, int nk) {
    double ws = 0.0;
    for (int k = 0; k < nk; ++k) ws += std::max(x[std::size_t(3 * k + 2)], 0.0);
    for (int k = 0; k < nk; ++k) x[std::size_t(3 * k + 2)] = ws > 0.0 ? std::max(x[std::size_t(3 * k + 2)], 0.0) / ws : 1.0 / nk;
}

/// The first n taps by increasing angle.
inline void sort_taps_by_angle(std::array<lobe_tap, lobe_max_taps>& taps, int n) {
    // sorted through a vector: g++ 12 -O3 reads std::sort over a prefix of the array as out of bounds
    std::vector<lobe_tap> sorted(taps.begin(), taps.begin() + n);
    std::sort(sorted.begin(), sorted.end(), [](const lobe_tap& a, const lobe_tap& b) { return a.angle < b.angle; });
    std::copy(sorted.begin(), sorted.end(), taps.begin());
}

} // namespace detail

/// The L1-closest mixture of o.taps chain kernels of weight w to the lobe of model M at (n.v, r)
/// (header). Starts: the one-tap moment match; k taps start from the fitted k - 1 taps with the
/// heaviest tap split in two along the plane of incidence (a greedy continuation).
template <class Model = ggx_height_correlated>
lobe_mixture fit_specular_lobe(double n_dot_v, double roughness, ld_weight w, const lobe_fit_options& o = {}) {
    lobe_mixture out;
    const int n_taps = std::clamp(o.taps, 1, lobe_max_taps);
    const double mu = clamp(n_dot_v, 1e-3, std::cos(lobe_min_theta)), r = saturate(roughness);
    // the start (and the moment match reported beside the fit): coarse quadratures suffice
    const lobe_moments m = specular_lobe_moments<Model>(mu, r, 32);
    const double r_eff = std::max(ld_matched_roughness(m.rho, w, 256), 0.01);
    const detail::lobe_points pts = detail::make_lobe_points<Model>(mu, r, o.nodes, o.part);
    const double vmax = o.level_roughness.empty() ? 1.0 : double(o.level_roughness.size() - 1);
    std::vector<double> x{m.phi, detail::lobe_tap_value(o.level_roughness, r_eff), 1.0};
    {
        std::array<lobe_tap, lobe_max_taps> t{};
        detail::taps_from_params(x.data(), 1, 1.0, t);
        out.l1_moments = detail::mixture_l1(pts, t, 1, w, {});
    }
    const double spread = 0.5 * std::max(r_eff * r_eff, 0.02);
    double best = 2.0;
    std::vector<double> x_same; // the k - 1 taps' mixture written with k taps (no new freedom used)
    double best_same = 2.0;
    for (int nk = 1; nk <= n_taps; ++nk) {
        if (nk > 1) {
            x_same = detail::split_heaviest_tap(x, nk, spread);
            best_same = best;
        }
        best = detail::fit_taps(pts, x, nk, vmax, spread, w, o);
        if (nk > 1 && !(best < best_same - o.min_gain)) { // the new tap does not pay: keep the copy
            x = x_same;
            best = best_same;
        }
        detail::normalise_tap_weights(x, nk); // the next split starts from the same mixture
    }
    out.count = n_taps;
    detail::taps_from_params(x.data(), n_taps, vmax, out.taps);
    detail::sort_taps_by_angle(out.taps, n_taps);
    out.l1 = o.leak_weight > 0.0 ? detail::mixture_l1(pts, out.taps, n_taps, w, o.level_roughness) : best;
    return out;
}

/// Fits every texel (header; rows in parallel) by fit_specular_lobe. size in [1, 256].
template <class Model = ggx_height_correlated, class Executor = thread_executor>
lobe_taps_lut make_lobe_taps_lut(std::uint32_t size, const dfg_lut_layout& layout, ld_weight w, const lobe_fit_options& o = {},
                                 Executor&& ex = Executor{}) {
    detail::check_total("make_lobe_taps_lut", "size", size, 256u, "256");
    if (size < 1) throw std::invalid_argument("ibl::make_lobe_taps_lut: size must be >= 1");
    const dfg_lut ab = make_dfg_lut_exact<Model>(size, layout, 2);
    lobe_taps_lut lut;
    lut.size = size;
    lut.taps = std::clamp(o.taps, 1, lobe_max_taps);
    lut.channels = 2u + 3u * std::uint32_t(lut.taps);
    lut.weight = w;
    lut.layout = layout;
    lut.level_roughness = o.level_roughness;
    lut.data.assign(std::size_t(size) * size * lut.channels, 0.0f);
    const double vmax = o.level_roughness.empty() ? 1.0 : double(o.level_roughness.size() - 1);
    std::vector<double> l1(std::size_t(size) * size, -1.0);
    ex(std::size_t(size), [&](std::size_t begin, std::size_t end) {
        for (std::size_t j = begin; j < end; ++j) {
            const double r = dfg_texel_value<double>(layout.roughness, std::uint32_t(j), size, layout.edge_aligned);
            for (std::uint32_t ii = size; ii-- > 0;) {
                const double mu = dfg_texel_value<double>(layout.n_dot_v, ii, size, layout.edge_aligned);
                float* t = &lut.data[(j * size + ii) * lut.channels];
                t[0] = ab.data[(j * size + ii) * 2];
                t[1] = ab.data[(j * size + ii) * 2 + 1];
                if (r <= 0.0) {
                    t[2] = 1.0f; // at R
                    t[3] = 0.0f;
                    t[4] = 1.0f;
                    continue;
                }
                // Each texel by the greedy fit from its own moments. (Starting from the neighbour's
                // taps instead drifts into worse minima: mean L1 0.80 against 0.71 for one tap,
                // 0.70 against 0.58 for two, and never gained more than 0.01 on a texel.)
                const lobe_mixture m = fit_specular_lobe<Model>(mu, r, w, o);
                const double view_angle = std::acos(clamp(mu, 1e-3, std::cos(lobe_min_theta))); // as the fit's
                // statistics: not the n.v = 0 column (no lobe) nor the near-mirror rows r < 0.05 (the
                // kernels' roughness floor 0.01 is wider than those lobes; the chain reads level 0)
                if (t[0] + t[1] > 1e-6f && r >= 0.05) l1[j * size + ii] = m.l1;
                for (int k = 0; k < lut.taps; ++k) {
                    t[2 + 3 * k] = float(m.taps[std::size_t(k)].angle / view_angle);
                    t[3 + 3 * k] = float(m.taps[std::size_t(k)].roughness / vmax);
                    t[4 + 3 * k] = float(m.taps[std::size_t(k)].weight);
                }
            }
        }
    });
    std::size_t cnt = 0;
    for (const double e : l1)
        if (e >= 0.0) lut.max_l1 = std::max(lut.max_l1, e), lut.mean_l1 += e, ++cnt;
    if (cnt > 0) lut.mean_l1 /= double(cnt);
    return lut;
}

namespace detail {
/// A one-tap lobe_taps_lut as a lobe LUT (A, B, s, r_eff): s the lerp factor whose
/// normalize(lerp(n, R, s)) is at the tap's angle (clamped to [0, 1]: between n and R).
inline lobe_lut lobe_lut_from_one_tap(const lobe_taps_lut& t) {
    const std::uint32_t size = t.size;
    const dfg_lut_layout& layout = t.layout;
    lobe_lut lut;
    lut.size = size;
    lut.weight = t.weight;
    lut.layout = layout;
    lut.data.assign(std::size_t(size) * size * 4, 0.0f);
    for (std::uint32_t j = 0; j < size; ++j)
        for (std::uint32_t i = 0; i < size; ++i) {
            const float* src = &t.data[(std::size_t(j) * size + i) * t.channels];
            float* dst = &lut.data[(std::size_t(j) * size + i) * 4];
            const double mu = dfg_texel_value<double>(layout.n_dot_v, i, size, layout.edge_aligned);
            const double theta = std::max(std::acos(saturate(mu)), lobe_min_theta);
            const double ta = std::tan(double(src[2]) * std::acos(clamp(mu, 1e-3, std::cos(lobe_min_theta))));
            dst[0] = src[0];
            dst[1] = src[1];
            dst[2] = src[3] > 0.0f ? float(clamp(ta / (std::sin(theta) + ta * (1.0 - std::cos(theta))), 0.0, 1.0)) : 1.0f;
            dst[3] = src[3];
        }
    return lut;
}
} // namespace detail

/// The one-tap fit as a lobe LUT (A, B, s, r_eff) for ibl::specular_lobe (runtime/specular_models.hpp): s the
/// lerp factor whose normalize(lerp(n, R, s)) is at the fitted angle (clamped to [0, 1]: between
/// n and R). Same layout and argument rules as make_lobe_taps_lut (o.taps is ignored: 1;
/// level_roughness must be empty).
template <class Model = ggx_height_correlated, class Executor = thread_executor>
lobe_lut make_lobe_lut_fitted(std::uint32_t size, const dfg_lut_layout& layout, ld_weight w, lobe_fit_options o = {},
                              Executor&& ex = Executor{}) {
    o.taps = 1;
    o.level_roughness.clear();
    return detail::lobe_lut_from_one_tap(make_lobe_taps_lut<Model>(size, layout, w, o, ex));
}

template <class Model = ggx_height_correlated, class Executor = thread_executor>
lobe_pair_lut make_lobe_pair_lut(std::uint32_t size, const dfg_lut_layout& layout, ld_weight w, lobe_fit_options o = {},
                                 Executor&& ex = Executor{}) {
    o.taps = 1;
    o.level_roughness.clear();
    lobe_pair_lut out;
    o.part = lobe_fresnel_part::whole;
    out.a = detail::lobe_lut_from_one_tap(make_lobe_taps_lut<Model>(size, layout, w, o, ex));
    o.part = lobe_fresnel_part::b;
    const lobe_taps_lut tb = make_lobe_taps_lut<Model>(size, layout, w, o, ex);
    out.b.size = size;
    out.b.weight = w;
    out.b.layout = layout;
    out.b.data.assign(std::size_t(size) * size * 4, 0.0f);
    for (std::size_t k = 0; k < std::size_t(size) * size; ++k) {
        out.b.data[k * 4] = tb.data[k * tb.channels + 2];
        out.b.data[k * 4 + 1] = tb.data[k * tb.channels + 3];
    }
    return out;
}

} // namespace ibl

#endif // IBL_DETAIL_CXX20
