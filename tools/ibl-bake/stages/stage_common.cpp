// tools/ibl-bake/stages/stage_common.cpp — what several stages share (stages.hpp).

#include "stages/stages.hpp"

#include <algorithm>
#include <cmath>
#include <locale>
#include <span>
#include <sstream>
#include <type_traits>

#include <ibl/core/color.hpp>
#include <ibl/env/convert.hpp>
#include <ibl/env/cube_geometry.hpp>
#include <ibl/bake/dfg.hpp>
#include <ibl/bake/prefilter.hpp>
#include <ibl/brdf/charlie.hpp>
#include <ibl/reference/disk_light.hpp>
#include <ibl/sampling/lobe.hpp>
#include <ibl/reference/ld_irradiance.hpp>
#include <ibl/runtime/specular_models.hpp>
#include <ibl/sh/convolve.hpp>
#include <ibl/sh/project.hpp>

namespace ibl_bake {

dvec3 diffuse_data::irradiance_over_pi(const dvec3& n) const {
    if (kind == ibl::diffuse_product::sh) return glm::max(ibl::sh_shader_evaluate(shader_over_pi, n), dvec3(0.0));
    if (kind == ibl::diffuse_product::irradiance_map) return dvec3(map.radiance(fvec3(n), 0.0f)) / ibl::pi_v<double>;
    return dvec3(0.0);
}

dvec3 product_view::ld(const dvec3& r_dir, double roughness) const {
    if (!chain) return dvec3(0.0);
    const ibl::specular_taps<float> t = ibl::specular_lookup_taps(float(roughness), virtual_levels, specular);
    fvec3 v[4];
    for (int k = 0; k < t.count; ++k) {
        const int stored = std::clamp(t.level[k] - first_level, 0, chain->levels() - 1);
        v[k] = t.weight[k] != 0.0f || k == 0 ? chain->bilinear(fvec3(r_dir), stored) : fvec3(0.0f);
    }
    return dvec3(ibl::specular_blend(t, v, specular));
}

dvec3 product_view::shade(const ibl::pbr_shader<double>& shader, const dvec3& n, const dvec3& v) const {
    dvec3 lo = shader.ambient(std::clamp(glm::dot(n, v), 0.0, 1.0), sample(n, v, shader.m.roughness, shader.m.f0, shader.m.f90));
    if (sun) lo += ibl::shade_disk(n, v, *sun, shader.m);
    return lo;
}

dvec3 product_view::irradiance(const dvec3& n) const {
    dvec3 e = diffuse ? ibl::pi_v<double> * diffuse->irradiance_over_pi(n) : dvec3(0.0);
    if (sun) e += ibl::disk_light_irradiance(n, *sun);
    return e;
}

dvec3 sun_ld(const ibl::disk_light<double>* sun, const dvec3& d, double roughness, ibl::ld_weight w) {
    // n.l: 8 nodes agree with 128 to 1e-13 (docs/sun.md); G1 (Gauss-Legendre in u): to 2e-5 at 8
    return sun ? ibl::disk_light_ld(*sun, d, roughness, 8, w) : dvec3(0.0);
}

dvec3 sheen_sun_ld(const ibl::disk_light<double>* sun, const dvec3& R, double roughness) {
    if (!sun) return dvec3(0.0);
    const double alpha = ibl::charlie_lobe::alpha(roughness);
    const double c = glm::dot(R, sun->direction);
    if (!(c > 0.0)) return dvec3(0.0);
    constexpr int m = 2048;
    double w = 0.0;
    for (int i = 0; i < m; ++i) {
        const double t = (i + 0.5) * ibl::half_pi_v<double> / m;
        w += ibl::ndf_charlie(std::cos(0.5 * t), alpha) * std::cos(t) * std::sin(t);
    }
    w *= ibl::two_pi_v<double> * ibl::half_pi_v<double> / m;
    const double d = ibl::ndf_charlie(std::sqrt(0.5 * (1.0 + c)), alpha) * c;
    return w > 0.0 ? sun->radiance * (sun->solid_angle * d / w) : dvec3(0.0);
}

ibl::vec4<double> product_view::lobe_params(double n_dot_v, double roughness) const {
    return ibl::vec4<double>(ibl::lobe_lut_lookup(*lobe, float(n_dot_v), float(roughness)));
}

ibl::vec2<double> product_view::lobe_b_params(double n_dot_v, double roughness) const {
    const ibl::vec4<float> p = ibl::lobe_lut_lookup(*lobe_b, float(n_dot_v), float(roughness));
    return ibl::vec2<double>(p.x, p.y);
}

std::array<float, 8> product_view::taps_params(double n_dot_v, double roughness) const {
    const ibl::vec2<float> st = ibl::dfg_lut_coord(float(n_dot_v), float(roughness), taps->size, dfg_layout);
    std::array<float, 8> p{};
    ibl::detail::table_bilinear(*taps, st.x, st.y, p.data(), std::uint32_t(p.size()));
    return p;
}

namespace {
/// LD of the two-tap model, as ibl::specular_lobe_taps forms it: the taps' directions in float
/// (cos(a) n + sin(a) t, t = incidence_tangent(n, R)), each read by the view's chain lookup, the
/// weighted mean; LD(R, r) where no weight is > 0.
dvec3 taps_ld(const product_view& pv, const std::array<float, 8>& p, const dvec3& n, const dvec3& v, double roughness) {
    const fvec3 fn(n), fv(v);
    const fvec3 r_dir = 2.0f * glm::dot(fn, fv) * fn - fv;
    const fvec3 t = ibl::incidence_tangent(fn, r_dir);
    const float n_dot_v = ibl::saturate(glm::dot(fn, fv));
    dvec3 sum(0.0);
    double wsum = 0.0;
    for (int k = 0; k < 2; ++k) {
        const float a = ibl::lobe_tap_angle(p[std::size_t(2 + 3 * k)], n_dot_v), w = p[std::size_t(4 + 3 * k)];
        if (!(w > 0.0f)) continue;
        const fvec3 d = glm::normalize(std::cos(a) * fn + std::sin(a) * t);
        sum += double(w) * pv.ld(dvec3(d), p[std::size_t(3 + 3 * k)]);
        wsum += double(w);
    }
    return wsum > 0.0 ? sum / wsum : pv.ld(dvec3(r_dir), roughness);
}
} // namespace

ibl::ibl_sample<double> product_view::sample(const dvec3& n, const dvec3& v, double roughness, const dvec3& f0,
                                             const dvec3& f90) const {
    const double n_dot_v = std::clamp(glm::dot(n, v), 0.0, 1.0);
    const dvec3 r_dir = 2.0 * glm::dot(n, v) * n - v;
    ibl::ibl_sample<double> s;
    if (diffuse) s.irradiance_over_pi = diffuse->irradiance_over_pi(n);
    if (taps) {
        const std::array<float, 8> p = taps_params(n_dot_v, roughness);
        s.ld = taps_ld(*this, p, n, v, roughness);
        s.dfg = ibl::vec2<double>(p[0], p[1]);
        return s;
    }
    if (lobe) { // as ibl::specular_lobe(_pair): the directions in float, the chain at r_eff (r_A, r_B)
        const ibl::vec4<double> p = lobe_params(n_dot_v, roughness);
        s.ld = ld(dvec3(ibl::lerp_direction(fvec3(n), fvec3(r_dir), float(p.z))), p.w);
        s.dfg = ibl::vec2<double>(p.x, p.y);
        if (lobe_b) {
            const ibl::vec2<double> pb = lobe_b_params(n_dot_v, roughness);
            const fvec3 d_b = ibl::lobe_pair_direction_b(fvec3(n), fvec3(r_dir), float(pb.x), float(n_dot_v));
            s.ld = ibl::lobe_pair_ld(s.ld, ld(dvec3(d_b), pb.y), f0, f90, s.dfg);
        }
        return s;
    }
    s.ld = ld(r_dir, roughness);
    if (lut) {
        const fvec3 ab = ibl::dfg_lookup(*lut, float(n_dot_v), float(roughness));
        s.dfg = ibl::vec2<double>(ab.x, ab.y);
    } else {
        s.dfg = ibl::dfg_exact<bake_model>(n_dot_v, roughness);
    }
    return s;
}

int lobe_lut_size_for(int dfg_size) { return std::clamp(dfg_size, 1, 24); }

runtime_model runtime_model_of(const bake_options& o, const ibl::bake_plan& plan) {
    runtime_model m;
    m.ld_weight = o.ld_weight;
    if (o.runtime != runtime_choice::split_sum && plan.dfg.enabled && plan.dfg.size > 0 && plan.specular.enabled) {
        m.kind = o.runtime;
        m.lobe_lut_size = lobe_lut_size_for(plan.dfg.size);
    }
    return m;
}

namespace {
const char* axis_name(ibl::dfg_axis a) {
    return a == ibl::dfg_axis::cbrt ? "cbrt" : a == ibl::dfg_axis::sqrt ? "sqrt" : "linear";
}
} // namespace

namespace {
void json_runtime_model(json_writer& j, const runtime_model& rm) {
    j.key("ld_weight").begin_object();
    j.key("name").value(to_string(rm.ld_weight));
    j.key("rule").value(rm.ld_weight == ibl::ld_weight::g1
                            ? "LD = int L D(h) G1(R.l) dl / int D(h) G1(R.l) dl (the specular lobe at n.v = 1)"
                            : "LD = int L D(h) (R.l) dl / int D(h) (R.l) dl (Karis 2013)");
    j.end_object();
    j.key("runtime_model").begin_object();
    j.key("name").value(to_string(rm.kind));
    if (rm.kind == runtime_choice::lobe) {
        j.key("lut").value("lobe_lut.exr (lobe_lut.hpp)").key("lut_size").value(rm.lobe_lut_size);
        j.key("channels").value("R = A, G = B, B = s, A = r_eff");
        j.key("lut_b").value("lobe_lut_b.exr (lobe_lut_b.hpp)");
        j.key("channels_b").value("R = f_B (the B kernel's angle from n towards R over acos(n.v)), G = r_B, B = 0, A = 0");
        j.key("parts").value(2);
        j.key("rule").value("(A, B, s, r_eff) = lobe LUT and (f_B, r_B) = lobe_lut_b at (n.v, r) in the DFG layout "
                            "(bilinear); t = the tangent of n towards R, a_B = min(f_B acos(n.v), pi/2); specular = "
                            "F0 A LD(normalize(lerp(n, R, s)), r_eff) + F90 B LD(cos(a_B) n + sin(a_B) t, r_B) "
                            "(ibl::specular_lobe_pair: the A part of the lobe by the whole lobe's kernel, the Fresnel B "
                            "part by its own)");
    } else if (rm.kind == runtime_choice::taps2) {
        j.key("lut").value("lobe_taps_a.exr, lobe_taps_b.exr (lobe_taps.hpp)").key("lut_size").value(rm.lobe_lut_size);
        j.key("channels").value("lobe_taps_a: R = A, G = B, B = angle0 / acos(n.v), A = roughness0; lobe_taps_b: R = weight0, "
                                "G = angle1 / acos(n.v), B = roughness1, A = weight1");
        j.key("rule").value("the 8 channels = the two tables at (n.v, r) in the DFG layout (bilinear); t = the tangent of n "
                            "towards R; specular = (F0 A + F90 B) sum_k w_k LD(cos(a_k) n + sin(a_k) t, r_k) / sum_k w_k "
                            "(ibl::specular_lobe_taps; LD(R, r) where no weight is > 0)");
    } else {
        j.key("rule").value("specular = LD(R, r) (F0 A + F90 B), (A, B) from the DFG table");
    }
    j.end_object();
}
} // namespace

void json_lookup_conventions(json_writer& j, const ibl::specular_lookup_desc& s, const ibl::dfg_lut_layout& d,
                             const runtime_model& rm) {
    json_runtime_model(j, rm);
    j.key("specular_lookup").begin_object();
    const bool textbook = s.weight == ibl::level_weight::lod;
    j.key("name").value(textbook ? "textbook" : "log-geometric");
    j.key("weight").value(textbook ? "lod" : "log");
    j.key("interpolation").value(textbook ? "linear" : "geometric");
    j.key("rule").value(textbook ? "textureLod(chain, R, lod(r)): lerp of levels l, l+1 at t = frac(lod)"
                                 : "levels l, l+1 bracketing r; t linear in log r between their roughness; "
                                   "L = L_l^(1-t) L_{l+1}^t per channel (ibl/runtime/lookup.hpp)");
    j.end_object();
    j.key("dfg_layout").begin_object();
    j.key("n_dot_v").value(axis_name(d.n_dot_v)).key("roughness").value(axis_name(d.roughness));
    j.key("edge_aligned").value(d.edge_aligned);
    j.key("rule").value(d.edge_aligned ? "texel i holds axis value f^-1(i / (N - 1)), f = the axis map; sample at "
                                         "s = (f(x) (N - 1) + 0.5) / N (ibl::dfg_lut_coord)"
                                       : "texel i holds (i + 0.5) / N; sample at (n.v, r) with clamp to edge");
    j.end_object();
}

std::vector<std::pair<std::string, std::string>> product_conventions(const bake_context& ctx, const std::string& product,
                                                                     const std::string& how_to_read) {
    return {{"ibl.preset", to_string(ctx.opt.preset)},
            {"ibl.product", product},
            {"ibl.sun_extracted", ctx.sun ? "yes: a compact bright source was taken out into lights.json (a disk light the "
                                            "renderer must add); this file holds the rest of the environment"
                                          : "no: this file holds the whole environment"},
            {"ibl.conventions", how_to_read}};
}

std::vector<std::pair<std::string, std::string>> table_conventions(const bake_context& ctx, const std::string& product,
                                                                   const std::string& how_to_read, const ibl::dfg_lut_layout& layout,
                                                                   const std::vector<std::pair<std::string, std::string>>& extra) {
    std::vector<std::pair<std::string, std::string>> m = product_conventions(ctx, product, how_to_read);
    m.push_back({"ibl.dfg_layout", layout.name()});
    m.push_back({"ibl.dfg_lookup", layout == ibl::dfg_lut_layout::uniform()
                                       ? "texture(lut, vec2(n.v, roughness)): texel (i, j) holds n.v = (i + 0.5) / N, r = (j + 0.5) / N"
                                       : "texture(lut, ibl_dfg_lut_coord(n.v, roughness, N, layout)) (ibl/glsl/ibl_lookup.glsl)"});
    m.insert(m.end(), extra.begin(), extra.end());
    return m;
}

product_view baked_view(const bake_context& ctx) {
    product_view v;
    v.specular = ctx.opt.specular_lookup;
    v.specular.mapping = ctx.plan.specular.policy.mapping;
    v.dfg_layout = ctx.opt.dfg_layout;
    v.chain = ctx.chain ? &*ctx.chain : nullptr;
    v.policy = ctx.plan.specular.policy;
    v.virtual_levels = ctx.plan.specular.virtual_levels;
    v.first_level = ctx.plan.specular.first_level;
    v.lut = ctx.lut ? &*ctx.lut : nullptr;
    v.diffuse = &ctx.diffuse;
    v.sun = ctx.sun ? &*ctx.sun : nullptr;
    v.lobe = ctx.lobe ? &*ctx.lobe : nullptr;
    v.lobe_b = ctx.lobe_b ? &*ctx.lobe_b : nullptr;
    v.taps = ctx.taps ? &*ctx.taps : nullptr;
    v.weight = ctx.opt.ld_weight;
    return v;
}

std::string c_table_header(const std::string& name, const std::string& what, std::uint32_t size, std::uint32_t channels,
                           const std::string& channel_list, const std::string& layout, const std::vector<float>& v) {
    std::ostringstream os;
    os.imbue(std::locale::classic());
    os << "#pragma once\n// Generated by ibl-bake " << version_string() << ": " << what << ".\n// " << size << " x " << size
       << " texels, " << channels << " channels (" << channel_list << "), float32, interleaved;\n// texel (i, j): " << layout
       << ";\n// row 0 (smallest roughness) first: value = " << name << "[(j * size + i) * " << channels
       << " + c].\n\nnamespace ibl_baked {\n\n"
       << "inline constexpr unsigned " << name << "_size = " << size << ";\ninline constexpr unsigned " << name
       << "_channels = " << channels << ";\n"
       << "inline constexpr float " << name << "[" << v.size() << "] = {\n";
    for (std::size_t k = 0; k < v.size(); ++k) {
        std::ostringstream num;
        num.imbue(std::locale::classic());
        num.precision(9);
        num << v[k];
        std::string s = num.str();
        if (s.find_first_of(".eEn") == std::string::npos) s += ".0";
        os << (k % 32 == 0 ? "    " : " ") << s << "f" << (k + 1 < v.size() ? "," : "") << (k % 32 == 31 || k + 1 == v.size() ? "\n" : "");
    }
    os << "};\n\n} // namespace ibl_baked\n";
    return os.str();
}

std::vector<std::array<double, 2>> fit_check_midpoints(std::uint32_t n, const ibl::dfg_lut_layout& layout) {
    std::vector<std::array<double, 2>> out;
    const auto mid = [&](ibl::dfg_axis a, std::uint32_t k) {
        return ibl::dfg_axis_value(a, 0.5 * (ibl::dfg_texel_coord<double>(k, n, layout.edge_aligned) +
                                             ibl::dfg_texel_coord<double>(k + 1, n, layout.edge_aligned)));
    };
    for (std::uint32_t j = 0; j + 1 < n; j += 2)
        for (std::uint32_t i = 0; i + 1 < n; i += 2) {
            const double nv = mid(layout.n_dot_v, i), r = mid(layout.roughness, j);
            if (r >= 0.05 && nv >= 1e-3) out.push_back({nv, r});
        }
    return out;
}

double ab_vs_dfg(const std::vector<float>& data, std::uint32_t n, std::uint32_t channels, const ibl::dfg_lut_layout& layout,
                 const ibl::dfg_lut& dfg) {
    double m = 0.0;
    for (std::uint32_t j = 0; j < n; ++j)
        for (std::uint32_t i = 0; i < n; ++i) {
            const float nv = ibl::dfg_texel_value<float>(layout.n_dot_v, i, n, layout.edge_aligned);
            const float r = ibl::dfg_texel_value<float>(layout.roughness, j, n, layout.edge_aligned);
            const fvec3 ab = ibl::dfg_lookup(dfg, nv, r);
            const float* t = &data[(std::size_t(j) * n + i) * channels];
            m = std::max({m, std::fabs(double(t[0]) - ab.x), std::fabs(double(t[1]) - ab.y)});
        }
    return m;
}

dvec3 brightest_direction(const ibl::cubemap<float>& cube, int level) {
    const int n = cube.size(level);
    double best = -1.0;
    dvec3 dir(0.0, 1.0, 0.0);
    for (int f = 0; f < 6; ++f)
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
                const double l = ibl::luminance(dvec3(cube.texel(f, x, y, level)));
                if (l > best) {
                    best = l;
                    dir = ibl::cube_texel_direction<double>(f, x, y, n);
                }
            }
    return dir;
}

