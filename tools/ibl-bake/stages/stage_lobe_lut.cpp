// tools/ibl-bake/stages/stage_lobe_lut.cpp — the tables of the two-part lobe model (--runtime lobe;
// ibl/runtime/specular_models.hpp specular_lobe_pair, bake/lobe_fit.hpp make_lobe_pair_lut): per (n.v, r)
// the DFG terms A, B, the lerp factor s and the chain roughness r_eff of the one chain kernel
// closest to the specular lobe in L1 (read for F0 A), and the kernel closest to the lobe's
// Fresnel B part (weight (1 - v.h)^5, read for F90 B): its angle from n over acos(n.v) and its
// roughness; the chain's weight, in the DFG table's layout at lobe_lut_size_for(DFG size) texels
// per side (each texel fitted on its own, about 1 ms a texel, part and thread).
// Checks: (A, B) against the DFG table read (ibl::dfg_lookup) at the lobe LUT's texels; at the
// midpoints of every second cell per axis, the L1 distance to the lobe of the tap read bilinearly
// (ibl::lobe_lut_lookup) against that of a direct fit there (what the table's interpolation
// costs) and of the one-tap moment match (ibl::specular_lobe_moments, what the fit gains); the
// same for the B part against its own direct fit, beside the L1 distance of the whole lobe's
// kernel and of the split sum's (R, r) to the B part (what the second kernel gains).
// Files: lobe_lut.exr (RGBA float32; rows as dfg.exr: row 0 = the smallest roughness; R = A,
// G = B, B = s, A = r_eff), lobe_lut_b.exr (R = f_B, G = r_B, B = A = 0) and lobe_lut.hpp,
// lobe_lut_b.hpp (the same floats as C headers, read by the viewer).

// GCC 12 at -O3 reports a false -Warray-bounds in ibl::fit_specular_lobe (its sort of the first
// n_taps of a std::array of taps) as instantiated here; off for the headers of this file only.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Warray-bounds"
#endif
#include "stages/stages.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <ibl/bake/lobe_fit.hpp>
#include <ibl/runtime/specular_models.hpp>
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif

namespace ibl_bake {

namespace {

constexpr std::uint32_t check_nodes = 32; ///< nodes^2 lobe points of the midpoint check's L1 distances

/// L1 distances at the midpoints: of the table's tap, of a direct fit, of the moment match.
struct midpoint_l1 {
    double table_mean = 0.0, fit_mean = 0.0, moments_mean = 0.0;
    double excess_max = 0.0, worst_n_dot_v = 0.0, worst_roughness = 0.0;
};

/// The B part's L1 distances at the midpoints: of the B table's tap, of a direct fit, of the whole
/// lobe's kernel (the lobe LUT's tap) and of the split sum's (R, r).
struct midpoint_l1_b {
    double table_mean = 0.0, fit_mean = 0.0, whole_mean = 0.0, split_mean = 0.0;
    double excess_max = 0.0, worst_n_dot_v = 0.0, worst_roughness = 0.0;
};

class lobe_lut_stage final : public stage {
public:
    const char* key() const override { return "lobe_lut"; }
    stage_kind kind() const override { return stage_kind::product; }
    const char* category() const override { return "lobe_lut"; }
    bool enabled(const bake_context& ctx) const override {
        return ctx.lut && ctx.chain && runtime_model_of(ctx.opt, ctx.plan).kind == runtime_choice::lobe;
    }
    double product_ms() const override { return ms_; }
    double check_ms() const override { return check_ms_; }

