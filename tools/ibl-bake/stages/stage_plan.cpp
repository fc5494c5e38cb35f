// tools/ibl-bake/stages/stage_plan.cpp — the plan: which products, levels, sizes and samples are baked.
//
// Full bake: ibl::full_bake_plan over the tool's chain (--size, --levels, linear policy) with the
// quality's samples, doubled per coarser level (ibl::doubling_prefilter_samples: level l >= 1
// takes samples * 2^(l-1), at most 16384; the library's default schedule from 512).
// Level l has 4^-l of the base's texels, so the whole chain costs less than twice level 1, while
// the rough levels, where a sun is smeared over many texels and shows as mottle, get many more
// samples. --scene: ibl::make_bake_plan of the scene over the same chain; the report says what the
// plan leaves out and what it should save by the plan's cost model.

#include "stages/stages.hpp"

#include <algorithm>

#include <ibl/bake/prefilter.hpp>

#include "io/scene_reader.hpp"

namespace ibl_bake {

namespace {

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
        j.key("samples").value(l.samples).key("trilinear").value(l.trilinear).key("needed").value(l.needed);
        j.key("expected_nrmse").value(l.expected_error);
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

/// The tool's full bake as a plan.
ibl::bake_plan tool_full_plan(const ibl::plan_settings& set, const quality_settings& qs, int lut_size) {
    ibl::bake_plan p = ibl::full_bake_plan(set, qs.prefilter_samples, qs.trilinear, lut_size);
    for (std::size_t l = 1; l < p.specular.levels.size(); ++l)
        p.specular.levels[l].samples = ibl::doubling_prefilter_samples(qs.prefilter_samples, int(l));
    return p;
}

class plan_stage final : public stage {
public:
    const char* key() const override { return "plan"; }
    stage_kind kind() const override { return stage_kind::setup; }
    bool enabled(const bake_context&) const override { return true; }

    void run(bake_context& ctx) override {
        ctx.set.levels = ctx.opt.levels > 0 ? ctx.opt.levels : auto_levels(ctx.opt.size);
        ctx.set.max_base_size = ctx.opt.size;
        ctx.set.policy = ctx.opt.policy;
        ctx.full = tool_full_plan(ctx.set, ctx.qs, ctx.opt.lut_size);
        ctx.scene_mode = !ctx.opt.scene.empty();
        if (ctx.scene_mode) {
            ctx.scene = read_scene(ctx.opt.scene);
            try {
                ctx.plan = ibl::make_bake_plan(ctx.scene, ctx.set);
            } catch (const std::invalid_argument& e) {
                throw scene_error(ctx.opt.scene + ": " + e.what());
            }
            omitted_ = ibl::left_out(ctx.plan, ctx.full);
        } else {
            ctx.plan = ctx.full;
        }
        est_ = ibl::estimate_cost(ctx.plan, ctx.qs.bake_k);
        est_full_ = ibl::estimate_cost(ctx.full, ctx.qs.bake_k);
        scene_mode_ = ctx.scene_mode;
        plan_ = ctx.plan;
        full_ = ctx.full;
        scene_file_ = ctx.opt.scene;
        scene_name_ = ctx.scene.name;
        levels_ = ctx.set.levels;
        specular_lookup_ = ctx.opt.specular_lookup;
        sheen_ = ctx.opt.sheen;
        policy_ = ctx.opt.policy;
        preset_ = ctx.opt.preset;
        dfg_channels_ = ctx.opt.dfg_channels;
        mirror_ = ctx.opt.mirror;
        runtime_diffuse_ = ctx.plan.diffuse.kind == ibl::diffuse_product::irradiance_map || (!ctx.scene_mode && ctx.opt.irradiance_size > 0)
                               ? "irradiance_map"
                               : diffuse_name(ctx.plan.diffuse.kind);
        dfg_layout_ = ctx.opt.dfg_layout;
        runtime_ = runtime_model_of(ctx.opt, ctx.plan);
    }

    std::vector<table_row> rows() const override { return {}; }
    std::vector<std::string> notes_before() const override;
    void report(json_writer& j) const override;

