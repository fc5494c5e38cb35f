#pragma once
// ibl/reference/ld_irradiance.hpp — converged references for the prefiltered LD term and for
// irradiance, in double, to measure the products' errors against (host only; slow by design).
//
// LD (definitions in bake/prefilter.hpp):
//   LD(R) = integral L(l) w(l) dl / W,   w(l) = D(h) max(n.l, 0),  h = normalize(R + l),  N = V = R
//   W(alpha) = integral w(l) dl over the sphere.
// * reference_ld(env, R, r, samples): GGX importance sampling with the n.l weights (the same
//   estimator as the product) from `samples` Hammersley points, every sample at lod 0, Neumaier
//   sums in double. Converges like QMC on the integrand: for smooth sources the error falls
//   about as 1/samples; for a source with a small bright feature (a sun) only as the fraction of
//   samples that hit it: a 1-degree sun (9.6e-4 sr) in a lobe of solid angle ~pi (2 alpha)^2
//   gets about samples * 9.6e-4 / lobe hits, i.e. a relative error of order
//   1 / sqrt(that) in the sun's neighbourhood. Use reference_ld_sky for analytic suns.
// * ggx_ld_normaliser(alpha) = W in closed form. With u the GGX NDF variate, W = 4 integral_0^1
//   max(n.l(u), 0) du and n.l = 2 cos^2(theta_h) - 1 = (1 - a u) / (1 - b u), a = 1 + alpha^2,
//   b = 1 - alpha^2, positive for u < u* = 1 / a. Integrating,
//     I = integral_0^u* (1 - a u)/(1 - b u) du = (1 / b) (1 + (2 alpha^2 / b) ln(2 alpha^2 / a)),
//   which cancels as alpha -> 1 (b -> 0); there, with x = b / a in [0, 1),
//     I = (1 / a) sum_{k >= 1} x^(k-1) / (k (k + 1))            (used for x <= 1/2).
//   W = 4 I: W -> 4 as alpha -> 0 (a mirror), W = 1 at alpha = 1.
// * LD weight (runtime/ld_weight.hpp): every LD reference takes the weight of the chain it is
//   compared with (default ld_weight::n_dot_l, Karis's w above). ld_weight::g1 replaces max(n.l, 0)
//   by G1(n.l) in w and in W: ggx_ld_normaliser_g1(alpha) = 4 integral_0^u* G1(n.l(u)) du by
//   midpoint rules (in u down to n.l = 1/2, then in n.l, where G1 falls to 0 over n.l ~ alpha;
//   the default 512 nodes agree with 2^18 to 5e-7 relative: every reference_ld_sky call with a
//   visible sun evaluates it, so it is kept cheap next to the sky's samples).
// * reference_ld_sky(sky, R, r, sky_samples, cap_nodes): sky and sun superpose, and LD is linear
//   in L with a common denominator, so LD = LD_sky + sun_radiance * (integral over the sun cap
//   of w) / W. LD_sky by reference_ld on the sky without its sun (smooth except the horizon
//   step), the cap integral by a product midpoint rule in polar coordinates about the sun
//   direction (cap_nodes radial x 4 cap_nodes azimuthal nodes; error O((r_sun / cap_nodes)^2)
//   relative, the cap edge is followed exactly), W in closed form. Deterministic.
// Irradiance (bake/irradiance.hpp): E(n) = integral over n's hemisphere of L(l) (n.l) dl.
// * reference_irradiance(env, n, samples): cosine-weighted Hammersley points, E = pi mean L,
//   Neumaier sums in double.
// * reference_irradiance_sky(sky, n, samples, cap_nodes): E_sky by reference_irradiance on the
//   sky without its sun plus the sun's cap integral of max(n.l, 0) by the same cap rule (exact
//   also when the cap straddles n's horizon, unlike sky_environment::sun_irradiance).
// * ld_texel_sum(cube, level, dirs, r, w, ex): the exact GGX LD of a cubemap level taken as
//   constant over each texel, by a deterministic sum over every texel t (no sampling noise, and no
//   correlation with any sampler's points: reference_ld draws the Hammersley points filtered
//   importance sampling draws, so at equal counts their errors are not independent):
//     LD(R) = sum_t L_t int_t K / sum_t int_t K,   K(l) = D(h) k(R.l),  h = (R + l) / |R + l|,
//   with k(mu) = mu (n.l) or G1(mu) (ld_weight::g1) and int_t K the kernel over the texel: its
//   value at the texel centre times the texel's exact solid angle, or, for texels within
//   6 lobe widths + 2 texels of R when the lobe (width 2 alpha in l) spans fewer than 8 texels, the
//   sum over s x s sub-texels (s = ceil(8 texel / (2 alpha)) <= 16) of their exact solid angles times
//   K at their centres. D from sin^2 + alpha^2 cos^2 of theta_h = (|R - l|^2 + alpha^2 |R + l|^2) / 4
//   (no cancellation near R). The centre rule's relative error in a texel is about
//   (texel / lobe width)^2 / 6 (0.2% at the 8-texel resolution; the ratio cancels most of it);
//   below alpha = texel / 4 (r < 0.044 on a 256^2 face) the 16 x 16 cap leaves fewer than 8
//   sub-texels across the lobe, and the error grows as (texel / 16 / lobe width)^2.
//   Cost: 6 n^2 kernel evaluations per direction (about 2 ns each on one core of the 2-core VM,
//   vectorised in double: bench_sun, BM_ld_texel_sum), plus s^2 per near texel.
//   ld_texel_sum_level(cube, r) picks a coarser level of an exact-solid-angle chain where the lobe
//   spans >= 10 of its texels (relative RMSE <= 3e-4 measured; see there).
// * irradiance_texel_sum(cube, level, normals, ex): the brute-force sum over every texel t of one
//   cubemap level, E(n) = sum_t L_t Omega_t max(0, n.d_t), with the exact texel solid angles
//   Omega_t (cube_texel_solid_angle) and the texel-centre directions d_t (cube_texel_direction),
//   in double. It is the exact irradiance of the environment that is constant over each texel
//   *up to the centre rule in each texel*: the cosine is taken at the texel centre, so even a
//   constant environment is off pi L by O(1 / n^2), worst at the face normals (the tests show the
//   1 / n^2 convergence; figures: docs/sun.md, section 1). Polynomials of
//   degree <= 2 in d that the cube's symmetries average (e.g. max(0, d_y) max(0, d_y) = d_y^2
//   on the upper half) come out exact up to rounding. Cost: 6 n^2 multiply-adds per normal (a
//   dot product, a max, a vec3 multiply-add), plus 6 n^2 directions and n^2 solid angles once;
//   memory 2 x 6 n^2 vec3<double> (1.2 MB at n = 64). irradiance_texel_sum_level(cube, max_face)
//   picks the first level whose face is <= max_face (bounding the cost per normal).

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "../brdf/ggx.hpp"
#include "../core/constants.hpp"
#include "../core/executor.hpp"
#include "../core/frame.hpp"
#include "../core/limits.hpp"
#include "../core/math.hpp"
#include "../core/sum.hpp"
#include "../core/vec.hpp"
#include "../env/analytic.hpp"
#include "../env/cube_geometry.hpp"
#include "../env/cubemap.hpp"
#include "../env/environment.hpp"
#include "../sampling/ggx.hpp"
#include "../sampling/hemisphere.hpp"
#include "../sampling/lobe.hpp"
#include "../sampling/sequence.hpp"
#include "../runtime/ld_weight.hpp"

