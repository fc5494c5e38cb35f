#pragma once
// ibl/bake/plan.hpp — the scene-driven bake plan: which products, mip levels, resolutions,
// SH bands, DFG table size and sample counts a scene needs, chosen from the scene's materials and
// an error target with the library's measured error-vs-cost relations. Pure arithmetic on the
// scene description: depends on core/ and runtime/roughness_mip.hpp only (no integrator code).
//
// ---- What the error target means --------------------------------------------------------------
//   error_target is the relative error allowed in the PRODUCTS as the scene samples them, against
//   converged products of the same layout (a bake with many samples, full resolution, exact DFG,
//   brute-force irradiance). It is NOT the error of the split-sum approximation against the true
//   integral (reference/radiance.hpp): that error (tens of per cent under a sun, see
//   research/split_sum_error.cpp) belongs to the shading model, and no product plan can reduce it.
//   Per product (each must meet the target on its own measure):
//     specular  normalised RMSE (RMSE / RMS of the reference) of each used prefiltered level;
//     diffuse   RMS(E_product - E) / RMS(E) over normals (irradiance, E = brute-force cosine integral);
//     dfg       the largest bilinear-interpolation error delta of A and B; it enters the specular
//               albedo F0 A + F90 B as up to 2 delta, and the DFG gets a quarter of the budget:
//               2 delta <= target / 4, i.e. delta <= target / 8.
//
// ---- Specular: which levels (the contiguous-chain decision) ------------------------------------
//   The engine's chain convention is fixed by plan_settings: `levels` L and a roughness_mip_policy
//   (runtime/roughness_mip.hpp) map roughness r to a continuous lod in [0, L - 1] of a virtual
//   chain whose level v has face size max(1, base >> v). A trilinear lookup at lod reads levels
//   floor(lod) and ceil(lod), so a roughness range [lo, hi] needs the levels
//   floor(lod(lo)) .. ceil(lod(hi)). A GPU mip chain is contiguous from its base, so the plan STORES
//   the virtual levels first_level .. last_level (the sharpest and the roughest needed):
//     * levels sharper than first_level are left out: the stored chain's base IS the sharpest
//       needed level (its face size base >> first_level);
//     * levels rougher than last_level are left out (the chain ends there; lookups clamp);
//     * levels strictly between that no used roughness reads (a scene of r = 0.1 and r = 0.9) are
//       kept for contiguity but baked cheaply (filler_samples) and marked needed = false.
//   Runtime lookup: lod_stored = policy.lod(r, L) - first_level (specular_plan::stored_lod), i.e.
//   the shader's usual lod minus a constant; no other change.
//
// ---- Specular: resolution --------------------------------------------------------------------
//   Lobe width. Half vectors of GGX with alpha = r^2 satisfy P(theta_h <= t) = tan^2 t / (alpha^2 +
//   tan^2 t), so half of them lie within theta_h = atan(alpha); the reflected direction turns by
//   twice that: w(r) = 2 atan(alpha), the median angular radius of the reflection lobe.
//   Texel. A cube face of size n has texels of ~(pi/2)/n rad (at the face centre; smaller towards
//   the corners). Rule: texel <= texel_fraction * w(r_v) at every needed level v (r_v the level's
//   roughness), texel_fraction = 1/4: bilinear reconstruction of a lobe of width w from texels h
//   errs by at most (h/w)^2 / 8 ~ 0.8% (Gaussian bound), well inside any useful target.
//   Screen cap. A reflective object covering P pixels across shows the reflected hemisphere
//   (~pi rad of directions on a sphere) on P pixels, so it cannot show texels smaller than pi/P:
//   n <= P / 2 (max_reflection_pixels). The mirror level (r = 0, w = 0) is limited by this cap only.
//   Each level's size is rounded up to a power of two; the virtual base is the largest
//   size_v << v over the needed levels, capped by plan_settings::max_base_size (the source's size).
//
// ---- Specular: samples and read mode per level (filtered importance sampling) ---------------------
//   Measured where it is used (research/plan_measure.cpp `prefilter`): the chain layouts
//   the plan produces for a 256 source (6 virtual levels, linear policy, virtual base 256 when
//   r = 0.2 is read, else 128; level v at face size base >> v; source baked at the base size, 4 x 4
//   sub-samples), default sky + 1-degree sun of 3e4 (the hardest case we ship). Error of a level:
//   nrmse at the texels ibl-bake --compare-full checks (6 x 6 per face + the 3 x 3 block at the sun)
//   against the CONVERGED level of the same layout (4096 samples, trilinear reads: what the target
//   refers to). Table: the non-increasing upper envelope over N' >= N and over both layouts
//   (trilinear at 4096 is the converged set itself: its entry is nearest-4096's, the noise left):
//       nearest    N=64    128    256    512   1024   2048   4096
//       r = 0.2   0.229  0.067  0.055  0.016  0.014  0.004  0.001
//       r = 0.4   0.262  0.221  0.221  0.112  0.090  0.035  0.021
//       r = 0.6   0.428  0.239  0.239  0.239  0.239  0.111  0.070
//       r = 0.8   0.376  0.252  0.252  0.194  0.194  0.126  0.067
//       r = 1.0   0.336  0.336  0.270  0.270  0.181  0.179  0.082
//       trilinear
//       r = 0.2   0.171  0.092  0.043  0.017  0.010  0.004  0.001
//       r = 0.4   0.229  0.203  0.203  0.141  0.069  0.038  0.021
//       r = 0.6   0.307  0.228  0.176  0.153  0.153  0.093  0.070
//       r = 0.8   0.304  0.239  0.222  0.169  0.169  0.142  0.067
//       r = 1.0   0.323  0.273  0.229  0.217  0.150  0.120  0.082
//   Not 1/sqrt(N): e sqrt(N) grows from ~2 (N = 64) to 4 - 8 (N = 1024 - 2048) on rough levels;
//   fitted on the envelope, e ~ N^-0.5 at r = 0.2 - 0.4 but only ~N^-0.3 at r >= 0.6 (a fixed
//   Hammersley pattern decides how many samples land on the sun; single N are lucky or unlucky,
//   hence the envelope). Nearest-level reads are not biased against trilinear ones beyond that
//   noise (nearest 4096 vs converged: 0.001 - 0.08). Reachable floor (4096 samples): 0.021 at
//   r = 0.4, 0.07 - 0.08 at r >= 0.6.
//   Rule: each needed level gets the cheapest (N, read mode), cost N x (2 if trilinear), N in 16 ..
//   4096 (powers of two), with expected error <= target / prefilter_product_margin(r) (N < 64:
//   e(64) sqrt(64 / N); r between rows: linear). None: the lowest error is taken and the plan warns
//   with the smallest target the scene can reach (floor x margin).
//   Margin: the product error (relative RMS of ambient luminance at the shading points vs the
//   converged products, what the target is about) against the largest needed level's measured
//   error, ibl-bake --compare-full, built-in sky (glossy_metals at targets 0.05 - 0.2 and the full
//   bake; rough_plastics): 0.50 - 1.83 (glossy: trilinear blending of levels 1 and 2 and the bright
//   metal reflections near the sun weight the sun's error more than the check texels do; rough:
//   blending and the diffuse share dilute it). Margin by level: 1.83 (the largest measured) for
//   r < 0.5, whose concentrated sun reflections dominate the product error (measured 0.72 - 1.83);
//   1.0 for r >= 0.5 (measured 0.49 on rough_plastics: no credit taken for the dilution).

