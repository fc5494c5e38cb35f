// tools/ibl-bake/stages/stage_lobe_taps.cpp — the two-tap table of the runtime model taps2 (--runtime
// taps2; ibl/runtime/specular_models.hpp specular_lobe_taps, bake/lobe_fit.hpp): per (n.v, r) the DFG terms
// A, B and the two chain kernels (angle from n towards R, roughness, weight) whose mixture is
// closest to the specular lobe in L1 (ibl::make_lobe_taps_lut, taps = 2, the chain's weight), in
// the DFG table's layout at lobe_lut_size_for(DFG size) texels per side, each texel fitted on its
// own with fit_options() (the quality docs/runtime.md measures).
// Checks: (A, B) against the DFG table read (ibl::dfg_lookup) at the table's texels; at the
// midpoints of every second cell per axis, the L1 distance to the lobe of the taps read
// bilinearly (what ibl::specular_lobe_taps reads) against that of a direct fit there (what the
// table's interpolation costs).
// Files (the GLSL storage split, ibl_common.glsl "Taps LUT"; rows as dfg.exr: row 0 = the
// smallest roughness): lobe_taps_a.exr (RGBA float32: A, B, angle0 / acos(n.v), roughness0),
// lobe_taps_b.exr (RGBA float32: weight0, angle1 / acos(n.v), roughness1, weight1) and
// lobe_taps.hpp (all 8 channels as a C header, read by the viewer).

#include "stages/stages.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <ibl/bake/lobe_fit.hpp>
#include <ibl/runtime/specular_models.hpp>

namespace ibl_bake {

namespace {

constexpr std::uint32_t taps_channels = 8;
constexpr std::uint32_t check_nodes = 32; ///< nodes^2 lobe points of the midpoint check's L1 distances

/// The fit of every texel: two taps, 32^2 lobe points, 150 Nelder-Mead iterations per parameter.
ibl::lobe_fit_options fit_options() {
    ibl::lobe_fit_options o;
    o.taps = 2;
    o.nodes = 32;
    o.iterations = 150;
    return o;
}

/// L1 distances at the midpoints: of the table's taps, of a direct fit.
struct midpoint_l1 {
    double table_mean = 0.0, fit_mean = 0.0;
    double excess_max = 0.0, worst_n_dot_v = 0.0, worst_roughness = 0.0;
};

/// Channels [first, first + 4) of every texel: one RGBA image of the GLSL storage split.
image_rgba32f taps_image(const ibl::lobe_taps_lut& t, std::uint32_t first) {
    image_rgba32f img{int(t.size), int(t.size), {}};
    img.rgba.reserve(std::size_t(t.size) * t.size * 4);
    for (std::size_t k = 0; k < std::size_t(t.size) * t.size; ++k)
        for (std::uint32_t c = 0; c < 4; ++c) img.rgba.push_back(t.data[k * t.channels + first + c]);
    return img;
}

class lobe_taps_stage final : public stage {
public:
    const char* key() const override { return "lobe_taps"; }
    stage_kind kind() const override { return stage_kind::product; }
    const char* category() const override { return "lobe_lut"; }
    bool enabled(const bake_context& ctx) const override {
        return ctx.lut && ctx.chain && runtime_model_of(ctx.opt, ctx.plan).kind == runtime_choice::taps2;
    }
    double product_ms() const override { return ms_; }
    double check_ms() const override { return check_ms_; }

    void run(bake_context& ctx) override {
        layout_ = ctx.opt.dfg_layout;
        weight_name_ = to_string(ctx.opt.ld_weight);
        weight_ = ctx.opt.ld_weight;
        const auto size = std::uint32_t(lobe_lut_size_for(ctx.plan.dfg.size));
        ctx.prog.begin("lobe taps");
        ctx.taps = ibl::make_lobe_taps_lut<bake_model>(size, layout_, weight_, fit_options(), ctx.ex);
        ms_ = ctx.prog.end();
        lut_ = &*ctx.taps;
        attrs_ = table_conventions(ctx, "lobe_taps",
                                   "lobe_taps_a = (A, B, a_0, r_0), lobe_taps_b = (w_0, a_1, r_1, w_1): specular = (F0 A + "
                                   "F90 B) sum_k w_k LD(cos(a_k acos(n.v)) n + sin(...) t, r_k) / sum_k w_k "
                                   "(ibl_specular_lobe_taps2)",
                                   layout_, {{"ibl.ld_weight", weight_name_}});
        checks_ = ctx.opt.checks;
        if (checks_ == check_mode::none) return;
        ctx.prog.begin("check lobe taps");
        ab_max_abs_ = ab_vs_dfg(lut_->data, lut_->size, lut_->channels, layout_, *ctx.lut);
        check_midpoints(ctx.ex, checks_ == check_mode::full);
        check_ms_ = ctx.prog.end();
    }