namespace ibl {

namespace detail {
/// Radiance of env at a double direction, as double (the environment's own scalar type inside).
template <class Env> vec3<double> radiance_d(const Env& env, const vec3<double>& d) {
    using Te = environment_scalar_t<Env>;
    return vec3<double>(vec3<Te>(env.radiance(vec3<Te>(d), Te(0))));
}

struct neumaier3 {
    neumaier_sum<double> c[3];
    void add(const vec3<double>& v) noexcept {
        for (int k = 0; k < 3; ++k) c[k].add(v[k]);
    }
    [[nodiscard]] vec3<double> value() const noexcept { return {c[0].value(), c[1].value(), c[2].value()}; }
};

/// Integral of f(l) over the cap of angular radius `radius` about unit `axis`: midpoint rule in
/// rho in [0, radius] (density sin rho) and psi in [0, 2 pi).
template <class F> vec3<double> cap_integral(const vec3<double>& axis, double radius, int nodes, F&& f) {
    const int n_rho = nodes > 0 ? nodes : 1, n_psi = 4 * n_rho;
    const frame<double> fr = make_frame(axis);
    const double d_rho = radius / double(n_rho), d_psi = two_pi_v<double> / double(n_psi);
    neumaier3 acc;
    for (int i = 0; i < n_rho; ++i) {
        const double rho = (double(i) + 0.5) * d_rho;
        const double s = std::sin(rho), c = std::cos(rho);
        for (int j = 0; j < n_psi; ++j) {
            const double psi = (double(j) + 0.5) * d_psi;
            const vec3<double> l = fr.to_world(vec3<double>(s * std::cos(psi), s * std::sin(psi), c));
            acc.add(vec3<double>(f(l)) * (s * d_rho * d_psi));
        }
    }
    return acc.value();
}
} // namespace detail

/// W(alpha) = integral over the sphere of D(h) max(n.l, 0) dl with N = V (see the header).
inline double ggx_ld_normaliser(double alpha) {
    const double a2 = sqr(clamp_alpha(alpha));
    const double a = 1.0 + a2, b = (1.0 - std::sqrt(a2)) * (1.0 + std::sqrt(a2)); // b = 1 - alpha^2
    const double x = b / a;
    double i_val;
    if (x <= 0.5) {
        // sum_{k>=1} x^(k-1) / (k (k+1)): 60 terms leave < 0.5^60 (below double resolution).
        double s = 0.0, p = 1.0;
        for (int k = 1; k <= 60; ++k, p *= x) s += p / (double(k) * double(k + 1));
        i_val = s / a;
    } else {
        i_val = (1.0 + (2.0 * a2 / b) * std::log(2.0 * a2 / a)) / b;
    }
    return 4.0 * i_val;
}

/// W of the G1 weight (see the header): 4 integral_0^u* G1(n.l(u)) du. Midpoint rules of
/// nodes / 2 points each: in u while n.l >= 1/2, then in n.l itself (du = 2 alpha^2 / (a - b n.l)^2
/// d n.l), where G1 falls to 0 over n.l ~ alpha (a sliver of u for a sharp lobe).
inline double ggx_ld_normaliser_g1(double alpha, std::uint32_t nodes = 512) {
    const double a = clamp_alpha(alpha), a2 = a * a, aq = 1.0 + a2, bq = (1.0 - a) * (1.0 + a);
    constexpr double mu_s = 0.5;
    const double u_s = (1.0 - mu_s) / (aq - bq * mu_s);
    const std::uint32_t q = nodes > 1 ? nodes / 2 : 1;
    neumaier_sum<double> s;
    for (std::uint32_t i = 0; i < q; ++i) {
        const double u = u_s * (double(i) + 0.5) / double(q);
        s.add(u_s / double(q) * g1_smith_ggx((1.0 - aq * u) / (1.0 - bq * u), a));
        const double mu = mu_s * (double(i) + 0.5) / double(q);
        s.add(mu_s / double(q) * g1_smith_ggx(mu, a) * 2.0 * a2 / sqr(aq - bq * mu));
    }
    return 4.0 * s.value();
}

/// W of weight w: ggx_ld_normaliser (n.l) or ggx_ld_normaliser_g1.
inline double ggx_ld_normaliser(double alpha, ld_weight w) {
    return w == ld_weight::g1 ? ggx_ld_normaliser_g1(alpha) : ggx_ld_normaliser(alpha);
}

/// LD at unit direction R for perceptual roughness r of lobe L (sampling/lobe.hpp; GGX by
/// default): importance sampling with L::sample and weights (n.l) L::ld_weight, `samples`
/// Hammersley points (0 -> 1), lod 0, double. Any environment. reference_ld<ibl::charlie_lobe>(...)
/// is the sheen LD. weight = ld_weight::g1 takes G1(n.l) in place of n.l (GGX; see the header).
/// samples > limits::max_samples throws std::length_error.
template <class Lobe = ggx_lobe, class Env>
    requires ld_lobe<Lobe>
vec3<double> reference_ld(const Env& env, const vec3<double>& dir, double roughness, std::uint32_t samples,
                          ld_weight weight = ld_weight::n_dot_l) {
    detail::check_total("reference_ld", "samples", samples, limits::max_samples, "limits::max_samples");
    const std::uint32_t n = samples > 0 ? samples : 1;
    const frame<double> fr = make_frame(glm::normalize(dir));
    detail::neumaier3 acc;
    neumaier_sum<double> wsum;
    for (std::uint32_t i = 0; i < n; ++i) {
        const vec3<double> h = Lobe::sample(hammersley<double>(i, n), roughness);
        const double n_dot_l = 2.0 * h.z * h.z - 1.0;
        if (!(n_dot_l > 0.0)) continue;
        const double w = ld_weight_factor(weight, n_dot_l, alpha_from_roughness(roughness)) * Lobe::ld_weight(h, roughness);
        if (!(w > 0.0)) continue;
        const vec3<double> l = fr.to_world(vec3<double>(2.0 * h.z * h.x, 2.0 * h.z * h.y, n_dot_l));
        acc.add(w * detail::radiance_d(env, l));
        wsum.add(w);
    }
    const double w = wsum.value();
    return w > 0.0 ? acc.value() / w : vec3<double>(0.0);
}

/// LD of a sky_environment with its sun handled by quadrature (see the header), with the LD
/// weight of the chain it is compared with. Deterministic. sky_samples <= limits::max_samples,
/// cap_nodes <= limits::max_cap_nodes (std::length_error; cap_nodes < 1 counts as 1).
template <class T>
vec3<double> reference_ld_sky(const sky_environment<T>& sky, const vec3<double>& dir, double roughness,
                              std::uint32_t sky_samples = 4096, int cap_nodes = 32,
                              ld_weight weight = ld_weight::n_dot_l) {
    detail::check_total("reference_ld_sky", "sky_samples", sky_samples, limits::max_samples, "limits::max_samples");
    detail::check_total("reference_ld_sky", "cap_nodes", cap_nodes, limits::max_cap_nodes, "limits::max_cap_nodes");
    sky_environment<T> no_sun = sky;
    no_sun.sun_radiance = vec3<T>(T(0));
    const vec3<double> R = glm::normalize(dir);
    vec3<double> ld = reference_ld(no_sun, R, roughness, sky_samples, weight);
    const vec3<double> sun_l(sky.sun_radiance);
    if (!(sky.sun_angular_radius > T(0)) || (sun_l.x == 0.0 && sun_l.y == 0.0 && sun_l.z == 0.0)) return ld;
    const vec3<double> axis = glm::normalize(vec3<double>(sky.sun_dir));
    const double radius = double(sky.sun_angular_radius);
    // The cap contributes nothing when it lies entirely below R's horizon.
    if (glm::dot(axis, R) <= -std::sin(radius)) return ld;
    const double alpha = alpha_from_roughness(roughness);
    const vec3<double> cap = detail::cap_integral(axis, radius, cap_nodes, [&](const vec3<double>& l) {
        const double n_dot_l = glm::dot(R, l);
        if (!(n_dot_l > 0.0)) return vec3<double>(0.0);
        const vec3<double> h = glm::normalize(R + l);
        return vec3<double>(ndf_ggx(glm::dot(R, h), alpha) * ld_weight_factor(weight, n_dot_l, alpha));
    });
    return ld + sun_l * (cap.x / ggx_ld_normaliser(alpha, weight));
}

/// Irradiance E at unit normal n: pi * mean of L over `samples` cosine-distributed Hammersley
/// directions (0 -> 1), lod 0, double. samples > limits::max_samples throws std::length_error.
template <class Env> vec3<double> reference_irradiance(const Env& env, const vec3<double>& normal, std::uint32_t samples) {
    detail::check_total("reference_irradiance", "samples", samples, limits::max_samples, "limits::max_samples");
    const std::uint32_t n = samples > 0 ? samples : 1;
    const frame<double> fr = make_frame(glm::normalize(normal));
    detail::neumaier3 acc;
    for (std::uint32_t i = 0; i < n; ++i) {
        const vec3<double> l = fr.to_world(sample_cosine_hemisphere(hammersley<double>(i, n)));
        acc.add(detail::radiance_d(env, l));
    }
    return acc.value() * (pi_v<double> / double(n));
}

/// Irradiance of a sky_environment with its sun by cap quadrature (see the header). Limits as
/// reference_ld_sky.
template <class T>
vec3<double> reference_irradiance_sky(const sky_environment<T>& sky, const vec3<double>& normal,
                                      std::uint32_t sky_samples = 4096, int cap_nodes = 32) {
    detail::check_total("reference_irradiance_sky", "sky_samples", sky_samples, limits::max_samples, "limits::max_samples");
    detail::check_total("reference_irradiance_sky", "cap_nodes", cap_nodes, limits::max_cap_nodes, "limits::max_cap_nodes");
    sky_environment<T> no_sun = sky;
    no_sun.sun_radiance = vec3<T>(T(0));
    const vec3<double> nn = glm::normalize(normal);
    vec3<double> e = reference_irradiance(no_sun, nn, sky_samples);
    if (!(sky.sun_angular_radius > T(0))) return e;
    const vec3<double> cap = detail::cap_integral(glm::normalize(vec3<double>(sky.sun_dir)),
                                                  double(sky.sun_angular_radius), cap_nodes,
                                                  [&](const vec3<double>& l) { return vec3<double>(saturate(glm::dot(nn, l))); });
    return e + vec3<double>(sky.sun_radiance) * cap.x;
}

/// The first level of c whose face size is <= max_face, or the coarsest level if none is: the level
/// irradiance_texel_sum runs on for a cost of at most 6 max_face^2 terms per normal (when the
/// chain reaches that size). Throws std::invalid_argument if max_face < 1.
template <class T> int irradiance_texel_sum_level(const cubemap<T>& c, int max_face) {
    if (max_face < 1)
        throw std::invalid_argument("ibl::irradiance_texel_sum_level: max_face must be >= 1, got " +
                                    std::to_string(max_face));
    int level = 0;
    while (c.size(level) > max_face && level + 1 < c.levels()) ++level;
    return level;
}

/// Brute-force irradiance over the texels of level `level` of c (see the header): for each normal
/// n_i, E_i = sum over faces f = 0..5, rows y, columns x (in that order) of
///     (vec3<double>(L_t) * Omega_t) * max(0, dot(n_i, d_t)),
/// accumulated in double in exactly that order (the texel's radiance times its solid angle first,
/// then times the clamped cosine), so the result is a fixed function of the texels and the normal;
/// the executor spreads the normals (work items: normals) and never changes a result.
/// Normals are used as given, not normalised: the sum is homogeneous of degree 1 in n, so a normal
/// of length s gives s E(n / s) up to rounding (exactly, bit for bit, when s is a power of two),
/// a zero normal gives 0, and a NaN component makes every clamped cosine max(0, NaN) = 0, so E = 0.
/// Non-finite radiance components read as 0. Borders are not read (they need not be valid).
/// Throws std::invalid_argument unless 0 <= level < c.levels().
template <class T, class Executor = serial_executor>
std::vector<vec3<double>> irradiance_texel_sum(const cubemap<T>& c, int level, std::span<const vec3<double>> normals,
                                               Executor&& ex = Executor{}) {
    if (level < 0 || level >= c.levels())
        throw std::invalid_argument("ibl::irradiance_texel_sum: level must be in [0, " + std::to_string(c.levels()) +
                                    "), got " + std::to_string(level));
    const int n = c.size(level);
    const std::size_t nn = std::size_t(n) * std::size_t(n);
    const std::vector<double> omega = cube_face_solid_angles<double>(n); // the same on every face
    std::vector<vec3<double>> dir, rad;
    dir.reserve(6 * nn);
    rad.reserve(6 * nn);
    for (int f = 0; f < 6; ++f)
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
                vec3<double> L(c.texel(f, x, y, level));
                for (int k = 0; k < 3; ++k)
                    if (!is_finite(L[k])) L[k] = 0.0;
                dir.push_back(cube_texel_direction<double>(f, x, y, n));
                rad.push_back(L * omega[std::size_t(y) * std::size_t(n) + std::size_t(x)]);
            }
    std::vector<vec3<double>> out(normals.size());
    ex(normals.size(), [&](std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i) {
            const vec3<double> ni = normals[i];
            vec3<double> s(0.0);
            for (std::size_t t = 0; t < dir.size(); ++t) s += rad[t] * std::max(0.0, glm::dot(ni, dir[t]));
            out[i] = s;
        }
    });
    return out;
}

