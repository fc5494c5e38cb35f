// tools/ibl-bake/tests/test_lookup_mode.cpp — `ibl-bake --lookup DIR` answers as the library's
// runtime functions do on the files of DIR. A tiny bake is made; the test loads its files itself
// (specular.ktx2 decoded to an ibl::cubemap, dfg.exr to an ibl::dfg_lut, sh.json's shader
// coefficients, lobe_lut.exr + lobe_lut_b.exr, lobe_taps_a.exr + lobe_taps_b.exr) and evaluates
// ibl::specular_lookup, ibl::dfg_lookup, ibl::sh_shader_evaluate, ibl::lobe_lut_lookup, the
// two-tap table's bilinear read and pbr_shader::ambient (multiple scattering) on the bake's
// runtime model (the accurate preset's lobe model: ibl::specular_lobe_pair's effective LD, ibl::lobe_pair_ld; taps2: ibl::specular_lobe_taps; split-sum:
// LD(R, r) DFG) at the
// same queries; every answer must agree to float precision (relative 2e-6, about 16 float ulps:
// the answers are printed with 9 digits). Malformed queries get an error line each and exit
// status 1; comments and blank lines get no answer.

#include <doctest/doctest.h>

#include "io/cube_layout.hpp"
#include "io/image_io.hpp"
#include "tool_test_support.hpp"
#include "io/json_value.hpp"
#include "io/ktx2.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <map>
#include <string>
#include <vector>

#include <sys/wait.h>
#include <unistd.h>

#include <ibl/bake/dfg_lut.hpp>
#include <ibl/reference/disk_light.hpp>
#include <ibl/bake/lobe_fit.hpp>
#include <ibl/bake/lobe_moments.hpp>
#include <ibl/runtime/lookup.hpp>
#include <ibl/runtime/specular_models.hpp>
#include <ibl/sh/convolve.hpp>
#include <ibl/runtime/shade.hpp>

namespace fs = std::filesystem;
using namespace ibl_bake;
using ibl_bake_test::scratch;
using ibl_bake_test::shell;
using ibl_bake_test::slurp;
using dvec3 = ibl::vec3<double>;
using fvec3 = ibl::vec3<float>;

