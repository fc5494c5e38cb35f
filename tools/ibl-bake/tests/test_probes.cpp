// tools/ibl-bake/tests/test_probes.cpp — `ibl-bake --probes probes.json --out DIR` and `--lookup`
// on the probe set it writes. The test makes two small lat-long captures (a pattern and a
// constant), bakes them (--size 16 --quality low) and checks: probes.ktx2 is a cubemap array
// (layerCount 2, faceCount 6, the levels of probes.json); probes.json's fields; `local` at a
// probe's own position (only its influence covers it) equals ibl::specular_lookup on its decoded
// layer; at a point in the overlap the answer is the blend the header of query/probe_lookup.hpp
// describes (computed here from ibl::parallax_correct / corrected_roughness and the weights by
// hand) and lies between the two probes' answers; outside every influence the nearest probe
// answers uncorrected; `local_irradiance` against the SH evaluation of probes.json's coefficients
// (and pi L for the constant capture); malformed probe files fail with exit status 1 and name
// the probe and the key. Also the KTX2 cubemap-array round trip of io/ktx2.hpp.

#include <doctest/doctest.h>

#include "io/cube_layout.hpp"
#include "io/image_io.hpp"
#include "io/json_value.hpp"
#include "io/ktx2.hpp"
#include "tool_test_support.hpp"

#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include <ibl/runtime/local_probe.hpp>
#include <ibl/runtime/lookup.hpp>
#include <ibl/sh/basis.hpp>

using namespace ibl_bake;
using ibl_bake_test::scratch;
using ibl_bake_test::shell;
using ibl_bake_test::slurp;
using dvec3 = ibl::vec3<double>;
using fvec3 = ibl::vec3<float>;

namespace {

const std::string tool = IBL_BAKE_TOOL;

constexpr float constant_b[3] = {0.25f, 0.5f, 1.0f};

/// Capture A: a pattern varying with direction (brighter towards the top, reddish); B: a constant.
void write_captures(const scratch& s) {
    image_rgb32f a(32, 16), b(32, 16);
    for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 32; ++x) {
            const float v = 1.0f - (float(y) + 0.5f) / 16.0f, u = (float(x) + 0.5f) / 32.0f;
            float* t = a.texel(x, y);
            t[0] = 1.0f + 2.0f * v;
            t[1] = 0.5f + 0.5f * u;
            t[2] = 0.2f;
            for (int c = 0; c < 3; ++c) b.texel(x, y)[c] = constant_b[c];
        }
    write_exr(s / "a.exr", a);
    write_hdr(s / "b.hdr", b);
}

// Probe 0 at (-2, 0, 0): proxy the room box [-4, 4] x [-2, 2]^2, influence box [-4, 1] x [-2, 2]^2
// fade 1. Probe 1 at (2, 0, 0): proxy sphere radius 4, influence sphere radius 3 fade 1.
const char* probe_file = R"({"probes": [
  {"input": "a.exr", "position": [-2, 0, 0],
   "proxy": {"box": {"min": [-4, -2, -2], "max": [4, 2, 2]}},
   "influence": {"box": {"min": [-4, -2, -2], "max": [1, 2, 2]}, "fade": 1}},
  {"input": "b.hdr", "position": [2, 0, 0], "priority": 0,
   "proxy": {"sphere": {"center": [2, 0, 0], "radius": 4}},
   "influence": {"sphere": {"center": [2, 0, 0], "radius": 3}, "fade": 1}}
]})";

struct baked_set {
    scratch s{"ibl_probes_test"};
    std::string out;
    int status = -1;
    std::string stdout_text;
    baked_set() {
        write_captures(s);
        std::ofstream(s / "probes.json") << probe_file;
        out = s / "set";
        status = shell(tool + " --probes " + s / "probes.json" + " --out " + out + " --size 16 --quality low --threads 2 >" +
                       s / "stdout.txt" + " 2>" + s / "stderr.txt");
        stdout_text = slurp(s / "stdout.txt");
    }
    /// The answer lines of --lookup for `queries`; *status its exit status.
    std::vector<std::string> lookup(const std::string& queries, int* st = nullptr) const {
        std::ofstream(s / "q.txt") << queries;
        const int r = shell(tool + " --lookup " + out + " <" + s / "q.txt" + " >" + s / "a.txt" + " 2>&1");
        if (st) *st = r;
        std::istringstream in(slurp(s / "a.txt"));
        std::vector<std::string> lines;
        for (std::string l; std::getline(in, l);) lines.push_back(l);
        return lines;
    }
};

