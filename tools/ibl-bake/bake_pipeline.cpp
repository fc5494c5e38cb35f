// tools/ibl-bake/bake_pipeline.cpp — the ibl-bake pipeline (see docs/ibl-bake.md).
//
//   source (lat-long file or built-in sky) --k x k supersampled bake--> source cube (n, full mips)
//   source cube --filtered importance sampling--> prefiltered chain (levels, linear roughness policy)
//   source cube --3-band projection (exact texel solid angles), auto window if E < 0--> SH
//   quadrature --> DFG LUT (A, B, k) of ggx_height_correlated
//   checks: each product against its reference; split sum of the baked products against the MIS
//   reference of outgoing radiance; preview rendered from the baked products only.
// Every step is deterministic (the library's integrators are partition-independent; the tool's
// own loops compute each item independently), so the outputs do not depend on --threads.

#include "bake_pipeline.hpp"
#include "check_texels.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <type_traits>
#include <vector>

#include <unistd.h>

#include <ibl/brdf/model.hpp>
#include <ibl/core/color.hpp>
#include <ibl/env/analytic.hpp>
#include <ibl/env/convert.hpp>
#include <ibl/env/cube_geometry.hpp>
#include <ibl/env/cubemap.hpp>
#include <ibl/env/latlong.hpp>
#include <ibl/integrate/dfg.hpp>
#include <ibl/integrate/dfg_export.hpp>
#include <ibl/integrate/dfg_lut.hpp>
#include <ibl/integrate/env_importance.hpp>
#include <ibl/integrate/metrics.hpp>
#include <ibl/integrate/prefilter.hpp>
#include <ibl/integrate/radiance_reference.hpp>
#include <ibl/integrate/reference.hpp>
#include <ibl/integrate/roughness_mip.hpp>
#include <ibl/sh/basis.hpp>
#include <ibl/sh/convolve.hpp>
#include <ibl/sh/project.hpp>
#include <ibl/sh/window.hpp>
#include <ibl/shade.hpp>

#include "bake_exec.hpp"
#include "bake_stage.hpp"
#include "image_io.hpp"
#include "json.hpp"
#include "ktx2.hpp"

namespace ibl_bake {

namespace {

using dvec3 = ibl::vec3<double>;
using fvec3 = ibl::vec3<float>;
using model = ibl::ggx_height_correlated;
using sh3 = ibl::sh_coeffs<double, 3>;

constexpr const char* tool_version = "1.0.0";
constexpr const char* face_names[6] = {"px", "nx", "py", "ny", "pz", "nz"};
constexpr int level0_ref_k = 16;      ///< sub-samples per axis of the level-0 reference texel mean
constexpr int sh_check_grid = 8;      ///< SH check normals: texel centres of an 8 x 8-per-face cube
constexpr int sh_brute_max_face = 128; ///< brute-force irradiance over a source level of face <= this
constexpr int dfg_check_grid = 16;    ///< DFG check: 16 x 16 texels (fewer if the LUT is smaller)
constexpr int dist_max_face = 128;    ///< env distribution of the split-sum reference: face <= this
constexpr int preview_cell = 128;     ///< preview: pixels per sphere cell
constexpr double preview_key = 0.6;   ///< preview exposure: key / mean luminance of the environment
constexpr double preview_hfov_deg = 90.0;

// ---- the source ----------------------------------------------------------------------------

struct source_env {
    std::string name;
    bool analytic = true;
    ibl::sky_environment<double> sky = ibl::make_default_sky<double>();
    std::unique_ptr<ibl::latlong<float>> map;
    read_report rr;
    int width = 0, height = 0;
};

template <class F> auto with_env(const source_env& s, F&& f) {
    if (s.analytic) return f(s.sky);
    return f(*s.map);
}


double lum(const dvec3& c) { return ibl::luminance(c); }
double min3(const dvec3& v) { return std::min({v.x, v.y, v.z}); }

/// Direction of the brightest texel of a cube level (luminance; first one on ties).
dvec3 brightest_direction(const ibl::cubemap<float>& cube, int level) {
    const int n = cube.size(level);
    double best = -1.0;
    dvec3 dir(0.0, 1.0, 0.0);
    for (int f = 0; f < 6; ++f)
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
                const double l = lum(dvec3(cube.texel(f, x, y, level)));
                if (l > best) {
                    best = l;
                    dir = ibl::cube_texel_direction<double>(f, x, y, n);
                }
            }
    return dir;
}

/// Solid-angle-weighted mean luminance and log-average luminance exp(mean log(1e-4 + Y)).
struct luminance_stats {
    double mean = 0.0, log_average = 0.0;
};
luminance_stats source_luminance(const ibl::cubemap<float>& cube) {
    const int n = cube.size(0);
    double sum = 0.0, logsum = 0.0, wsum = 0.0;
    for (int f = 0; f < 6; ++f)
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
                const double w = ibl::cube_texel_solid_angle<double>(x, y, n);
                const double l = lum(dvec3(cube.texel(f, x, y, 0)));
                sum += w * l;
                logsum += w * std::log(1e-4 + l);
                wsum += w;
            }
    return {sum / wsum, std::exp(logsum / wsum)};
}

// ---- report rows -----------------------------------------------------------------------------

struct table_row {
    std::string product, method, cost;
    double ms = 0.0;
    std::string error;
};

std::string fmt(const char* f, double a) {
    char buf[128];
    std::snprintf(buf, sizeof buf, f, a);
    return buf;
}
std::string fmt2(const char* f, double a, double b) {
    char buf[160];
    std::snprintf(buf, sizeof buf, f, a, b);
    return buf;
}