// ---- Diffuse -------------------------------------------------------------------------------------
//   None when diffuse is not lit by IBL or every material is a bare metal (metallic = 1). Else SH:
//   RMS(E_SH - E)/RMS(E) of 2 and 3 bands against a brute-force cosine integral of the same 64^2
//   cube, for the SH irradiance as shipped (with the automatic window that keeps E >= 0; a sun
//   left in the environment makes the raw projection ring negative, and the window costs
//   accuracy): the worst over a sky with a sun and two real HDRIs, measured by
//   `ibl_plan_measure sh` (figures in docs/scene-format.md):
//       2 bands  0.451
//       3 bands  0.120
//   bands = 2 if the diffuse target >= sh2_irradiance_error, 3 if >= sh3_irradiance_error,
//   otherwise an irradiance cubemap
//   (bake/irradiance.hpp, 32^2, 1024 filtered cosine samples) whose band limit is not 3.
//   plan_limits::max_sh_bands caps the bands (a warning says when the target is then missed).
//
// ---- DFG table -----------------------------------------------------------------------------------
//   Measured (plan_measure.cpp): largest |dA|, |dB| of a bilinear lookup of the exact N^2 table
//   (ggx_height_correlated) against dfg_exact at 257^2 off-grid points with n.v >= 0.1:
//       N      16       32       64       128      256
//       delta  3.84e-2  1.89e-2  9.39e-3  4.68e-3  2.33e-3      (~0.6 / N: first order)
//   N = the smallest size with delta <= target / 8. Below n.v = 0.1 the clamp-to-edge lookup
//   errs by up to ~0.08 at every size (A and B change fastest at grazing angles, and n.v < 0.5/N
//   is extrapolated): a size cannot fix that, a remapped lookup could. Channels: 2 (A, B), 3 only
//   when the scene asks for multiple scattering (the k = (1 - E)/E channel).
//
// ---- Cost model ------------------------------------------------------------------------------------
//   Units counted per product (the integrators' inner loops), times per unit measured from an
//   `ibl-bake` default run (release, 2 loaded cores, built-in sky): source cube 25.7 ns per
//   sub-sample (6 n^2 k^2), prefilter 14.7 ns per bilinear tap (6 n_l^2 N per level, x2 for
//   trilinear), SH 48 ns per source texel (6 n^2; 2 bands ~ 3 bands: bound by the texel loop),
//   DFG 6.1 ns per quadrature evaluation (N^2 x 432), irradiance map as the prefilter. Only ratios
//   (time saved) are meant; --compare-full in ibl-bake measures the real times.
//
// ---- Bad input ------------------------------------------------------------------------------------
//   Roughness outside [0, 1] is clamped with a warning (plan.warnings); a NaN roughness, metallic
//   or error target, an error target <= 0, a scene without materials and max_reflection_pixels < 1
//   throw std::invalid_argument. metallic outside [0, 1] is clamped with a warning. plan_settings
//   (make_bake_plan, full_bake_plan): levels in [1, limits::max_plan_levels], max_base_size in
//   [1, limits::max_face_size], texel_fraction finite and > 0, filler_samples and the full bake's
//   samples <= limits::max_samples, source_subsamples in [1, limits::max_subsamples], the full
//   bake's dfg_size in [1, limits::max_dfg_lut_size]: std::invalid_argument below a domain,
//   std::length_error above a bound (core/limits.hpp).

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include "../core/constants.hpp"
#include "../core/limits.hpp"
#include "../runtime/roughness_mip.hpp"

