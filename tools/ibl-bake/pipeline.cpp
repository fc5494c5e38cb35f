// tools/ibl-bake/pipeline.cpp — runs the stages in order and assembles the files, report.json and
// the printed table from what they return (pipeline.hpp).

#include "pipeline.hpp"

#include <algorithm>
#include <chrono>
#include <stdexcept>
#include <cstring>

#include <unistd.h>

#include "output_stage.hpp"
#include "stages.hpp"

namespace ibl_bake {

namespace {

/// The fixed order of the stages (stages.hpp).
std::vector<std::unique_ptr<stage>> all_stages() {
    std::vector<std::unique_ptr<stage>> s;
    s.push_back(make_plan_stage());
    s.push_back(make_source_stage());
    s.push_back(make_sun_stage());
    s.push_back(make_specular_stage());
    s.push_back(make_sh_stage());
    s.push_back(make_irradiance_stage());
    s.push_back(make_dfg_stage());
    s.push_back(make_lobe_lut_stage());
    s.push_back(make_lobe_taps_stage());
    s.push_back(make_sheen_stage());
    s.push_back(make_lookup_stage());
    s.push_back(make_split_sum_stage());
    s.push_back(make_preview_stage());
    s.push_back(make_target_check_stage());
    s.push_back(make_compare_full_stage());
    return s;
}

void add_time(product_times& t, const stage& s) {
    const char* c = s.category();
    double* slot = std::strcmp(c, "source") == 0     ? &t.source
                   : std::strcmp(c, "specular") == 0 ? &t.specular
                   : std::strcmp(c, "diffuse") == 0  ? &t.diffuse
                   : std::strcmp(c, "dfg") == 0      ? &t.dfg
                   : std::strcmp(c, "lobe_lut") == 0 ? &t.lobe
                                                     : nullptr;
    if (slot) *slot += s.product_ms();
}

/// Runs every enabled stage; returns those that ran, in order.
std::vector<std::unique_ptr<stage>> run_stages(bake_context& ctx) {
    std::vector<std::unique_ptr<stage>> ran;
    for (auto& s : all_stages()) {
        if (!s->enabled(ctx)) continue;
        s->run(ctx);
        if (s->kind() == stage_kind::product) add_time(ctx.measured, *s);
        ran.push_back(std::move(s));
    }
    return ran;
}

void report_options(json_writer& j, const bake_context& ctx) {
    const bake_options& o = ctx.opt;
    j.key("options").begin_object();
    j.key("input").value(o.input.empty() ? std::string("(built-in sky)") : o.input);
    j.key("scene").value(o.scene.empty() ? std::string("(none: full bake)") : o.scene);
    j.key("compare_full").value(o.compare_full);
    j.key("size").value(o.size);
    j.key("lut_size").value(o.lut_size);
    j.key("levels").value(ctx.set.levels);
    j.key("quality").value(ctx.qs.name);
    j.key("threads").value(ctx.ex.threads());
    j.key("ktx2_format").value(o.ktx2_f32 ? "rgba32f" : "rgba16f");
    j.end_object();
    // the sizes baked (a scene's plan may use less than --size and --lut-size); level 0 = the mirror level
    const ibl::specular_plan& sp = ctx.plan.specular;
    j.key("baked_sizes").begin_object();
    j.key("face_size").value(std::max(1, sp.virtual_base_size >> sp.first_level));
    j.key("virtual_base_size").value(sp.virtual_base_size);
    j.key("stored_levels").value(int(sp.levels.size()));
    j.key("first_level").value(sp.first_level);
    j.key("last_level").value(sp.first_level + int(sp.levels.size()) - 1);
    j.key("virtual_levels").value(sp.virtual_levels);
    j.key("source_size").value(ctx.plan.source_size);
    j.key("lut_size").value(ctx.plan.dfg.size);
    j.end_object();
}

std::string report_json(const bake_context& ctx, const std::vector<std::unique_ptr<stage>>& stages,
                        const std::vector<std::string>& files, double total_ms) {
    json_writer j;
    j.begin_object();
    j.key("tool").value("ibl-bake");
    j.key("version").value(version_string());
    j.key("mode").value(ctx.scene_mode ? "scene" : "full");
    report_options(j, ctx);
    for (const auto& s : stages) {
        j.key(s->key());
        s->report(j);
    }
    const product_times& t = ctx.measured;
    j.key("measured_ms").begin_object();
    j.key("source").value(t.source).key("specular").value(t.specular).key("diffuse").value(t.diffuse);
    j.key("dfg").value(t.dfg).key("lobe_lut").value(t.lobe).key("total").value(t.total());
    j.end_object();
    j.key("files").begin_array();
    for (const auto& f : files) j.value(f);
    j.value("report.json");
    j.end_array();
    j.key("total_time_ms").value(total_ms);
    j.end_object();
    return j.str() + "\n";
}

/// Writes every stage's files and report.json into the staging folder, then commits.
void write_outputs(const bake_context& ctx, const std::vector<std::unique_ptr<stage>>& stages,
                   std::vector<std::string>& names, std::chrono::steady_clock::time_point t_total) {
    ctx.prog.begin("write files");
    output_stage out(ctx.opt.out);
    for (const auto& s : stages)
        for (const file_out& f : s->files()) {
            names.push_back(f.name);
            f.write(out.file(f.name));
        }
    ctx.prog.end();
    const double total_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t_total).count();
    write_text(out.file("report.json"), report_json(ctx, stages, names, total_ms));
    out.commit();
}

void print_report(std::FILE* out, const bake_context& ctx, const std::vector<std::unique_ptr<stage>>& stages,
                  std::size_t files, double total_ms) {
    // the sizes the plan bakes (a scene's are at most --size / --levels / --lut-size); level 0 = the mirror level
    const ibl::specular_plan& sp = ctx.plan.specular;
    const int stored = int(sp.levels.size());
    const std::string levels = ctx.scene_mode ? std::to_string(stored) + " levels (" + std::to_string(sp.first_level) + ".." +
                                                    std::to_string(sp.first_level + stored - 1) + " of 0.." +
                                                    std::to_string(sp.virtual_levels - 1) + ")"
                                              : std::to_string(stored) + " levels";
    std::fprintf(out, "ibl-bake %s: %s -> %s (%s: size %d, %s, LUT %d, quality %s, %u threads)\n\n", version_string().c_str(),
                 ctx.src.name.c_str(), ctx.opt.out.c_str(), ctx.scene_mode ? "scene plan" : "full bake",
                 std::max(1, sp.virtual_base_size >> sp.first_level), levels.c_str(), ctx.plan.dfg.size, ctx.qs.name,
                 ctx.ex.threads());
    std::vector<table_row> rows;
    for (const auto& s : stages) {
        for (const auto& line : s->notes_before()) std::fprintf(out, "%s\n", line.c_str());
        for (auto& r : s->rows()) rows.push_back(std::move(r));
    }
    if (ctx.scene_mode) std::fprintf(out, "\n");
    print_table(out, rows);
    const product_times& t = ctx.measured;
    std::fprintf(out, "\nproducts: source %.1f, specular %.1f, diffuse %.1f, dfg %.1f, lobe lut %.1f ms, total %.1f ms\n", t.source,
                 t.specular, t.diffuse, t.dfg, t.lobe, t.total());
    for (const auto& s : stages)
        for (const auto& line : s->notes_after()) std::fprintf(out, "%s\n", line.c_str());
    std::fprintf(out, "\ntotal %.0f ms; %zu files in %s\n", total_ms, files + 1, ctx.opt.out.c_str());
}

} // namespace

void run_bake(const bake_options& opt, std::FILE* out) {
    const auto t_total = std::chrono::steady_clock::now();
    progress prog(!opt.quiet, ::isatty(2) != 0);
    pool_executor ex(opt.threads, &prog);
    check_output_dir(opt.out);
    bake_context ctx{opt, settings_for(opt.q), prog, ex};
    const std::vector<std::unique_ptr<stage>> stages = run_stages(ctx);
    if (opt.strict && !ctx.target_misses.empty()) { // nothing is staged yet: DIR stays as it was
        std::string what;
        for (const auto& m : ctx.target_misses) what += (what.empty() ? "" : "; ") + m;
        throw std::runtime_error("--strict: " + what + " (nothing written)");
    }
    for (const auto& m : ctx.target_misses) std::fprintf(stderr, "ibl-bake: warning: %s\n", m.c_str());
    std::vector<std::string> names;
    write_outputs(ctx, stages, names, t_total);
    const double total_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t_total).count();
    print_report(out, ctx, stages, names.size(), total_ms);
}

} // namespace ibl_bake
