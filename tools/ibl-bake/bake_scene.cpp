// tools/ibl-bake/bake_scene.cpp — `ibl-bake --scene` (see bake_scene.hpp, docs/scene-format.md).
//
//   scene.json --parse--> ibl::scene_description --ibl::make_bake_plan--> ibl::bake_plan
//   source (lat-long file or built-in sky) --bake at plan.source_size--> source cube
//   the plan's products only:
//     specular  stored levels first_level .. last_level of the virtual chain, each by filtered
//               importance sampling (nearest-level reads) with the plan's samples; virtual level 0
//               is a copy of the source
//     diffuse   2- or 3-band SH projection (auto window if the irradiance goes negative), or an
//               irradiance cubemap, or nothing
//     dfg       exact quadrature table of the plan's size, 2 or 3 channels
//   --compare-full: also the full products (ibl-bake's defaults for --size/--quality) and a
//   converged set (the levels the scene reads at full resolution with 4096 filtered-IS samples and
//   trilinear reads, dfg_exact,
//   brute-force irradiance), timed; the scene's materials are shaded with each set at 54 normals x
//   the used roughness values; the planned and full products' error is against the converged set
//   (the error the plan's target refers to), and separately the converged split sum against
//   ibl::reference_radiance (the split-sum approximation's own error, which no plan can change).

#include "bake_scene.hpp"
#include "check_texels.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>
#include <span>
#include <string>
#include <type_traits>
#include <vector>

#include <unistd.h>

#include <ibl/brdf/model.hpp>
#include <ibl/core/color.hpp>
#include <ibl/core/frame.hpp>
#include <ibl/env/analytic.hpp>
#include <ibl/env/convert.hpp>
#include <ibl/env/cube_geometry.hpp>
#include <ibl/env/cubemap.hpp>
#include <ibl/env/latlong.hpp>
#include <ibl/integrate/dfg.hpp>
#include <ibl/integrate/dfg_lut.hpp>
#include <ibl/integrate/env_importance.hpp>
#include <ibl/integrate/irradiance.hpp>
#include <ibl/integrate/prefilter.hpp>
#include <ibl/integrate/metrics.hpp>
#include <ibl/integrate/radiance_reference.hpp>
#include <ibl/integrate/reference.hpp>
#include <ibl/plan.hpp>
#include <ibl/sh/basis.hpp>
#include <ibl/sh/convolve.hpp>
#include <ibl/sh/project.hpp>
#include <ibl/sh/window.hpp>
#include <ibl/shade.hpp>

#include "bake_exec.hpp"
#include "bake_stage.hpp"
#include "image_io.hpp"
#include "json.hpp"
#include "json_value.hpp"
#include "ktx2.hpp"

namespace ibl_bake {

namespace {

using dvec3 = ibl::vec3<double>;
using fvec3 = ibl::vec3<float>;
using model = ibl::ggx_height_correlated;

// ---- JSON access (the reader is json_value.hpp) ----------

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

// ---- baking the plan ----------------------------------------------------------------------------------

double ms_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}
std::string fmt(const char* f, double a) {
    char buf[160];
    std::snprintf(buf, sizeof buf, f, a);
    return buf;
}

struct source_data {
    std::string name;
    bool analytic = true;
    std::unique_ptr<ibl::latlong<float>> map;
    int width = 0;
};

/// Diffuse product: SH (stored as 3 bands; band 2 zero for a 2-band plan) or an irradiance map.
struct diffuse_data {
    ibl::diffuse_product kind = ibl::diffuse_product::none;
    int bands = 0;
    ibl::sh_coeffs<double, 3> radiance{};
    ibl::cubemap<float> map{1};
    dvec3 irradiance_over_pi(const dvec3& n) const {
        if (kind == ibl::diffuse_product::sh) return glm::max(ibl::sh_irradiance_at(radiance, n), dvec3(0.0)) / ibl::pi_v<double>;
        if (kind == ibl::diffuse_product::irradiance_map) return dvec3(map.radiance(fvec3(n), 0.0f)) / ibl::pi_v<double>;
        return dvec3(0.0);
    }
};

template <int B> diffuse_data project_sh(const ibl::cubemap<float>& src, pool_executor& ex) {
    const auto raw = ibl::project_cube<B>(
        src.size(0), [&](int f, int x, int y) { return dvec3(src.texel(f, x, y, 0)); }, ex);
    // No window: the plan's SH error figures are for the plain projection, and a window only adds
    // error (it trades accuracy for E >= 0); the renderer clamps E at 0 (irradiance_over_pi).
    diffuse_data d;
    d.kind = ibl::diffuse_product::sh;
    d.bands = B;
    for (int k = 0; k < B * B; ++k) d.radiance[k] = raw[k];
    return d;
}

/// The products as a renderer samples them: a chain with its lod rule, a DFG source, irradiance.
struct product_set {
    const ibl::cubemap<float>* chain = nullptr;
    ibl::roughness_mip_policy policy{};
    int virtual_levels = 1, first_level = 0;
    const ibl::dfg_lut* lut = nullptr; ///< nullptr: dfg_exact
    const diffuse_data* diffuse = nullptr;
    const std::vector<dvec3>* brute_normals = nullptr; ///< converged irradiance at these normals
    const std::vector<dvec3>* brute_e = nullptr;

