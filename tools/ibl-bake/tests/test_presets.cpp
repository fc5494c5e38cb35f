// tools/ibl-bake/tests/test_presets.cpp — --preset filament and gltf change exactly the conventions
// docs/ibl-bake.md lists, each checked here against a default bake told the same conventions by
// hand (so the products must agree): filament's mirror (x -> -x) moves the sun to -x, its chain
// follows lod = r (2 - r) (level roughness 1 - sqrt(1 - l/(V - 1))), its DFG table stores
// (B, A + B) so that mix(dfg.x, dfg.y, F0) = F0 A + B, and its KTX2 records what a loader needs;
// gltf keeps the linear chain and the (A, B) texel-centre table. --lookup answers the same DFG
// queries for both tables.

#include <doctest/doctest.h>

#include "io/image_io.hpp"
#include "tool_test_support.hpp"
#include "io/json_value.hpp"
#include "io/ktx2.hpp"
#include <ibl/bake/prefilter.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <cstdio>
#include <iterator>
#include <sstream>
#include <map>
#include <string>

#include <sys/wait.h>
#include <unistd.h>

namespace fs = std::filesystem;
using namespace ibl_bake;
using ibl_bake_test::scratch;
using ibl_bake_test::shell;
using ibl_bake_test::slurp;

namespace {

const std::string tool = IBL_BAKE_TOOL;

} // namespace

