#pragma once
// tools/ibl-bake/stages/probe_bake.hpp — `ibl-bake --probes probes.json --out DIR`: bakes a set of
// local reflection probes (io/probes_reader.hpp) into DIR, all or nothing (output_stage.hpp):
//
//   probes.ktx2   a KTX2 cubemap ARRAY (layerCount = number of probes, faceCount 6; each level
//                 holds for each layer its six faces: ktx2.hpp, encode_ktx2_cubemap_array) in
//                 --ktx2-format: layer i is probe i's prefiltered GGX chain, baked as the default
//                 full bake bakes specular.ktx2 (--size, --levels, --quality, --threads, --policy,
//                 --ld-weight, --prefilter, --mirror; the textbook lookup at lod(r))
//   probes.json   what a shader reads: the chain's levels, their roughness and the mapping, the
//                 conventions, and per probe its layer, position, proxy, influence, fade,
//                 priority and SH3 (radiance and irradiance E coefficients of ibl/sh/basis.hpp's
//                 real basis, raw: no window)
//   report.json   per probe: its input and size, bake and check times, each level against its
//                 reference (the full bake's specular check with --checks fast's grid and samples:
//                 rel_rmse, nrmse, max_overshoot, max_rel) and the storage's rounding
//                 (ktx2_quantisation); "format" is probe_report_format
// and a short report on stdout. --lookup DIR answers `local` and `local_irradiance` queries on
// such a folder (query/probe_lookup.hpp).

#include <cstdio>

#include "options/bake_options.hpp"

namespace ibl_bake {

/// report.json's "format" in a probe-set folder (what tells --lookup a probe set from a single bake).
inline constexpr const char* probe_report_format = "ibl-bake probe-set report";

/// Throws probes_error (a bad probe-set file), image_error (an unreadable input) or
/// std::runtime_error (the output); DIR is then left as it was.
void run_probe_bake(const bake_options& opt, std::FILE* out);

} // namespace ibl_bake