const baked_set& the_set() {
    static const baked_set b;
    return b;
}

dvec3 parse3(const std::string& line) {
    std::istringstream in(line);
    dvec3 v(0.0);
    in >> v.x >> v.y >> v.z;
    CHECK_MESSAGE(!in.fail(), line);
    return v;
}

void check_close(const dvec3& a, const dvec3& b, double rel, const std::string& what) {
    for (int c = 0; c < 3; ++c) CHECK_MESSAGE(std::fabs(a[c] - b[c]) <= rel * std::max(1e-6, std::fabs(b[c])), what << " channel " << c << ": " << a[c] << " vs " << b[c]);
}

std::vector<ibl::cubemap<float>> decoded_layers(const std::string& dir) {
    std::vector<ibl::cubemap<float>> out;
    for (const cubemap_rgb32f& c : decode_ktx2_cubemap_array(read_file(dir + "/probes.ktx2"), "probes.ktx2"))
        out.push_back(cubemap_from_rgb32f(c));
    return out;
}

ibl::sh_coeffs<double, 3> sh_of(const ibl_examples::json_value& probe) {
    ibl::sh_coeffs<double, 3> c{};
    const auto& a = probe.find("sh_irradiance")->values;
    for (int k = 0; k < 9; ++k)
        for (int ch = 0; ch < 3; ++ch) c[k][ch] = a.at(std::size_t(k)).values.at(std::size_t(ch)).number;
    return c;
}

/// Runs --probes on `text` (written beside the captures); the exit status and stderr.
int bad_probe_file(const std::string& text, std::string& err) {
    const baked_set& b = the_set();
    std::ofstream(b.s / "bad.json") << text;
    const int st = shell(tool + " --probes " + b.s / "bad.json" + " --out " + b.s / "bad_out" + " --size 16 --quality low 2>" +
                         b.s / "err.txt" + " >/dev/null");
    err = slurp(b.s / "err.txt");
    return st;
}

} // namespace

TEST_CASE("probes: KTX2 cubemap array round trip") {
    std::vector<cubemap_rgb32f> layers;
    for (int i = 0; i < 3; ++i) {
        cubemap_rgb32f c = cubemap_rgb32f::zeros(4, 3);
        for (std::size_t l = 0; l < c.levels.size(); ++l)
            for (int f = 0; f < 6; ++f)
                for (std::size_t k = 0; k < c.levels[l][std::size_t(f)].size(); ++k)
                    c.levels[l][std::size_t(f)][k] = float(i * 1000 + int(l) * 100 + f * 10) + float(k) * 0.25f;
        layers.push_back(c);
    }
    for (const ktx2_format fmt : {ktx2_format::rgba32f, ktx2_format::rgba16f}) {
        const std::vector<unsigned char> b = encode_ktx2_cubemap_array(layers, fmt, "test", "a.ktx2");
        const ktx2_info k = parse_ktx2(b);
        CHECK(k.layer_count == 3);
        CHECK(k.face_count == 6);
        CHECK(k.level_count == 3);
        // level 0: layer-major, then face
        CHECK(k.levels[0].byte_length == 3 * 6 * 16 * ktx2_texel_bytes(fmt));
        const std::vector<cubemap_rgb32f> back = decode_ktx2_cubemap_array(b, "a.ktx2");
        REQUIRE(back.size() == 3);
        for (std::size_t i = 0; i < 3; ++i)
            for (std::size_t l = 0; l < 3; ++l)
                for (std::size_t f = 0; f < 6; ++f)
                    for (std::size_t t = 0; t < back[i].levels[l][f].size(); ++t)
                        CHECK(std::fabs(back[i].levels[l][f][t] - layers[i].levels[l][f][t]) <= 1e-3f * std::fabs(layers[i].levels[l][f][t]));
        CHECK_THROWS_AS(decode_ktx2_cubemap(b, "a.ktx2"), image_error); // an array is not a single cubemap
    }
    // a single cubemap is not an array; layers of different sizes are refused
    CHECK_THROWS_AS(decode_ktx2_cubemap_array(encode_ktx2_cubemap(layers[0], ktx2_format::rgba16f), "s.ktx2"), image_error);
    std::vector<cubemap_rgb32f> mixed = {layers[0], cubemap_rgb32f::zeros(8, 3)};
    CHECK_THROWS_AS(encode_ktx2_cubemap_array(mixed, ktx2_format::rgba16f), image_error);
    CHECK_THROWS_AS(encode_ktx2_cubemap_array({}, ktx2_format::rgba16f), image_error);
    // a damaged layerCount is refused
    std::vector<unsigned char> b = encode_ktx2_cubemap_array(layers, ktx2_format::rgba32f);
    b[32] = 4;
    CHECK_THROWS_AS(decode_ktx2_cubemap_array(b, "x.ktx2"), image_error);
}

