#pragma once
// tools/ibl-bake/query/lookup.hpp — `ibl-bake --lookup DIR`: answers queries about a bake folder exactly
// as the documented runtime code does, from the files in DIR (report.json's plan.runtime,
// specular.ktx2, dfg.exr, lobe_lut.exr and lobe_lut_b.exr or lobe_taps_a.exr and lobe_taps_b.exr, sh.json or
// irradiance.ktx2).
//
// Queries on stdin, one per line, one answer line each (numbers separated by spaces; lines that
// are empty or start with # are skipped, without an answer):
//   specular X Y Z R            -> r g b   LD for reflection direction (X,Y,Z) (normalised), roughness R
//   dfg NV R                    -> A B     the DFG lookup (specular = LD (F0 A + F90 B))
//   irradiance X Y Z            -> r g b   irradiance E (not E/pi) at the normal (X,Y,Z) (normalised)
//   shade NX NY NZ VX VY VZ R M BR BG BB -> r g b   outgoing radiance of the runtime model (shade.hpp
//                                 pbr_shader ambient, multiple scattering) for normal N, view V
//                                 (towards the eye; both normalised), roughness R, metallic M,
//                                 base colour B
//   sheen X Y Z R               -> r g b   Charlie LD of the whole environment (a --sheen bake): the sheen
//                                 chain at lod = r (V - 1) plus an extracted sun's Charlie term
//   dfg_sheen NV R              -> E       the sheen albedo lookup (bilinear, texel centres)
//   lobe NV R                   -> A B s r_eff   the lobe LUT lookup (a --runtime lobe bake;
//                                 ibl::lobe_lut_lookup in the DFG layout)
//   lobe_b NV R                 -> f_B r_B       the lobe model's B-part table (lobe_lut_b.exr), the
//                                 same lookup
//   taps NV R                   -> A B a0 r0 w0 a1 r1 w1   the two-tap table's bilinear read (a
//                                 --runtime taps2 bake; in the DFG layout, as
//                                 ibl::specular_lobe_taps reads it; angles over pi/2)
// shade uses the bake's runtime model (report.json plan.runtime.runtime_model): lobe reads the
// chain at normalize(lerp(n, R, s)) and r_eff for F0 A and at the B kernel (f_B, r_B) for F90 B
// (ibl::specular_lobe_pair; a bake without runtime_model.parts = 2: one kernel, LD(normalize(
// lerp(n, R, s)), r_eff) (F0 A + F90 B)); taps2 at the two taps
// (cos(a_k) n + sin(a_k) t, r_k; their weighted mean) with the table's (A, B); split-sum at R
// and r with the DFG table's. specular and dfg answer the chain and the DFG table themselves.
// With a sun in lights.json the answers are about the whole environment: specular adds the sun's
// exact LD term (ibl::disk_light_ld), irradiance its cap irradiance, shade its disk-light shading.
// R, NV, M are clamped to [0, 1] as the runtime does. A malformed query (unknown word, wrong count,
// a non-number, a zero or non-finite direction) gets one line "error: line L: <why>: <the query>"
// in place of its answer; the exit status is then 1 (0 when every query was answered).
// Numbers are printed with 9 significant digits (they read back as the same float).
// A probe-set folder (the output of --probes) is answered by query/probe_lookup.hpp instead.

#include <iosfwd>
#include <sstream>
#include <string>
#include <vector>

#include "stages/stages.hpp"

namespace ibl_bake {

/// The products of a bake folder as a renderer holds them (the chain as the KTX2 stores it).
struct baked_folder {
    ibl::cubemap<float> chain{1};
    bool has_chain = false;
    ibl::dfg_lut lut;
    bool has_lut = false;
    diffuse_data diffuse;
    int virtual_levels = 1, first_level = 0;
    bool filament_policy = false;
    ibl::specular_lookup_desc specular{};
    ibl::dfg_lut_layout dfg_layout{};
    std::optional<ibl::disk_light<double>> sun; ///< lights.json's sun, if any
    ibl::cubemap<float> sheen{1};               ///< the Charlie chain (--sheen bakes)
    ibl::dfg_lut sheen_lut;
    bool has_sheen = false;
    ibl::lobe_lut lobe;                         ///< lobe_lut.exr (runtime model lobe)
    bool has_lobe = false;
    ibl::lobe_lut lobe_b;                       ///< lobe_lut_b.exr (f_B, r_B: the lobe model's B part)
    bool has_lobe_b = false;
    ibl::lobe_taps_lut taps;                    ///< lobe_taps_a.exr + lobe_taps_b.exr (runtime model taps2)
    bool has_taps = false;
    ibl::ld_weight weight = ibl::ld_weight::n_dot_l; ///< the chain's LD weight (plan.runtime.ld_weight)

    product_view view() const;
};

/// Loads DIR. Throws image_error / std::runtime_error naming the file.
baked_folder load_baked_folder(const std::string& dir);

/// Answers the queries of `in` on `out` (see the header). Returns the exit status (0 or 1).
int run_lookup(const baked_folder& b, std::istream& in, std::ostream& out);

/// What both query modes (a bake folder, a probe set) share, so that they read and answer alike.
namespace query_text {
/// The numbers after the query word; false if one is not a finite number.
bool numbers(std::istringstream& in, std::vector<double>& out);
/// A number as every answer prints it (9 significant digits) and an RGB / XYZ triple of them.
std::string fmt9(double x);
std::string triple(const ibl::vec3<double>& v);
/// (x, y, z) normalised; std::invalid_argument naming `what` when zero or not finite.
ibl::vec3<double> unit(double x, double y, double z, const char* what);
} // namespace query_text

} // namespace ibl_bake
