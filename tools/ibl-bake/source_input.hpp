#pragma once
// tools/ibl-bake/source_input.hpp — reading --input into a source environment.
//
//   a path containing {face}       six face files (px nx py ny pz nz), each square, equal sizes
//   a .ktx2 file                   level 0 of a KTX2 cubemap (any of the formats ibl-bake writes)
//   any other .hdr / .exr image    by its aspect ratio (--input-layout overrides): 2:1 lat-long,
//                                  4:3 horizontal cross, 3:4 vertical cross, 6:1 / 1:6 strips
// Faces are in the library's GL orientation (cube_layout.hpp has the cross diagrams). A cube input
// becomes an ibl::cubemap<float> with its full mip chain, which the source stage bakes to the
// plan's face size like any other environment (a copy when the sizes agree).

#include "pipeline.hpp"

namespace ibl_bake {

/// Reads opt.input per the rules above into src (name, kind, image or cube, read report).
/// Throws image_error naming the file.
void read_source(const bake_options& opt, source_env& src);

/// Mirrors the environment x -> -x (--mirror): the sky's sun, a lat-long's columns (u -> 1.5 - u),
/// a cube input's texels (texel centres map onto texel centres). Exact: no resampling.
void mirror_source(source_env& src);

} // namespace ibl_bake
