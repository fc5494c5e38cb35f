// tools/ibl-bake/tests/test_scene.cpp — `ibl-bake --scene` end to end at tiny sizes:
// the planned products and only those are written, the report says what was left out, bad scene
// files fail with a clear message and leave DIR untouched, --compare-full runs.
#include <doctest/doctest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <sys/wait.h>
#include <unistd.h>

namespace fs = std::filesystem;

namespace {

const std::string tool = IBL_BAKE_TOOL;
const std::string scenes = IBL_BAKE_SCENES_DIR;

struct scratch {
    fs::path path;
    explicit scratch(const std::string& tag) {
        path = fs::temp_directory_path() / ("ibl_bake_scene_tests_" + tag + "_" + std::to_string(::getpid()));
        fs::remove_all(path);
        fs::create_directories(path);
    }
    ~scratch() {
        std::error_code ec;
        fs::remove_all(path, ec);
    }
    std::string operator/(const std::string& name) const { return (path / name).string(); }
};

std::string slurp(const std::string& p) {
    std::ifstream f(p, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
}

struct result {
    int status;
    std::string out, err;
};

result run(const scratch& s, const std::string& args) {
    const std::string out = s / "stdout.txt", err = s / "stderr.txt";
    const int rc = std::system((tool + " " + args + " >" + out + " 2>" + err).c_str());
    return {WIFEXITED(rc) ? WEXITSTATUS(rc) : -1, slurp(out), slurp(err)};
}

std::string write(const scratch& s, const std::string& name, const std::string& text) {
    std::ofstream(s / name, std::ios::binary) << text;
    return s / name;
}

const std::string tiny = " --size 16 --quality low --threads 2 --quiet";

} // namespace

TEST_CASE("scene: rough plastics bake only the planned products") {
    scratch s("rough");
    const result r = run(s, "--scene " + scenes + "/rough_plastics.json --out " + (s / "out") + tiny);
    INFO(r.err);
    REQUIRE(r.status == 0);
    CHECK(fs::exists(s / "out/specular.ktx2"));
    CHECK(fs::exists(s / "out/dfg.exr"));
    CHECK(fs::exists(s / "out/sh.json"));
    CHECK_FALSE(fs::exists(s / "out/preview.png")); // the scene mode bakes products only
    const std::string report = slurp(s / "out/report.json");
    CHECK(report.find("\"left_out\"") != std::string::npos);
    CHECK(report.find("sharp levels 0") != std::string::npos);
    CHECK(report.find("\"first_level\": 1") != std::string::npos); // --size 16: 3 levels, lod(0.5) = 1
    CHECK(slurp(s / "out/sh.json").find("\"bands\": 3") != std::string::npos);
    CHECK(r.out.find("left out:") != std::string::npos);
}

TEST_CASE("scene: metals only write no irradiance, mobile gets 2 bands") {
    scratch s("metal");
    result r = run(s, "--scene " + scenes + "/glossy_metals.json --out " + (s / "out") + tiny);
    INFO(r.err);
    REQUIRE(r.status == 0);
    CHECK_FALSE(fs::exists(s / "out/sh.json"));
    CHECK(slurp(s / "out/report.json").find("diffuse irradiance (SH)") != std::string::npos);
    r = run(s, "--scene " + scenes + "/mobile.json --out " + (s / "mobile") + tiny);
    REQUIRE(r.status == 0);
    CHECK(slurp(s / "mobile/sh.json").find("\"bands\": 2") != std::string::npos);
    CHECK(r.out.find("dfg:      32^2, 2 channels") != std::string::npos);
}

TEST_CASE("scene: --compare-full times the full bake and measures the error") {
    scratch s("compare");
    const std::string scene = write(s, "small.json", R"({"name": "small", "error_target": 0.3,
        "materials": [{"name": "m", "metallic": 0.0, "roughness_range": [0.6, 1.0]}]})");
    const result r = run(s, "--scene " + scene + " --compare-full --out " + (s / "out") + tiny);
    INFO(r.err);
    REQUIRE(r.status == 0);
    const std::string report = slurp(s / "out/report.json");
    CHECK(report.find("\"speedup\"") != std::string::npos);
    CHECK(report.find("\"planned_vs_converged\"") != std::string::npos);
    CHECK(report.find("\"split_sum_vs_reference\"") != std::string::npos);
    CHECK(r.out.find("split-sum approximation vs MIS reference") != std::string::npos);
}

TEST_CASE("scene: bad scene files") {
    scratch s("bad");
    SUBCASE("malformed JSON: line and column, DIR untouched") {
        const std::string scene = write(s, "bad.json", "{\n  \"error_target\": 0.1,\n  \"materials\": [ {\"metallic\": 1,, } ]\n}\n");
        const result r = run(s, "--scene " + scene + " --out " + (s / "out") + tiny);
        CHECK(r.status == 1);
        CHECK(r.err.find("malformed JSON at line 3") != std::string::npos);
        CHECK_FALSE(fs::exists(s / "out"));
    }
    SUBCASE("unknown key and wrong type are named") {
        std::string scene = write(s, "typo.json", R"({"materials": [{"metallic": 0, "roughnes": [0.5]}]})");
        result r = run(s, "--scene " + scene + " --out " + (s / "out") + tiny);
        CHECK(r.status == 1);
        CHECK(r.err.find("materials[0].roughnes: unknown key") != std::string::npos);
        scene = write(s, "type.json", R"({"error_target": "tight", "materials": [{"metallic": 0, "roughness": [0.5]}]})");
        r = run(s, "--scene " + scene + " --out " + (s / "out") + tiny);
        CHECK(r.status == 1);
        CHECK(r.err.find("error_target: expected a number") != std::string::npos);
        CHECK_FALSE(fs::exists(s / "out"));
    }
    SUBCASE("roughness outside [0, 1] is clamped with a warning") {
        const std::string scene = write(s, "clamp.json", R"({"materials": [{"metallic": 0, "roughness": [1.5]}]})");
        const result r = run(s, "--scene " + scene + " --out " + (s / "out") + tiny);
        CHECK(r.status == 0);
        CHECK(r.out.find("warning: material") != std::string::npos);
        CHECK(r.out.find("clamped to [0, 1]") != std::string::npos);
    }
    SUBCASE("missing file, --compare-full without --scene") {
        CHECK(run(s, "--scene " + (s / "nope.json") + " --out " + (s / "out") + tiny).status == 1);
        CHECK(run(s, "--compare-full --out " + (s / "out") + tiny).status == 2);
        CHECK_FALSE(fs::exists(s / "out"));
    }
}