TEST_CASE("probes: bake writes a cubemap array and its metadata") {
    const baked_set& b = the_set();
    REQUIRE_MESSAGE(b.status == 0, slurp(b.s / "stderr.txt"));
    CHECK(b.stdout_text.find("probes.ktx2") != std::string::npos);
    CHECK(b.stdout_text.find("probe 1") != std::string::npos);
    const ktx2_info k = parse_ktx2(read_file(b.out + "/probes.ktx2"));
    CHECK(k.layer_count == 2);
    CHECK(k.face_count == 6);
    CHECK(k.pixel_width == 16);
    CHECK(k.vk_format == std::uint32_t(ktx2_format::rgba16f));
    const ibl_examples::json_value j = ibl_examples::parse_json(slurp(b.out + "/probes.json"));
    REQUIRE(j.find("levels"));
    CHECK(k.level_count == std::uint32_t(j.find("levels")->number));
    CHECK(j.find("face_size")->number == 16);
    const ibl_examples::json_value& conv = *j.find("conventions");
    CHECK(conv.find("mapping")->string == "linear");
    CHECK(conv.find("specular_lookup")->string == "textbook");
    REQUIRE(conv.find("level_roughness")->values.size() == k.level_count);
    CHECK(conv.find("level_roughness")->values.front().number == 0.0);
    CHECK(conv.find("level_roughness")->values.back().number == doctest::Approx(1.0));
    const auto& probes = j.find("probes")->values;
    REQUIRE(probes.size() == 2);
    CHECK(probes[0].find("layer")->number == 0);
    CHECK(probes[1].find("layer")->number == 1);
    CHECK(probes[0].find("position")->values[0].number == -2);
    CHECK(probes[0].find("proxy")->find("box")->find("max")->values[0].number == 4);
    CHECK(probes[0].find("influence")->find("box")->find("max")->values[0].number == 1);
    CHECK(probes[0].find("fade")->number == 1);
    CHECK(probes[1].find("proxy")->find("sphere")->find("radius")->number == 4);
    CHECK(probes[1].find("influence")->find("sphere")->find("radius")->number == 3);
    CHECK(probes[1].find("priority")->number == 0);
    CHECK(probes[1].find("sh_irradiance")->values.size() == 9);
    CHECK(probes[1].find("sh_radiance")->values.size() == 9);
    // the constant capture: E = pi L exactly in SH3 (the bake's source cube is that constant)
    const dvec3 e = ibl::sh_evaluate(sh_of(probes[1]), dvec3(0.3, 0.8, -0.52));
    for (int c = 0; c < 3; ++c) CHECK(e[c] == doctest::Approx(ibl::pi_v<double> * constant_b[c]).epsilon(1e-3));
}