namespace ibl {

// ---- the scene -----------------------------------------------------------------------------------

/// A closed range of perceptual roughness used by a material class (lo = hi: one value).
struct roughness_range {
    double lo = 0.5, hi = 0.5;
};

/// A class of materials: its metalness (0 dielectric, 1 bare metal, between: both lobes) and the
/// roughness values / ranges it uses (a histogram becomes the ranges of its non-empty bins).
struct material_class {
    std::string name;
    double metallic = 0.0;
    std::vector<roughness_range> roughness;
};

/// Platform limits (e.g. mobile): the plan never exceeds them, and warns when a target is missed.
struct plan_limits {
    int max_sh_bands = 3;     ///< 2 or 3
    int max_dfg_size = 256;
    std::uint32_t max_samples = 4096;
};

struct scene_description {
    std::string name;
    std::vector<material_class> materials;
    bool diffuse_ibl = true;           ///< diffuse lit by IBL (false: lightmaps / probes do it)
    int max_reflection_pixels = 1024;  ///< largest on-screen size (pixels across) of a reflective object
    double error_target = 0.1;         ///< relative error of the products (see the header)
    double diffuse_error_target = 0.0; ///< 0: error_target
    bool multiscatter = false;         ///< the DFG table's third channel (Turquin / Fdez-Aguera)
    plan_limits limits{};
};

/// The engine's conventions and the bake's ceilings the plan works within.
struct plan_settings {
    int levels = 6;                     ///< L: levels of the virtual chain (ibl-bake: auto_levels(256))
    roughness_mip_policy policy{};      ///< roughness <-> lod of the virtual chain
    int max_base_size = 256;            ///< largest face size (the source's)
    double texel_fraction = 0.25;       ///< texel <= fraction x lobe width (see the header)
    std::uint32_t filler_samples = 16;  ///< samples of kept-for-contiguity levels
    int source_subsamples = 4;          ///< k x k sub-samples of the source bake (cost model)
};

// ---- the plan --------------------------------------------------------------------------------------

struct specular_level_plan {
    int level = 0;              ///< virtual level v (stored index = v - first_level)
    int size = 1;               ///< face size
    double roughness = 0.0;     ///< policy.roughness(v, L)
    std::uint32_t samples = 0;  ///< 0 for the mirror level (a copy of the source)
    bool needed = true;         ///< read by some used roughness (false: contiguity filler)
    bool trilinear = false;     ///< prefilter reads of this level (nearest level or trilinear)
    double expected_error = 0.0;
};

struct specular_plan {
    bool enabled = false;
    roughness_mip_policy policy{};
    int virtual_levels = 1;
    int virtual_base_size = 1;
    int first_level = 0;
    bool trilinear = false;     ///< true when every baked level reads trilinearly (per level: specular_level_plan)
    std::vector<specular_level_plan> levels; ///< stored levels, sharpest first