namespace {

const std::string tool = IBL_BAKE_TOOL;

/// The chain lookup of --preset accurate: log-geometric on its levels spaced lod = (V - 1) r (2 - r)
/// (a chain read from a file carries no mapping: the reader states it, as a renderer does).
ibl::specular_lookup_desc accurate_preset_lookup() {
    ibl::specular_lookup_desc d = ibl::specular_lookup_desc::accurate();
    d.mapping = ibl::roughness_mapping::filament;
    return d;
}

ibl::cubemap<float> load_chain(const std::string& path) {
    const std::string b = slurp(path);
    return cubemap_from_rgb32f(
        decode_ktx2_cubemap(std::span<const unsigned char>(reinterpret_cast<const unsigned char*>(b.data()), b.size())));
}

/// The layout a table file records (ibl.dfg_layout).
ibl::dfg_lut_layout layout_of(const std::string& path) {
    for (const auto& [k, v] : read_exr_string_attributes(path))
        if (k == "ibl.dfg_layout") return ibl::parse_dfg_lut_layout(v);
    FAIL("no ibl.dfg_layout in " << path);
    return {};
}

ibl::dfg_lut load_lut(const std::string& path) {
    const image_rgb32f img = read_image(path);
    ibl::dfg_lut lut{std::uint32_t(img.width), 3, {}, layout_of(path)};
    for (int j = 0; j < img.height; ++j)
        for (int i = 0; i < img.width; ++i)
            for (int c = 0; c < 3; ++c) lut.data.push_back(img.texel(i, j)[c]);
    return lut;
}

ibl::lobe_lut load_lobe(const std::string& path) {
    const image_rgba32f img = read_exr_rgba(path);
    ibl::lobe_lut lut;
    lut.size = std::uint32_t(img.width);
    lut.data = img.rgba;
    lut.layout = layout_of(path);
    return lut;
}

/// The effective LD of the two-part lobe model (ibl::lobe_pair_ld) for a material, formed as the
/// tool forms it: R in double, the directions in float, each chain read by the accurate lookup.
dvec3 lobe_pair_ld(const ibl::cubemap<float>& chain, const ibl::lobe_lut& lobe, const ibl::lobe_lut& lobe_b, const dvec3& n,
                   const dvec3& v, double r, const dvec3& f0, const dvec3& f90) {
    const ibl::specular_lookup_desc sd = accurate_preset_lookup();
    const double ndv = std::clamp(glm::dot(n, v), 0.0, 1.0);
    const dvec3 r_dir = 2.0 * glm::dot(n, v) * n - v;
    const ibl::vec4<float> pa = ibl::lobe_lut_lookup(lobe, float(ndv), float(r));
    const ibl::vec4<float> pb = ibl::lobe_lut_lookup(lobe_b, float(ndv), float(r));
    const fvec3 d_a = ibl::lerp_direction(fvec3(n), fvec3(r_dir), pa.z);
    const fvec3 d_b = ibl::lobe_pair_direction_b(fvec3(n), fvec3(r_dir), pb.x, float(ndv));
    const dvec3 ld_a(ibl::specular_lookup(chain, fvec3(dvec3(d_a)), pa.w, sd));
    const dvec3 ld_b(ibl::specular_lookup(chain, fvec3(dvec3(d_b)), pb.y, sd));
    return ibl::lobe_pair_ld(ld_a, ld_b, f0, f90, ibl::vec2<double>(pa.x, pa.y));
}

/// The two-tap table from its two RGBA files (channels 0..3 and 4..7).
ibl::lobe_taps_lut load_taps(const std::string& a_path, const std::string& b_path) {
    const image_rgba32f a = read_exr_rgba(a_path), b = read_exr_rgba(b_path);
    REQUIRE(a.width == b.width);
    ibl::lobe_taps_lut lut;
    lut.size = std::uint32_t(a.width);
    lut.taps = 2;
    lut.channels = 8;
    lut.layout = layout_of(a_path);
    for (std::size_t k = 0; k < std::size_t(lut.size) * lut.size; ++k) {
        for (std::size_t c = 0; c < 4; ++c) lut.data.push_back(a.rgba[4 * k + c]);
        for (std::size_t c = 0; c < 4; ++c) lut.data.push_back(b.rgba[4 * k + c]);
    }
    return lut;
}

/// The table's 8 channels at (n.v, r): one bilinear read in the DFG layout.
std::vector<double> taps_read(const ibl::lobe_taps_lut& t, double n_dot_v, double r) {
    const ibl::vec2<float> st = ibl::dfg_lut_coord(float(n_dot_v), float(r), t.size, t.layout);
    float p[8] = {};
    ibl::detail::table_bilinear(t, st.x, st.y, p, 8);
    return std::vector<double>(p, p + 8);
}

/// LD of the two-tap model at (n, v, r): ibl::specular_lobe_taps with F0 = F90 = 1 gives LD (A + B).
dvec3 taps_ld(const ibl::cubemap<float>& chain, const ibl::lobe_taps_lut& t, const dvec3& n, const dvec3& v, double r) {
    const fvec3 fn(n), fv(v);
    const std::vector<double> p = taps_read(t, ibl::saturate(glm::dot(fn, fv)), r);
    const fvec3 e = ibl::specular_lobe_taps(chain, accurate_preset_lookup(), t, fn, fv, float(r),
                                            fvec3(1.0f), fvec3(1.0f));
    return dvec3(e) / double(ibl::saturate(float(p[0])) + ibl::saturate(float(p[1])));
}

ibl::sh_coeffs<double, 3> load_sh(const std::string& path) {
    const ibl_examples::json_value v = ibl_examples::parse_json(slurp(path));
    ibl::sh_coeffs<double, 3> k{};
    const ibl_examples::json_value* w = v.find("irradiance_over_pi_shader_windowed"); // the renderer's coefficients
    const ibl_examples::json_value* kj = w ? w : v.find("irradiance_over_pi_shader");
    REQUIRE(kj != nullptr);
    const auto& a = kj->values;
    for (std::size_t i = 0; i < a.size(); ++i)
        for (int c = 0; c < 3; ++c) k[int(i)][c] = a[i].values[std::size_t(c)].number;
    return k;
}

std::vector<double> numbers(const std::string& line) {
    std::istringstream s(line);
    std::vector<double> v;
    double x;
    while (s >> x) v.push_back(x);
    return v;
}

void check_close(const std::vector<double>& got, const std::vector<double>& want) {
    REQUIRE(got.size() == want.size());
    for (std::size_t i = 0; i < got.size(); ++i) CHECK(std::fabs(got[i] - want[i]) <= 2e-6 * std::fabs(want[i]) + 1e-12);
}

/// One answer line per expected row, each equal to it within check_close's tolerance.
void check_answers(const std::string& text, const std::vector<std::vector<double>>& want) {
    std::istringstream answers(text);
    std::string line;
    std::size_t n = 0;
    while (std::getline(answers, line)) {
        REQUIRE(n < want.size());
        INFO("answer " << n + 1 << ": " << line);
        check_close(numbers(line), want[n]);
        ++n;
    }
    CHECK(n == want.size());
}

/// The numbers of each answer line.
std::vector<std::vector<double>> parse_answers(const std::string& text) {
    std::istringstream answers(text);
    std::vector<std::vector<double>> rows;
    std::string line;
    while (std::getline(answers, line)) rows.push_back(numbers(line));
    return rows;
}

} // namespace

