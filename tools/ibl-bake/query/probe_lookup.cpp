// tools/ibl-bake/query/probe_lookup.cpp — see probe_lookup.hpp.

#include "query/probe_lookup.hpp"
#include "query/lookup.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <istream>
#include <ostream>
#include <sstream>
#include <stdexcept>

#include "io/cube_layout.hpp"
#include "io/image_io.hpp"
#include "io/json_value.hpp"
#include "io/ktx2.hpp"
#include "stages/probe_bake.hpp"

namespace ibl_bake {

namespace {

using ibl_examples::json_value;
using dv3 = ibl::vec3<double>;

struct probe_json {
    std::string file;
    [[noreturn]] void fail(const std::string& where, const std::string& what) const {
        throw std::runtime_error(file + ": " + where + ": " + what);
    }
    const json_value& need(const json_value& v, const char* key, const std::string& where) const {
        const json_value* m = v.find(key);
        if (!m) fail(where, std::string("missing \"") + key + "\"");
        return *m;
    }
    double number(const json_value& v, const std::string& where) const {
        if (!v.is_number() || !std::isfinite(v.number)) fail(where, "expected a finite number");
        return v.number;
    }
    dv3 vec(const json_value& v, const std::string& where) const {
        if (!v.is_array() || v.values.size() != 3) fail(where, "expected [x, y, z]");
        return {number(v.values[0], where), number(v.values[1], where), number(v.values[2], where)};
    }
    /// A volume: sets box or sphere, returns whether it is a sphere.
    bool volume(const json_value& v, const std::string& where, ibl::probe_box<double>& box, ibl::probe_sphere<double>& ball) const {
        if (const json_value* b = v.find("box")) {
            const std::string w = where + ".box";
            if (b->find("min")) {
                box = ibl::probe_box<double>::axis_aligned(vec(need(*b, "min", w), w + ".min"), vec(need(*b, "max", w), w + ".max"));
                return false;
            }
            // oriented: center, half_extents, axes (orthonormal as the bake wrote them)
            box.center = vec(need(*b, "center", w), w + ".center");
            box.half = vec(need(*b, "half_extents", w), w + ".half_extents");
            const json_value& axes = need(*b, "axes", w);
            if (!axes.is_array() || axes.values.size() != 3) fail(w + ".axes", "expected 3 axes");
            for (std::size_t i = 0; i < 3; ++i) {
                box.axis[i] = vec(axes.values[i], w + ".axes");
                if (!(std::fabs(glm::length(box.axis[i]) - 1.0) <= 1e-6)) fail(w + ".axes", "not unit vectors");
            }
            return false;
        }
        const json_value& s = need(v, "sphere", where);
        ball.center = vec(need(s, "center", where + ".sphere"), where + ".sphere.center");
        ball.radius = number(need(s, "radius", where + ".sphere"), where + ".sphere.radius");
        return true;
    }
};

} // namespace

using query_text::fmt9;
using query_text::numbers;
using query_text::triple;
using query_text::unit;

bool is_probe_set_folder(const std::string& dir) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(dir + "/probes.json", ec)) return false;
    if (!std::filesystem::exists(dir + "/report.json", ec)) return true; // a probe set baked before it wrote a report
    // both files: the report says which bake wrote the folder last (a folder keeps the files a
    // bake does not write, so a single bake over a probe set leaves probes.json behind)
    try {
        const std::vector<unsigned char> text = read_file(dir + "/report.json");
        const json_value r = ibl_examples::parse_json(std::string(text.begin(), text.end()));
        const json_value* f = r.is_object() ? r.find("format") : nullptr;
        return f && f->is_string() && f->string == probe_report_format;
    } catch (const std::exception&) {
        return false; // an unreadable report: the single bake's loader says what is wrong with it
    }
}

probe_set_folder load_probe_set(const std::string& dir) {
    const std::string pj = dir + "/probes.json", pk = dir + "/probes.ktx2";
    const std::vector<unsigned char> text = read_file(pj);
    json_value root;
    try {
        root = ibl_examples::parse_json(std::string(text.begin(), text.end()));
    } catch (const ibl_examples::json_error& e) {
        throw std::runtime_error(pj + ": malformed JSON at " + e.what());
    }
    const probe_json r{pj};
    probe_set_folder s;
    const json_value& conv = r.need(root, "conventions", "probe set");
    const json_value& mapping = r.need(conv, "mapping", "conventions");
    if (mapping.string != "linear" && mapping.string != "filament") r.fail("conventions.mapping", "expected linear or filament");
    s.specular = ibl::specular_lookup_desc::textbook(mapping.string == "filament" ? ibl::roughness_mapping::filament
                                                                                  : ibl::roughness_mapping::linear);
    const std::vector<cubemap_rgb32f> layers = decode_ktx2_cubemap_array(read_file(pk), pk);
    const json_value& list = r.need(root, "probes", "probe set");
    if (!list.is_array() || list.values.empty()) r.fail("probes", "expected a non-empty array");
    for (std::size_t i = 0; i < list.values.size(); ++i) {
        const json_value& v = list.values[i];
        const std::string w = "probes[" + std::to_string(i) + "]";
        loaded_probe p;
        const double layer = r.number(r.need(v, "layer", w), w + ".layer");
        if (layer != std::floor(layer) || layer < 0 || layer >= double(layers.size()))
            r.fail(w + ".layer", "not a layer of " + pk + " (" + std::to_string(layers.size()) + " layers)");
        p.layer = int(layer);
        p.position = r.vec(r.need(v, "position", w), w + ".position");
        p.proxy_sphere = r.volume(r.need(v, "proxy", w), w + ".proxy", p.proxy_box, p.proxy_ball);
        p.influence_sphere = r.volume(r.need(v, "influence", w), w + ".influence", p.influence_box, p.influence_ball);
        p.fade = r.number(r.need(v, "fade", w), w + ".fade");
        p.priority = int(r.number(r.need(v, "priority", w), w + ".priority"));
        const json_value& sh = r.need(v, "sh_irradiance", w);
        if (!sh.is_array() || sh.values.size() != 9) r.fail(w + ".sh_irradiance", "expected 9 RGB coefficients");
        for (int k = 0; k < 9; ++k) p.irradiance[k] = r.vec(sh.values[std::size_t(k)], w + ".sh_irradiance");
        p.chain = cubemap_from_rgb32f(layers[std::size_t(p.layer)]);
        s.probes.push_back(std::move(p));
    }
    return s;
}