ibl::cubemap<float> bake_source(const source_env& src, int n, int base_k, pool_executor& ex, int* k_used) {
    int k = base_k;
    if (src.cube) k = std::clamp(int(std::ceil(double(src.cube->size(0)) / double(n))), base_k, 32);
    else if (!src.analytic) k = std::clamp(int(std::ceil(double(src.width) / (4.0 * n))), base_k, 32);
    if (k_used) *k_used = src.cube && src.cube->size(0) == n ? 1 : k;
    if (src.analytic && !src.mirrored) return ibl::bake_cubemap<float>(ibl::make_default_sky<float>(), n, k, ex, 0);
    if (src.analytic) { // the mirrored sky, in float as the default one is baked
        ibl::sky_environment<float> sky = ibl::make_default_sky<float>();
        sky.set_sun(fvec3(src.sky.sun_dir), fvec3(src.sky.sun_radiance), float(src.sky.sun_angular_radius));
        return ibl::bake_cubemap<float>(sky, n, k, ex, 0);
    }
    if (src.cube) return src.cube->size(0) == n ? *src.cube : ibl::bake_cubemap<float>(*src.cube, n, k, ex, 0);
    return ibl::bake_cubemap<float>(*src.map, n, k, ex, 0);
}

int level_at_most(const ibl::cubemap<float>& cube, int max_face) { return ibl::irradiance_texel_sum_level(cube, max_face); }