void print_table(std::FILE* out, const std::vector<table_row>& rows) {
    std::size_t w[4] = {7, 6, 9, 5};
    for (const auto& r : rows) {
        w[0] = std::max(w[0], r.product.size());
        w[1] = std::max(w[1], r.method.size());
        w[2] = std::max(w[2], r.cost.size());
        w[3] = std::max(w[3], r.error.size());
    }
    auto line = [&](const std::string& a, const std::string& b, const std::string& c, const std::string& d,
                    const std::string& e) {
        std::fprintf(out, "%-*s  %-*s  %-*s  %9s  %s\n", int(w[0]), a.c_str(), int(w[1]), b.c_str(), int(w[2]),
                     c.c_str(), d.c_str(), e.c_str());
    };
    line("product", "method", "cost knob", "time (ms)", "error");
    std::fprintf(out, "%s\n", std::string(w[0] + w[1] + w[2] + w[3] + 19, '-').c_str());
    for (const auto& r : rows) line(r.product, r.method, r.cost, r.ms >= 0 ? fmt("%.1f", r.ms) : "", r.error);
}

// ---- specular check --------------------------------------------------------------------------

struct level_check {
    int level = 0, size = 0;
    double roughness = 0.0;
    std::uint32_t samples = 0;
    std::size_t texels = 0;
    ibl::error_metrics m;
    double ref_ms = 0.0;
};

// ---- split sum ---------------------------------------------------------------------------------

struct view_geom {
    std::string name;
    dvec3 n, v;
    double n_dot_v;
};

/// Three views about the brightest direction (its azimuth h): n = +Y seen from above (n.v = 1);
/// n = +Y with R towards h's azimuth (n.v = 0.5); a wall facing h with R 60 deg above it (n.v = 0.5).
std::vector<view_geom> make_views(const dvec3& light) {
    const dvec3 up(0.0, 1.0, 0.0);
    dvec3 h(light.x, 0.0, light.z);
    h = glm::dot(h, h) > 1e-12 ? glm::normalize(h) : dvec3(1.0, 0.0, 0.0);
    const double mu = 0.5, s = std::sqrt(1.0 - mu * mu);
    const dvec3 r_wall = mu * h + s * up;
    return {{"up, n.v=1", up, up, 1.0},
            {"up, n.v=0.5 towards light", up, -s * h + mu * up, mu},
            {"wall facing light, n.v=0.5", h, 2.0 * mu * h - r_wall, mu}};
}

struct material_case {
    const char* name;
    dvec3 base_color;
    double metallic;
};
const material_case k_materials[2] = {{"dielectric", dvec3(0.8), 0.0}, {"metal", dvec3(0.95, 0.64, 0.54), 1.0}};
const double k_split_roughness[3] = {0.1, 0.5, 0.9};

/// The baked products as a renderer samples them.
struct baked_products {
    const ibl::cubemap<float>* chain;
    ibl::roughness_mip_policy policy;
    const ibl::dfg_lut* lut;
    sh3 shader_over_pi; ///< sh_shader_coeffs(radiance, irradiance_over_pi)

    ibl::ibl_sample<double> sample(const dvec3& n, const dvec3& v, double roughness) const {
        const double n_dot_v = std::clamp(glm::dot(n, v), 0.0, 1.0);
        const dvec3 r = 2.0 * glm::dot(n, v) * n - v;
        ibl::ibl_sample<double> s;
        const float lod = policy.lod(float(roughness), chain->levels());
        s.ld = dvec3(chain->radiance(fvec3(r), lod));
        const fvec3 ab = lut->sample(float(n_dot_v), float(roughness));
        s.dfg = ibl::vec2<double>(ab.x, ab.y);
        s.irradiance_over_pi = glm::max(ibl::sh_shader_evaluate(shader_over_pi, n), dvec3(0.0));
        return s;
    }
};

struct split_result {
    std::string material;
    double roughness;
    struct view_result {
        std::string view;
        double n_dot_v, y_ref, y_split, rel, se_rel;
    };
    std::vector<view_result> views;
    double max_abs_rel = 0.0, mean_abs_rel = 0.0, ms = 0.0;
};

// ---- preview -----------------------------------------------------------------------------------

struct camera {
    dvec3 fwd, right, up;
};
camera make_camera(const dvec3& light) {
    dvec3 f(-light.x, 0.0, -light.z); // look away from the light: spheres lit from the front
    f = glm::dot(f, f) > 1e-12 ? glm::normalize(f) : dvec3(0.0, 0.0, -1.0);
    const dvec3 right = glm::normalize(glm::cross(f, dvec3(0.0, 1.0, 0.0)));
    return {f, right, glm::cross(right, f)};
}

