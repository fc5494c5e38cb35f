// tools/ibl-bake/stages/output_stage.cpp — staging directory, atomic swap, signal cleanup and stale
// staging directories (see output_stage.hpp).

#include "stages/output_stage.hpp"

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <random>
#include <stdexcept>
#include <string_view>
#include <system_error>
#include <thread>

#include <fcntl.h>
#include <pthread.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <time.h>
#include <unistd.h>

namespace fs = std::filesystem;

namespace ibl_bake {

namespace {

// ---- names -----------------------------------------------------------------------------------

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

/// DIR as an absolute path without "." / ".." / a trailing slash, symbolic links resolved.
fs::path normalized(const std::string& dir) {
    fs::path p = fs::absolute(fs::path(dir)).lexically_normal();
    if (!p.has_filename() && p.has_parent_path()) p = p.parent_path(); // "out/" -> "out"
    std::error_code ec;
    fs::path c = fs::weakly_canonical(p, ec);
    if (ec) return p;
    if (!c.has_filename() && c.has_parent_path()) c = c.parent_path();
    return c;
}

/// ".<name>.ibl-bake-": the prefix of every staging directory of DIR.
std::string stage_prefix(const fs::path& target) {
    std::string s(1, '.');
    s.append(target.filename().string()).append(".ibl-bake-");
    return s;
}

std::string errno_text(int e) { return std::strerror(e); }

// ---- async-signal-safe removal -----------------------------------------------------------------

/// Removes `name` (relative to parent_fd) and, for a directory, everything below it, with
/// system calls only (async-signal-safe). Entries removed concurrently are tolerated; a folder
/// that keeps getting new entries is retried a bounded number of times.
bool remove_tree_at(int parent_fd, const char* name, int depth) noexcept {
    if (::unlinkat(parent_fd, name, 0) == 0 || errno == ENOENT) return true;
    if (errno != EISDIR && errno != EPERM) return false;
    if (depth > 16) return false;
    const int fd = ::openat(parent_fd, name, O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
    if (fd < 0) return errno == ENOENT;
    bool done = false;
    for (int pass = 0; pass < 100 && !done; ++pass) {
        ::lseek(fd, 0, SEEK_SET);
        alignas(8) char buf[2048];
        for (;;) {
            const long n = ::syscall(SYS_getdents64, fd, buf, sizeof buf);
            if (n <= 0) break;
            for (long off = 0; off < n;) {
                // struct linux_dirent64: u64 d_ino, s64 d_off, u16 d_reclen, u8 d_type, char d_name[]
                unsigned short reclen = 0;
                std::memcpy(&reclen, buf + off + 16, sizeof reclen);
                const char* entry = buf + off + 19;
                off += reclen;
                if (reclen == 0) break;
                if (entry[0] == '.' && (entry[1] == '\0' || (entry[1] == '.' && entry[2] == '\0'))) continue;
                remove_tree_at(fd, entry, depth + 1);
            }
        }
        done = ::unlinkat(parent_fd, name, AT_REMOVEDIR) == 0 || errno == ENOENT;
    }
    ::close(fd);
    return done;
}

// ---- signal state --------------------------------------------------------------------------------

// g_state: 0 no staging directory; 1 staging directory live (the handler may remove it);
// 2 the handler is removing it; 3 swap in progress (the handler waits); 4 swapped: g_path is the
// old DIR, to be removed.
std::atomic<int> g_state{0};
static_assert(std::atomic<int>::is_always_lock_free, "the signal handler needs a lock-free atomic");
constexpr std::size_t path_capacity = 4096;
char g_path[path_capacity];
constexpr int guarded_signals[] = {SIGINT, SIGTERM, SIGHUP};
struct sigaction g_previous[3];
bool g_installed = false;

extern "C" void on_fatal_signal(int sig) {
    const int saved = errno;
    int s = g_state.load();
    while (s == 3) { // swap in progress on another thread: wait for it
        const timespec ts{0, 1000000};
        ::nanosleep(&ts, nullptr);
        s = g_state.load();
    }
    if ((s == 1 || s == 4) && g_state.compare_exchange_strong(s, 2)) remove_tree_at(AT_FDCWD, g_path, 0);
    struct sigaction dfl {};
    dfl.sa_handler = SIG_DFL;
    sigemptyset(&dfl.sa_mask);
    ::sigaction(sig, &dfl, nullptr);
    errno = saved;
    ::raise(sig); // delivered with the default action as soon as the handler returns
}

void install_handlers() {
    struct sigaction sa {};
    sa.sa_handler = on_fatal_signal;
    sigemptyset(&sa.sa_mask);
    for (int s : guarded_signals) sigaddset(&sa.sa_mask, s);
    sa.sa_flags = 0;
    for (std::size_t i = 0; i < 3; ++i) ::sigaction(guarded_signals[i], &sa, &g_previous[i]);
    g_installed = true;
}

void restore_handlers() {
    if (!g_installed) return;
    for (std::size_t i = 0; i < 3; ++i) ::sigaction(guarded_signals[i], &g_previous[i], nullptr);
    g_installed = false;
}

/// Blocks the guarded signals on this thread for its lifetime.
class signal_block {
public:
    signal_block() {
        sigset_t set;
        sigemptyset(&set);
        for (int s : guarded_signals) sigaddset(&set, s);
        ::pthread_sigmask(SIG_BLOCK, &set, &old_);
    }
    ~signal_block() { ::pthread_sigmask(SIG_SETMASK, &old_, nullptr); }
    signal_block(const signal_block&) = delete;
    signal_block& operator=(const signal_block&) = delete;

private:
    sigset_t old_;
};

void set_path(const std::string& p) {
    if (p.size() >= path_capacity) throw std::runtime_error(p + ": path too long");
    std::memcpy(g_path, p.c_str(), p.size() + 1);
}

/// A signal handler is removing the staging directory and will end the process: wait for it.
[[noreturn]] void wait_for_signal_death() {
    std::this_thread::sleep_for(std::chrono::seconds(30));
    throw std::runtime_error("interrupted by a signal");
}

// ---- carrying DIR's entries over -------------------------------------------------------------

void carry(const fs::path& from, const fs::path& to, int depth) {
    struct stat st {};
    if (::lstat(from.c_str(), &st) != 0) throw std::runtime_error(from.string() + ": cannot read: " + errno_text(errno));
    if (S_ISREG(st.st_mode)) {
        if (::link(from.c_str(), to.c_str()) == 0) return;
        std::error_code ec;
        fs::copy_file(from, to, fs::copy_options::none, ec);
        if (ec) throw std::runtime_error(from.string() + ": cannot keep it in the new output directory: " + ec.message());
        ::chmod(to.c_str(), st.st_mode & 07777);
    } else if (S_ISLNK(st.st_mode)) {
        std::error_code ec;
        const fs::path target = fs::read_symlink(from, ec);
        if (!ec) fs::create_symlink(target, to, ec);
        if (ec) throw std::runtime_error(from.string() + ": cannot keep the symbolic link: " + ec.message());
    } else if (S_ISDIR(st.st_mode)) {
        if (depth > 64) throw std::runtime_error(from.string() + ": directories nested too deeply to keep");
        if (::mkdir(to.c_str(), 0700) != 0) throw std::runtime_error(to.string() + ": cannot create: " + errno_text(errno));
        std::error_code ec;
        for (const auto& e : fs::directory_iterator(from, ec)) carry(e.path(), to / e.path().filename(), depth + 1);
        if (ec) throw std::runtime_error(from.string() + ": cannot list: " + ec.message());
        ::chmod(to.c_str(), st.st_mode & 07777);
    } else if (S_ISFIFO(st.st_mode)) {
        if (::mkfifo(to.c_str(), st.st_mode & 07777) != 0)
            throw std::runtime_error(from.string() + ": cannot keep the FIFO: " + errno_text(errno));
    } else {
        throw std::runtime_error(from.string() + ": a socket or device file in the output directory cannot be carried over; move it away");
    }
}

std::string random_suffix() {
    std::random_device rd;
    static std::atomic<unsigned> counter{0};
    const std::uint64_t x = (std::uint64_t(rd()) << 20) ^ std::uint64_t(std::chrono::steady_clock::now().time_since_epoch().count()) ^
                            (std::uint64_t(counter++) << 44);
    static constexpr char digits[] = "0123456789abcdefghijklmnopqrstuvwxyz";
    std::string s;
    std::uint64_t v = x;
    for (int i = 0; i < 8; ++i, v /= 36) s.push_back(digits[v % 36]);
    return s;
}

void fsync_dir(const fs::path& p) noexcept {
    const int fd = ::open(p.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd < 0) return;
    ::fsync(fd);
    ::close(fd);
}

} // namespace

// ---- checks ----------------------------------------------------------------------------------

int remove_stale_stages(const std::string& dir) {
    const fs::path target = normalized(dir);
    const fs::path parent = target.parent_path();
    const std::string prefix = stage_prefix(target);
    std::error_code ec;
    int removed = 0;
    std::vector<fs::path> candidates;
    for (const auto& e : fs::directory_iterator(parent, ec)) {
        const std::string n = e.path().filename().string();
        if (n.compare(0, prefix.size(), prefix) == 0) candidates.push_back(e.path());
    }
    for (const fs::path& p : candidates) {
        const std::string rest = p.filename().string().substr(prefix.size());
        std::size_t i = 0;
        while (i < rest.size() && rest[i] >= '0' && rest[i] <= '9') ++i;
        if (i == 0 || i > 9 || i >= rest.size() || rest[i] != '-') continue; // no pid: not ours to judge
        const long pid = std::stol(rest.substr(0, i));
        if (pid <= 0 || pid == long(::getpid())) continue;
        if (::kill(pid_t(pid), 0) == 0 || errno != ESRCH) continue; // alive (or not ours to signal)
        const int fd = ::open(p.c_str(), O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
        if (fd < 0) continue;
        const bool free = ::flock(fd, LOCK_EX | LOCK_NB) == 0;
        ::close(fd);
        if (!free) continue; // a live run holds it (another PID namespace)
        const bool old = rest.size() > 4 && rest.compare(rest.size() - 4, 4, ".old") == 0;
        if (old && !fs::exists(fs::symlink_status(target, ec)) && std::rename(p.c_str(), target.c_str()) == 0) {
            ++removed;
            continue;
        }
        fs::remove_all(p, ec);
        if (!ec) ++removed;
    }
    return removed;
}

void check_output_dir(const std::string& dir) {
    if (dir.empty()) throw std::runtime_error("--out: empty path");
    const fs::path p = normalized(dir);
    if (p.filename().empty() || p == p.root_path()) throw std::runtime_error(dir + ": not a usable output directory");
    std::error_code ec;
    const fs::path cwd = fs::current_path(ec);
    if (!ec) {
        const fs::path c = fs::weakly_canonical(cwd, ec);
        const fs::path& here = ec ? cwd : c;
        const auto m = std::mismatch(p.begin(), p.end(), here.begin(), here.end());
        if (m.first == p.end())
            throw std::runtime_error(dir + ": is the current directory or one of its parents; ibl-bake replaces DIR as a whole, "
                                           "so give --out a directory of its own (for example --out bake)");
    }
    const auto lst = fs::symlink_status(p, ec);
    const auto st = fs::status(p, ec);
    if (fs::is_symlink(lst) && !fs::exists(st)) throw std::runtime_error(dir + ": is a dangling symbolic link");
    if (fs::exists(st)) {
        if (!fs::is_directory(st)) throw std::runtime_error(dir + ": exists and is not a directory");
        if (::access(p.c_str(), R_OK | W_OK | X_OK) != 0)
            throw std::runtime_error(dir + ": the output directory is not writable: " + errno_text(errno));
    }
    fs::path q = p.parent_path();
    while (!q.empty() && q != q.root_path() && !fs::exists(fs::symlink_status(q, ec))) q = q.parent_path();
    if (!fs::is_directory(fs::status(q, ec)))
        throw std::runtime_error(dir + ": cannot create the output directory: " + q.string() + " is not a directory");
    // A real test: create (and remove) a directory where the staging directory will be made.
    const fs::path probe = q / (stage_prefix(p) + std::to_string(::getpid()) + "-probe");
    if (::mkdir(probe.c_str(), 0700) != 0)
        throw std::runtime_error(dir + ": cannot create the output directory in " + q.string() + ": " + errno_text(errno));
    ::rmdir(probe.c_str());
    if (q == p.parent_path()) remove_stale_stages(dir);
}

// ---- the stage -------------------------------------------------------------------------------

output_stage::output_stage(const std::string& dir) : dir_(normalized(dir).string()) {
    check_output_dir(dir);
    if (g_state.load() != 0) throw std::runtime_error("internal: a second output stage in one process");
    const fs::path target(dir_);
    const fs::path parent = target.parent_path();
    std::error_code ec;
    fs::create_directories(parent, ec);
    if (ec) throw std::runtime_error(parent.string() + ": cannot create the parent directory: " + ec.message());
    const std::string base = stage_prefix(target) + std::to_string(::getpid()) + "-";
    for (int attempt = 0; attempt < 100 && staging_.empty(); ++attempt) {
        const std::string p = (parent / (base + random_suffix())).string();
        if (::mkdir(p.c_str(), 0777) == 0) staging_ = p; // 0777 & ~umask
        else if (errno != EEXIST)
            throw std::runtime_error(parent.string() + ": cannot create a staging directory: " + errno_text(errno));
    }
    if (staging_.empty()) throw std::runtime_error(parent.string() + ": cannot create a unique staging directory");
    lock_fd_ = ::open(staging_.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (lock_fd_ >= 0) ::flock(lock_fd_, LOCK_EX);
    try {
        set_path(staging_);
    } catch (...) {
        ::rmdir(staging_.c_str());
        if (lock_fd_ >= 0) ::close(lock_fd_);
        throw;
    }
    install_handlers();
    g_state.store(1);
}

output_stage::~output_stage() {
    int s = g_state.load();
    if (s == 1 && g_state.compare_exchange_strong(s, 0)) {
        std::error_code ec;
        if (!committed_) fs::remove_all(staging_, ec);
    } else if (s == 2) {
        std::this_thread::sleep_for(std::chrono::seconds(30)); // a handler is ending the process
    }
    restore_handlers();
    if (lock_fd_ >= 0) ::close(lock_fd_);
}

std::string output_stage::file(const std::string& name) {
    if (std::find(names_.begin(), names_.end(), name) == names_.end()) names_.push_back(name);
    return (fs::path(staging_) / name).string();
}

void output_stage::carry_existing(unsigned mode) {
    const fs::path target(dir_), stage(staging_);
    for (const std::string& n : names_) {
        struct stat e {};
        if (::lstat((target / n).c_str(), &e) == 0 && !S_ISREG(e.st_mode))
            throw std::runtime_error((target / n).string() + ": is not a regular file, and ibl-bake writes a file of that name; "
                                                             "move it away (the output directory was left as it was)");
    }
    std::error_code ec;
    std::vector<fs::path> keep;
    for (const auto& entry : fs::directory_iterator(target, ec)) {
        const std::string n = entry.path().filename().string();
        if (std::find(names_.begin(), names_.end(), n) != names_.end()) continue; // replaced
        if (is_level_face(n) && entry.is_regular_file(ec)) continue;               // stale level: dropped
        keep.push_back(entry.path());
    }
    if (ec) throw std::runtime_error(dir_ + ": cannot list the output directory: " + ec.message());
    for (const fs::path& k : keep) carry(k, stage / k.filename(), 0);
    ::chmod(staging_.c_str(), mode & 07777);
}

std::string output_stage::swap_in(bool exists) {
    std::string old;
    const signal_block block;
    int s = 1;
    if (!g_state.compare_exchange_strong(s, 3)) wait_for_signal_death();
    int err = 0;
    if (!exists) {
        if (std::rename(staging_.c_str(), dir_.c_str()) != 0) err = errno;
    } else if (::renameat2(AT_FDCWD, staging_.c_str(), AT_FDCWD, dir_.c_str(), RENAME_EXCHANGE) == 0) {
        old = staging_; // g_path already names it
    } else if (errno == EINVAL || errno == ENOSYS || errno == EOPNOTSUPP) {
        const std::string aside = staging_ + ".old";
        if (std::rename(dir_.c_str(), aside.c_str()) != 0) err = errno;
        else if (std::rename(staging_.c_str(), dir_.c_str()) != 0) {
            err = errno;
            std::rename(aside.c_str(), dir_.c_str());
        } else {
            old = aside;
            std::memcpy(g_path, aside.c_str(), std::min(aside.size() + 1, path_capacity - 1));
            g_path[path_capacity - 1] = '\0';
        }
    } else {
        err = errno;
    }
    if (err != 0) {
        g_state.store(1);
        throw std::runtime_error(dir_ + ": cannot move the new output directory into place: " + errno_text(err) +
                                 " (the output directory was left as it was)");
    }
    committed_ = true;
    g_state.store(old.empty() ? 0 : 4);
    return old;
}

void output_stage::commit() {
    if (committed_) return;
    struct stat st {};
    const bool exists = ::lstat(dir_.c_str(), &st) == 0;
    if (exists) {
        if (!S_ISDIR(st.st_mode)) throw std::runtime_error(dir_ + ": exists and is not a directory");
        carry_existing(st.st_mode);
    }
    fsync_dir(fs::path(staging_));
    const std::string old = swap_in(exists); // the path that holds the old DIR after the swap
    if (!old.empty()) {
        int s = 4;
        if (g_state.compare_exchange_strong(s, 0)) {
            std::error_code ec;
            fs::remove_all(old, ec); // if this fails, the next run removes it (stale, pid gone)
        }
    }
    fsync_dir(fs::path(dir_).parent_path());
}

} // namespace ibl_bake