namespace detail {
/// GGX LD kernel D(h) k(R.l) (ld_texel_sum) for unit R, l; 0 behind R's plane.
inline double ld_sum_kernel(const vec3<double>& R, const vec3<double>& l, double a2, double alpha, ld_weight w) noexcept {
    const double c = glm::dot(R, l);
    if (!(c > 0.0)) return 0.0;
    const vec3<double> s = R + l, d = R - l;
    const double q = 0.25 * (glm::dot(d, d) + a2 * glm::dot(s, s));
    return a2 / (pi_v<double> * q * q) * ld_weight_factor(w, c, alpha);
}
} // namespace detail

/// The coarsest level of c whose texels (2 / face, the angle of a face-centre texel) are at most
/// min(alpha / 10, 1 / 32) for GGX roughness r (clamped to [0, 1]), else level 0: the level
/// ld_texel_sum may sum instead of level 0 when the chain's mips are exact solid-angle averages.
/// A coarser level moves each texel's flux to its centre; measured against level 0 on the
/// courtyard and studio HDRIs at 256^2, 400 directions per roughness (research/fast_tap_study.cpp):
/// relative RMSE 7e-5 .. 2.8e-4 at r = 0.4 .. 1 (levels 1, 2); r = 0.2 stays at level 0 (level 1
/// would be 9e-4). The largest single error measured: 6.1e-4 on the built-in sky's sun (10^4 times
/// the sky) at r = 0.6, level 2 (bench_sun, BM_ld_texel_sum).
template <class T> int ld_texel_sum_level(const cubemap<T>& c, double roughness) {
    const double r = std::clamp(std::isfinite(roughness) ? roughness : 0.0, 0.0, 1.0);
    const double max_texel = std::min(alpha_from_roughness(r) / 10.0, 1.0 / 32.0);
    int level = 0;
    while (level + 1 < c.levels() && 2.0 / double(c.size(level + 1)) <= max_texel) ++level;
    return level;
}

