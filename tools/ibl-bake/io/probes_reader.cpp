// tools/ibl-bake/io/probes_reader.cpp — see probes_reader.hpp; the JSON reader is json_value.hpp.

#include "io/probes_reader.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "io/input_guard.hpp"
#include "io/json_value.hpp"

namespace ibl_bake {

namespace {

using ibl_examples::json_value;

const char* type_name(const json_value& v) {
    switch (v.type) {
    case json_value::kind::null: return "null";
    case json_value::kind::boolean: return "a boolean";
    case json_value::kind::number: return "a number";
    case json_value::kind::string: return "a string";
    case json_value::kind::array: return "an array";
    default: return "an object";
    }
}

struct probes_reader {
    std::string src, base;

    [[noreturn]] void fail(const std::string& where, const std::string& what) const {
        throw probes_error(src + ": " + where + ": " + what);
    }
    void object(const json_value& v, const std::string& where) const {
        if (!v.is_object()) fail(where, std::string("expected an object, got ") + type_name(v));
    }
    double number(const json_value& v, const std::string& where) const {
        if (!v.is_number()) fail(where, std::string("expected a number, got ") + type_name(v));
        if (!std::isfinite(v.number)) fail(where, "not a finite number");
        return v.number;
    }
    std::array<double, 3> vec3(const json_value& v, const std::string& where) const {
        if (!v.is_array()) fail(where, std::string("expected [x, y, z], got ") + type_name(v));
        if (v.values.size() != 3) fail(where, "expected [x, y, z] (3 numbers), got " + std::to_string(v.values.size()));
        return {number(v.values[0], where + "[0]"), number(v.values[1], where + "[1]"), number(v.values[2], where + "[2]")};
    }
    const json_value& need(const json_value& v, const char* key, const std::string& where) const {
        const json_value* m = v.find(key);
        if (!m) fail(where, std::string("missing \"") + key + "\"");
        return *m;
    }
    bool comment(const std::string& k, const json_value& x, const std::string& where) const {
        if (k != "$comment" && k != "description") return false;
        if (!x.is_string()) fail(where + "." + k, std::string("expected a string, got ") + type_name(x));
        return true;
    }

    /// A box: {"min", "max"} (axis-aligned) or {"center", "half_extents", "axes"} (oriented).
    void box(const json_value& x, const std::string& w, probe_volume_desc& d) const {
        object(x, w);
        bool aligned = false, oriented = false;
        for (std::size_t j = 0; j < x.keys.size(); ++j) {
            const std::string& k = x.keys[j];
            if (comment(k, x.values[j], w)) continue;
            if (k == "min" || k == "max") aligned = true;
            else if (k == "center" || k == "half_extents" || k == "axes") oriented = true;
            else fail(w + "." + k, "unknown key (expected min, max, or center, half_extents, axes)");
        }
        if (aligned && oriented)
            fail(w, "both min/max and center/half_extents/axes (two forms of a box: give one)");
        d.sphere = false;
        if (!oriented) {
            d.min = vec3(need(x, "min", w), w + ".min");
            d.max = vec3(need(x, "max", w), w + ".max");
            for (int a = 0; a < 3; ++a)
                if (d.min[std::size_t(a)] > d.max[std::size_t(a)]) fail(w, std::string("min > max along ") + "xyz"[a]);
            return;
        }
        d.oriented = true;
        d.center = vec3(need(x, "center", w), w + ".center");
        d.half_extents = vec3(need(x, "half_extents", w), w + ".half_extents");
        for (std::size_t a = 0; a < 3; ++a)
            if (!(d.half_extents[a] >= 0.0)) fail(w + ".half_extents[" + std::to_string(a) + "]", "must be >= 0");
        const json_value* ax = x.find("axes");
        if (!ax) return; // the world's axes
        const std::string wa = w + ".axes";
        if (!ax->is_array()) fail(wa, std::string("expected [[x, y, z], [x, y, z], [x, y, z]], got ") + type_name(*ax));
        if (ax->values.size() != 3) fail(wa, "expected 3 axes, got " + std::to_string(ax->values.size()));
        using a3 = std::array<double, 3>;
        const auto dot = [](const a3& a, const a3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; };
        for (std::size_t i = 0; i < 3; ++i) {
            d.axes[i] = vec3(ax->values[i], wa + "[" + std::to_string(i) + "]");
            const double len = std::sqrt(dot(d.axes[i], d.axes[i]));
            if (!(std::fabs(len - 1.0) <= 1e-3))
                fail(wa + "[" + std::to_string(i) + "]", "not a unit vector (length " + std::to_string(len) + ")");
        }
        for (std::size_t i = 0; i < 3; ++i)
            for (std::size_t j = i + 1; j < 3; ++j)
                if (!(std::fabs(dot(d.axes[i], d.axes[j])) <= 1e-3))
                    fail(wa, "axes[" + std::to_string(i) + "] and axes[" + std::to_string(j) +
                                 "] are not perpendicular (dot " + std::to_string(dot(d.axes[i], d.axes[j])) + ")");
        // Gram-Schmidt: exactly orthonormal (the checks above keep every step well away from zero)
        for (std::size_t i = 0; i < 3; ++i) {
            a3 v = d.axes[i];
            for (std::size_t j = 0; j < i; ++j) {
                const double p = dot(v, d.axes[j]);
                for (std::size_t c = 0; c < 3; ++c) v[c] -= p * d.axes[j][c];
            }
            const double len = std::sqrt(dot(v, v));
            for (std::size_t c = 0; c < 3; ++c) v[c] /= len;
            d.axes[i] = v;
        }
    }

