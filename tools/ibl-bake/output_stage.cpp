// tools/ibl-bake/output_stage.cpp — staging directory and commit (see output_stage.hpp).

#include "output_stage.hpp"

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <string_view>
#include <system_error>

namespace fs = std::filesystem;

namespace ibl_bake {

namespace {
/// True for "specular_l<digits>_<face>.exr" (the per-level faces ibl-bake writes).
bool is_level_face(std::string_view n) {
    constexpr std::string_view prefix = "specular_l";
    if (n.substr(0, prefix.size()) != prefix) return false;
    std::size_t i = prefix.size();
    const std::size_t digits = i;
    while (i < n.size() && n[i] >= '0' && n[i] <= '9') ++i;
    if (i == digits) return false;
    const std::string_view rest = n.substr(i);
    for (const std::string_view f : {"_px.exr", "_nx.exr", "_py.exr", "_ny.exr", "_pz.exr", "_nz.exr"})
        if (rest == f) return true;
    return false;
}

fs::path normalized(const std::string& dir) {
    fs::path p = fs::absolute(fs::path(dir)).lexically_normal();
    if (!p.has_filename() && p.has_parent_path()) p = p.parent_path(); // "out/" -> "out"
    return p;
}
} // namespace

void check_output_dir(const std::string& dir) {
    std::error_code ec;
    const fs::path p = normalized(dir);
    const auto st = fs::status(p, ec);
    if (!ec && fs::exists(st) && !fs::is_directory(st))
        throw std::runtime_error(dir + ": exists and is not a directory");
    if (p.filename().empty() || p == p.root_path()) throw std::runtime_error(dir + ": not a usable output directory");
}

output_stage::output_stage(const std::string& dir) : dir_(normalized(dir).string()) {
    check_output_dir(dir);
    const fs::path target(dir_);
    const fs::path parent = target.parent_path();
    std::error_code ec;
    fs::create_directories(parent, ec);
    if (ec) throw std::runtime_error(parent.string() + ": cannot create the parent directory: " + ec.message());
    // (built with append, not "." + s: g++ 12 -O3 flags operator+(const char*, string&&) with a
    // false -Wrestrict)
    std::string name(1, '.');
    name.append(target.filename().string()).append(".ibl-bake-XXXXXX");
    const std::string tmpl = (parent / name).string();
    std::vector<char> buf(tmpl.begin(), tmpl.end());
    buf.push_back('\0');
    if (!::mkdtemp(buf.data()))
        throw std::runtime_error(parent.string() + ": cannot create a staging directory: " + std::strerror(errno));
    staging_ = buf.data();
}

output_stage::~output_stage() {
    if (committed_ || staging_.empty()) return;
    std::error_code ec;
    fs::remove_all(staging_, ec);
}

std::string output_stage::file(const std::string& name) {
    if (std::find(names_.begin(), names_.end(), name) == names_.end()) names_.push_back(name);
    return (fs::path(staging_) / name).string();
}

void output_stage::commit() {
    std::error_code ec;
    const fs::path target(dir_);
    if (!fs::exists(target, ec)) {
        if (std::rename(staging_.c_str(), dir_.c_str()) != 0)
            throw std::runtime_error(dir_ + ": cannot move the staging directory into place: " + std::strerror(errno));
        committed_ = true;
        return;
    }
    if (!fs::is_directory(target, ec)) throw std::runtime_error(dir_ + ": exists and is not a directory");
    for (const std::string& n : names_) {
        const fs::path from = fs::path(staging_) / n, to = target / n;
        if (std::rename(from.c_str(), to.c_str()) != 0)
            throw std::runtime_error(to.string() + ": cannot move into place: " + std::strerror(errno));
    }
    // Stale per-level faces of an earlier, longer chain.
    for (const auto& entry : fs::directory_iterator(target, ec)) {
        const std::string n = entry.path().filename().string();
        if (is_level_face(n) && std::find(names_.begin(), names_.end(), n) == names_.end())
            fs::remove(entry.path(), ec);
    }
    fs::remove_all(staging_, ec);
    committed_ = true;
}

} // namespace ibl_bake