    const ibl::plan_cost& estimate() const { return est_; }
    const ibl::plan_cost& estimate_full() const { return est_full_; }

private:
    bool scene_mode_ = false;
    ibl::bake_plan plan_, full_;
    ibl::plan_cost est_, est_full_;
    std::vector<std::string> omitted_;
    std::string scene_file_, scene_name_, runtime_diffuse_;
    ibl::specular_lookup_desc specular_lookup_{};
    ibl::dfg_lut_layout dfg_layout_{};
    runtime_model runtime_;
    int levels_ = 1;
    bool sheen_ = false, mirror_ = false;
    ibl::roughness_mip_policy policy_{};
    bake_preset preset_ = bake_preset::standard;
    dfg_channel_order dfg_channels_ = dfg_channel_order::ab;
};

std::vector<std::string> plan_stage::notes_before() const {
    if (!scene_mode_) return {};
    std::vector<std::string> n;
    const ibl::specular_plan& sp = plan_.specular;
    n.push_back("scene " + scene_file_ + " (" + scene_name_ + "), target " + fmt("%.3g", plan_.error_target) +
                fmt(" (diffuse %.3g)", plan_.diffuse_error_target));
    n.push_back("specular: virtual chain " + std::to_string(sp.virtual_levels) + " levels, base " +
                std::to_string(sp.virtual_base_size) + "; stored levels " + std::to_string(sp.first_level) + ".." +
                std::to_string(sp.first_level + int(sp.levels.size()) - 1) + " (lod = virtual lod - " +
                std::to_string(sp.first_level) + ")");
    for (const auto& l : sp.levels) {
        char buf[160];
        std::snprintf(buf, sizeof buf, "  level %d  %4dx%-4d r=%.2f  %5u spp%s", l.level, l.size, l.size, l.roughness,
                      l.samples, l.level == 0 ? " (source copy)" : l.needed ? "" : " (contiguity filler)");
        n.push_back(buf);
    }
    std::string d = std::string("diffuse:  ") + diffuse_name(plan_.diffuse.kind);
    if (plan_.diffuse.kind == ibl::diffuse_product::sh) d += ", " + std::to_string(plan_.diffuse.sh_bands) + " bands";
    n.push_back(d);
    n.push_back("dfg:      " + std::to_string(plan_.dfg.size) + "^2, " + std::to_string(plan_.dfg.channels) + " channels");
    n.push_back("left out:");
    for (const auto& s : omitted_) n.push_back("  - " + s);
    for (const auto& s : plan_.warnings) n.push_back("warning: " + s);
    n.push_back(fmt("estimated time saved by the plan's cost model: %.0f%%", 100.0 * (1.0 - est_.total_ms() / est_full_.total_ms())));
    return n;
}

void plan_stage::report(json_writer& j) const {
    j.begin_object();
    j.key("name").value(plan_.scene);
    if (scene_mode_) {
        j.key("scene").value(scene_file_);
        j.key("scene_name").value(scene_name_);
        j.key("error_target").value(plan_.error_target);
        j.key("diffuse_error_target").value(plan_.diffuse_error_target);
    }
    j.key("runtime_lookup").value(std::string(policy_.mapping == ibl::roughness_mapping::filament ? "lod = r (2 - r) * " : "lod = r * ") + std::to_string(levels_ - 1) +
                                  " - " + std::to_string(plan_.specular.first_level) +
                                  " (the policy over the virtual chain, minus the first stored level), clamped to the stored levels");
    j.key("runtime").begin_object(); // what a loader (and ibl-bake --lookup) needs
    j.key("policy").value(to_string(policy_));
    j.key("preset").value(to_string(preset_));
    j.key("dfg_channels_layout").value(dfg_channels_ == dfg_channel_order::filament ? "B, A + B, k (mix(dfg.x, dfg.y, f0))" : "A, B, k");
    j.key("mirrored").value(mirror_);
    j.key("virtual_levels").value(plan_.specular.virtual_levels);
    j.key("first_level").value(plan_.specular.first_level);
    j.key("stored_levels").value(int(plan_.specular.levels.size()));
    j.key("diffuse").value(runtime_diffuse_); // the product the runtime shades with (sh.json may exist beside a map)
    j.key("sh_bands").value(plan_.diffuse.sh_bands);
    j.key("dfg_size").value(plan_.dfg.size);
    j.key("dfg_channels").value(plan_.dfg.channels);
    j.key("sheen").value(sheen_);
    json_lookup_conventions(j, specular_lookup_, dfg_layout_, runtime_);
    j.end_object();
    j.key("products");
    plan_json(j, plan_, est_);
    if (scene_mode_) {
        j.key("full_plan");
        plan_json(j, full_, est_full_);
        j.key("left_out").begin_array();
        for (const auto& s : omitted_) j.value(s);
        j.end_array();
        j.key("warnings").begin_array();
        for (const auto& s : plan_.warnings) j.value(s);
        j.end_array();
        j.key("estimated_time_saved").value(1.0 - est_.total_ms() / est_full_.total_ms());
    }
    j.end_object();
}

} // namespace

std::unique_ptr<stage> make_plan_stage() { return std::make_unique<plan_stage>(); }

} // namespace ibl_bake