    /// The lod to sample the stored chain at for roughness r.
    template <class T> [[nodiscard]] T stored_lod(T roughness) const noexcept {
        return policy.lod(roughness, virtual_levels) - T(first_level);
    }
};

enum class diffuse_product : int { none = 0, sh = 1, irradiance_map = 2 };

struct diffuse_plan {
    diffuse_product kind = diffuse_product::none;
    int sh_bands = 0;
    int map_size = 0;
    std::uint32_t map_samples = 0;
    double expected_error = 0.0;
};

struct dfg_plan {
    bool enabled = false;
    int size = 0;
    int channels = 0;
    double expected_error = 0.0;
};

/// Estimated time per product in milliseconds (the cost model of the header).
struct plan_cost {
    double source_ms = 0, specular_ms = 0, diffuse_ms = 0, dfg_ms = 0;
    [[nodiscard]] double total_ms() const noexcept { return source_ms + specular_ms + diffuse_ms + dfg_ms; }
};

struct bake_plan {
    std::string scene;
    double error_target = 0.0, diffuse_error_target = 0.0;
    int source_size = 1;        ///< face size of the source cube the bake needs
    specular_plan specular;
    diffuse_plan diffuse;
    dfg_plan dfg;
    std::vector<std::string> warnings;
};

// ---- measured relations (sources in the header) ------------------------------------------------------

/// Measured filtered-IS error of one level (plan_measure.cpp, header table): roughness rows, sample
/// columns, nearest-level and trilinear reads; the non-increasing upper envelope over the two
/// chain layouts the plan produces.
inline constexpr double prefilter_table_r[5] = {0.2, 0.4, 0.6, 0.8, 1.0};
inline constexpr std::uint32_t prefilter_table_n[7] = {64, 128, 256, 512, 1024, 2048, 4096};
inline constexpr double prefilter_error_nearest[5][7] = {
    {0.229, 0.067, 0.055, 0.016, 0.014, 0.004, 0.001}, {0.262, 0.221, 0.221, 0.112, 0.090, 0.035, 0.021},
    {0.428, 0.239, 0.239, 0.239, 0.239, 0.111, 0.070}, {0.376, 0.252, 0.252, 0.194, 0.194, 0.126, 0.067},
    {0.336, 0.336, 0.270, 0.270, 0.181, 0.179, 0.082}};
inline constexpr double prefilter_error_trilinear[5][7] = {
    {0.171, 0.092, 0.043, 0.017, 0.010, 0.004, 0.001}, {0.229, 0.203, 0.203, 0.141, 0.069, 0.038, 0.021},
    {0.307, 0.228, 0.176, 0.153, 0.153, 0.093, 0.070}, {0.304, 0.239, 0.222, 0.169, 0.169, 0.142, 0.067},
    {0.323, 0.273, 0.229, 0.217, 0.150, 0.120, 0.082}};
/// Product error (ambient luminance at shading points) per unit of a needed level's error, measured
/// with ibl-bake --compare-full (header): a level of roughness r must meet target / margin(r).
inline constexpr double prefilter_product_margin_sharp = 1.83; ///< levels r < 0.5 (measured 0.72 - 1.83)
inline constexpr double prefilter_product_margin_rough = 1.0;  ///< levels r >= 0.5 (measured 0.49; no credit taken)
[[nodiscard]] inline double prefilter_product_margin(double roughness) noexcept {
    return roughness < 0.5 ? prefilter_product_margin_sharp : prefilter_product_margin_rough;
}

/// Expected error (nrmse vs converged) of a level of roughness r baked with N samples per texel.
/// Between table rows: linear in r (below 0.2: the 0.2 row); between columns: the value at the
/// largest tabulated N <= N (the envelope is non-increasing); below 64: e(64) sqrt(64 / N);
/// above 4096: e(4096) (the floor: not measured beyond).
[[nodiscard]] inline double prefilter_expected_error(double roughness, std::uint32_t samples, bool trilinear) noexcept {
    const auto& t = trilinear ? prefilter_error_trilinear : prefilter_error_nearest;
    const double r = std::clamp(roughness, prefilter_table_r[0], prefilter_table_r[4]);
    int i = 0;
    while (i < 3 && r > prefilter_table_r[i + 1]) ++i;
    const double w = (r - prefilter_table_r[i]) / (prefilter_table_r[i + 1] - prefilter_table_r[i]);
    const std::uint32_t n = std::max<std::uint32_t>(samples, 1u);
    int j = 0;
    while (j < 6 && prefilter_table_n[j + 1] <= n) ++j;
    const double scale = n < prefilter_table_n[0] ? std::sqrt(double(prefilter_table_n[0]) / double(n)) : 1.0;
    return scale * ((1.0 - w) * t[i][j] + w * t[i + 1][j]);
}

/// The cheapest (samples, read mode) of a level whose expected error is within `level_target`;
/// cost = samples x (2 if trilinear). met = false: nothing within max_samples reaches it (then the
/// smallest expected error is chosen).
struct prefilter_choice {
    std::uint32_t samples = 16;
    bool trilinear = false;
    double expected_error = 0.0;
    bool met = false;
};
[[nodiscard]] inline prefilter_choice choose_prefilter(double roughness, double level_target, std::uint32_t max_samples = 4096) {
    constexpr std::uint32_t grid[9] = {16, 32, 64, 128, 256, 512, 1024, 2048, 4096};
    prefilter_choice best, lowest;
    double best_cost = 0.0;
    lowest.expected_error = 1e300;
    for (std::uint32_t n : grid) {
        if (n > std::max<std::uint32_t>(max_samples, 16u)) break;
        for (bool tri : {false, true}) {
            const double e = prefilter_expected_error(roughness, n, tri), cost = double(n) * (tri ? 2.0 : 1.0);
            if (e < lowest.expected_error) lowest = {n, tri, e, false};
            if (e <= level_target && (!best.met || cost < best_cost || (cost == best_cost && e < best.expected_error))) {
                best = {n, tri, e, true};
                best_cost = cost;
            }
        }
    }
    return best.met ? best : lowest;
}
/// The smallest error the table reaches at roughness r (4096 samples or max_samples).
[[nodiscard]] inline double prefilter_reachable_error(double roughness, std::uint32_t max_samples = 4096) {
    return choose_prefilter(roughness, 0.0, max_samples).expected_error;
}

/// Largest bilinear error of an exact N^2 DFG table (n.v >= 0.1), N in dfg_sizes.
inline constexpr int dfg_sizes[5] = {16, 32, 64, 128, 256};
inline constexpr double dfg_interp_error[5] = {3.84e-2, 1.89e-2, 9.39e-3, 4.68e-3, 2.33e-3};

/// Worst measured RMS(E_SH - E) / RMS(E) of 2 and 3 SH bands.
inline constexpr double sh2_irradiance_error = 0.451;
inline constexpr double sh3_irradiance_error = 0.120;

// ---- the rules -------------------------------------------------------------------------------------

namespace detail {
inline int pow2_ceil(double x) {
    int n = 1;
    while (double(n) < x && n < (1 << 20)) n <<= 1;
    return n;
}
inline std::uint32_t ceil16(double x) { return std::uint32_t(std::ceil(x / 16.0)) * 16u; }
inline std::string fmt_num(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", v);
    return buf;
}
} // namespace detail

/// Median angular radius (rad) of the reflected GGX lobe of roughness r: 2 atan(r^2).
[[nodiscard]] inline double lobe_width(double roughness) noexcept {
    const double r = std::clamp(roughness, 0.0, 1.0);
    return 2.0 * std::atan(r * r);
}

/// Smallest power-of-two face size whose texels are at most `fraction` of the lobe width at r,
/// capped by `cap` (the mirror lobe, width 0, gets the cap).
[[nodiscard]] inline int face_size_for_roughness(double roughness, double fraction, int cap) {
    const double w = lobe_width(roughness);
    if (!(w > 0.0)) return cap;
    const double n = half_pi_v<double> / (fraction * w);
    return std::min(detail::pow2_ceil(n), cap);
}

/// Filtered-IS samples per texel of the cheapest choice meeting `target` at roughness r.
[[nodiscard]] inline std::uint32_t prefilter_samples_for(double roughness, double target, std::uint32_t max_samples = 4096) {
    return choose_prefilter(roughness, target, max_samples).samples;
}

/// Smallest DFG size whose interpolation error is within target / 8 (256 if none).
[[nodiscard]] inline int dfg_size_for(double target) noexcept {
    for (int i = 0; i < 5; ++i)
        if (dfg_interp_error[i] <= target / 8.0) return dfg_sizes[i];
    return dfg_sizes[4];
}
[[nodiscard]] inline double dfg_error_at(int size) noexcept {
    for (int i = 0; i < 5; ++i)
        if (size <= dfg_sizes[i]) return dfg_interp_error[i];
    return dfg_interp_error[4] * double(dfg_sizes[4]) / double(size);
}

/// Estimated time per product (the header's cost model).
[[nodiscard]] inline plan_cost estimate_cost(const bake_plan& p, int source_subsamples = 4) {
    constexpr double ns_source = 25.7, ns_tap = 14.7, ns_sh_texel = 48.0, ns_dfg_eval = 6.1;
    constexpr double dfg_evals_per_texel = 432.0;
    plan_cost c;
    const double k2 = double(source_subsamples) * double(source_subsamples);
    c.source_ms = 6.0 * double(p.source_size) * double(p.source_size) * k2 * ns_source * 1e-6;
    if (p.specular.enabled)
        for (const auto& l : p.specular.levels)
            c.specular_ms += 6.0 * double(l.size) * double(l.size) * double(l.samples) * (l.trilinear ? 2.0 : 1.0) *
                             ns_tap * 1e-6;
    if (p.diffuse.kind == diffuse_product::sh)
        c.diffuse_ms = 6.0 * double(p.source_size) * double(p.source_size) * ns_sh_texel * 1e-6;
    else if (p.diffuse.kind == diffuse_product::irradiance_map)
        c.diffuse_ms = 6.0 * double(p.diffuse.map_size) * double(p.diffuse.map_size) * double(p.diffuse.map_samples) * ns_tap * 1e-6;
    if (p.dfg.enabled) c.dfg_ms = double(p.dfg.size) * double(p.dfg.size) * dfg_evals_per_texel * ns_dfg_eval * 1e-6;
    return c;
}

/// Checks and normalises a scene (clamps with warnings; throws std::invalid_argument).
inline scene_description validate_scene(scene_description s, std::vector<std::string>& warnings) {
    if (s.materials.empty()) throw std::invalid_argument("scene: no materials");
    if (!(s.error_target > 0.0) || !std::isfinite(s.error_target))
        throw std::invalid_argument("scene: error_target must be a finite number > 0");
    if (s.diffuse_error_target == 0.0) s.diffuse_error_target = s.error_target;
    if (!(s.diffuse_error_target > 0.0) || !std::isfinite(s.diffuse_error_target))
        throw std::invalid_argument("scene: diffuse_error_target must be a finite number > 0");
    if (s.max_reflection_pixels < 1) throw std::invalid_argument("scene: max_reflection_pixels must be >= 1");
    if (s.limits.max_sh_bands < 2 || s.limits.max_sh_bands > 3) throw std::invalid_argument("scene: max_sh_bands must be 2 or 3");
    if (s.limits.max_dfg_size < 16) throw std::invalid_argument("scene: max_dfg_size must be >= 16");
    if (s.limits.max_samples < 16) throw std::invalid_argument("scene: max_samples must be >= 16");
    for (auto& m : s.materials) {
        const std::string who = "material '" + m.name + "'";
        if (std::isnan(m.metallic)) throw std::invalid_argument(who + ": metallic is NaN");
        if (m.metallic < 0.0 || m.metallic > 1.0) {
            warnings.push_back(who + ": metallic " + detail::fmt_num(m.metallic) + " clamped to [0, 1]");
            m.metallic = std::clamp(m.metallic, 0.0, 1.0);
        }
        if (m.roughness.empty()) throw std::invalid_argument(who + ": no roughness values");
        for (auto& r : m.roughness) {
            if (std::isnan(r.lo) || std::isnan(r.hi)) throw std::invalid_argument(who + ": roughness is NaN");
            if (r.lo > r.hi) std::swap(r.lo, r.hi);
            for (double* v : {&r.lo, &r.hi})
                if (*v < 0.0 || *v > 1.0) {
                    warnings.push_back(who + ": roughness " + detail::fmt_num(*v) + " clamped to [0, 1]");
                    *v = std::clamp(*v, 0.0, 1.0);
                }
        }
    }
    return s;
}

namespace detail {
/// The settings' sizes and counts (the header's "Bad input"), checked for function fn.
inline void check_plan_settings(const char* fn, const plan_settings& set) {
    check_arg(fn, "plan_settings.levels", set.levels, 1, limits::max_plan_levels, "limits::max_plan_levels");
    check_arg(fn, "plan_settings.max_base_size", set.max_base_size, 1, limits::max_face_size, "limits::max_face_size");
    if (!(set.texel_fraction > 0.0) || !std::isfinite(set.texel_fraction))
        throw std::invalid_argument(std::string("ibl::") + fn + ": plan_settings.texel_fraction must be a finite number > 0, got " +
                                    fmt_num(set.texel_fraction));
    check_total(fn, "plan_settings.filler_samples", set.filler_samples, limits::max_samples, "limits::max_samples");
    check_arg(fn, "plan_settings.source_subsamples", set.source_subsamples, 1, limits::max_subsamples,
              "limits::max_subsamples");
}
} // namespace detail

/// The plan for a scene (the rules of the header).
inline bake_plan make_bake_plan(const scene_description& scene_in, const plan_settings& set = {}) {
    detail::check_plan_settings("make_bake_plan", set);
    bake_plan p;
    const scene_description s = validate_scene(scene_in, p.warnings);
    p.scene = s.name;
    p.error_target = s.error_target;
    p.diffuse_error_target = s.diffuse_error_target;
    const int L = set.levels;

    // Specular: needed virtual levels.
    std::vector<bool> needed(std::size_t(L), false);
    for (const auto& m : s.materials)
        for (const auto& r : m.roughness) {
            const double a = set.policy.lod(r.lo, L), b = set.policy.lod(r.hi, L);
            const int v0 = std::clamp(int(std::floor(a)), 0, L - 1), v1 = std::clamp(int(std::ceil(b)), 0, L - 1);
            for (int v = v0; v <= v1; ++v) needed[std::size_t(v)] = true;
        }
    int first = 0, last = L - 1;
    while (!needed[std::size_t(first)]) ++first;
    while (!needed[std::size_t(last)]) --last;
    specular_plan& sp = p.specular;
    sp.enabled = true;
    sp.policy = set.policy;
    sp.virtual_levels = L;
    sp.first_level = first;
    const int screen_cap = std::max(1, s.max_reflection_pixels / 2);
    int base = 1;
    for (int v = first; v <= last; ++v) {
        if (!needed[std::size_t(v)]) continue;
        const double r = set.policy.roughness(double(v), L);
        const int n = face_size_for_roughness(r, set.texel_fraction, std::min(screen_cap, set.max_base_size));
        base = std::max(base, int(std::min<long long>((long long)n << v, set.max_base_size))); // n <= 2^16, v < 17
    }
    base = std::min(base, set.max_base_size);
    sp.virtual_base_size = base;
    double worst_reachable = 0.0;
    bool all_tri = true;
    for (int v = first; v <= last; ++v) {
        specular_level_plan lp;
        lp.level = v;
        lp.size = std::max(1, base >> v);
        lp.roughness = set.policy.roughness(double(v), L);
        lp.needed = needed[std::size_t(v)];
        if (v == 0) {
            lp.samples = 0; // the mirror level: a copy of the source
        } else if (lp.needed) {
            const double margin = prefilter_product_margin(lp.roughness), level_target = s.error_target / margin;
            const prefilter_choice c = choose_prefilter(lp.roughness, level_target, s.limits.max_samples);
            lp.samples = c.samples;
            lp.trilinear = c.trilinear;
            lp.expected_error = c.expected_error;
            if (!c.met) {
                p.warnings.push_back("specular level " + std::to_string(v) + " (r=" + detail::fmt_num(lp.roughness) + "): target " +
                                     detail::fmt_num(s.error_target) + " needs level error <= " + detail::fmt_num(level_target) +
                                     " (margin " + detail::fmt_num(margin) + "), below the reachable ~" +
                                     detail::fmt_num(c.expected_error) + " (" + std::to_string(c.samples) +
                                     (c.trilinear ? " trilinear" : " nearest") + " samples, sky + sun)");
                worst_reachable = std::max(worst_reachable, c.expected_error * margin);
            }
        } else {
            lp.samples = set.filler_samples;
        }
        if (v > 0) all_tri = all_tri && lp.trilinear;
        sp.levels.push_back(lp);
    }
    sp.trilinear = all_tri && sp.levels.size() > 1;
    if (worst_reachable > 0.0)
        p.warnings.push_back("specular: the smallest reachable target for this scene is ~" +
                             detail::fmt_num(worst_reachable) +
                             " (filtered IS on a sky with a sun; the full bake is not better)");
    p.source_size = base;

    // Diffuse.
    bool any_dielectric = false;
    for (const auto& m : s.materials) any_dielectric = any_dielectric || m.metallic < 1.0;
    if (s.diffuse_ibl && any_dielectric) {
        diffuse_plan& d = p.diffuse;
        const double t = s.diffuse_error_target;
        if (t >= sh2_irradiance_error || s.limits.max_sh_bands == 2) {
            d.kind = diffuse_product::sh;
            d.sh_bands = 2;
            d.expected_error = sh2_irradiance_error;
            if (t < sh2_irradiance_error)
                p.warnings.push_back("diffuse: max_sh_bands = 2 gives ~" + detail::fmt_num(sh2_irradiance_error) + " > target " +
                                     detail::fmt_num(t));
        } else if (t >= sh3_irradiance_error) {
            d.kind = diffuse_product::sh;
            d.sh_bands = 3;
            d.expected_error = sh3_irradiance_error;
        } else {
            d.kind = diffuse_product::irradiance_map;
            d.map_size = 32;
            d.map_samples = 1024;
            d.expected_error = 0.0; // not measured here: bounded by the map's resolution and samples
        }
    } else {
        p.diffuse.kind = diffuse_product::none;
    }

    // DFG.
    p.dfg.enabled = true;
    p.dfg.size = std::min(dfg_size_for(s.error_target), s.limits.max_dfg_size);
    p.dfg.channels = s.multiscatter ? 3 : 2;
    p.dfg.expected_error = dfg_error_at(p.dfg.size);
    if (p.dfg.expected_error > s.error_target / 8.0)
        p.warnings.push_back("dfg: size " + std::to_string(p.dfg.size) + " errs by ~" + detail::fmt_num(p.dfg.expected_error) +
                             " > target / 8");
    return p;
}

/// The full bake the plan is compared with (ibl-bake's defaults): every level of the virtual
/// chain at max_base_size, `samples` trilinear filtered IS per level, 3-band SH, a 3-channel
/// DFG table of dfg_size.
inline bake_plan full_bake_plan(const plan_settings& set = {}, std::uint32_t samples = 512, bool trilinear = true,
                                int dfg_size = 128) {
    detail::check_plan_settings("full_bake_plan", set);
    detail::check_total("full_bake_plan", "samples", samples, limits::max_samples, "limits::max_samples");
    detail::check_arg("full_bake_plan", "dfg_size", dfg_size, 1, int(limits::max_dfg_lut_size), "limits::max_dfg_lut_size");
    bake_plan p;
    p.scene = "full";
    p.source_size = set.max_base_size;
    specular_plan& sp = p.specular;
    sp.enabled = true;
    sp.policy = set.policy;
    sp.virtual_levels = set.levels;
    sp.virtual_base_size = set.max_base_size;
    sp.first_level = 0;
    sp.trilinear = trilinear;
    for (int v = 0; v < set.levels; ++v) {
        specular_level_plan lp;
        lp.level = v;
        lp.size = std::max(1, set.max_base_size >> v);
        lp.roughness = set.policy.roughness(double(v), set.levels);
        lp.samples = v == 0 ? 0u : samples;
        lp.trilinear = trilinear;
        sp.levels.push_back(lp);
    }
    p.diffuse = {diffuse_product::sh, 3, 0, 0, sh3_irradiance_error};
    p.dfg = {true, dfg_size, 3, dfg_error_at(dfg_size)};
    return p;
}

/// Human-readable list of what `plan` leaves out relative to `full`.
inline std::vector<std::string> left_out(const bake_plan& plan, const bake_plan& full) {
    std::vector<std::string> out;
    const specular_plan& a = plan.specular;
    if (!a.enabled) {
        out.push_back("specular chain");
    } else {
        std::string sharp, rough;
        for (const auto& l : full.specular.levels) {
            const bool stored = l.level >= a.first_level && l.level < a.first_level + int(a.levels.size());
            if (stored) continue;
            std::string& s = l.level < a.first_level ? sharp : rough;
            s += (s.empty() ? "" : ", ") + std::to_string(l.level) + " (r=" + detail::fmt_num(l.roughness) + ")";
        }
        if (!sharp.empty()) out.push_back("sharp levels " + sharp);
        if (!rough.empty()) out.push_back("rough levels " + rough);
        for (const auto& l : a.levels)
            if (!l.needed) out.push_back("level " + std::to_string(l.level) + " kept for contiguity only (" + std::to_string(l.samples) + " samples)");
        if (a.virtual_base_size < full.specular.virtual_base_size)
            out.push_back("resolution: virtual base " + std::to_string(a.virtual_base_size) + " instead of " +
                          std::to_string(full.specular.virtual_base_size));
    }
    if (plan.diffuse.kind == diffuse_product::none) out.push_back("diffuse irradiance (SH)");
    else if (plan.diffuse.kind == diffuse_product::sh && plan.diffuse.sh_bands < 3) out.push_back("SH band 2 (2 bands instead of 3)");
    if (!plan.dfg.enabled) out.push_back("DFG table");
    else {
        if (plan.dfg.size < full.dfg.size)
            out.push_back("DFG " + std::to_string(plan.dfg.size) + "^2 instead of " + std::to_string(full.dfg.size) + "^2");
        if (plan.dfg.channels < full.dfg.channels) out.push_back("DFG multiscatter channel");
    }
    return out;
}

} // namespace ibl

#endif // IBL_DETAIL_CXX20
