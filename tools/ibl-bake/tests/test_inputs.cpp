// tools/ibl-bake/tests/test_inputs.cpp — end-to-end: cube inputs give the products of the lat-long
// they were made from. A lat-long (tests/data/courtyard.exr) is baked once at face 64 with
// --layout faces,cross,latlong: its level 0 is the source cube, written as six faces, a
// horizontal cross and a lat-long. Baking at face 16 from the six faces and from the cross must
// give bit-identical products (the same texels); from the original lat-long, the same products
// within the resampling difference (the cube inputs are a 64^2 resample of the 1024 x 512 map,
// the lat-long goes to 16^2 directly): SH within 1% of L00, every specular level within 2%
// (relative RMS, measured 0.2-0.6%). A mis-sized or mislabelled cross is refused with a message.

#include <doctest/doctest.h>

#include "io/image_io.hpp"
#include "tool_test_support.hpp"
#include "io/json_value.hpp"

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <sys/wait.h>
#include <unistd.h>

namespace fs = std::filesystem;
using namespace ibl_bake;
using ibl_bake_test::scratch;
using ibl_bake_test::shell;
using ibl_bake_test::level_rel_rms;
using ibl_bake_test::sh_radiance;
using ibl_bake_test::slurp;

namespace {

const std::string tool = IBL_BAKE_TOOL;
const std::string data_dir = IBL_BAKE_TEST_DATA_DIR;

int run(const scratch& s, const std::string& args, std::string* err = nullptr) {
    const std::string e = s / "stderr.txt";
    const int st = shell(tool + " --quiet --quality low --lut-size 16 " + args + " >/dev/null 2>" + e);
    if (err) *err = slurp(e);
    return st;
}

} // namespace

TEST_CASE("inputs: six faces and a cross give the lat-long's products") {
    scratch s("ibl_bake_input_tests");
    const std::string ll = data_dir + "/courtyard.exr";
    REQUIRE(run(s, "--input " + ll + " --size 64 --levels 1 --layout faces,cross,latlong --out " + (s / "cube64")) == 0);
    REQUIRE(run(s, "--input " + ll + " --size 16 --out " + (s / "from_latlong")) == 0);
    REQUIRE(run(s, "--input " + (s / "cube64/specular_l0_cross.exr") + " --size 16 --out " + (s / "from_cross")) == 0);
    REQUIRE(run(s, "--input '" + (s / "cube64/specular_l0_{face}.exr") + "' --size 16 --out " + (s / "from_faces")) == 0);
    // The lat-long of the cube is a 2:1 image: it is read as a lat-long (aspect-ratio detection).
    REQUIRE(run(s, "--input " + (s / "cube64/specular_l0_latlong.exr") + " --size 16 --out " + (s / "from_ll64")) == 0);

    for (const char* f : {"sh.json", "specular.ktx2", "dfg.exr", "specular_l1_px.exr", "specular_l2_nz.exr"}) {
        INFO(f);
        CHECK(slurp(s / ("from_faces/" + std::string(f))) == slurp(s / ("from_cross/" + std::string(f))));
    }
    const std::vector<double> a = sh_radiance(s / "from_latlong"), b = sh_radiance(s / "from_cross"),
                              c = sh_radiance(s / "from_ll64");
    REQUIRE(a.size() == 27);
    double worst = 0.0, worst_ll = 0.0;
    for (std::size_t i = 0; i < a.size(); ++i) {
        worst = std::max(worst, std::fabs(a[i] - b[i]) / a[i % 3]);
        worst_ll = std::max(worst_ll, std::fabs(a[i] - c[i]) / a[i % 3]);
    }
    MESSAGE("SH: cross vs lat-long max |diff| / L00 = " << worst << ", lat-long of the cube: " << worst_ll);
    CHECK(worst < 1e-2);
    CHECK(worst_ll < 1e-2);
    for (int l = 0; l < 3; ++l) {
        const double e = level_rel_rms(s / "from_cross", s / "from_latlong", l);
        MESSAGE("specular level " << l << ": cross vs lat-long rel RMS " << e);
        CHECK(e < 2e-2);
    }
}

TEST_CASE("inputs: a mis-sized or mislabelled cross is refused") {
    scratch s("ibl_bake_input_tests");
    write_exr(s / "odd.exr", image_rgb32f(40, 31)); // neither 2:1, 4:3, 3:4 nor a strip
    std::string err;
    CHECK(run(s, "--input " + (s / "odd.exr") + " --size 16 --out " + (s / "o1"), &err) == 1);
    CHECK(err.find("odd.exr") != std::string::npos);
    CHECK(err.find("40") != std::string::npos);
    CHECK_FALSE(fs::exists(s / "o1"));
    write_exr(s / "ll.exr", image_rgb32f(32, 16)); // a lat-long declared a cross
    CHECK(run(s, "--input " + (s / "ll.exr") + " --input-layout hcross --size 16 --out " + (s / "o2"), &err) == 1);
    CHECK(err.find("ll.exr") != std::string::npos);
    CHECK_FALSE(fs::exists(s / "o2"));
    CHECK(run(s, "--input '" + (s / "missing_{face}.exr") + "' --size 16 --out " + (s / "o3"), &err) == 1);
    CHECK(err.find("missing_px.exr") != std::string::npos);
}