    /// {"box": {...}} or {"sphere": {...}} (and, for influences, "fade").
    probe_volume_desc volume(const json_value& v, const std::string& where, double* fade) const {
        object(v, where);
        probe_volume_desc d;
        int shapes = 0;
        bool have_fade = false;
        for (std::size_t i = 0; i < v.keys.size(); ++i) {
            const std::string& k = v.keys[i];
            const json_value& x = v.values[i];
            const std::string w = where + "." + k;
            if (comment(k, x, where)) continue;
            if (k == "box") {
                box(x, w, d);
                ++shapes;
            } else if (k == "sphere") {
                object(x, w);
                for (std::size_t j = 0; j < x.keys.size(); ++j)
                    if (x.keys[j] != "center" && x.keys[j] != "radius" && !comment(x.keys[j], x.values[j], w))
                        fail(w + "." + x.keys[j], "unknown key (expected center, radius)");
                d.sphere = true;
                d.center = vec3(need(x, "center", w), w + ".center");
                d.radius = number(need(x, "radius", w), w + ".radius");
                if (!(d.radius > 0.0)) fail(w + ".radius", "must be > 0");
                ++shapes;
            } else if (k == "fade" && fade) {
                *fade = number(x, w);
                if (!(*fade > 0.0)) fail(w, "must be > 0");
                have_fade = true;
            } else {
                fail(w, fade ? "unknown key (expected box or sphere, and fade)" : "unknown key (expected box or sphere)");
            }
        }
        if (shapes == 0) fail(where, "missing \"box\" or \"sphere\"");
        if (shapes > 1) fail(where, "both \"box\" and \"sphere\" (one volume each)");
        if (fade && !have_fade) fail(where, "missing \"fade\"");
        return d;
    }

    probe_desc probe(const json_value& v, const std::string& where) const {
        object(v, where);
        probe_desc p;
        for (std::size_t i = 0; i < v.keys.size(); ++i) {
            const std::string& k = v.keys[i];
            const std::string w = where + "." + k;
            if (comment(k, v.values[i], where)) continue;
            if (k != "input" && k != "position" && k != "proxy" && k != "influence" && k != "priority")
                fail(w, "unknown key (expected input, position, proxy, influence, priority)");
        }
        const json_value& in = need(v, "input", where);
        if (!in.is_string()) fail(where + ".input", std::string("expected a string, got ") + type_name(in));
        if (in.string.empty()) fail(where + ".input", "empty path");
        if (in.string.find('\0') != std::string::npos) fail(where + ".input", "a NUL character in the path");
        std::filesystem::path ip(in.string);
        p.input = ip.is_relative() && !base.empty() ? (std::filesystem::path(base) / ip).string() : in.string;
        p.position = vec3(need(v, "position", where), where + ".position");
        p.proxy = volume(need(v, "proxy", where), where + ".proxy", nullptr);
        p.influence = volume(need(v, "influence", where), where + ".influence", &p.fade);
        if (const json_value* pr = v.find("priority")) {
            const double d = number(*pr, where + ".priority");
            if (d != std::floor(d) || d < -1000000.0 || d > 1000000.0)
                fail(where + ".priority", "expected an integer in [-1000000, 1000000]");
            p.priority = int(d);
        }
        return p;
    }

    std::vector<probe_desc> set(const json_value& root) const {
        object(root, "probe set");
        for (std::size_t i = 0; i < root.keys.size(); ++i)
            if (root.keys[i] != "probes" && !comment(root.keys[i], root.values[i], "probe set"))
                fail(root.keys[i], "unknown key (expected probes)");
        const json_value& a = need(root, "probes", "probe set");
        if (!a.is_array()) fail("probes", std::string("expected an array, got ") + type_name(a));
        if (a.values.empty()) fail("probes", "no probes (a probe set needs at least one)");
        if (a.values.size() > probe_set_max)
            fail("probes", std::to_string(a.values.size()) + " probes, at most " + std::to_string(probe_set_max));
        std::vector<probe_desc> out;
        for (std::size_t i = 0; i < a.values.size(); ++i) out.push_back(probe(a.values[i], "probes[" + std::to_string(i) + "]"));
        return out;
    }
};

} // namespace

std::vector<probe_desc> parse_probes(const std::string& text, const std::string& source, const std::string& base_dir) {
    json_value root;
    try {
        root = ibl_examples::parse_json(text);
    } catch (const ibl_examples::json_error& e) { // "line:col: what"
        const std::string m = e.what();
        const std::size_t c1 = m.find(':'), c2 = c1 == std::string::npos ? c1 : m.find(':', c1 + 1);
        if (c2 == std::string::npos) throw probes_error(source + ": malformed JSON: " + m);
        throw probes_error(source + ": malformed JSON at line " + m.substr(0, c1) + ", column " + m.substr(c1 + 1, c2 - c1 - 1) +
                           ":" + m.substr(c2 + 1));
    }
    return probes_reader{source, base_dir}.set(root);
}

std::vector<probe_desc> read_probes(const std::string& path) {
    try {
        check_input_file(path, scene_byte_limit);
    } catch (const image_error& e) {
        throw probes_error(e.what());
    }
    std::ifstream in(path, std::ios::binary);
    if (!in) throw probes_error(path + ": cannot open the probe-set file");
    std::ostringstream ss;
    ss << in.rdbuf();
    const std::filesystem::path parent = std::filesystem::path(path).parent_path();
    return parse_probes(ss.str(), path, parent.string()); // no folder in the path: relative to the current one as it is
}

} // namespace ibl_bake