    void run(bake_context& ctx) override {
        layout_ = ctx.opt.dfg_layout;
        weight_name_ = to_string(ctx.opt.ld_weight);
        weight_ = ctx.opt.ld_weight;
        const auto size = std::uint32_t(lobe_lut_size_for(ctx.plan.dfg.size));
        ctx.prog.begin("lobe lut");
        {
            ibl::lobe_pair_lut pair = ibl::make_lobe_pair_lut<bake_model>(size, layout_, weight_, ibl::lobe_fit_options{}, ctx.ex);
            ctx.lobe = std::move(pair.a);
            ctx.lobe_b = std::move(pair.b);
        }
        ms_ = ctx.prog.end();
        lut_ = &*ctx.lobe;
        lut_b_ = &*ctx.lobe_b;
        const std::vector<std::pair<std::string, std::string>> keys = {
            {"ibl.ld_weight", weight_name_},
            {"ibl.lobe_parts", "2: lobe_lut.exr (A part and A, B), lobe_lut_b.exr (the Fresnel B part)"}};
        attrs_ = table_conventions(ctx, "lobe_lut",
                                   "R = A, G = B, B = s, A = r_eff: the two-part lobe model (with lobe_lut_b.exr) specular = "
                                   "F0 A LD(normalize(mix(n, R, s)), r_eff) + F90 B LD(d_B, r_B); a one-kernel reader: "
                                   "LD(normalize(mix(n, R, s)), r_eff) (F0 A + F90 B); LD from a chain of weight ibl.ld_weight",
                                   layout_, keys);
        attrs_b_ = table_conventions(ctx, "lobe_lut_b",
                                     "R = f_B, G = r_B, B = 0, A = 0: the kernel of the lobe's Fresnel B part (weight "
                                     "(1 - v.h)^5), read as LD(cos(a) n + sin(a) t, r_B), a = min(f_B acos(n.v), pi/2), t the "
                                     "unit tangent of n towards R; specular = F0 A LD(normalize(mix(n, R, s)), r_eff) + F90 B "
                                     "LD(d_B, r_B) with (A, B, s, r_eff) from lobe_lut.exr",
                                     layout_, keys);
        checked_ = ctx.opt.checks != check_mode::none;
        if (!checked_) return;
        ctx.prog.begin("check lobe lut");
        ab_max_abs_ = ab_vs_dfg(lut_->data, lut_->size, 4, layout_, *ctx.lut);
        check_midpoints(ctx.ex);
        check_ms_ = ctx.prog.end();
    }

    std::vector<table_row> rows() const override {
        const ibl::lobe_fit_options o;
        const std::string method = std::string("L1 fit of one kernel per part, ") + bake_model::name + ", chain weight " + weight_name_;
        const std::string cost = std::to_string(lut_->size) + "^2 x 2, " + std::to_string(o.nodes) + "^2 points/texel";
        if (!checked_) return {table_row{"lobe lut", method, cost, ms_, "not checked"}.compact("L1 fit, kernel per part", "not checked")};
        return {table_row{"lobe lut", method, cost, ms_,
                          fmt("A,B vs dfg max abs %.3g", ab_max_abs_) +
                              fmt2("; midpoint L1 table %.3g, direct fit %.3g", l1_.table_mean, l1_.fit_mean) +
                              fmt(", moments %.3g", l1_.moments_mean) +
                              fmt2("; B part: table %.3g, direct fit %.3g", l1b_.table_mean, l1b_.fit_mean) +
                              fmt2(", whole kernel %.3g, (R, r) %.3g", l1b_.whole_mean, l1b_.split_mean)}
                    .compact("L1 fit, kernel per part", fmt2("midpoint L1 %.3g, B part %.3g", l1_.table_mean, l1b_.table_mean))};
    }
    std::vector<file_out> files() const override;
    void report(json_writer& j) const override;

private:
    void check_midpoints(pool_executor& ex);