TEST_CASE("lookup: answers equal the library's runtime functions on the bake's files") {
    scratch s("ibl_bake_lookup_tests");
    // SH diffuse and no extracted sun here; the next case checks the default (map + sun) answers.
    REQUIRE(shell(tool + " --quiet --preset accurate --size 16 --lut-size 16 --quality low --extract-sun off --irradiance-size 0 --out " + (s / "bake") +
               " >/dev/null 2>&1") == 0);
    const ibl::cubemap<float> chain = load_chain(s / "bake/specular.ktx2");
    const ibl::dfg_lut lut = load_lut(s / "bake/dfg.exr");
    const ibl::sh_coeffs<double, 3> shc = load_sh(s / "bake/sh.json");
    const ibl::lobe_lut lobe = load_lobe(s / "bake/lobe_lut.exr"); // the accurate preset's runtime model
    const ibl::lobe_lut lobe_b = load_lobe(s / "bake/lobe_lut_b.exr"); // its B part
    const ibl::specular_lookup_desc sd = accurate_preset_lookup();

    std::vector<std::string> q;
    std::vector<std::vector<double>> want;
    for (int k = 0; k < 24; ++k) {
        const double t = 0.37 * k + 0.1, p = 0.91 * k;
        const dvec3 d = glm::normalize(dvec3(std::cos(t) * std::sin(p), std::cos(p), std::sin(t) * std::sin(p) + 0.01));
        const double r = std::fmod(0.043 * k, 1.0), nv = std::fmod(0.071 * k + 0.003, 1.0);
        char buf[256];
        std::snprintf(buf, sizeof buf, "specular %.17g %.17g %.17g %.17g", d.x, d.y, d.z, r);
        q.push_back(buf);
        const fvec3 ld = ibl::specular_lookup(chain, fvec3(d), float(r), sd);
        want.push_back({ld.x, ld.y, ld.z});
        std::snprintf(buf, sizeof buf, "dfg %.17g %.17g", nv, r);
        q.push_back(buf);
        const fvec3 ab = ibl::dfg_lookup(lut, float(nv), float(r));
        want.push_back({ab.x, ab.y});
        std::snprintf(buf, sizeof buf, "irradiance %.17g %.17g %.17g", d.x, d.y, d.z);
        q.push_back(buf);
        const dvec3 e = ibl::pi_v<double> * glm::max(ibl::sh_shader_evaluate(shc, d), dvec3(0.0));
        want.push_back({e.x, e.y, e.z});
        // shade: view v in the plane of n and +Y
        const dvec3 v = glm::normalize(d + dvec3(0.3, 0.8, -0.2));
        std::snprintf(buf, sizeof buf, "shade %.17g %.17g %.17g %.17g %.17g %.17g %.17g %g 0.9 0.6 0.5", d.x, d.y, d.z, v.x, v.y, v.z, r,
                      k % 2 ? 1.0 : 0.0);
        q.push_back(buf);
        ibl::pbr_material<double> m;
        m.roughness = r;
        m.metallic = k % 2 ? 1.0 : 0.0;
        m.base_color = dvec3(0.9, 0.6, 0.5);
        ibl::ibl_sample<double> smp;
        const double ndv = std::clamp(glm::dot(d, v), 0.0, 1.0);
        const ibl::vec4<float> pv = ibl::lobe_lut_lookup(lobe, float(ndv), float(r));
        const auto shader = ibl::pbr_shader<double>::from(m, true);
        smp.ld = lobe_pair_ld(chain, lobe, lobe_b, d, v, r, shader.m.f0, shader.m.f90);
        smp.dfg = ibl::vec2<double>(pv.x, pv.y);
        smp.irradiance_over_pi = glm::max(ibl::sh_shader_evaluate(shc, d), dvec3(0.0));
        const dvec3 lo = shader.ambient(ndv, smp);
        want.push_back({lo.x, lo.y, lo.z});
        std::snprintf(buf, sizeof buf, "lobe %.17g %.17g", nv, r);
        q.push_back(buf);
        const ibl::vec4<float> pl = ibl::lobe_lut_lookup(lobe, float(nv), float(r));
        want.push_back({pl.x, pl.y, pl.z, pl.w});
        std::snprintf(buf, sizeof buf, "lobe_b %.17g %.17g", nv, r);
        q.push_back(buf);
        const ibl::vec4<float> pbl = ibl::lobe_lut_lookup(lobe_b, float(nv), float(r));
        want.push_back({pbl.x, pbl.y});
    }
    std::ofstream(s / "queries.txt") << "# a comment\n\n" << [&] {
        std::string all;
        for (const auto& x : q) all += x + "\n";
        return all;
    }();
    REQUIRE(shell(tool + " --lookup " + (s / "bake") + " < " + (s / "queries.txt") + " > " + (s / "answers.txt")) == 0);
    check_answers(slurp(s / "answers.txt"), want);

    std::ofstream(s / "bad.txt") << "specular 0 1 0\nfoo 1 2\ndfg 0.5 x\nirradiance 0 0 0\ndfg 0.5 0.5\n";
    CHECK(shell(tool + " --lookup " + (s / "bake") + " < " + (s / "bad.txt") + " > " + (s / "bad_answers.txt")) == 1);
    const std::string bad = slurp(s / "bad_answers.txt");
    CHECK(bad.find("error: line 1: 'specular' takes 4 numbers") != std::string::npos);
    CHECK(bad.find("error: line 2: unknown query 'foo'") != std::string::npos);
    CHECK(bad.find("error: line 3: expected numbers") != std::string::npos);
    CHECK(bad.find("error: line 4: the normal is zero") != std::string::npos);
    CHECK(std::count(bad.begin(), bad.end(), '\n') == 5); // one line per query, the last one answered
    CHECK(shell(tool + " --lookup " + (s / "nothing") + " < /dev/null > /dev/null 2>&1") == 1);
}

