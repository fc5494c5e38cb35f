// tools/ibl-bake/stages/stage_preview.cpp — check: preview.png, a 5 x 2 sphere grid (roughness 0, 0.25,
// 0.5, 0.75, 1 left to right; dielectric top, metal bottom) shaded with the multiple-scattering
// ambient (Fdez-Aguera 2019) from the baked products only (plus an extracted sun as a disk
// light), over a pinhole view of the residual source with the sun's disk drawn analytically;
// orthographic spheres, camera looking away from the brightest direction (spheres lit from the
// front); exposure 0.6 / mean luminance, Reinhard, sRGB.

#include "stages/stages.hpp"
#include "stages/preview_render.hpp"

#include <algorithm>
#include <cmath>

namespace ibl_bake {

namespace {

using namespace preview;

class preview_stage final : public stage {
public:
    const char* key() const override { return "preview"; }
    stage_kind kind() const override { return stage_kind::check; }
    bool enabled(const bake_context& ctx) const override { return !ctx.scene_mode && ctx.chain && ctx.lut; }

    void run(bake_context& ctx) override {
        ss_ = ctx.qs.preview_ss;
        ctx.prog.begin("preview");
        const product_view bp = baked_view(ctx);
        const preview_renderer pr(bp, ctx.source, ctx.light);
        img_ = image_rgb32f(pr.w, pr.h);
        ctx.ex(std::size_t(pr.h), [&](std::size_t b, std::size_t e) {
            for (std::size_t py = b; py < e; ++py)
                for (int px = 0; px < pr.w; ++px) {
                    dvec3 acc(0.0);
                    for (int sy = 0; sy < ss_; ++sy)
                        for (int sx = 0; sx < ss_; ++sx) acc += pr.at(px + (sx + 0.5) / ss_, double(py) + (sy + 0.5) / ss_);
                    acc /= double(ss_ * ss_);
                    float* t = img_.texel(px, int(py));
                    for (int c = 0; c < 3; ++c) t[c] = float(acc[c]);
                }
        });
        png_.op = tonemap::reinhard;
        png_.exposure = float(key_value / std::max(ctx.lstats.mean, 1e-6));
        ms_ = ctx.prog.end();
    }

    std::vector<table_row> rows() const override {
        return {table_row{"preview", "baked products, orthographic spheres",
                          "640x256, " + std::to_string(ss_) + "x" + std::to_string(ss_) + " ss", ms_, fmt("exposure %.3g", png_.exposure)}
                    .compact("spheres (preview.png)", fmt("exposure %.3g", png_.exposure))};
    }
    std::vector<file_out> files() const override {
        return {{"preview.png", [this](const std::string& p) { write_png(p, img_, png_); }}};
    }
    void report(json_writer& j) const override {
        j.begin_object();
        j.key("file").value("preview.png");
        j.key("layout").value("5 x 2 spheres: roughness 0, 0.25, 0.5, 0.75, 1 left to right; dielectric (top), metal "
                              "(bottom); orthographic, camera looking away from the brightest direction");
        j.key("shading").value("multiple-scattering ambient (Fdez-Aguera 2019) from the baked products");
        j.key("exposure").value(png_.exposure);
        j.key("tonemap").value("exposure = 0.6 / mean luminance of the environment (solid-angle weighted), Reinhard x/(1+x), sRGB");
        j.key("time_ms").value(ms_);
        j.end_object();
    }

private:
    int ss_ = 1;
    image_rgb32f img_{1, 1};
    png_options png_;
    double ms_ = 0.0;
};

} // namespace

std::unique_ptr<stage> make_preview_stage() { return std::make_unique<preview_stage>(); }

} // namespace ibl_bake
