// tools/ibl-bake/stages/stage_lookup.cpp — check: the specular chain where a renderer samples it. At
// roughness 0.05, 0.1, ..., 1 (between the levels as well as on them), the lookup of
// --specular-lookup (ibl/runtime/lookup.hpp) against the exact LD at that roughness, on the texel centres
// of a g x g-per-face cube (g = the quality's check grid) plus the 5 x 5 block about the brightest
// direction: built-in sky: ibl::reference_ld_sky (sky by GGX IS, the sun's cap by quadrature);
// files: ibl::reference_ld_texel_sum (every texel of a source level fine enough for the lobe).
// Reported per roughness: the total error, its interpolation part (the blend of exact levels) and
// its level part (the lookup against that blend); for the default and the textbook lookup, and for
// the chain as specular.ktx2 stores it (--ktx2-format round trip). Full plans only (a scene plan's
// stored chain starts at a virtual level; its levels are checked by the specular stage).

#include "stages/stages.hpp"

#include "io/cube_layout.hpp"

#include <algorithm>
#include <cmath>
#include <map>

#include <ibl/reference/lookup_error.hpp>
#include <ibl/core/color.hpp>
#include <ibl/reference/metrics.hpp>
#include <ibl/reference/ld_irradiance.hpp>

namespace ibl_bake {

namespace {

struct lookup_rows {
    std::string name;
    std::vector<ibl::specular_lookup_report> r;
};

class lookup_stage final : public stage {
public:
    const char* key() const override { return "specular_lookup"; }
    stage_kind kind() const override { return stage_kind::check; }
    bool enabled(const bake_context& ctx) const override {
        return ctx.chain && ctx.plan.specular.first_level == 0 && ctx.chain->levels() == ctx.plan.specular.virtual_levels &&
               ctx.chain->levels() > 1;
    }

    double check_ms() const override { return ms_; }

    void run(bake_context& ctx) override {
        ctx.prog.begin("check lookups");
        const auto t0 = std::chrono::steady_clock::now();
        weight_ = ctx.opt.ld_weight; // every reference takes the chain's weight
        // --checks fast: the roughness midway between adjacent levels (where the lookup's error
        // peaks; on a level it is that level's error, which the specular check measures), the
        // chosen lookup only, texel sums of 4 texels per alpha
        fast_ = ctx.opt.checks == check_mode::fast;
        texels_per_alpha_ = fast_ ? 4.0 : 8.0;
        const auto& lv = ctx.plan.specular.levels;
        if (fast_)
            for (std::size_t k = 0; k + 1 < lv.size(); ++k) roughness_.push_back(0.5 * (lv[k].roughness + lv[k + 1].roughness));
        else
            for (int k = 1; k <= 20; ++k) roughness_.push_back(0.05 * k);
        dirs_ = ibl::lookup_error_directions(ctx.qs.ref_grid, ctx.light);
        ibl::specular_lookup_desc chosen = ctx.opt.specular_lookup;
        chosen.mapping = ctx.plan.specular.policy.mapping;
        const ibl::cubemap<float> stored = ctx.specular_file ? ctx.specular_file->decoded
                                                             : cubemap_from_rgb32f(decode_ktx2_cubemap(
                                                                   encode_ktx2_cubemap(cubemap_to_rgb32f(*ctx.chain),
                                                                                       ktx2_format_of(ctx.opt.ktx2_format), "check",
                                                                                       "specular.ktx2", nullptr, {},
                                                                                       ktx2_encoding_of(ctx.opt)),
                                                                   "specular.ktx2"));
        const bool textbook = textbook_lookup(ctx.opt.specular_lookup);
        ibl::specular_lookup_desc other = textbook ? ibl::specular_lookup_desc::accurate() : ibl::specular_lookup_desc::textbook();
        other.mapping = chosen.mapping;
        const std::string chosen_name = textbook ? "textbook (chosen)" : "log-geometric (chosen)";
        const std::string stored_name = "as stored in specular.ktx2 (" + std::string(to_string(ctx.opt.ktx2_format)) + ")";
        if (ctx.sun) { // the chain is the residual: measure what the runtime adds up (with the sun) against the whole
            sets_.push_back(with_sun(ctx, *ctx.chain, chosen, chosen_name + " + sun"));
            if (fast_) return finish(ctx, t0);
            sets_.push_back(with_sun(ctx, stored, chosen, stored_name + " + sun"));
            sets_.push_back(with_sun(ctx, *ctx.chain, other, std::string(textbook ? "log-geometric" : "textbook") + " + sun"));
        } else {
            std::map<double, std::vector<dvec3>> cache; // the three sets share one reference per roughness
            auto ref = [&](std::span<const dvec3> d, double r) {
                auto it = cache.find(r);
                if (it == cache.end()) it = cache.emplace(r, reference(ctx, d, r)).first;
                return it->second;
            };
            sets_.push_back({chosen_name, ibl::specular_lookup_error(*ctx.chain, chosen, roughness_, dirs_, ref)});
            if (fast_) return finish(ctx, t0);
            sets_.push_back({stored_name, ibl::specular_lookup_error(stored, chosen, roughness_, dirs_, ref)});
            sets_.push_back({textbook ? "log-geometric" : "textbook", ibl::specular_lookup_error(*ctx.chain, other, roughness_, dirs_, ref)});
        }
        finish(ctx, t0);
    }

