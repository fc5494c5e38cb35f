#pragma once
// tools/ibl-bake/stages/stages.hpp — the stages of the bake, in the order the pipeline runs them, and
// what several of them share (stage.hpp describes the stage interface).
//
//   plan          the full plan, or the scene's plan (--scene) and what it leaves out
//   source        read the input (or the built-in sky); k x k supersampled bake to the source cube
//   sun           a compact dominant source taken out as a disk light (lights.json)
//   specular      the plan's levels of the GGX-prefiltered chain (filtered importance sampling)
//   sh            SH projection of the source cube (the plan's bands), window, irradiance
//   irradiance    irradiance cubemap (when the plan chooses a map over SH)
//   sheen         (--sheen) the Charlie sheen chain and the sheen albedo LUT
//   dfg           the split-sum DFG table by exact quadrature
//   lobe_lut      (--runtime lobe) the lobe LUT (A, B, s, r_eff) in the DFG table's layout
//   lobe_taps     (--runtime taps2) the fitted two-tap table (A, B, 2 x (angle, roughness,
//                 weight)) in the DFG table's layout
//   lookup        check: the chain where a renderer samples it (between levels), vs exact LD
//   split_sum     check: the baked products through the runtime model (and the plain split
//                 sum) against the full integral
//   preview       check: a sphere grid rendered from the baked products
//   target_check  check (--scene): the scene's error targets measured on the products, met or missed
//   compare_full  check (--scene --compare-full): full and converged bakes, the plan's error

#include <array>
#include <chrono>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <ibl/brdf/model.hpp>
#include <ibl/runtime/ld_weight.hpp>
#include <ibl/runtime/roughness_mip.hpp>
#include <ibl/runtime/lookup.hpp>
#include <ibl/runtime/shade.hpp>

#include "io/ktx2.hpp"
#include "stages/stage.hpp"

namespace ibl_bake {

std::unique_ptr<stage> make_plan_stage();
std::unique_ptr<stage> make_source_stage();
std::unique_ptr<stage> make_sun_stage();
std::unique_ptr<stage> make_specular_stage();
std::unique_ptr<stage> make_sh_stage();
std::unique_ptr<stage> make_irradiance_stage();
std::unique_ptr<stage> make_dfg_stage();
std::unique_ptr<stage> make_lobe_lut_stage();
std::unique_ptr<stage> make_lobe_taps_stage();
std::unique_ptr<stage> make_sheen_stage();
std::unique_ptr<stage> make_lookup_stage();
std::unique_ptr<stage> make_split_sum_stage();
std::unique_ptr<stage> make_preview_stage();
std::unique_ptr<stage> make_compression_stage();
std::unique_ptr<stage> make_target_check_stage();
std::unique_ptr<stage> make_compare_full_stage();

/// The BRDF model of every product and check.
using bake_model = ibl::ggx_height_correlated;

/// The package version (include/ibl/core/config.hpp), e.g. "0.1.0".
inline std::string version_string() { return IBL_VERSION_STRING; }

inline constexpr const char* face_names[6] = {"px", "nx", "py", "ny", "pz", "nz"};

/// Milliseconds since t0.
inline double ms_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

/// The products as a renderer samples them (ibl/runtime/lookup.hpp): the chain by the lookup `specular`
/// (its taps over the virtual chain, minus the first stored level, clamped to the stored levels),
/// the DFG table by ibl::dfg_lookup in its layout (or dfg_exact when there is none), the diffuse
/// product. The runtime model is the two-tap model when `taps` is set (ibl/runtime/specular_models.hpp,
/// specular_lobe_taps: LD = sum_k w_k LD(cos(a_k) n + sin(a_k) t, r_k) / sum_k w_k, t the tangent
/// of n towards R, (A, B) and the taps from one bilinear read of the table), the lobe LUT's when
/// `lobe` is set (specular_lobe: LD at normalize(lerp(n, R, s)) and r_eff, (A, B) from the lobe
/// LUT), both tables read in the DFG table's layout, else the plain split sum (LD at R and r,
/// (A, B) from the DFG table).
struct product_view {
    const ibl::cubemap<float>* chain = nullptr;
    ibl::roughness_mip_policy policy{};
    int virtual_levels = 1, first_level = 0;
    const ibl::dfg_lut* lut = nullptr;
    const diffuse_data* diffuse = nullptr;
    ibl::specular_lookup_desc specular{};
    ibl::dfg_lut_layout dfg_layout{};
    const ibl::disk_light<double>* sun = nullptr; ///< an extracted sun, added by the shading functions
    const ibl::lobe_lut* lobe = nullptr;          ///< the lobe LUT: the runtime model is lobe when set
    /// The lobe model's B-part kernel table (f_B, r_B; ibl::make_lobe_pair_lut): with `lobe` the
    /// two-part model F0 A LD(d_A, r_A) + F90 B LD(d_B, r_B) (ibl::specular_lobe_pair); without it
    /// the one-kernel model (ibl::specular_lobe: bakes before the two-part model).
    const ibl::lobe_lut* lobe_b = nullptr;
    const ibl::lobe_taps_lut* taps = nullptr;     ///< the two-tap table: the runtime model is taps2 when set
    ibl::ld_weight weight = ibl::ld_weight::n_dot_l; ///< the chain's LD weight (of the sun's LD term)

