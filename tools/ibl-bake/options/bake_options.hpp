#pragma once
// tools/ibl-bake/options/bake_options.hpp — the command line of ibl-bake and the quality presets.
//
// Every option is checked before anything is computed or written: a bad option throws
// usage_error (main prints "ibl-bake: <message>" and the hint to --help, exit status 2).
//
//   --input PATH        Radiance .hdr, OpenEXR or KTX2 cubemap: a lat-long (2:1), a horizontal (4:3) or
//                       vertical (3:4) cross, or six face files (a path containing {face}); omitted:
//                       the built-in sky + sun
//   --input-layout L    auto (from the aspect ratio) | latlong | hcross | vcross | faces | ktx2
//   --part NAME         the part of a multi-part EXR to read (default: the first with R, G, B)
//   --max-input-pixels N  inputs with more pixels are refused before decoding (default 2^27)
//   --layout L[,L...]   files per specular level: faces (default), latlong, cross, octahedral
//   --out DIR           output directory (required)
//   --size N            face size of the prefiltered base level, 1..4096 (default 256)
//   --lut-size N        DFG LUT texels per side, 1..1024 (default 128)
//   --levels N          prefiltered levels, 0 = automatic (default): floor(log2 N) - 1 clamped
//                       to [2, 6] (smallest face >= 4 for N >= 16), at most the full chain
//   --threads N         worker threads, 0 = all cores (default 0), at most 256
//   --quality Q         low | default | high (the mapping is quality_settings below)
//   --ktx2-format F     rgba16f = f16 (default, VK_FORMAT_R16G16B16A16_SFLOAT) | rgba32f = f32 |
//                       b10g11r11 (VK_FORMAT_B10G11R11_UFLOAT_PACK32) | e5b9g9r9 (..._E5B9G9R9_UFLOAT_PACK32) |
//                       bc6h (VK_FORMAT_BC6H_UFLOAT_BLOCK) | astc4x4 / astc6x6 (..._ASTC_4x4/6x6_SFLOAT_BLOCK);
//                       every preset writes rgba16f unless this option says otherwise
//   --ktx2-quality Q    fast | normal (default) | exhaustive: the block formats' encoder effort
//   --ktx2-zstd N       0 (default: none) | 1..22: Zstandard supercompression level of the KTX2 files
//   --quiet             no progress output on stderr
//   --sh-bands B        SH bands 2..5 (default: 3; a scene plan's 2 or 3)
//   --sh-window W       auto (default) | none | a Hanning width > 0 (applies to irradiance / shader)
//   --irradiance-size N irradiance map face 1..256 (default 32), 0 = no map (full bake)
//   --extract-sun S     off (default: the products hold the whole environment) | auto (extract a
//                       compact dominant source as a disk light, lights.json) | on
//   --preset P          default (the textbook products) | accurate | filament | gltf: a set of
//                       conventions (docs/ibl-bake.md); options after it override what it sets
//   --policy P          linear (default) | filament (--preset accurate, filament): the roughness <-> lod mapping of the chain
//   --mirror            mirror the environment (x -> -x), as Filament's cmgen does by default
//   --sheen             also the sheen products (Charlie chain sheen_*.exr / sheen.ktx2, sheen_lut.exr)
//   --dfg-layout L      uniform (default: texel centres in (n.v, r)) | remapped (cbrt(n.v) x sqrt(r),
//                       edge-aligned)
//   --specular-lookup S textbook (default: textureLod at lod(r)) | accurate (log-geometric two-level blend)
//   --prefilter M       fis (default: filtered importance sampling, 512 * 2^(l-1) samples) | fast (the
//                       fast filter, bake/prefilter_fast.hpp: 32 * 2^(l-1) samples; --quality scales both)
//   --ld-weight W       nl (default: Karis's D n.l) | g1 (D G1, the lobe at n.v = 1): the chain's weight
//   --runtime M         split-sum (default: LD(R, r) DFG) | lobe (the lobe LUT, lobe_lut.exr) | taps2
//                       (the fitted two-tap model, lobe_taps_a.exr, lobe_taps_b.exr)
//   --lookup DIR        answer queries on stdin about the bake in DIR (lookup.hpp); no --out
//   --scene PATH        bake only what the scene needs (docs/scene-format.md)
//   --probes PATH       bake the local reflection probes of PATH into DIR (probes.ktx2, probes.json)
//   --compare-full      with --scene: also bake and time the full products, measure the error
//   --strict            with --scene: a missed error target is an error (exit 1, DIR untouched)
//   --checks C          fast (default: cheaper references, checks <= 1/4 of the run) | full | none
//   --verbose           the wide report table (every column and sub-row) instead of the compact one
//   --help, --version
// Values may be given as "--size 32" or "--size=32". Numbers must be plain decimal integers.

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include <ibl/bake/dfg.hpp>
#include <ibl/runtime/dfg_layout.hpp>
#include <ibl/runtime/ld_weight.hpp>
#include <ibl/runtime/lookup.hpp>
#include <ibl/runtime/roughness_mip.hpp>

