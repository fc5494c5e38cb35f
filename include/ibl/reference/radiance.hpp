#pragma once
// ibl/reference/radiance.hpp — outgoing radiance under an environment WITHOUT the
// split-sum approximation: the reference that measures the split sum's error per material
// (host only, double precision, deterministic; slow by design).
//
// ---- The integral ------------------------------------------------------------------------------
//   Lo(n, v) = integral over the hemisphere of f(v, l) L(l) (n.l) d(omega_l),   f = f_d + f_s
//   f_s = D(h) V(v, l) F(v.h)      the specular lobe of a BRDF model M (brdf/model.hpp; default
//                                  ggx_height_correlated), h = normalize(v + l), Schlick Fresnel
//                                  F = F0 + (F90 - F0)(1 - v.h)^5 per channel (fresnel_schlick)
//   f_d = k_d diffuse_albedo / pi  Lambert, diffuse_albedo = base_color (1 - metallic). k_d is a
//                                  constant per (n, v), so the diffuse lobe stays exactly Lambertian
//                                  and its integral is k_d diffuse_albedo E(n) / pi:
//       diffuse_weighting::lambert                       k_d = 1 (f = f_d + f_s, no coupling)
//       diffuse_weighting::one_minus_fresnel_roughness   k_d = 1 - F_r(n.v), F_r = fresnel_schlick_
//           roughness(n.v, F0, r): the kD of runtime/shade.hpp's single-scattering ambient
//           ((1 - F)(1 - metallic) base_color), so that runtime/shade.hpp's diffuse term and this
//           reference's diffuse term are the same functional of L and the comparison measures the
//           specular split-sum error (and the irradiance product's error) only.
//   The reference is single scattering: it matches runtime/shade.hpp's single-scattering path, not the
//   Fdez-Agüera multiple-scattering path (whose extra lobe has no BRDF to integrate).
//   Mirror limit: when M::alpha(r) is ggx_effectively_smooth (r < 2^-6 for alpha = r^2), f_s is
//   the delta of an ideal mirror and its term is exactly F(n.v) L(R), R = reflect(-v, n) = 2 (n.v)
//   n - v (the r = 0 limit of dfg_smooth_limit: F0 A + F90 B = F(n.v)); only f_d is sampled.
//
// ---- The estimator: multiple importance sampling (E. Veach, L. Guibas, "Optimally Combining
//      Sampling Techniques for Monte Carlo Rendering", SIGGRAPH 1995; Veach's thesis ch. 9) ------
//   Two techniques, each with its own sample count (n_b + n_e per batch):
//   (b) the BRDF: a lobe-selection mixture
//         pdf_b(l) = p_s pdf_vndf(l) + (1 - p_s) (n.l) / pi
//       pdf_vndf(l) = G1(v) D_ggx(h) / (4 n.v) per solid angle of l: GGX visible normals
//       (sample_ggx_vndf, Dupuy & Benyoub 2023) reflected (ggx_vndf_reflected_pdf); the cosine
//       lobe by sample_cosine_hemisphere. The lobe is chosen with u.x < p_s and u.x is rescaled to
//       [0, 1) within the chosen branch (keeps the stratification). The mixture pdf (not the pdf of
//       the branch taken) enters the weights, so the technique is one density over the hemisphere.
//       Lobe-selection probability: p_s = s / (s + d) with s = Y(F(n.v)) (Schlick at the view
//       cosine: the specular albedo's leading factor) and d = Y(k_d diffuse_albedo) (the diffuse
//       albedo), Y = luminance, clamped to [lobe_select_min, 1 - lobe_select_min] = [0.2, 0.8]
//       when both lobes are present. Reason for the clamp: F(n.v) underestimates the specular
//       share of the PRODUCT f L when the lobe meets a bright source (a dielectric's highlight of
//       the sun dominates Lo although F(n.v) = 0.04); the clamp keeps either lobe at >= 20% of the
//       BRDF draws. A lobe that is absent (zero albedo) gets p = 0, the other 1. For the mirror
//       p_s = 0.
//       For a model whose NDF is not GGX, the GGX VNDF of alpha = M::alpha(r) is still a valid
//       proposal (its support is the whole upper hemisphere); only efficiency changes.
//   (e) the environment: cube_env_distribution (reference/env_importance.hpp): texels by luminance
//       times solid angle, uniform in (sc, tc) within the texel, pdf_e per solid angle.
//   Weights: the power heuristic (beta = 2) by default, balance optionally, with the counts:
//       w_b(l) = (n_b pdf_b)^2 / ((n_b pdf_b)^2 + (n_e pdf_e)^2),   w_e = 1 - w_b,
//   computed as 1 / (1 + (q_other / q_self)^2) (no overflow for peaked pdfs). Estimate per batch:
//       (1/n_b) sum_i w_b f L cos / pdf_b  +  (1/n_e) sum_j w_e f L cos / pdf_e.
//   Unbiased whenever pdf_b > 0 wherever f cos > 0 (always: the mixture covers the hemisphere when
//   p_s < 1, and the VNDF alone covers it when p_s = 1, since every l above the horizon has a half
//   vector with v.h > 0) — the environment distribution may vanish where L does not.
//   Strategies: mis (default; n_e = floor(env_fraction N), n_b = N - n_e), brdf (n_e = 0: the
//   BRDF mixture alone) and env (n_b = 0: environment sampling alone; unbiased only when the
//   distribution covers the support of L, which the tent filter guarantees for the cubemap it was
//   built from; the mirror term is still added exactly).
//
// ---- Determinism and the standard error ------------------------------------------------------
//   Randomised quasi-Monte Carlo: the samples are split into `batches` independent batches; batch
//   k draws technique t's points from the 2-D Sobol' sequence (dimension 1 = van der Corput,
//   dimension 2 = Sobol's second, the (0, 2)-sequence of I. M. Sobol' 1967 / A. Kollig, A. Keller
//   2002), each dimension Owen-scrambled (owen_hash_permutation, Burley 2020) with a seed hashed
//   from (options.seed, k, t, dimension). Batches are therefore i.i.d. unbiased estimates, and
//       estimate = mean of the batch means,  std_error = sd(batch means) / sqrt(batches)
//   is an honest error of the returned estimate (it does not assume independence of the
//   samples within a batch, which QMC violates on purpose). Batches are computed through the
//   executor and folded in batch order: the result depends only on the inputs and options.
//   samples = total radiance evaluations (draws) over all batches; per batch samples / batches
//   (at least 1), batches >= 2 (smaller counts are raised to 2); samples <= limits::max_samples and
//   batches <= limits::max_batches (core/limits.hpp; std::length_error beyond). The mirror term costs one more evaluation and has zero error.
//   Caveat (every sample-based error bar has it): a bright feature that no batch hits is
//   invisible to the standard error: BRDF sampling alone under a small sun can miss it in every
//   batch and report a value far too low with a small standard error; with environment sampling
//   in the mix every batch hits the sun. Use mis for peaked environments (figures: docs/runtime.md,
//   "The full integral"). The residual MIS error is the sun's edge: a texel the cap covers
//   partly is drawn by its mean luminance and its draws hit or miss the sun (relative variance
//   (1 - c) / c at coverage c); a finer proposal cube shrinks the partly covered share.
//
// ---- Domains ------------------------------------------------------------------------------------
//   n, v unit (world space); n.v is clamped to [0, 1] by projecting v onto n's upper hemisphere
//   (v with n.v < 0 is moved to the tangent plane; v = -n gives 0). n.v = 0, r = 0 and r = 1 give
//   finite estimates. The environment is evaluated at lod 0 in its own scalar type (its
//   `scalar_type` member if present, else double when it models environment<E, double>, else
//   float), converted to double. Radiance must be finite and non-negative for the bounds above.

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <cmath>
#include <concepts>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <type_traits>
#include <vector>