TEST_CASE("lookup: a split-sum bake shades with LD(R, r) and the DFG table, and has no lobe answers") {
    scratch s("ibl_bake_lookup_split");
    REQUIRE(shell(tool + " --quiet --size 16 --lut-size 16 --quality low --extract-sun off --irradiance-size 0 --runtime split-sum --out " +
                  (s / "bake") + " >/dev/null 2>&1") == 0);
    CHECK_FALSE(fs::exists(s / "bake/lobe_lut.exr"));
    const ibl::cubemap<float> chain = load_chain(s / "bake/specular.ktx2");
    const ibl::dfg_lut lut = load_lut(s / "bake/dfg.exr");
    const ibl::sh_coeffs<double, 3> shc = load_sh(s / "bake/sh.json");
    std::string q;
    std::vector<std::vector<double>> want;
    for (int k = 0; k < 12; ++k) {
        const dvec3 n = glm::normalize(dvec3(std::sin(0.7 * k), 0.5, std::cos(0.3 * k))), v = glm::normalize(n + dvec3(0.4, 0.2, -0.3));
        const double r = std::fmod(0.083 * k + 0.01, 1.0);
        char buf[256];
        std::snprintf(buf, sizeof buf, "shade %.17g %.17g %.17g %.17g %.17g %.17g %.17g 1 0.9 0.6 0.5\n", n.x, n.y, n.z, v.x, v.y, v.z, r);
        q += buf;
        ibl::pbr_material<double> m;
        m.roughness = r;
        m.metallic = 1.0;
        m.base_color = dvec3(0.9, 0.6, 0.5);
        const double ndv = std::clamp(glm::dot(n, v), 0.0, 1.0);
        ibl::ibl_sample<double> smp;
        smp.ld = dvec3(ibl::specular_lookup(chain, fvec3(2.0 * glm::dot(n, v) * n - v), float(r)));
        const fvec3 ab = ibl::dfg_lookup(lut, float(ndv), float(r));
        smp.dfg = ibl::vec2<double>(ab.x, ab.y);
        smp.irradiance_over_pi = glm::max(ibl::sh_shader_evaluate(shc, n), dvec3(0.0));
        const dvec3 lo = ibl::pbr_shader<double>::from(m, true).ambient(ndv, smp);
        want.push_back({lo.x, lo.y, lo.z});
    }
    std::ofstream(s / "q.txt") << q;
    REQUIRE(shell(tool + " --lookup " + (s / "bake") + " < " + (s / "q.txt") + " > " + (s / "a.txt")) == 0);
    check_answers(slurp(s / "a.txt"), want);
    std::ofstream(s / "q2.txt") << "lobe 0.5 0.5\n";
    CHECK(shell(tool + " --lookup " + (s / "bake") + " < " + (s / "q2.txt") + " > " + (s / "a2.txt")) == 1);
    CHECK(slurp(s / "a2.txt").find("no lobe LUT") != std::string::npos);
}