    ibl::ibl_sample<double> sample(const dvec3& n, const dvec3& v, double r, std::size_t normal_index) const {
        ibl::ibl_sample<double> s;
        const double n_dot_v = std::clamp(glm::dot(n, v), 0.0, 1.0);
        const dvec3 refl = 2.0 * glm::dot(n, v) * n - v;
        const float lod = policy.lod(float(r), virtual_levels) - float(first_level);
        s.ld = dvec3(chain->radiance(fvec3(refl), std::max(lod, 0.0f)));
        if (lut) {
            const fvec3 ab = lut->sample(float(n_dot_v), float(r));
            s.dfg = ibl::vec2<double>(ab.x, ab.y);
        } else {
            s.dfg = ibl::dfg_exact<model>(n_dot_v, r);
        }
        if (brute_e) s.irradiance_over_pi = (*brute_e)[normal_index] / ibl::pi_v<double>;
        else if (diffuse) s.irradiance_over_pi = diffuse->irradiance_over_pi(n);
        return s;
    }
};

struct shading_point {
    dvec3 n, v;
    std::size_t normal_index;
};

struct material_sample {
    std::string name;
    ibl::pbr_material<double> m;
};

/// Relative RMS and largest relative difference of luminance between two product sets.
struct shade_error {
    double rel_rms = 0.0, max_rel = 0.0;
    std::size_t points = 0;
};

shade_error compare_shading(const std::vector<material_sample>& mats, const std::vector<shading_point>& pts,
                            const product_set& a, const product_set& ref, bool multiscatter) {
    double num = 0.0, den = 0.0;
    shade_error e;
    for (const auto& ms : mats) {
        const auto shader = ibl::pbr_shader<double>::from(ms.m, multiscatter);
        for (const auto& p : pts) {
            const double nv = std::clamp(glm::dot(p.n, p.v), 0.0, 1.0);
            const double ya = ibl::luminance(shader.ambient(nv, a.sample(p.n, p.v, ms.m.roughness, p.normal_index)));
            const double yr = ibl::luminance(shader.ambient(nv, ref.sample(p.n, p.v, ms.m.roughness, p.normal_index)));
            num += (ya - yr) * (ya - yr);
            den += yr * yr;
            if (yr > 0) e.max_rel = std::max(e.max_rel, std::fabs(ya - yr) / yr);
            ++e.points;
        }
    }
    e.rel_rms = den > 0 ? std::sqrt(num / den) : 0.0;
    return e;
}

/// Brute-force irradiance E(n) over every texel of the first source level of face <= 64.
std::vector<dvec3> brute_irradiance(const ibl::cubemap<float>& src, const std::vector<dvec3>& normals, pool_executor& ex) {
    int level = 0;
    while (src.size(level) > 64 && level + 1 < src.levels()) ++level;
    const int n = src.size(level);
    std::vector<dvec3> dir, rad;
    for (int f = 0; f < 6; ++f)
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
                dir.push_back(ibl::cube_texel_direction<double>(f, x, y, n));
                rad.push_back(dvec3(src.texel(f, x, y, level)) * ibl::cube_texel_solid_angle<double>(x, y, n));
            }
    std::vector<dvec3> e(normals.size());
    ex(normals.size(), [&](std::size_t b, std::size_t end) {
        for (std::size_t i = b; i < end; ++i) {
            dvec3 s(0.0);
            for (std::size_t t = 0; t < dir.size(); ++t) s += rad[t] * std::max(0.0, glm::dot(normals[i], dir[t]));
            e[i] = s;
        }
    });
    return e;
}

