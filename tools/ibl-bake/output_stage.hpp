#pragma once
// tools/ibl-bake/output_stage.hpp — all-or-nothing output of ibl-bake.
//
// Every file is first written into a fresh staging directory created next to DIR (same parent,
// so the same file system): "<parent>/.<name>.ibl-bake-XXXXXX" (mkdtemp). Only when every file
// has been written does commit() move them into place:
//   * DIR does not exist: the staging directory is renamed to DIR (one atomic rename);
//   * DIR exists (a directory): each file is renamed into it (each rename atomic, replacing a
//     file of the same name from an earlier bake); files in DIR that an earlier bake wrote with
//     names this bake does not produce (specular_l<k>_<face>.exr of levels no longer present) are
//     removed; any other file in DIR is left alone. Then the staging directory is removed.
// If anything fails before commit (a bad input detected late, a write error, an exception), the
// destructor removes the staging directory: DIR is never touched and no partial file remains.
// check_output_dir() runs before any work: DIR must not be an existing non-directory.

#include <string>
#include <vector>

namespace ibl_bake {

/// Throws std::runtime_error if `dir` exists and is not a directory.
void check_output_dir(const std::string& dir);

class output_stage {
public:
    explicit output_stage(const std::string& dir);
    ~output_stage();
    output_stage(const output_stage&) = delete;
    output_stage& operator=(const output_stage&) = delete;

    /// Path of `name` inside the staging directory; records the name for commit().
    std::string file(const std::string& name);
    const std::string& staging_dir() const noexcept { return staging_; }
    /// Moves the staged files into DIR (see the header). Throws std::runtime_error.
    void commit();

private:
    std::string dir_, staging_;
    std::vector<std::string> names_;
    bool committed_ = false;
};

} // namespace ibl_bake
