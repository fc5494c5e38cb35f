#pragma once
// ibl/bake/prefilter.hpp — the prefiltered specular environment: the split-sum LD term per
// roughness, one roughness per mip level (host only).
//
// Derivation. The split-sum approximation (B. Karis, "Real Shading in Unreal Engine 4", SIGGRAPH
// 2013 course notes) factors the specular integral into DFG (bake/dfg*.hpp) and
//     LD(R) = integral L(l) D(h) max(n.l, 0) dl / integral D(h) max(n.l, 0) dl
// with the isotropic assumption N = V = R (h = normalize(R + l)). Sampling h from the GGX NDF
// (pdf_h = D(h) n.h, sampling/ggx.hpp) and reflecting V about h gives l with
//     pdf_l = pdf_h / (4 v.h) = D(h) / 4          (v.h = n.h because V = N),
// so the weight D(h) n.l / pdf_l = 4 n.l and the normalised estimator is the literature's
//     LD ~ sum_i L(l_i) n.l_i / sum_i n.l_i       over samples with n.l_i > 0.
// In tangent space (z = R): l = (2 h.z h.x, 2 h.z h.y, 2 h.z^2 - 1), n.l = 2 h.z^2 - 1.
//
// Filtered importance sampling (J. Krivanek, M. Colbert, "Real-time Shading with Filtered
// Importance Sampling", EGSR 2008; GPU Gems 3 ch. 20). Each sample reads the source mip whose
// texel solid angle matches the sample's share of the sphere,
//     Omega_s = 1 / (N pdf_l) = 4 / (N D(h)),
//     lod     = 0.5 log2(Omega_s / Omega_0) + bias          (clamped to [0, max_lod])
// with N the number of samples drawn (also those dropped for n.l <= 0: they are part of the
// density) and Omega_0 = 4 pi / (6 n_0^2) the source's average level-0 texel solid angle (the
// cubemap's lod_for_solid_angle; env_lod_for_solid_angle for other sources: analytic sources
// have no texels and always read lod 0). Krivanek-Colbert and Filament's libibl add a bias of
// +1 (a footprint of 4 Omega_s). Here the default is +0.5: the bilinear reconstruction of the
// mips already spreads a texel over about 2 x 2 texels, and on a sky with a sun +1 over-blurs the
// rough levels (the sun leaks into texels facing away from it) while +0 keeps much of plain
// importance sampling's noise near the sun (figures: docs/ibl-bake.md, "Quality presets").
// Fetch: by default each sample blends the two levels around its lod (trilinear, two bilinear
// taps); trilinear = false reads only the nearest level round(lod) (one tap: half the cost, the
// lod quantised to whole levels). At equal cost nearest-level reads are the more accurate, but at
// 512 samples trilinear reads remove the mottle that nearest reads leave in a sun's glossy
// highlight (figures: docs/ibl-bake.md, "Quality presets"). With bias = -inf (or method =
// importance) every sample reads level 0: plain importance sampling.
//
// Default sample schedule (samples = 0, default_prefilter_samples): 512 samples per texel at
// level 1 for filtered importance sampling (1024 for plain importance sampling), doubled at each
// coarser level, capped at 16384. Level l has 4^-l of the base's texels, so the chain still costs
// under twice its level 1, while the rough levels, where a sun is smeared over many texels, get
// the samples they need (figures: docs/ibl-bake.md, "Quality presets"). This is ibl-bake's
// default quality.
//
// LD weight (prefilter_options::weight). ld_weight::n_dot_l is Karis's n.l above. ld_weight::g1
// weights each sample by the Smith masking of its direction instead,
//     LD_G1(R) = integral L(l) D(h) G1(R.l) dl / integral D(h) G1(R.l) dl      (weight G1(n.l)),
// which is the true specular lobe at normal view: with N = V = R the integrand f (n.l) is
// D G2 / (4 n.v n.l) n.l = D G1(l) / 4 (height-correlated G2 with G1(v) = 1), so the split sum with
// this LD is exact at n.v = 1 for every environment (docs/runtime.md measures both).
//
// Sample tables. Per output level one table of N Hammersley points (i / N, radical inverse),
// shared by every texel: tangent-space l, weight n.l, lod; samples with n.l <= 0 are dropped.
// Per texel the table is rotated into the frame make_frame(R) of the texel centre R. The hot loop
// is the cubemap fast path of bake/sphere_convolve.hpp (structure of arrays over a face row,
// one bilinear tap per sample on a level that is the same for every texel, or two for trilinear
// reads; blocked float accumulation).
//
// Levels (roughness_mip.hpp): level l of the output holds roughness policy.roughness(l, levels)
// at face size max(1, base_size >> l). Level 0 is r = 0, not an integral (for the GGX lobe and
// every lobe whose r = 0 limit is the mirror; sampling/lobe.hpp): a copy of the source
// (texel for texel when the source is a cubemap of the same face size; otherwise the source's
// radiance at the output texel centres, read at the lod of the output texel's solid angle).
//
// Level plan (prefilter_options::level_plan, prefilter_level). The output is a list of levels,
// each a chain level l (face size max(1, base_size >> l)), a roughness, a sample count and a read
// mode; prefilter_plan gives the plan of the options (levels 0 .. levels - 1 as above). A given
// plan bakes any run of consecutive chain levels: output level 0 is then chain level
// plan[0].level, at face size max(1, base_size >> plan[0].level) (what ibl-bake stores for a
// scene that reads only some roughness range, with its own samples and reads per level). A mirror
// level 0 with nearest reads (trilinear = false) copies the cubemap source's level nearest in
// face size (texel for texel where the sizes match, else read at that whole lod; other sources:
// the footprint's lod rounded); the options' plan reads it at the footprint's lod as above.
//
// Bad input: a table of 0 samples (make_ld_table) is clamped to 1 (one sample: h = n, l = R: a mirror lookup at the lod of
// that sample's footprint). Non-finite source radiance reads as 0 (sphere_convolve.hpp); level 0
// copies it as 0 too, so the output is finite. base_size < 1 for a source without a size (not a
// cubemap) and levels < 0 throw std::invalid_argument; base_size > limits::max_face_size, samples
// > limits::max_samples and more than limits::max_work taps in one call throw std::length_error
// (core/limits.hpp).
//
// Determinism: the output depends only on the source and the options; each texel is computed by
// the same operations whatever the executor (work items are face rows).

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "../brdf/ggx.hpp"
#include "../core/executor.hpp"
#include "../core/limits.hpp"
#include "../core/math.hpp"
#include "../core/vec.hpp"
#include "../env/cube_geometry.hpp"
#include "../env/cubemap.hpp"
#include "../env/environment.hpp"
#include "../sampling/ggx.hpp"
#include "../sampling/lobe.hpp"
#include "../sampling/sequence.hpp"
#include "../runtime/chain.hpp"
#include "../runtime/ld_weight.hpp"
#include "../runtime/roughness_mip.hpp"
#include "prefilter_fast.hpp"
#include "prefilter_peaks.hpp"
#include "prefilter_sh.hpp"
#include "sphere_convolve.hpp"