    const ibl::lobe_lut* lut_ = nullptr;
    const ibl::lobe_lut* lut_b_ = nullptr;
    ibl::dfg_lut_layout layout_{};
    std::vector<std::pair<std::string, std::string>> attrs_, attrs_b_;
    ibl::ld_weight weight_ = ibl::ld_weight::g1;
    std::string weight_name_;
    double ms_ = 0.0, check_ms_ = 0.0, ab_max_abs_ = 0.0;
    bool checked_ = true;
    std::size_t cells_ = 0;
    midpoint_l1 l1_;
    midpoint_l1_b l1b_;
};

/// The one tap (angle from n towards R, roughness) a lobe LUT read (s, r_eff) stands for at n.v.
ibl::lobe_tap tap_of(double n_dot_v, double s, double r_eff) {
    const double th = std::acos(std::clamp(n_dot_v, 0.0, 1.0));
    return {std::atan2(s * std::sin(th), 1.0 + s * (std::cos(th) - 1.0)), r_eff, 1.0};
}

void lobe_lut_stage::check_midpoints(pool_executor& ex) {
    const std::uint32_t n = lut_->size;
    // n.v, r, L1 of the table's tap, of a direct fit, of the moments; B part: of the B table's tap,
    // of a direct fit, of the whole lobe's tap, of (R, r)
    std::vector<std::array<double, 9>> pts;
    for (const auto& m : fit_check_midpoints(n, layout_)) pts.push_back({m[0], m[1], 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0});
    ex(pts.size(), [&](std::size_t b, std::size_t e) {
        for (std::size_t k = b; k < e; ++k) {
            const double nv = pts[k][0], r = pts[k][1];
            const ibl::vec4<float> p = ibl::lobe_lut_lookup(*lut_, float(nv), float(r));
            const ibl::detail::lobe_points lp = ibl::detail::make_lobe_points<bake_model>(nv, r, check_nodes);
            std::array<ibl::lobe_tap, ibl::lobe_max_taps> t{};
            t[0] = tap_of(nv, p.z, p.w);
            pts[k][2] = ibl::detail::mixture_l1(lp, t, 1, weight_, {});
            const ibl::lobe_mixture f = ibl::fit_specular_lobe<bake_model>(nv, r, weight_);
            pts[k][3] = ibl::detail::mixture_l1(lp, f.taps, 1, weight_, {});
            pts[k][4] = f.l1_moments;
            // the B part
            const ibl::detail::lobe_points lb =
                ibl::detail::make_lobe_points<bake_model>(nv, r, check_nodes, ibl::lobe_fresnel_part::b);
            const ibl::vec4<float> pb = ibl::lobe_lut_lookup(*lut_b_, float(nv), float(r));
            std::array<ibl::lobe_tap, ibl::lobe_max_taps> tb{};
            tb[0] = {std::clamp(double(ibl::lobe_tap_angle(pb.x, float(nv))), 0.0, ibl::half_pi_v<double>), double(pb.y), 1.0};
            pts[k][5] = ibl::detail::mixture_l1(lb, tb, 1, weight_, {});
            ibl::lobe_fit_options ob;
            ob.part = ibl::lobe_fresnel_part::b;
            const ibl::lobe_mixture fb = ibl::fit_specular_lobe<bake_model>(nv, r, weight_, ob);
            pts[k][6] = ibl::detail::mixture_l1(lb, fb.taps, 1, weight_, {});
            pts[k][7] = ibl::detail::mixture_l1(lb, t, 1, weight_, {});
            std::array<ibl::lobe_tap, ibl::lobe_max_taps> ts{};
            ts[0] = {std::acos(std::clamp(nv, 0.0, 1.0)), std::max(r, 0.01), 1.0};
            pts[k][8] = ibl::detail::mixture_l1(lb, ts, 1, weight_, {});
        }
    });
    for (const auto& p : pts) {
        const double c = double(pts.size());
        l1b_.table_mean += p[5] / c;
        l1b_.fit_mean += p[6] / c;
        l1b_.whole_mean += p[7] / c;
        l1b_.split_mean += p[8] / c;
        if (p[5] - p[6] > l1b_.excess_max) l1b_.excess_max = p[5] - p[6], l1b_.worst_n_dot_v = p[0], l1b_.worst_roughness = p[1];
    }
    for (const auto& p : pts) {
        l1_.table_mean += p[2] / double(pts.size());
        l1_.fit_mean += p[3] / double(pts.size());
        l1_.moments_mean += p[4] / double(pts.size());
        if (p[2] - p[3] > l1_.excess_max) l1_.excess_max = p[2] - p[3], l1_.worst_n_dot_v = p[0], l1_.worst_roughness = p[1];
    }
    cells_ = pts.size();
}

std::vector<file_out> lobe_lut_stage::files() const {
    const std::string rule = layout_.edge_aligned ? "n.v = (i / (size - 1))^3, roughness = (j / (size - 1))^2 (edge-aligned; "
                                                    "sample at ibl::dfg_lut_coord)"
                                                  : "n.v = (i + 0.5) / size, roughness = (j + 0.5) / size";
    return {{"lobe_lut.exr",
             [this](const std::string& p) { write_exr_rgba(p, image_rgba32f{int(lut_->size), int(lut_->size), lut_->data}, attrs_); }},
            {"lobe_lut.hpp", [this, rule](const std::string& p) {
                 write_text(p, c_table_header("lobe_lut", std::string("the lobe LUT of ibl/runtime/specular_models.hpp (") + bake_model::name +
                                                              ", chain weight " + weight_name_ + ")",
                                              lut_->size, 4, "A, B, s, r_eff", rule, lut_->data));
             }},
            {"lobe_lut_b.exr",
             [this](const std::string& p) {
                 write_exr_rgba(p, image_rgba32f{int(lut_b_->size), int(lut_b_->size), lut_b_->data}, attrs_b_);
             }},
            {"lobe_lut_b.hpp", [this, rule](const std::string& p) {
                 write_text(p, c_table_header("lobe_lut_b", std::string("the lobe model's B-part kernel table of ibl/runtime/specular_models.hpp (") +
                                                                bake_model::name + ", chain weight " + weight_name_ + ")",
                                              lut_b_->size, 4, "f_B (angle over acos(n.v)), r_B, 0, 0", rule, lut_b_->data));
             }}};
}

void lobe_lut_stage::report(json_writer& j) const {
    j.begin_object();
    j.key("files").value("lobe_lut.exr, lobe_lut.hpp, lobe_lut_b.exr, lobe_lut_b.hpp");
    j.key("parts").value(2);
    j.key("size").value(lut_->size);
    j.key("layout").value(std::string("the DFG table's (report dfg.layout; ") +
                          (layout_.edge_aligned ? "edge-aligned cbrt(n.v) x sqrt(r)" : "texel centres, uniform") +
                          "); EXR row 0 (top) = the smallest roughness");
    j.key("weight").value(weight_name_);
    j.key("channels").value("R = A, G = B (the DFG terms), B = s (lerp factor: d = normalize(lerp(n, R, s))), A = r_eff (the chain's roughness)");
    j.key("channels_b").value("lobe_lut_b: R = f_B (the B kernel's angle from n towards R over acos(n.v)), G = r_B (its chain "
                              "roughness), B = A = 0");
    j.key("method").value("ibl::make_lobe_pair_lut: A, B by ibl::make_dfg_lut_exact; s, r_eff of the one chain kernel "
                          "closest to the normalised specular lobe in L1 (ibl::fit_specular_lobe, " +
                          std::to_string(ibl::lobe_fit_options{}.nodes) + "^2 lobe points, Nelder-Mead; read for F0 A); "
                          "f_B, r_B of the kernel closest to the lobe's Fresnel B part (weight (1 - v.h)^5; read for F90 B)");
    j.key("time_ms").value(ms_);
    if (!checked_) { // --checks none
        j.key("check").begin_object().key("ran").value(false).end_object();
        j.end_object();
        return;
    }
    j.key("check").begin_object();
    j.key("ab_vs_dfg_max_abs").value(ab_max_abs_);
    j.key("midpoints").value(cells_);
    j.key("l1").begin_object();
    j.key("table_mean").value(l1_.table_mean).key("direct_fit_mean").value(l1_.fit_mean).key("moments_mean").value(l1_.moments_mean);
    j.key("excess_max").value(l1_.excess_max).key("worst_n_dot_v").value(l1_.worst_n_dot_v);
    j.key("worst_roughness").value(l1_.worst_roughness).end_object();
    j.key("l1_b").begin_object();
    j.key("table_mean").value(l1b_.table_mean).key("direct_fit_mean").value(l1b_.fit_mean);
    j.key("whole_kernel_mean").value(l1b_.whole_mean).key("split_sum_mean").value(l1b_.split_mean);
    j.key("excess_max").value(l1b_.excess_max).key("worst_n_dot_v").value(l1b_.worst_n_dot_v);
    j.key("worst_roughness").value(l1b_.worst_roughness).end_object();
    j.key("method").value("A, B against ibl::dfg_lookup of the DFG table at the lobe LUT's texels; at the midpoints of every "
                          "second cell per axis (r >= 0.05) the L1 distance to the lobe (" + std::to_string(check_nodes) +
                          "^2 points; 2 = disjoint) of the tap read by ibl::lobe_lut_lookup, of a direct fit there, and of "
                          "the one-tap moment match; l1_b: the same for the lobe's B part (weight (1 - v.h)^5) of the "
                          "B table's tap and of a direct fit, beside the whole lobe's tap and the split sum's (R, r)");
    j.key("time_ms").value(check_ms_);
    j.end_object();
    j.end_object();
}

} // namespace

std::unique_ptr<stage> make_lobe_lut_stage() { return std::make_unique<lobe_lut_stage>(); }

} // namespace ibl_bake
