// tools/ibl-bake/stages/stage_specular.cpp — the prefiltered specular chain: the plan's stored levels of
// the virtual chain, each by GGX filtered importance sampling (Krivanek-Colbert; N = V = R) with the
// plan's samples and read mode; virtual level 0 is the source at the output texel centres.
// Check: each level against its reference at check_texels (a grid per face plus the 3 x 3 block
// at the brightest direction): level 0 against the 16 x 16 sub-sampled texel mean of the source,
// rougher levels against ibl::reference_ld_sky (the sky by GGX IS plus the sun cap by quadrature)
// or ibl::reference_ld on the input map (GGX IS, double).

#include "stages/stages.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <type_traits>

#include <ibl/env/cube_geometry.hpp>
#include <ibl/reference/metrics.hpp>
#include <ibl/bake/prefilter.hpp>
#include <ibl/reference/ld_irradiance.hpp>

#include "stages/check_texels.hpp"
#include "io/cube_layout.hpp"

namespace ibl_bake {

namespace {

/// The roughness <-> lod rule of a policy, as the files and report.json state it.
const char* policy_rule(ibl::roughness_mip_policy p) {
    return p.mapping == ibl::roughness_mapping::filament ? "filament: lod = (V - 1) r (2 - r)" : "linear: lod = (V - 1) r";
}

/// What a loader needs, in the KTX2's key/value data: the level -> roughness mapping, the first
/// stored level of the virtual chain, the policy, the lookup, the preset, the chain's LD weight
/// and the runtime model (lobe: read with lobe_lut.exr; taps2: with lobe_taps_a.exr and
/// lobe_taps_b.exr; split-sum: with dfg.exr).
std::vector<std::pair<std::string, std::string>> chain_metadata(const bake_context& ctx) {
    const ibl::specular_plan& sp = ctx.plan.specular;
    std::string r;
    for (const auto& l : sp.levels) {
        if (!r.empty()) r.push_back(' ');
        r.append(fmt("%.9g", l.roughness));
    }
    const std::string lookup = textbook_lookup(ctx.opt.specular_lookup)
                                   ? "textureLod(chain, R, lod(r))"
                                   : "the two levels bracketing r blended log-geometrically (ibl_specular_lookup)";
    std::vector<std::pair<std::string, std::string>> m =
        product_conventions(ctx, "specular",
                            std::string("level l holds LD at roughness ibl.level_roughness[l], weight ") +
                                (ctx.opt.ld_weight == ibl::ld_weight::g1 ? "D G1 (the specular lobe at n.v = 1)" : "D n.l (Karis)") +
                                "; read at R = reflect(-v, n) by " + lookup);
    for (auto kv : std::vector<std::pair<std::string, std::string>>{
             {"ibl.first_level", std::to_string(sp.first_level)},
             {"ibl.ld_weight", to_string(ctx.opt.ld_weight)},
             {"ibl.level_roughness", r},
             {"ibl.policy", policy_rule(ctx.opt.policy)},
             {"ibl.runtime", to_string(runtime_model_of(ctx.opt, ctx.plan).kind)},
             {"ibl.specular_lookup", ctx.opt.specular_lookup.name()},
             {"ibl.virtual_levels", std::to_string(sp.virtual_levels)}})
        m.push_back(kv);
    return m;
}

struct level_check {
    int level = 0, virtual_level = 0, size = 0;
    double roughness = 0.0;
    std::uint32_t samples = 0;
    bool trilinear = false;
    std::size_t texels = 0;
    ibl::error_metrics m;
    double ref_ms = 0.0;
};

class specular_stage final : public stage {
public:
    const char* key() const override { return "specular"; }
    stage_kind kind() const override { return stage_kind::product; }
    const char* category() const override { return "specular"; }
    bool enabled(const bake_context& ctx) const override { return ctx.plan.specular.enabled && !ctx.plan.specular.levels.empty(); }
    double product_ms() const override { return ms_; }
    double check_ms() const override { return check_ms_; }