    /// LD at reflection direction r_dir and roughness (the chain only).
    dvec3 ld(const dvec3& r_dir, double roughness) const;
    /// The products at a shading point through the runtime model (see above). The two-part lobe
    /// model's LD depends on the material's F0, F90: its sample holds the effective LD
    /// (ibl::lobe_pair_ld) whose LD (F0 A + F90 B) is the model's specular.
    ibl::ibl_sample<double> sample(const dvec3& n, const dvec3& v, double roughness, const dvec3& f0 = dvec3(1.0),
                                   const dvec3& f90 = dvec3(1.0)) const;
    /// The lobe LUT's (A, B, s, r_eff) at (n.v, r) (ibl::lobe_lut_lookup); needs `lobe`.
    ibl::vec4<double> lobe_params(double n_dot_v, double roughness) const;
    /// The B-part table's (f_B, r_B) at (n.v, r) (ibl::lobe_lut_lookup); needs `lobe_b`.
    ibl::vec2<double> lobe_b_params(double n_dot_v, double roughness) const;
    /// The two-tap table's 8 channels at (n.v, r) (one bilinear read in the DFG layout, as
    /// ibl::specular_lobe_taps reads it); needs `taps`.
    std::array<float, 8> taps_params(double n_dot_v, double roughness) const;
    /// The same view with the plain split sum as its runtime model.
    product_view split_sum() const {
        product_view p = *this;
        p.lobe = nullptr;
        p.lobe_b = nullptr;
        p.taps = nullptr;
        return p;
    }
    /// The runtime model: shader's ambient from the products plus the sun as a disk light.
    dvec3 shade(const ibl::pbr_shader<double>& shader, const dvec3& n, const dvec3& v) const;
    /// E(n) of the runtime (diffuse product plus the sun's cap irradiance), not E/pi.
    dvec3 irradiance(const dvec3& n) const;
};

/// Whether a lookup is the textbook one (textureLod at lod(r)): its level weight and blend.
inline bool textbook_lookup(const ibl::specular_lookup_desc& d) noexcept {
    constexpr ibl::specular_lookup_desc textbook = ibl::specular_lookup_desc::textbook();
    return d.weight == textbook.weight && d.interpolation == textbook.interpolation;
}

/// The runtime model of a bake: lobe or taps2 (with its table's size) or the split sum.
struct runtime_model {
    runtime_choice kind = runtime_choice::split_sum;
    int lobe_lut_size = 0; ///< texels per side of the lobe LUT or of the two-tap table
    ibl::ld_weight ld_weight = ibl::ld_weight::n_dot_l; ///< the chain's weight
};
/// What the options and the plan give: lobe (taps2) when --runtime lobe (taps2) and the plan has
/// a DFG table and a chain.
runtime_model runtime_model_of(const bake_options& o, const ibl::bake_plan& plan);
/// Texels per side of the lobe LUT and of the two-tap table: 24, at most the DFG table's
/// (docs/ibl-bake.md, "Lobe LUT").
int lobe_lut_size_for(int dfg_size);

/// Their description in report.json.
void json_lookup_conventions(json_writer& j, const ibl::specular_lookup_desc& s, const ibl::dfg_lut_layout& d,
                             const runtime_model& rm);

/// The shading points of the scene checks (target_check, compare_full): each material class at
/// the ends and the middle of each roughness range, at 54 normals (3 x 3 texel centres per cube
/// face) each seen at 45 degrees.
struct scene_shading_material {
    std::string name;
    ibl::pbr_material<double> m;
};
struct scene_shading_point {
    dvec3 n, v;
};
ibl::pbr_material<double> scene_material(double metallic, double roughness);
std::vector<scene_shading_material> scene_shading_materials(const ibl::scene_description& scene);
std::vector<scene_shading_point> scene_shading_points();

/// The products of ctx as a renderer samples them.
product_view baked_view(const bake_context& ctx);

/// The conventions every file of a product states in its metadata (EXR string attributes, KTX2
/// key/values; the JSON files carry the same under "conventions"): ibl.preset, ibl.product,
/// ibl.sun_extracted (whether the product holds the whole environment or the residual of an
/// extracted sun, which lights.json then holds) and ibl.conventions (one sentence on how a
/// renderer reads the file), then the product's own keys (docs/ibl-bake.md, "Conventions in the
/// files").
std::vector<std::pair<std::string, std::string>> product_conventions(const bake_context& ctx, const std::string& product,
                                                                     const std::string& how_to_read);

/// The conventions of a (n.v, r) table's file: product_conventions, then ibl.dfg_layout
/// (ibl::dfg_lut_layout::name()) and ibl.dfg_lookup (how a shader computes the sampler
/// coordinates), then `extra`.
std::vector<std::pair<std::string, std::string>> table_conventions(const bake_context& ctx, const std::string& product,
                                                                   const std::string& how_to_read, const ibl::dfg_lut_layout& layout,
                                                                   const std::vector<std::pair<std::string, std::string>>& extra = {});

/// Direction of the brightest texel of a cube level (luminance; first one on ties).
dvec3 brightest_direction(const ibl::cubemap<float>& cube, int level);

/// Sub-samples per axis of the level-0 reference texel mean of the chain checks.
inline constexpr int level0_ref_k = 16;
/// The references a chain level is checked against at `texels` (face, x, y) of its n x n faces:
/// level 0 (mirror = true) the level0_ref_k^2 sub-sampled texel mean of the source; rougher
/// levels ibl::reference_ld_sky (analytic sky: GGX IS of the sky, quadrature of the sun's cap)
/// or, for maps and cubes, ibl::ld_texel_sum over `cube` (the source cube the chain is filtered
/// from, before any sun extraction) at ibl::ld_texel_sum_level: the exact LD of that cube, no
/// sampling noise, and no Hammersley points shared with filtered importance sampling (reference_ld
/// at a level's own sample count draws that level's directions). The chain's LD
/// weight throughout. One definition for the bake's check and the probe set's.
std::vector<dvec3> chain_check_references(const source_env& src, const ibl::cubemap<float>& cube,
                                          const std::vector<std::array<int, 3>>& texels, int n,
                                          bool mirror, double roughness, const quality_settings& qs, ibl::ld_weight w,
                                          pool_executor& ex);

/// The sun's LD at direction d and roughness r for a chain of weight w (its exact term, host
/// quadrature); 0 without one.
dvec3 sun_ld(const ibl::disk_light<double>* sun, const dvec3& d, double roughness, ibl::ld_weight w);

/// An extracted sun's term of the Charlie (sheen) LD at R and sheen roughness r: the disk's
/// radiance x solid angle x D(h_c) (n.l_c) at its centre, over the lobe's normaliser
/// W(r) = 2 pi int_0^{pi/2} D(cos(theta / 2)) cos(theta) sin(theta) d theta (2048-node midpoint).
/// The centre-point rule is exact to ~(disk radius / lobe width)^2: 1e-3 for a 1-degree sun at
/// r >= 0.25. 0 without a sun.
dvec3 sheen_sun_ld(const ibl::disk_light<double>* sun, const dvec3& R, double roughness);

/// The first level of `cube` whose face is <= max_face (the last level if none is):
/// ibl::irradiance_texel_sum_level.
int level_at_most(const ibl::cubemap<float>& cube, int max_face);

/// Irradiance E(n) at each normal by summing every texel of `level` (cosine-weighted, exact texel
/// solid angles): ibl::irradiance_texel_sum.
std::vector<dvec3> texel_sum_irradiance(const ibl::cubemap<float>& cube, int level, const std::vector<dvec3>& normals,
                                        pool_executor& ex);

/// The source cube of face n (full mip chain): the built-in sky, a lat-long or a cube input by k x k
/// supersampling (ibl::bake_cubemap). k = base_k, raised so that every input texel reaches the
/// cube: k >= W / (4 n) for a lat-long of width W (a face spans 90 degrees), k >= m / n for a cube
/// of face m; at most 32. A cube input of face n is used as it is (a copy). *k_used: the k taken.
ibl::cubemap<float> bake_source(const source_env& src, int n, int base_k, pool_executor& ex, int* k_used = nullptr);

/// Bakes virtual levels [first, first + count) of the plan's chain (sizes base >> v) with the
/// plan's samples and read mode per level: GGX filtered importance sampling, N = V = R.
/// The fast filter's samples per level are the plan's (filtered importance sampling's) / 8, at
/// least 8, times 2^(l - 1) at chain level l >= 1, at most ibl::prefilter_max_scheduled_samples:
/// 64 * 4^(l - 1) at the default quality (ibl::fast_default_samples, the library's equal-cost
/// schedule, ibl::equal_cost_prefilter_samples), read from the nearest level (the library's
/// default plan for the fast filter).
inline constexpr std::uint32_t fast_samples_divisor = 8;
/// The samples chain level `level` is filtered with: the plan's (fis_samples) for fis, the fast
/// filter's for fast.
std::uint32_t chain_samples(std::uint32_t fis_samples, prefilter_choice method, int level);
/// The plan's chain filtered by `method` (ibl::prefilter with a level plan).
/// fast_peaks: the fast filter's peak split (ibl::peak_split_options::max_peaks; 0 = off);
/// fast_sh_bands: its rough levels by spherical harmonics (ibl::sh_rough_options::max_bands; 0 = off).
ibl::cubemap<float> bake_chain(const ibl::cubemap<float>& src, const ibl::specular_plan& sp, ibl::ld_weight w, pool_executor& ex,
                               prefilter_choice method = prefilter_choice::fis, std::uint32_t fast_peaks = 1024, int fast_sh_bands = 24,
                               bool fast_mid_tail = true);
/// The prefilter options bake_chain filters with.
ibl::prefilter_options chain_options(const ibl::specular_plan& sp, ibl::ld_weight w, prefilter_choice method, std::uint32_t fast_peaks,
                                     int fast_sh_bands, bool fast_mid_tail = true);

/// The raw 3-band SH projection of a cube's level 0 as a diffuse product.
diffuse_data sh3_diffuse(const ibl::cubemap<float>& src, pool_executor& ex);

/// Files: one face of a cube level as an RGB image; text (cube_layout.hpp converts cubes for the KTX2 writer).
image_rgb32f face_image(const ibl::cubemap<float>& cube, int face, int level);
void write_text(const std::string& path, const std::string& text);

/// The KTX2 format of a --ktx2-format (the same names).
ktx2_format ktx2_format_of(ktx2_storage storage);
/// How the KTX2 files are encoded: --ktx2-quality, --ktx2-zstd and --threads.
ktx2_encoding ktx2_encoding_of(const bake_options& o);

/// Writes the quantisation of a cube stored as `format` (per level: max and RMS relative error of
/// the decoded values, values above the format's range and negatives clamped) as a JSON object.
void json_quantisation(json_writer& j, const std::vector<ktx2_quantisation_level>& q, ktx2_storage format);

/// A square table of `channels` floats per texel as a C header (the layout of dfg.hpp:
/// name_size, name_channels, name[] row by row, row 0 = the smallest roughness; exact floats):
/// `what` names the table, `channel_list` its channels, `layout` the texel rule.
std::string c_table_header(const std::string& name, const std::string& what, std::uint32_t size, std::uint32_t channels,
                           const std::string& channel_list, const std::string& layout, const std::vector<float>& data);

/// The (n.v, r) where the fitted tables' checks compare a bilinear read with a direct fit: the
/// midpoints of every second cell per axis of a size^2 table in `layout`, those with r >= 0.05
/// and n.v >= 1e-3 (as the fit's own statistics: no lobe at n.v = 0, near-mirror rows below).
std::vector<std::array<double, 2>> fit_check_midpoints(std::uint32_t size, const ibl::dfg_lut_layout& layout);

/// Max |A - A_dfg|, |B - B_dfg| of a table in a DFG layout whose channels 0, 1 are (A, B), against
/// the DFG table read by ibl::dfg_lookup at the table's texels.
double ab_vs_dfg(const std::vector<float>& data, std::uint32_t size, std::uint32_t channels, const ibl::dfg_lut_layout& layout,
                 const ibl::dfg_lut& dfg);

/// Writes an array of RGB triples (the first `count` coefficients).
void json_triples(json_writer& j, const sh5& c, int count);

} // namespace ibl_bake
