// tools/ibl-bake/stages/stage_sheen.cpp — sheen (--sheen): the Charlie sheen products of glTF's
// KHR_materials_sheen / Filament's cloth model.
//   sheen chain  LD with N = V = R of the Charlie NDF (Estevez & Kulla 2017) per level of the
//                tool's chain (roughness r = v / (V - 1), the sheen roughness), by filtered
//                importance sampling of the Charlie lobe (ibl::prefilter<ibl::charlie_lobe>: level
//                0 convolved too, the Charlie lobe at r -> 0 is a ring, not a mirror), from the
//                source after sun extraction; the runtime adds the sun's Charlie LD term
//                (sheen_sun_ld: the disk's centre-point weight over the lobe's normaliser).
//   sheen LUT    the sheen albedo E(n.v, r) = integral D V n.l (Neubelt's V) by quadrature
//                (ibl::make_sheen_lut), the DFG table's texel-centre layout (x = n.v, y = r).
// Checks: each level plus the sun's term against the exact Charlie LD of the source before
// extraction by a texel sum (the GGX check texels);
// the LUT at 16 x 16 texels against ibl::sheen_albedo (double, its own nodes).

#include "stages/stages.hpp"

#include "io/cube_layout.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include <ibl/env/cube_geometry.hpp>
#include <ibl/reference/lookup_error.hpp>
#include <ibl/reference/metrics.hpp>
#include <ibl/reference/ld_irradiance.hpp>
#include <ibl/brdf/charlie.hpp>
#include <ibl/bake/sheen.hpp>

#include "stages/check_texels.hpp"

namespace ibl_bake {

namespace {

class sheen_stage final : public stage {
public:
    const char* key() const override { return "sheen"; }
    stage_kind kind() const override { return stage_kind::product; }
    const char* category() const override { return "specular"; }
    bool enabled(const bake_context& ctx) const override { return ctx.opt.sheen && ctx.chain; }
    double product_ms() const override { return ms_; }
    double check_ms() const override { return check_ms_; }

    void run(bake_context& ctx) override {
        ibl::prefilter_options po;
        po.levels = ctx.chain->levels();
        po.base_size = ctx.chain->size(0);
        po.policy = ibl::roughness_mip_policy::linear();
        po.method = ibl::prefilter_method::filtered_importance;
        po.trilinear = ctx.qs.trilinear;
        po.samples_per_level.assign(std::size_t(po.levels), 0u);
        for (int l = 0; l < po.levels; ++l) po.samples_per_level[std::size_t(l)] = ibl::doubling_prefilter_samples(ctx.qs.prefilter_samples, std::max(l, 1));
        ctx.prog.begin("sheen");
        chain_ = ibl::prefilter<ibl::charlie_lobe>(ctx.source, po, ctx.ex); // the residual when a sun was extracted
        sun_ = ctx.sun ? &*ctx.sun : nullptr;
        lut_ = ibl::make_sheen_lut(std::uint32_t(ctx.opt.lut_size), ibl::sheen_lut_default_nodes, ctx.ex);
        ms_ = ctx.prog.end();
        format_ = ctx.opt.ktx2_format;
        encoding_ = ktx2_encoding_of(ctx.opt);
        samples_ = po.samples_per_level;
        attrs_ = product_conventions(ctx, "sheen", "level l holds the Charlie-lobe LD at roughness l / (levels - 1) (linear), read "
                                                   "at R by textureLod(chain, R, lod(r))");
        lut_attrs_ = table_conventions(ctx, "sheen_lut", "R = sheen albedo E(n.v, r) (Charlie NDF, Neubelt visibility)", lut_.layout);
        checked_ = ctx.opt.checks != check_mode::none;
        if (!checked_) return;
        ctx.prog.begin("check sheen");
        const auto t0 = std::chrono::steady_clock::now();
        // Level 0 (r = 0: a ring of zero width at R's horizon) is below any texel sum's resolution:
        // it is not checked (report: null); levels >= 1 are.
        levels_.push_back(ibl::error_metrics{});
        levels_.back().rel_rmse = std::numeric_limits<double>::quiet_NaN();
        for (int l = 1; l < chain_.levels(); ++l) levels_.push_back(check_level(ctx, l));
        check_lut(ctx.ex);
        check_ms_ = ms_since(t0);
        ctx.prog.end();
    }