TEST_CASE("probes: report.json per probe") {
    const baked_set& b = the_set();
    REQUIRE(b.status == 0);
    CHECK(b.stdout_text.find("report.json") != std::string::npos);
    const ibl_examples::json_value r = ibl_examples::parse_json(slurp(b.out + "/report.json"));
    REQUIRE(r.find("format"));
    CHECK(r.find("format")->string == "ibl-bake probe-set report");
    CHECK(r.find("settings")->find("face_size")->number == 16);
    CHECK(r.find("settings")->find("quality")->string == "low");
    CHECK(r.find("time_ms")->number > 0.0);
    CHECK(r.find("ktx2")->find("bytes")->number == double(read_file(b.out + "/probes.ktx2").size()));
    const ibl_examples::json_value j = ibl_examples::parse_json(slurp(b.out + "/probes.json"));
    const std::size_t levels = std::size_t(j.find("levels")->number);
    const auto& probes = r.find("probes")->values;
    REQUIRE(probes.size() == 2);
    for (std::size_t i = 0; i < 2; ++i) {
        const ibl_examples::json_value& p = probes[i];
        CAPTURE(i);
        CHECK(p.find("layer")->number == double(i));
        CHECK(p.find("input")->string.find(i == 0 ? "a.exr" : "b.hdr") != std::string::npos);
        CHECK(p.find("input_size")->values.at(0).number == 32);
        CHECK(p.find("input_size")->values.at(1).number == 16);
        CHECK(p.find("time_ms")->number > 0.0);
        const auto& lv = p.find("levels")->values;
        REQUIRE(lv.size() == levels);
        for (std::size_t k = 0; k < levels; ++k) {
            CAPTURE(k);
            CHECK(lv[k].find("size")->number == double(16 >> k));
            CHECK(lv[k].find("roughness")->number ==
                  doctest::Approx(j.find("conventions")->find("level_roughness")->values.at(k).number));
            CHECK(lv[k].find("texels_compared")->number > 0);
            const double e = lv[k].find("rel_rmse")->number;
            CHECK(e >= 0.0);
            // the constant capture is filtered exactly (half-float storage aside); the pattern's
            // low-quality chain stays within 10% of its reference
            CHECK(e < (i == 1 ? 1e-3 : 0.1));
        }
        REQUIRE(p.find("ktx2_quantisation"));
    }
    // --lookup still takes the folder as a probe set (its report says so)
    int st = 0;
    const auto lines = b.lookup("local -2 0 0 0 1 0 0.5\n", &st);
    CHECK(st == 0);
    REQUIRE(lines.size() == 1);
    CHECK(lines[0].find("error") == std::string::npos);
}

TEST_CASE("probes: --lookup tells the bake that wrote a folder last by its report.json") {
    // A folder keeps the files a bake does not write: a single bake over a probe set leaves
    // probes.json behind, a probe set over a single bake leaves specular.ktx2; report.json's
    // "format" says which bake wrote the folder last.
    const baked_set& b = the_set();
    REQUIRE(b.status == 0);
    const std::string dir = b.s / "mixed";
    std::filesystem::remove_all(dir);
    std::filesystem::copy(b.out, dir, std::filesystem::copy_options::recursive);
    const auto ask = [&](const std::string& q) {
        std::ofstream(b.s / "mq.txt") << q;
        shell(tool + " --lookup " + dir + " <" + b.s / "mq.txt" + " >" + b.s / "ma.txt" + " 2>&1");
        return slurp(b.s / "ma.txt");
    };
    CHECK(ask("local 0 0 0 0 1 0 0.5\n").find("error") == std::string::npos);
    REQUIRE(shell(tool + " --size 16 --quality low --checks none --threads 2 --quiet --out " + dir + " >/dev/null 2>&1") == 0);
    CHECK(std::filesystem::exists(dir + "/probes.json")); // kept
    CHECK(ask("specular 0 0 1 0.5\n").find("error") == std::string::npos);
    CHECK(ask("local 0 0 0 0 1 0 0.5\n").find("error") == 0); // a single bake now: no local queries
    REQUIRE(shell(tool + " --probes " + b.s / "probes.json" + " --size 16 --quality low --threads 2 --out " + dir + " >/dev/null 2>&1") == 0);
    CHECK(ask("local 0 0 0 0 1 0 0.5\n").find("error") == std::string::npos);
}