TEST_CASE("presets: filament and gltf change the documented conventions") {
    scratch s("ibl_bake_preset_tests");
    const std::string base = tool + " --quiet --size 32 --quality low --lut-size 32 ";
    REQUIRE(shell(base + "--preset filament --out " + (s / "fil") + " >/dev/null") == 0);
    REQUIRE(shell(base + "--preset gltf --out " + (s / "gltf") + " >/dev/null") == 0);
    REQUIRE(shell(base + "--dfg-layout uniform --specular-lookup textbook --extract-sun off --irradiance-size 0 --ld-weight nl "
                         "--runtime split-sum --out " + (s / "ref") + " >/dev/null") == 0);
    const auto fil = ibl_examples::parse_json(slurp(s / "fil/report.json"));
    const auto ref = ibl_examples::parse_json(slurp(s / "ref/report.json"));
    // mirror: the brightest direction's x flips, y and z stay
    const auto& bf = fil.find("source")->find("brightest_direction")->values;
    const auto& br = ref.find("source")->find("brightest_direction")->values;
    CHECK(bf[0].number == doctest::Approx(-br[0].number));
    CHECK(bf[1].number == doctest::Approx(br[1].number));
    // the chain's levels follow lod = (V - 1) r (2 - r): r_l = 1 - sqrt(1 - l / (V - 1))
    const auto& lv = fil.find("specular")->find("levels")->values;
    REQUIRE(lv.size() == 4);
    for (std::size_t l = 0; l < lv.size(); ++l)
        CHECK(lv[l].find("roughness")->number == doctest::Approx(1.0 - std::sqrt(1.0 - double(l) / 3.0)));
    CHECK(fil.find("plan")->find("runtime")->find("policy")->string == "filament");
    // the specular section names the policy the chain was baked with
    CHECK(fil.find("specular")->find("mip_policy")->string.rfind("filament: ", 0) == 0);
    CHECK(ref.find("specular")->find("mip_policy")->string.rfind("linear: ", 0) == 0);
    // report.json names the KTX2 storage actually written (every --ktx2-format value)
    CHECK(ref.find("options")->find("ktx2_format")->string == "rgba16f");
    REQUIRE(shell(tool + " --quiet --size 8 --quality low --lut-size 8 --checks none --ktx2-format e5b9g9r9 --out " +
                  (s / "e5") + " >/dev/null") == 0);
    CHECK(ibl_examples::parse_json(slurp(s / "e5/report.json")).find("options")->find("ktx2_format")->string == "e5b9g9r9");
    // the DFG table: filament stores (B, A + B); gltf and the reference (A, B) at texel centres
    const image_rgb32f tf = read_image(s / "fil/dfg.exr"), tr = read_image(s / "ref/dfg.exr"), tg = read_image(s / "gltf/dfg.exr");
    REQUIRE(tf.rgb.size() == tr.rgb.size());
    for (int j = 0; j < 32; ++j)
        for (int i = 0; i < 32; ++i) {
            const float a = tr.texel(i, j)[0], b = tr.texel(i, j)[1];
            CHECK(tf.texel(i, j)[0] == b);
            CHECK(tf.texel(i, j)[1] == a + b);
            CHECK(tg.texel(i, j)[0] == a);
            CHECK(tg.texel(i, j)[1] == b);
        }
    // --lookup undoes the channel layout: the same (A, B) from both folders
    std::ofstream(s / "q.txt") << "dfg 0.3 0.4\ndfg 0.02 0.9\n";
    REQUIRE(shell(tool + " --lookup " + (s / "fil") + " < " + (s / "q.txt") + " > " + (s / "af.txt")) == 0);
    REQUIRE(shell(tool + " --lookup " + (s / "ref") + " < " + (s / "q.txt") + " > " + (s / "ar.txt")) == 0);
    CHECK(slurp(s / "af.txt") == slurp(s / "ar.txt"));
    // the KTX2 records the loader's facts
    const std::string k = slurp(s / "fil/specular.ktx2");
    const ktx2_info info = parse_ktx2(std::span<const unsigned char>(reinterpret_cast<const unsigned char*>(k.data()), k.size()));
    std::map<std::string, std::string> kv(info.key_values.begin(), info.key_values.end());
    CHECK(kv["ibl.preset"] == "filament");
    CHECK(kv["ibl.ld_weight"] == "nl"); // the engines' n.l chain and split sum
    CHECK(kv["ibl.runtime"] == "split-sum");
    CHECK(fil.find("plan")->find("runtime")->find("runtime_model")->find("name")->string == "split-sum");
    CHECK(fil.find("plan")->find("runtime")->find("ld_weight")->find("name")->string == "nl");
    CHECK_FALSE(fs::exists(s / "fil/lobe_lut.exr"));
    CHECK_FALSE(fs::exists(s / "gltf/lobe_lut.exr"));
    for (const char* d : {"fil", "gltf"}) // nor the two-tap table
        for (const char* f : {"lobe_taps_a.exr", "lobe_taps_b.exr", "lobe_taps.hpp"}) CHECK_FALSE(fs::exists(s / (std::string(d) + "/" + f)));
    CHECK(kv["ibl.first_level"] == "0");
    CHECK(kv["ibl.virtual_levels"] == "4");
    CHECK(kv["ibl.policy"].rfind("filament", 0) == 0);
    CHECK(kv["ibl.level_roughness"].find(' ') != std::string::npos);
    CHECK(kv.count("KTXwriter") == 1);
    // Filament's SH text: 9 lines "(r, g, b); // L.." = sh.json's shader coefficients (E / pi)
    {
        const auto shj = ibl_examples::parse_json(slurp(s / "fil/sh.json"));
        const ibl_examples::json_value* w = shj.find("irradiance_over_pi_shader_windowed");
        const auto& k = (w ? *w : *shj.find("irradiance_over_pi_shader")).values;
        std::istringstream txt(slurp(s / "fil/sh.txt"));
        std::string line;
        std::size_t n = 0;
        while (std::getline(txt, line)) {
            REQUIRE(n < k.size());
            double r = 0, g = 0, b = 0;
            char name[16] = {};
            REQUIRE(std::sscanf(line.c_str(), "(%lf, %lf, %lf); // %15s", &r, &g, &b, name) == 4);
            CHECK(r == doctest::Approx(k[n].values[0].number).epsilon(1e-8));
            CHECK(g == doctest::Approx(k[n].values[1].number).epsilon(1e-8));
            CHECK(b == doctest::Approx(k[n].values[2].number).epsilon(1e-8));
            ++n;
        }
        CHECK(n == 9);
        CHECK_FALSE(fs::exists(s / "gltf/sh.txt"));
    }
    // gltf: linear chain, no mirror
    const auto gl = ibl_examples::parse_json(slurp(s / "gltf/report.json"));
    CHECK(gl.find("source")->find("brightest_direction")->values[0].number == doctest::Approx(br[0].number));
    CHECK(gl.find("specular")->find("levels")->values[1].find("roughness")->number == doctest::Approx(1.0 / 3.0));
}