TEST_CASE("lookup: a taps2 bake shades with ibl::specular_lobe_taps and answers taps from its two files") {
    scratch s("ibl_bake_lookup_taps");
    REQUIRE(shell(tool + " --quiet --preset accurate --size 16 --lut-size 16 --quality low --extract-sun off --irradiance-size 0 --runtime taps2 --out " +
                  (s / "bake") + " >/dev/null 2>&1") == 0);
    CHECK_FALSE(fs::exists(s / "bake/lobe_lut.exr"));
    const ibl::cubemap<float> chain = load_chain(s / "bake/specular.ktx2");
    const ibl::lobe_taps_lut taps = load_taps(s / "bake/lobe_taps_a.exr", s / "bake/lobe_taps_b.exr");
    CHECK(taps.size == 16); // at most the DFG table's size
    const ibl::sh_coeffs<double, 3> shc = load_sh(s / "bake/sh.json");
    std::string q;
    std::vector<std::vector<double>> want;
    for (int k = 0; k < 16; ++k) {
        const dvec3 n = glm::normalize(dvec3(std::sin(0.7 * k), 0.5, std::cos(0.3 * k))), v = glm::normalize(n + dvec3(0.4, 0.2, -0.3 + 0.1 * k));
        const double r = std::fmod(0.067 * k + 0.01, 1.0), nv = std::fmod(0.071 * k + 0.003, 1.0);
        char buf[320];
        std::snprintf(buf, sizeof buf, "shade %.17g %.17g %.17g %.17g %.17g %.17g %.17g %d 0.9 0.6 0.5\ntaps %.17g %.17g\n", n.x, n.y, n.z,
                      v.x, v.y, v.z, r, k % 2, nv, r);
        q += buf;
        ibl::pbr_material<double> m;
        m.roughness = r;
        m.metallic = k % 2;
        m.base_color = dvec3(0.9, 0.6, 0.5);
        const double ndv = std::clamp(glm::dot(n, v), 0.0, 1.0);
        const std::vector<double> p = taps_read(taps, ndv, r);
        ibl::ibl_sample<double> smp;
        smp.ld = taps_ld(chain, taps, n, v, r);
        smp.dfg = ibl::vec2<double>(p[0], p[1]);
        smp.irradiance_over_pi = glm::max(ibl::sh_shader_evaluate(shc, n), dvec3(0.0));
        const dvec3 lo = ibl::pbr_shader<double>::from(m, true).ambient(ndv, smp);
        want.push_back({lo.x, lo.y, lo.z});
        want.push_back(taps_read(taps, nv, r));
    }
    std::ofstream(s / "q.txt") << q;
    REQUIRE(shell(tool + " --lookup " + (s / "bake") + " < " + (s / "q.txt") + " > " + (s / "a.txt")) == 0);
    check_answers(slurp(s / "a.txt"), want);
    // the other bakes have no taps answer, this one no lobe answer
    std::ofstream(s / "q2.txt") << "lobe 0.5 0.5\n";
    CHECK(shell(tool + " --lookup " + (s / "bake") + " < " + (s / "q2.txt") + " > " + (s / "a2.txt")) == 1);
    CHECK(slurp(s / "a2.txt").find("no lobe LUT") != std::string::npos);
    REQUIRE(shell(tool + " --quiet --preset accurate --size 16 --lut-size 16 --quality low --extract-sun off --out " + (s / "lobe") + " >/dev/null 2>&1") == 0);
    std::ofstream(s / "q3.txt") << "taps 0.5 0.5\n";
    CHECK(shell(tool + " --lookup " + (s / "lobe") + " < " + (s / "q3.txt") + " > " + (s / "a3.txt")) == 1);
    CHECK(slurp(s / "a3.txt").find("bake with --runtime taps2") != std::string::npos);
}