TEST_CASE("probes: local lookups blend parallax-corrected probes") {
    const baked_set& b = the_set();
    REQUIRE(b.status == 0);
    const std::vector<ibl::cubemap<float>> layers = decoded_layers(b.out);
    REQUIRE(layers.size() == 2);
    const ibl::specular_lookup_desc desc = ibl::specular_lookup_desc::textbook();
    const auto ld = [&](int i, const dvec3& d, double r) { return dvec3(ibl::specular_lookup(layers[std::size_t(i)], fvec3(d), float(r), desc)); };
    const dvec3 d = glm::normalize(dvec3(0.3, 0.8, -0.5));
    const double r = 0.4;
    const auto lines = b.lookup("# own positions\n"
                                "local -2 0 0 0.3 0.8 -0.5 0.4\n"
                                "local 2 0 0 0.3 0.8 -0.5 0.4\n"
                                "local 0.5 0 0 0.3 0.8 -0.5 0.4\n"
                                "local 100 0 0 0.3 0.8 -0.5 0.4\n"
                                "local_irradiance -2 0 0 0 1 0\n"
                                "local_irradiance 0.5 0 0 0.3 0.8 -0.5\n");
    REQUIRE(lines.size() == 6);
    // at a probe's own position only its influence covers the point: its own chain at (R, r)
    check_close(parse3(lines[0]), ld(0, d, r), 2e-6, "probe 0 at its position");
    check_close(parse3(lines[1]), ld(1, d, r), 2e-6, "probe 1 at its position");
    // P = (0.5, 0, 0): probe 0's weight 0.5 (0.5 inside its box), probe 1's 1 (1.5 inside its
    // sphere); blend_probe_weights: sum 1.5 -> 1/3, 2/3
    const dvec3 p(0.5, 0.0, 0.0);
    const ibl::probe_box<double> box0 = ibl::probe_box<double>::axis_aligned(dvec3(-4, -2, -2), dvec3(4, 2, 2));
    const ibl::probe_sphere<double> ball1{dvec3(2, 0, 0), 4.0};
    const auto l0 = ibl::parallax_correct(box0, dvec3(-2, 0, 0), p, d);
    const auto l1 = ibl::parallax_correct(ball1, dvec3(2, 0, 0), p, d);
    REQUIRE(l0.hit);
    REQUIRE(l1.hit);
    const dvec3 a0 = ld(0, l0.direction, ibl::corrected_roughness(r, l0));
    const dvec3 a1 = ld(1, l1.direction, ibl::corrected_roughness(r, l1));
    const dvec3 blended = parse3(lines[2]);
    check_close(blended, a0 / 3.0 + a1 * (2.0 / 3.0), 1e-5, "blend at (0.5, 0, 0)");
    for (int c = 0; c < 3; ++c) {
        CHECK(blended[c] >= std::min(a0[c], a1[c]) - 1e-6);
        CHECK(blended[c] <= std::max(a0[c], a1[c]) + 1e-6);
    }
    CHECK(std::fabs(a0.x - a1.x) > 0.1); // the captures differ: the blend is not trivial
    // outside every influence: the nearest probe (1), without parallax correction
    check_close(parse3(lines[3]), ld(1, d, r), 2e-6, "nearest probe outside every influence");
    // local_irradiance: the SH evaluation of probes.json's coefficients, blended the same way
    const ibl_examples::json_value j = ibl_examples::parse_json(slurp(b.out + "/probes.json"));
    const auto& probes = j.find("probes")->values;
    const auto e = [&](int i, const dvec3& n) { return glm::max(ibl::sh_evaluate(sh_of(probes[std::size_t(i)]), n), dvec3(0.0)); };
    check_close(parse3(lines[4]), e(0, dvec3(0, 1, 0)), 2e-6, "irradiance of probe 0");
    check_close(parse3(lines[5]), e(0, d) / 3.0 + e(1, d) * (2.0 / 3.0), 1e-6, "blended irradiance");
    // the pattern is brighter above: E(up) > E(down) for probe 0
    CHECK(e(0, dvec3(0, 1, 0)).x > e(0, dvec3(0, -1, 0)).x);
}