std::vector<double> probe_contributions(const probe_set_folder& s, const dv3& p) {
    const std::size_t n = s.probes.size();
    std::vector<double> w(n), c(n, 0.0);
    std::vector<int> prio(n);
    for (std::size_t i = 0; i < n; ++i) {
        const loaded_probe& q = s.probes[i];
        w[i] = q.influence_sphere ? ibl::influence_weight(q.influence_ball, q.fade, p) : ibl::influence_weight(q.influence_box, q.fade, p);
        prio[i] = q.priority;
    }
    (void)ibl::blend_probe_weights(w.data(), prio.data(), n, c.data()); // the fallback share: no distant environment here
    double sum = 0.0;
    for (const double x : c) sum += x;
    if (sum > 0.0) {
        for (double& x : c) x /= sum;
        return c;
    }
    // outside every influence volume: the nearest probe alone (flagged by -1: no parallax correction)
    std::size_t best = 0;
    double bd = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
        const dv3 d = p - s.probes[i].position;
        const double dd = glm::dot(d, d);
        if (i == 0 || dd < bd) best = i, bd = dd;
    }
    c[best] = -1.0;
    return c;
}

dv3 local_specular(const probe_set_folder& s, const dv3& p, const dv3& d, double roughness) {
    const double r = std::clamp(roughness, 0.0, 1.0);
    const std::vector<double> c = probe_contributions(s, p);
    dv3 sum(0.0);
    for (std::size_t i = 0; i < c.size(); ++i) {
        const loaded_probe& q = s.probes[i];
        if (c[i] < 0.0) return dv3(ibl::specular_lookup(q.chain, ibl::vec3<float>(d), float(r), s.specular));
        if (!(c[i] > 0.0)) continue;
        const ibl::parallax_lookup<double> pl =
            q.proxy_sphere ? ibl::parallax_correct(q.proxy_ball, q.position, p, d) : ibl::parallax_correct(q.proxy_box, q.position, p, d);
        const double rc = ibl::corrected_roughness(r, pl);
        sum += c[i] * dv3(ibl::specular_lookup(q.chain, ibl::vec3<float>(pl.direction), float(rc), s.specular));
    }
    return sum;
}

dv3 local_irradiance(const probe_set_folder& s, const dv3& p, const dv3& n) {
    const std::vector<double> c = probe_contributions(s, p);
    dv3 sum(0.0);
    for (std::size_t i = 0; i < c.size(); ++i) {
        if (c[i] == 0.0) continue;
        const dv3 e = glm::max(ibl::sh_evaluate(s.probes[i].irradiance, n), dv3(0.0));
        if (c[i] < 0.0) return e;
        sum += c[i] * e;
    }
    return sum;
}

int run_probe_lookup(const probe_set_folder& s, std::istream& in, std::ostream& out) {
    std::string line;
    int status = 0;
    for (long n = 1; std::getline(in, line); ++n) {
        std::istringstream ls(line);
        std::string word;
        if (!(ls >> word) || word[0] == '#') continue;
        std::vector<double> a;
        try {
            if (!numbers(ls, a)) throw std::invalid_argument("expected numbers after '" + word + "'");
            if (word == "local") {
                if (a.size() != 7) throw std::invalid_argument("'local' takes 7 numbers, got " + std::to_string(a.size()));
                out << triple(local_specular(s, dv3(a[0], a[1], a[2]), unit(a[3], a[4], a[5], "the direction"), a[6])) << '\n';
            } else if (word == "local_irradiance") {
                if (a.size() != 6) throw std::invalid_argument("'local_irradiance' takes 6 numbers, got " + std::to_string(a.size()));
                out << triple(local_irradiance(s, dv3(a[0], a[1], a[2]), unit(a[3], a[4], a[5], "the normal"))) << '\n';
            } else if (word == "specular" || word == "dfg" || word == "irradiance" || word == "shade" || word == "sheen" ||
                       word == "dfg_sheen" || word == "lobe" || word == "lobe_b" || word == "taps") {
                throw std::invalid_argument("'" + word + "' needs a single bake's folder; this is a probe set (local, local_irradiance)");
            } else {
                throw std::invalid_argument("unknown query '" + word + "' (a probe set answers local, local_irradiance)");
            }
        } catch (const std::invalid_argument& e) {
            out << "error: line " << n << ": " << e.what() << ": " << line << '\n';
            status = 1;
        }
    }
    out.flush();
    return status;
}

} // namespace ibl_bake
