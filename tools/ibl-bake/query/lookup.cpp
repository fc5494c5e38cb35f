// tools/ibl-bake/query/lookup.cpp — see lookup.hpp.

#include "query/lookup.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <istream>
#include <iterator>
#include <ostream>
#include <sstream>
#include <stdexcept>
#include <vector>

#include <ibl/sh/convolve.hpp>

#include "io/cube_layout.hpp"
#include "io/json_value.hpp"
#include "io/ktx2.hpp"

namespace ibl_bake {

using query_text::fmt9;
using query_text::numbers;
using query_text::triple;
using query_text::unit;

namespace {

using ibl_examples::json_value;

bool fs_exists(const std::string& path) {
    std::ifstream f(path);
    return bool(f);
}

std::string slurp(const std::string& path) {
    const std::vector<unsigned char> b = read_file(path);
    return std::string(b.begin(), b.end());
}

const json_value& member(const json_value& v, const char* key, const std::string& file) {
    const json_value* m = v.find(key);
    if (!m) throw std::runtime_error(file + ": missing \"" + key + "\"");
    return *m;
}

ibl::cubemap<float> cube_from_ktx2(const std::string& path) { return cubemap_from_rgb32f(decode_ktx2_cubemap(read_file(path), path)); }

ibl::dfg_lut lut_from_exr(const std::string& path, int channels) {
    const image_rgb32f img = read_image(path);
    if (img.width != img.height) throw std::runtime_error(path + ": the DFG table is not square");
    ibl::dfg_lut lut;
    lut.size = std::uint32_t(img.width);
    lut.channels = std::uint32_t(std::clamp(channels, 2, 3));
    lut.data.resize(std::size_t(lut.size) * lut.size * lut.channels);
    for (std::uint32_t j = 0; j < lut.size; ++j)
        for (std::uint32_t i = 0; i < lut.size; ++i)
            for (std::uint32_t c = 0; c < lut.channels; ++c)
                lut.data[(std::size_t(j) * lut.size + i) * lut.channels + c] = img.texel(int(i), int(j))[c];
    return lut;
}

diffuse_data sh_from_json(const std::string& path) {
    const json_value v = ibl_examples::parse_json(slurp(path));
    diffuse_data d;
    d.kind = ibl::diffuse_product::sh;
    d.bands = int(member(v, "bands", path).number);
    const json_value* kw = v.find("irradiance_over_pi_shader_windowed");
    const json_value& k = kw ? *kw : member(v, "irradiance_over_pi_shader", path);
    const json_value& r = member(v, "radiance", path);
    if (k.values.size() > 25 || k.values.size() != r.values.size()) throw std::runtime_error(path + ": unexpected coefficient count");
    for (std::size_t i = 0; i < k.values.size(); ++i)
        for (int c = 0; c < 3; ++c) {
            d.shader_over_pi[int(i)][c] = k.values[i].values.at(std::size_t(c)).number;
            d.radiance[int(i)][c] = r.values[i].values.at(std::size_t(c)).number;
        }
    return d;
}

double unit_interval(double x) { return std::clamp(x, 0.0, 1.0); }

// The answers, one function per query word: the numbers a (their count checked) against the bake.
using numbers_t = std::vector<double>;

std::string answer_specular(const baked_folder& b, const product_view& v, const numbers_t& a) {
    if (!b.has_chain) throw std::invalid_argument("the bake has no specular chain");
    const dvec3 d = unit(a[0], a[1], a[2], "the direction");
    return triple(v.ld(d, unit_interval(a[3])) + sun_ld(v.sun, d, unit_interval(a[3]), v.weight));
}

std::string answer_dfg(const baked_folder& b, const product_view&, const numbers_t& a) {
    if (!b.has_lut) throw std::invalid_argument("the bake has no DFG table");
    const fvec3 ab = ibl::dfg_lookup(b.lut, float(unit_interval(a[0])), float(unit_interval(a[1])));
    return fmt9(ab.x) + " " + fmt9(ab.y);
}

std::string answer_irradiance(const baked_folder& b, const product_view& v, const numbers_t& a) {
    if (b.diffuse.kind == ibl::diffuse_product::none) throw std::invalid_argument("the bake has no diffuse product");
    return triple(v.irradiance(unit(a[0], a[1], a[2], "the normal")));
}

std::string answer_shade(const baked_folder&, const product_view& v, const numbers_t& a) {
    const dvec3 n = unit(a[0], a[1], a[2], "the normal"), vv = unit(a[3], a[4], a[5], "the view direction");
    ibl::pbr_material<double> m;
    m.roughness = unit_interval(a[6]);
    m.metallic = unit_interval(a[7]);
    m.base_color = glm::clamp(dvec3(a[8], a[9], a[10]), dvec3(0.0), dvec3(1.0));
    const auto shader = ibl::pbr_shader<double>::from(m, true);
    return triple(v.shade(shader, n, vv));
}

std::string answer_sheen(const baked_folder& b, const product_view& v, const numbers_t& a) {
    if (!b.has_sheen) throw std::invalid_argument("the bake has no sheen chain (bake with --sheen)");
    const dvec3 d = unit(a[0], a[1], a[2], "the direction");
    const float lod = ibl::roughness_mip_policy::linear().lod(float(unit_interval(a[3])), b.sheen.levels());
    return triple(dvec3(b.sheen.radiance(fvec3(d), lod)) + sheen_sun_ld(v.sun, d, unit_interval(a[3])));
}

std::string answer_dfg_sheen(const baked_folder& b, const product_view&, const numbers_t& a) {
    if (!b.has_sheen) throw std::invalid_argument("the bake has no sheen table (bake with --sheen)");
    return fmt9(b.sheen_lut.sample(float(unit_interval(a[0])), float(unit_interval(a[1]))).x);
}

std::string answer_lobe(const baked_folder& b, const product_view& v, const numbers_t& a) {
    if (!b.has_lobe) throw std::invalid_argument("the bake has no lobe LUT (bake with --runtime lobe)");
    const ibl::vec4<double> p = v.lobe_params(unit_interval(a[0]), unit_interval(a[1]));
    return fmt9(p.x) + " " + fmt9(p.y) + " " + fmt9(p.z) + " " + fmt9(p.w);
}

std::string answer_lobe_b(const baked_folder& b, const product_view& v, const numbers_t& a) {
    if (!b.has_lobe_b) throw std::invalid_argument("the bake has no B-part lobe table (bake with --runtime lobe)");
    const ibl::vec2<double> p = v.lobe_b_params(unit_interval(a[0]), unit_interval(a[1]));
    return fmt9(p.x) + " " + fmt9(p.y);
}

std::string answer_taps(const baked_folder& b, const product_view& v, const numbers_t& a) {
    if (!b.has_taps) throw std::invalid_argument("the bake has no two-tap table (bake with --runtime taps2)");
    std::string s;
    for (const float x : v.taps_params(unit_interval(a[0]), unit_interval(a[1]))) {
        if (!s.empty()) s += ' ';
        s += fmt9(x);
    }
    return s;
}

struct query_kind {
    const char* word;
    std::size_t count; ///< of numbers
    std::string (*answer)(const baked_folder&, const product_view&, const numbers_t&);
};

constexpr query_kind query_kinds[] = {
    {"specular", 4, answer_specular}, {"dfg", 2, answer_dfg},           {"irradiance", 3, answer_irradiance},
    {"shade", 11, answer_shade},      {"sheen", 4, answer_sheen},       {"dfg_sheen", 2, answer_dfg_sheen},
    {"lobe", 2, answer_lobe},         {"lobe_b", 2, answer_lobe_b},     {"taps", 2, answer_taps},
};

/// One answer line for a query, or throws std::invalid_argument with the reason.
std::string answer(const baked_folder& b, const product_view& v, const std::string& word, const numbers_t& a) {
    std::string words;
    for (const query_kind& q : query_kinds) {
        words += (words.empty() ? "" : ", ") + std::string(q.word);
        if (word != q.word) continue;
        if (a.size() != q.count)
            throw std::invalid_argument("'" + word + "' takes " + std::to_string(q.count) + " numbers, got " + std::to_string(a.size()));
        return q.answer(b, v, a);
    }
    throw std::invalid_argument("unknown query '" + word + "' (" + words + ")");
}

} // namespace

namespace query_text {

bool numbers(std::istringstream& in, std::vector<double>& out) {
    std::string w;
    while (in >> w) {
        double x = 0.0;
        const auto r = std::from_chars(w.data(), w.data() + w.size(), x);
        if (r.ec != std::errc() || r.ptr != w.data() + w.size() || !std::isfinite(x)) return false;
        out.push_back(x);
    }
    return true;
}

std::string fmt9(double x) {
    char b[32];
    std::snprintf(b, sizeof b, "%.9g", x);
    return b;
}
std::string triple(const dvec3& v) { return fmt9(v.x) + " " + fmt9(v.y) + " " + fmt9(v.z); }

dvec3 unit(double x, double y, double z, const char* what) {
    const dvec3 d(x, y, z);
    const double l = std::sqrt(glm::dot(d, d));
    if (!(l > 0.0) || !std::isfinite(l)) throw std::invalid_argument(std::string(what) + " is zero or not finite");
    return d / l;
}

} // namespace query_text


product_view baked_folder::view() const {
    product_view v;
    v.chain = has_chain ? &chain : nullptr;
    v.policy = filament_policy ? ibl::roughness_mip_policy::filament() : ibl::roughness_mip_policy::linear();
    v.virtual_levels = virtual_levels;
    v.first_level = first_level;
    v.lut = has_lut ? &lut : nullptr;
    v.diffuse = &diffuse;
    v.specular = specular;
    v.dfg_layout = dfg_layout;
    v.sun = sun ? &*sun : nullptr;
    v.lobe = has_lobe ? &lobe : nullptr;
    v.lobe_b = has_lobe_b ? &lobe_b : nullptr;
    v.taps = has_taps ? &taps : nullptr;
    v.weight = weight;
    return v;
}

namespace {
/// The two-tap table from its GLSL storage split: channels 0..3 from lobe_taps_a.exr, 4..7 from
/// lobe_taps_b.exr.
void load_taps(baked_folder& b, const std::string& dir) {
    const image_rgba32f ta = read_exr_rgba(dir + "/lobe_taps_a.exr"), tb = read_exr_rgba(dir + "/lobe_taps_b.exr");
    if (ta.width != ta.height) throw std::runtime_error(dir + "/lobe_taps_a.exr: the two-tap table is not square");
    if (tb.width != ta.width || tb.height != ta.height)
        throw std::runtime_error(dir + "/lobe_taps_b.exr: not the size of lobe_taps_a.exr");
    b.taps.size = std::uint32_t(ta.width);
    b.taps.taps = 2;
    b.taps.channels = 8;
    b.taps.weight = b.weight;
    b.taps.layout = b.dfg_layout;
    b.taps.data.resize(std::size_t(b.taps.size) * b.taps.size * 8);
    for (std::size_t k = 0; k < std::size_t(b.taps.size) * b.taps.size; ++k)
        for (std::size_t c = 0; c < 4; ++c) {
            b.taps.data[k * 8 + c] = ta.rgba[k * 4 + c];
            b.taps.data[k * 8 + 4 + c] = tb.rgba[k * 4 + c];
        }
    b.has_taps = true;
}

/// A table file whose ibl.dfg_layout attribute names another layout than report.json is refused
/// (files of two bakes mixed in one folder); files without the attribute take report.json's.
void check_layout_attribute(const std::string& path, const ibl::dfg_lut_layout& expected) {
    for (const auto& [k, v] : read_exr_string_attributes(path))
        if (k == "ibl.dfg_layout" && v != expected.name())
            throw std::runtime_error(path + ": the table is in the " + v + " layout, report.json says " + expected.name() +
                                     " (files of different bakes?)");
}

/// The runtime model of plan.runtime (bakes before it: the split sum of an n.l chain).
void load_runtime_model(baked_folder& b, const json_value& rt, const std::string& dir) {
    if (const json_value* w = rt.find("ld_weight"); w && w->find("name")) b.weight = ld_weight_from(w->find("name")->string);
    const json_value* m = rt.find("runtime_model");
    if (m && m->find("name") && m->find("name")->string == "taps2") {
        load_taps(b, dir);
        return;
    }
    if (!m || !m->find("name") || m->find("name")->string != "lobe") return;
    const image_rgba32f img = read_exr_rgba(dir + "/lobe_lut.exr");
    if (img.width != img.height) throw std::runtime_error(dir + "/lobe_lut.exr: the lobe LUT is not square");
    b.lobe.size = std::uint32_t(img.width);
    b.lobe.data = img.rgba;
    b.lobe.weight = b.weight;
    b.lobe.layout = b.dfg_layout;
    check_layout_attribute(dir + "/lobe_lut.exr", b.dfg_layout);
    b.has_lobe = true;
    // the two-part model (plan.runtime.runtime_model.parts = 2); a bake before it: one kernel
    if (!m->find("parts") || m->find("parts")->number != 2.0) return;
    const image_rgba32f ib = read_exr_rgba(dir + "/lobe_lut_b.exr");
    if (ib.width != img.width || ib.height != img.height)
        throw std::runtime_error(dir + "/lobe_lut_b.exr: not the size of lobe_lut.exr");
    b.lobe_b = b.lobe;
    b.lobe_b.data = ib.rgba;
    check_layout_attribute(dir + "/lobe_lut_b.exr", b.dfg_layout);
    b.has_lobe_b = true;
}
} // namespace

baked_folder load_baked_folder(const std::string& dir) {
    const std::string rp = dir + "/report.json";
    const json_value report = ibl_examples::parse_json(slurp(rp));
    const json_value& rt = member(member(report, "plan", rp), "runtime", rp);
    baked_folder b;
    b.virtual_levels = int(member(rt, "virtual_levels", rp).number);
    b.filament_policy = member(rt, "policy", rp).string == "filament";
    b.first_level = int(member(rt, "first_level", rp).number);
    if (member(rt, "stored_levels", rp).number > 0) {
        b.chain = cube_from_ktx2(dir + "/specular.ktx2");
        b.has_chain = true;
    }
    b.specular = member(member(rt, "specular_lookup", rp), "name", rp).string == "textbook" ? ibl::specular_lookup_desc::textbook()
                                                                                           : ibl::specular_lookup_desc::accurate();
    b.dfg_layout = member(member(rt, "dfg_layout", rp), "edge_aligned", rp).boolean ? ibl::dfg_lut_layout::remapped()
                                                                                     : ibl::dfg_lut_layout::uniform();
    b.specular.mapping = b.filament_policy ? ibl::roughness_mapping::filament : ibl::roughness_mapping::linear;
    if (member(rt, "dfg_size", rp).number > 0) {
        b.lut = lut_from_exr(dir + "/dfg.exr", int(member(rt, "dfg_channels", rp).number));
        if (const json_value* ch = rt.find("dfg_channels_layout"); ch && ch->string.rfind("B,", 0) == 0) // (B, A + B, k)
            for (std::size_t k = 0; k + 1 < b.lut.data.size(); k += b.lut.channels) {
                const float x = b.lut.data[k], y = b.lut.data[k + 1];
                b.lut.data[k] = y - x, b.lut.data[k + 1] = x;
            }
        b.lut.layout = b.dfg_layout;
        check_layout_attribute(dir + "/dfg.exr", b.dfg_layout);
        b.has_lut = true;
    }
    if (fs_exists(dir + "/lights.json")) {
        const json_value lj = ibl_examples::parse_json(slurp(dir + "/lights.json"));
        for (const json_value& l : member(lj, "lights", dir + "/lights.json").values) {
            const json_value& d = member(l, "direction", "lights.json");
            const json_value& rad = member(l, "radiance", "lights.json");
            b.sun = ibl::disk_light<double>{dvec3(d.values.at(0).number, d.values.at(1).number, d.values.at(2).number),
                                            member(l, "solid_angle", "lights.json").number,
                                            dvec3(rad.values.at(0).number, rad.values.at(1).number, rad.values.at(2).number)};
        }
    }
    if (const json_value* sh = rt.find("sheen"); sh && sh->boolean) {
        b.sheen = cube_from_ktx2(dir + "/sheen.ktx2");
        const image_rgb32f img = read_image(dir + "/sheen_lut.exr");
        b.sheen_lut = ibl::dfg_lut{std::uint32_t(img.width), 1, {}};
        for (int j = 0; j < img.height; ++j)
            for (int i = 0; i < img.width; ++i) b.sheen_lut.data.push_back(img.texel(i, j)[0]);
        b.has_sheen = true;
    }
    load_runtime_model(b, rt, dir);
    const std::string diffuse = member(rt, "diffuse", rp).string;
    if (diffuse == "sh") b.diffuse = sh_from_json(dir + "/sh.json");
    else if (diffuse == "irradiance_map") {
        b.diffuse.kind = ibl::diffuse_product::irradiance_map;
        b.diffuse.map = cube_from_ktx2(dir + "/irradiance.ktx2");
    }
    return b;
}

int run_lookup(const baked_folder& b, std::istream& in, std::ostream& out) {
    const product_view v = b.view();
    std::string line;
    int status = 0;
    for (long n = 1; std::getline(in, line); ++n) {
        std::istringstream ls(line);
        std::string word;
        if (!(ls >> word) || word[0] == '#') continue;
        std::vector<double> a;
        try {
            if (!numbers(ls, a)) throw std::invalid_argument("expected numbers after '" + word + "'");
            out << answer(b, v, word, a) << '\n';
        } catch (const std::invalid_argument& e) {
            out << "error: line " << n << ": " << e.what() << ": " << line << '\n';
            status = 1;
        }
    }
    out.flush();
    return status;
}

} // namespace ibl_bake