TEST_CASE("probes: oriented boxes (center, half_extents, axes)") {
    // One probe, the proxy a box turned 30 degrees about y (axes slightly off unit length and
    // perpendicularity: the reader orthonormalises them), the influence an oriented box with the
    // world's axes. probes.json carries the oriented form; `local` answers with the oriented proxy.
    const baked_set& b = the_set();
    REQUIRE(b.status == 0);
    std::ofstream(b.s / "oriented.json") << R"({"probes": [
  {"input": "a.exr", "position": [0.5, 0, 0],
   "proxy": {"box": {"center": [0, 0, 0], "half_extents": [4, 2, 3],
                     "axes": [[0.86603, 0, -0.5], [0, 1, 0], [0.5, 0, 0.86602]]}},
   "influence": {"box": {"center": [0, 0, 0], "half_extents": [5, 3, 4]}, "fade": 1}}]})";
    const std::string out = b.s / "oriented_set";
    REQUIRE(shell(tool + " --probes " + b.s / "oriented.json" + " --out " + out + " --size 16 --quality low --threads 2 >/dev/null 2>" +
                  b.s / "oriented_err.txt") == 0);
    const ibl_examples::json_value j = ibl_examples::parse_json(slurp(out + "/probes.json"));
    const ibl_examples::json_value& pr = j.find("probes")->values.at(0);
    const ibl_examples::json_value* box = pr.find("proxy")->find("box");
    REQUIRE(box);
    CHECK(!box->find("min"));
    REQUIRE(box->find("axes"));
    const double c30 = std::sqrt(3.0) / 2.0;
    const dvec3 ax0(box->find("axes")->values.at(0).values.at(0).number, box->find("axes")->values.at(0).values.at(1).number,
                    box->find("axes")->values.at(0).values.at(2).number);
    CHECK(glm::length(ax0) == doctest::Approx(1.0).epsilon(1e-12));
    CHECK(ax0.x == doctest::Approx(c30).epsilon(1e-5));
    CHECK(box->find("half_extents")->values.at(2).number == 3);
    REQUIRE(pr.find("influence")->find("box")->find("axes"));
    CHECK(pr.find("influence")->find("box")->find("axes")->values.at(1).values.at(1).number == 1.0);

    ibl::probe_box<double> proxy;
    proxy.center = dvec3(0.0);
    proxy.half = dvec3(4, 2, 3);
    proxy.axis[0] = dvec3(c30, 0, -0.5);
    proxy.axis[1] = dvec3(0, 1, 0);
    proxy.axis[2] = dvec3(0.5, 0, c30);
    const ibl::probe_box<double> aligned = ibl::probe_box<double>::axis_aligned(dvec3(-4, -2, -3), dvec3(4, 2, 3));
    const std::vector<ibl::cubemap<float>> layers = decoded_layers(out);
    REQUIRE(layers.size() == 1);
    const ibl::specular_lookup_desc desc = ibl::specular_lookup_desc::textbook();
    const dvec3 p(-1.5, 0.5, 1.0), c(0.5, 0, 0), d = glm::normalize(dvec3(-0.8, 0.1, 0.3));
    const double r = 0.2;
    const auto corrected = [&](const ibl::probe_box<double>& bx) {
        const auto l = ibl::parallax_correct(bx, c, p, d);
        REQUIRE(l.hit);
        return dvec3(ibl::specular_lookup(layers[0], fvec3(l.direction), float(ibl::corrected_roughness(r, l)), desc));
    };
    std::ofstream(b.s / "oq.txt") << "local -1.5 0.5 1 -0.8 0.1 0.3 0.2\n";
    REQUIRE(shell(tool + " --lookup " + out + " <" + b.s / "oq.txt" + " >" + b.s / "oa.txt" + " 2>&1") == 0);
    const dvec3 got = parse3(slurp(b.s / "oa.txt"));
    check_close(got, corrected(proxy), 1e-5, "oriented proxy");
    // the orientation matters here: the axis-aligned box of the same extents gives another answer
    const dvec3 other = corrected(aligned);
    CHECK(std::fabs(other.x - got.x) + std::fabs(other.y - got.y) > 1e-3);
}

