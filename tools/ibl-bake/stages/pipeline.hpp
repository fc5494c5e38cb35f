#pragma once
// tools/ibl-bake/stages/pipeline.hpp — the one bake pipeline of ibl-bake.
//
// A bake is a plan and a fixed sequence of stages. The plan (ibl::bake_plan) says which products
// exist and at what cost: the full bake is ibl::full_bake_plan with the tool's quality settings
// (every product); `--scene` is ibl::make_bake_plan of the scene (fewer levels, a smaller DFG
// table, SH of fewer bands, an irradiance map or no diffuse product). Each stage (stage.hpp)
// decides from the plan whether it runs, computes and checks its product, and returns its rows,
// notes, files and report section. The pipeline (pipeline.cpp) runs the stages in order, writes
// every file into one staging folder (output_stage.hpp: all or nothing), assembles report.json
// and prints the table. A new product is one new stage (stages.hpp) added to the sequence.

#include <cstdio>

#include "options/bake_options.hpp"

namespace ibl_bake {

/// Runs a bake (full, or the scene's plan with --scene); prints the report on `out`, progress on
/// stderr. Throws on any failure (image_error for inputs, scene_error for scene files,
/// std::runtime_error for outputs), leaving the output directory as it was.
void run_bake(const bake_options& options, std::FILE* out);

} // namespace ibl_bake