TEST_CASE("--prefilter fast: the chain by the fast filter, named in report.json with the samples it used") {
    scratch s("ibl_bake_prefilter_tests");
    const std::string base = tool + " --quiet --size 32 --lut-size 8 ";
    REQUIRE(shell(base + "--prefilter fast --out " + (s / "fast") + " >/dev/null") == 0);
    REQUIRE(shell(base + "--out " + (s / "fis") + " >/dev/null") == 0);
    const auto fast = ibl_examples::parse_json(slurp(s / "fast/report.json"));
    const auto fis = ibl_examples::parse_json(slurp(s / "fis/report.json"));
    CHECK(fast.find("options")->find("prefilter")->string == "fast");
    CHECK(fis.find("options")->find("prefilter")->string == "fis");
    CHECK(fast.find("specular")->find("prefilter")->string == "fast");
    CHECK(fast.find("specular")->find("method")->string.rfind("GGX fast filter", 0) == 0);
    const auto& lf = fast.find("specular")->find("levels")->values;
    const auto& li = fis.find("specular")->find("levels")->values;
    REQUIRE(lf.size() == li.size());
    REQUIRE(lf.size() >= 3);
    for (std::size_t l = 1; l < lf.size(); ++l) {
        CAPTURE(l);
        // The fast filter's samples are the plan's / 8 (at least 8) times 2^(l - 1): the
        // equal-cost schedule 64 * 4^(l - 1) at the default quality, read from the nearest level.
        CHECK(lf[l].find("samples")->number == std::max(8.0, li[l].find("samples")->number / 8.0) * std::exp2(double(l - 1)));
        CHECK(lf[l].find("samples")->number == 64.0 * std::exp2(2.0 * double(l - 1)));
        CHECK(lf[l].find("samples")->number == double(ibl::equal_cost_prefilter_samples(64, int(l))));
        CHECK_FALSE(lf[l].find("trilinear")->boolean);
        // Checked at the same texels against the same reference as the FIS chain.
        CHECK(std::isfinite(lf[l].find("rel_rmse")->number));
        CHECK(lf[l].find("texels_compared")->number == li[l].find("texels_compared")->number);
    }
    // More samples (--quality high: 256 * 4^(l - 1), at most 16384) give a smaller error on every level >= 1.
    REQUIRE(shell(base + "--prefilter fast --quality high --out " + (s / "high") + " >/dev/null") == 0);
    const auto high = ibl_examples::parse_json(slurp(s / "high/report.json"));
    const auto& lh = high.find("specular")->find("levels")->values;
    REQUIRE(lh.size() == lf.size());
    for (std::size_t l = 1; l < lf.size(); ++l) {
        CAPTURE(l);
        CHECK(lh[l].find("rel_rmse")->number < lf[l].find("rel_rmse")->number);
    }
    CHECK(shell(base + "--prefilter slow --out " + (s / "bad") + " >/dev/null 2>&1") == 2);
}

TEST_CASE("--fast-peaks: the fast filter's peak split, reported in report.json; it lowers the error on the sky with a sun") {
    scratch s("ibl_bake_fast_peaks_tests");
    const std::string base = tool + " --quiet --size 64 --lut-size 8 --threads 2 --prefilter fast ";
    REQUIRE(shell(base + "--out " + (s / "on") + " >/dev/null") == 0);
    REQUIRE(shell(base + "--fast-peaks 0 --out " + (s / "off") + " >/dev/null") == 0);
    REQUIRE(shell(base + "--fast-peaks 5 --out " + (s / "five") + " >/dev/null") == 0);
    const auto on = ibl_examples::parse_json(slurp(s / "on/report.json"));
    const auto off = ibl_examples::parse_json(slurp(s / "off/report.json"));
    const auto five = ibl_examples::parse_json(slurp(s / "five/report.json"));
    const auto* p = on.find("specular")->find("peaks");
    REQUIRE(p != nullptr);
    CHECK(p->find("enabled")->boolean);
    CHECK(p->find("max_peaks")->number == 1024.0);
    CHECK(p->find("count")->number >= 1.0);
    CHECK(p->find("count")->number <= 1024.0);
    CHECK(p->find("threshold")->number >= p->find("ratio")->number * p->find("mean_luminance")->number);
    CHECK(on.find("specular")->find("method")->string.find("peak split") != std::string::npos);
    CHECK_FALSE(off.find("specular")->find("peaks")->find("enabled")->boolean);
    CHECK(five.find("specular")->find("peaks")->find("count")->number <= 5.0);
    CHECK(five.find("specular")->find("peaks")->find("threshold")->number >= p->find("threshold")->number);
    // The built-in sky's sun is 10^4 times the sky: the split takes the tap set's error away.
    const auto& lo = on.find("specular")->find("levels")->values;
    const auto& lf = off.find("specular")->find("levels")->values;
    REQUIRE(lo.size() == lf.size());
    for (std::size_t l = 1; l < lo.size(); ++l) {
        CAPTURE(l);
        CHECK(lo[l].find("rel_rmse")->number < 0.5 * lf[l].find("rel_rmse")->number);
    }
    CHECK(shell(base + "--fast-peaks -1 --out " + (s / "bad") + " >/dev/null 2>&1") == 2);
}