TEST_CASE("probes: options that do not apply to a probe set are refused") {
    const baked_set& b = the_set();
    REQUIRE(b.status == 0);
    const std::string base = tool + " --probes " + b.s / "probes.json" + " --out " + b.s / "refused_out" + " --size 16 --quality low ";
    for (const std::string opt : {"--sheen", "--runtime taps2", "--runtime=lobe", "--preset filament", "--specular-lookup accurate",
                                  "--extract-sun on", "--irradiance-size 8", "--dfg-layout uniform", "--sh-bands 3",
                                  "--sh-window none", "--lut-size 16", "--layout faces", "--checks full", "--verbose",
                                  "--compare-full", "--strict"}) {
        const std::string name = opt.substr(0, opt.find_first_of(" ="));
        CHECK_MESSAGE(shell(base + opt + " 2>" + b.s / "refused.txt" + " >/dev/null") == 2, opt);
        const std::string err = slurp(b.s / "refused.txt");
        CHECK_MESSAGE(err.find(name + " does not apply to --probes") != std::string::npos, err);
        CHECK(!std::filesystem::exists(b.s / "refused_out"));
    }
    // the options a probe set uses are accepted (a usage error would be exit status 2)
    CHECK(shell(base + "--levels 3 --threads 2 --policy filament --ld-weight g1 --prefilter fast --mirror --input-layout auto "
                       "--max-input-pixels 100000 --ktx2-format rgba32f --ktx2-zstd 0 --ktx2-quality fast --quiet >/dev/null 2>" +
                b.s / "accepted.txt") == 0);
    CHECK(std::filesystem::exists(b.s / "refused_out" + "/probes.ktx2"));
}

TEST_CASE("probes: lookup errors on a probe set") {
    const baked_set& b = the_set();
    REQUIRE(b.status == 0);
    int st = 0;
    const auto lines = b.lookup("specular 0 0 1 0.5\nlocal 0 0 0 0 0 0 0.5\nlocal 1 2 3\nlocal_irradiance 0 0 0 0 0 1\n", &st);
    CHECK(st == 1);
    REQUIRE(lines.size() == 4);
    CHECK(lines[0].find("error: line 1") == 0);
    CHECK(lines[0].find("probe set") != std::string::npos);
    CHECK(lines[1].find("error: line 2") == 0);
    CHECK(lines[2].find("takes 7 numbers") != std::string::npos);
    CHECK(lines[3].find("error") == std::string::npos);
}