    void run(bake_context& ctx) override {
        ctx.prog.begin("prefilter");
        weight_ = ctx.opt.ld_weight;
        method_ = ctx.opt.prefilter;
        ctx.chain = bake_chain(ctx.source, ctx.plan.specular, weight_, ctx.ex, method_, ctx.opt.fast_peaks, ctx.opt.fast_sh_bands,
                               ctx.opt.fast_mid_tail);
        if (method_ == prefilter_choice::fast) { // the bands of each level by spherical harmonics (0: its tap set)
            const ibl::prefilter_options po =
                chain_options(ctx.plan.specular, weight_, method_, ctx.opt.fast_peaks, ctx.opt.fast_sh_bands, ctx.opt.fast_mid_tail);
            sh_bands_.clear();
            mid_roughness_.clear();
            const int first_size = std::max(1, po.base_size >> po.level_plan.front().level);
            for (std::size_t k = 0; k < po.level_plan.size(); ++k) {
                sh_bands_.push_back(ibl::detail::prefilter_sh_bands<ibl::ggx_lobe>(po, po.level_plan[k]));
                mid_roughness_.push_back(ibl::detail::prefilter_mid_roughness<ibl::ggx_lobe>(po, po.level_plan, k, first_size, true));
            }
            sh_max_bands_ = ctx.opt.fast_sh_bands;
            mid_tail_ = ctx.opt.fast_mid_tail;
        }
        ms_ = ctx.prog.end();
        if (method_ == prefilter_choice::fast && ctx.opt.fast_peaks > 0) { // the split again, for the report (untimed)
            ibl::peak_split_options po;
            po.max_peaks = ctx.opt.fast_peaks;
            const ibl::cube_peak_split<float> split = ibl::split_cube_peaks(ctx.source, po, ctx.ex);
            peaks_ = {true, po.ratio, po.max_peaks, po.max_level_peaks, split.peaks.size(), split.threshold, split.mean_luminance};
        }
        chain_ = &*ctx.chain;
        sp_ = ctx.plan.specular;
        analytic_ = ctx.src.analytic;
        qs_ = ctx.qs;
        format_ = ctx.opt.ktx2_format;
        metadata_ = chain_metadata(ctx);
        layouts_ = ctx.opt.layouts;
        floor_ = 1e-3 * std::max(ctx.lstats.mean, 1e-30);
        checked_ = ctx.opt.checks != check_mode::none;
        // specular.ktx2, encoded once (the block formats' encoder takes time: reported apart from
        // the product's) and decoded as a renderer reads it
        ctx.prog.begin("encode specular.ktx2");
        auto file = std::make_shared<bake_context::stored_ktx2>();
        const cubemap_rgb32f rgb = cubemap_to_rgb32f(*chain_);
        const auto t_enc = std::chrono::steady_clock::now();
        file->bytes = encode_ktx2_cubemap(rgb, ktx2_format_of(format_), "ibl-bake " + version_string(), "specular.ktx2", nullptr,
                                          metadata_, ktx2_encoding_of(ctx.opt));
        file->encode_ms = ms_since(t_enc);
        const cubemap_rgb32f decoded = decode_ktx2_cubemap(file->bytes, "specular.ktx2");
        file->decoded = cubemap_from_rgb32f(decoded);
        ctx.prog.end();
        file_ = file;
        ctx.specular_file = file;
        if (!checked_) return;
        ctx.prog.begin("check specular");
        quant_ = ktx2_quantisation_report(rgb, ktx2_format_of(format_), &decoded);
        for (int k = 0; k < chain_->levels(); ++k) {
            ctx.prog.label("level " + std::to_string(k) + "/" + std::to_string(chain_->levels() - 1));
            checks_.push_back(check_level(ctx, k));
        }
        check_ms_ = ctx.prog.end();
    }

    std::vector<table_row> rows() const override;
    std::vector<file_out> files() const override;
    void report(json_writer& j) const override;

private:
    level_check check_level(const bake_context& ctx, int k) const;
    void report_levels(json_writer& j) const;

