#pragma once
// tools/ibl-bake/stages/output_stage.hpp — all-or-nothing output of ibl-bake.
//
// At every instant DIR (--out) is either entirely the old one or entirely the new one; a failure
// or a signal at any point leaves DIR as it was and nothing beside it.
//
// Staging. Every file is first written into a fresh staging directory next to DIR (same parent,
// so the same file system): "<parent>/.<name>.ibl-bake-<pid>-<random>", created with mode
// 0777 & ~umask (so a new DIR gets the umask's mode, like mkdir(1)) and locked with flock(2) for
// the lifetime of the run.
//
// Commit (commit(), once every file is written):
//   1. DIR exists: each of its entries that the new DIR must keep is carried into the staging
//      directory: every entry the bake does not write, except stale per-level faces
//      (specular_l<k>_<face>.exr regular files of levels no longer produced), which are dropped.
//      Regular files are hard-linked (the same file, no copy; copied with its mode if the link is
//      refused, e.g. by fs.protected_hardlinks), symbolic links recreated, subdirectories
//      recreated recursively with their modes, FIFOs recreated; a socket or device in DIR is an
//      error. An entry of DIR with a name the bake writes that is not a regular file (say a
//      directory report.json) is an error too: it would be lost. The staging directory gets
//      DIR's permission bits. (DIR's owner, ACLs and extended attributes are not carried over.)
//   2. The staging directory and DIR are swapped in one step: renameat2(RENAME_EXCHANGE); where
//      the file system lacks it, DIR is renamed to "<staging>.old", the staging directory to
//      DIR (the first rename is undone if the second fails). The old DIR is then removed.
//      Without DIR, the staging directory is simply renamed to DIR.
// If anything fails before the swap (a bad input detected late, a write error, an exception), the
// destructor removes the staging directory: DIR is never touched.
//
// Signals. While the staging directory exists, SIGINT, SIGTERM and SIGHUP remove it (async-
// signal-safe: its path is recorded beforehand; files are unlinked and folders removed with
// open/getdents64/unlinkat only) and are then re-raised with the default action, so the exit
// status says the process was killed by that signal. During the swap itself (two renames) the
// handler waits for the swap to finish and then removes what is left (the old DIR).
//
// Stale staging directories. SIGKILL (or a crash) cannot be caught; the next run with the same
// DIR removes every "<parent>/.<name>.ibl-bake-<pid>-*" whose process no longer exists (kill(pid,
// 0) fails with ESRCH) and whose flock is free (so a live run in another PID namespace keeps its
// folder). A stale "<staging>.old" while DIR is missing (killed between the two renames of the
// fallback swap) is renamed back to DIR instead. Names without a pid (older versions) are left
// alone.
//
// check_output_dir() runs before any work (run_bake's first step) and throws std::runtime_error:
//   * DIR names the root, the current directory or one of its ancestors ("--out .", "--out ..")
//     (replacing it would pull the directory from under the running process and its shell);
//   * DIR exists and is not a directory, or is a dangling symbolic link;
//   * DIR exists and is not readable, writable and searchable by this process;
//   * the parent (or, if the parent is still to be created, its nearest existing ancestor) is not
//     a directory in which this process can create a directory (tested by creating and removing
//     one, so read-only file systems and ACLs count);
// then removes stale staging directories of DIR (above). A symbolic link DIR is resolved: the
// directory it names is the one replaced.

#include <string>
#include <vector>

namespace ibl_bake {

/// The checks above; throws std::runtime_error. Also removes stale staging directories of dir.
void check_output_dir(const std::string& dir);

/// Removes stale staging directories beside dir (see the header); returns how many were removed
/// or restored.
int remove_stale_stages(const std::string& dir);

class output_stage {
public:
    explicit output_stage(const std::string& dir);
    ~output_stage();
    output_stage(const output_stage&) = delete;
    output_stage& operator=(const output_stage&) = delete;

    /// Path of `name` inside the staging directory; records the name for commit().
    std::string file(const std::string& name);
    const std::string& staging_dir() const noexcept { return staging_; }
    /// Swaps the staging directory in as DIR (see the header). Throws std::runtime_error, leaving
    /// DIR as it was.
    void commit();

private:
    /// Into the stage, what an existing DIR holds beside the files of this bake (a stale level's
    /// faces aside); refuses a non-file where a file of this bake goes. `mode`: DIR's permissions.
    void carry_existing(unsigned mode);
    /// Swaps the stage in as DIR (a rename when there is none), signals blocked; the path that
    /// holds the old DIR (empty when there was none).
    std::string swap_in(bool exists);

    std::string dir_, staging_;
    std::vector<std::string> names_;
    int lock_fd_ = -1;
    bool committed_ = false;
};

} // namespace ibl_bake