image_rgb32f render_preview(const baked_products& bp, const ibl::cubemap<float>& source, const camera& cam,
                            int preview_ss, pool_executor& ex) {
    constexpr int cols = 5, rows = 2;
    const int w = cols * preview_cell, h = rows * preview_cell;
    image_rgb32f img(w, h);
    const double tan_h = std::tan(0.5 * preview_hfov_deg * ibl::pi_v<double> / 180.0);
    const double tan_v = tan_h * double(h) / double(w);
    const double radius = 0.45 * preview_cell;
    ibl::pbr_shader<double> shaders[rows][cols];
    for (int j = 0; j < rows; ++j)
        for (int i = 0; i < cols; ++i) {
            ibl::pbr_material<double> m;
            m.base_color = k_materials[j].base_color;
            m.metallic = k_materials[j].metallic;
            m.roughness = 0.25 * i;
            shaders[j][i] = ibl::pbr_shader<double>::from(m, true);
        }
    ex(std::size_t(h), [&](std::size_t b, std::size_t e) {
        for (std::size_t py = b; py < e; ++py)
            for (int px = 0; px < w; ++px) {
                dvec3 acc(0.0);
                for (int sy = 0; sy < preview_ss; ++sy)
                    for (int sx = 0; sx < preview_ss; ++sx) {
                        const double fx = px + (sx + 0.5) / preview_ss, fy = double(py) + (sy + 0.5) / preview_ss;
                        const int ci = std::min(int(fx) / preview_cell, cols - 1);
                        const int cj = std::min(int(fy) / preview_cell, rows - 1);
                        const double lx = (fx - (ci + 0.5) * preview_cell) / radius;
                        const double ly = -(fy - (cj + 0.5) * preview_cell) / radius;
                        const double d2 = lx * lx + ly * ly;
                        if (d2 < 1.0) { // orthographic sphere
                            const dvec3 n = lx * cam.right + ly * cam.up - std::sqrt(1.0 - d2) * cam.fwd;
                            const dvec3 v = -cam.fwd;
                            const double r = 0.25 * ci;
                            acc += shaders[cj][ci].ambient(std::clamp(glm::dot(n, v), 0.0, 1.0), bp.sample(n, v, r));
                        } else { // background: a pinhole view of the source
                            const double ndc_x = 2.0 * fx / w - 1.0, ndc_y = 1.0 - 2.0 * fy / h;
                            const dvec3 d = glm::normalize(cam.fwd + ndc_x * tan_h * cam.right + ndc_y * tan_v * cam.up);
                            acc += dvec3(source.radiance(fvec3(d), 0.0f));
                        }
                    }
                acc /= double(preview_ss * preview_ss);
                float* t = img.texel(px, int(py));
                for (int c = 0; c < 3; ++c) t[c] = float(acc[c]);
            }
    });
    return img;
}

// ---- files -------------------------------------------------------------------------------------

image_rgb32f face_image(const ibl::cubemap<float>& cube, int face, int level) {
    const int n = cube.size(level);
    image_rgb32f img(n, n);
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            const fvec3& v = cube.texel(face, x, y, level);
            float* t = img.texel(x, y);
            t[0] = v.x;
            t[1] = v.y;
            t[2] = v.z;
        }
    return img;
}

void write_text(const std::string& path, const std::string& text) {
    write_file_atomic(path, std::span<const unsigned char>(reinterpret_cast<const unsigned char*>(text.data()), text.size()));
}

const char* sh_convention =
    "Real spherical harmonics, orthonormal over the sphere, without the Condon-Shortley phase, 3 bands "
    "(9 coefficients, index k = l*l + l + m). Basis on a unit direction (x, y, z) of the world frame: "
    "Y0 = 0.282095 (1/(2 sqrt(pi))); Y1 = 0.488603 y; Y2 = 0.488603 z; Y3 = 0.488603 x "
    "(sqrt(3/(4 pi))); Y4 = 1.092548 x y; Y5 = 1.092548 y z (sqrt(15/pi)/2); "
    "Y6 = 0.315392 (3 z^2 - 1) (sqrt(5/pi)/4); Y7 = 1.092548 x z; Y8 = 0.546274 (x^2 - y^2) (sqrt(15/pi)/4). "
    "Frame: right-handed, +Y up; lat-long images map direction (x, y, z) to u = 0.5 + atan2(z, x)/(2 pi), "
    "v = 0.5 + asin(y)/pi, with the top image row at +Y (v = 1); cubemap faces +X, -X, +Y, -Y, +Z, -Z in the "
    "OpenGL orientation. 'radiance' holds L_k = integral L(w) Y_k(w) dw (linear RGB, after the window if one "
    "was applied); 'irradiance' holds E_k = A_l L_k with A_0 = pi, A_1 = 2 pi/3, A_2 = pi/4, so that "
    "E(n) = sum_k E_k Y_k(n) = integral L(w) max(0, n.w) dw; 'irradiance_over_pi_shader' holds c_k = E_k K_k / pi "
    "for the polynomial form E(n)/pi = sum_k c_k p_k(n) with p = (1, y, z, x, x y, y z, 3 z^2 - 1, x z, x^2 - y^2) "
    "(multiply by the diffuse albedo for Lambert).";

} // namespace