std::vector<dvec3> texel_sum_irradiance(const ibl::cubemap<float>& cube, int level, const std::vector<dvec3>& normals,
                                        pool_executor& ex) {
    return ibl::irradiance_texel_sum(cube, level, std::span<const dvec3>(normals), ex);
}

image_rgb32f face_image(const ibl::cubemap<float>& cube, int face, int level) {
    const int n = cube.size(level);
    image_rgb32f img(n, n);
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            const fvec3& v = cube.texel(face, x, y, level);
            float* t = img.texel(x, y);
            t[0] = v.x, t[1] = v.y, t[2] = v.z;
        }
    return img;
}



void write_text(const std::string& path, const std::string& text) {
    write_file_atomic(path, std::span<const unsigned char>(reinterpret_cast<const unsigned char*>(text.data()), text.size()));
}

ktx2_format ktx2_format_of(ktx2_storage storage) {
    switch (storage) {
    case ktx2_storage::rgba32f: return ktx2_format::rgba32f;
    case ktx2_storage::b10g11r11: return ktx2_format::b10g11r11;
    case ktx2_storage::e5b9g9r9: return ktx2_format::e5b9g9r9;
    case ktx2_storage::bc6h: return ktx2_format::bc6h;
    case ktx2_storage::astc4x4: return ktx2_format::astc4x4;
    case ktx2_storage::astc6x6: return ktx2_format::astc6x6;
    case ktx2_storage::rgba16f: break;
    }
    return ktx2_format::rgba16f;
}