TEST_CASE("lookup: with the accurate bake (irradiance map, extracted sun) answers are about the whole environment") {
    scratch s("ibl_bake_lookup_tests");
    REQUIRE(shell(tool + " --quiet --preset accurate --size 32 --lut-size 16 --quality low --out " + (s / "bake") + " >/dev/null 2>&1") == 0);
    const ibl_examples::json_value lights = ibl_examples::parse_json(slurp(s / "bake/lights.json"));
    const auto& list = lights.find("lights")->values;
    REQUIRE(list.size() == 1); // the built-in sky's sun
    const auto& l = list[0];
    auto vec = [&](const char* k) {
        const auto& a = l.find(k)->values;
        return dvec3(a[0].number, a[1].number, a[2].number);
    };
    const ibl::disk_light<double> sun{vec("direction"), l.find("solid_angle")->number, vec("radiance")};
    const ibl::cubemap<float> chain = load_chain(s / "bake/specular.ktx2");
    const ibl::cubemap<float> map = load_chain(s / "bake/irradiance.ktx2");
    const dvec3 dirs[3] = {sun.direction, glm::normalize(sun.direction + dvec3(0.0, 0.3, 0.0)), dvec3(0.0, 1.0, 0.0)};
    std::string q;
    std::vector<std::vector<double>> want;
    for (const dvec3& d : dirs)
        for (const double r : {0.1, 0.45}) {
            char buf[200];
            std::snprintf(buf, sizeof buf, "specular %.17g %.17g %.17g %.17g\nirradiance %.17g %.17g %.17g\n", d.x, d.y, d.z, r, d.x, d.y, d.z);
            q += buf;
            // the chain is G1-weighted: the sun's term of the same weight (the tool's 8 nodes)
            const dvec3 ld = dvec3(ibl::specular_lookup(chain, fvec3(d), float(r), accurate_preset_lookup())) +
                             ibl::disk_light_ld(sun, d, r, 8, ibl::ld_weight::g1);
            const dvec3 e = dvec3(map.radiance(fvec3(d), 0.0f)) + ibl::disk_light_irradiance(d, sun);
            want.push_back({ld.x, ld.y, ld.z});
            want.push_back({e.x, e.y, e.z});
        }
    std::ofstream(s / "q.txt") << q;
    REQUIRE(shell(tool + " --lookup " + (s / "bake") + " < " + (s / "q.txt") + " > " + (s / "a.txt")) == 0);
    check_answers(slurp(s / "a.txt"), want);
}

