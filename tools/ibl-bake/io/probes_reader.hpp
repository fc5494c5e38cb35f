#pragma once
// tools/ibl-bake/io/probes_reader.hpp — probe-set files for `ibl-bake --probes probes.json`
// (docs/ibl-bake.md, "Probe sets (--probes)"): JSON text -> a list of local reflection probes,
// with messages that name the file, the probe index and the key.
//
//   {"probes": [{"input": "a.exr",                       capture (any --input form), relative
//                                                        paths against the JSON file's folder
//                "position": [x, y, z],                  capture point C
//                "proxy": {"box": {"min": [..], "max": [..]}}   axis-aligned, or
//                         {"box": {"center": [..], "half_extents": [..], "axes": [[..], [..], [..]]}}
//                                                        oriented (axes optional: the world's), or
//                         {"sphere": {"center": [..], "radius": r}}
//                "influence": {"box": ... | "sphere": ..., "fade": f},   fade width f > 0
//                "priority": 0},                         optional integer (default 0), higher first
//               ...]}
// Rules: 1..probe_set_max probes; every number finite; box min <= max per axis; one box form
// (min/max or center/half_extents/axes); half_extents >= 0; axes three unit vectors (length within
// 1e-3 of 1), pairwise perpendicular (|dot| <= 1e-3), stored orthonormalised (Gram-Schmidt in
// their order); radius > 0; fade > 0; unknown keys are errors ("$comment" and "description" strings are allowed at every
// level). Any text gives a probe set or throws probes_error (never anything else).

#include <array>
#include <cstddef>
#include <stdexcept>
#include <string>
#include <vector>

namespace ibl_bake {

/// A malformed or invalid probe-set file; what() names the file and, for content, the probe and key.
class probes_error : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

inline constexpr std::size_t probe_set_max = 64;

/// A box (axis-aligned: min, max; or oriented: center, half_extents, axes) or a sphere (center, radius).
struct probe_volume_desc {
    bool sphere = false;
    bool oriented = false;                ///< a box given as center, half_extents, axes
    std::array<double, 3> min{}, max{};   ///< axis-aligned box
    std::array<double, 3> center{};       ///< sphere; oriented box
    double radius = 0.0;                  ///< sphere
    std::array<double, 3> half_extents{}; ///< oriented box: >= 0 along each axis
    std::array<std::array<double, 3>, 3> axes{{{1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, {0.0, 0.0, 1.0}}}; ///< oriented box: orthonormal
};

struct probe_desc {
    std::string input;                    ///< resolved against the JSON file's folder
    std::array<double, 3> position{};
    probe_volume_desc proxy, influence;
    double fade = 0.0;
    int priority = 0;
};

/// Parses the text of a probe-set file. `source` names it in messages; relative inputs are
/// resolved against `base_dir` (empty: left as they are).
std::vector<probe_desc> parse_probes(const std::string& text, const std::string& source = "probes.json",
                                     const std::string& base_dir = "");

/// Reads and parses a probe-set file (inputs relative to its folder). Throws probes_error.
std::vector<probe_desc> read_probes(const std::string& path);

} // namespace ibl_bake
