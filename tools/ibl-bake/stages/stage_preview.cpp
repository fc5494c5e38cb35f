// tools/ibl-bake/stages/stage_preview.cpp — check: preview.png, a 5 x 2 sphere grid (roughness 0, 0.25,
// 0.5, 0.75, 1 left to right; dielectric top, metal bottom) shaded with the multiple-scattering
// ambient (Fdez-Aguera 2019) from the baked products only (plus an extracted sun as a disk
// light), over a pinhole view of the residual source with the sun's disk drawn analytically;
// orthographic spheres, camera looking away from the brightest direction (spheres lit from the
// front); exposure 0.6 / mean luminance, Reinhard, sRGB.

#include "stages/stages.hpp"

#include <algorithm>
#include <cmath>

namespace ibl_bake {

namespace {

constexpr int cell = 128;          ///< pixels per sphere cell
constexpr int cols = 5, rows_ = 2;
constexpr double key_value = 0.6;  ///< exposure: key / mean luminance of the environment
constexpr double hfov_deg = 90.0;

struct camera {
    dvec3 fwd, right, up;
};
camera make_camera(const dvec3& light) {
    dvec3 f(-light.x, 0.0, -light.z);
    f = glm::dot(f, f) > 1e-12 ? glm::normalize(f) : dvec3(0.0, 0.0, -1.0);
    const dvec3 right = glm::normalize(glm::cross(f, dvec3(0.0, 1.0, 0.0)));
    return {f, right, glm::cross(right, f)};
}

struct preview_material {
    dvec3 base_color;
    double metallic;
};
const preview_material k_materials[rows_] = {{dvec3(0.8), 0.0}, {dvec3(0.95, 0.64, 0.54), 1.0}};

class preview_renderer {
public:
    preview_renderer(const product_view& bp, const ibl::cubemap<float>& source, const dvec3& light)
        : bp_(bp), source_(source), cam_(make_camera(light)) {
        for (int j = 0; j < rows_; ++j)
            for (int i = 0; i < cols; ++i) {
                ibl::pbr_material<double> m;
                m.base_color = k_materials[j].base_color;
                m.metallic = k_materials[j].metallic;
                m.roughness = 0.25 * i;
                shaders_[j][i] = ibl::pbr_shader<double>::from(m, true);
            }
    }

    /// Radiance at the sub-pixel position (fx, fy) of the w x h image.
    dvec3 at(double fx, double fy) const {
        const double radius = 0.45 * cell;
        const int ci = std::min(int(fx) / cell, cols - 1), cj = std::min(int(fy) / cell, rows_ - 1);
        const double lx = (fx - (ci + 0.5) * cell) / radius, ly = -(fy - (cj + 0.5) * cell) / radius;
        const double d2 = lx * lx + ly * ly;
        if (d2 < 1.0) { // orthographic sphere
            const dvec3 n = lx * cam_.right + ly * cam_.up - std::sqrt(1.0 - d2) * cam_.fwd;
            const dvec3 v = -cam_.fwd;
            return bp_.shade(shaders_[cj][ci], n, v);
        }
        const double tan_h = std::tan(0.5 * hfov_deg * ibl::pi_v<double> / 180.0), tan_v = tan_h * double(h) / double(w);
        const double ndc_x = 2.0 * fx / w - 1.0, ndc_y = 1.0 - 2.0 * fy / h;
        const dvec3 d = glm::normalize(cam_.fwd + ndc_x * tan_h * cam_.right + ndc_y * tan_v * cam_.up);
        // The residual's level 0 (the chain's level 0, what a runtime has) plus the extracted sun's
        // disk drawn analytically: its radiance where d is inside the cap, d.dir >= cos r,
        // 1 - cos r = omega / (2 pi). Without extraction the residual is the whole source.
        dvec3 l = dvec3(source_.radiance(fvec3(d), 0.0f));
        if (bp_.sun && glm::dot(d, bp_.sun->direction) >= 1.0 - ibl::cap_one_minus_cos(bp_.sun->solid_angle))
            l += bp_.sun->radiance;
        return l;
    }

    static constexpr int w = cols * cell, h = rows_ * cell;

private:
    const product_view& bp_;
    const ibl::cubemap<float>& source_;
    camera cam_;
    ibl::pbr_shader<double> shaders_[rows_][cols];
};

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