TEST_CASE("defaults: the default bake is the textbook products, whole, and every file says so") {
    scratch s("ibl_bake_lookup_defaults");
    REQUIRE(shell(tool + " --quiet --size 16 --lut-size 16 --quality low --out " + (s / "bake") + " >/dev/null 2>&1") == 0);
    CHECK_FALSE(std::filesystem::exists(s / "bake/lights.json")); // nothing taken out of the environment
    CHECK_FALSE(std::filesystem::exists(s / "bake/lobe_lut.exr"));
    auto attrs = [](const std::string& path) {
        std::map<std::string, std::string> m;
        for (const auto& [k, v] : read_exr_string_attributes(path)) m[k] = v;
        return m;
    };
    const auto dfg = attrs(s / "bake/dfg.exr");
    CHECK(dfg.at("ibl.dfg_layout") == "uniform");
    CHECK(dfg.at("ibl.dfg_channels") == "A, B, k");
    CHECK(dfg.at("ibl.model") == "ggx_height_correlated");
    CHECK(dfg.at("ibl.preset") == "default");
    CHECK(dfg.at("ibl.sun_extracted").rfind("no", 0) == 0);
    const auto l1 = attrs(s / "bake/specular_l1_px.exr");
    CHECK(l1.at("ibl.ld_weight") == "nl");
    CHECK(l1.at("ibl.specular_lookup") == "textbook");
    CHECK(l1.at("ibl.level") == "1");
    CHECK(l1.at("ibl.runtime") == "split-sum");
    CHECK(l1.at("ibl.sun_extracted").rfind("no", 0) == 0);
    CHECK(attrs(s / "bake/irradiance_py.exr").count("ibl.conventions") == 1);
    const ibl_examples::json_value sh = ibl_examples::parse_json(slurp(s / "bake/sh.json"));
    REQUIRE(sh.find("conventions") != nullptr);
    CHECK(sh.find("conventions")->find("ibl.preset")->string == "default");
    // The textbook table answers texture(lut, vec2(n.v, r)): texel (i, j) at ((i + 0.5) / N, (j + 0.5) / N).
    const ibl::dfg_lut lut = load_lut(s / "bake/dfg.exr");
    const ibl::vec2<double> e = ibl::dfg_exact<ibl::ggx_height_correlated>(lut.n_dot_v(5), lut.roughness(9));
    CHECK(double(lut.at(5, 9, 0)) == doctest::Approx(e.x).epsilon(1e-4));
    CHECK(double(lut.at(5, 9, 1)) == doctest::Approx(e.y).scale(1).epsilon(1e-4));
    // A table of another layout copied into the folder is refused.
    REQUIRE(shell(tool + " --quiet --preset accurate --size 16 --lut-size 16 --quality low --out " + (s / "acc") + " >/dev/null 2>&1") == 0);
    std::filesystem::copy_file(s / "acc/dfg.exr", s / "bake/dfg.exr", std::filesystem::copy_options::overwrite_existing);
    CHECK(shell(tool + " --lookup " + (s / "bake") + " < /dev/null > /dev/null 2> " + (s / "err.txt")) == 1);
    CHECK(slurp(s / "err.txt").find("remapped layout, report.json says uniform") != std::string::npos);
}

TEST_CASE("lookup: sheen and dfg_sheen answer from the sheen chain and table") {
    scratch s("ibl_bake_lookup_sheen");
    REQUIRE(shell(tool + " --quiet --size 16 --lut-size 16 --quality low --sheen --extract-sun off --out " + (s / "bake") +
                  " >/dev/null 2>&1") == 0);
    const ibl::cubemap<float> sheen = load_chain(s / "bake/sheen.ktx2");
    const image_rgb32f lut_img = read_image(s / "bake/sheen_lut.exr");
    ibl::dfg_lut lut{std::uint32_t(lut_img.width), 1, {}};
    for (int j = 0; j < lut_img.height; ++j)
        for (int i = 0; i < lut_img.width; ++i) lut.data.push_back(lut_img.texel(i, j)[0]);
    std::string q;
    std::vector<std::vector<double>> want;
    for (int k = 0; k < 12; ++k) {
        const dvec3 d = glm::normalize(dvec3(std::sin(0.7 * k), 0.4 - 0.05 * k, std::cos(0.7 * k)));
        const double r = std::fmod(0.09 * k + 0.02, 1.0), nv = std::fmod(0.13 * k + 0.01, 1.0);
        char buf[200];
        std::snprintf(buf, sizeof buf, "sheen %.17g %.17g %.17g %.17g\ndfg_sheen %.17g %.17g\n", d.x, d.y, d.z, r, nv, r);
        q += buf;
        const fvec3 ld = sheen.radiance(fvec3(d), ibl::roughness_mip_policy::linear().lod(float(r), sheen.levels()));
        want.push_back({ld.x, ld.y, ld.z});
        want.push_back({lut.sample(float(nv), float(r)).x});
    }
    std::ofstream(s / "q.txt") << q;
    REQUIRE(shell(tool + " --lookup " + (s / "bake") + " < " + (s / "q.txt") + " > " + (s / "a.txt")) == 0);
    check_answers(slurp(s / "a.txt"), want);
    // a bake without --sheen says so
    REQUIRE(shell(tool + " --quiet --size 16 --lut-size 16 --quality low --out " + (s / "plain") + " >/dev/null 2>&1") == 0);
    std::ofstream(s / "q2.txt") << "sheen 0 1 0 0.5\n";
    CHECK(shell(tool + " --lookup " + (s / "plain") + " < " + (s / "q2.txt") + " > " + (s / "a2.txt")) == 1);
    CHECK(slurp(s / "a2.txt").find("bake with --sheen") != std::string::npos);
}