TEST_CASE("probes: malformed probe files name the probe and the key") {
    const std::string box = R"("proxy": {"box": {"min": [-1, -1, -1], "max": [1, 1, 1]}})";
    const std::string infl = R"("influence": {"box": {"min": [-1, -1, -1], "max": [1, 1, 1]}, "fade": 0.5})";
    const auto one = [&](const std::string& probe) { return R"({"probes": [{"input": "b.hdr", "position": [0, 0, 0], )" + box + ", " + infl + "}, {" + probe + "}]}"; };
    const std::string good = R"("input": "b.hdr", "position": [0, 0, 0], )";
    struct bad_case {
        std::string text, expect;
    };
    std::string many = R"({"probes": [)";
    for (int i = 0; i < 65; ++i) many += std::string(i ? ", " : "") + "{" + good + box + ", " + infl + "}";
    many += "]}";
    const bad_case cases[] = {
        {R"({"probes": [ {"input": "b.hdr",, }]})", "malformed JSON at line 1"},
        {one(R"("input": "b.hdr", )" + box + ", " + infl), "probes[1]: missing \"position\""},
        {one(R"("input": 7, "position": [0, 0, 0], )" + box + ", " + infl), "probes[1].input: expected a string"},
        {one(good + R"("proxy": {"box": {"min": [0, 0, NaN], "max": [1, 1, 1]}}, )" + infl), "probes[1].proxy.box.min[2]: not a finite number"},
        {one(good + R"("proxy": {"box": {"min": [0, 2, 0], "max": [1, 1, 1]}}, )" + infl), "probes[1].proxy.box: min > max along y"},
        {one(good + box + R"(, "influence": {"sphere": {"center": [0, 0, 0], "radius": 0}, "fade": 1})"), "probes[1].influence.sphere.radius: must be > 0"},
        {one(good + box + R"(, "influence": {"sphere": {"center": [0, 0, 0], "radius": 1}, "fade": 0})"), "probes[1].influence.fade: must be > 0"},
        {one(good + box + R"(, "influence": {"sphere": {"center": [0, 0, 0], "radius": 1}})"), "probes[1].influence: missing \"fade\""},
        {one(good + box + ", " + infl + R"(, "priority": 0.5)"), "probes[1].priority: expected an integer"},
        {one(good + box + ", " + infl + R"(, "colour": 1)"), "probes[1].colour: unknown key"},
        {one(good + R"("proxy": {"box": {"min": [0, 0, 0], "center": [1, 1, 1], "half_extents": [1, 1, 1]}}, )" + infl),
         "probes[1].proxy.box: both min/max and center/half_extents/axes"},
        {one(good + R"("proxy": {"box": {"center": [1, 1, 1]}}, )" + infl), "probes[1].proxy.box: missing \"half_extents\""},
        {one(good + R"("proxy": {"box": {"center": [1, 1, 1], "half_extents": [1, -1, 1]}}, )" + infl),
         "probes[1].proxy.box.half_extents[1]: must be >= 0"},
        {one(good + box + R"(, "influence": {"box": {"center": [0, 0, 0], "half_extents": [1, 1, 1], "axes": [[1, 0, 0], [0, 2, 0], [0, 0, 1]]}, "fade": 1})"),
         "probes[1].influence.box.axes[1]: not a unit vector"},
        {one(good + box + R"(, "influence": {"box": {"center": [0, 0, 0], "half_extents": [1, 1, 1], "axes": [[1, 0, 0], [0.6, 0.8, 0], [0, 0, 1]]}, "fade": 1})"),
         "probes[1].influence.box.axes: axes[0] and axes[1] are not perpendicular"},
        {one(good + R"("proxy": {"box": {"center": [0, 0, 0], "half_extents": [1, 1, 1], "axes": [[1, 0, 0], [0, 1, 0]]}}, )" + infl),
         "probes[1].proxy.box.axes: expected 3 axes"},
        {one(good + R"("proxy": {"box": {"center": [0, 0, 0], "half_extents": [1, 1, 1], "rotation": 30}}, )" + infl),
         "probes[1].proxy.box.rotation: unknown key"},
        {R"({"probes": []})", "probes: no probes"},
        {many, "65 probes, at most 64"},
        {R"([1, 2])", "expected an object"},
    };
    for (const bad_case& c : cases) {
        std::string err;
        CHECK_MESSAGE(bad_probe_file(c.text, err) == 1, c.text);
        CHECK_MESSAGE(err.find(c.expect) != std::string::npos, err, " (expected: ", c.expect, ")");
        CHECK_MESSAGE(err.find("bad.json") != std::string::npos, err);
    }
    // a missing capture: exit 1, the output folder not created
    std::string err;
    CHECK(bad_probe_file(one(R"("input": "missing.exr", "position": [0, 0, 0], )" + box + ", " + infl), err) == 1);
    CHECK(err.find("missing.exr") != std::string::npos);
    CHECK(!std::filesystem::exists(the_set().s / "bad_out"));
    // command line: --probes takes no --input
    CHECK(shell(tool + " --probes x.json --input y.exr --out o 2>/dev/null") == 2);
}