    std::vector<table_row> rows() const override;
    void report(json_writer& j) const override;

private:
    void finish(bake_context& ctx, std::chrono::steady_clock::time_point t0) {
        ms_ = ms_since(t0);
        ctx.prog.end();
    }

    std::vector<dvec3> reference(const bake_context& ctx, std::span<const dvec3> d, double r) const {
        if (r <= 0.0) { // the mirror level: the source cube itself (the texel sum degenerates at alpha = 0)
            std::vector<dvec3> out(d.size());
            for (std::size_t i = 0; i < d.size(); ++i) out[i] = dvec3(ctx.source.bilinear(fvec3(d[i]), 0));
            return out;
        }
        if (ctx.src.analytic) {
            std::vector<dvec3> out(d.size());
            ctx.ex(d.size(), [&](std::size_t b, std::size_t e) {
                for (std::size_t i = b; i < e; ++i)
                    out[i] = ibl::reference_ld_sky(ctx.src.sky, d[i], r, std::max(ctx.qs.sky_ref_samples / 4, 256u), ctx.qs.sun_cap_nodes,
                                                   weight_);
            });
            return out;
        }
        return ibl::reference_ld_texel_sum(ctx.source, ibl::reference_ld_texel_level(ctx.source, r, texels_per_alpha_), d, r, ctx.ex, weight_);
    }

    /// With an extracted sun: the runtime's LD (the chain's lookup plus the sun's exact LD term)
    /// against the exact LD of the source before extraction (total error only: the residual's own
    /// exact LD near the sun is a difference of two large numbers, no reference to measure against).
    lookup_rows with_sun(const bake_context& ctx, const ibl::cubemap<float>& chain, const ibl::specular_lookup_desc& d,
                         const std::string& name) {
        product_view v = baked_view(ctx);
        v.chain = &chain;
        v.specular = d;
        lookup_rows rows{name, {}};
        for (const double r : roughness_) {
            auto it = whole_.find(r);
            if (it == whole_.end()) {
                std::vector<dvec3> ref = ctx.src.analytic
                                             ? reference(ctx, dirs_, r) // the sky's exact LD holds its sun
                                             : ibl::reference_ld_texel_sum(ctx.whole_source(), ibl::reference_ld_texel_level(ctx.whole_source(), r, texels_per_alpha_),
                                                                           std::span<const dvec3>(dirs_), r, ctx.ex, weight_);
                it = whole_.emplace(r, std::move(ref)).first;
            }
            const std::vector<dvec3>& ref = it->second;
            double mean = 0.0;
            for (const auto& x : ref) mean += ibl::luminance(x) / double(ref.size());
            ibl::error_accumulator acc(std::max(1e-3 * mean, 1e-30));
            for (std::size_t i = 0; i < dirs_.size(); ++i)
                acc.add(ibl::luminance(v.ld(dirs_[i], r) + sun_ld(v.sun, dirs_[i], r, weight_)), ibl::luminance(ref[i]));
            ibl::specular_lookup_report rep;
            rep.roughness = r;
            rep.total = acc.finish();
            rows.r.push_back(rep);
        }
        return rows;
    }

