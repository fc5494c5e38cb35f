// tools/ibl-bake/stages/stage_split_sum.cpp — check: what the baked products give through the runtime
// model. The single-scattering ambient of shade.hpp from the baked products (the chain read by
// ibl/runtime/lookup.hpp's lookups; with --runtime lobe at the lobe LUT's direction and roughness with its
// (A, B), with --runtime taps2 at the two taps' directions and roughness with the table's (A, B),
// else at R and r with the DFG table's) and the diffuse product, plus an extracted sun as a
// disk light, against ibl::reference_radiance (MIS of the BRDF and the source's luminance
// distribution, no split sum) with the same diffuse weighting, for a dielectric and a metal at
// three roughness values, seen in three views about the brightest direction. With the lobe or
// taps2 model the plain split sum (LD(R, r) DFG) of the same products is measured too, against
// the same reference: the report shows both, each mean |rel| with its standard error from the
// reference's (each view's |rel| moves by (1 + rel) times the reference's relative standard
// error; views independent), and flags the runtime model as worse than the split sum only where
// its mean |rel| exceeds the split sum's by more than the noise: two standard errors of the
// difference, sqrt(se_runtime^2 + se_split^2).

#include "stages/stages.hpp"

#include <algorithm>
#include <cmath>

#include <ibl/core/color.hpp>
#include <ibl/reference/env_importance.hpp>
#include <ibl/reference/radiance.hpp>

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
/// One model's answers for one material and roughness.
struct model_result {
    std::vector<view_result> views;
    double max_abs_rel = 0.0, mean_abs_rel = 0.0;
    double mean_abs_rel_var = 0.0; ///< variance of mean_abs_rel from the reference's noise

    void add(const view_result& v, std::size_t count) {
        views.push_back(v);
        max_abs_rel = std::max(max_abs_rel, std::fabs(v.rel));
        mean_abs_rel += std::fabs(v.rel) / double(count);
        const double s = (1.0 + v.rel) * v.se_rel / double(count);
        mean_abs_rel_var += s * s;
    }
    double mean_abs_rel_se() const { return std::sqrt(mean_abs_rel_var); }
};
struct split_result {
    std::string material;
    double roughness = 0.0;
    model_result runtime, plain; ///< the runtime model; the plain split sum (the same with --runtime split-sum)
    double ms = 0.0;

    /// The runtime model's mean |rel| minus the split sum's, the noise it is judged against (two
    /// standard errors of the difference) and whether it exceeds it.
    double excess() const { return runtime.mean_abs_rel - plain.mean_abs_rel; }
    double noise() const { return 2.0 * std::sqrt(runtime.mean_abs_rel_var + plain.mean_abs_rel_var); }
    bool worse() const { return excess() > noise(); }
};

class split_sum_stage final : public stage {
public:
    const char* key() const override { return "split_sum"; }
    stage_kind kind() const override { return stage_kind::check; }
    bool enabled(const bake_context& ctx) const override { return !ctx.scene_mode && ctx.chain && ctx.lut; }
    double check_ms() const override {
        double t = 0.0;
        for (const auto& r : results_) t += r.ms;
        return t;
    }

