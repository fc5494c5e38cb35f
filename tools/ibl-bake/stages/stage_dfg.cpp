// tools/ibl-bake/stages/stage_dfg.cpp — the split-sum DFG table of the plan's size and channels by exact
// quadrature (ibl::make_dfg_lut_exact) in the table layout of --dfg-layout (ibl/runtime/lookup.hpp; the
// default puts texels in cbrt(n.v) and sqrt(r), edge-aligned): A, B and, with 3 channels, the
// multiscatter k = (1 - E)/E. Checks: a 16 x 16 grid of texels (fewer for a smaller table) against
// ibl::dfg_exact at the texels' own (n.v, r); and the lookup a shader makes (ibl::dfg_lookup,
// bilinear) at points between the texels: n.v at 0, 1 and 33 uniform plus 33 quadratic steps
// (dense near grazing) x 24 roughness values in [0.05, 1], against dfg_exact; the same for the
// table rounded to half floats (a 16-bit texture).

#include "stages/stages.hpp"

#include <algorithm>
#include <cmath>

#include <ibl/bake/dfg.hpp>
#include <ibl/bake/dfg_export.hpp>
#include <ibl/reference/lookup_error.hpp>

namespace ibl_bake {

namespace {

constexpr int check_grid = 16; ///< 16 x 16 checked texels (fewer if the table is smaller)

class dfg_stage final : public stage {
public:
    const char* key() const override { return "dfg"; }
    stage_kind kind() const override { return stage_kind::product; }
    const char* category() const override { return "dfg"; }
    bool enabled(const bake_context& ctx) const override { return ctx.plan.dfg.enabled && ctx.plan.dfg.size > 0; }
    double product_ms() const override { return ms_; }
    double check_ms() const override { return check_ms_; }

    void run(bake_context& ctx) override {
        nodes_ = ctx.qs.dfg_nodes;
        quality_ = ctx.qs.name;
        ctx.prog.begin("dfg lut");
        layout_ = ctx.opt.dfg_layout;
        filament_channels_ = ctx.opt.dfg_channels == dfg_channel_order::filament;
        ctx.lut = ibl::make_dfg_lut_exact<bake_model>(std::uint32_t(ctx.plan.dfg.size), layout_,
                                                      std::uint32_t(ctx.plan.dfg.channels), nodes_, ctx.ex);
        ms_ = ctx.prog.end();
        lut_ = &*ctx.lut;
        attrs_ = table_conventions(ctx, "dfg",
                                   std::string(filament_channels_ ? "R = B, G = A + B, B = k (specular = LD mix(R, G, F0))"
                                                                  : "R = A, G = B, B = k (specular = LD (F0 A + F90 B))") +
                                       "; EXR row 0 (top) is the smallest roughness",
                                   layout_, {{"ibl.model", lut_->model}, {"ibl.dfg_channels", filament_channels_ ? "B, A + B, k" : "A, B, k"}});
        checked_ = ctx.opt.checks != check_mode::none;
        if (!checked_) return;
        ctx.prog.begin("check dfg");
        check(ctx.ex);
        const ibl::dfg_error_grid grid = ibl::dfg_error_grid::dense(33, 24, 0.05);
        const std::vector<ibl::vec2<double>> exact = ibl::dfg_exact_grid<bake_model>(grid, ctx.ex);
        lookup_ = ibl::dfg_lookup_error(*lut_, grid, exact);
        lookup_half_ = ibl::dfg_lookup_error(ibl::quantize_half_lut(*lut_), grid, exact);
        check_ms_ = ctx.prog.end();
    }