ktx2_encoding ktx2_encoding_of(const bake_options& o) {
    ktx2_encoding e;
    e.quality = o.ktx2_quality;
    e.zstd_level = o.ktx2_zstd;
    e.threads = o.threads;
    return e;
}

void json_quantisation(json_writer& j, const std::vector<ktx2_quantisation_level>& q, ktx2_storage format) {
    j.begin_object();
    j.key("format").value(to_string(format));
    j.key("relative_to").value("max(|x|, floor), floor = 1e-3 x the level's mean |x|");
    j.key("levels").begin_array();
    for (const auto& l : q) {
        j.begin_object();
        j.key("level").value(l.level).key("face_size").value(l.face_size).key("values").value(l.values);
        j.key("floor").value(l.floor).key("max_rel_error").value(l.max_rel_error).key("rms_rel_error").value(l.rms_rel_error);
        j.key("above_range").value(l.above_range).key("negative_clamped").value(l.negative_clamped).key("nan").value(l.nan);
        j.end_object();
    }
    j.end_array();
    j.end_object();
}

void json_triples(json_writer& j, const sh5& c, int count) {
    j.begin_array();
    for (int k = 0; k < count; ++k) {
        j.begin_array();
        for (int ch = 0; ch < 3; ++ch) j.value(c[k][ch]);
        j.end_array();
    }
    j.end_array();
}