/// Bakes virtual levels [first, first + count) of the chain (sizes base >> v) with per-level samples.
ibl::cubemap<float> bake_chain(const ibl::cubemap<float>& src, const ibl::specular_plan& sp, pool_executor& ex) {
    const int stored_base = std::max(1, sp.virtual_base_size >> sp.first_level);
    ibl::cubemap<float> chain(stored_base, int(sp.levels.size()));
    for (std::size_t k = 0; k < sp.levels.size(); ++k) {
        const ibl::specular_level_plan& lp = sp.levels[k];
        const int n = chain.size(int(k));
        if (lp.level == 0) { // the mirror level: the source at the output texel centres
            const int sl = std::clamp(int(std::lround(std::log2(double(src.size(0)) / double(n)))), 0, src.levels() - 1);
            chain.fill(int(k), [&](int f, int x, int y) {
                return src.size(sl) == n ? src.texel(f, x, y, sl)
                                         : src.radiance(ibl::cube_texel_direction<float>(f, x, y, n), float(sl));
            });
            continue;
        }
        ibl::sphere_sample_table<float> table = ibl::make_ld_table_for<float>(
            src, lp.roughness, lp.samples, ibl::prefilter_method::filtered_importance, 0.5);
        table.trilinear = lp.trilinear;
        const std::vector<fvec3> texels = ibl::convolve_faces(src, table, n, ex);
        chain.fill(int(k), [&](int f, int x, int y) {
            return texels[(std::size_t(f) * std::size_t(n) + std::size_t(y)) * std::size_t(n) + std::size_t(x)];
        });
    }
    chain.update_borders();
    return chain;
}

cubemap_rgb32f to_ktx(const ibl::cubemap<float>& c) {
    cubemap_rgb32f k = cubemap_rgb32f::zeros(c.size(0), c.levels());
    for (int l = 0; l < c.levels(); ++l) {
        const int s = k.face_size(l);
        for (int f = 0; f < 6; ++f)
            for (int y = 0; y < s; ++y)
                for (int x = 0; x < s; ++x) {
                    const fvec3& v = c.texel(f, x, y, l);
                    float* t = &k.levels[std::size_t(l)][std::size_t(f)][3 * (std::size_t(y) * std::size_t(s) + std::size_t(x))];
                    t[0] = v.x, t[1] = v.y, t[2] = v.z;
                }
    }
    return k;
}

void write_text(const std::string& path, const std::string& text) {
    write_file_atomic(path, std::span<const unsigned char>(reinterpret_cast<const unsigned char*>(text.data()), text.size()));
}

const char* diffuse_name(ibl::diffuse_product k) {
    return k == ibl::diffuse_product::sh ? "sh" : k == ibl::diffuse_product::irradiance_map ? "irradiance_map" : "none";
}

void plan_json(json_writer& j, const ibl::bake_plan& p, const ibl::plan_cost& c) {
    j.begin_object();
    j.key("source_size").value(p.source_size);
    j.key("specular").begin_object();
    j.key("virtual_levels").value(p.specular.virtual_levels);
    j.key("virtual_base_size").value(p.specular.virtual_base_size);
    j.key("first_level").value(p.specular.first_level);
    j.key("trilinear_reads").value(p.specular.trilinear);
    j.key("levels").begin_array();
    for (const auto& l : p.specular.levels) {
        j.begin_object();
        j.key("virtual_level").value(l.level).key("size").value(l.size).key("roughness").value(l.roughness);
        j.key("samples").value(l.samples).key("trilinear").value(l.trilinear).key("needed").value(l.needed).key("expected_nrmse").value(l.expected_error);
        j.end_object();
    }
    j.end_array();
    j.end_object();
    j.key("diffuse").begin_object();
    j.key("kind").value(diffuse_name(p.diffuse.kind)).key("sh_bands").value(p.diffuse.sh_bands);
    j.key("map_size").value(p.diffuse.map_size).key("expected_error").value(p.diffuse.expected_error);
    j.end_object();
    j.key("dfg").begin_object();
    j.key("size").value(p.dfg.size).key("channels").value(p.dfg.channels).key("expected_max_abs").value(p.dfg.expected_error);
    j.end_object();
    j.key("estimated_ms").begin_object();
    j.key("source").value(c.source_ms).key("specular").value(c.specular_ms).key("diffuse").value(c.diffuse_ms);
    j.key("dfg").value(c.dfg_ms).key("total").value(c.total_ms());
    j.end_object();
    j.end_object();
}

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
    std::ifstream in(path, std::ios::binary);
    if (!in) throw scene_error(path + ": cannot open the scene file");
    std::ostringstream ss;
    ss << in.rdbuf();
    return parse_scene(ss.str(), path);
}