    std::vector<table_row> rows() const override {
        const ibl::lobe_fit_options o = fit_options();
        const std::string method = std::string("L1 fit of two kernels, ") + bake_model::name + ", chain weight " + weight_name_;
        const std::string cost = std::to_string(lut_->size) + "^2, " + std::to_string(o.nodes) + "^2 points/texel";
        const std::string fit = fmt2("fit L1 mean %.3g, max %.3g", lut_->mean_l1, lut_->max_l1);
        if (checks_ == check_mode::none) return {table_row{"lobe taps", method, cost, ms_, fit}.compact("L1 fit, two kernels", fmt("fit L1 mean %.3g", lut_->mean_l1))};
        const bool fits = checks_ == check_mode::full;
        return {table_row{"lobe taps", method, cost, ms_,
                          fit + fmt("; A,B vs dfg max abs %.3g", ab_max_abs_) + fmt("; midpoint L1 table %.3g", l1_.table_mean) +
                              (fits ? fmt(", direct fit %.3g", l1_.fit_mean) : std::string())}
                    .compact("L1 fit, two kernels", fmt("midpoint L1 %.3g", l1_.table_mean) +
                                                        (fits ? fmt(" (direct fit %.3g)", l1_.fit_mean) : std::string()))};
    }
    std::vector<file_out> files() const override;
    void report(json_writer& j) const override;

private:
    void check_midpoints(pool_executor& ex, bool fits);
    void report_check(json_writer& j) const;

