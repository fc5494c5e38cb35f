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
//                       b10g11r11 (VK_FORMAT_B10G11R11_UFLOAT_PACK32) | e5b9g9r9 (..._E5B9G9R9_UFLOAT_PACK32)
//   --quiet             no progress output on stderr
//   --sh-bands B        SH bands 2..5 (default: 3; a scene plan's 2 or 3)
//   --sh-window W       auto (default) | none | a Hanning width > 0 (applies to irradiance / shader)
//   --irradiance-size N irradiance map face 1..256 (default 32), 0 = no map (full bake)
//   --extract-sun S     off (default: the products hold the whole environment) | auto (extract a
//                       compact dominant source as a disk light, lights.json) | on
//   --preset P          default (the textbook products) | accurate | filament | gltf: a set of
//                       conventions (docs/ibl-bake.md); options after it override what it sets
//   --policy P          linear (default) | filament: the roughness <-> lod mapping of the chain
//   --mirror            mirror the environment (x -> -x), as Filament's cmgen does by default
//   --sheen             also the sheen products (Charlie chain sheen_*.exr / sheen.ktx2, sheen_lut.exr)
//   --dfg-layout L      uniform (default: texel centres in (n.v, r)) | remapped (cbrt(n.v) x sqrt(r),
//                       edge-aligned)
//   --specular-lookup S textbook (default: textureLod at lod(r)) | accurate (log-geometric two-level blend)
//   --ld-weight W       nl (default: Karis's D n.l) | g1 (D G1, the lobe at n.v = 1): the chain's weight
//   --runtime M         split-sum (default: LD(R, r) DFG) | lobe (the lobe LUT, lobe_lut.exr) | taps2
//                       (the fitted two-tap model, lobe_taps_a.exr, lobe_taps_b.exr)
//   --lookup DIR        answer queries on stdin about the bake in DIR (lookup.hpp); no --out
//   --scene PATH        bake only what the scene needs (docs/scene-format.md)
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

namespace ibl_bake {

class usage_error : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

enum class quality { low, standard, high };

struct bake_options {
    std::string input;   ///< empty: the built-in sky
    std::string out;
    int size = 256;
    int lut_size = 128;
    int levels = 0;      ///< 0: automatic
    unsigned threads = 0;
    quality q = quality::standard;
    bool ktx2_f32 = false;       ///< ktx2_format == "rgba32f"
    std::string ktx2_format = "rgba16f"; ///< rgba16f | rgba32f | b10g11r11 | e5b9g9r9
    std::string part;            ///< --part: EXR part name (empty: the first with R, G, B)
    std::string input_layout = "auto"; ///< auto | latlong | hcross | vcross | faces | ktx2
    std::vector<std::string> layouts{"faces"}; ///< per-level files: faces, latlong, cross, octahedral
    std::uint64_t max_input_pixels = std::uint64_t(1) << 27; ///< 16384 x 8192
    bool quiet = false;
    bool help = false;
    bool version = false;
    int sh_bands = 0;                          ///< --sh-bands 2..5; 0: the plan's (3 in the full bake)
    std::string sh_window = "auto";            ///< auto | none | a Hanning width W > 0
    int irradiance_size = 32;                  ///< --irradiance-size: face of the irradiance map (0: none)
    std::string extract_sun = "off";           ///< auto (a compact dominant source as a disk light) | on | off
    bool sheen = false;                        ///< --sheen: the Charlie sheen chain and LUT
    std::string preset = "default";            ///< default (textbook) | accurate | filament | gltf (sets the fields below)
    std::string policy = "linear";             ///< roughness <-> lod: linear | filament (lod = r (2 - r) ...)
    std::string dfg_channels = "ab";           ///< ab: (A, B, k) | filament: (B, A + B, k) for mix(x, y, f0)
    bool mirror = false;                       ///< the environment mirrored x -> -x (cmgen's default)
    std::string dfg_layout = "uniform";        ///< uniform (ibl::dfg_lut_layout::uniform(), textbook) | remapped
    std::string specular_lookup = "textbook";  ///< textbook (textureLod at lod(r)) | accurate (log-geometric)
    std::string ld_weight = "nl";              ///< the chain's LD weight: nl (Karis) | g1 (ibl::ld_weight)
    std::string runtime = "split-sum";         ///< the runtime model: split-sum | lobe (lobe LUT) | taps2 (two-tap table)
    std::string lookup;        ///< --lookup DIR: query mode (lookup.hpp)
    std::string scene;         ///< --scene: plan from this scene file (scene_reader.hpp, stage_plan.cpp)
    bool compare_full = false; ///< --compare-full (with --scene)
    bool strict = false;       ///< --strict (with --scene): a missed error target fails the bake
    std::string checks = "fast"; ///< the reference checks: fast | full | none (check_settings_for)
    bool verbose = false;      ///< --verbose: the wide report table
};

/// Cost knobs of one quality preset (docs/ibl-bake.md has the table).
struct quality_settings {
    const char* name;
    int bake_k;                      ///< k x k sub-samples per source texel (lat-long / sky -> cube)
    std::uint32_t prefilter_samples; ///< GGX samples per texel and level (filtered IS)
    bool trilinear;                  ///< prefilter reads two source levels per sample
    ibl::dfg_quadrature_nodes dfg_nodes;
    std::uint32_t ld_ref_samples;    ///< reference LD (lat-long sources) per texel
    std::uint32_t sky_ref_samples;   ///< reference LD of the sky without its sun per texel
    int sun_cap_nodes;               ///< reference: radial nodes over the sun cap
    int ref_grid;                    ///< specular check: ref_grid^2 texels per face and level
    std::uint32_t split_sum_samples; ///< MIS reference of outgoing radiance per view
    int preview_ss;                  ///< preview: preview_ss^2 sub-pixel samples
};

quality_settings settings_for(quality q);

/// The quality's settings with the check knobs of a --checks mode: full keeps them; fast takes a
/// coarser texel grid (ref_grid - 3, at least 3), a quarter of the reference samples and an
/// eighth of the split-sum reference's (docs/ibl-bake.md "Checks"); none keeps them (no check runs).
quality_settings check_settings_for(quality_settings q, const std::string& checks);

/// Parses argv[1..argc). Throws usage_error.
bake_options parse_options(const std::vector<std::string>& args);

/// Automatic level count for a base face size (see --levels).
int auto_levels(int size);

std::string usage_text();

} // namespace ibl_bake
