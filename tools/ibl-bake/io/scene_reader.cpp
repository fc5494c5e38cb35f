// tools/ibl-bake/io/scene_reader.cpp — see scene_reader.hpp; the JSON reader is json_value.hpp.

#include "io/scene_reader.hpp"

#include <cmath>
#include <cstdint>
#include <fstream>
#include <sstream>
#include <utility>
#include <vector>

#include "io/input_guard.hpp"
#include "io/json_value.hpp"

namespace ibl_bake {

namespace {

using ibl_examples::json_value;
using jarray = std::vector<json_value>;
using jobject = std::vector<std::pair<std::string, json_value>>;

const char* json_type_name(const json_value& v) {
    switch (v.type) {
    case json_value::kind::null: return "null";
    case json_value::kind::boolean: return "a boolean";
    case json_value::kind::number: return "a number";
    case json_value::kind::string: return "a string";
    case json_value::kind::array: return "an array";
    default: return "an object";
    }
}

// ---- scene content ----------------------------------------------------------------------------------

struct scene_reader {
    std::string src;
    [[noreturn]] void fail(const std::string& where, const std::string& what) const {
        throw scene_error(src + ": " + where + ": " + what);
    }
    double number(const json_value& v, const std::string& where) const {
        if (v.is_number()) return v.number;
        fail(where, std::string("expected a number, got ") + json_type_name(v));
    }
    bool boolean(const json_value& v, const std::string& where) const {
        if (v.is_bool()) return v.boolean;
        fail(where, std::string("expected true or false, got ") + json_type_name(v));
    }
    int integer(const json_value& v, const std::string& where, int lo, int hi) const {
        const double d = number(v, where);
        if (d != std::floor(d) || d < lo || d > hi)
            fail(where, "expected an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
        return int(d);
    }
    std::string string(const json_value& v, const std::string& where) const {
        if (v.is_string()) return v.string;
        fail(where, std::string("expected a string, got ") + json_type_name(v));
    }
    const jarray& array(const json_value& v, const std::string& where) const {
        if (v.is_array()) return v.values;
        fail(where, std::string("expected an array, got ") + json_type_name(v));
    }
    /// The members of an object in file order (a copy: scene files are small).
    jobject object(const json_value& v, const std::string& where) const {
        if (!v.is_object()) fail(where, std::string("expected an object, got ") + json_type_name(v));
        jobject members;
        for (std::size_t i = 0; i < v.keys.size(); ++i) members.emplace_back(v.keys[i], v.values[i]);
        return members;
    }

    ibl::material_class material(const json_value& v, const std::string& where) const {
        ibl::material_class m;
        bool have_metallic = false;
        for (const auto& [k, x] : object(v, where)) {
            const std::string w = where + "." + k;
            if (k == "name") m.name = string(x, w);
            else if (k == "metallic") m.metallic = number(x, w), have_metallic = true;
            else if (k == "roughness") {
                for (const json_value& r : array(x, w)) {
                    const double d = number(r, w);
                    m.roughness.push_back({d, d});
                }
            } else if (k == "roughness_range") {
                const jarray& a = array(x, w);
                if (a.size() != 2) fail(w, "expected [lo, hi]");
                m.roughness.push_back({number(a[0], w), number(a[1], w)});
            } else if (k == "roughness_histogram") {
                const jarray& a = array(x, w);
                if (a.empty()) fail(w, "empty histogram");
                for (std::size_t i = 0; i < a.size(); ++i) {
                    const double c = number(a[i], w);
                    if (c < 0) fail(w, "negative count");
                    if (c > 0) m.roughness.push_back({double(i) / double(a.size()), double(i + 1) / double(a.size())});
                }
                if (m.roughness.empty()) fail(w, "every bin is empty");
            } else fail(w, "unknown key (expected name, metallic, roughness, roughness_range, roughness_histogram)");
        }
        if (!have_metallic) fail(where, "missing \"metallic\"");
        if (m.roughness.empty()) fail(where, "missing \"roughness\", \"roughness_range\" or \"roughness_histogram\"");
        if (m.name.empty()) m.name = where;
        return m;
    }

    ibl::scene_description scene(const json_value& root) const {
        ibl::scene_description s;
        bool have_materials = false;
        for (const auto& [k, x] : object(root, "scene")) {
            if (k == "name") s.name = string(x, k);
            else if (k == "error_target") s.error_target = number(x, k);
            else if (k == "diffuse_error_target") s.diffuse_error_target = number(x, k);
            else if (k == "diffuse_ibl") s.diffuse_ibl = boolean(x, k);
            else if (k == "max_reflection_pixels") s.max_reflection_pixels = integer(x, k, 1, 1 << 16);
            else if (k == "multiscatter") s.multiscatter = boolean(x, k);
            else if (k == "limits") {
                for (const auto& [lk, lx] : object(x, k)) {
                    const std::string w = "limits." + lk;
                    if (lk == "max_sh_bands") s.limits.max_sh_bands = integer(lx, w, 2, 3);
                    else if (lk == "max_dfg_size") s.limits.max_dfg_size = integer(lx, w, 16, 1024);
                    else if (lk == "max_samples") s.limits.max_samples = std::uint32_t(integer(lx, w, 16, 1 << 20));
                    else fail(w, "unknown key (expected max_sh_bands, max_dfg_size, max_samples)");
                }
            } else if (k == "materials") {
                have_materials = true;
                const jarray& a = array(x, k);
                for (std::size_t i = 0; i < a.size(); ++i) s.materials.push_back(material(a[i], "materials[" + std::to_string(i) + "]"));
            } else if (k == "$comment" || k == "description") {
                (void)string(x, k);
            } else {
                fail(k, "unknown key");
            }
        }
        if (!have_materials || s.materials.empty()) fail("materials", "a scene needs at least one material");
        return s;
    }
};


} // namespace

ibl::scene_description parse_scene(const std::string& text, const std::string& source) {
    json_value root;
    try {
        root = ibl_examples::parse_json(text);
    } catch (const ibl_examples::json_error& e) { // "line:col: what"
        const std::string m = e.what();
        const std::size_t c1 = m.find(':'), c2 = m.find(':', c1 + 1);
        throw scene_error(source + ": malformed JSON at line " + m.substr(0, c1) + ", column " +
                          m.substr(c1 + 1, c2 - c1 - 1) + ":" + m.substr(c2 + 1));
    }
    return scene_reader{source}.scene(root);
}

ibl::scene_description read_scene(const std::string& path) {
    try {
        check_input_file(path, scene_byte_limit);
    } catch (const image_error& e) {
        throw scene_error(e.what());
    }
    std::ifstream in(path, std::ios::binary);
    if (!in) throw scene_error(path + ": cannot open the scene file");
    std::ostringstream ss;
    ss << in.rdbuf();
    return parse_scene(ss.str(), path);
}

} // namespace ibl_bake