    const ibl::lobe_taps_lut* lut_ = nullptr;
    check_mode checks_ = check_mode::fast;
    ibl::dfg_lut_layout layout_{};
    std::vector<std::pair<std::string, std::string>> attrs_;
    ibl::ld_weight weight_ = ibl::ld_weight::g1;
    std::string weight_name_;
    double ms_ = 0.0, check_ms_ = 0.0, ab_max_abs_ = 0.0;
    std::size_t cells_ = 0;
    midpoint_l1 l1_;
};

/// The taps of a bilinear read of the table's channels at n.v (angles in radians, weights normalised).
std::array<ibl::lobe_tap, ibl::lobe_max_taps> taps_of(const std::array<float, taps_channels>& p, double n_dot_v) {
    std::array<ibl::lobe_tap, ibl::lobe_max_taps> t{};
    const double ws = double(std::max(p[4], 0.0f)) + double(std::max(p[7], 0.0f));
    for (int k = 0; k < 2; ++k) {
        const double w = std::max(double(p[std::size_t(4 + 3 * k)]), 0.0);
        t[std::size_t(k)] = {ibl::lobe_tap_angle(double(p[std::size_t(2 + 3 * k)]), n_dot_v), double(p[std::size_t(3 + 3 * k)]),
                             ws > 0.0 ? w / ws : 0.5};
    }
    return t;
}

/// fits: also a direct fit at each midpoint (--checks full; most of the check's time).
void lobe_taps_stage::check_midpoints(pool_executor& ex, bool fits) {
    const std::uint32_t n = lut_->size;
    std::vector<std::array<double, 4>> pts; // n.v, r, L1 of the table's taps, of a direct fit
    for (const auto& m : fit_check_midpoints(n, layout_)) pts.push_back({m[0], m[1], 0.0, 0.0});
    product_view pv;
    pv.taps = lut_;
    pv.dfg_layout = layout_;
    const ibl::lobe_fit_options o = fit_options();
    ex(pts.size(), [&](std::size_t b, std::size_t e) {
        for (std::size_t k = b; k < e; ++k) {
            const double nv = pts[k][0], r = pts[k][1];
            const ibl::detail::lobe_points lp = ibl::detail::make_lobe_points<bake_model>(nv, r, check_nodes);
            pts[k][2] = ibl::detail::mixture_l1(lp, taps_of(pv.taps_params(nv, r), nv), 2, weight_, {});
        }
    });
    if (fits)
        ex(pts.size(), [&](std::size_t b, std::size_t e) {
            for (std::size_t k = b; k < e; ++k) {
                const double nv = pts[k][0], r = pts[k][1];
                const ibl::detail::lobe_points lp = ibl::detail::make_lobe_points<bake_model>(nv, r, check_nodes);
                const ibl::lobe_mixture f = ibl::fit_specular_lobe<bake_model>(nv, r, weight_, o);
                pts[k][3] = ibl::detail::mixture_l1(lp, f.taps, 2, weight_, {});
            }
        });
    for (const auto& p : pts) {
        l1_.table_mean += p[2] / double(pts.size());
        l1_.fit_mean += p[3] / double(pts.size());
        if (fits && p[2] - p[3] > l1_.excess_max) l1_.excess_max = p[2] - p[3], l1_.worst_n_dot_v = p[0], l1_.worst_roughness = p[1];
    }
    cells_ = pts.size();
}

std::vector<file_out> lobe_taps_stage::files() const {
    const std::string rule = layout_.edge_aligned ? "n.v = (i / (size - 1))^3, roughness = (j / (size - 1))^2 (edge-aligned; "
                                                    "sample at ibl::dfg_lut_coord)"
                                                  : "n.v = (i + 0.5) / size, roughness = (j + 0.5) / size";
    return {{"lobe_taps_a.exr", [this](const std::string& p) { write_exr_rgba(p, taps_image(*lut_, 0), attrs_); }},
            {"lobe_taps_b.exr", [this](const std::string& p) { write_exr_rgba(p, taps_image(*lut_, 4), attrs_); }},
            {"lobe_taps.hpp", [this, rule](const std::string& p) {
                 write_text(p, c_table_header("lobe_taps",
                                              std::string("the two-tap table of ibl/runtime/specular_models.hpp specular_lobe_taps (") +
                                                  bake_model::name + ", chain weight " + weight_name_ + ")",
                                              lut_->size, 8,
                                              "A, B, angle0 / acos(n.v), roughness0, weight0, angle1 / acos(n.v), roughness1, weight1",
                                              rule, lut_->data));
             }}};
}

void lobe_taps_stage::report(json_writer& j) const {
    const ibl::lobe_fit_options o = fit_options();
    j.begin_object();
    j.key("files").value("lobe_taps_a.exr, lobe_taps_b.exr, lobe_taps.hpp");
    j.key("size").value(lut_->size);
    j.key("layout").value(std::string("the DFG table's (report dfg.layout; ") +
                          (layout_.edge_aligned ? "edge-aligned cbrt(n.v) x sqrt(r)" : "texel centres, uniform") +
                          "); EXR row 0 (top) = the smallest roughness");
    j.key("weight").value(weight_name_);
    j.key("taps").value(lut_->taps);
    j.key("channels").value("A, B, then per tap (ascending angle) angle / acos(n.v) (from n towards R: 1 = at R), roughness, weight; "
                            "lobe_taps_a.exr RGBA = channels 0..3 (A, B, angle0, roughness0), lobe_taps_b.exr RGBA = "
                            "channels 4..7 (weight0, angle1, roughness1, weight1); the mirror row r = 0 holds one tap at R "
                            "of roughness 0 (weight1 = 0)");
    j.key("method").value("ibl::make_lobe_taps_lut: A, B by ibl::make_dfg_lut_exact; the two chain kernels closest to the "
                          "normalised specular lobe in L1 (ibl::fit_specular_lobe, " + std::to_string(o.nodes) + "^2 lobe "
                          "points, Nelder-Mead of " + std::to_string(o.iterations) + " iterations per parameter from the "
                          "one-tap fit split in two), every texel on its own");
    j.key("nodes").value(o.nodes).key("iterations").value(o.iterations);
    j.key("time_ms").value(ms_);
    j.key("fit").begin_object();
    j.key("mean_l1").value(lut_->mean_l1).key("max_l1").value(lut_->max_l1);
    j.key("method").value("L1 distance of each texel's fit to the lobe (2 = disjoint), over the texels with r >= 0.05 "
                          "and A + B > 0 (lobe_taps_lut::mean_l1, max_l1)");
    j.end_object();
    report_check(j);
    j.end_object();
}

void lobe_taps_stage::report_check(json_writer& j) const {
    j.key("check").begin_object();
    j.key("ran").value(checks_ != check_mode::none);
    if (checks_ == check_mode::none) { // --checks none
        j.end_object();
        return;
    }
    j.key("direct_fits").value(checks_ == check_mode::full);
    j.key("ab_vs_dfg_max_abs").value(ab_max_abs_);
    j.key("midpoints").value(cells_);
    j.key("l1").begin_object();
    j.key("table_mean").value(l1_.table_mean);
    if (checks_ == check_mode::full) { // --checks fast leaves out the direct fits
        j.key("direct_fit_mean").value(l1_.fit_mean);
        j.key("excess_max").value(l1_.excess_max).key("worst_n_dot_v").value(l1_.worst_n_dot_v);
        j.key("worst_roughness").value(l1_.worst_roughness);
    }
    j.end_object();
    j.key("method").value("A, B against ibl::dfg_lookup of the DFG table at the table's texels; at the midpoints of every "
                          "second cell per axis (r >= 0.05) the L1 distance to the lobe (" + std::to_string(check_nodes) +
                          "^2 points; 2 = disjoint) of the taps read bilinearly (as ibl::specular_lobe_taps reads them) "
                          "and of a direct fit there");
    j.key("time_ms").value(check_ms_);
    j.end_object();
}

} // namespace

std::unique_ptr<stage> make_lobe_taps_stage() { return std::make_unique<lobe_taps_stage>(); }

} // namespace ibl_bake