TEST_CASE("lookup: block-compressed bakes answer from their decoded files, near the uncompressed bake") {
    scratch s("ibl_bake_lookup_blocks");
    const std::string common = " --quiet --size 32 --lut-size 16 --quality low --checks none --threads 2 --out ";
    REQUIRE(shell(tool + common + (s / "f16") + " >/dev/null 2>&1") == 0);
    std::string q;
    std::vector<dvec3> dirs;
    std::vector<double> rough;
    for (int k = 0; k < 24; ++k) {
        const dvec3 d = glm::normalize(dvec3(std::sin(0.7 * k + 0.1), std::cos(1.3 * k), std::cos(0.3 * k + 0.5)));
        const double r = 0.25 + 0.75 * std::fmod(0.37 * k, 1.0);
        char buf[160];
        std::snprintf(buf, sizeof buf, "specular %.17g %.17g %.17g %.17g\n", d.x, d.y, d.z, r);
        q += buf;
        dirs.push_back(d);
        rough.push_back(r);
    }
    std::ofstream(s / "q.txt") << q;
    REQUIRE(shell(tool + " --lookup " + (s / "f16") + " < " + (s / "q.txt") + " > " + (s / "a_f16.txt")) == 0);
    const std::vector<std::vector<double>> f16 = parse_answers(slurp(s / "a_f16.txt"));
    for (const char* format : {"bc6h", "astc4x4", "astc6x6"}) {
        CAPTURE(format);
        const fs::path dir = s / format;
        REQUIRE(shell(tool + common + dir.string() + " --ktx2-format " + format + " >/dev/null 2>&1") == 0);
        // the answers are the library's lookup on the file as decoded (the GPU's decode)
        const ibl::cubemap<float> chain = load_chain(dir / "specular.ktx2");
        std::vector<std::vector<double>> want;
        for (std::size_t i = 0; i < dirs.size(); ++i) {
            const fvec3 ld = ibl::specular_lookup(chain, fvec3(dirs[i]), float(rough[i]));
            want.push_back({ld.x, ld.y, ld.z});
        }
        REQUIRE(shell(tool + " --lookup " + dir.string() + " < " + (s / "q.txt") + " > " + (s / "a.txt")) == 0);
        const std::string answers = slurp(s / "a.txt");
        check_answers(answers, want);
        // and within a few percent of the uncompressed bake at r >= 0.25
        const std::vector<std::vector<double>> got = parse_answers(answers);
        REQUIRE(got.size() == f16.size());
        double sq = 0.0, ref = 0.0;
        for (std::size_t i = 0; i < got.size(); ++i)
            for (int c = 0; c < 3; ++c) sq += (got[i][std::size_t(c)] - f16[i][std::size_t(c)]) * (got[i][std::size_t(c)] - f16[i][std::size_t(c)]),
                                        ref += f16[i][std::size_t(c)] * f16[i][std::size_t(c)];
        CHECK(std::sqrt(sq / ref) < 0.05);
    }
}