void run_scene_bake(const bake_options& opt, std::FILE* out) {
    const auto t_all = std::chrono::steady_clock::now();
    const quality_settings qs = settings_for(opt.q);
    check_output_dir(opt.out);

    // ---- plan ------------------------------------------------------------------------------------
    const ibl::scene_description scene = read_scene(opt.scene);
    ibl::plan_settings set;
    set.levels = opt.levels > 0 ? opt.levels : auto_levels(opt.size);
    set.max_base_size = opt.size;
    set.policy = ibl::roughness_mip_policy::linear();
    ibl::bake_plan plan;
    try {
        plan = ibl::make_bake_plan(scene, set);
    } catch (const std::invalid_argument& e) {
        throw scene_error(opt.scene + ": " + e.what());
    }
    const ibl::bake_plan full = ibl::full_bake_plan(set, qs.prefilter_samples, qs.trilinear, opt.lut_size);
    const ibl::plan_cost est = ibl::estimate_cost(plan, qs.bake_k), est_full = ibl::estimate_cost(full, qs.bake_k);

    progress prog(!opt.quiet, ::isatty(2) != 0);
    pool_executor ex(opt.threads, &prog);

    // ---- source ----------------------------------------------------------------------------------
    source_data src;
    if (!opt.input.empty()) {
        prog.begin("read input");
        image_rgb32f img = read_latlong(opt.input);
        src.analytic = false;
        src.name = opt.input;
        src.width = img.width;
        src.map = std::make_unique<ibl::latlong<float>>(img.width, img.height, std::span<const float>(img.rgb), 1);
        src.map->update_borders();
        prog.end();
    } else {
        src.name = "built-in sky + sun (ibl::make_default_sky)";
    }
    auto bake_source = [&](int n) {
        if (src.analytic) return ibl::bake_cubemap<float>(ibl::make_default_sky<float>(), n, qs.bake_k, ex, 0);
        const int k = std::clamp(int(std::ceil(double(src.width) / (4.0 * n))), qs.bake_k, 32);
        return ibl::bake_cubemap<float>(*src.map, n, k, ex, 0);
    };

    struct timed {
        double source = 0, specular = 0, diffuse = 0, dfg = 0;
        double total() const { return source + specular + diffuse + dfg; }
    };

    // ---- the planned products ----------------------------------------------------------------------
    timed tp;
    prog.begin("source cube");
    auto t0 = std::chrono::steady_clock::now();
    const ibl::cubemap<float> source = bake_source(plan.source_size);
    tp.source = ms_since(t0);
    prog.end();
    prog.begin("specular (planned)");
    t0 = std::chrono::steady_clock::now();
    const ibl::cubemap<float> chain = bake_chain(source, plan.specular, ex);
    tp.specular = ms_since(t0);
    prog.end();
    prog.begin("diffuse (planned)");
    t0 = std::chrono::steady_clock::now();
    diffuse_data diffuse;
    if (plan.diffuse.kind == ibl::diffuse_product::sh) {
        diffuse = plan.diffuse.sh_bands == 2 ? project_sh<2>(source, ex) : project_sh<3>(source, ex);
    } else if (plan.diffuse.kind == ibl::diffuse_product::irradiance_map) {
        ibl::irradiance_options io;
        io.size = plan.diffuse.map_size;
        io.samples = plan.diffuse.map_samples;
        diffuse.kind = ibl::diffuse_product::irradiance_map;
        diffuse.map = ibl::irradiance_cubemap(source, io, ex);
    }
    tp.diffuse = ms_since(t0);
    prog.end();
    prog.begin("dfg (planned)");
    t0 = std::chrono::steady_clock::now();
    const ibl::dfg_lut lut = ibl::make_dfg_lut_exact<model>(std::uint32_t(plan.dfg.size), std::uint32_t(plan.dfg.channels),
                                                            qs.dfg_nodes, ex);
    tp.dfg = ms_since(t0);
    prog.end();

    // ---- --compare-full: full products, converged products, shading errors ---------------------------
    timed tf;
    shade_error err_plan, err_full;
    struct split_row {
        std::string material;
        double roughness, mean_abs_rel, max_abs_rel;
    };
    std::vector<split_row> split;
    struct level_check {
        int level;
        double roughness, nrmse_plan, nrmse_full, conv_plan = 0, conv_full = 0, expected = 0;
        std::uint32_t samples = 0;
        bool trilinear = false;
    };
    std::vector<level_check> level_checks;
    double converged_ms = 0.0;
    std::size_t shading_points = 0;
    if (opt.compare_full) {
        prog.begin("full bake");
        t0 = std::chrono::steady_clock::now();
        const ibl::cubemap<float> fsource = bake_source(opt.size);
        tf.source = ms_since(t0);
        t0 = std::chrono::steady_clock::now();
        ibl::prefilter_options po;
        po.levels = set.levels;
        po.base_size = opt.size;
        po.policy = set.policy;
        po.samples = qs.prefilter_samples;
        po.trilinear = qs.trilinear;
        const ibl::cubemap<float> fchain = ibl::prefilter(fsource, po, ex);
        tf.specular = ms_since(t0);
        t0 = std::chrono::steady_clock::now();
        const diffuse_data fdiffuse = project_sh<3>(fsource, ex);
        tf.diffuse = ms_since(t0);
        t0 = std::chrono::steady_clock::now();
        const ibl::dfg_lut flut = ibl::make_dfg_lut_exact<model>(std::uint32_t(opt.lut_size), 3, qs.dfg_nodes, ex);
        tf.dfg = ms_since(t0);
        prog.end();

        // Converged: the virtual levels the scene reads, at full resolution, 4096 samples.
        prog.begin("converged products");
        t0 = std::chrono::steady_clock::now();
        ibl::specular_plan cp = plan.specular;
        cp.virtual_base_size = opt.size;
        cp.trilinear = true;
        for (auto& l : cp.levels) {
            l.trilinear = true;
            l.size = std::max(1, opt.size >> l.level);
            if (l.level > 0) l.samples = 4096;
        }
        const ibl::cubemap<float> cchain = bake_chain(fsource, cp, ex);
        std::vector<dvec3> normals;
        for (int f = 0; f < 6; ++f)
            for (int y = 0; y < 3; ++y)
                for (int x = 0; x < 3; ++x) normals.push_back(ibl::cube_texel_direction<double>(f, x, y, 3));
        const std::vector<dvec3> e_brute = brute_irradiance(fsource, normals, ex);
        converged_ms = ms_since(t0);
        prog.end();

        // Shading points: each normal seen at 45 degrees; materials at lo, mid, hi of each range.
        std::vector<shading_point> pts;
        for (std::size_t i = 0; i < normals.size(); ++i) {
            const ibl::frame<double> fr = ibl::make_frame(normals[i]);
            pts.push_back({normals[i], glm::normalize(normals[i] + fr.t), i});
        }
        std::vector<material_sample> mats;
        for (const auto& m : scene.materials)
            for (const auto& r : m.roughness)
                for (double x : {r.lo, 0.5 * (r.lo + r.hi), r.hi}) {
                    ibl::pbr_material<double> pm;
                    pm.metallic = std::clamp(m.metallic, 0.0, 1.0);
                    pm.base_color = pm.metallic > 0.5 ? dvec3(0.95, 0.64, 0.54) : dvec3(0.8);
                    pm.roughness = std::clamp(x, 0.0, 1.0);
                    if (!mats.empty() && mats.back().name == m.name && mats.back().m.roughness == pm.roughness) continue;
                    mats.push_back({m.name, pm});
                }
        const bool diffuse_lit = plan.diffuse.kind != ibl::diffuse_product::none;
        const product_set ps_plan{&chain, set.policy, set.levels, plan.specular.first_level, &lut,
                                  diffuse_lit ? &diffuse : nullptr, nullptr, nullptr};
        const product_set ps_full{&fchain, set.policy, set.levels, 0, &flut, diffuse_lit ? &fdiffuse : nullptr, nullptr, nullptr};
        const product_set ps_conv{&cchain, set.policy, set.levels, plan.specular.first_level, nullptr, nullptr,
                                  diffuse_lit ? &normals : nullptr, diffuse_lit ? &e_brute : nullptr};
        // Per level: planned and full chains against the reference LD (the measure plan.hpp's C(r)
        // was fitted with): a 6 x 6 grid per face plus the 3 x 3 block at the brightest texel.
        prog.begin("specular levels vs reference");
        const dvec3 light = [&] {
            double best = -1;
            dvec3 d(0, 1, 0);
            const int n = fsource.size(0);
            for (int f = 0; f < 6; ++f)
                for (int y = 0; y < n; ++y)
                    for (int x = 0; x < n; ++x)
                        if (const double l = ibl::luminance(dvec3(fsource.texel(f, x, y, 0))); l > best)
                            best = l, d = ibl::cube_texel_direction<double>(f, x, y, n);
            return d;
        }();
        for (std::size_t k = 0; k < plan.specular.levels.size(); ++k) {
            const ibl::specular_level_plan& lp = plan.specular.levels[k];
            if (lp.level == 0 || !lp.needed) continue;
            level_check lc{lp.level, lp.roughness, 0, 0};
            lc.expected = lp.expected_error, lc.samples = lp.samples, lc.trilinear = lp.trilinear;
            for (int which = 0; which < 2; ++which) {
                const ibl::cubemap<float>& c = which == 0 ? chain : fchain;
                const int lvl = which == 0 ? int(k) : lp.level, n = c.size(lvl);
                const std::vector<std::array<int, 3>> tex = check_texels(n, 6, light);
                std::vector<dvec3> ref(tex.size());
                ex(tex.size(), [&](std::size_t b, std::size_t e) {
                    for (std::size_t i = b; i < e; ++i) {
                        const dvec3 d = ibl::cube_texel_direction<double>(tex[i][0], tex[i][1], tex[i][2], n);
                        ref[i] = src.analytic ? ibl::reference_ld_sky(ibl::make_default_sky<double>(), d, lp.roughness, 2048, 16)
                                              : ibl::reference_ld(*src.map, d, lp.roughness, 8192);
                    }
                });
                ibl::error_accumulator acc(1e-3), acc_conv(1e-3);
                for (std::size_t i = 0; i < tex.size(); ++i) {
                    const dvec3 got(c.texel(tex[i][0], tex[i][1], tex[i][2], lvl));
                    acc.add(got, ref[i]);
                    const fvec3 d = ibl::cube_texel_direction<float>(tex[i][0], tex[i][1], tex[i][2], n);
                    acc_conv.add(got, dvec3(cchain.radiance(d, float(k))));
                }
                (which == 0 ? lc.nrmse_plan : lc.nrmse_full) = acc.finish().nrmse;
                (which == 0 ? lc.conv_plan : lc.conv_full) = acc_conv.finish().nrmse;
            }
            level_checks.push_back(lc);
        }
        prog.end();

        err_plan = compare_shading(mats, pts, ps_plan, ps_conv, scene.multiscatter);
        err_full = compare_shading(mats, pts, ps_full, ps_conv, scene.multiscatter);
        shading_points = err_plan.points;

        // The split sum itself (converged products) against the MIS reference, 3 views per class.
        prog.begin("split sum vs reference");
        int dist_level = 0;
        while (fsource.size(dist_level) > 128 && dist_level + 1 < fsource.levels()) ++dist_level;
        ibl::cube_env_distribution_options dopt;
        dopt.level = dist_level;
        const ibl::cube_env_distribution dist(fsource, dopt);
        const dvec3 up(0, 1, 0), side = glm::normalize(dvec3(1, 0, 1));
        const std::vector<std::pair<dvec3, dvec3>> views = {
            {up, up}, {up, glm::normalize(up + side)}, {side, glm::normalize(side + up)}};
        for (const auto& m : scene.materials) {
            const double r = std::clamp(0.5 * (m.roughness.front().lo + m.roughness.back().hi), 0.0, 1.0);
            ibl::pbr_material<double> pm;
            pm.metallic = std::clamp(m.metallic, 0.0, 1.0);
            pm.base_color = pm.metallic > 0.5 ? dvec3(0.95, 0.64, 0.54) : dvec3(0.8);
            pm.roughness = r;
            const auto shader = ibl::pbr_shader<double>::from(pm, false);
            ibl::reference_material rm = ibl::make_reference_material(pm.base_color, pm.metallic, r,
                                                                       ibl::diffuse_weighting::one_minus_fresnel_roughness);
            if (!diffuse_lit) rm.diffuse_albedo = dvec3(0.0);
            ibl::radiance_reference_options ro;
            ro.samples = 1u << 14;
            split_row row{m.name, r, 0.0, 0.0};
            for (std::size_t vi = 0; vi < views.size(); ++vi) {
                const auto& [n, v] = views[vi];
                const ibl::radiance_estimate ref = src.analytic
                    ? ibl::reference_radiance<model>(ibl::make_default_sky<double>(), dist, n, v, rm, ro, ex)
                    : ibl::reference_radiance<model>(*src.map, dist, n, v, rm, ro, ex);
                product_set conv = ps_conv;
                conv.brute_e = nullptr;
                const std::vector<dvec3> e1 = diffuse_lit ? brute_irradiance(fsource, {n}, ex) : std::vector<dvec3>{dvec3(0.0)};
                ibl::ibl_sample<double> s = conv.sample(n, v, r, 0);
                s.irradiance_over_pi = e1[0] / ibl::pi_v<double>;
                const double ys = ibl::luminance(shader.ambient(std::clamp(glm::dot(n, v), 0.0, 1.0), s));
                const double yr = ibl::luminance(ref.value);
                const double rel = yr > 0 ? std::fabs(ys / yr - 1.0) : 0.0;
                row.mean_abs_rel += rel / double(views.size());
                row.max_abs_rel = std::max(row.max_abs_rel, rel);
            }
            split.push_back(row);
        }
        prog.end();
    }

    // ---- files -----------------------------------------------------------------------------------
    output_stage stage(opt.out);
    std::vector<std::string> files;
    auto staged = [&](const std::string& name) {
        files.push_back(name);
        return stage.file(name);
    };
    write_ktx2_cubemap(staged("specular.ktx2"), to_ktx(chain), opt.ktx2_f32 ? ktx2_format::rgba32f : ktx2_format::rgba16f,
                       "ibl-bake --scene");
    {
        image_rgb32f d(plan.dfg.size, plan.dfg.size);
        for (std::uint32_t j = 0; j < lut.size; ++j)
            for (std::uint32_t i = 0; i < lut.size; ++i)
                for (std::uint32_t c = 0; c < lut.channels; ++c) d.texel(int(i), int(j))[c] = lut.at(i, j, c);
        write_exr(staged("dfg.exr"), d);
    }
    if (diffuse.kind == ibl::diffuse_product::sh) {
        json_writer j;
        j.begin_object();
        j.key("bands").value(diffuse.bands);
        j.key("convention").value("as ibl-bake's sh.json: real orthonormal SH without Condon-Shortley phase, k = l*l + l + m; "
                                  "'radiance' holds L_k (after the window if applied); E(n) = sum_k A_l L_k Y_k(n)");
        j.key("window_applied").value(false);
        j.key("radiance").begin_array();
        for (int k = 0; k < diffuse.bands * diffuse.bands; ++k)
            j.begin_array().value(diffuse.radiance[k].x).value(diffuse.radiance[k].y).value(diffuse.radiance[k].z).end_array();
        j.end_array();
        j.end_object();
        write_text(staged("sh.json"), j.str() + "\n");
    } else if (diffuse.kind == ibl::diffuse_product::irradiance_map) {
        write_ktx2_cubemap(staged("irradiance.ktx2"), to_ktx(diffuse.map), ktx2_format::rgba16f, "ibl-bake --scene");
    }
    const std::vector<std::string> omitted = ibl::left_out(plan, full);
    {
        json_writer j;
        j.begin_object();
        j.key("tool").value("ibl-bake --scene");
        j.key("scene").value(opt.scene);
        j.key("scene_name").value(scene.name);
        j.key("source").value(src.name);
        j.key("error_target").value(plan.error_target);
        j.key("diffuse_error_target").value(plan.diffuse_error_target);
        j.key("runtime_lookup").value("lod = " + std::string(set.policy.mapping == ibl::roughness_mapping::linear ? "r" : "r (2 - r)") +
                                      " * " + std::to_string(set.levels - 1) + " - " + std::to_string(plan.specular.first_level) +
                                      " (virtual lod minus first_level), clamped to the stored levels");
        j.key("plan");
        plan_json(j, plan, est);
        j.key("full_plan");
        plan_json(j, full, est_full);
        j.key("left_out").begin_array();
        for (const auto& s : omitted) j.value(s);
        j.end_array();
        j.key("warnings").begin_array();
        for (const auto& s : plan.warnings) j.value(s);
        j.end_array();
        j.key("estimated_time_saved").value(1.0 - est.total_ms() / est_full.total_ms());
        j.key("measured_ms").begin_object();
        j.key("source").value(tp.source).key("specular").value(tp.specular).key("diffuse").value(tp.diffuse);
        j.key("dfg").value(tp.dfg).key("total").value(tp.total());
        j.end_object();
        if (opt.compare_full) {
            j.key("compare_full").begin_object();
            j.key("full_measured_ms").begin_object();
            j.key("source").value(tf.source).key("specular").value(tf.specular).key("diffuse").value(tf.diffuse);
            j.key("dfg").value(tf.dfg).key("total").value(tf.total());
            j.end_object();
            j.key("speedup").value(tf.total() / tp.total());
            j.key("converged").value("levels read by the scene at full resolution with 4096 filtered-IS samples (trilinear reads), dfg_exact, "
                                     "brute-force irradiance");
            j.key("converged_ms").value(converged_ms);
            j.key("shading_points").value(shading_points);
            j.key("planned_vs_converged").begin_object().key("rel_rms").value(err_plan.rel_rms).key("max_rel").value(err_plan.max_rel).end_object();
            j.key("full_vs_converged").begin_object().key("rel_rms").value(err_full.rel_rms).key("max_rel").value(err_full.max_rel).end_object();
            j.key("within_target").value(err_plan.rel_rms <= plan.error_target);
            j.key("specular_levels_vs_reference").begin_array();
            for (const auto& c : level_checks) {
                j.begin_object();
                j.key("virtual_level").value(c.level).key("roughness").value(c.roughness);
                j.key("nrmse_planned").value(c.nrmse_plan).key("nrmse_full").value(c.nrmse_full);
                j.key("nrmse_vs_converged_planned").value(c.conv_plan).key("nrmse_vs_converged_full").value(c.conv_full);
                j.key("expected_nrmse_vs_converged").value(c.expected);
                j.end_object();
            }
            j.end_array();
            j.key("split_sum_vs_reference").begin_array();
            for (const auto& s : split) {
                j.begin_object();
                j.key("material").value(s.material).key("roughness").value(s.roughness);
                j.key("mean_abs_rel").value(s.mean_abs_rel).key("max_abs_rel").value(s.max_abs_rel);
                j.end_object();
            }
            j.end_array();
            j.end_object();
        }
        j.key("files").begin_array();
        for (const auto& f : files) j.value(f);
        j.value("report.json");
        j.end_array();
        j.end_object();
        write_text(stage.file("report.json"), j.str() + "\n");
    }
    stage.commit();

    // ---- the printed report ----------------------------------------------------------------------------
    std::fprintf(out, "ibl-bake --scene %s (%s): %s -> %s, target %.3g (diffuse %.3g)\n\n", opt.scene.c_str(), scene.name.c_str(),
                 src.name.c_str(), opt.out.c_str(), plan.error_target, plan.diffuse_error_target);
    std::fprintf(out, "specular: virtual chain %d levels, base %d; stored levels %d..%d (lod = virtual lod - %d)\n",
                 plan.specular.virtual_levels, plan.specular.virtual_base_size, plan.specular.first_level,
                 plan.specular.first_level + int(plan.specular.levels.size()) - 1, plan.specular.first_level);
    for (const auto& l : plan.specular.levels)
        std::fprintf(out, "  level %d  %4dx%-4d r=%.2f  %5u spp%s\n", l.level, l.size, l.size, l.roughness, l.samples,
                     l.level == 0 ? " (source copy)" : l.needed ? "" : " (contiguity filler)");
    std::fprintf(out, "diffuse:  %s", diffuse_name(plan.diffuse.kind));
    if (plan.diffuse.kind == ibl::diffuse_product::sh) std::fprintf(out, ", %d bands", plan.diffuse.sh_bands);
    std::fprintf(out, "\ndfg:      %d^2, %d channels\n", plan.dfg.size, plan.dfg.channels);
    std::fprintf(out, "left out:\n");
    for (const auto& s : omitted) std::fprintf(out, "  - %s\n", s.c_str());
    for (const auto& s : plan.warnings) std::fprintf(out, "warning: %s\n", s.c_str());
    std::fprintf(out, "\n%-10s %12s %12s %12s %12s\n", "time (ms)", "source", "specular", "diffuse", "dfg");
    std::fprintf(out, "%-10s %12.1f %12.1f %12.1f %12.1f   total %.1f\n", "planned", tp.source, tp.specular, tp.diffuse, tp.dfg, tp.total());
    std::fprintf(out, "%-10s %12.1f %12.1f %12.1f %12.1f   total %.1f (estimate: %.0f%% saved)\n", "est. plan", est.source_ms,
                 est.specular_ms, est.diffuse_ms, est.dfg_ms, est.total_ms(), 100.0 * (1.0 - est.total_ms() / est_full.total_ms()));
    std::fprintf(out, "%-10s %12.1f %12.1f %12.1f %12.1f   total %.1f\n", "est. full", est_full.source_ms, est_full.specular_ms,
                 est_full.diffuse_ms, est_full.dfg_ms, est_full.total_ms());
    if (opt.compare_full) {
        std::fprintf(out, "%-10s %12.1f %12.1f %12.1f %12.1f   total %.1f (measured: %.2fx faster planned)\n", "full", tf.source,
                     tf.specular, tf.diffuse, tf.dfg, tf.total(), tf.total() / tp.total());
        std::fprintf(out, "\nproduct error (ambient luminance vs converged products, %zu points): planned %s, full %s; target %.3g: %s\n",
                     shading_points, (fmt("rel RMS %.4f", err_plan.rel_rms) + fmt(" max %.4f", err_plan.max_rel)).c_str(),
                     (fmt("rel RMS %.4f", err_full.rel_rms) + fmt(" max %.4f", err_full.max_rel)).c_str(), plan.error_target,
                     err_plan.rel_rms <= plan.error_target ? "within" : "NOT within");
        std::fprintf(out, "specular levels (nrmse at the check texels) vs reference LD and vs converged (plan.hpp's table):\n");
        for (const auto& c : level_checks)
            std::fprintf(out, "  level %d r=%.2f  planned (%u %s) %.4f  full %.4f;  vs converged: planned %.4f (expected %.4f)  full %.4f\n",
                         c.level, c.roughness, c.samples, c.trilinear ? "tri" : "near", c.nrmse_plan, c.nrmse_full, c.conv_plan,
                         c.expected, c.conv_full);
        std::fprintf(out, "split-sum approximation vs MIS reference (converged products; no plan can change it):\n");
        for (const auto& s : split)
            std::fprintf(out, "  %-16s r=%.2f  mean |rel| %.1f%%, max |rel| %.1f%%\n", s.material.c_str(), s.roughness,
                         100.0 * s.mean_abs_rel, 100.0 * s.max_abs_rel);
    }
    std::fprintf(out, "\ntotal %.0f ms; %zu files in %s\n", ms_since(t_all), files.size() + 1, opt.out.c_str());
}

} // namespace ibl_bake
