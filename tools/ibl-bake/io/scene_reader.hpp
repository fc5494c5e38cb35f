#pragma once
// tools/ibl-bake/io/scene_reader.hpp — scene files for `ibl-bake --scene` (docs/scene-format.md):
// JSON text -> ibl::scene_description, with messages that name the file, the line and column
// (syntax) or the key (content).

#include <stdexcept>
#include <string>

#include <ibl/bake/plan.hpp>

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

} // namespace ibl_bake
