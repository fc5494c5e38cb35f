#pragma once
// tools/ibl-bake/tests/tool_test_support.hpp — what the end-to-end tests of the executable share:
// a scratch folder removed at the end, reading a whole file, running a shell command.

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "io/image_io.hpp"
#include "io/json_value.hpp"

#include <sys/wait.h>
#include <unistd.h>

namespace ibl_bake_test {

/// A fresh folder <tmp>/<tag>_<pid>, removed with everything in it when the object goes.
struct scratch {
    std::filesystem::path path;
    explicit scratch(const std::string& tag)
        : path(std::filesystem::temp_directory_path() / (tag + "_" + std::to_string(::getpid()))) {
        std::filesystem::remove_all(path);
        std::filesystem::create_directories(path);
    }
    ~scratch() {
        std::error_code ec;
        std::filesystem::remove_all(path, ec);
    }
    scratch(const scratch&) = delete;
    scratch& operator=(const scratch&) = delete;
    std::string operator/(const std::string& name) const { return (path / name).string(); }
};

/// The whole file (empty if it cannot be read).
inline std::string slurp(const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
}

/// Runs `cmd` with /bin/sh; its exit status (-1 if it did not exit normally).
inline int shell(const std::string& cmd) {
    const int st = std::system(cmd.c_str());
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

/// sh.json's raw radiance coefficients of a bake folder, as one list (coefficient-major, RGB).
inline std::vector<double> sh_radiance(const std::string& dir) {
    const ibl_examples::json_value v = ibl_examples::parse_json(slurp(dir + "/sh.json"));
    std::vector<double> out;
    for (const auto& t : v.find("radiance")->values)
        for (const auto& c : t.values) out.push_back(c.number);
    return out;
}

/// Relative RMS difference of every texel of specular level l (all six face EXRs) of bake a against
/// bake b; infinity when their sizes differ.
inline double level_rel_rms(const std::string& a, const std::string& b, int l) {
    double num = 0.0, den = 0.0;
    for (const char* f : {"px", "nx", "py", "ny", "pz", "nz"}) {
        const std::string name = "/specular_l" + std::to_string(l) + "_" + f + ".exr";
        const ibl_bake::image_rgb32f x = ibl_bake::read_image(a + name), y = ibl_bake::read_image(b + name);
        if (x.rgb.size() != y.rgb.size()) return INFINITY;
        for (std::size_t i = 0; i < x.rgb.size(); ++i) {
            num += (double(x.rgb[i]) - y.rgb[i]) * (double(x.rgb[i]) - y.rgb[i]);
            den += double(y.rgb[i]) * y.rgb[i];
        }
    }
    return std::sqrt(num / den);
}

} // namespace ibl_bake_test
