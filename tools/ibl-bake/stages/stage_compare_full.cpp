// tools/ibl-bake/stages/stage_compare_full.cpp — check (--scene --compare-full): is the plan worth it?
//   * the full bake (the full plan at --size) is baked and timed per product;
//   * a converged set: the virtual levels the scene reads at full resolution with 4096 filtered-IS
//     samples (trilinear reads), dfg_exact, brute-force irradiance;
//   * the scene's materials (lo, mid, hi of each roughness range) are shaded at 54 normals, each
//     seen at 45 degrees, with the planned, full and converged products; the planned and full
//     products' error is the relative RMS of ambient luminance against the converged set (the
//     error the plan's target refers to);
//   * per planned level: the planned and full levels against the reference LD and the converged
//     level (the measure of plan.hpp's tables);
//   * the split-sum approximation itself (converged products) against ibl::reference_radiance,
//     which no plan can change.

#include "stages/stages.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include <ibl/core/color.hpp>
#include <ibl/core/frame.hpp>
#include <ibl/env/convert.hpp>
#include <ibl/env/cube_geometry.hpp>
#include <ibl/bake/dfg_lut.hpp>
#include <ibl/reference/env_importance.hpp>
#include <ibl/reference/metrics.hpp>
#include <ibl/reference/radiance.hpp>
#include <ibl/reference/ld_irradiance.hpp>

#include "stages/check_texels.hpp"

namespace ibl_bake {

namespace {

struct shade_error {
    double rel_rms = 0.0, max_rel = 0.0;
    std::size_t points = 0;
};
struct level_row {
    int level;
    double roughness, nrmse_plan = 0, nrmse_full = 0, conv_plan = 0, conv_full = 0, expected = 0;
    std::uint32_t samples = 0;
    bool trilinear = false;
};
struct split_row {
    std::string material;
    double roughness, mean_abs_rel, max_abs_rel;
};

/// The converged reference set of the comparison.
struct converged_set {
    ibl::cubemap<float> chain{1};
    std::vector<dvec3> normals, e_brute;
    product_view view;
};

/// Relative RMS and largest relative difference of ambient luminance: `a` against the converged
/// set (whose irradiance is the brute-force value at the point's normal when `diffuse_lit`).
shade_error compare_shading(const std::vector<scene_shading_material>& mats, const std::vector<scene_shading_point>& pts,
                            const product_view& a, const converged_set& c, bool diffuse_lit, bool multiscatter) {
    double num = 0.0, den = 0.0;
    shade_error e;
    for (const auto& ms : mats) {
        const auto shader = ibl::pbr_shader<double>::from(ms.m, multiscatter);
        for (std::size_t i = 0; i < pts.size(); ++i) {
            const scene_shading_point& p = pts[i];
            const double nv = std::clamp(glm::dot(p.n, p.v), 0.0, 1.0);
            ibl::ibl_sample<double> sr = c.view.sample(p.n, p.v, ms.m.roughness);
            sr.irradiance_over_pi = diffuse_lit ? c.e_brute[i] / ibl::pi_v<double> : dvec3(0.0);
            const double ya = ibl::luminance(shader.ambient(nv, a.sample(p.n, p.v, ms.m.roughness)));
            const double yr = ibl::luminance(shader.ambient(nv, sr));
            num += (ya - yr) * (ya - yr);
            den += yr * yr;
            if (yr > 0) e.max_rel = std::max(e.max_rel, std::fabs(ya - yr) / yr);
            ++e.points;
        }
    }
    e.rel_rms = den > 0 ? std::sqrt(num / den) : 0.0;
    return e;
}

class compare_full_stage final : public stage {
public:
    const char* key() const override { return "compare_full"; }
    stage_kind kind() const override { return stage_kind::check; }
    bool enabled(const bake_context& ctx) const override { return ctx.scene_mode && ctx.opt.compare_full && ctx.chain && ctx.lut; }

    void run(bake_context& ctx) override {
        target_ = ctx.plan.error_target;
        diffuse_lit_ = ctx.plan.diffuse.kind != ibl::diffuse_product::none;
        bake_full(ctx);
        bake_converged(ctx);
        shade(ctx);
        check_levels(ctx);
        check_split_sum(ctx);
        planned_ms_ = ctx.measured.total();
    }

