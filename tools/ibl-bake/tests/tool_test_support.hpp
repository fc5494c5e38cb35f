#pragma once
// tools/ibl-bake/tests/tool_test_support.hpp — what the end-to-end tests of the executable share:
// a scratch folder removed at the end, reading a whole file, running a shell command.

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

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

} // namespace ibl_bake_test