void run_bake(const bake_options& opt, std::FILE* out) {
    const auto t_total = std::chrono::steady_clock::now();
    const quality_settings qs = settings_for(opt.q);
    progress prog(!opt.quiet, ::isatty(2) != 0);
    pool_executor ex(opt.threads, &prog);
    check_output_dir(opt.out);
    std::vector<table_row> rows;
    const int n = opt.size;
    const int levels = opt.levels > 0 ? opt.levels : auto_levels(n);

    // ---- source ----------------------------------------------------------------------------
    source_env src;
    if (!opt.input.empty()) {
        prog.begin("read input");
        image_rgb32f img = read_latlong(opt.input, {}, &src.rr);
        src.analytic = false;
        src.name = opt.input;
        src.width = img.width;
        src.height = img.height;
        src.map = std::make_unique<ibl::latlong<float>>(img.width, img.height, std::span<const float>(img.rgb), 1);
        src.map->update_borders();
        const double ms = prog.end();
        rows.push_back({"input", src.rr.format + " " + std::to_string(img.width) + "x" + std::to_string(img.height),
                        std::to_string(src.rr.negative_values) + " negative values clamped", ms, "-"});
    } else {
        src.name = "built-in sky + sun (ibl::make_default_sky)";
    }
    int bake_k = qs.bake_k;
    if (!src.analytic) // every lat-long texel reaches the cube: k n >= W / 4 (a face spans 90 degrees)
        bake_k = std::clamp(int(std::ceil(double(src.width) / (4.0 * n))), qs.bake_k, 32);
    prog.begin("source cube");
    const ibl::cubemap<float> source = with_env(src, [&](const auto& env) {
        if constexpr (std::is_same_v<std::decay_t<decltype(env)>, ibl::latlong<float>>)
            return ibl::bake_cubemap<float>(env, n, bake_k, ex, 0);
        else
            return ibl::bake_cubemap<float>(ibl::make_default_sky<float>(), n, bake_k, ex, 0);
    });
    const double source_ms = prog.end();
    rows.push_back({"source cube", "supersampled bake + box mips", std::to_string(n) + "^2, " + std::to_string(bake_k) +
                    "x" + std::to_string(bake_k) + " sub-samples", source_ms, "-"});
    const dvec3 light = brightest_direction(source, 0);
    const luminance_stats lstats = source_luminance(source);

    // ---- prefiltered specular chain --------------------------------------------------------
    ibl::prefilter_options po;
    po.levels = levels;
    po.base_size = n;
    po.policy = ibl::roughness_mip_policy::linear();
    po.method = ibl::prefilter_method::filtered_importance;
    po.samples = qs.prefilter_samples;
    // Level l has 4^-l of the base's texels, so doubling the samples per level keeps each level's
    // cost falling geometrically (the whole chain costs < 2x level 1) while the rough levels,
    // where a sun is smeared over many texels and shows as mottle, get many more samples.
    po.samples_per_level.assign(std::size_t(levels > 0 ? levels : 1), 0u);
    for (std::size_t l = 1; l < po.samples_per_level.size(); ++l)
        po.samples_per_level[l] = std::min<std::uint32_t>(qs.prefilter_samples << (l - 1), 16384u);
    po.trilinear = qs.trilinear;
    prog.begin("prefilter");
    const ibl::cubemap<float> chain = ibl::prefilter(source, po, ex);
    const double prefilter_ms = prog.end();
    const int chain_levels = chain.levels();

    // ---- SH --------------------------------------------------------------------------------
    prog.begin("sh");
    const sh3 sh_raw = ibl::project_cube<3>(
        n, [&](int f, int x, int y) { return dvec3(source.texel(f, x, y, 0)); }, ex);
    const ibl::sh_auto_window_result<double, 3> win = ibl::sh_auto_window(sh_raw);
    const bool windowed = std::isfinite(win.width);
    const sh3 sh_rad = win.radiance;
    const sh3 sh_irr = ibl::sh_irradiance(sh_rad);
    const sh3 sh_shader = ibl::sh_shader_coeffs(sh_rad, ibl::sh_shader_output::irradiance_over_pi);
    const double sh_ms = prog.end();

    // ---- DFG -------------------------------------------------------------------------------
    prog.begin("dfg lut");
    const ibl::dfg_lut lut = ibl::make_dfg_lut_exact<model>(std::uint32_t(opt.lut_size), 3, qs.dfg_nodes, ex);
    const double dfg_ms = prog.end();

    // ---- checks: specular ------------------------------------------------------------------
    std::vector<level_check> spec_checks;
    prog.begin("check specular");
    const double mean_radiance = std::max(lstats.mean, 1e-30);
    for (int l = 0; l < chain_levels; ++l) {
        prog.label("level " + std::to_string(l) + "/" + std::to_string(chain_levels - 1));
        const auto t0 = std::chrono::steady_clock::now();
        level_check lc;
        lc.level = l;
        lc.size = chain.size(l);
        lc.roughness = po.policy.roughness(double(l), chain_levels);
        lc.samples = l == 0 ? 0u : ibl::prefilter_samples(po, l, chain_levels);
        const std::vector<std::array<int, 3>> texels = check_texels(lc.size, qs.ref_grid, light);
        std::vector<dvec3> ref(texels.size());
        with_env(src, [&](const auto& env) {
            ex(texels.size(), [&](std::size_t b, std::size_t e) {
                for (std::size_t i = b; i < e; ++i) {
                    const auto& t = texels[i];
                    const dvec3 d = ibl::cube_texel_direction<double>(t[0], t[1], t[2], lc.size);
                    if (l == 0) {
                        ref[i] = ibl::cube_texel_mean(env, t[0], t[1], t[2], lc.size, level0_ref_k);
                    } else if constexpr (std::is_same_v<std::decay_t<decltype(env)>, ibl::sky_environment<double>>) {
                        ref[i] = ibl::reference_ld_sky(env, d, lc.roughness, qs.sky_ref_samples, qs.sun_cap_nodes);
                    } else {
                        ref[i] = ibl::reference_ld(env, d, lc.roughness, qs.ld_ref_samples);
                    }
                }
            });
            return 0;
        });
        // Relative errors use a floor of 1e-3 x the mean radiance (dark texels do not dominate).
        ibl::error_accumulator acc(1e-3 * mean_radiance);
        for (std::size_t i = 0; i < texels.size(); ++i)
            acc.add(dvec3(chain.texel(texels[i][0], texels[i][1], texels[i][2], l)), ref[i]);
        lc.m = acc.finish();
        lc.texels = texels.size();
        lc.ref_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        spec_checks.push_back(lc);
    }
    const double spec_check_ms = prog.end();
    {
        double worst_rel = 0.0, worst_over = 0.0;
        int worst_l = 0;
        for (const auto& c : spec_checks)
            if (c.level > 0) {
                if (c.m.rel_rmse > worst_rel) worst_rel = c.m.rel_rmse, worst_l = c.level;
                worst_over = std::max(worst_over, c.m.max_ratio);
            }
        rows.push_back({"specular chain", std::string("GGX filtered IS") + (qs.trilinear ? " (trilinear)" : ""),
                        std::to_string(qs.prefilter_samples) + "*2^(l-1) spp, " + std::to_string(chain_levels) + " levels",
                        prefilter_ms,
                        chain_levels > 1 ? fmt2("worst rel RMSE %.3g (level %.0f)", worst_rel, worst_l) +
                                               fmt(", max overshoot %.3g", worst_over)
                                         : "-"});
        for (const auto& c : spec_checks) {
            char name[64];
            std::snprintf(name, sizeof name, "  l%d %dx%d r=%.2f", c.level, c.size, c.size, c.roughness);
            const std::string ref = c.level == 0 ? "texel mean " + std::to_string(level0_ref_k) + "^2"
                                    : src.analytic ? "ref: sky IS + sun cap quadrature"
                                                   : "ref: GGX IS " + std::to_string(qs.ld_ref_samples) + " spp";
            rows.push_back({name, ref, std::to_string(c.texels) + " texels", c.ref_ms,
                            fmt2("rel RMSE %.3g, overshoot %.3g", c.m.rel_rmse, c.m.max_ratio)});
        }
    }

    // ---- checks: SH irradiance -------------------------------------------------------------
    prog.begin("check sh");
    int brute_level = 0;
    while (source.size(brute_level) > sh_brute_max_face && brute_level + 1 < source.levels()) ++brute_level;
    const int nb = source.size(brute_level);
    std::vector<dvec3> normals;
    for (int f = 0; f < 6; ++f)
        for (int y = 0; y < sh_check_grid; ++y)
            for (int x = 0; x < sh_check_grid; ++x) normals.push_back(ibl::cube_texel_direction<double>(f, x, y, sh_check_grid));
    std::vector<dvec3> tex_dir, tex_rad;
    for (int f = 0; f < 6; ++f)
        for (int y = 0; y < nb; ++y)
            for (int x = 0; x < nb; ++x) {
                tex_dir.push_back(ibl::cube_texel_direction<double>(f, x, y, nb));
                tex_rad.push_back(dvec3(source.texel(f, x, y, brute_level)) * ibl::cube_texel_solid_angle<double>(x, y, nb));
            }
    std::vector<dvec3> e_ref(normals.size());
    ex(normals.size(), [&](std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i) {
            dvec3 s(0.0);
            for (std::size_t t = 0; t < tex_dir.size(); ++t) s += tex_rad[t] * std::max(0.0, glm::dot(normals[i], tex_dir[t]));
            e_ref[i] = s;
        }
    });
    double sh_mean_rel = 0.0, sh_max_rel = 0.0, sh_mean_rel_raw = 0.0, sh_max_rel_raw = 0.0;
    for (std::size_t i = 0; i < normals.size(); ++i) {
        const double er = e_ref[i].x + e_ref[i].y + e_ref[i].z;
        const dvec3 es = ibl::sh_irradiance_at(sh_rad, normals[i]), eraw = ibl::sh_irradiance_at(sh_raw, normals[i]);
        const double rel = std::fabs(es.x + es.y + es.z - er) / er, rel_raw = std::fabs(eraw.x + eraw.y + eraw.z - er) / er;
        sh_mean_rel += rel / double(normals.size());
        sh_max_rel = std::max(sh_max_rel, rel);
        sh_mean_rel_raw += rel_raw / double(normals.size());
        sh_max_rel_raw = std::max(sh_max_rel_raw, rel_raw);
    }
    const double sh_check_ms = prog.end();
    rows.push_back({"sh irradiance", windowed ? fmt("3-band projection, Hanning window W=%.3g", win.width)
                                              : std::string("3-band projection, no window"),
                    std::to_string(6 * n * n) + " texels", sh_ms,
                    fmt2("mean rel %.3g, max rel %.3g", sh_mean_rel, sh_max_rel) +
                        fmt2(", min E %.3g -> %.3g", min3(win.min_before), min3(win.min_after))});

    // ---- checks: DFG -----------------------------------------------------------------------
    prog.begin("check dfg");
    const int gd = std::min(dfg_check_grid, opt.lut_size);
    std::vector<double> dfg_err(std::size_t(gd) * std::size_t(gd));
    ex(dfg_err.size(), [&](std::size_t b, std::size_t e) {
        for (std::size_t k = b; k < e; ++k) {
            const auto i = std::uint32_t((double(k % std::size_t(gd)) + 0.5) * opt.lut_size / gd);
            const auto j = std::uint32_t((double(k / std::size_t(gd)) + 0.5) * opt.lut_size / gd);
            const ibl::vec2<double> ref = ibl::dfg_exact<model>(lut.n_dot_v(i), lut.roughness(j));
            dfg_err[k] = std::max(std::fabs(double(lut.at(i, j, 0)) - ref.x), std::fabs(double(lut.at(i, j, 1)) - ref.y));
        }
    });
    const double dfg_max_abs = *std::max_element(dfg_err.begin(), dfg_err.end());
    const double dfg_check_ms = prog.end();
    const ibl::dfg_quadrature_nodes& dn = qs.dfg_nodes;
    rows.push_back({"dfg lut", std::string("quadrature, ") + model::name,
                    std::to_string(opt.lut_size) + "^2, " + std::to_string(dn.evaluations()) + " evals/texel", dfg_ms,
                    fmt("max abs %.3g vs dfg_exact", dfg_max_abs)});

    // ---- split sum against the MIS reference ----------------------------------------------
    const baked_products bp{&chain, po.policy, &lut, sh_shader};
    std::vector<split_result> split;
    prog.begin("check split sum");
    {
        int dist_level = 0;
        while (source.size(dist_level) > dist_max_face && dist_level + 1 < source.levels()) ++dist_level;
        ibl::cube_env_distribution_options dopt;
        dopt.level = dist_level;
        const ibl::cube_env_distribution dist(source, dopt);
        const std::vector<view_geom> views = make_views(light);
        for (const material_case& mc : k_materials)
            for (const double r : k_split_roughness) {
                prog.label(std::string(mc.name) + fmt(" r=%.1f", r));
                const auto t0 = std::chrono::steady_clock::now();
                split_result res;
                res.material = mc.name;
                res.roughness = r;
                const ibl::reference_material rm = ibl::make_reference_material(
                    mc.base_color, mc.metallic, r, ibl::diffuse_weighting::one_minus_fresnel_roughness);
                ibl::pbr_material<double> pm;
                pm.base_color = mc.base_color;
                pm.metallic = mc.metallic;
                pm.roughness = r;
                const auto shader = ibl::pbr_shader<double>::from(pm, false);
                ibl::radiance_reference_options ro;
                ro.samples = qs.split_sum_samples;
                for (const view_geom& g : views) {
                    const ibl::radiance_estimate ref = with_env(src, [&](const auto& env) {
                        return ibl::reference_radiance<model>(env, dist, g.n, g.v, rm, ro, ex);
                    });
                    const dvec3 split_lo = shader.ambient(g.n_dot_v, bp.sample(g.n, g.v, r));
                    const double yr = lum(ref.value), ys = lum(split_lo);
                    const double rel = yr > 0.0 ? ys / yr - 1.0 : 0.0;
                    res.views.push_back({g.name, g.n_dot_v, yr, ys, rel, yr > 0.0 ? lum(ref.std_error) / yr : 0.0});
                    res.max_abs_rel = std::max(res.max_abs_rel, std::fabs(rel));
                    res.mean_abs_rel += std::fabs(rel) / double(views.size());
                }
                res.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
                double se = 0.0;
                for (const auto& v : res.views) se = std::max(se, v.se_rel);
                rows.push_back({std::string("split sum ") + mc.name + fmt(" r=%.1f", r),
                                "baked LD+DFG+SH vs MIS reference",
                                std::to_string(views.size()) + " views x " + std::to_string(qs.split_sum_samples) + " spp",
                                res.ms,
                                fmt2("mean |rel| %.2f%%, max |rel| %.2f%%", 100.0 * res.mean_abs_rel, 100.0 * res.max_abs_rel) +
                                    fmt(" (ref se %.2f%%)", 100.0 * se)});
                split.push_back(res);
            }
    }
    prog.end();

    // ---- preview ---------------------------------------------------------------------------
    prog.begin("preview");
    const camera cam = make_camera(light);
    const image_rgb32f preview = render_preview(bp, source, cam, qs.preview_ss, ex);
    png_options png;
    png.op = tonemap::reinhard;
    png.exposure = float(preview_key / std::max(lstats.mean, 1e-6));
    const double preview_ms = prog.end();
    rows.push_back({"preview", "baked products, orthographic spheres", "640x256, " + std::to_string(qs.preview_ss) + "x" + std::to_string(qs.preview_ss) + " ss", preview_ms,
                    fmt("exposure %.3g", png.exposure)});

    // ---- files -----------------------------------------------------------------------------
    prog.begin("write files");
    output_stage stage(opt.out);
    std::vector<std::string> files;
    auto staged = [&](const std::string& name) {
        files.push_back(name);
        return stage.file(name);
    };
    for (int l = 0; l < chain_levels; ++l)
        for (int f = 0; f < 6; ++f)
            write_exr(staged("specular_l" + std::to_string(l) + "_" + face_names[f] + ".exr"), face_image(chain, f, l));
    {
        cubemap_rgb32f kc = cubemap_rgb32f::zeros(n, chain_levels);
        for (int l = 0; l < chain_levels; ++l) {
            const int s = kc.face_size(l);
            for (int f = 0; f < 6; ++f)
                for (int y = 0; y < s; ++y)
                    for (int x = 0; x < s; ++x) {
                        const fvec3& v = chain.texel(f, x, y, l);
                        float* t = &kc.levels[std::size_t(l)][std::size_t(f)][3 * (std::size_t(y) * std::size_t(s) + std::size_t(x))];
                        t[0] = v.x;
                        t[1] = v.y;
                        t[2] = v.z;
                    }
        }
        write_ktx2_cubemap(staged("specular.ktx2"), kc, opt.ktx2_f32 ? ktx2_format::rgba32f : ktx2_format::rgba16f,
                           std::string("ibl-bake ") + tool_version);
    }
    {
        image_rgb32f d(opt.lut_size, opt.lut_size);
        for (std::uint32_t j = 0; j < lut.size; ++j)
            for (std::uint32_t i = 0; i < lut.size; ++i)
                for (std::uint32_t c = 0; c < 3; ++c) d.texel(int(i), int(j))[c] = lut.at(i, j, c);
        write_exr(staged("dfg.exr"), d);
        write_text(staged("dfg.hpp"),
                   ibl::dfg_lut_header(lut, "dfg_lut", "ibl_baked",
                                       std::string(model::name) + ", exact quadrature (ibl-bake --quality " + qs.name + ")"));
    }
    write_png(staged("preview.png"), preview, png);
    {
        json_writer j;
        j.begin_object();
        j.key("bands").value(3);
        auto triples = [&](const char* key, const sh3& c) {
            j.key(key).begin_array();
            for (int k = 0; k < 9; ++k) {
                j.begin_array();
                for (int ch = 0; ch < 3; ++ch) j.value(c[k][ch]);
                j.end_array();
            }
            j.end_array();
        };
        triples("radiance", sh_rad);
        triples("irradiance", sh_irr);
        triples("irradiance_over_pi_shader", sh_shader);
        j.key("convention").value(sh_convention);
        j.key("window").begin_object();
        j.key("applied").value(windowed);
        j.key("kind").value("hanning");
        if (windowed) j.key("width").value(win.width);
        else j.key("width").null();
        j.key("rule").value("applied (weakest Hanning window keeping E >= 0 everywhere, ibl::sh_auto_window) only when "
                            "the unwindowed irradiance has a negative minimum");
        j.key("min_irradiance_before").begin_array().value(win.min_before.x).value(win.min_before.y).value(win.min_before.z).end_array();
        j.key("min_irradiance_after").begin_array().value(win.min_after.x).value(win.min_after.y).value(win.min_after.z).end_array();
        j.end_object();
        j.end_object();
        write_text(staged("sh.json"), j.str() + "\n");
    }
    const double write_ms = prog.end();
    rows.push_back({"files", "EXR (ZIP), KTX2, PNG, JSON, C++ header", std::to_string(files.size() + 1) + " files",
                    write_ms, "-"});
    const double total_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t_total).count();

    // ---- report.json -----------------------------------------------------------------------
    {
        json_writer j;
        j.begin_object();
        j.key("tool").value("ibl-bake");
        j.key("version").value(tool_version);
        j.key("options").begin_object();
        j.key("input").value(opt.input.empty() ? std::string("(built-in sky)") : opt.input);
        j.key("size").value(n);
        j.key("lut_size").value(opt.lut_size);
        j.key("levels").value(chain_levels);
        j.key("quality").value(qs.name);
        j.key("threads").value(ex.threads());
        j.key("ktx2_format").value(opt.ktx2_f32 ? "rgba32f" : "rgba16f");
        j.end_object();
        j.key("source").begin_object();
        j.key("kind").value(src.analytic ? "analytic" : "latlong");
        j.key("name").value(src.name);
        if (!src.analytic) {
            j.key("format").value(src.rr.format);
            j.key("width").value(src.width);
            j.key("height").value(src.height);
            j.key("negative_values_clamped").value(src.rr.negative_values);
            j.key("max_value").value(src.rr.max_value);
        }
        j.key("method").value("k x k supersampled bake to a cubemap (ibl::bake_cubemap), exact spherical box mips");
        j.key("cost").begin_object().key("face_size").value(n).key("subsamples_per_axis").value(bake_k).end_object();
        j.key("time_ms").value(source_ms);
        j.key("mean_luminance").value(lstats.mean);
        j.key("log_average_luminance").value(lstats.log_average);
        j.key("brightest_direction").begin_array().value(light.x).value(light.y).value(light.z).end_array();
        j.end_object();

        j.key("specular").begin_object();
        j.key("files").value("specular_l{level}_{px,nx,py,ny,pz,nz}.exr, specular.ktx2");
        j.key("method").value(std::string("GGX filtered importance sampling (Krivanek-Colbert), ") +
                              (qs.trilinear ? "trilinear" : "nearest-level") + " source reads, N = V = R");
        j.key("cost").begin_object().key("samples_per_texel").value(qs.prefilter_samples).key("lod_bias").value(po.lod_bias).end_object();
        j.key("time_ms").value(prefilter_ms);
        j.key("mip_policy").value("linear: roughness = level / (levels - 1); lod = roughness * (levels - 1)");
        j.key("check").begin_object();
        j.key("reference").value(src.analytic ? "level 0: texel mean (16x16 sub-samples); levels >= 1: ibl::reference_ld_sky "
                                                "(sky by GGX IS + sun cap quadrature)"
                                              : "level 0: texel mean (16x16 sub-samples) of the input; levels >= 1: "
                                                "ibl::reference_ld on the input lat-long map (GGX IS, double)");
        j.key("texels").value("per level: a grid per face plus the 3x3 block around the brightest direction");
        j.key("relative_error_floor").value(1e-3 * mean_radiance);
        j.key("time_ms").value(spec_check_ms);
        j.end_object();
        j.key("levels").begin_array();
        for (const auto& c : spec_checks) {
            j.begin_object();
            j.key("level").value(c.level);
            j.key("size").value(c.size);
            j.key("roughness").value(c.roughness);
            j.key("samples").value(c.samples);
            j.key("texels_compared").value(c.texels);
            j.key("rel_rmse").value(c.m.rel_rmse);
            j.key("nrmse").value(c.m.nrmse);
            j.key("max_overshoot").value(c.m.max_ratio);
            j.key("max_rel").value(c.m.max_rel);
            j.key("reference_time_ms").value(c.ref_ms);
            j.end_object();
        }
        j.end_array();
        j.end_object();

        j.key("sh").begin_object();
        j.key("file").value("sh.json");
        j.key("method").value("3-band projection of the source cube (exact texel solid angles), Lambert convolution");
        j.key("cost").begin_object().key("texels").value(6 * n * n).end_object();
        j.key("time_ms").value(sh_ms);
        j.key("window_applied").value(windowed);
        if (windowed) j.key("window_width").value(win.width);
        else j.key("window_width").null();
        j.key("min_irradiance_before").value(min3(win.min_before));
        j.key("min_irradiance_after").value(min3(win.min_after));
        j.key("check").begin_object();
        j.key("reference").value("brute-force cosine integration over every texel of source level " +
                                 std::to_string(brute_level) + " (" + std::to_string(nb) + "^2 faces)");
        j.key("normals").value(normals.size());
        j.key("mean_rel").value(sh_mean_rel);
        j.key("max_rel").value(sh_max_rel);
        j.key("mean_rel_unwindowed").value(sh_mean_rel_raw);
        j.key("max_rel_unwindowed").value(sh_max_rel_raw);
        j.key("time_ms").value(sh_check_ms);
        j.end_object();
        j.end_object();

        j.key("dfg").begin_object();
        j.key("files").value("dfg.exr, dfg.hpp");
        j.key("model").value(std::string(model::name) +
                             ": GGX NDF, height-correlated Smith masking-shadowing, Schlick Fresnel; "
                             "specular = LD (F0 A + F90 B); multiscatter k = (1 - E)/E, E = A + B (Turquin 2019)");
        j.key("method").value("deterministic quadrature (ibl::make_dfg_lut_exact)");
        j.key("cost").begin_object();
        j.key("size").value(opt.lut_size);
        j.key("nodes").begin_array().value(dn.full_y).value(dn.full_phi).value(dn.partial_y).value(dn.partial_phi).end_array();
        j.key("evaluations_per_texel").value(dn.evaluations());
        j.end_object();
        j.key("time_ms").value(dfg_ms);
        j.key("layout").value("x = n.v = (i + 0.5)/N, y = roughness = (j + 0.5)/N (texel centres); EXR row 0 (top) = "
                              "roughness 0.5/N, roughness increases downwards; R = A, G = B, B = k");
        j.key("check").begin_object();
        j.key("reference").value("ibl::dfg_exact (default nodes, converged to 1e-6)");
        j.key("texels").value(dfg_err.size());
        j.key("max_abs").value(dfg_max_abs);
        j.key("time_ms").value(dfg_check_ms);
        j.end_object();
        j.end_object();

        j.key("split_sum").begin_object();
        j.key("method").value("single-scattering ambient (shade.hpp) from the baked products: chain sampled trilinearly "
                              "at lod = policy(r), DFG LUT bilinear, SH irradiance; against ibl::reference_radiance "
                              "(MIS of the BRDF and the source's luminance distribution), same diffuse weighting");
        j.key("samples_per_view").value(qs.split_sum_samples);
        j.key("materials").begin_array();
        for (const auto& s : split) {
            j.begin_object();
            j.key("material").value(s.material);
            j.key("roughness").value(s.roughness);
            j.key("mean_abs_rel").value(s.mean_abs_rel);
            j.key("max_abs_rel").value(s.max_abs_rel);
            j.key("time_ms").value(s.ms);
            j.key("views").begin_array();
            for (const auto& v : s.views) {
                j.begin_object();
                j.key("view").value(v.view);
                j.key("n_dot_v").value(v.n_dot_v);
                j.key("luminance_reference").value(v.y_ref);
                j.key("luminance_split_sum").value(v.y_split);
                j.key("rel").value(v.rel);
                j.key("reference_rel_std_error").value(v.se_rel);
                j.end_object();
            }
            j.end_array();
            j.end_object();
        }
        j.end_array();
        j.end_object();

        j.key("preview").begin_object();
        j.key("file").value("preview.png");
        j.key("layout").value("5 x 2 spheres: roughness 0, 0.25, 0.5, 0.75, 1 left to right; dielectric (top), metal "
                              "(bottom); orthographic, camera looking away from the brightest direction");
        j.key("shading").value("multiple-scattering ambient (Fdez-Aguera 2019) from the baked products");
        j.key("exposure").value(png.exposure);
        j.key("tonemap").value("exposure = 0.6 / mean luminance of the environment (solid-angle weighted), Reinhard x/(1+x), sRGB");
        j.key("time_ms").value(preview_ms);
        j.end_object();

        j.key("files").begin_array();
        for (const auto& f : files) j.value(f);
        j.value("report.json");
        j.end_array();
        j.key("total_time_ms").value(total_ms);
        j.end_object();
        write_text(stage.file("report.json"), j.str() + "\n");
    }
    stage.commit();

    std::fprintf(out, "ibl-bake %s: %s -> %s (size %d, %d levels, LUT %d, quality %s, %u threads)\n\n", tool_version,
                 src.name.c_str(), opt.out.c_str(), n, chain_levels, opt.lut_size, qs.name, ex.threads());
    print_table(out, rows);
    std::fprintf(out, "\ntotal %.0f ms; %zu files in %s\n", total_ms, files.size() + 1, opt.out.c_str());
}

} // namespace ibl_bake