    std::vector<table_row> rows() const override {
        double worst = 0.0;
        for (const auto& m : levels_)
            if (std::isfinite(m.rel_rmse)) worst = std::max(worst, m.rel_rmse);
        const std::string method = std::string("Charlie filtered IS") + (sun_ ? " + sun term" : "");
        if (!checked_)
            return {table_row{"sheen chain", method, std::to_string(chain_.levels()) + " levels", ms_, "not checked"}.compact("Charlie filtered IS", "not checked")};
        return {table_row{"sheen chain", method, std::to_string(chain_.levels()) + " levels", ms_,
                          fmt("worst rel RMSE (levels >= 1) %.3g vs texel-sum Charlie LD", worst)}
                    .compact("Charlie filtered IS", fmt("worst rel RMSE %.3g (levels >= 1)", worst))
                    .alarm(worst, alarm_relative, "sheen levels > 5% off the texel-sum Charlie LD: more samples (--quality high)"),
                table_row{"sheen lut", "quadrature (Neubelt V)", std::to_string(lut_.size) + "^2", -1.0, fmt("max abs %.3g vs sheen_albedo", lut_max_abs_)}
                    .compact("quadrature (Neubelt V)", fmt("max abs %.3g", lut_max_abs_))
                    .alarm(lut_max_abs_, alarm_absolute, "the sheen table's quadrature is off by > 0.01: --quality high")};
    }
    std::vector<file_out> files() const override {
        std::vector<file_out> f;
        for (int l = 0; l < chain_.levels(); ++l)
            for (int face = 0; face < 6; ++face)
                f.push_back({"sheen_l" + std::to_string(l) + "_" + face_names[face] + ".exr",
                             [this, l, face](const std::string& p) { write_exr(p, face_image(chain_, face, l), attrs_); }});
        f.push_back({"sheen.ktx2", [this](const std::string& p) {
                         write_ktx2_cubemap(p, cubemap_to_rgb32f(chain_), ktx2_format_of(format_), "ibl-bake " + version_string(),
                                            attrs_, encoding_);
                     }});
        f.push_back({"sheen_lut.exr", [this](const std::string& p) {
                         image_rgb32f img(int(lut_.size), int(lut_.size));
                         for (std::uint32_t j = 0; j < lut_.size; ++j)
                             for (std::uint32_t i = 0; i < lut_.size; ++i) img.texel(int(i), int(j))[0] = lut_.at(i, j, 0);
                         write_exr(p, img, lut_attrs_);
                     }});
        return f;
    }
    void report(json_writer& j) const override;

private:
    std::vector<std::pair<std::string, std::string>> attrs_, lut_attrs_;
    /// Level l plus the sun's term against the exact Charlie LD of the source before extraction
    /// (ibl::reference_ld_texel_sum_lobe over its first level of face <= 64; a sampled reference
    /// does not converge on a sun).
    ibl::error_metrics check_level(const bake_context& ctx, int l) const {
        const int n = chain_.size(l);
        const double r = ibl::roughness_mip_policy::linear().roughness(double(l), chain_.levels());
        const ibl::cubemap<float>& src = ctx.whole_source(); // the whole environment: the runtime adds the sun
        const std::vector<std::array<int, 3>> tex = check_texels(n, ctx.qs.ref_grid, ctx.light);
        std::vector<dvec3> dirs;
        for (const auto& t : tex) dirs.push_back(ibl::cube_texel_direction<double>(t[0], t[1], t[2], n));
        const std::vector<dvec3> ref = ibl::reference_ld_texel_sum_lobe<ibl::charlie_lobe>(
            src, level_at_most(src, 64), std::span<const dvec3>(dirs), r, ctx.ex);
        ibl::error_accumulator acc(1e-3 * std::max(ctx.lstats.mean, 1e-30));
        for (std::size_t i = 0; i < tex.size(); ++i)
            acc.add(dvec3(chain_.texel(tex[i][0], tex[i][1], tex[i][2], l)) + sheen_sun_ld(sun_, dirs[i], r), ref[i]);
        return acc.finish();
    }
    void check_lut(pool_executor& ex) {
        const int n = int(lut_.size), g = std::min(16, n);
        std::vector<double> err(std::size_t(g) * std::size_t(g));
        ex(err.size(), [&](std::size_t b, std::size_t e) {
            for (std::size_t k = b; k < e; ++k) {
                const auto i = std::uint32_t((double(k % std::size_t(g)) + 0.5) * n / g), jj = std::uint32_t((double(k / std::size_t(g)) + 0.5) * n / g);
                err[k] = std::fabs(double(lut_.at(i, jj, 0)) - ibl::sheen_albedo(lut_.n_dot_v(i), lut_.roughness(jj)));
            }
        });
        lut_max_abs_ = *std::max_element(err.begin(), err.end());
    }

    ibl::cubemap<float> chain_{1};
    const ibl::disk_light<double>* sun_ = nullptr;
    ibl::dfg_lut lut_;
    ktx2_storage format_ = ktx2_storage::rgba16f;
    ktx2_encoding encoding_;
    std::vector<std::uint32_t> samples_;
    std::vector<ibl::error_metrics> levels_;
    double ms_ = 0.0, check_ms_ = 0.0, lut_max_abs_ = 0.0;
    bool checked_ = true;
};

void sheen_stage::report(json_writer& j) const {
    j.begin_object();
    j.key("files").value("sheen_l{level}_{px,nx,py,ny,pz,nz}.exr, sheen.ktx2, sheen_lut.exr (R = E)");
    j.key("method").value("Charlie NDF LD (N = V = R) by filtered importance sampling of the Charlie lobe, from the source after "
                          "sun extraction (the runtime adds the sun's Charlie term); "
                          "sheen albedo E(n.v, r) with Neubelt's visibility by quadrature");
    j.key("lookup").value("chain: textureLod at lod = r (V - 1) (linear policy); LUT: bilinear at x = n.v, y = r, texel centres (i + 0.5) / N");
    j.key("samples_per_level").begin_array();
    for (const auto s : samples_) j.value(s);
    j.end_array();
    j.key("time_ms").value(ms_);
    j.key("check").begin_object();
    j.key("ran").value(checked_);
    j.key("levels").begin_array();
    for (std::size_t l = 0; l < levels_.size(); ++l)
        j.begin_object().key("level").value(int(l)).key("rel_rmse").value(levels_[l].rel_rmse).key("max_overshoot").value(levels_[l].max_ratio).end_object();
    j.end_array();
    j.key("lut_max_abs_vs_sheen_albedo").value(lut_max_abs_);
    j.key("time_ms").value(check_ms_);
    j.end_object();
    j.end_object();
}

} // namespace

std::unique_ptr<stage> make_sheen_stage() { return std::make_unique<sheen_stage>(); }

} // namespace ibl_bake
