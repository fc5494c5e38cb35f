// tools/ibl-bake/tests/test_tool_guard.cpp — reliability of the ibl-bake executable: the output
// directory is replaced in one step or not at all (a commit that fails, SIGTERM/SIGINT, stale
// staging folders of killed runs), --out is checked before any work, inputs must be regular
// files of bounded size, radiance near float's limit is clamped and counted, and a black map
// gives finite metrics. Every case runs the built tool (IBL_BAKE_TOOL) at tiny sizes.

#include <doctest/doctest.h>

#include "io/image_io.hpp"

#include <chrono>
#include <cmath>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <fcntl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

namespace fs = std::filesystem;
using namespace ibl_bake;

namespace {

const std::string tool = IBL_BAKE_TOOL;
const std::vector<std::string> tiny = {"--size", "16", "--lut-size", "16", "--quality", "low", "--quiet"};

std::vector<std::string> with(std::vector<std::string> a, const std::vector<std::string>& more) {
    a.insert(a.end(), more.begin(), more.end());
    return a;
}

std::string slurp(const fs::path& path) {
    std::ifstream f(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
}

struct scratch {
    fs::path path;
    explicit scratch(const std::string& tag) {
        path = fs::temp_directory_path() / ("ibl_bake_guard_" + tag + "_" + std::to_string(::getpid()));
        std::error_code ec;
        fs::permissions(path, fs::perms::owner_all, fs::perm_options::add, ec);
        fs::remove_all(path, ec);
        fs::create_directories(path);
    }
    ~scratch() {
        std::error_code ec;
        for (auto it = fs::recursive_directory_iterator(path, ec); it != fs::recursive_directory_iterator(); it.increment(ec))
            if (it->is_directory(ec)) fs::permissions(it->path(), fs::perms::owner_all, fs::perm_options::add, ec);
        fs::remove_all(path, ec);
    }
    fs::path operator/(const std::string& n) const { return path / n; }
};

struct child {
    pid_t pid = -1;
    fs::path err;
};

struct spawn_options {
    fs::path cwd;
    mode_t umask_value = 022;
};

/// Starts the tool (stdout to /dev/null, stderr to `err`).
child spawn(const std::vector<std::string>& args, const fs::path& err, const spawn_options& o = {}) {
    std::vector<std::string> argv_s{tool};
    argv_s.insert(argv_s.end(), args.begin(), args.end());
    const pid_t pid = ::fork();
    REQUIRE(pid >= 0);
    if (pid == 0) {
        ::umask(o.umask_value);
        if (!o.cwd.empty() && ::chdir(o.cwd.c_str()) != 0) ::_exit(126);
        const int null_fd = ::open("/dev/null", O_WRONLY);
        const int err_fd = ::open(err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        if (null_fd < 0 || err_fd < 0) ::_exit(126);
        ::dup2(null_fd, 1);
        ::dup2(err_fd, 2);
        std::vector<char*> argv;
        for (auto& a : argv_s) argv.push_back(a.data());
        argv.push_back(nullptr);
        ::execv(tool.c_str(), argv.data());
        ::_exit(127);
    }
    return {pid, err};
}

struct result {
    int status = -1;  ///< exit status, or -1 if killed
    int signal = 0;   ///< the signal that killed it
    bool timed_out = false;
    double seconds = 0;
    std::string err;
};

result wait_for(const child& c, double timeout_s = 60) {
    const auto t0 = std::chrono::steady_clock::now();
    result r;
    int st = 0;
    for (;;) {
        const pid_t w = ::waitpid(c.pid, &st, WNOHANG);
        if (w == c.pid) break;
        if (std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() > timeout_s) {
            ::kill(c.pid, SIGKILL);
            ::waitpid(c.pid, &st, 0);
            r.timed_out = true;
            break;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (WIFEXITED(st)) r.status = WEXITSTATUS(st);
    if (WIFSIGNALED(st)) r.signal = WTERMSIG(st);
    r.err = slurp(c.err);
    return r;
}

result run(const scratch& s, const std::vector<std::string>& args, const spawn_options& o = {}, double timeout_s = 60) {
    return wait_for(spawn(args, s / "stderr.txt", o), timeout_s);
}

/// Every entry below `dir` (relative paths) with its type and, for files, its content.
std::map<std::string, std::string> snapshot(const fs::path& dir) {
    std::map<std::string, std::string> m;
    if (!fs::exists(dir)) return m;
    for (const auto& e : fs::recursive_directory_iterator(dir)) {
        const std::string rel = fs::relative(e.path(), dir).string();
        if (e.is_symlink()) m[rel] = "link:" + fs::read_symlink(e.path()).string();
        else if (e.is_directory()) m[rel] = "dir";
        else m[rel] = "file:" + slurp(e.path());
    }
    return m;
}

std::set<std::string> entries(const fs::path& dir) {
    std::set<std::string> s;
    for (const auto& e : fs::directory_iterator(dir)) s.insert(e.path().filename().string());
    return s;
}

/// Entries of `dir` that look like a staging folder of ibl-bake.
std::vector<std::string> stages_in(const fs::path& dir) {
    std::vector<std::string> v;
    for (const auto& n : entries(dir))
        if (n.find(".ibl-bake-") != std::string::npos) v.push_back(n);
    return v;
}

bool has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

/// A pid that no longer exists: a child that has exited and been reaped.
pid_t dead_pid() {
    const pid_t p = ::fork();
    if (p == 0) ::_exit(0);
    int st = 0;
    ::waitpid(p, &st, 0);
    return p;
}

void write_text(const fs::path& p, const std::string& text) { std::ofstream(p, std::ios::binary) << text; }

} // namespace

TEST_CASE("guard: a commit that fails leaves DIR exactly as it was and nothing beside it") {
    scratch s("commit");
    const fs::path out = s / "bake";
    REQUIRE(run(s, with(tiny, {"--out", out.string()})).status == 0);
    write_text(out / "keep.txt", "mine");
    // report.json is now a directory holding a user's file: the bake cannot write it
    fs::remove(out / "report.json");
    fs::create_directories(out / "report.json");
    write_text(out / "report.json" / "inside.txt", "precious");
    const auto before = snapshot(out);
    const result r = run(s, with(tiny, {"--out", out.string(), "--lut-size", "8"}));
    INFO(r.err);
    CHECK(r.status == 1);
    CHECK(has(r.err, "report.json"));
    CHECK(has(r.err, "left as it was"));
    CHECK(snapshot(out) == before); // no file of the new bake moved in (dfg.exr still 16 x 16)
    CHECK(read_image((out / "dfg.exr").string()).width == 16);
    CHECK(stages_in(s.path).empty());
}

TEST_CASE("guard: a rebake swaps DIR whole: other files kept (same inode), stale levels removed, mode kept") {
    scratch s("swap");
    const fs::path out = s / "bake";
    fs::create_directories(out / "notes" / "deep");
    write_text(out / "keep.txt", "mine");
    write_text(out / "notes" / "deep" / "a.txt", "deep");
    fs::create_symlink("keep.txt", out / "link");
    write_text(out / "specular_l7_px.exr", "stale");
    write_text(out / "dfg.exr", "old");
    ::chmod(out.c_str(), 0750);
    struct stat before {};
    REQUIRE(::stat((out / "keep.txt").c_str(), &before) == 0);
    const result r = run(s, with(tiny, {"--out", out.string()}));
    INFO(r.err);
    REQUIRE(r.status == 0);
    CHECK(slurp(out / "keep.txt") == "mine");
    CHECK(slurp(out / "notes" / "deep" / "a.txt") == "deep");
    CHECK(fs::read_symlink(out / "link") == "keep.txt");
    CHECK_FALSE(fs::exists(out / "specular_l7_px.exr"));
    CHECK(read_image((out / "dfg.exr").string()).width == 16);
    struct stat after {};
    REQUIRE(::stat((out / "keep.txt").c_str(), &after) == 0);
    CHECK(after.st_ino == before.st_ino); // hard-linked, not copied
    struct stat dir {};
    REQUIRE(::stat(out.c_str(), &dir) == 0);
    CHECK((dir.st_mode & 07777) == 0750);
    CHECK(entries(s.path) == std::set<std::string>{"bake", "stderr.txt"});
}

TEST_CASE("guard: a new DIR is created with the umask") {
    scratch s("umask");
    for (const mode_t m : {mode_t(022), mode_t(027), mode_t(077)}) {
        const fs::path out = s / ("bake" + std::to_string(m));
        spawn_options o;
        o.umask_value = m;
        REQUIRE(run(s, with(tiny, {"--out", out.string()}), o).status == 0);
        struct stat st {};
        REQUIRE(::stat(out.c_str(), &st) == 0);
        CHECK((st.st_mode & 0777) == (0777 & ~m));
    }
}

TEST_CASE("guard: --out naming the current directory or an ancestor is refused") {
    scratch s("cwd");
    const fs::path work = s / "a" / "b";
    fs::create_directories(work);
    write_text(work / "mine.txt", "x");
    const auto before = snapshot(s / "a");
    spawn_options o;
    o.cwd = work;
    for (const std::string& out : {std::string("."), std::string(".."), std::string("./"), std::string("../b"), work.string(),
                                   (s / "a").string(), s.path.string()}) {
        const result r = run(s, with(tiny, {"--out", out}), o);
        INFO(out, " ", r.err);
        CHECK(r.status == 1);
        CHECK(has(r.err, "current directory or one of its parents"));
    }
    CHECK(snapshot(s / "a") == before);
    CHECK(stages_in(s.path).empty());
    CHECK(stages_in(s / "a").empty());
}

TEST_CASE("guard: an unwritable --out is refused before the bake starts") {
    scratch s("unwritable");
    // A size whose bake takes seconds: the refusal must come at once.
    const std::vector<std::string> big = {"--size", "1024", "--quiet"};
    {   // /proc refuses new directories even to root
        const result r = run(s, with(big, {"--out", "/proc/ibl-bake-guard-test/out"}));
        INFO(r.err);
        CHECK(r.status == 1);
        CHECK(has(r.err, "cannot create the output directory"));
        CHECK(r.seconds < 2.0);
    }
    if (::geteuid() != 0) { // permissions bind only non-root users
        const fs::path ro = s / "ro";
        fs::create_directories(ro / "existing");
        ::chmod((ro / "existing").c_str(), 0555);
        ::chmod(ro.c_str(), 0555);
        for (const fs::path& out : {ro / "new", ro / "existing"}) {
            const result r = run(s, with(big, {"--out", out.string()}));
            INFO(out, r.err);
            CHECK(r.status == 1);
            CHECK(r.seconds < 2.0);
        }
        ::chmod(ro.c_str(), 0755);
    } else {
        MESSAGE("running as root: permission cases skipped (root ignores file modes)");
    }
}

TEST_CASE("guard: stale staging folders of dead runs are removed, a live run's kept, an interrupted swap restored") {
    scratch s("stale");
    const fs::path out = s / "bake";
    const pid_t dead = dead_pid();
    const fs::path stale = s / (".bake.ibl-bake-" + std::to_string(dead) + "-abcdefgh");
    const fs::path live = s / (".bake.ibl-bake-" + std::to_string(::getpid()) + "-livelive");
    const fs::path other = s / (".other.ibl-bake-" + std::to_string(dead) + "-abcdefgh"); // another DIR's
    for (const fs::path& d : {stale, live, other}) {
        fs::create_directories(d / "sub");
        write_text(d / "specular_l0_px.exr", std::string(1000, 'x'));
        write_text(d / "sub" / "f", "y");
    }
    // killed between the two renames of a swap: DIR is missing, the old DIR lies aside
    const fs::path aside = s / (".bake.ibl-bake-" + std::to_string(dead) + "-qqqqqqqq.old");
    fs::create_directories(aside);
    write_text(aside / "keep.txt", "old bake's neighbour");
    const result r = run(s, with(tiny, {"--out", out.string()}));
    INFO(r.err);
    REQUIRE(r.status == 0);
    CHECK_FALSE(fs::exists(stale));
    CHECK_FALSE(fs::exists(aside));
    CHECK(fs::exists(live / "sub" / "f"));
    CHECK(fs::exists(other / "sub" / "f"));
    CHECK(slurp(out / "keep.txt") == "old bake's neighbour");
    CHECK(fs::exists(out / "report.json"));
}

TEST_CASE("guard: SIGTERM while files are written removes the staging folder and kills with SIGTERM") {
    scratch s("signal");
    const fs::path out = s / "bake";
    fs::create_directories(out);
    write_text(out / "keep.txt", "mine");
    const auto before = snapshot(out);
    // --size 512: about 1 s of computing, then about 1 s of writing files into the staging folder
    const child c = spawn({"--size", "512", "--lut-size", "16", "--quality", "low", "--quiet", "--out", out.string()},
                          s / "stderr.txt");
    bool seen = false;
    const auto t0 = std::chrono::steady_clock::now();
    while (!seen && std::chrono::steady_clock::now() - t0 < std::chrono::seconds(60)) {
        for (const auto& n : stages_in(s.path)) {
            std::error_code ec;
            if (!fs::is_empty(s / n, ec) && !ec) seen = true; // writing has started
        }
        if (::waitpid(c.pid, nullptr, WNOHANG) == c.pid) break;
        if (!seen) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    REQUIRE(seen);
    ::kill(c.pid, SIGTERM);
    const result r = wait_for(c);
    INFO(r.err);
    CHECK(r.signal == SIGTERM);
    CHECK(stages_in(s.path).empty());
    CHECK(snapshot(out) == before);

    // SIGINT while computing (before the staging folder exists): killed, nothing left
    fs::remove_all(out);
    const child c2 = spawn({"--size", "512", "--lut-size", "16", "--quality", "low", "--quiet", "--out", out.string()},
                           s / "stderr.txt");
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    ::kill(c2.pid, SIGINT);
    const result r2 = wait_for(c2);
    CHECK(r2.signal == SIGINT);
    CHECK(stages_in(s.path).empty());
    CHECK_FALSE(fs::exists(out));
}

TEST_CASE("guard: inputs must be regular files of bounded size") {
    scratch s("inputs");
    const fs::path out = s / "bake";
    REQUIRE(::mkfifo((s / "fifo.hdr").c_str(), 0600) == 0);
    fs::create_directories(s / "dir.exr");
    {   // a sparse file above the default bound (4 GiB + 64 MiB): no disk space used
        const int fd = ::open((s / "huge.exr").c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        REQUIRE(fd >= 0);
        REQUIRE(::ftruncate(fd, off_t(5) << 30) == 0);
        ::close(fd);
    }
    write_text(s / "small.hdr", std::string(2000, 'x'));
    const std::vector<std::pair<std::string, std::string>> cases = {
        {"/dev/zero", "character device"},
        {(s / "fifo.hdr").string(), "FIFO"},
        {(s / "dir.exr").string(), "directory"},
        {(s / "huge.exr").string(), "larger than the limit"},
        {(s / "missing.exr").string(), "no such file"},
    };
    for (const auto& c : cases) {
        const std::string& in = c.first;
        const std::string& what = c.second;
        const result r = run(s, with(tiny, {"--input", in, "--out", out.string()}), {}, 10);
        INFO(in, " ", r.err);
        CHECK_FALSE(r.timed_out);
        CHECK(r.status == 1);
        CHECK(has(r.err, in));
        CHECK(has(r.err, what));
        CHECK(r.seconds < 5.0);
        CHECK_FALSE(fs::exists(out));
    }
    // the bound follows --max-input-pixels: 64 MiB + 32 bytes per pixel
    {
        const int fd = ::open((s / "big.hdr").c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        REQUIRE(fd >= 0);
        REQUIRE(::ftruncate(fd, (off_t(64) << 20) + 32 * 1000 + 1) == 0);
        ::close(fd);
    }
    const result r = run(s, with(tiny, {"--input", (s / "big.hdr").string(), "--max-input-pixels", "1000", "--out", out.string()}));
    CHECK(r.status == 1);
    CHECK(has(r.err, "larger than the limit of " + std::to_string((64u << 20) + 32 * 1000)));
    // scene files too
    const result rs = run(s, with(tiny, {"--scene", "/dev/zero", "--out", out.string()}), {}, 10);
    CHECK_FALSE(rs.timed_out);
    CHECK(rs.status == 1);
    CHECK(has(rs.err, "character device"));
    CHECK(stages_in(s.path).empty());
}

namespace {
/// Every value of every specular face file in DIR is finite; returns how many were read.
std::size_t check_faces_finite(const fs::path& dir) {
    std::size_t n = 0;
    for (const auto& name : entries(dir)) {
        if (name.rfind("specular_l", 0) != 0 || name.size() < 4 || name.substr(name.size() - 4) != ".exr") continue;
        const image_rgb32f img = read_image((dir / name).string());
        std::size_t bad = 0;
        for (float v : img.rgb) bad += std::isfinite(v) ? 0 : 1;
        INFO(name);
        CHECK(bad == 0);
        ++n;
    }
    return n;
}

/// report.json holds no null other than the documented "no window" width.
void check_no_nulls(const fs::path& report) {
    std::string text = slurp(report);
    for (const char* ok : {"\"window_width\": null", "\"width\": null"})
        for (std::size_t p; (p = text.find(ok)) != std::string::npos;) text.erase(p, std::string(ok).size());
    INFO(text);
    CHECK_FALSE(has(text, "null"));
}
} // namespace

TEST_CASE("guard: radiance near float's limit is clamped and counted; a black map gives finite metrics") {
    scratch s("radiance");
    image_rgb32f spot(32, 16);
    for (float& v : spot.rgb) v = 0.5f;
    for (int c = 0; c < 3; ++c) spot.texel(5, 5)[c] = 1e37f;
    write_exr((s / "spot.exr").string(), spot);
    image_rgb32f top(32, 16);
    for (float& v : top.rgb) v = 3e38f; // Radiance: written at the largest exponent (2^126)
    write_hdr((s / "top.hdr").string(), top);
    write_exr((s / "top.exr").string(), top);
    write_exr((s / "black.exr").string(), image_rgb32f(32, 16));
    write_hdr((s / "black.hdr").string(), image_rgb32f(32, 16));
    const std::map<std::string, std::size_t> expected_clamped = {
        {"spot.exr", 3}, {"top.hdr", 32 * 16 * 3}, {"top.exr", 32 * 16 * 3}, {"black.exr", 0}, {"black.hdr", 0}};
    for (const auto& e : expected_clamped) {
        const std::string& name = e.first;
        const std::size_t clamped = e.second;
        const fs::path out = s / ("out_" + name);
        const result r = run(s, with(tiny, {"--input", (s / name).string(), "--out", out.string()}));
        INFO(name, " ", r.err);
        REQUIRE(r.status == 0);
        CHECK(check_faces_finite(out) == 18);
        const std::string rep = slurp(out / "report.json");
        CHECK(has(rep, "\"values_clamped\": " + std::to_string(clamped)));
        check_no_nulls(out / "report.json");
    }
}