    std::vector<table_row> rows() const override {
        const std::string cost = std::to_string(lut_->size) + "^2, " + std::to_string(nodes_.evaluations()) + " evals/texel";
        const std::string method = std::string("quadrature, ") + bake_model::name;
        if (!checked_) return {table_row{"dfg lut", method, cost, ms_, "not checked"}.compact("quadrature", "not checked")};
        const std::string layout = layout_.edge_aligned ? "remapped" : "uniform";
        return {table_row{"dfg lut", method, cost, ms_, fmt("max abs %.3g vs dfg_exact", max_abs_)}
                    .compact("quadrature", fmt("max abs %.3g at the texels", max_abs_))
                    .alarm(max_abs_, alarm_absolute, "the table's quadrature is off by > 0.01: --quality high takes more nodes"),
                table_row{"  dfg lookup", "bilinear, " + layout + " layout", std::to_string(lookup_.count) + " points, r >= 0.05", -1.0,
                          fmt2("max abs %.3g (half %.3g)", lookup_.max_abs, lookup_half_.max_abs) +
                              fmt2(" at n.v %.3g r %.3g", lookup_.worst_n_dot_v, lookup_.worst_roughness)}
                    .compact("bilinear, " + layout, fmt2("max abs %.3g at n.v %.3g", lookup_.max_abs, lookup_.worst_n_dot_v))
                    .alarm(lookup_.max_abs, alarm_absolute,
                           layout_.edge_aligned ? "bilinear reads between texels are off by > 0.01: raise --lut-size"
                                                : "texel centres miss n.v -> 0 (textbook table): --dfg-layout remapped fixes it")};
    }
    std::vector<file_out> files() const override;
    void report(json_writer& j) const override;

private:
    void check(pool_executor& ex) {
        const int n = int(lut_->size), gd = std::min(check_grid, n);
        std::vector<double> err(std::size_t(gd) * std::size_t(gd));
        ex(err.size(), [&](std::size_t b, std::size_t e) {
            for (std::size_t k = b; k < e; ++k) {
                const auto i = std::uint32_t((double(k % std::size_t(gd)) + 0.5) * n / gd);
                const auto j = std::uint32_t((double(k / std::size_t(gd)) + 0.5) * n / gd);
                const double nv = ibl::dfg_texel_value<double>(layout_.n_dot_v, i, std::uint32_t(n), layout_.edge_aligned);
                const double r = ibl::dfg_texel_value<double>(layout_.roughness, j, std::uint32_t(n), layout_.edge_aligned);
                const ibl::vec2<double> ref = ibl::dfg_exact<bake_model>(nv, r);
                err[k] = std::max(std::fabs(double(lut_->at(i, j, 0)) - ref.x), std::fabs(double(lut_->at(i, j, 1)) - ref.y));
            }
        });
        max_abs_ = *std::max_element(err.begin(), err.end());
        texels_checked_ = err.size();
    }