/// Exact LD of level `level` of c, constant over each texel, at unit directions `dirs` for GGX
/// perceptual roughness r and LD weight w (see the header: the centre rule, with sub-texels near R
/// for lobes of fewer than 8 texels). Every direction's sums run over faces, rows, columns in that
/// order in fixed lanes, so the result is a fixed function of the texels and the direction; the
/// executor spreads the directions and never changes a result. Non-finite radiance components read
/// as 0; borders are not read. A zero or NaN direction gives 0. r is clamped to [0, 1] (NaN: 0).
/// Throws std::invalid_argument unless 0 <= level < c.levels().
template <class T, class Executor = serial_executor>
std::vector<vec3<double>> ld_texel_sum(const cubemap<T>& c, int level, std::span<const vec3<double>> dirs, double roughness,
                                       ld_weight w = ld_weight::n_dot_l, Executor&& ex = Executor{}) {
    if (level < 0 || level >= c.levels())
        throw std::invalid_argument("ibl::ld_texel_sum: level must be in [0, " + std::to_string(c.levels()) + "), got " +
                                    std::to_string(level));
    const int n = c.size(level);
    const std::size_t nn = std::size_t(n) * std::size_t(n), count = 6 * nn;
    const double r = std::clamp(std::isfinite(roughness) ? roughness : 0.0, 0.0, 1.0);
    const double alpha = clamp_alpha(alpha_from_roughness(r)), a2 = alpha * alpha;
    // Structure of arrays: direction and radiance times solid angle per texel, in cubemap order.
    std::vector<double> dx(count), dy(count), dz(count), om(count), lr(count), lg(count), lb(count);
    for (int f = 0; f < 6; ++f)
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
                const std::size_t i = cube_texel_index(f, x, y, n);
                const vec3<double> d = cube_texel_direction<double>(f, x, y, n);
                vec3<double> L(c.texel(f, x, y, level));
                for (int k = 0; k < 3; ++k)
                    if (!is_finite(L[k])) L[k] = 0.0;
                const double o = cube_texel_solid_angle<double>(x, y, n);
                dx[i] = d.x, dy[i] = d.y, dz[i] = d.z, om[i] = o;
                lr[i] = L.x, lg[i] = L.y, lb[i] = L.z;
            }
    // Sub-texels near R when the lobe spans fewer than 8 texels (face-centre texel angle 2 / n).
    const double texel = 2.0 / double(n), width = 2.0 * alpha;
    const int sub = int(std::clamp(std::ceil(8.0 * texel / width), 1.0, 16.0));
    const double near_cos = sub > 1 ? std::cos(std::min(pi_v<double>, 6.0 * width + 2.0 * texel)) : 2.0;
    std::vector<vec3<double>> out(dirs.size());
    // Directions in groups of `group` over tiles of `tile` texels (the 7 arrays of a tile stay in
    // cache); each direction's terms still run over the texels in order in its own lanes.
    constexpr std::size_t lanes = 8, group = 8, tile = 2048;
    ex(dirs.size(), [&](std::size_t b, std::size_t e) {
        for (std::size_t g0 = b; g0 < e; g0 += group) {
            const std::size_t gn = std::min(group, e - g0);
            vec3<double> R[group];
            bool ok[group];
            double sr[group][lanes] = {}, sg[group][lanes] = {}, sb[group][lanes] = {}, sw[group][lanes] = {};
            for (std::size_t g = 0; g < gn; ++g) {
                const double len = std::sqrt(glm::dot(dirs[g0 + g], dirs[g0 + g]));
                ok[g] = len > 0.0 && std::isfinite(len);
                R[g] = ok[g] ? dirs[g0 + g] / len : vec3<double>(0.0, 0.0, 1.0);
            }
            // One direction's terms over texels [t0, t0 + M): K at the texel centre times its solid
            // angle, 0 behind R's plane and, with sub-texels, for the near texels the second pass sums.
            auto block = [&]<bool G1, std::size_t M>(std::size_t g, std::size_t t0) {
                const vec3<double> r = R[g];
                for (std::size_t j = 0; j < M; ++j) {
                    const std::size_t t = t0 + j;
                    const double cth = dx[t] * r.x + dy[t] * r.y + dz[t] * r.z;
                    const double m = std::max(cth, 0.0);
                    // |R - l|^2 from the components, |R + l|^2 = 4 - |R - l|^2 (no cancellation at c ~ 1).
                    const double ex_ = dx[t] - r.x, ey = dy[t] - r.y, ez = dz[t] - r.z;
                    const double d2 = ex_ * ex_ + ey * ey + ez * ez;
                    const double q = 0.25 * (d2 + a2 * (4.0 - d2));
                    double k = m;
                    if constexpr (G1) k = 2.0 * m / (m + std::sqrt(m * m + a2 * (1.0 - m) * (1.0 + m)));
                    const double kw = (cth < near_cos ? k : 0.0) * (a2 * inv_pi_v<double>) / (q * q) * om[t];
                    sr[g][j] += kw * lr[t], sg[g][j] += kw * lg[t], sb[g][j] += kw * lb[t], sw[g][j] += kw;
                }
            };
            auto run = [&]<bool G1>() {
                for (std::size_t t0 = 0; t0 < count; t0 += tile) {
                    const std::size_t t1 = std::min(count, t0 + tile);
                    for (std::size_t g = 0; g < gn; ++g) {
                        std::size_t t = t0;
                        for (; t + lanes <= t1; t += lanes) block.template operator()<G1, lanes>(g, t);
                        for (; t < t1; ++t) block.template operator()<G1, 1>(g, t);
                    }
                }
            };
            if (w == ld_weight::g1) run.template operator()<true>();
            else run.template operator()<false>();
            for (std::size_t g = 0; g < gn; ++g) {
                if (sub > 1) // near texels: s x s sub-texels, each its exact solid angle times K at its centre
                    for (std::size_t u = 0; u < count; ++u) {
                        if (!(dx[u] * R[g].x + dy[u] * R[g].y + dz[u] * R[g].z >= near_cos)) continue;
                        const int f = int(u / nn), y = int((u % nn) / std::size_t(n)), x = int(u % std::size_t(n));
                        double kw = 0.0;
                        for (int sy = 0; sy < sub; ++sy)
                            for (int sx = 0; sx < sub; ++sx) {
                                const int X = x * sub + sx, Y = y * sub + sy, N = n * sub;
                                kw += detail::ld_sum_kernel(R[g], cube_texel_direction<double>(f, X, Y, N), a2, alpha, w) *
                                      cube_texel_solid_angle<double>(X, Y, N);
                            }
                        sr[g][0] += kw * lr[u], sg[g][0] += kw * lg[u], sb[g][0] += kw * lb[u], sw[g][0] += kw;
                    }
                double r_ = 0.0, g_ = 0.0, b_ = 0.0, w_ = 0.0;
                for (std::size_t j = 0; j < lanes; ++j) r_ += sr[g][j], g_ += sg[g][j], b_ += sb[g][j], w_ += sw[g][j];
                out[g0 + g] = ok[g] && w_ > 0.0 ? vec3<double>(r_, g_, b_) / w_ : vec3<double>(0.0);
            }
        }
    });
    return out;
}