    std::vector<table_row> rows() const override;
    std::vector<std::string> notes_after() const override;
    void report(json_writer& j) const override;

private:
    void bake_full(bake_context& ctx);
    void bake_converged(bake_context& ctx);
    void shade(const bake_context& ctx);
    void check_levels(bake_context& ctx);
    void check_split_sum(bake_context& ctx);

    double target_ = 0.0;
    bool diffuse_lit_ = false;
    product_times tf_;
    ibl::cubemap<float> fsource_{1}, fchain_{1};
    std::optional<ibl::dfg_lut> flut_;
    diffuse_data fdiffuse_;
    converged_set conv_;
    double converged_ms_ = 0.0;
    shade_error err_plan_, err_full_;
    std::vector<level_row> levels_;
    std::vector<split_row> split_;
    double planned_ms_ = 0.0;
};

void compare_full_stage::bake_full(bake_context& ctx) {
    ctx.prog.begin("full bake");
    auto t0 = std::chrono::steady_clock::now();
    fsource_ = bake_source(ctx.src, ctx.full.source_size, ctx.qs.bake_k, ctx.ex);
    tf_.source = ms_since(t0);
    t0 = std::chrono::steady_clock::now();
    fchain_ = bake_chain(fsource_, ctx.full.specular, ctx.opt.ld_weight, ctx.ex);
    tf_.specular = ms_since(t0);
    t0 = std::chrono::steady_clock::now();
    fdiffuse_ = sh3_diffuse(fsource_, ctx.ex);
    tf_.diffuse = ms_since(t0);
    t0 = std::chrono::steady_clock::now();
    flut_ = ibl::make_dfg_lut_exact<bake_model>(std::uint32_t(ctx.full.dfg.size), std::uint32_t(ctx.full.dfg.channels),
                                                ctx.qs.dfg_nodes, ctx.ex);
    tf_.dfg = ms_since(t0);
    ctx.prog.end();
}

void compare_full_stage::bake_converged(bake_context& ctx) {
    ctx.prog.begin("converged products");
    const auto t0 = std::chrono::steady_clock::now();
    ibl::specular_plan cp = ctx.plan.specular;
    cp.virtual_base_size = ctx.opt.size;
    cp.trilinear = true;
    for (auto& l : cp.levels) {
        l.trilinear = true;
        l.size = std::max(1, ctx.opt.size >> l.level);
        if (l.level > 0) l.samples = 4096;
    }
    conv_.chain = bake_chain(fsource_, cp, ctx.opt.ld_weight, ctx.ex);
    for (const auto& p : scene_shading_points()) conv_.normals.push_back(p.n);
    conv_.e_brute = texel_sum_irradiance(fsource_, level_at_most(fsource_, 64), conv_.normals, ctx.ex);
    conv_.view = {&conv_.chain, ctx.set.policy, ctx.set.levels, ctx.plan.specular.first_level, nullptr, nullptr};
    converged_ms_ = ms_since(t0);
    ctx.prog.end();
}

void compare_full_stage::shade(const bake_context& ctx) {
    const std::vector<scene_shading_point> pts = scene_shading_points();
    const std::vector<scene_shading_material> mats = scene_shading_materials(ctx.scene);
    product_view planned = baked_view(ctx).split_sum(); // the plan's products, read as the full bake's are
    if (!diffuse_lit_) planned.diffuse = nullptr;
    const product_view full{&fchain_, ctx.set.policy, ctx.set.levels, 0, &*flut_, diffuse_lit_ ? &fdiffuse_ : nullptr};
    err_plan_ = compare_shading(mats, pts, planned, conv_, diffuse_lit_, ctx.scene.multiscatter);
    err_full_ = compare_shading(mats, pts, full, conv_, diffuse_lit_, ctx.scene.multiscatter);
}

void compare_full_stage::check_levels(bake_context& ctx) {
    ctx.prog.begin("specular levels vs reference");
    const dvec3 light = brightest_direction(fsource_, 0);
    const ibl::specular_plan& sp = ctx.plan.specular;
    const ibl::ld_weight w = ctx.opt.ld_weight; // the chains' weight
    for (std::size_t k = 0; k < sp.levels.size(); ++k) {
        const ibl::specular_level_plan& lp = sp.levels[k];
        if (lp.level == 0 || !lp.needed) continue;
        level_row lc{lp.level, lp.roughness};
        lc.expected = lp.expected_error, lc.samples = lp.samples, lc.trilinear = lp.trilinear;
        for (int which = 0; which < 2; ++which) {
            const ibl::cubemap<float>& c = which == 0 ? *ctx.chain : fchain_;
            const int lvl = which == 0 ? int(k) : lp.level, n = c.size(lvl);
            const std::vector<std::array<int, 3>> tex = check_texels(n, 6, light);
            std::vector<dvec3> ref(tex.size());
            ctx.ex(tex.size(), [&](std::size_t b, std::size_t e) {
                for (std::size_t i = b; i < e; ++i) {
                    const dvec3 d = ibl::cube_texel_direction<double>(tex[i][0], tex[i][1], tex[i][2], n);
                    ref[i] = ctx.src.analytic ? ibl::reference_ld_sky(ctx.src.sky, d, lp.roughness, 2048, 16, w)
                                              : ctx.src.visit([&](const auto& env) { return ibl::reference_ld(env, d, lp.roughness, 8192, w); });
                }
            });
            ibl::error_accumulator acc(1e-3), acc_conv(1e-3);
            for (std::size_t i = 0; i < tex.size(); ++i) {
                const dvec3 got(c.texel(tex[i][0], tex[i][1], tex[i][2], lvl));
                acc.add(got, ref[i]);
                acc_conv.add(got, dvec3(conv_.chain.radiance(ibl::cube_texel_direction<float>(tex[i][0], tex[i][1], tex[i][2], n), float(k))));
            }
            (which == 0 ? lc.nrmse_plan : lc.nrmse_full) = acc.finish().nrmse;
            (which == 0 ? lc.conv_plan : lc.conv_full) = acc_conv.finish().nrmse;
        }
        levels_.push_back(lc);
    }
    ctx.prog.end();
}

void compare_full_stage::check_split_sum(bake_context& ctx) {
    ctx.prog.begin("split sum vs reference");
    ibl::cube_env_distribution_options dopt;
    dopt.level = level_at_most(fsource_, 128);
    const ibl::cube_env_distribution dist(fsource_, dopt);
    const dvec3 up(0, 1, 0), side = glm::normalize(dvec3(1, 0, 1));
    const std::vector<std::pair<dvec3, dvec3>> views = {{up, up}, {up, glm::normalize(up + side)}, {side, glm::normalize(side + up)}};
    for (const auto& m : ctx.scene.materials) {
        const ibl::pbr_material<double> pm = scene_material(m.metallic, 0.5 * (m.roughness.front().lo + m.roughness.back().hi));
        const auto shader = ibl::pbr_shader<double>::from(pm, false);
        ibl::reference_material rm = ibl::make_reference_material(pm.base_color, pm.metallic, pm.roughness,
                                                                   ibl::diffuse_weighting::one_minus_fresnel_roughness);
        if (!diffuse_lit_) rm.diffuse_albedo = dvec3(0.0);
        ibl::radiance_reference_options ro;
        ro.samples = 1u << 14;
        split_row row{m.name, pm.roughness, 0.0, 0.0};
        for (const auto& view : views) {
            const dvec3 n = view.first, v = view.second; // named copies: clang 14 lambdas cannot capture bindings
            const ibl::radiance_estimate ref = ctx.src.visit(
                [&](const auto& env) { return ibl::reference_radiance<bake_model>(env, dist, n, v, rm, ro, ctx.ex); });
            ibl::ibl_sample<double> s = conv_.view.sample(n, v, pm.roughness);
            s.irradiance_over_pi = diffuse_lit_ ? texel_sum_irradiance(fsource_, level_at_most(fsource_, 64), {n}, ctx.ex)[0] / ibl::pi_v<double>
                                                : dvec3(0.0);
            const double ys = ibl::luminance(shader.ambient(std::clamp(glm::dot(n, v), 0.0, 1.0), s));
            const double yr = ibl::luminance(ref.value);
            const double rel = yr > 0 ? std::fabs(ys / yr - 1.0) : 0.0;
            row.mean_abs_rel += rel / double(views.size());
            row.max_abs_rel = std::max(row.max_abs_rel, rel);
        }
        split_.push_back(row);
    }
    ctx.prog.end();
}

std::vector<table_row> compare_full_stage::rows() const {
    return {{"full bake", "the full plan, timed", fmt("%.2fx the planned products' time", tf_.total() / planned_ms_), tf_.total(),
             fmt2("full vs converged: rel RMS %.4f, max %.4f", err_full_.rel_rms, err_full_.max_rel)},
            table_row{"converged products", "4096 spp trilinear, dfg_exact, brute-force E", std::to_string(err_plan_.points) + " points",
                      converged_ms_, fmt2("planned vs converged: rel RMS %.4f, max %.4f", err_plan_.rel_rms, err_plan_.max_rel)}
                .alarm(err_plan_.rel_rms, target_, "the scene plan misses its error target: raise the target or bake the full plan")};
}

std::vector<std::string> compare_full_stage::notes_after() const {
    std::vector<std::string> n;
    n.push_back("product error (ambient luminance vs converged products, " + std::to_string(err_plan_.points) + " points): planned " +
                fmt("rel RMS %.4f", err_plan_.rel_rms) + fmt(", full rel RMS %.4f", err_full_.rel_rms) +
                fmt("; target %.3g: ", target_) + (err_plan_.rel_rms <= target_ ? "within" : "NOT within"));
    n.push_back("specular levels (nrmse at the check texels) vs reference LD and vs converged (plan.hpp's table):");
    for (const auto& c : levels_) {
        char buf[256];
        std::snprintf(buf, sizeof buf, "  level %d r=%.2f  planned (%u %s) %.4f  full %.4f;  vs converged: planned %.4f (expected %.4f)  full %.4f",
                      c.level, c.roughness, c.samples, c.trilinear ? "tri" : "near", c.nrmse_plan, c.nrmse_full, c.conv_plan,
                      c.expected, c.conv_full);
        n.push_back(buf);
    }
    n.push_back("split-sum approximation vs MIS reference (converged products; no plan can change it):");
    for (const auto& s : split_) {
        char buf[200];
        std::snprintf(buf, sizeof buf, "  %-16s r=%.2f  mean |rel| %.1f%%, max |rel| %.1f%%", s.material.c_str(), s.roughness,
                      100.0 * s.mean_abs_rel, 100.0 * s.max_abs_rel);
        n.push_back(buf);
    }
    return n;
}

void compare_full_stage::report(json_writer& j) const {
    j.begin_object();
    j.key("full_measured_ms").begin_object();
    j.key("source").value(tf_.source).key("specular").value(tf_.specular).key("diffuse").value(tf_.diffuse);
    j.key("dfg").value(tf_.dfg).key("total").value(tf_.total());
    j.end_object();
    j.key("speedup").value(tf_.total() / planned_ms_);
    j.key("converged").value("levels read by the scene at full resolution with 4096 filtered-IS samples (trilinear reads), dfg_exact, "
                             "brute-force irradiance");
    j.key("converged_ms").value(converged_ms_);
    j.key("shading_points").value(err_plan_.points);
    j.key("planned_vs_converged").begin_object().key("rel_rms").value(err_plan_.rel_rms).key("max_rel").value(err_plan_.max_rel).end_object();
    j.key("full_vs_converged").begin_object().key("rel_rms").value(err_full_.rel_rms).key("max_rel").value(err_full_.max_rel).end_object();
    j.key("within_target").value(err_plan_.rel_rms <= target_);
    j.key("specular_levels_vs_reference").begin_array();
    for (const auto& c : levels_) {
        j.begin_object();
        j.key("virtual_level").value(c.level).key("roughness").value(c.roughness);
        j.key("nrmse_planned").value(c.nrmse_plan).key("nrmse_full").value(c.nrmse_full);
        j.key("nrmse_vs_converged_planned").value(c.conv_plan).key("nrmse_vs_converged_full").value(c.conv_full);
        j.key("expected_nrmse_vs_converged").value(c.expected);
        j.end_object();
    }
    j.end_array();
    j.key("split_sum_vs_reference").begin_array();
    for (const auto& s : split_) {
        j.begin_object();
        j.key("material").value(s.material).key("roughness").value(s.roughness);
        j.key("mean_abs_rel").value(s.mean_abs_rel).key("max_abs_rel").value(s.max_abs_rel);
        j.end_object();
    }
    j.end_array();
    j.end_object();
}

} // namespace

std::unique_ptr<stage> make_compare_full_stage() { return std::make_unique<compare_full_stage>(); }

} // namespace ibl_bake