TEST_CASE("--ktx2-format bc6h / astc: the compression check in report.json, Zstandard files, every KTX2 in the format") {
    scratch s("ibl_bake_compression_tests");
    const std::string base = tool + " --quiet --size 32 --lut-size 8 --quality low --threads 2 ";
    REQUIRE(shell(base + "--ktx2-format bc6h --out " + (s / "bc6h") + " >/dev/null") == 0);
    REQUIRE(shell(base + "--ktx2-format astc4x4 --ktx2-quality fast --ktx2-zstd 5 --out " + (s / "astc") + " >/dev/null") == 0);
    REQUIRE(shell(base + "--out " + (s / "f16") + " >/dev/null") == 0);
    for (const char* dir : {"bc6h", "astc"}) {
        CAPTURE(dir);
        const auto r = ibl_examples::parse_json(slurp(s / (std::string(dir) + "/report.json")));
        const ibl_examples::json_value* c = r.find("compression");
        REQUIRE(c);
        const bool bc6h = std::string(dir) == "bc6h";
        CHECK(c->find("format")->string == (bc6h ? "bc6h" : "astc4x4"));
        CHECK(c->find("quality")->string == (bc6h ? "normal" : "fast"));
        CHECK(c->find("zstd_level")->number == (bc6h ? 0.0 : 5.0));
        CHECK(c->find("file_bytes")->number == double(fs::file_size(s / (std::string(dir) + "/specular.ktx2"))));
        const double bpt = c->find("bits_per_texel")->number;
        if (bc6h) CHECK(bpt > 8.0); // 8 bits per texel plus the header and the 1-block levels' padding
        else CHECK(bpt < 8.0);      // Zstandard on top
        CHECK(c->find("encode_ms")->number > 0.0);
        const auto& levels = c->find("levels")->values;
        CHECK(levels.size() == r.find("specular")->find("levels")->values.size());
        for (const auto& l : levels) {
            CHECK(l.find("rmsle")->number > 0.0);
            CHECK(l.find("rmsle")->number < 0.1);
            CHECK(std::isfinite(l.find("seam_step_compressed")->number));
        }
        const double shaded = c->find("lookup")->find("rel_rmse_r_ge_0_25")->number;
        CHECK(shaded > 0.0);
        CHECK(shaded < 0.05);
        CHECK(c->find("preview_rel_rmse")->number < 0.05);
        // every KTX2 of the bake in the format
        for (const char* file : {"specular.ktx2", "irradiance.ktx2"}) {
            const std::vector<unsigned char> bytes = ibl_bake::read_file(s / (std::string(dir) + "/" + file));
            const ibl_bake::ktx2_info k = ibl_bake::parse_ktx2(bytes);
            CHECK(k.vk_format == (bc6h ? 143u : 1000066000u));
            CHECK(k.supercompression == (bc6h ? 0u : 2u));
        }
    }
    // the uncompressed bake has no compression section
    CHECK_FALSE(ibl_examples::parse_json(slurp(s / "f16/report.json")).find("compression"));
    CHECK(shell(base + "--ktx2-format bc7 --out " + (s / "bad") + " >/dev/null 2>&1") == 2);
    CHECK(shell(base + "--ktx2-zstd 23 --out " + (s / "bad") + " >/dev/null 2>&1") == 2);
}
