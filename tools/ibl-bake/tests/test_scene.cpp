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
    // diffuse target 0.1 is below 3-band SH's 0.120 (windowed, plan.hpp): an irradiance map
    CHECK(fs::exists(s / "out/irradiance.ktx2"));
    CHECK_FALSE(fs::exists(s / "out/sh.json"));
    CHECK_FALSE(fs::exists(s / "out/preview.png")); // the scene mode bakes products only
    const std::string report = slurp(s / "out/report.json");
    CHECK(report.find("\"left_out\"") != std::string::npos);
    CHECK(report.find("sharp levels 0") != std::string::npos);
    CHECK(report.find("\"first_level\": 1") != std::string::npos); // --size 16: 3 levels, lod(0.5) = 1
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

TEST_CASE("scene: the targets are checked by default and reported") {
    scratch s("targets");
    const result r = run(s, "--scene " + scenes + "/mobile.json --out " + (s / "out") + tiny);
    INFO(r.err);
    REQUIRE(r.status == 0);
    CHECK(r.out.find("scene targets") != std::string::npos);
    CHECK(r.out.find("specular  target 0.2") != std::string::npos);
    CHECK(r.out.find("diffuse   target 0.5") != std::string::npos);
    const std::string report = slurp(s / "out/report.json");
    CHECK(report.find("\"target_check\"") != std::string::npos);
    CHECK(report.find("\"product\": \"specular\"") != std::string::npos);
    CHECK(report.find("\"product\": \"diffuse\"") != std::string::npos);
    CHECK(report.find("\"measured\"") != std::string::npos);
    CHECK(report.find("\"met\"") != std::string::npos);
    CHECK(report.find("\"uncertainty\"") != std::string::npos);
}

TEST_CASE("scene: a missed target warns; --strict makes it an error and writes nothing") {
    scratch s("strict");
    // a target far below what 2-band SH and the sample table reach: missed on any environment
    const std::string scene = write(s, "tight.json", R"({"name": "tight", "error_target": 0.001,
        "limits": {"max_sh_bands": 2, "max_samples": 64},
        "materials": [{"name": "m", "metallic": 0.0, "roughness_range": [0.3, 0.9]}]})");
    result r = run(s, "--scene " + scene + " --out " + (s / "out") + tiny);
    INFO(r.err);
    REQUIRE(r.status == 0);
    CHECK(r.err.find("warning: scene target missed: specular") != std::string::npos);
    CHECK(r.out.find("MISSED") != std::string::npos);
    const std::string report = slurp(s / "out/report.json");
    CHECK(report.find("\"all_met\": false") != std::string::npos);
    CHECK(report.find("\"met\": false") != std::string::npos);

    r = run(s, "--scene " + scene + " --strict --out " + (s / "strict") + tiny);
    CHECK(r.status == 1);
    CHECK(r.err.find("--strict: scene target missed") != std::string::npos);
    CHECK_FALSE(fs::exists(s / "strict")); // all or nothing: the products are not kept

    // an existing DIR is left as it was
    fs::create_directories(s / "kept");
    write(s, "kept/marker.txt", "x");
    r = run(s, "--scene " + scene + " --strict --out " + (s / "kept") + tiny);
    CHECK(r.status == 1);
    CHECK(fs::exists(s / "kept/marker.txt"));
    CHECK_FALSE(fs::exists(s / "kept/report.json"));

    CHECK(run(s, "--strict --out " + (s / "nos") + tiny).status == 2); // --strict needs --scene
}

TEST_CASE("scene: the header and report.json give the sizes the plan bakes") {
    scratch s("sizes");
    const result r = run(s, "--scene " + scenes + "/mobile.json --size 256 --quality low --threads 2 --quiet --verbose --out " + (s / "out"));
    INFO(r.err);
    REQUIRE(r.status == 0);
    // mobile at --size 256: virtual base 128 (screen cap 64 at level 1), stored levels 1..5, DFG 32^2
    CHECK(r.out.find("size 64, 5 levels (1..5 of 0..5), LUT 32") != std::string::npos);
    CHECK(r.out.find("  level 1    64x64") != std::string::npos); // level 0 = the mirror level, everywhere
    CHECK(r.out.find("  l1 64x64 r=0.20") != std::string::npos);
    const std::string report = slurp(s / "out/report.json");
    CHECK(report.find("\"face_size\": 64") != std::string::npos);
    CHECK(report.find("\"stored_levels\": 5") != std::string::npos);
    CHECK(report.find("\"lut_size\": 32") != std::string::npos);
}