std::vector<dvec3> chain_check_references(const source_env& src, const ibl::cubemap<float>& cube,
                                          const std::vector<std::array<int, 3>>& texels, int n, bool mirror, double roughness,
                                          const quality_settings& qs, ibl::ld_weight w, pool_executor& ex) {
    std::vector<dvec3> ref(texels.size());
    if (!mirror && !src.analytic) { // the exact LD of the source cube: a deterministic texel sum
        std::vector<dvec3> dirs(texels.size());
        for (std::size_t i = 0; i < texels.size(); ++i)
            dirs[i] = ibl::cube_texel_direction<double>(texels[i][0], texels[i][1], texels[i][2], n);
        return ibl::ld_texel_sum(cube, ibl::ld_texel_sum_level(cube, roughness), std::span<const dvec3>(dirs), roughness, w, ex);
    }
    src.visit([&](const auto& env) {
        ex(texels.size(), [&](std::size_t b, std::size_t e) {
            for (std::size_t i = b; i < e; ++i) {
                const auto& t = texels[i];
                const dvec3 d = ibl::cube_texel_direction<double>(t[0], t[1], t[2], n);
                // Maps and cubes reach here only for the mirror level: their rougher levels took the texel sum.
                if constexpr (std::is_same_v<std::decay_t<decltype(env)>, ibl::sky_environment<double>>)
                    ref[i] = mirror ? ibl::cube_texel_mean(env, t[0], t[1], t[2], n, level0_ref_k)
                                    : ibl::reference_ld_sky(env, d, roughness, qs.sky_ref_samples, qs.sun_cap_nodes, w);
                else ref[i] = ibl::cube_texel_mean(env, t[0], t[1], t[2], n, level0_ref_k);
            }
        });
        return 0;
    });
    return ref;
}