    void run(bake_context& ctx) override {
        samples_ = ctx.qs.split_sum_samples;
        ctx.prog.begin("check split sum");
        ibl::cube_env_distribution_options dopt;
        dopt.level = level_at_most(ctx.whole_source(), dist_max_face); // with its sun: the reference is of the whole
        const ibl::cube_env_distribution dist(ctx.whole_source(), dopt);
        const std::vector<view_geom> views = make_views(ctx.light);
        nviews_ = views.size();
        const product_view bp = baked_view(ctx);
        model_ = bp.taps ? runtime_choice::taps2 : bp.lobe ? runtime_choice::lobe : runtime_choice::split_sum;
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

    void report_model(json_writer& j, bool runtime) const;

    std::uint32_t samples_ = 0;
    std::size_t nviews_ = 0;
    runtime_choice model_ = runtime_choice::split_sum; ///< the runtime model measured beside the plain split sum
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
        const double yr = ibl::luminance(ref.value), se = yr > 0.0 ? ibl::luminance(ref.std_error) / yr : 0.0;
        auto result = [&](const product_view& pv) {
            const double ys = ibl::luminance(pv.shade(shader, g.n, g.v));
            return view_result{g.name, g.n_dot_v, yr, ys, yr > 0.0 ? ys / yr - 1.0 : 0.0, se};
        };
        res.runtime.add(result(bp), views.size());
        res.plain.add(bp.lobe || bp.taps ? result(bp.split_sum()) : res.runtime.views.back(), views.size());
    }
    res.ms = ms_since(t0);
    return res;
}

namespace {
/// What an alarming error of a runtime model against the full integral means.
std::string model_meaning(runtime_choice model) {
    if (model == runtime_choice::split_sum) return "the split-sum approximation's own error, not a bake defect: --runtime lobe/taps2 lower it";
    if (model == runtime_choice::lobe) return "the lobe model's own error vs the full integral, not a bake defect: --runtime taps2 lowers it";
    return "the two-tap model's own error vs the full integral, not a bake defect (docs/runtime.md)";
}
} // namespace

std::vector<table_row> split_sum_stage::rows() const {
    std::vector<table_row> rows;
    auto name_of = [](runtime_choice model) { return std::string(model == runtime_choice::split_sum ? "split sum " : model == runtime_choice::lobe ? "lobe lut " : "taps2 "); };
    auto method_of = [](runtime_choice model) {
        return model == runtime_choice::split_sum ? "baked LD+DFG+SH vs MIS reference"
               : model == runtime_choice::lobe    ? "baked F0 A LD(d_A)+F90 B LD(d_B)+SH vs MIS"
                                    : "baked 2 x LD(d_k, r_k)+taps LUT+SH vs MIS";
    };
    auto row = [&](const split_result& res, const model_result& m, runtime_choice model) {
        double se = 0.0;
        for (const auto& v : m.views) se = std::max(se, v.se_rel);
        const bool plain = model == runtime_choice::split_sum;
        std::string cmp;
        if (!plain)
            cmp = fmt2("; vs split sum %+.2f%% (noise %.2f%%)", 100.0 * res.excess(), 100.0 * res.noise()) +
                  (res.worse() ? " WORSE" : "");
        table_row r{name_of(model) + res.material + fmt(" r=%.1f", res.roughness), method_of(model),
                    std::to_string(nviews_) + " views x " + std::to_string(samples_) + " spp", plain ? res.ms : -1.0,
                    fmt2("mean |rel| %.2f%%, max |rel| %.2f%%", 100.0 * m.mean_abs_rel, 100.0 * m.max_abs_rel) +
                        fmt(" (ref se %.2f%%)", 100.0 * se) + cmp};
        r.detail = true;
        r.alarm(m.max_abs_rel, alarm_relative, model_meaning(model));
        rows.push_back(r);
    };
    // the compact table: per model and material the worst max |rel| over the roughness values
    auto summary = [&](runtime_choice model, bool runtime) {
        for (const material_case& mc : k_materials) {
            double worst = -1.0, at = 0.0, se = 0.0, ms = 0.0;
            int worse = 0; // roughness values where the runtime model is worse than the split sum beyond noise
            for (const auto& res : results_) {
                if (res.material != mc.name) continue;
                if (runtime && res.worse()) ++worse;
                const model_result& m = runtime ? res.runtime : res.plain;
                if (m.max_abs_rel > worst) worst = m.max_abs_rel, at = res.roughness;
                for (const auto& v : m.views) se = std::max(se, v.se_rel);
                ms += res.ms;
            }
            if (worst < 0.0) continue;
            table_row r{name_of(model) + mc.name, method_of(model), std::to_string(nviews_) + " views x 3 r", model == runtime_choice::split_sum ? ms : -1.0,
                        ""};
            r.compact(model == runtime_choice::split_sum ? "LD+DFG+SH vs MIS" : model == runtime_choice::lobe ? "lobe LUT+SH vs MIS" : "2 taps+SH vs MIS",
                      fmt2("max |rel| %.3g%% (r=%.1f)", 100.0 * worst, at) + fmt(", ref se %.2f%%", 100.0 * se) +
                          (worse > 0 ? std::string(", WORSE than split sum") : std::string()))
                .alarm(worst, alarm_relative, model_meaning(model));
            r.summary = true; // the wide table has the rows per roughness instead
            rows.push_back(r);
        }
    };
    summary(runtime_choice::split_sum, false);
    if (model_ != runtime_choice::split_sum) summary(model_, true);
    for (const auto& res : results_) row(res, res.plain, runtime_choice::split_sum);
    if (model_ != runtime_choice::split_sum)
        for (const auto& res : results_) row(res, res.runtime, model_);
    return rows;
}