    /// Worst total rel RMSE over r >= lo.
    static std::pair<double, double> worst(const std::vector<ibl::specular_lookup_report>& v, double lo) {
        double w = 0.0, at = 0.0;
        for (const auto& x : v)
            if (x.roughness >= lo - 1e-9 && x.total.rel_rmse > w) w = x.total.rel_rmse, at = x.roughness;
        return {w, at};
    }

    std::vector<double> roughness_;
    std::vector<dvec3> dirs_;
    std::vector<lookup_rows> sets_;
    std::map<double, std::vector<dvec3>> whole_;
    ibl::ld_weight weight_ = ibl::ld_weight::n_dot_l;
    double ms_ = 0.0, texels_per_alpha_ = 8.0;
    bool fast_ = false;
};

std::vector<table_row> lookup_stage::rows() const {
    std::vector<table_row> rows;
    const double lo = roughness_.empty() ? 0.05 : roughness_.front();
    for (std::size_t s = 0; s < sets_.size(); ++s) {
        const auto [w25, r25] = worst(sets_[s].r, 0.25);
        const auto [wlo, rlo] = worst(sets_[s].r, lo);
        table_row row{s == 0 ? "specular lookup" : "", sets_[s].name,
                      s == 0 ? std::to_string(dirs_.size()) + " dirs x " + std::to_string(roughness_.size()) + " r" : "", s == 0 ? ms_ : -1.0,
                      fmt2("worst rel RMSE r>=0.25 %.3g (r=%.2f)", w25, r25) + fmt(", r>=%.2f", lo) + fmt2(" %.3g (r=%.2f)", wlo, rlo)};
        row.detail = s > 0;
        const std::string name = sets_[s].name, brief = name.substr(0, name.find(" (chosen)")) + (name.find("+ sun") != std::string::npos ? " + sun" : "");
        row.compact(brief, fmt2("worst rel RMSE %.3g (r=%.2f)", wlo, rlo))
            .alarm(wlo, alarm_relative, "a lookup between levels is > 5% off: more levels (--levels) space them closer");
        rows.push_back(row);
    }
    return rows;
}

void lookup_stage::report(json_writer& j) const {
    j.begin_object();
    j.key("method").value("the lookup at roughness 0.05..1 against the exact LD (ibl::specular_lookup_error): total, "
                          "interpolation part (blend of exact levels), level part (lookup vs that blend); relative RMSE "
                          "with a floor of 1e-3 x the mean; the exact LD with the chain's LD weight");
    j.key("directions").value(dirs_.size());
    j.key("texels_per_alpha").value(texels_per_alpha_);
    j.key("time_ms").value(ms_);
    j.key("sets").begin_array();
    for (const auto& s : sets_) {
        j.begin_object();
        j.key("name").value(s.name);
        j.key("roughness").begin_array();
        for (const auto& x : s.r) {
            j.begin_object();
            j.key("r").value(x.roughness).key("total_rel_rmse").value(x.total.rel_rmse);
            j.key("interpolation_rel_rmse").value(x.interpolation.rel_rmse).key("levels_rel_rmse").value(x.levels.rel_rmse);
            j.key("total_max_rel").value(x.total.max_rel);
            j.end_object();
        }
        j.end_array();
        j.end_object();
    }
    j.end_array();
    j.end_object();
}

} // namespace

std::unique_ptr<stage> make_lookup_stage() { return std::make_unique<lookup_stage>(); }

} // namespace ibl_bake
