// tools/ibl-bake/stages/stage_source.cpp — the source: the input lat-long (Radiance .hdr, OpenEXR) or the
// built-in sky + sun, or a cube input (a cross, six faces, a KTX2 cubemap: source_input.hpp), baked
// to a cube of the plan's source size by k x k supersampling with exact spherical box mips
// (ibl::bake_cubemap: stages.hpp bake_source).

#include "stages/stages.hpp"

#include "io/source_input.hpp"
#include "io/input_guard.hpp"

#include <algorithm>
#include <cmath>
#include <span>

#include <ibl/core/color.hpp>
#include <ibl/env/convert.hpp>
#include <ibl/env/cube_geometry.hpp>

namespace ibl_bake {

namespace {

luminance_stats source_luminance(const ibl::cubemap<float>& cube) {
    const int n = cube.size(0);
    double sum = 0.0, logsum = 0.0, wsum = 0.0;
    for (int f = 0; f < 6; ++f)
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
                const double w = ibl::cube_texel_solid_angle<double>(x, y, n);
                const double l = ibl::luminance(dvec3(cube.texel(f, x, y, 0)));
                sum += w * l;
                logsum += w * std::log(1e-4 + l);
                wsum += w;
            }
    return {sum / wsum, std::exp(logsum / wsum)};
}

class source_stage final : public stage {
public:
    const char* key() const override { return "source"; }
    stage_kind kind() const override { return stage_kind::product; }
    const char* category() const override { return "source"; }
    bool enabled(const bake_context&) const override { return true; }
    double product_ms() const override { return cube_ms_; }

    void run(bake_context& ctx) override {
        if (!ctx.opt.input.empty()) read_input(ctx);
        else ctx.src.name = "built-in sky + sun (ibl::make_default_sky)";
        if (ctx.opt.mirror) mirror_source(ctx.src);
        size_ = ctx.plan.source_size;
        ctx.prog.begin("source cube");
        ctx.source = bake_source(ctx.src, size_, ctx.qs.bake_k, ctx.ex, &k_);
        cube_ms_ = ctx.prog.end();
        ctx.light = brightest_direction(ctx.source, 0);
        ctx.lstats = source_luminance(ctx.source);
        src_ = &ctx.src;
        light_ = ctx.light;
        lstats_ = ctx.lstats;
    }

    std::vector<table_row> rows() const override {
        std::vector<table_row> r;
        if (!src_->analytic)
            r.push_back(table_row{"input", src_->rr.format + " " + src_->layout + " " + std::to_string(src_->width) + "x" + std::to_string(src_->height),
                                  std::to_string(src_->rr.negative_values) + " negative values clamped", read_ms_, "-"}
                            .compact(src_->rr.format + " " + src_->layout, std::to_string(src_->width) + "x" + std::to_string(src_->height) + ", " +
                                                                               std::to_string(src_->rr.negative_values) + " negatives clamped"));
        r.push_back(table_row{"source cube", "supersampled bake + box mips",
                              std::to_string(size_) + "^2, " + std::to_string(k_) + "x" + std::to_string(k_) + " sub-samples", cube_ms_, "-"}
                        .compact("supersampled bake", std::to_string(size_) + "^2, " + std::to_string(k_) + "x" + std::to_string(k_) + " sub-samples"));
        return r;
    }

    void report(json_writer& j) const override {
        j.begin_object();
        j.key("kind").value(src_->analytic ? "analytic" : src_->cube ? "cube" : "latlong");
        if (!src_->analytic) j.key("layout").value(src_->layout);
        j.key("mirrored").value(src_->mirrored);
        j.key("name").value(src_->name);
        if (!src_->analytic) {
            j.key("format").value(src_->rr.format);
            j.key("width").value(src_->width);
            j.key("height").value(src_->height);
            j.key("negative_values_clamped").value(src_->rr.negative_values);
            j.key("max_value").value(src_->rr.max_value);
            j.key("values_clamped").value(src_->values_clamped).key("clamp_bound").value(double(radiance_clamp_bound));
            j.key("read_time_ms").value(read_ms_);
        }
        j.key("method").value("k x k supersampled bake to a cubemap (ibl::bake_cubemap), exact spherical box mips");
        j.key("cost").begin_object().key("face_size").value(size_).key("subsamples_per_axis").value(k_).end_object();
        j.key("time_ms").value(cube_ms_);
        j.key("mean_luminance").value(lstats_.mean);
        j.key("log_average_luminance").value(lstats_.log_average);
        j.key("brightest_direction").begin_array().value(light_.x).value(light_.y).value(light_.z).end_array();
        j.end_object();
    }

private:
    void read_input(bake_context& ctx) {
        ctx.prog.begin("read input");
        read_source(ctx.opt, ctx.src);
        read_ms_ = ctx.prog.end();
    }

    const source_env* src_ = nullptr;
    int size_ = 1, k_ = 1;
    double read_ms_ = 0.0, cube_ms_ = 0.0;
    dvec3 light_{0.0};
    luminance_stats lstats_;
};

} // namespace

std::unique_ptr<stage> make_source_stage() { return std::make_unique<source_stage>(); }

} // namespace ibl_bake