void split_sum_stage::report(json_writer& j) const {
    j.begin_object();
    j.key("method").value("single-scattering ambient (shade.hpp) from the baked products through the runtime model "
                          "(runtime_model; lobe: LD at normalize(lerp(n, R, s)) and r_eff, (A, B, s, r_eff) from the lobe "
                          "LUT; taps2: sum_k w_k LD(d_k, r_k) / sum_k w_k at the two taps' directions and roughness, "
                          "(A, B) and the taps from the two-tap table; split-sum: LD at R and r, (A, B) from the DFG "
                          "LUT), the chain by the bake's lookup, the "
                          "diffuse product; against ibl::reference_radiance (MIS of the BRDF and the source's luminance "
                          "distribution), same diffuse weighting. materials: the runtime model; materials_split_sum: "
                          "the plain split sum of the same products; mean_abs_rel_std_error: the standard error of "
                          "mean_abs_rel from the reference's (sqrt(sum_views ((1 + rel) reference_rel_std_error)^2) / "
                          "views); vs_split_sum (materials): excess = mean_abs_rel - the split sum's, noise = 2 "
                          "sqrt(se^2 + se_split_sum^2), worse = excess > noise");
    j.key("runtime_model").value(to_string(model_));
    j.key("samples_per_view").value(samples_);
    std::size_t worse = 0;
    for (const auto& s : results_) worse += s.worse() ? 1 : 0;
    j.key("runtime_worse_than_split_sum").value(std::uint64_t(model_ == runtime_choice::split_sum ? 0 : worse));
    report_model(j, true);
    report_model(j, false);
    j.end_object();
}

void split_sum_stage::report_model(json_writer& j, bool runtime) const {
    j.key(runtime ? "materials" : "materials_split_sum").begin_array();
    for (const auto& s : results_) {
        const model_result& m = runtime ? s.runtime : s.plain;
        j.begin_object();
        j.key("material").value(s.material).key("roughness").value(s.roughness);
        j.key("mean_abs_rel").value(m.mean_abs_rel).key("mean_abs_rel_std_error").value(m.mean_abs_rel_se());
        j.key("max_abs_rel").value(m.max_abs_rel).key("time_ms").value(s.ms);
        if (runtime) {
            j.key("vs_split_sum").begin_object();
            j.key("split_sum_mean_abs_rel").value(s.plain.mean_abs_rel).key("split_sum_std_error").value(s.plain.mean_abs_rel_se());
            j.key("excess").value(s.excess()).key("noise").value(s.noise()).key("worse").value(model_ != runtime_choice::split_sum && s.worse());
            j.end_object();
        }
        j.key("views").begin_array();
        for (const auto& v : m.views) {
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
}

} // namespace

std::unique_ptr<stage> make_split_sum_stage() { return std::make_unique<split_sum_stage>(); }

} // namespace ibl_bake