/// fn(unit direction) at every texel centre of an n x n-per-face cube, in cubemap order
/// (face, y, x), through the executor (work items: face rows). For references of whole levels.
/// Throws std::invalid_argument for n < 1, std::length_error for 6 n^2 > limits::max_texels.
template <class F, class Executor = serial_executor>
std::vector<vec3<double>> reference_faces(int n, F&& fn, Executor&& ex = Executor{}) {
    detail::check_arg("reference_faces", "n", n, 1, limits::max_face_size, "limits::max_face_size");
    detail::check_total("reference_faces", "texels 6 n^2", 6 * std::uint64_t(n) * std::uint64_t(n), limits::max_texels,
                        "limits::max_texels");
    std::vector<vec3<double>> out(std::size_t(6) * std::size_t(n) * std::size_t(n));
    ex(std::size_t(6 * n), [&](std::size_t b, std::size_t e) {
        for (std::size_t row = b; row < e; ++row) {
            const int face = int(row) / n, y = int(row) % n;
            for (int x = 0; x < n; ++x)
                out[row * std::size_t(n) + std::size_t(x)] = vec3<double>(fn(cube_texel_direction<double>(face, x, y, n)));
        }
    });
    return out;
}

} // namespace ibl

#endif // IBL_DETAIL_CXX20