    const ibl::cubemap<float>* chain_ = nullptr;
    ibl::specular_plan sp_;
    bool analytic_ = true;
    ktx2_storage format_ = ktx2_storage::rgba16f;
    std::vector<level_layout> layouts_;
    std::vector<ktx2_quantisation_level> quant_;
    std::shared_ptr<const bake_context::stored_ktx2> file_;
    std::vector<std::pair<std::string, std::string>> metadata_;
    /// The chain's keys plus the level and its roughness (ibl.level, ibl.roughness).
    exr_attributes level_attrs(int l) const {
        exr_attributes a = metadata_;
        a.push_back({"ibl.level", std::to_string(l)});
        a.push_back({"ibl.roughness", l < int(sp_.levels.size()) ? fmt("%.9g", sp_.levels[std::size_t(l)].roughness) : "?"});
        return a;
    }
    quality_settings qs_{};
    ibl::ld_weight weight_ = ibl::ld_weight::n_dot_l;
    prefilter_choice method_ = prefilter_choice::fis;
    std::vector<int> sh_bands_; ///< per stored level, the fast filter's spherical-harmonic bands (0: taps)
    std::vector<double> mid_roughness_; ///< per stored level, the fast filter's intermediate level's roughness (-1: none)
    bool mid_tail_ = false;
    int sh_max_bands_ = 0;
    struct peak_report {
        bool on = false;
        double ratio = 0.0;
        std::uint32_t max_peaks = 0, max_level_peaks = 0;
        std::size_t count = 0;
        double threshold = 0.0, mean = 0.0;
    } peaks_;
    double ms_ = 0.0, check_ms_ = 0.0, floor_ = 0.0;
    bool checked_ = true;
    std::vector<level_check> checks_;
};

level_check specular_stage::check_level(const bake_context& ctx, int k) const {
    const auto t0 = std::chrono::steady_clock::now();
    const ibl::specular_level_plan& lp = sp_.levels[std::size_t(k)];
    level_check lc;
    lc.level = k;
    lc.virtual_level = lp.level;
    lc.size = chain_->size(k);
    lc.roughness = lp.roughness;
    lc.samples = lp.samples;
    lc.trilinear = lp.trilinear && method_ != prefilter_choice::fast; // the fast filter reads the nearest level
    const std::vector<std::array<int, 3>> texels = check_texels(lc.size, qs_.ref_grid, ctx.light);
    const std::vector<dvec3> ref =
        chain_check_references(ctx.src, ctx.whole_source(), texels, lc.size, lp.level == 0, lc.roughness, qs_, weight_, ctx.ex);
    // Relative errors use a floor of 1e-3 x the mean radiance (dark texels do not dominate). With an
    // extracted sun the product is what the runtime gets: the level plus the sun's LD term (level 0:
    // the texel with the removed excess added back, i.e. the source before extraction).
    ibl::error_accumulator acc(floor_);
    const ibl::disk_light<double>* sun = ctx.sun ? &*ctx.sun : nullptr;
    for (std::size_t i = 0; i < texels.size(); ++i) {
        const auto& t = texels[i];
        dvec3 got(chain_->texel(t[0], t[1], t[2], k));
        if (sun && lp.level == 0 && ctx.whole_source().size(0) == lc.size) got = dvec3(ctx.whole_source().texel(t[0], t[1], t[2], 0));
        else if (sun) got += sun_ld(sun, ibl::cube_texel_direction<double>(t[0], t[1], t[2], lc.size), lc.roughness, weight_);
        acc.add(got, ref[i]);
    }
    lc.m = acc.finish();
    lc.texels = texels.size();
    lc.ref_ms = ms_since(t0);
    return lc;
}

std::vector<table_row> specular_stage::rows() const {
    const bool fast = method_ == prefilter_choice::fast;
    const std::string spp = sp_.first_level == 0 && sp_.levels.size() > 1 && sp_.levels[1].samples == qs_.prefilter_samples
                                ? std::to_string(chain_samples(qs_.prefilter_samples, method_, 1)) + (fast ? "*4^(l-1) spp" : "*2^(l-1) spp")
                                : "planned spp";
    const std::string method = std::string(fast ? "GGX fast filter" : "GGX filtered IS") + (sp_.trilinear && !fast ? " (trilinear)" : "");
    const std::string brief = fast ? "GGX fast filter" : "GGX filtered IS";
    const std::string cost = spp + ", " + std::to_string(sp_.levels.size()) + " levels";
    if (!checked_) return {table_row{"specular chain", method, cost, ms_, "not checked (--checks none)"}.compact(brief, "not checked")};
    double worst_rel = 0.0, worst_over = 0.0;
    int worst_l = 0;
    for (const auto& c : checks_)
        if (c.virtual_level > 0) {
            if (c.m.rel_rmse > worst_rel) worst_rel = c.m.rel_rmse, worst_l = c.virtual_level;
            worst_over = std::max(worst_over, c.m.max_ratio);
        }
    const bool any = worst_rel > 0.0 || checks_.size() > 1;
    std::vector<table_row> rows;
    rows.push_back(table_row{"specular chain", method, cost, ms_,
                             any ? fmt2("worst rel RMSE %.3g (level %.0f)", worst_rel, worst_l) + fmt(", max overshoot %.3g", worst_over) : "-"}
                       .compact(brief, any ? fmt2("worst rel RMSE %.3g (level %.0f)", worst_rel, worst_l) : "-")
                       .alarm(worst_rel, alarm_relative,
                              "levels > 5% off the exact LD: more samples (--quality high), or --extract-sun on for a sun"));
    double qmax = 0.0, qrms = 0.0;
    std::size_t clamped = 0;
    for (const auto& q : quant_) {
        qmax = std::max(qmax, q.max_rel_error), qrms = std::max(qrms, q.rms_rel_error);
        clamped += q.above_range + q.negative_clamped + q.nan;
    }
    table_row q{"  specular.ktx2", std::string(to_string(format_)) + " storage vs float", std::to_string(quant_.size()) + " levels", -1.0,
                fmt2("max rel %.3g, worst level rms rel %.3g", qmax, qrms) + ", " + std::to_string(clamped) + " values clamped"};
    q.compact(std::string(to_string(format_)) + " storage", fmt("max rel %.3g, ", qmax) + std::to_string(clamped) + " clamped");
    if (clamped > 0)
        q.meaning = "values beyond the format's range were clamped: --ktx2-format rgba32f stores them (or scale the input)";
    else
        q.alarm(qmax, alarm_quantisation, "the format's rounding, not the bake: --ktx2-format rgba16f or rgba32f keep more bits");
    rows.push_back(q);
    for (const auto& c : checks_) {
        char name[64];
        std::snprintf(name, sizeof name, "  l%d %dx%d r=%.2f", c.virtual_level, c.size, c.size, c.roughness); // level 0 = mirror
        const std::string ref = c.virtual_level == 0 ? "texel mean " + std::to_string(level0_ref_k) + "^2"
                                : analytic_      ? "ref: sky IS + sun cap quadrature"
                                                 : "ref: exact texel sum";
        table_row r{name, ref, std::to_string(c.texels) + " texels", c.ref_ms, fmt2("rel RMSE %.3g, overshoot %.3g", c.m.rel_rmse, c.m.max_ratio)};
        r.detail = true;
        rows.push_back(r);
    }
    return rows;
}

std::vector<file_out> specular_stage::files() const {
    std::vector<file_out> f;
    const auto has = [&](level_layout l) { return std::find(layouts_.begin(), layouts_.end(), l) != layouts_.end(); };
    for (int l = 0; l < chain_->levels(); ++l) {
        const std::string base = "specular_l" + std::to_string(l) + "_";
        if (has(level_layout::faces))
            for (int face = 0; face < 6; ++face)
                f.push_back({base + face_names[face] + ".exr",
                             [this, l, face](const std::string& p) { write_exr(p, face_image(*chain_, face, l), level_attrs(l)); }});
        if (has(level_layout::latlong))
            f.push_back({base + "latlong.exr", [this, l](const std::string& p) { write_exr(p, latlong_from_cube(*chain_, l), level_attrs(l)); }});
        if (has(level_layout::cross))
            f.push_back({base + "cross.exr", [this, l](const std::string& p) {
                             write_exr(p, cross_from_faces(faces_from_cubemap(*chain_, l)), level_attrs(l));
                         }});
        if (has(level_layout::octahedral))
            f.push_back({base + "octahedral.exr",
                         [this, l](const std::string& p) { write_exr(p, octahedral_from_cube(*chain_, l), level_attrs(l)); }});
    }
    f.push_back({"specular.ktx2", [this](const std::string& p) { write_file_atomic(p, file_->bytes); }});
    return f;
}

void specular_stage::report(json_writer& j) const {
    j.begin_object();
    j.key("files").value("specular_l{level}_{px,nx,py,ny,pz,nz}.exr (layout faces), specular_l{level}_{latlong,cross,octahedral}.exr "
                         "(those layouts), specular.ktx2");
    j.key("layouts").begin_array();
    for (const auto& l : layouts_) j.value(to_string(l));
    j.end_array();
    j.key("ktx2_quantisation");
    if (checked_) json_quantisation(j, quant_, format_);
    else j.null();
    j.key("prefilter").value(to_string(method_));
    j.key("method").value(std::string(method_ == prefilter_choice::fast
                                          ? std::string("GGX fast filter (ibl::prefilter_method::fast: spiral tap sets shaped offline, "
                                                        "read from the exact-solid-angle mips; coarse tail: each level's kernel tail "
                                                        "read from the next level of face >= 16") +
                                                (peaks_.on ? "; peak split: the brightest texels added back exactly through the LD kernel" : "") +
                                                (mid_tail_ ? "; intermediate coarse tail: a level at r <= 0.3 reads its tail from a "
                                                             "half-size level between it and the next, where that face resolves its kernel"
                                                           : "") +
                                                (sh_max_bands_ > 0 ? "; rough levels by spherical-harmonic convolution of the source), "
                                                                   : "), ")
                                          : "GGX filtered importance sampling (Krivanek-Colbert), ") +
                          (sp_.trilinear && method_ != prefilter_choice::fast ? "trilinear" : "nearest-level") +
                          " source reads, N = V = R, weight " +
                          (weight_ == ibl::ld_weight::g1 ? "D G1(n.l)" : "D n.l"));
    j.key("ld_weight").value(to_string(weight_));
    j.key("cost").begin_object().key("samples_per_texel").value(sp_.levels.size() > 1 ? chain_samples(sp_.levels[1].samples, method_, sp_.levels[1].level) : 0u);
    j.key("samples_per_level").begin_array();
    for (const auto& l : sp_.levels) j.value(chain_samples(l.samples, method_, l.level));
    j.end_array();
    if (method_ == prefilter_choice::fast) j.key("lod_bias").value("per level: the fast table's shape (ibl::fast_shape)");
    else j.key("lod_bias").value(0.5);
    j.end_object();
    if (method_ == prefilter_choice::fast) {
        j.key("sh_levels").begin_object().key("max_bands").value(sh_max_bands_).key("tolerance").value(ibl::sh_rough_options{}.tolerance);
        j.key("bands_per_level").begin_array();
        for (const int b : sh_bands_) j.value(b);
        j.end_array().end_object();
        j.key("mid_tail").begin_object().key("enabled").value(mid_tail_).key("mid_roughness_per_level").begin_array();
        for (const double r : mid_roughness_) {
            if (r >= 0.0) j.value(r);
            else j.null();
        }
        j.end_array().end_object();
        j.key("peaks").begin_object().key("enabled").value(peaks_.on);
        if (peaks_.on)
            j.key("ratio").value(peaks_.ratio).key("max_peaks").value(peaks_.max_peaks).key("max_level_peaks").value(peaks_.max_level_peaks)
                .key("count").value(std::uint64_t(peaks_.count))
                .key("threshold").value(peaks_.threshold).key("mean_luminance").value(peaks_.mean);
        j.end_object();
    }
    j.key("time_ms").value(ms_);
    j.key("mip_policy").value(sp_.policy.mapping == ibl::roughness_mapping::filament
                                  ? "filament: roughness r at virtual lod v = (V - 1) r (2 - r) of V levels; stored level = v - first_level"
                                  : "linear: roughness = v / (V - 1) for virtual level v of V; stored level = v - first_level");
    j.key("virtual_levels").value(sp_.virtual_levels);
    j.key("first_level").value(sp_.first_level);
    j.key("check").begin_object();
    j.key("reference").value(std::string(analytic_ ? "level 0: texel mean (16x16 sub-samples); levels >= 1: ibl::reference_ld_sky "
                                                     "(sky by GGX IS + sun cap quadrature)"
                                                   : "level 0: texel mean (16x16 sub-samples) of the input; levels >= 1: "
                                                     "ibl::ld_texel_sum, the exact LD of the source cube (a texel sum in "
                                                     "double at ibl::ld_texel_sum_level; no sampling noise)") +
                             ", with the chain's LD weight");
    j.key("texels").value("per level: a grid per face plus the 3x3 block around the brightest direction");
    j.key("relative_error_floor").value(floor_);
    j.key("ran").value(checked_);
    j.key("time_ms").value(check_ms_);
    j.end_object();
    report_levels(j);
    j.end_object();
}

void specular_stage::report_levels(json_writer& j) const {
    j.key("levels").begin_array();
    for (std::size_t k = 0; k < sp_.levels.size(); ++k) {
        const ibl::specular_level_plan& lp = sp_.levels[k];
        const level_check* c = k < checks_.size() ? &checks_[k] : nullptr;
        j.begin_object();
        j.key("level").value(int(k));
        j.key("virtual_level").value(lp.level);
        j.key("size").value(chain_->size(int(k)));
        j.key("roughness").value(lp.roughness);
        j.key("samples").value(chain_samples(lp.samples, method_, lp.level));
        j.key("trilinear").value(lp.trilinear && method_ != prefilter_choice::fast);
        if (c) {
            j.key("texels_compared").value(c->texels);
            j.key("rel_rmse").value(c->m.rel_rmse);
            j.key("nrmse").value(c->m.nrmse);
            j.key("max_overshoot").value(c->m.max_ratio);
            j.key("max_rel").value(c->m.max_rel);
            j.key("reference_time_ms").value(c->ref_ms);
        } else { // --checks none
            j.key("texels_compared").value(0);
            for (const char* m : {"rel_rmse", "nrmse", "max_overshoot", "max_rel"}) j.key(m).null();
        }
        j.end_object();
    }
    j.end_array();
}

} // namespace

std::unique_ptr<stage> make_specular_stage() { return std::make_unique<specular_stage>(); }

} // namespace ibl_bake