#include "../brdf/fresnel.hpp"
#include "../brdf/ggx.hpp"
#include "../brdf/model.hpp"
#include "../core/color.hpp"
#include "../core/constants.hpp"
#include "../core/executor.hpp"
#include "../core/frame.hpp"
#include "../core/limits.hpp"
#include "../core/math.hpp"
#include "../core/vec.hpp"
#include "../env/environment.hpp"
#include "../sampling/ggx.hpp"
#include "../sampling/hemisphere.hpp"
#include "../sampling/sequence.hpp"
#include "env_importance.hpp"

namespace ibl {

// ---- options and results -------------------------------------------------------------------------

enum class radiance_strategy { mis, brdf, env };
enum class mis_heuristic { balance, power };
enum class diffuse_weighting { lambert, one_minus_fresnel_roughness };

/// Smallest lobe-selection probability when both lobes are present (reason: header comment).
inline constexpr double lobe_select_min = 0.2;

struct radiance_reference_options {
    std::uint32_t samples = 1u << 14; ///< total draws (radiance evaluations), the cost knob
    std::uint32_t batches = 16;       ///< independent randomisations (>= 2) for the standard error
    std::uint32_t seed = 0;           ///< base seed of the scrambles
    radiance_strategy strategy = radiance_strategy::mis;
    mis_heuristic heuristic = mis_heuristic::power;
    double env_fraction = 0.5;        ///< share of the draws given to environment sampling (mis)
};

/// A material as the reference sees it (all linear RGB).
struct reference_material {
    vec3<double> diffuse_albedo{0.0}; ///< Lambert albedo (base_color (1 - metallic))
    vec3<double> f0{0.04};            ///< Schlick F0
    vec3<double> f90{1.0};            ///< Schlick F90
    double roughness = 0.5;           ///< perceptual roughness r in [0, 1]
    diffuse_weighting diffuse = diffuse_weighting::lambert;
};

/// The reference material of a metallic-roughness material (glTF 2.0): F0 = mix(dielectric_f0,
/// base_color, metallic), diffuse_albedo = base_color (1 - metallic) (brdf/fresnel.hpp).
inline reference_material make_reference_material(const vec3<double>& base_color, double metallic, double roughness,
                                                  diffuse_weighting weighting = diffuse_weighting::lambert,
                                                  double dielectric_f0 = dielectric_f0_v<double>,
                                                  const vec3<double>& f90 = vec3<double>(1.0)) {
    return {diffuse_from_metallic(base_color, metallic), f0_from_metallic(base_color, metallic, dielectric_f0), f90,
            saturate(roughness), weighting};
}

/// Two-part value of a lobe (see integrate_product_mis): parts[0] and parts[1] are integrated and
/// reported separately (diffuse and specular for the BRDF).
struct lobe_value {
    vec3<double> parts[2] = {vec3<double>(0.0), vec3<double>(0.0)};
};

/// A draw of a lobe: unit world direction and its density per unit solid angle (0: no sample).
struct lobe_sample {
    vec3<double> dir{0.0, 0.0, 1.0};
    double pdf = 0.0;
};

/// What integrate_product_mis needs from the non-environment factor g(l) of the integrand
/// integral g(l) L(l) d(omega_l): a sampler, its density, and g's two parts.
template <class B>
concept product_lobe = requires(const B& b, vec2<double> u, vec3<double> d) {
    { b.sample(u) } -> std::same_as<lobe_sample>;
    { b.pdf(d) } -> std::convertible_to<double>;
    { b.eval(d) } -> std::same_as<lobe_value>;
};

/// Estimate and standard error of a two-part integral.
struct product_estimate {
    vec3<double> value{0.0};            ///< parts[0] + parts[1]
    vec3<double> parts[2] = {vec3<double>(0.0), vec3<double>(0.0)};
    vec3<double> std_error{0.0};        ///< of value (from the batch means of the sum)
    vec3<double> parts_std_error[2] = {vec3<double>(0.0), vec3<double>(0.0)};
    std::uint64_t samples = 0;          ///< radiance evaluations drawn
};

/// Outgoing radiance and its parts, each with its standard error.
struct radiance_estimate {
    vec3<double> value{0.0};             ///< Lo = diffuse + specular
    vec3<double> diffuse{0.0};           ///< the f_d part
    vec3<double> specular{0.0};          ///< the f_s part (with the exact mirror term when r ~ 0)
    vec3<double> std_error{0.0};
    vec3<double> std_error_diffuse{0.0};
    vec3<double> std_error_specular{0.0};
    std::uint64_t samples = 0;           ///< radiance evaluations
};

namespace detail {

// ---- sample streams ------------------------------------------------------------------------------

/// 32-bit integer hash (C. Wellons' "lowbias32", a bijective xorshift-multiply mix).
IBL_FUNC constexpr std::uint32_t rr_hash(std::uint32_t x) noexcept {
    x ^= x >> 16;
    x *= 0x7feb352du;
    x ^= x >> 15;
    x *= 0x846ca68bu;
    x ^= x >> 16;
    return x;
}

/// Seed of (base, batch, technique, dimension): chained hashes.
IBL_FUNC constexpr std::uint32_t rr_seed(std::uint32_t base, std::uint32_t batch, std::uint32_t technique,
                                         std::uint32_t dim) noexcept {
    return rr_hash(rr_hash(rr_hash(base ^ 0x9e3779b9u) + batch) + 2u * technique + dim);
}

/// Sobol's second dimension as 32 fraction bits (MSB first): x = XOR of v_k over the set bits k
/// of i, v_0 = 2^31, v_{k+1} = v_k ^ (v_k >> 1) (Kollig & Keller 2002).
IBL_FUNC constexpr std::uint32_t sobol_dim2_bits(std::uint32_t i) noexcept {
    std::uint32_t x = 0;
    for (std::uint32_t v = 1u << 31; i != 0; i >>= 1, v ^= v >> 1)
        if (i & 1u) x ^= v;
    return x;
}

/// Owen scramble of 32 fraction bits (MSB first): the nested-uniform hash acts on the
/// bit-reversed word (bit k of the result depends on bits 0..k), so reverse, hash, reverse.
IBL_FUNC constexpr std::uint32_t owen_scramble_bits(std::uint32_t bits, std::uint32_t seed) noexcept {
    return reverse_bits(owen_hash_permutation(reverse_bits(bits), seed));
}

/// Point i of the Owen-scrambled 2-D Sobol' sequence with per-dimension seeds, in [0, 1)^2.
IBL_FUNC vec2<double> scrambled_sobol2(std::uint32_t i, std::uint32_t seed0, std::uint32_t seed1) noexcept {
    return {double(owen_scramble_bits(reverse_bits(i), seed0)) * 0x1p-32,
            double(owen_scramble_bits(sobol_dim2_bits(i), seed1)) * 0x1p-32};
}

// ---- environment access ----------------------------------------------------------------------

/// Radiance of env at lod 0 in direction d, evaluated in the environment's scalar type.
template <class Env> vec3<double> rr_radiance(const Env& env, const vec3<double>& d) {
    using Te = environment_scalar_t<Env>;
    return vec3<double>(vec3<Te>(env.radiance(vec3<Te>(d), Te(0))));
}

/// MIS weight of the technique with q_self = n_self pdf_self against q_other.
inline double rr_mis_weight(double q_self, double q_other, mis_heuristic h) noexcept {
    if (!(q_self > 0.0)) return 0.0;
    const double ratio = q_other / q_self;
    return h == mis_heuristic::power ? 1.0 / (1.0 + ratio * ratio) : 1.0 / (1.0 + ratio);
}

struct rr_batch {
    vec3<double> parts[2] = {vec3<double>(0.0), vec3<double>(0.0)};
};

/// One technique's sum over its n draws (seeds seed0, seed1): draw(u) gives a sample (dir, pdf),
/// q_other(dir) the other technique's count times its pdf; each draw adds its MIS-weighted
/// g(l) L(l) / pdf to sum[0], sum[1] (the lobe's two parts).
template <class Lobe, class Env, class Draw, class QOther>
void rr_technique_sum(const Env& env, const Lobe& lobe, std::uint32_t n, double n_self, std::uint32_t seed0,
                      std::uint32_t seed1, mis_heuristic h, Draw&& draw, QOther&& q_other, vec3<double> (&sum)[2]) {
    for (std::uint32_t i = 0; i < n; ++i) {
        const auto s = draw(scrambled_sobol2(i, seed0, seed1));
        if (!(s.pdf > 0.0)) continue;
        const lobe_value g = lobe.eval(s.dir);
        if (g.parts[0] == vec3<double>(0.0) && g.parts[1] == vec3<double>(0.0)) continue;
        const double w = rr_mis_weight(n_self * s.pdf, q_other(s.dir), h) / s.pdf;
        const vec3<double> l = rr_radiance(env, s.dir);
        sum[0] += (w * l) * g.parts[0];
        sum[1] += (w * l) * g.parts[1];
    }
}

/// Batch k's estimate: n_b lobe draws and n_e environment draws, each technique's sum over its count.
template <class Lobe, class Env>
rr_batch rr_batch_estimate(const Env& env, const cube_env_distribution* dist, const Lobe& lobe,
                           const radiance_reference_options& opt, std::uint32_t kb, std::uint32_t n_b, std::uint32_t n_e) {
    const double nb = double(n_b), ne = double(n_e);
    vec3<double> sum_b[2] = {vec3<double>(0.0), vec3<double>(0.0)};
    vec3<double> sum_e[2] = {vec3<double>(0.0), vec3<double>(0.0)};
    rr_technique_sum(env, lobe, n_b, nb, rr_seed(opt.seed, kb, 0, 0), rr_seed(opt.seed, kb, 0, 1), opt.heuristic,
                     [&](const vec2<double>& u) { return lobe.sample(u); },
                     [&](const vec3<double>& d) { return ne * (n_e > 0 ? dist->pdf(d) : 0.0); }, sum_b);
    rr_technique_sum(env, lobe, n_e, ne, rr_seed(opt.seed, kb, 1, 0), rr_seed(opt.seed, kb, 1, 1), opt.heuristic,
                     [&](const vec2<double>& u) { return dist->sample(u); },
                     [&](const vec3<double>& d) { return nb * (n_b > 0 ? double(lobe.pdf(d)) : 0.0); }, sum_e);
    rr_batch r;
    for (int p = 0; p < 2; ++p)
        r.parts[p] = (n_b > 0 ? sum_b[p] / nb : vec3<double>(0.0)) + (n_e > 0 ? sum_e[p] / ne : vec3<double>(0.0));
    return r;
}

/// Mean and standard error of the batch means, folded in batch order.
inline product_estimate rr_fold_batches(const std::vector<rr_batch>& res) {
    product_estimate out;
    const double bn = double(res.size());
    vec3<double> mean[3] = {vec3<double>(0.0), vec3<double>(0.0), vec3<double>(0.0)};
    for (const auto& r : res) {
        mean[0] += r.parts[0];
        mean[1] += r.parts[1];
        mean[2] += r.parts[0] + r.parts[1];
    }
    for (auto& m : mean) m /= bn;
    vec3<double> var[3] = {vec3<double>(0.0), vec3<double>(0.0), vec3<double>(0.0)};
    for (const auto& r : res) {
        const vec3<double> d0 = r.parts[0] - mean[0], d1 = r.parts[1] - mean[1];
        const vec3<double> d2 = (r.parts[0] + r.parts[1]) - mean[2];
        var[0] += d0 * d0;
        var[1] += d1 * d1;
        var[2] += d2 * d2;
    }
    auto se = [&](const vec3<double>& v) {
        const vec3<double> q = v / (bn * (bn - 1.0));
        return vec3<double>(std::sqrt(q.x), std::sqrt(q.y), std::sqrt(q.z));
    };
    out.parts[0] = mean[0];
    out.parts[1] = mean[1];
    out.value = mean[2];
    out.parts_std_error[0] = se(var[0]);
    out.parts_std_error[1] = se(var[1]);
    out.std_error = se(var[2]);
    return out;
}

} // namespace detail

// ---- the generic MIS integrator --------------------------------------------------------------------

/// integral g(l) L(l) d(omega_l) for a lobe g (concept product_lobe) by MIS of the lobe's sampler
/// and the environment distribution `dist` (nullptr: lobe sampling only), with the batching and
/// scrambling described in the header. Throws std::invalid_argument for strategy env without a
/// distribution or env_fraction outside [0, 1], std::length_error for opt.samples >
/// limits::max_samples or opt.batches > limits::max_batches.
template <class Lobe, class Env, class Executor = serial_executor>
    requires product_lobe<Lobe>
product_estimate integrate_product_mis(const Env& env, const cube_env_distribution* dist, const Lobe& lobe,
                                       const radiance_reference_options& opt, Executor&& ex = Executor{}) {
    if (opt.strategy == radiance_strategy::env && dist == nullptr)
        throw std::invalid_argument("ibl::integrate_product_mis: strategy env needs an environment distribution");
    if (!(opt.env_fraction >= 0.0 && opt.env_fraction <= 1.0))
        throw std::invalid_argument("ibl::integrate_product_mis: env_fraction must be in [0, 1]");
    detail::check_total("integrate_product_mis", "samples", opt.samples, limits::max_samples, "limits::max_samples");
    detail::check_total("integrate_product_mis", "batches", opt.batches, limits::max_batches, "limits::max_batches");
    const std::uint32_t batches = opt.batches >= 2 ? opt.batches : 2;
    const std::uint32_t per_batch = opt.samples / batches > 0 ? opt.samples / batches : 1;
    std::uint32_t n_e = 0;
    if (dist != nullptr) {
        if (opt.strategy == radiance_strategy::env) n_e = per_batch;
        if (opt.strategy == radiance_strategy::mis) n_e = std::uint32_t(std::floor(opt.env_fraction * double(per_batch)));
    }
    const std::uint32_t n_b = per_batch - n_e;
    std::vector<detail::rr_batch> res(batches);
    ex(std::size_t(batches), [&](std::size_t begin, std::size_t end) {
        for (std::size_t k = begin; k < end; ++k) res[k] = detail::rr_batch_estimate(env, dist, lobe, opt, std::uint32_t(k), n_b, n_e);
    });
    product_estimate out = detail::rr_fold_batches(res);
    out.samples = std::uint64_t(batches) * per_batch;
    return out;
}

// ---- the BRDF lobe ---------------------------------------------------------------------------------

/// f(v, l) (n.l) of a reference_material under model M as a product_lobe: parts[0] = diffuse,
/// parts[1] = specular (0 in the mirror regime, whose delta the caller adds: mirror_term()).
template <class Model = ggx_height_correlated> class brdf_lobe {
public:
    brdf_lobe(const vec3<double>& n, const vec3<double>& v, const reference_material& m)
        : frame_(make_frame(n)), m_(m) {
        vec3<double> vl = frame_.to_local(v);
        if (vl.z < 0.0) vl.z = 0.0; // project onto the upper hemisphere (header: domains)
        const double len2 = glm::dot(vl, vl);
        valid_ = len2 > 0.0;
        v_ = valid_ ? vl * (1.0 / std::sqrt(len2)) : vec3<double>(0.0, 0.0, 1.0);
        n_dot_v_ = v_.z;
        alpha_ = Model::alpha(m.roughness);
        mirror_ = ggx_effectively_smooth(alpha_);
        const vec3<double> kd = m.diffuse == diffuse_weighting::one_minus_fresnel_roughness
                                    ? vec3<double>(1.0) - fresnel_schlick_roughness(n_dot_v_, m.f0, m.roughness)
                                    : vec3<double>(1.0);
        diffuse_ = valid_ ? kd * m.diffuse_albedo * inv_pi_v<double> : vec3<double>(0.0);
        const double s = valid_ ? luminance(fresnel_schlick(n_dot_v_, m.f0, m.f90)) : 0.0;
        const double d = luminance(diffuse_) * pi_v<double>;
        if (mirror_ || !(s > 0.0))
            p_spec_ = 0.0;
        else if (!(d > 0.0))
            p_spec_ = 1.0;
        else
            p_spec_ = clamp(s / (s + d), lobe_select_min, 1.0 - lobe_select_min);
    }

    /// Probability of choosing the specular lobe.
    [[nodiscard]] double specular_probability() const noexcept { return p_spec_; }
    /// True when the specular lobe is treated as an ideal mirror.
    [[nodiscard]] bool mirror() const noexcept { return mirror_; }
    /// The clamped view cosine.
    [[nodiscard]] double n_dot_v() const noexcept { return n_dot_v_; }
    /// The mirror direction R = 2 (n.v) n - v (world).
    [[nodiscard]] vec3<double> reflected() const noexcept {
        return frame_.to_world(vec3<double>(-v_.x, -v_.y, v_.z));
    }
    /// Fresnel weight of the mirror term, F(n.v) (0 when not a mirror or v = -n).
    [[nodiscard]] vec3<double> mirror_weight() const noexcept {
        return mirror_ && valid_ ? fresnel_schlick(n_dot_v_, m_.f0, m_.f90) : vec3<double>(0.0);
    }

    [[nodiscard]] lobe_sample sample(const vec2<double>& u) const noexcept {
        if (!valid_) return {};
        vec3<double> l;
        if (u.x < p_spec_) {
            const vec3<double> h = sample_ggx_vndf(v_, vec2<double>(u.x / p_spec_, u.y), alpha_);
            l = 2.0 * glm::dot(v_, h) * h - v_;
        } else {
            const double ux = p_spec_ > 0.0 ? (u.x - p_spec_) / (1.0 - p_spec_) : u.x;
            l = sample_cosine_hemisphere(vec2<double>(ux < 1.0 ? ux : one_minus_epsilon_v<double>, u.y));
        }
        return {frame_.to_world(l), pdf_local(l)};
    }

    [[nodiscard]] double pdf(const vec3<double>& dir) const noexcept {
        return valid_ ? pdf_local(frame_.to_local(dir)) : 0.0;
    }

    [[nodiscard]] lobe_value eval(const vec3<double>& dir) const noexcept {
        lobe_value out;
        const vec3<double> l = frame_.to_local(dir);
        const double n_dot_l = l.z;
        if (!valid_ || !(n_dot_l > 0.0)) return out;
        out.parts[0] = diffuse_ * n_dot_l;
        if (!mirror_) {
            const vec3<double> h = half_vector(l);
            const double d = Model::ndf(h.z, alpha_);
            const double vis = Model::visibility(n_dot_v_, n_dot_l, m_.roughness);
            out.parts[1] = fresnel_schlick(saturate(glm::dot(v_, h)), m_.f0, m_.f90) * ((d * vis) * n_dot_l);
        }
        return out;
    }

private:
    /// normalize(v + l); l = -v (only at n.v = n.l = 0, outside the support) gives the normal.
    vec3<double> half_vector(const vec3<double>& l) const noexcept {
        const vec3<double> s = v_ + l;
        const double len2 = glm::dot(s, s);
        return len2 > 0.0 ? s * (1.0 / std::sqrt(len2)) : vec3<double>(0.0, 0.0, 1.0);
    }

    double pdf_local(const vec3<double>& l) const noexcept {
        double p = 0.0;
        if (p_spec_ > 0.0) p += p_spec_ * ggx_vndf_reflected_pdf(v_, half_vector(l), alpha_);
        if (p_spec_ < 1.0) p += (1.0 - p_spec_) * cosine_hemisphere_pdf(l.z);
        return p;
    }

    frame<double> frame_;
    reference_material m_;
    vec3<double> v_{0.0, 0.0, 1.0};
    vec3<double> diffuse_{0.0};
    double n_dot_v_ = 1.0, alpha_ = 0.0, p_spec_ = 0.0;
    bool mirror_ = false, valid_ = true;
};

static_assert(product_lobe<brdf_lobe<ggx_height_correlated>>);

// ---- the reference ---------------------------------------------------------------------------------

/// Reference outgoing radiance Lo(n, v) of material m under env (see the header), model M (default
/// ggx_height_correlated), by MIS of the BRDF and `dist` (nullptr: BRDF sampling only; pass a
/// distribution built from env itself or from a baked copy: make_cube_env_distribution).
template <class Model = ggx_height_correlated, class Env, class Executor = serial_executor>
    requires brdf_model<Model, double>
radiance_estimate reference_radiance(const Env& env, const cube_env_distribution* dist, const vec3<double>& n,
                                     const vec3<double>& v, const reference_material& m,
                                     const radiance_reference_options& opt = {}, Executor&& ex = Executor{}) {
    const brdf_lobe<Model> lobe(n, v, m);
    const product_estimate p = integrate_product_mis(env, dist, lobe, opt, ex);
    radiance_estimate out;
    out.diffuse = p.parts[0];
    out.specular = p.parts[1];
    out.std_error = p.std_error;
    out.std_error_diffuse = p.parts_std_error[0];
    out.std_error_specular = p.parts_std_error[1];
    out.samples = p.samples;
    const vec3<double> fm = lobe.mirror_weight();
    if (fm != vec3<double>(0.0)) {
        out.specular += fm * detail::rr_radiance(env, lobe.reflected()); // exact: zero error
        out.samples += 1;
    }
    out.value = out.diffuse + out.specular;
    return out;
}

/// reference_radiance with a distribution held by reference.
template <class Model = ggx_height_correlated, class Env, class Executor = serial_executor>
    requires brdf_model<Model, double>
radiance_estimate reference_radiance(const Env& env, const cube_env_distribution& dist, const vec3<double>& n,
                                     const vec3<double>& v, const reference_material& m,
                                     const radiance_reference_options& opt = {}, Executor&& ex = Executor{}) {
    return reference_radiance<Model>(env, &dist, n, v, m, opt, ex);
}

} // namespace ibl

#endif // IBL_DETAIL_CXX20