    const ibl::dfg_lut* lut_ = nullptr;
    ibl::dfg_lut_layout layout_{};
    bool filament_channels_ = false; ///< files hold (B, A + B, k): mix(dfg.x, dfg.y, f0) = F0 A + B
    /// The table as the files store it.
    ibl::dfg_lut file_lut() const {
        ibl::dfg_lut t = *lut_;
        if (filament_channels_)
            for (std::size_t k = 0; k + 1 < t.data.size(); k += t.channels) {
                const float a = t.data[k], b = t.data[k + 1];
                t.data[k] = b, t.data[k + 1] = a + b;
            }
        return t;
    }
    ibl::dfg_lookup_report lookup_, lookup_half_;
    std::vector<std::pair<std::string, std::string>> attrs_;
    ibl::dfg_quadrature_nodes nodes_{};
    std::string quality_;
    double ms_ = 0.0, check_ms_ = 0.0, max_abs_ = 0.0;
    std::size_t texels_checked_ = 0;
    bool checked_ = true;
};

std::vector<file_out> dfg_stage::files() const {
    return {{"dfg.exr",
             [this](const std::string& p) {
                 const ibl::dfg_lut t = file_lut();
                 image_rgb32f d(int(t.size), int(t.size));
                 for (std::uint32_t j = 0; j < t.size; ++j)
                     for (std::uint32_t i = 0; i < t.size; ++i)
                         for (std::uint32_t c = 0; c < t.channels && c < 3; ++c) d.texel(int(i), int(j))[c] = t.at(i, j, c);
                 write_exr(p, d, attrs_);
             }},
            {"dfg.hpp", [this](const std::string& p) {
                 write_text(p, ibl::dfg_lut_header(file_lut(), "dfg_lut", "ibl_baked",
                                                   std::string(bake_model::name) + ", exact quadrature (ibl-bake --quality " +
                                                       quality_ + ")" +
                                                       (filament_channels_ ? "; channels stored as (B, A + B, k): "
                                                                             "specular = LD mix(dfg.x, dfg.y, F0)"
                                                                           : ""),
                                                   layout_.edge_aligned ? "n.v = (i / (size - 1))^3, roughness = (j / (size - 1))^2 "
                                                                          "(edge-aligned; sample at ibl::dfg_lut_coord)"
                                                                        : ""));
             }}};
}

void dfg_stage::report(json_writer& j) const {
    j.begin_object();
    j.key("files").value("dfg.exr, dfg.hpp");
    j.key("model").value(std::string(bake_model::name) +
                         ": GGX NDF, height-correlated Smith masking-shadowing, Schlick Fresnel; "
                         "specular = LD (F0 A + F90 B); multiscatter k = (1 - E)/E, E = A + B (Turquin 2019)");
    j.key("method").value("deterministic quadrature (ibl::make_dfg_lut_exact)");
    j.key("cost").begin_object();
    j.key("size").value(lut_->size);
    j.key("channels").value(lut_->channels);
    j.key("nodes").begin_array().value(nodes_.full_y).value(nodes_.full_phi).value(nodes_.partial_y).value(nodes_.partial_phi).end_array();
    j.key("evaluations_per_texel").value(nodes_.evaluations());
    j.end_object();
    j.key("time_ms").value(ms_);
    j.key("layout").value(layout_.edge_aligned
                              ? "x: n.v = (i / (N - 1))^3, y: roughness = (j / (N - 1))^2 (edge-aligned; ibl::dfg_lut_layout::remapped()); EXR row 0 "
                                "(top) = roughness 0, roughness increases downwards; R = A, G = B, B = k (0 for a 2-channel table)"
                              : "x = n.v = (i + 0.5)/N, y = roughness = (j + 0.5)/N (texel centres); EXR row 0 (top) = "
                                "roughness 0.5/N, roughness increases downwards; R = A, G = B, B = k (0 for a 2-channel table)");
    if (!checked_) { // --checks none
        j.key("check").begin_object().key("ran").value(false).end_object();
        j.end_object();
        return;
    }
    j.key("check").begin_object();
    j.key("ran").value(checked_);
    j.key("reference").value("ibl::dfg_exact (default nodes, converged to 1e-6)");
    j.key("texels").value(texels_checked_);
    j.key("max_abs").value(max_abs_);
    j.key("time_ms").value(check_ms_);
    j.end_object();
    auto lookup_json = [&](const char* key, const ibl::dfg_lookup_report& r) {
        j.key(key).begin_object();
        j.key("points").value(r.count).key("max_abs").value(r.max_abs).key("max_abs_a").value(r.max_abs_a);
        j.key("max_abs_b").value(r.max_abs_b).key("rms").value(r.rms);
        j.key("worst_n_dot_v").value(r.worst_n_dot_v).key("worst_roughness").value(r.worst_roughness);
        j.end_object();
    };
    j.key("lookup_check").begin_object();
    j.key("method").value("ibl::dfg_lookup (bilinear, the table's layout) against ibl::dfg_exact at n.v in {k/32, (k/32)^2}, "
                          "r in [0.05, 1] (24 values)");
    lookup_json("float", lookup_);
    lookup_json("half", lookup_half_);
    j.end_object();
    j.end_object();
}

} // namespace

std::unique_ptr<stage> make_dfg_stage() { return std::make_unique<dfg_stage>(); }

} // namespace ibl_bake