#include "io/ktx2.hpp" // ktx2_format's block_quality

namespace ibl_bake {

class usage_error : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

enum class quality { low, standard, high };

// The option values, parsed once by parse_options: what a stage tests is one of these, never the
// text of the command line. Where the library has the type (ibl::ld_weight, ibl::dfg_lut_layout,
// ibl::roughness_mip_policy, ibl::specular_lookup_desc) the option holds it. to_string gives the
// one name each value has on the command line, in report.json and in the files' metadata (it
// names an enum's values by their order of declaration).

/// --preset: a set of conventions (docs/ibl-bake.md, "Presets"); `standard` is named "default".
enum class bake_preset { standard, accurate, filament, gltf };
/// --checks: the reference checks (check_settings_for).
enum class check_mode { fast, full, none };
/// --extract-sun: a compact dominant source taken out as a disk light (automatic: when it is compact).
enum class sun_extraction { off, automatic, on };
/// The DFG table's channels: (A, B, k), or Filament's (B, A + B, k) for mix(x, y, f0).
enum class dfg_channel_order { ab, filament };
/// --runtime: the runtime model the products are for.
enum class runtime_choice { split_sum, lobe, taps2 };
/// --layout: the files of each specular level.
enum class level_layout { faces, latlong, cross, octahedral };
/// --input-layout: how --input is read (automatic: from its name and aspect ratio).
enum class input_form { automatic, latlong, hcross, vcross, hstrip, vstrip, faces, ktx2 };
/// --prefilter: the specular chain's filter (fis: filtered importance sampling; fast: the fast filter).
enum class prefilter_choice { fis, fast };
/// --ktx2-format: the storage of the KTX2 files (ktx2.hpp's ktx2_format of the same names).
enum class ktx2_storage { rgba16f, rgba32f, b10g11r11, e5b9g9r9, bc6h, astc4x4, astc6x6 };

/// --sh-window: automatic (a Hanning window when the SH go negative), none, or a Hanning width.
struct sh_window_choice {
    enum class kind { automatic, none, hanning };
    kind k = kind::automatic;
    double width = 0.0; ///< kind::hanning: the width
    std::string text;   ///< kind::hanning: the width as given (report.json repeats it)
};

const char* to_string(quality q) noexcept;
const char* to_string(bake_preset p) noexcept;
const char* to_string(check_mode c) noexcept;
const char* to_string(sun_extraction s) noexcept;
const char* to_string(dfg_channel_order c) noexcept;
const char* to_string(runtime_choice r) noexcept;
const char* to_string(level_layout l) noexcept;
const char* to_string(input_form f) noexcept;
const char* to_string(ktx2_storage f) noexcept;
const char* to_string(block_quality q) noexcept;
const char* to_string(prefilter_choice p) noexcept;
std::string to_string(const sh_window_choice& w);
/// "g1" | "nl"
const char* to_string(ibl::ld_weight w) noexcept;
/// "linear" | "filament"
const char* to_string(ibl::roughness_mip_policy p) noexcept;

/// The LD weight of a name to_string gives (files read back by --lookup); nl for any other.
ibl::ld_weight ld_weight_from(const std::string& name) noexcept;

struct bake_options {
    std::string input;   ///< empty: the built-in sky
    std::string out;
    int size = 256;
    int lut_size = 128;
    int levels = 0;      ///< 0: automatic
    unsigned threads = 0;
    quality q = quality::standard;
    ktx2_storage ktx2_format = ktx2_storage::rgba16f;
    block_quality ktx2_quality = block_quality::normal; ///< --ktx2-quality
    int ktx2_zstd = 0;                                  ///< --ktx2-zstd: 0 none, else the Zstandard level
    std::string part;            ///< --part: EXR part name (empty: the first with R, G, B)
    input_form input_layout = input_form::automatic;
    std::vector<level_layout> layouts{level_layout::faces}; ///< per-level files
    std::uint64_t max_input_pixels = std::uint64_t(1) << 27; ///< 16384 x 8192
    bool quiet = false;
    bool help = false;
    bool version = false;
    int sh_bands = 0;                          ///< --sh-bands 2..5; 0: the plan's (3 in the full bake)
    sh_window_choice sh_window;                ///< --sh-window (applies to irradiance / shader)
    int irradiance_size = 32;                  ///< --irradiance-size: face of the irradiance map (0: none)
    sun_extraction extract_sun = sun_extraction::off;
    bool sheen = false;                        ///< --sheen: the Charlie sheen chain and LUT
    bake_preset preset = bake_preset::standard; ///< --preset (sets the fields below)
    ibl::roughness_mip_policy policy = ibl::roughness_mip_policy::linear(); ///< roughness <-> lod of the chain
    dfg_channel_order dfg_channels = dfg_channel_order::ab;
    bool mirror = false;                       ///< the environment mirrored x -> -x (cmgen's default)
    ibl::dfg_lut_layout dfg_layout = ibl::dfg_lut_layout::uniform(); ///< uniform (textbook) | remapped
    /// textbook (textureLod at lod(r)) | accurate (log-geometric); its mapping is the plan's policy's
    ibl::specular_lookup_desc specular_lookup = ibl::specular_lookup_desc::textbook();
    ibl::ld_weight ld_weight = ibl::ld_weight::n_dot_l; ///< the chain's LD weight: nl (Karis) | g1
    prefilter_choice prefilter = prefilter_choice::fis; ///< --prefilter: the chain's filter
    std::uint32_t fast_peaks = 1024; ///< --fast-peaks: the fast filter's peak split (0 = off)
    int fast_sh_bands = 24; ///< --fast-sh-bands: the fast filter's rough levels by spherical harmonics, at most N bands (0 = off)
    bool fast_mid_tail = true; ///< --fast-mid-tail: the fast filter's intermediate coarse tail (ibl::prefilter_options::mid_tail)
    runtime_choice runtime = runtime_choice::split_sum;
    std::string lookup;        ///< --lookup DIR: query mode (lookup.hpp)
    std::string probes;        ///< --probes: bake this probe set (io/probes_reader.hpp, stages/probe_bake.hpp)
    std::string scene;         ///< --scene: plan from this scene file (scene_reader.hpp, stage_plan.cpp)
    bool compare_full = false; ///< --compare-full (with --scene)
    bool strict = false;       ///< --strict (with --scene): a missed error target fails the bake
    check_mode checks = check_mode::fast; ///< the reference checks (check_settings_for)
    bool verbose = false;      ///< --verbose: the wide report table
};

/// Cost knobs of one quality preset (docs/ibl-bake.md has the table).
struct quality_settings {
    const char* name;
    int bake_k;                      ///< k x k sub-samples per source texel (lat-long / sky -> cube)
    std::uint32_t prefilter_samples; ///< GGX samples per texel and level (filtered IS)
    bool trilinear;                  ///< prefilter reads two source levels per sample
    ibl::dfg_quadrature_nodes dfg_nodes;
    std::uint32_t sky_ref_samples;   ///< reference LD of the sky without its sun per texel
    int sun_cap_nodes;               ///< reference: radial nodes over the sun cap
    int ref_grid;                    ///< specular check: ref_grid^2 texels per face and level
    std::uint32_t split_sum_samples; ///< MIS reference of outgoing radiance per view
    int preview_ss;                  ///< preview: preview_ss^2 sub-pixel samples
};

quality_settings settings_for(quality q);

/// The quality's settings with the check knobs of a --checks mode: full keeps them; fast takes a
/// coarser texel grid (ref_grid - 3, at least 3), a quarter of the sky's reference samples and an
/// eighth of the split-sum reference's (docs/ibl-bake.md "Checks"); none keeps them (no check runs).
quality_settings check_settings_for(quality_settings q, check_mode checks);

/// Parses argv[1..argc). Throws usage_error.
bake_options parse_options(const std::vector<std::string>& args);

/// Automatic level count for a base face size (see --levels).
int auto_levels(int size);

std::string usage_text();

} // namespace ibl_bake
