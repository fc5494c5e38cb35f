// tools/ibl-bake/stage_split_sum.cpp — check: what the baked products give through the runtime
// model. The single-scattering ambient of shade.hpp from the baked chain and DFG table (read by
// ibl/lookup.hpp's lookups) and the diffuse product, plus an extracted sun as a disk light, against
// ibl::reference_radiance (MIS of the BRDF and the source's luminance distribution, no split sum)
// with the same diffuse weighting, for a dielectric and a metal at three roughness values, seen
// in three views about the brightest direction.

#include "stages.hpp"

#include <algorithm>
#include <cmath>

#include <ibl/core/color.hpp>
#include <ibl/integrate/env_importance.hpp>
#include <ibl/integrate/radiance_reference.hpp>

namespace ibl_bake {

namespace {

constexpr int dist_max_face = 128; ///< env distribution of the reference: face <= this

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
const double k_roughness[3] = {0.1, 0.5, 0.9};

struct view_result {
    std::string view;
    double n_dot_v, y_ref, y_split, rel, se_rel;
};
struct split_result {
    std::string material;
    double roughness = 0.0;
    std::vector<view_result> views;
    double max_abs_rel = 0.0, mean_abs_rel = 0.0, ms = 0.0;
};

class split_sum_stage final : public stage {
public:
    const char* key() const override { return "split_sum"; }
    stage_kind kind() const override { return stage_kind::check; }
    bool enabled(const bake_context& ctx) const override { return !ctx.scene_mode && ctx.chain && ctx.lut; }

    void run(bake_context& ctx) override {
        samples_ = ctx.qs.split_sum_samples;
        ctx.prog.begin("check split sum");
        ibl::cube_env_distribution_options dopt;
        dopt.level = level_at_most(ctx.whole_source(), dist_max_face); // with its sun: the reference is of the whole
        const ibl::cube_env_distribution dist(ctx.whole_source(), dopt);
        const std::vector<view_geom> views = make_views(ctx.light);
        nviews_ = views.size();
        const product_view bp = baked_view(ctx);
        for (const material_case& mc : k_materials)
            for (const double r : k_roughness) {
                ctx.prog.label(std::string(mc.name) + fmt(" r=%.1f", r));
                results_.push_back(measure(ctx, dist, views, bp, mc, r));
            }
        ctx.prog.end();
    }

    std::vector<table_row> rows() const override;
    void report(json_writer& j) const override;

private:
    split_result measure(const bake_context& ctx, const ibl::cube_env_distribution& dist, const std::vector<view_geom>& views,
                         const product_view& bp, const material_case& mc, double r) const;

    std::uint32_t samples_ = 0;
    std::size_t nviews_ = 0;
    std::vector<split_result> results_;
};

split_result split_sum_stage::measure(const bake_context& ctx, const ibl::cube_env_distribution& dist,
                                      const std::vector<view_geom>& views, const product_view& bp, const material_case& mc,
                                      double r) const {
    const auto t0 = std::chrono::steady_clock::now();
    split_result res;
    res.material = mc.name;
    res.roughness = r;
    const ibl::reference_material rm =
        ibl::make_reference_material(mc.base_color, mc.metallic, r, ibl::diffuse_weighting::one_minus_fresnel_roughness);
    ibl::pbr_material<double> pm;
    pm.base_color = mc.base_color;
    pm.metallic = mc.metallic;
    pm.roughness = r;
    const auto shader = ibl::pbr_shader<double>::from(pm, false);
    ibl::radiance_reference_options ro;
    ro.samples = samples_;
    for (const view_geom& g : views) {
        const ibl::radiance_estimate ref = ctx.src.visit(
            [&](const auto& env) { return ibl::reference_radiance<bake_model>(env, dist, g.n, g.v, rm, ro, ctx.ex); });
        const dvec3 split_lo = bp.shade(shader, g.n, g.v);
        const double yr = ibl::luminance(ref.value), ys = ibl::luminance(split_lo);
        const double rel = yr > 0.0 ? ys / yr - 1.0 : 0.0;
        res.views.push_back({g.name, g.n_dot_v, yr, ys, rel, yr > 0.0 ? ibl::luminance(ref.std_error) / yr : 0.0});
        res.max_abs_rel = std::max(res.max_abs_rel, std::fabs(rel));
        res.mean_abs_rel += std::fabs(rel) / double(views.size());
    }
    res.ms = ms_since(t0);
    return res;
}

std::vector<table_row> split_sum_stage::rows() const {
    std::vector<table_row> rows;
    for (const auto& res : results_) {
        double se = 0.0;
        for (const auto& v : res.views) se = std::max(se, v.se_rel);
        rows.push_back({"split sum " + res.material + fmt(" r=%.1f", res.roughness), "baked LD+DFG+SH vs MIS reference",
                        std::to_string(nviews_) + " views x " + std::to_string(samples_) + " spp", res.ms,
                        fmt2("mean |rel| %.2f%%, max |rel| %.2f%%", 100.0 * res.mean_abs_rel, 100.0 * res.max_abs_rel) +
                            fmt(" (ref se %.2f%%)", 100.0 * se)});
    }
    return rows;
}

void split_sum_stage::report(json_writer& j) const {
    j.begin_object();
    j.key("method").value("single-scattering ambient (shade.hpp) from the baked products: chain sampled trilinearly "
                          "at lod = policy(r), DFG LUT bilinear, SH irradiance; against ibl::reference_radiance "
                          "(MIS of the BRDF and the source's luminance distribution), same diffuse weighting");
    j.key("samples_per_view").value(samples_);
    j.key("materials").begin_array();
    for (const auto& s : results_) {
        j.begin_object();
        j.key("material").value(s.material).key("roughness").value(s.roughness);
        j.key("mean_abs_rel").value(s.mean_abs_rel).key("max_abs_rel").value(s.max_abs_rel).key("time_ms").value(s.ms);
        j.key("views").begin_array();
        for (const auto& v : s.views) {
            j.begin_object();
            j.key("view").value(v.view).key("n_dot_v").value(v.n_dot_v);
            j.key("luminance_reference").value(v.y_ref).key("luminance_split_sum").value(v.y_split);
            j.key("rel").value(v.rel).key("reference_rel_std_error").value(v.se_rel);
            j.end_object();
        }
        j.end_array();
        j.end_object();
    }
    j.end_array();
    j.end_object();
}

} // namespace

std::unique_ptr<stage> make_split_sum_stage() { return std::make_unique<split_sum_stage>(); }

} // namespace ibl_bake