namespace ibl {

enum class prefilter_method : int {
    importance = 0,          ///< GGX importance sampling, every sample reads level 0
    filtered_importance = 1, ///< Krivanek-Colbert filtered importance sampling
    fast = 2,                ///< the fast filter: a small tap set shaped offline (bake/prefilter_fast.hpp)
};

/// One output level of a prefilter plan (prefilter_options::level_plan, prefilter_plan).
struct prefilter_level {
    int level = 0;             ///< level l of the chain: face size max(1, base_size >> l)
    double roughness = 0.0;    ///< the lobe's roughness at this level
    std::uint32_t samples = 0; ///< samples drawn per texel (0 reads as 1, make_ld_table); unused by a mirror level 0
    /// Source reads: true = trilinear at each sample's lod, false = the nearest level. A mirror
    /// level 0 (a copy of the source): true reads at the lod of the output texel's footprint,
    /// false copies the nearest source level (texel for texel where its face size is the output's).
    bool trilinear = true;
};

struct prefilter_options {
    /// levels = automatic (the default, ibl-bake's rule): floor(log2 base) - 1 clamped to [2, 6]
    /// and to the full chain (256 -> 6 levels, 256..8; the smallest face >= 4 for base >= 16; at
    /// least one rough level besides the mirror level 0 wherever the base has a mip).
    static constexpr int automatic = -1;
    /// Output levels, clamped to the full chain of base_size (floor(log2 base) + 1); 0 means the
    /// full chain, automatic (-1) the rule above. Other negative values throw.
    int levels = automatic;
    /// Face size of output level 0; 0 = the source's (cubemaps only: other sources need a size).
    int base_size = 0;
    roughness_mip_policy policy{};
    prefilter_method method = prefilter_method::filtered_importance;
    /// Samples drawn per texel at every level >= 1; 0 = the default schedule, which doubles per
    /// level (default_prefilter_samples). Overridden per level by samples_per_level when that is
    /// long enough.
    std::uint32_t samples = 0;
    /// Samples for level l at index l (index 0 is used only by a lobe whose r = 0 limit is not the
    /// mirror: prefilter<charlie_lobe>); levels beyond its size use `samples`.
    std::vector<std::uint32_t> samples_per_level{};
    /// Filtered importance sampling: lod bias added to 0.5 log2(Omega_s / Omega_0).
    double lod_bias = 0.5;
    /// Cubemap fast path: trilinear reads (two bilinear taps per sample, the default); false reads
    /// only the nearest level round(lod) (one tap: half the cost, the lod quantised to whole levels).
    /// Read by filtered and plain importance sampling; the fast filter's plan reads the nearest
    /// level (prefilter_plan; a level_plan sets any reads).
    bool trilinear = true;
    /// The LD weight (header: "LD weight"); the default is Karis's n.l.
    ld_weight weight = ld_weight::n_dot_l;
    /// The per-level plan (header: "Level plan"); empty (the default) = the plan of the fields
    /// above, prefilter_plan(opt, base). When set, levels, samples, samples_per_level and
    /// trilinear are not read.
    std::vector<prefilter_level> level_plan{};
    /// The fast filter's peak split (bake/prefilter_peaks.hpp): read by method = fast on a cubemap
    /// source with the GGX lobe only.
    peak_split_options peaks{};
    /// The fast filter's coarse tail (bake/prefilter_fast.hpp, "Coarse tail"): each convolved
    /// level but the last reads the heavy tail of its kernel from the finished next level (one
    /// bilinear read per texel; the levels are filtered coarse to fine) and spends its tap set on
    /// the rest. Read by method = fast only; false filters every level from the source alone.
    bool coarse_tail = true;
    /// The fast filter's intermediate coarse tail (bake/prefilter_fast.hpp, "Intermediate coarse
    /// tail"; cubemap sources, the GGX lobe): a level with a coarse tail, at roughness up to
    /// max_roughness, reads it from an intermediate level at r + position (r_next - r) with the
    /// next level's face, filtered with `mid` times the level's samples and its own coarse tail
    /// from the next level, and spends `own` times its samples on the narrower rest of its kernel
    /// (the defaults: 24 + 64 / 4 = 40 taps a texel instead of 64). Only where that face resolves
    /// the intermediate kernel: its full width at half maximum spans at least min_texels texels
    /// (a 256^2 chain's level 1, not a 128^2 one's), and where the own tap set keeps at least
    /// min_own_samples (16: not at --quality low's 8 samples, where 3 own samples miss the core).
    /// The intermediate level is not part of the output. enabled = false reads the next level directly.
    struct mid_tail_options {
        bool enabled = true;
        double max_roughness = 0.3;
        double position = 0.1;
        double own = 0.375;
        double mid = 1.0;
        double min_texels = 3.0;
        std::uint32_t min_own_samples = 16;
    } mid_tail{};
    /// The fast filter's rough levels by spherical-harmonic convolution (bake/prefilter_sh.hpp):
    /// read by method = fast on a cubemap source; a level whose kernel needs at most
    /// sh_rough.max_bands bands is reconstructed from the source's projection instead of its tap
    /// set (and reads no coarse tail).
    sh_rough_options sh_rough{};
};

/// Ceiling of the doubling sample schedule (samples per texel).
inline constexpr std::uint32_t prefilter_max_scheduled_samples = 16384;

/// The doubling schedule: level1_samples at level 1, twice as many at each coarser level, at most
/// prefilter_max_scheduled_samples (levels < 1 get level1_samples; level1_samples = 0 gives 0).
inline std::uint32_t doubling_prefilter_samples(std::uint32_t level1_samples, int level) {
    std::uint64_t n = level1_samples;
    for (int l = 1; l < level && n < prefilter_max_scheduled_samples; ++l) n *= 2;
    return std::uint32_t(std::min<std::uint64_t>(n, std::max(level1_samples, prefilter_max_scheduled_samples)));
}

/// The equal-cost schedule: level1_samples at level 1, four times as many at each coarser level
/// (level l has a quarter of the texels of level l - 1, so every level costs the same taps), at
/// most prefilter_max_scheduled_samples (levels < 1 get level1_samples; level1_samples = 0 gives 0).
/// The fast filter's default (bake/prefilter_fast.hpp, "Cost").
inline std::uint32_t equal_cost_prefilter_samples(std::uint32_t level1_samples, int level) {
    std::uint64_t n = level1_samples;
    for (int l = 1; l < level && n < prefilter_max_scheduled_samples; ++l) n *= 4;
    return std::uint32_t(std::min<std::uint64_t>(n, std::max(level1_samples, prefilter_max_scheduled_samples)));
}

/// Default samples per texel at level l (the default schedule of the header comment): the
/// doubling schedule from 512 at level 1 for filtered importance sampling (ibl-bake's default
/// quality, with trilinear reads), from 1024 (the literature's count) for plain importance
/// sampling; the equal-cost schedule from fast_default_samples for the fast filter.
inline std::uint32_t default_prefilter_samples(prefilter_method method, int level) {
    if (method == prefilter_method::fast) return equal_cost_prefilter_samples(fast_default_samples, level);
    return doubling_prefilter_samples(method == prefilter_method::importance ? 1024u : 512u, level);
}

/// The LD sample table of lobe L (sampling/lobe.hpp; GGX by default) for one roughness
/// (N = V = R): N Hammersley draws h = L::sample, weights (n.l) L::ld_weight, lods from
/// lod_of_solid_angle(Omega_s), Omega_s = 1 / (N pdf_l) (GGX: 4 / (N D(h))). Computed in double,
/// stored as S. samples = 0 is clamped to 1; samples > limits::max_samples throws std::length_error.
/// weight = ld_weight::g1 multiplies each sample's weight by the GGX G1(n.l) / n.l (the true
/// D G1 weight instead of Karis' n.l; header: "LD weight"; meant for the GGX lobe).
template <class S, class Lobe = ggx_lobe, class LodFn>
    requires ld_lobe<Lobe>
sphere_sample_table<S> make_ld_table(double roughness, std::uint32_t samples, LodFn&& lod_of_solid_angle,
                                     ld_weight weight = ld_weight::n_dot_l) {
    detail::check_total("make_ld_table", "samples", samples, limits::max_samples, "limits::max_samples");
    const std::uint32_t n = samples > 0 ? samples : 1;
    sphere_sample_table<S> t;
    t.drawn = n;
    for (std::uint32_t i = 0; i < n; ++i) {
        const vec3<double> h = Lobe::sample(hammersley<double>(i, n), roughness);
        const double n_dot_l = 2.0 * h.z * h.z - 1.0;
        if (!(n_dot_l > 0.0)) continue;
        const double nl_or_g1 = weight == ld_weight::g1 ? g1_smith_ggx(n_dot_l, alpha_from_roughness(roughness)) : n_dot_l;
        const double w = nl_or_g1 * Lobe::ld_weight(h, roughness);
        if (!(w > 0.0)) continue;
        const vec3<double> l(2.0 * h.z * h.x, 2.0 * h.z * h.y, n_dot_l);
        const double pdf_l = lobe_ld_pdf<Lobe>(h, roughness);
        const double omega_s = 1.0 / (double(n) * pdf_l);
        t.push(vec3<S>(l), S(w), S(lod_of_solid_angle(omega_s)));
    }
    return t;
}

/// The LD table of lobe L (GGX by default) of one level for a given source and options (the lod
/// rule of the header comment). samples > limits::max_samples throws std::length_error. The fast
/// filter's table with a next roughness >= 0 is that of its coarse tail (make_fast_ld_table).
template <class S, class Lobe = ggx_lobe, class Env>
    requires ld_lobe<Lobe>
sphere_sample_table<S> make_ld_table_for(const Env& env, double roughness, std::uint32_t samples,
                                         prefilter_method method, double lod_bias,
                                         ld_weight weight = ld_weight::n_dot_l, double next_roughness = -1.0) {
    detail::check_total("make_ld_table_for", "samples", samples, limits::max_samples, "limits::max_samples");
    using Te = std::conditional_t<environment<Env, float>, float, double>;
    if (method == prefilter_method::fast)
        return make_fast_ld_table<S, Lobe>(roughness, samples, fast_shape(roughness, samples, weight), [&](double omega) -> double {
            return double(env_lod_for_solid_angle<Te>(env, Te(omega)));
        }, weight, next_roughness);
    return make_ld_table<S, Lobe>(roughness, samples, [&](double omega_s) -> double {
        if (method == prefilter_method::importance) return 0.0;
        // The bias b scales the footprint by 4^b: 0.5 log2(4^b Omega_s / Omega_0) = lod + b.
        const double omega = omega_s * std::exp2(2.0 * lod_bias);
        return double(env_lod_for_solid_angle<Te>(env, Te(omega)));
    }, weight);
}

namespace detail {
template <class Env> int prefilter_base_size(const Env& env, int base_size) {
    if (base_size < 0)
        throw std::invalid_argument("ibl::prefilter: base_size must be >= 0, got " + std::to_string(base_size));
    detail::check_total("prefilter", "base_size", base_size, limits::max_face_size, "limits::max_face_size");
    if (base_size > 0) return base_size;
    if constexpr (requires { env.size(0); }) return env.size(0);
    throw std::invalid_argument("ibl::prefilter: base_size must be >= 1 for a source without a size");
}

/// The source level nearest in face size to n (a mirror level 0 with nearest reads).
template <class Env> int prefilter_nearest_level(const Env& env, int n) {
    return std::clamp(int(std::lround(std::log2(double(env.size(0)) / double(n)))), 0, env.levels() - 1);
}

/// How level 0 of a mirror lobe reads the source: a texel-for-texel copy of source level
/// copy_level (>= 0), or the source's radiance at the output texel centres at lod (copy_level < 0).
struct prefilter_base_read {
    int copy_level = -1;
    double lod = 0.0; ///< the source's lod type (float for a float source) round-trips exactly
};

/// The read of level 0 (face size n): at the lod of the output texel's footprint (trilinear) or at
/// the nearest source level (prefilter_level::trilinear = false), a copy where the sizes match.
template <class Env> prefilter_base_read prefilter_base_mode(const Env& env, int n, bool trilinear) {
    using Te = std::conditional_t<environment<Env, float>, float, double>;
    Te lod = env_lod_for_solid_angle<Te>(env, Te(four_pi_v<double> / (6.0 * double(n) * double(n))));
    if constexpr (requires { detail::pack_cube(env); }) {
        const int sl = trilinear ? 0 : prefilter_nearest_level(env, n);
        if (env.size(sl) == n) return {sl, 0.0}; // the same texels: an exact copy
        if (!trilinear) lod = Te(sl);
    } else if (!trilinear) {
        lod = std::round(lod);
    }
    return {-1, double(lod)};
}

/// One face row (row = face n + y) of level 0 into out[0 .. n): non-finite components read as 0.
template <class Env> void prefilter_base_row(const Env& env, int n, const prefilter_base_read& m, std::size_t row,
                                             vec3<float>* out) {
    using Te = std::conditional_t<environment<Env, float>, float, double>;
    auto finite = [](const vec3<Te>& v) {
        vec3<float> o;
        for (int k = 0; k < 3; ++k) o[k] = is_finite(v[k]) ? float(v[k]) : 0.f;
        return o;
    };
    const int face = int(row) / n, y = int(row) % n;
    if constexpr (requires { detail::pack_cube(env); }) {
        if (m.copy_level >= 0) {
            // The row is contiguous in the cubemap: a plain loop over it vectorises.
            const auto* v = &env.texel(face, 0, y, m.copy_level);
            for (int x = 0; x < n; ++x) out[x] = finite(vec3<Te>(v[x]));
            return;
        }
    }
    for (int x = 0; x < n; ++x) out[x] = finite(vec3<Te>(env.radiance(cube_texel_direction<Te>(face, x, y, n), Te(m.lod))));
}

/// Level 0 of a mirror lobe: the source at the output's texel centres, read at the lod of the
/// output texel's footprint (trilinear) or at the nearest source level (prefilter_level::trilinear).
template <class Env, class Executor>
std::vector<vec3<float>> prefilter_base(const Env& env, int n, bool trilinear, Executor& ex) {
    std::vector<vec3<float>> out(std::size_t(6) * std::size_t(n) * std::size_t(n));
    const prefilter_base_read m = prefilter_base_mode(env, n, trilinear);
    ex(std::size_t(6 * n), [&](std::size_t b, std::size_t e) {
        for (std::size_t row = b; row < e; ++row) prefilter_base_row(env, n, m, row, out.data() + row * std::size_t(n));
    });
    return out;
}
} // namespace detail

/// The automatic level count of a base face size (prefilter_options::automatic): floor(log2 base)
/// - 1 clamped to [2, 6], at most the full chain floor(log2 base) + 1.
inline int prefilter_auto_levels(int base_size) {
    int log2n = 0;
    while ((base_size >> (log2n + 1)) > 0) ++log2n;
    const int full = log2n + 1;
    const int l = std::clamp(log2n - 1, 2, 6);
    return std::min(l, full);
}

/// Number of levels the options give for a base face size.
inline int prefilter_levels(const prefilter_options& opt, int base_size) {
    int full = 1;
    while ((base_size >> full) > 0) ++full;
    if (opt.levels == prefilter_options::automatic) return prefilter_auto_levels(base_size);
    if (opt.levels < 0)
        throw std::invalid_argument("ibl::prefilter: levels must be >= 0 or prefilter_options::automatic, got " +
                                    std::to_string(opt.levels));
    return opt.levels == 0 ? full : std::min(opt.levels, full);
}

/// Samples drawn per texel at level l under the options.
inline std::uint32_t prefilter_samples(const prefilter_options& opt, int level, int /*levels*/) {
    if (std::size_t(level) < opt.samples_per_level.size() && opt.samples_per_level[std::size_t(level)] > 0)
        return opt.samples_per_level[std::size_t(level)];
    if (opt.samples > 0) return opt.samples;
    return default_prefilter_samples(opt.method, level);
}

/// The levels prefilter computes for the options (header: "Level plan"): opt.level_plan when set,
/// else levels 0 .. prefilter_levels(opt, base_size) - 1 at roughness opt.policy.roughness(l, levels)
/// with prefilter_samples(opt, l, levels) samples and opt.trilinear reads, nearest reads for the
/// fast filter (a mirror level 0 of lobe L reads at the footprint's lod). Throws as prefilter_levels.
template <class Lobe = ggx_lobe>
    requires ld_lobe<Lobe>
std::vector<prefilter_level> prefilter_plan(const prefilter_options& opt, int base_size) {
    if (!opt.level_plan.empty()) return opt.level_plan;
    const int levels = prefilter_levels(opt, base_size);
    std::vector<prefilter_level> plan;
    const bool reads = opt.method == prefilter_method::fast ? false : opt.trilinear;
    for (int l = 0; l < levels; ++l)
        plan.push_back({l, opt.policy.roughness(double(l), levels), prefilter_samples(opt, l, levels),
                        reads || (l == 0 && lobe_mirror_limit<Lobe>())});
    return plan;
}

namespace detail {
/// The options' sample counts within limits::max_samples.
inline void check_prefilter_samples(const prefilter_options& opt) {
    check_total("prefilter", "samples", opt.samples, limits::max_samples, "limits::max_samples");
    for (std::size_t l = 0; l < opt.samples_per_level.size(); ++l)
        if (opt.samples_per_level[l] > limits::max_samples)
            throw std::length_error("ibl::prefilter: samples_per_level[" + std::to_string(l) +
                                    "] = " + std::to_string(opt.samples_per_level[l]) +
                                    " exceeds limits::max_samples = " + std::to_string(limits::max_samples));
}

/// A given level plan: consecutive levels from a first level in [0, 30], samples within limits::max_samples.
inline void check_level_plan(const std::vector<prefilter_level>& plan) {
    for (std::size_t k = 0; k < plan.size(); ++k) {
        const int want = plan[0].level + int(k);
        if (plan[k].level != want || want < 0 || want > 30)
            throw std::invalid_argument("ibl::prefilter: level_plan[" + std::to_string(k) + "].level = " +
                                        std::to_string(plan[k].level) + ": levels must be consecutive, in [0, 30]");
        check_total("prefilter", "level_plan samples", plan[k].samples, limits::max_samples, "limits::max_samples");
    }
}

/// The taps of the plan's levels >= 1: the sum of 6 n_l^2 samples_l (x 2 when trilinear).
inline std::uint64_t prefilter_plan_work(const std::vector<prefilter_level>& plan, int base) {
    std::uint64_t work = 0;
    for (const prefilter_level& lp : plan) {
        if (lp.level < 1) continue;
        const std::uint64_t n = std::uint64_t(base >> lp.level > 0 ? base >> lp.level : 1);
        work = work_add(work, 6 * n * n, std::uint64_t(lp.samples) * (lp.trilinear ? 2u : 1u));
    }
    return work;
}
/// prefilter's checks, before any table is built: the sample counts of the options or of the
/// given plan, and the total taps of the plan's levels >= 1 within limits::max_work.
inline void check_prefilter_work(const prefilter_options& opt, const std::vector<prefilter_level>& plan, int base) {
    if (opt.level_plan.empty()) check_prefilter_samples(opt);
    else check_level_plan(plan);
    check_total("prefilter", "taps (sum of 6 n_l^2 samples_l)", prefilter_plan_work(plan, base), limits::max_work, "limits::max_work");
}
} // namespace detail

namespace detail {
/// The smallest face of a next level that a coarse tail reads (prefilter_options::coarse_tail):
/// below it the bilinear read of the next level's coarse texels costs more accuracy than the tail
/// saves (docs/ibl-bake.md, "Fast filter": a 256^2 chain's level 4, reading 8^2, is better without).
inline constexpr int prefilter_coarse_tail_min_face = 16;
/// The bands of plan level lp when the fast filter reconstructs it from the source's spherical
/// harmonics (prefilter_options::sh_rough, bake/prefilter_sh.hpp; cubemap sources), else 0.
template <class Lobe> int prefilter_sh_bands(const prefilter_options& opt, const prefilter_level& lp) {
    if (opt.method != prefilter_method::fast || !opt.sh_rough.enabled) return 0;
    if (lobe_mirror_limit<Lobe>() && lp.level == 0) return 0;
    return sh_rough_bands<Lobe>(std::clamp(std::isfinite(lp.roughness) ? lp.roughness : 0.0, 0.0, 1.0), opt.weight, opt.sh_rough);
}
/// The roughness of the level after plan level k that level k reads its coarse tail from
/// (prefilter_options::coarse_tail: the fast filter, a convolved level with a next level of face
/// >= prefilter_coarse_tail_min_face; output level 0 has face first_size), or -1.
/// cube_source: the levels of a cubemap source, where a level by spherical harmonics reads no tail.
template <class Lobe> double prefilter_tail_roughness(const prefilter_options& opt, const std::vector<prefilter_level>& plan,
                                                      std::size_t k, int first_size, bool cube_source = false) {
    if (opt.method != prefilter_method::fast || !opt.coarse_tail || k + 1 >= plan.size()) return -1.0;
    if (lobe_mirror_limit<Lobe>() && plan[k].level == 0) return -1.0;
    if (cube_source && prefilter_sh_bands<Lobe>(opt, plan[k]) > 0) return -1.0;
    if (k + 1 >= 31 || (first_size >> (k + 1)) < prefilter_coarse_tail_min_face) return -1.0;
    return std::clamp(std::isfinite(plan[k + 1].roughness) ? plan[k + 1].roughness : 0.0, 0.0, 1.0);
}
/// The samples of a level that reads an intermediate level: its own tap set's (own times s, at
/// least 1) and the intermediate level's (mid times s, at least 1, at most limits::max_samples).
inline std::uint32_t prefilter_mid_own_samples(const prefilter_options& opt, std::uint32_t s) noexcept {
    return std::max(1u, std::uint32_t(std::round(std::clamp(opt.mid_tail.own, 0.0, 1.0) * double(s))));
}
inline std::uint32_t prefilter_mid_samples(const prefilter_options& opt, std::uint32_t s) noexcept {
    const double v = std::min(opt.mid_tail.mid * double(std::max<std::uint32_t>(s, 1)), double(limits::max_samples));
    return std::uint32_t(std::max(1.0, std::round(v)));
}
/// The roughness of the intermediate level that plan level k reads its coarse tail from
/// (prefilter_options::mid_tail; cubemap sources), or -1 when it reads the next level directly or
/// has no coarse tail.
template <class Lobe> double prefilter_mid_roughness(const prefilter_options& opt, const std::vector<prefilter_level>& plan,
                                                     std::size_t k, int first_size, bool cube_source) {
    if constexpr (!std::is_same_v<Lobe, ggx_lobe>) return -1.0;
    const prefilter_options::mid_tail_options& m = opt.mid_tail;
    if (!cube_source || !m.enabled || !(m.position > 0.0) || !(m.position < 1.0) || !(m.own > 0.0) || !(m.mid > 0.0)) return -1.0;
    const double rn = prefilter_tail_roughness<Lobe>(opt, plan, k, first_size, true);
    if (rn < 0.0) return -1.0;
    const double r = std::clamp(std::isfinite(plan[k].roughness) ? plan[k].roughness : 0.0, 0.0, 1.0);
    if (!(r <= m.max_roughness) || !(rn > r)) return -1.0;
    if (prefilter_mid_own_samples(opt, plan[k].samples) < m.min_own_samples) return -1.0;
    const double rm = r + m.position * (rn - r);
    // the intermediate level's face (the next level's) resolves its kernel: a texel at the face
    // centre is 2 / face radians
    const int face = std::max(1, first_size >> int(k + 1));
    if (!(ggx_ld_fwhm(rm) >= (std::isfinite(m.min_texels) ? m.min_texels : 3.0) * 2.0 / double(face))) return -1.0;
    return rm;
}
/// prefilter's work check with the intermediate levels (mid_tail) of a cubemap source, after
/// check_prefilter_work: the plan's taps plus 6 n_m^2 samples_m of each intermediate level (its
/// face n_m the next level's), within limits::max_work.
template <class Lobe> void check_prefilter_mid_work(const prefilter_options& opt, const std::vector<prefilter_level>& plan, int base) {
    const int first_size = std::max(1, base >> plan.front().level);
    std::uint64_t mids = 0;
    for (std::size_t k = 0; k < plan.size(); ++k)
        if (prefilter_mid_roughness<Lobe>(opt, plan, k, first_size, true) >= 0.0) {
            const std::uint64_t m = std::uint64_t(std::max(1, first_size >> int(k + 1)));
            mids = work_add(mids, 6 * m * m, std::uint64_t(prefilter_mid_samples(opt, plan[k].samples)) * (plan[k].trilinear ? 2u : 1u));
        }
    if (mids == 0) return;
    check_total("prefilter", "taps (sum of 6 n_l^2 samples_l, intermediate levels included)",
                work_add(prefilter_plan_work(plan, base), 1, mids), limits::max_work, "limits::max_work");
}
/// The order prefilter computes the plan's levels in: coarse to fine when a level reads its
/// coarse tail, else fine to coarse.
template <class Lobe>
std::vector<std::size_t> prefilter_order(const prefilter_options& opt, const std::vector<prefilter_level>& plan, int first_size,
                                         bool cube_source = false) {
    std::vector<std::size_t> order(plan.size());
    bool tail = false;
    for (std::size_t k = 0; k < plan.size(); ++k)
        tail = tail || prefilter_tail_roughness<Lobe>(opt, plan, k, first_size, cube_source) >= 0.0;
    for (std::size_t k = 0; k < plan.size(); ++k) order[k] = tail ? plan.size() - 1 - k : k;
    return order;
}
/// A finished level as the next finer level reads it: one level of n x n texels (texel(f, x, y))
/// with its borders, read bilinearly at the finer texel centres.
template <class TexelFn> cubemap<float> prefilter_tail_cube(int n, TexelFn&& texel) {
    cubemap<float> c(n, 1);
    c.fill(0, [&](int f, int x, int y) { return vec3<float>(texel(f, x, y)); });
    c.update_borders();
    return c;
}
/// Adds share times the next level, read at the texel centres of row y of face `face` (n x n):
/// cubemap::bilinear(face, s, t, 0) at s = (x + 1/2) / n, the same operations texel by texel, with
/// the row's two source rows found once (the texel loop then vectorises).
inline void add_coarse_tail_row(const cubemap<float>& next, float share, int face, int y, int n, vec3<float>* out) {
    const float t = (float(y) + 0.5f) / float(n);
    const int m = next.size(0);
    // bilinear_unchecked's row: bordered coordinates, t in (0, 1) so no clamp applies
    const float fy = t * float(m) + 0.5f;
    const int y0 = std::min(int(fy), m);
    const float wy = fy - float(y0);
    const vec3<float>* r0 = &next.texel(face, -1, y0 - 1, 0); // bordered row y0 from its x = -1
    const vec3<float>* r1 = &next.texel(face, -1, y0, 0);
    for (int x = 0; x < n; ++x) {
        const float fx = ((float(x) + 0.5f) / float(n)) * float(m) + 0.5f;
        const int x0 = std::min(int(fx), m);
        const float wx = fx - float(x0);
        const vec3<float> top = r0[x0] + wx * (r0[x0 + 1] - r0[x0]);
        const vec3<float> bot = r1[x0] + wx * (r1[x0 + 1] - r1[x0]);
        out[x] += share * (top + wy * (bot - top));
    }
}

/// The face rows of level `level` of c (row r = face n + y, from its texel x = 0), taken before
/// the work items write them in place: texel_ref marks the level's borders stale, so that flag is
/// written here, on the calling thread, and not by the workers.
inline std::vector<vec3<float>*> level_row_pointers(cubemap<float>& c, int level) {
    const int n = c.size(level);
    std::vector<vec3<float>*> rows(std::size_t(6 * n));
    for (int r = 0; r < 6 * n; ++r) rows[std::size_t(r)] = &c.texel_ref(r / n, 0, r % n, level);
    return rows;
}

/// A convolved level of a cubemap source: its taps, its peaks and its coarse tail's share.
struct prefilter_cube_level {
    tap_table taps{};
    peak_level peaks{};
    float tail_share = 0.f; ///< > 0: the row adds this times the next level (prefilter_options::coarse_tail)
    sh_level sh{};          ///< active: the level is reconstructed from the source's projection (no taps)
};
/// What prefilter reads from a cubemap source: the packed copy of the source (or of the base of
/// its peak split), the split's peaks, and per level the taps and the merged peaks. The same
/// object serves prefilter and prefilter_update, so both compute a row by the same operations.
template <class Lobe, class T> class prefilter_cube_source {
public:
    /// The source of a prefilter: the peak split (the fast filter's), then the packed copy.
    template <class Executor>
    prefilter_cube_source(const cubemap<T>& src, const prefilter_options& opt, Executor& ex) : prefilter_cube_source(src, opt, ex, 0) {
        ex(packed_rows(packed_), [&](std::size_t b, std::size_t e) { pack(src, b, e); });
        finish_packing(src, ex);
    }
    /// The same, packing only the levels that a plan's levels read (first_read_level): prefilter.
    template <class Executor>
    prefilter_cube_source(const cubemap<T>& src, const prefilter_options& opt, const std::vector<prefilter_level>& plan,
                          int out_size, Executor& ex)
        : prefilter_cube_source(src, opt, ex, 0) {
        packed_.first = first_read_level(src, plan, out_size);
        ex(packed_rows(packed_), [&](std::size_t b, std::size_t e) { pack(src, b, e); });
        finish_packing(src, ex);
    }
    /// Packs only levels >= first (first_read_level) from the next packing on (set before pack()).
    void set_first_packed(int first) noexcept { packed_.first = first; }
    /// The finest packed level that the plan's levels read: their tap tables' levels (built as
    /// level() builds them) and the spherical-harmonic projection's level. Mirror levels read the
    /// source itself.
    template <class Env> [[nodiscard]] int first_read_level(const Env& env, const std::vector<prefilter_level>& plan, int out_size) const {
        int first = int(packed_.levels.size()) - 1;
        int bands = 0;
        for (std::size_t k = 0; k < plan.size(); ++k) {
            const prefilter_level& lp = plan[k];
            if (lobe_mirror_limit<Lobe>() && lp.level == 0) continue;
            if (const int b = prefilter_sh_bands<Lobe>(opt_, lp); b > 0) {
                bands = std::max(bands, b);
                continue;
            }
            const double rn = prefilter_tail_roughness<Lobe>(opt_, plan, k, out_size, true);
            const double rm = prefilter_mid_roughness<Lobe>(opt_, plan, k, out_size, true);
            // the level's table, and its intermediate level's (mid_tail), as level() builds them
            const std::pair<prefilter_level, double> one[] = {{lp, rn}};
            const std::pair<prefilter_level, double> two[] = {{mid_owner(lp), rm}, {mid_of(lp, rm), rn}};
            for (const auto& [t, next] : rm >= 0.0 ? std::span<const std::pair<prefilter_level, double>>(two)
                                                   : std::span<const std::pair<prefilter_level, double>>(one)) {
                if (const int b = prefilter_sh_bands<Lobe>(opt_, t); b > 0) { // an intermediate level by spherical harmonics
                    bands = std::max(bands, b);
                    continue;
                }
                sphere_sample_table<float> table =
                    make_ld_table_for<float, Lobe>(env, t.roughness, t.samples, opt_.method, opt_.lod_bias, opt_.weight, next);
                table.trilinear = t.trilinear;
                for (const int l : make_taps(table, int(packed_.levels.size())).level) first = std::min(first, l);
                if (first == 0) return 0; // every level is packed: the other tables need not be built twice
            }
        }
        if (bands > 0) first = std::min(first, sh_projection_level(packed_, bands));
        return std::max(first, 0);
    }
    /// The same with the packing left to the caller (prefilter_update spreads it over its calls):
    /// pack() every item of pack_items(), then finish_packing(), then the object is the one the
    /// other constructor builds (the same operations, so the same bits).
    template <class Executor>
    prefilter_cube_source(const cubemap<T>& src, const prefilter_options& opt, Executor& ex, int /*deferred packing*/)
        : opt_(opt) {
        restart(src, ex);
    }
    /// An empty source for restart_deferred (prefilter_update).
    explicit prefilter_cube_source(const prefilter_options& opt) : opt_(opt) {}
    /// Deferred packing of a new source: the peak split again, the packed copy's storage kept when
    /// the source has the same levels (every packing item overwrites its texels).
    template <class Executor> void restart(const cubemap<T>& src, Executor& ex) {
        reset(src);
        if (splits()) set_split(find_cube_peaks(src, opt_.peaks, ex));
    }
    /// The same with the split left to the caller too (prefilter_update): without a 1 x 1 level,
    /// first split_mean_row every row of split_mean_rows() in order (the mean of level 0 by texel
    /// solid angles, as find_cube_peaks sums it); then split_row every row of split_rows(), then
    /// split_select(), then split_build every peak of split_peaks(), and the object is the one
    /// restart makes (the same operations: the same peaks).
    void restart_deferred(const cubemap<T>& src) {
        reset(src);
        split_pending_ = scanned_ = false;
        mean_rows_ = 0;
        mean_acc_ = 0.0;
        hits_.clear();
        if (!splits()) return;
        split_pending_ = scanned_ = true;
        scan_row_.resize(std::size_t(src.size(0)));
        if (peak_scan_start(src, opt_.peaks, scan_)) return;
        const int n = src.size(0);
        if (omega_n_ != n) { // the face's texel solid angles, once per source size
            omega_ = cube_face_solid_angles<double>(n);
            omega_n_ = n;
        }
        peak_scan_reset(opt_.peaks, n, 0.0, scan_); // the rows' slots; the threshold once the mean is known
        mean_rows_ = std::size_t(6 * n);
    }
    /// The rows of level 0 the mean reads before the scan (0 with a 1 x 1 level), row r added
    /// (rows in order), and the scan's threshold from the mean after the last.
    [[nodiscard]] std::size_t split_mean_rows() const noexcept { return mean_rows_; }
    void split_mean_row(const cubemap<T>& src, std::size_t r) noexcept { peak_mean_row(src, omega_, r, mean_acc_); }
    void split_mean_finish() { peak_scan_reset(opt_.peaks, scan_.n, mean_acc_ / four_pi_v<double>, scan_); }
    /// True until split_select: the scan's rows and the selection are due.
    [[nodiscard]] bool split_pending() const noexcept { return split_pending_; }
    /// The rows of this pass's scan (0 when the pass has none), and the texels it kept so far (the
    /// selection's cost).
    [[nodiscard]] std::size_t split_rows() const noexcept { return scanned_ ? scan_.rows.size() : 0; }
    [[nodiscard]] std::size_t split_hits() const noexcept { return scanned_ ? scan_.hits : 0; }
    void split_row(const cubemap<T>& src, std::size_t r) noexcept { scan_.hits += peak_scan_row(src, scan_, r, scan_row_.data()); }
    /// The threshold (select_peak_threshold) and the peaks' slots; split_build fills them.
    void split_select() {
        hits_ = peak_scan_hits(scan_);
        threshold_ = select_peak_threshold(opt_.peaks, hits_, scan_.t);
        mean_ = scan_.mean;
        if (threshold_ > 0.0) peaks_.resize(hits_.size());
        else hits_.clear();
        split_pending_ = false;
    }
    /// The peaks the selection kept (after split_select), and peaks [b, e) built.
    [[nodiscard]] std::size_t split_peaks() const noexcept { return hits_.size(); }
    void split_build(const cubemap<T>& src, std::size_t b, std::size_t e) noexcept {
        for (std::size_t h = b; h < e; ++h) peaks_[h] = make_cube_peak(src, hits_[h], threshold_);
    }
    /// The spherical-harmonic projection for levels of up to `bands` bands (0: none), after the
    /// packing: sh_add_row every row of sh_rows() (a face's rows in order), then sh_finish().
    void sh_setup(int bands) {
        sh_ready_ = false;
        if (bands <= 0) {
            proj_ = sh_projection{};
            return;
        }
        const int pl = sh_projection_level(packed_, bands);
        if (proj_.bands() != bands || proj_.level() != pl || proj_.face_size() != packed_.levels[std::size_t(pl)].n)
            proj_ = sh_projection(bands, pl, packed_.levels[std::size_t(pl)].n);
        else
            proj_.clear();
    }
    [[nodiscard]] std::size_t sh_rows() const noexcept { return proj_.bands() > 0 ? proj_.rows() : 0; }
    [[nodiscard]] int sh_projection_bands() const noexcept { return proj_.bands(); }
    [[nodiscard]] int sh_projection_face() const noexcept { return proj_.face_size(); }
    void sh_add_row(std::size_t row) noexcept { proj_.add_row(packed_, row); }
    void sh_finish() {
        sh_coef_ = proj_.coefficients();
        sh_ready_ = true;
    }
    /// The projection (every face's rows in order, the faces in parallel) and its coefficients.
    template <class Executor> void sh_project(int bands, Executor& ex) {
        sh_setup(bands);
        if (bands <= 0) return;
        const std::size_t n = std::size_t(proj_.face_size());
        ex(6, [&](std::size_t b, std::size_t e) {
            for (std::size_t f = b; f < e; ++f)
                for (std::size_t y = 0; y < n; ++y) sh_add_row(f * n + y);
        });
        sh_finish();
    }
    /// A level by spherical harmonics gets the coefficients of the current source's projection.
    void sh_fill(prefilter_cube_level& lv) const {
        if (lv.sh.active() && sh_ready_) lv.sh.set_coefficients(sh_coef_, proj_.bands());
    }
    /// Packing items (packed_rows), and items [b, e) copied from the source.
    [[nodiscard]] std::size_t pack_items() const noexcept { return packed_rows(packed_); }
    [[nodiscard]] const std::vector<packed_cube::level>& packed_levels() const noexcept { return packed_.levels; }
    [[nodiscard]] std::size_t pack_item_texels(std::size_t item) const noexcept {
        const std::size_t l = packed_row_level(packed_, item);
        return int(l) < packed_.first ? 0 : std::size_t(packed_.levels[l].stride);
    }
    [[nodiscard]] int first_packed() const noexcept { return packed_.first; }
    void pack(const cubemap<T>& src, std::size_t b, std::size_t e) noexcept { pack_cube_rows(packed_, src, b, e); }
    /// After every item: the peaks taken out of the packed copy (the base of the split), in place
    /// when the mips nest (patch_packed_peaks, a few texels per peak and level), else by packing
    /// the split's base again (a chain whose mips do not halve).
    template <class Executor> void finish_packing(const cubemap<T>& src, Executor& ex) {
        if (peaks_.empty()) return;
        if constexpr (std::is_same_v<T, float>)
            if (patch_packed_peaks(packed_, src, peaks_, threshold_)) return;
        packed_ = pack_cube(split_cube_peaks(src, opt_.peaks, ex).base, ex);
    }
    /// The taps of a plan level (tables from the source's lod mapping), its peaks and its coarse
    /// tail from the level of roughness next_roughness (< 0: none).
    /// n: the level's face size; ex computes a level by spherical harmonics' norm (once per level
    /// shape; such a level needs sh_setup first).
    template <class Env, class Executor>
    prefilter_cube_level level(const Env& env, const prefilter_level& lp, double next_roughness, int n, Executor& ex) const {
        prefilter_cube_level lv;
        lv.peaks = level_peaks(lp);
        if (const int bands = prefilter_sh_bands<Lobe>(opt_, lp); bands > 0 && proj_.bands() >= bands) {
            lv.sh.bands = bands;
            lv.sh.rec = sh_recurrence(bands);
            const std::shared_ptr<const std::vector<double>> k = lobe_band_factors<Lobe>(clamped(lp.roughness), opt_.weight);
            lv.sh.k.assign(k->begin(), k->begin() + bands);
            lv.sh.norm = sh_level_norm_for<Lobe>(lv.sh, clamped(lp.roughness), opt_.weight, proj_, n, ex);
            sh_fill(lv);
            return lv;
        }
        sphere_sample_table<float> table = make_ld_table_for<float, Lobe>(env, lp.roughness, lp.samples, opt_.method,
                                                                          opt_.lod_bias, opt_.weight, next_roughness);
        table.trilinear = lp.trilinear;
        lv.taps = make_taps(table, int(packed_.levels.size()));
        for (const int l : lv.taps.level)
            if (l < packed_.first) // first_read_level builds the same tables: never
                throw std::logic_error("ibl::prefilter: a tap reads an unpacked source level");
        if (next_roughness >= 0.0) lv.tail_share = float(fast_tail_of<Lobe>(clamped(lp.roughness), next_roughness, opt_.weight).share);
        return lv;
    }
    /// The intermediate level of plan level lp (prefilter_mid_roughness rm; its coarse tail from
    /// the level of roughness rn): its taps (prefilter_mid_samples), no peaks (the level that reads
    /// it adds them through its own kernel). Its face nm is the next level's (half of lp's).
    template <class Env, class Executor>
    prefilter_cube_level mid_level(const Env& env, const prefilter_level& lp, double rm, double rn, int nm, Executor& ex) const {
        prefilter_cube_level lv = level(env, mid_of(lp, rm), rn, nm, ex);
        lv.peaks = {};
        return lv;
    }
    /// The intermediate level of plan level lp as a plan level: the next level's face, roughness rm,
    /// prefilter_mid_samples.
    [[nodiscard]] prefilter_level mid_of(const prefilter_level& lp, double rm) const {
        prefilter_level m = lp;
        m.level = lp.level + 1;
        m.roughness = rm;
        m.samples = prefilter_mid_samples(opt_, lp.samples);
        return m;
    }
    /// Plan level lp with the samples of its own tap set when it reads an intermediate level.
    [[nodiscard]] prefilter_level mid_owner(const prefilter_level& lp) const {
        prefilter_level o = lp;
        o.samples = prefilter_mid_own_samples(opt_, lp.samples);
        return o;
    }
    /// The merged peaks of a plan level (empty without a split), with the level's whole kernel.
    [[nodiscard]] peak_level level_peaks(const prefilter_level& lp) const {
        if (peaks_.empty()) return {};
        return make_peak_level(peaks_, n0_, table_source_levels_, lp.roughness, opt_.weight, opt_.peaks.footprint,
                               opt_.peaks.max_merge_angle, mean_, opt_.peaks.cut, opt_.peaks.max_level_peaks,
                               opt_.peaks.max_level_steps);
    }
    /// Row `row` (face n + y) of an n x n level: the tap set, then the coarse tail from `next` (the
    /// next level without its peaks; lv.tail_share > 0), then the peaks. base_out (when not null)
    /// receives the row before its peaks: this level as the coarse tail of the level before it reads it.
    void row(const prefilter_cube_level& lv, std::size_t row, int n, vec3<float>* out, const cubemap<float>* next = nullptr,
             vec3<float>* base_out = nullptr) const {
        if (lv.sh.active()) sh_level_row(lv.sh, int(row) / n, int(row) % n, n, out);
        else convolve_row(packed_, lv.taps, int(row) / n, int(row) % n, n, out);
        row_finish(lv, row, n, out, next, base_out);
    }
    /// Taps [st.next, end) of W lanes of a level (their frames fr): a row's tap sums below a texel
    /// (prefilter_update), the same operations as convolve_row's lanes.
    template <std::size_t W>
    void lanes_part(const prefilter_cube_level& lv, const lane_frames<W>& fr, lane_sums<W>& st, std::size_t end) const {
        convolve_lanes_part<W>(packed_, lv.taps, fr, st, end);
    }
    /// The rest of row() once every texel of the row has its tap sum: the coarse tail, the copy
    /// before the peaks, the peaks (whole-row operations).
    void row_finish(const prefilter_cube_level& lv, std::size_t row, int n, vec3<float>* out, const cubemap<float>* next = nullptr,
                    vec3<float>* base_out = nullptr) const {
        if (next && lv.tail_share > 0.f) add_coarse_tail_row(*next, lv.tail_share, int(row) / n, int(row) % n, n, out);
        if (base_out) std::copy(out, out + n, base_out);
        splat_peaks_row(lv.peaks, int(row) / n, int(row) % n, n, out);
    }
    [[nodiscard]] std::size_t peak_count() const noexcept { return peaks_.size(); }

private:
    /// A new source's state before its split: no peaks, the packed layout kept when the source has
    /// the same levels.
    void reset(const cubemap<T>& src) {
        const bool same_layout = int(packed_.levels.size()) == src.levels() && n0_ == src.size(0) && !packed_.data.empty();
        n0_ = src.size(0);
        table_source_levels_ = src.levels();
        peaks_.clear();
        mean_ = threshold_ = 0.0;
        if (!same_layout) packed_ = packed_layout(src);
        sh_ready_ = false;
        proj_.clear();
    }
    /// True when the options split the source's peaks (the fast filter's, the GGX lobe).
    [[nodiscard]] bool splits() const noexcept {
        if constexpr (std::is_same_v<Lobe, ggx_lobe>) return opt_.method == prefilter_method::fast && opt_.peaks.enabled;
        else return false;
    }
    void set_split(cube_peak_split<T>&& split) {
        peaks_ = std::move(split.peaks);
        mean_ = split.mean_luminance;
        threshold_ = split.threshold;
    }
    static double clamped(double r) noexcept { return std::clamp(std::isfinite(r) ? r : 0.0, 0.0, 1.0); }
    prefilter_options opt_;
    int n0_ = 1, table_source_levels_ = 1;
    double mean_ = 0.0, threshold_ = 0.0;
    packed_cube packed_{};
    std::vector<cube_peak> peaks_;
    sh_projection proj_{};
    std::vector<double> sh_coef_;
    bool sh_ready_ = false;
    peak_scan scan_{};            ///< the deferred split's scan (restart_deferred)
    std::size_t mean_rows_ = 0;   ///< rows of level 0 the deferred split's mean reads first (no 1 x 1 level)
    double mean_acc_ = 0.0;       ///< their sum so far (luminance times texel solid angle)
    std::vector<double> omega_;   ///< a face's texel solid angles for that mean
    int omega_n_ = 0;             ///< and the face size they are for
    std::vector<float> scan_row_; ///< its scratch row
    std::vector<std::pair<std::size_t, float>> hits_; ///< the texels the selection kept (split_build's)
    bool split_pending_ = false;  ///< the scan's rows or the selection are due
    bool scanned_ = false;        ///< this source's split is a deferred scan
};
/// The most bands of the plan's levels by spherical harmonics (0: none).
template <class Lobe> int prefilter_sh_max_bands(const prefilter_options& opt, const std::vector<prefilter_level>& plan) {
    int b = 0;
    for (const prefilter_level& lp : plan) b = std::max(b, prefilter_sh_bands<Lobe>(opt, lp));
    return b;
}
} // namespace detail

/// The prefiltered mip chain of an environment for lobe L (a specular_chain: the levels and the
/// weight and mapping they were filtered with, runtime/chain.hpp) (sampling/lobe.hpp; GGX by default,
/// prefilter<ibl::charlie_lobe>(env, opt) for sheen): output level k holds LD of the plan's level
/// k (prefilter_plan: by default level l at roughness opt.policy.roughness(l, levels), face size
/// max(1, base >> l)). Chain level 0 is the copy of the source when the lobe's r = 0 limit is the
/// mirror (GGX), else convolved at its roughness with its samples. Cubemap sources (with their
/// mip chain generated) take the fast path; any other environment is evaluated per sample.
/// Throws std::invalid_argument for base_size < 0 (or 0 without a source size), levels < 0 and a
/// level_plan whose levels are not consecutive in [0, 30], std::length_error for base_size >
/// limits::max_face_size, a level's samples (opt.samples, samples_per_level[l] or the plan's) >
/// limits::max_samples, or a total work sum over levels >= 1 of 6 n_l^2 samples_l (x 2 when
/// trilinear) > limits::max_work, before any work.
template <class Lobe = ggx_lobe, class Env, class Executor = thread_executor>
    requires ld_lobe<Lobe>
specular_chain prefilter(const Env& env, const prefilter_options& opt = {}, Executor&& ex = Executor{}) {
    const int base = detail::prefilter_base_size(env, opt.base_size);
    const std::vector<prefilter_level> plan = prefilter_plan<Lobe>(opt, base);
    detail::check_prefilter_work(opt, plan, base);
    if constexpr (requires { detail::pack_cube(env); }) detail::check_prefilter_mid_work<Lobe>(opt, plan, base);
    // Every interior texel of every level is written below (by the workers, in place), then the borders.
    cubemap<float> out(std::max(1, base >> plan.front().level), int(plan.size()), detail::for_overwrite);
    // Coarse to fine when a level reads its coarse tail from the next (finished) level.
    std::optional<cubemap<float>> next; // the level after the one being computed, as its tail reads it
    if constexpr (requires { detail::pack_cube(env); }) {
        const std::vector<std::size_t> order = detail::prefilter_order<Lobe>(opt, plan, out.size(0), true);
        // Cubemap sources: one packed copy for every level, the peak split of the fast filter,
        // the projection of the levels by spherical harmonics.
        detail::prefilter_cube_source<Lobe, std::remove_cvref_t<decltype(env.texel(0, 0, 0, 0).x)>> cs(env, opt, plan, out.size(0), ex);
        cs.sh_project(detail::prefilter_sh_max_bands<Lobe>(opt, plan), ex);
        for (const std::size_t k : order) {
            const prefilter_level& lp = plan[k];
            const int n = out.size(int(k));
            // The rows are written in place: each work item owns whole face rows of the output.
            const std::vector<vec3<float>*> rows = detail::level_row_pointers(out, int(k));
            if (lobe_mirror_limit<Lobe>() && lp.level == 0) {
                const detail::prefilter_base_read m = detail::prefilter_base_mode(env, n, lp.trilinear);
                ex(std::size_t(6 * n), [&](std::size_t b, std::size_t e) {
                    for (std::size_t row = b; row < e; ++row) detail::prefilter_base_row(env, n, m, row, rows[row]);
                });
            } else {
                const double rn = detail::prefilter_tail_roughness<Lobe>(opt, plan, k, out.size(0), true);
                const double rm = detail::prefilter_mid_roughness<Lobe>(opt, plan, k, out.size(0), true);
                const cubemap<float>* nx = rn >= 0.0 && next ? &*next : nullptr;
                std::optional<cubemap<float>> mid; // the intermediate level (mid_tail), which this level's tail reads
                if (rm >= 0.0) {
                    const int nm = std::max(1, n / 2);
                    const detail::prefilter_cube_level lm = cs.mid_level(env, lp, rm, rn, nm, ex);
                    mid.emplace(nm, 1, detail::for_overwrite);
                    const std::vector<vec3<float>*> mid_rows = detail::level_row_pointers(*mid, 0);
                    ex(std::size_t(6 * nm), [&](std::size_t b, std::size_t e) {
                        for (std::size_t row = b; row < e; ++row) cs.row(lm, row, nm, mid_rows[row], nx, nullptr);
                    });
                    mid->update_borders();
                    nx = &*mid;
                }
                const detail::prefilter_cube_level lv = cs.level(env, rm >= 0.0 ? cs.mid_owner(lp) : lp, rm >= 0.0 ? rm : rn, n, ex);
                // The level before this one reads its coarse tail from this level without its peaks
                // (they are added to every level exactly, through its own kernel).
                // Those rows go straight into the bordered cube that level reads.
                std::optional<cubemap<float>> tail;
                if (k > 0 && detail::prefilter_tail_roughness<Lobe>(opt, plan, k - 1, out.size(0), true) >= 0.0)
                    tail.emplace(n, 1, detail::for_overwrite);
                const std::vector<vec3<float>*> tail_rows =
                    tail ? detail::level_row_pointers(*tail, 0) : std::vector<vec3<float>*>(std::size_t(6 * n), nullptr);
                ex(std::size_t(6 * n), [&](std::size_t b, std::size_t e) {
                    for (std::size_t row = b; row < e; ++row) cs.row(lv, row, n, rows[row], nx, tail_rows[row]);
                });
                if (tail) {
                    tail->update_borders();
                    next = std::move(tail);
                }
            }
        }
    } else {
        const std::vector<std::size_t> order = detail::prefilter_order<Lobe>(opt, plan, out.size(0));
        for (const std::size_t k : order) {
            const prefilter_level& lp = plan[k];
            const int n = out.size(int(k));
            std::vector<vec3<float>> texels;
            if (lobe_mirror_limit<Lobe>() && lp.level == 0) {
                texels = detail::prefilter_base(env, n, lp.trilinear, ex);
            } else {
                const double rn = detail::prefilter_tail_roughness<Lobe>(opt, plan, k, out.size(0));
                sphere_sample_table<float> table = make_ld_table_for<float, Lobe>(env, lp.roughness, lp.samples, opt.method,
                                                                                  opt.lod_bias, opt.weight, rn);
                table.trilinear = lp.trilinear;
                texels = convolve_faces(env, table, n, ex);
                if (rn >= 0.0 && next) {
                    const float share = float(detail::fast_tail_of<Lobe>(std::clamp(std::isfinite(lp.roughness) ? lp.roughness : 0.0, 0.0, 1.0),
                                                                  rn, opt.weight).share);
                    for (int r = 0; r < 6 * n; ++r)
                        detail::add_coarse_tail_row(*next, share, r / n, r % n, n, texels.data() + std::size_t(r) * std::size_t(n));
                }
            }
            out.fill(int(k), [&](int f, int x, int y) { return texels[cube_texel_index(f, x, y, n)]; });
            if (k > 0 && detail::prefilter_tail_roughness<Lobe>(opt, plan, k - 1, out.size(0)) >= 0.0)
                next = detail::prefilter_tail_cube(n, [&](int f, int x, int y) { return texels[cube_texel_index(f, x, y, n)]; });
        }
    }
    out.update_borders();
    return specular_chain(std::move(out), opt.weight, opt.policy.mapping);
}

} // namespace ibl

#endif // IBL_DETAIL_CXX20
