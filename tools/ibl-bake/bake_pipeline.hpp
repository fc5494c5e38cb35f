#pragma once
// tools/ibl-bake/bake_pipeline.hpp — the ibl-bake pipeline: source -> products -> checks ->
// files (docs/ibl-bake.md describes every product, file and report field).

#include <cstdio>

#include "bake_options.hpp"

namespace ibl_bake {

/// Runs a bake; prints the report table on `out`, progress on stderr. Throws on any failure
/// (image_error for inputs, std::runtime_error for outputs), leaving the output directory as it was.
void run_bake(const bake_options& options, std::FILE* out);

} // namespace ibl_bake