std::uint32_t chain_samples(std::uint32_t fis_samples, prefilter_choice method, int level) {
    if (method != prefilter_choice::fast) return fis_samples;
    // The plan's samples already double per level; one more doubling makes the equal-cost schedule.
    return ibl::doubling_prefilter_samples(std::max<std::uint32_t>(8, fis_samples / fast_samples_divisor), level);
}

/// Virtual levels [first, first + count) of the chain (sizes base >> v) with per-level samples and the LD weight w.
ibl::prefilter_options chain_options(const ibl::specular_plan& sp, ibl::ld_weight w, prefilter_choice method, std::uint32_t fast_peaks,
                                     int fast_sh_bands, bool fast_mid_tail) {
    ibl::prefilter_options o;
    o.mid_tail.enabled = fast_mid_tail;
    o.peaks.enabled = fast_peaks > 0;
    o.peaks.max_peaks = fast_peaks;
    o.sh_rough.enabled = fast_sh_bands > 0;
    o.sh_rough.max_bands = fast_sh_bands;
    o.base_size = sp.virtual_base_size;
    o.policy = sp.policy;
    o.weight = w;
    o.method = method == prefilter_choice::fast ? ibl::prefilter_method::fast : ibl::prefilter_method::filtered_importance;
    for (const ibl::specular_level_plan& lp : sp.levels) // the mirror level copies the nearest source level
        o.level_plan.push_back({lp.level, lp.roughness, chain_samples(lp.samples, method, lp.level),
                                lp.level > 0 && lp.trilinear && method != prefilter_choice::fast});
    return o;
}

ibl::cubemap<float> bake_chain(const ibl::cubemap<float>& src, const ibl::specular_plan& sp, ibl::ld_weight w, pool_executor& ex,
                               prefilter_choice method, std::uint32_t fast_peaks, int fast_sh_bands, bool fast_mid_tail) {
    return ibl::cubemap<float>(ibl::prefilter(src, chain_options(sp, w, method, fast_peaks, fast_sh_bands, fast_mid_tail), ex));
}

diffuse_data sh3_diffuse(const ibl::cubemap<float>& src, pool_executor& ex) {
    diffuse_data d;
    d.kind = ibl::diffuse_product::sh;
    d.bands = 3;
    const sh3 raw = ibl::project_cube<3>(
        src.size(0), [&](int f, int x, int y) { return dvec3(src.texel(f, x, y, 0)); }, ex);
    for (int k = 0; k < 9; ++k) d.radiance[k] = raw[k];
    d.shader_over_pi = ibl::sh_shader_coeffs(d.radiance, ibl::sh_shader_output::irradiance_over_pi);
    return d;
}

} // namespace ibl_bake
