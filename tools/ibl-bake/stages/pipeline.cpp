// tools/ibl-bake/stages/pipeline.cpp — runs the stages in order and assembles the files, report.json and
// the printed table from what they return (pipeline.hpp; the stage interface: stage.hpp).

#include "stages/pipeline.hpp"

#include <algorithm>
#include <chrono>
#include <stdexcept>
#include <cstring>

#include <unistd.h>

#include "stages/output_stage.hpp"
#include "stages/stages.hpp"

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
    s.push_back(make_compression_stage());
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

/// A check stage that measures products against references (--checks none skips it): not the
/// preview (a product file) nor --compare-full (asked for by name).
bool reference_check(const stage& s) {
    return s.kind() == stage_kind::check && std::strcmp(s.key(), "preview") != 0 && std::strcmp(s.key(), "compare_full") != 0;
}

/// Runs every enabled stage; returns those that ran, in order.
std::vector<std::unique_ptr<stage>> run_stages(bake_context& ctx) {
    std::vector<std::unique_ptr<stage>> ran;
    for (auto& s : all_stages()) {
        if (!s->enabled(ctx) || (ctx.opt.checks == check_mode::none && reference_check(*s))) continue;
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
    j.key("ktx2_format").value(to_string(o.ktx2_format));
    j.key("prefilter").value(to_string(o.prefilter));
    j.key("checks").value(to_string(o.checks));
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

/// Time of every reference check (the product stages' own checks and the check stages').
double checks_ms(const std::vector<std::unique_ptr<stage>>& stages) {
    double t = 0.0;
    for (const auto& s : stages) t += s->check_ms();
    return t;
}

/// The stages' table rows, in order.
std::vector<table_row> all_rows(const std::vector<std::unique_ptr<stage>>& stages) {
    std::vector<table_row> rows;
    for (const auto& s : stages)
        for (auto& r : s->rows()) rows.push_back(std::move(r));
    return rows;
}

const char* checks_accuracy(check_mode mode) {
    if (mode == check_mode::none) return "no reference checks ran (--checks none): the products are written unchecked";
    if (mode == check_mode::full) return "the full references of the quality (docs/ibl-bake.md, quality table)";
    return "fast: a texel grid 3 smaller per side (at least 3), a quarter of the built-in sky's reference LD samples (maps "
           "and cubes are checked against the exact texel sum in both modes), an eighth of the split-sum reference samples "
           "(reference_rel_std_error gives that noise), the lookup check at the roughness midway between levels with the "
           "chosen lookup only and texel-sum references of 4 texels per alpha, the irradiance brute force over a level of "
           "face <= 64, the two-tap table's midpoint check without direct fits. The specular levels' rel_rmse is then "
           "measured on fewer texels; the other figures agree with full's within their reference's noise or 10-20% "
           "(docs/ibl-bake.md, \"Checks\")";
}

/// report.json's "checks": the mode, its time and share of the run, what it costs in accuracy,
/// the alarm thresholds and the alarming figures with what they mean.
void report_checks(json_writer& j, const bake_context& ctx, const std::vector<std::unique_ptr<stage>>& stages, double total_ms) {
    const double t = checks_ms(stages);
    j.key("checks").begin_object();
    j.key("mode").value(to_string(ctx.opt.checks));
    j.key("time_ms").value(t);
    j.key("share_of_run").value(total_ms > 0.0 ? t / total_ms : 0.0);
    j.key("stages_ms").begin_object();
    for (const auto& s : stages)
        if (s->check_ms() > 0.0) j.key(s->key()).value(s->check_ms());
    j.end_object();
    j.key("accuracy").value(checks_accuracy(ctx.opt.checks));
    j.key("alarm_thresholds").begin_object();
    j.key("relative").value(alarm_relative).key("absolute").value(alarm_absolute).key("quantisation").value(alarm_quantisation);
    j.key("rule").value("a figure is alarming above its threshold: relative errors (rel RMSE, mean or max |rel|) above "
                        "'relative', absolute errors of [0, 1] tables above 'absolute', the storage's max relative error "
                        "above 'quantisation' or any value clamped, a scene plan missing its error target");
    j.end_object();
    j.key("alarms").begin_array();
    for (const auto& r : all_rows(stages))
        if (!r.meaning.empty() && !r.detail) { // the compact table's alarms
            j.begin_object();
            j.key("product").value(r.product).key("figure").value(r.headline.empty() ? r.error : r.headline);
            j.key("meaning").value(r.meaning);
            j.end_object();
        }
    j.end_array();
    j.end_object();
}

/// report.json's "metrics": the definition of every metric name the rest of the file uses.
void report_metrics(json_writer& j, const std::string& body) {
    j.key("metrics").begin_object();
    for (const auto& [name, definition] : metric_definitions())
        if (body.find("\"" + name + "\":") != std::string::npos) j.key(name).value(definition);
    j.end_object();
}

std::string report_json(const bake_context& ctx, const std::vector<std::unique_ptr<stage>>& stages,
                        const std::vector<std::string>& files, double total_ms, const std::string* body = nullptr) {
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
    report_checks(j, ctx, stages, total_ms);
    if (body) report_metrics(j, *body); // the second pass: the metrics the first one used
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
    const std::string body = report_json(ctx, stages, names, total_ms);
    write_text(out.file("report.json"), report_json(ctx, stages, names, total_ms, &body));
    out.commit();
}

void print_report(std::FILE* out, const bake_context& ctx, const std::vector<std::unique_ptr<stage>>& stages,
                  std::size_t files, double total_ms) {
    const bool verbose = ctx.opt.verbose;
    const std::string head = "ibl-bake " + version_string() + ": " + ctx.src.name + " -> " + ctx.opt.out;
    // the sizes the plan bakes (a scene's are at most --size / --levels / --lut-size); level 0 = the mirror level
    const ibl::specular_plan& sp = ctx.plan.specular;
    const int stored = int(sp.levels.size());
    const std::string levels = ctx.scene_mode ? std::to_string(stored) + " levels (" + std::to_string(sp.first_level) + ".." +
                                                    std::to_string(sp.first_level + stored - 1) + " of 0.." +
                                                    std::to_string(sp.virtual_levels - 1) + ")"
                                              : std::to_string(stored) + " levels";
    char setup[240];
    std::snprintf(setup, sizeof setup, "%s: size %d, %s, LUT %d, quality %s, checks %s, %u threads",
                  ctx.scene_mode ? "scene plan" : "full bake", std::max(1, sp.virtual_base_size >> sp.first_level), levels.c_str(),
                  ctx.plan.dfg.size, ctx.qs.name, to_string(ctx.opt.checks), ctx.ex.threads());
    if (verbose) std::fprintf(out, "%s (%s)\n\n", head.c_str(), setup);
    else if (head.size() < compact_width) std::fprintf(out, "%s\n%s\n\n", head.c_str(), setup);
    else std::fprintf(out, "ibl-bake %s: %s\n  -> %s\n%s\n\n", version_string().c_str(), ctx.src.name.c_str(), ctx.opt.out.c_str(), setup);
    for (const auto& s : stages)
        for (const auto& line : s->notes_before()) std::fprintf(out, "%s\n", line.c_str());
    if (ctx.scene_mode) std::fprintf(out, "\n");
    const std::vector<table_row> rows = all_rows(stages);
    if (verbose) print_table(out, rows);
    else print_compact_table(out, rows);
    const product_times& t = ctx.measured;
    std::fprintf(out, "\n");
    if (verbose)
        std::fprintf(out, "products: source %.1f, specular %.1f, diffuse %.1f, dfg %.1f, lobe lut %.1f ms, total %.1f ms\n", t.source,
                     t.specular, t.diffuse, t.dfg, t.lobe, t.total());
    else
        print_wrapped(out, fmt("products %.1f ms: ", t.total()) + fmt("source %.1f, ", t.source) + fmt("specular %.1f, ", t.specular) +
                               fmt("diffuse %.1f, ", t.diffuse) + fmt("dfg %.1f, ", t.dfg) + fmt("lobe lut %.1f", t.lobe),
                      2);
    const double c = checks_ms(stages);
    if (ctx.opt.checks == check_mode::none)
        print_wrapped(out, "checks skipped (--checks none): no product was measured against a reference", 2);
    else
        print_wrapped(out, fmt("checks %.1f ms", c) + fmt(" = %.0f%% of the run (", 100.0 * c / std::max(total_ms, 1e-9)) +
                               to_string(ctx.opt.checks) + (ctx.opt.checks == check_mode::fast ? "; --checks full: the full references)" : ")"),
                      2);
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
    bake_context ctx{opt, check_settings_for(settings_for(opt.q), opt.checks), prog, ex};
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
