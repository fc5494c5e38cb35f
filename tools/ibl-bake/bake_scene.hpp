#pragma once
// tools/ibl-bake/bake_scene.hpp — `ibl-bake --scene scene.json` (issue 7): parse a scene
// description (docs/scene-format.md), plan its products with ibl::make_bake_plan
// (include/ibl/plan.hpp) and bake exactly the plan; the report says what was left out and the
// time saved (estimated from the plan's cost model; measured with --compare-full, which also
// bakes the full products and a converged set and measures the products' shading error).

#include <cstdio>
#include <stdexcept>
#include <string>

#include <ibl/plan.hpp>

#include "bake_options.hpp"

namespace ibl_bake {

/// A malformed or invalid scene file; what() names the file, the line and column (JSON syntax)
/// or the key (content).
class scene_error : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// Parses the scene JSON text (docs/scene-format.md). Throws scene_error. `source` names the
/// text in messages.
ibl::scene_description parse_scene(const std::string& text, const std::string& source = "scene");

/// Reads and parses a scene file. Throws scene_error.
ibl::scene_description read_scene(const std::string& path);

/// Plans and bakes options.scene into options.out (all-or-nothing, as run_bake); prints the
/// report on `out`. Throws scene_error, image_error or std::runtime_error.
void run_scene_bake(const bake_options& options, std::FILE* out);

} // namespace ibl_bake
