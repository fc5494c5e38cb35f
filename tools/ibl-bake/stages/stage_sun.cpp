// tools/ibl-bake/stages/stage_sun.cpp — the sun as a light. With --extract-sun auto (default) or on, the
// source cube is searched for a compact bright region (ibl::extract_sun_in_place: the connected
// texels around the peak above max(50 x the median, 1e-3 x the peak) luminance, accepted when
// their solid angle is <= 0.01 sr and they carry >= 20% of the irradiance facing them). A found
// sun is removed (filled from its surroundings, mips rebuilt) and written to lights.json as a
// disk light; every product is then of the residual, and the runtime adds the sun back
// (shade.hpp disk_light: cap irradiance and specular; --lookup's specular adds its exact LD term).
// lights.json is written in every case (an empty list, with the reason, when none was found).

#include "stages/stages.hpp"

#include <ibl/core/color.hpp>
#include <ibl/env/sun_extract.hpp>

namespace ibl_bake {

namespace {

class sun_stage final : public stage {
public:
    const char* key() const override { return "sun"; }
    stage_kind kind() const override { return stage_kind::product; }
    const char* category() const override { return "source"; }
    /// auto: the full bake only (a scene plan's error tables were measured without extraction).
    bool enabled(const bake_context& ctx) const override {
        return ctx.opt.extract_sun == sun_extraction::on || (ctx.opt.extract_sun == sun_extraction::automatic && !ctx.scene_mode);
    }
    double product_ms() const override { return ms_; }

    void run(bake_context& ctx) override {
        ctx.prog.begin("sun");
        ibl::cubemap<float> residual = ctx.source;
        ext_ = ibl::extract_sun_in_place(residual, ibl::sun_extract_options{}, ctx.ex);
        if (ext_.found()) {
            ctx.original = std::move(ctx.source);
            ctx.source = std::move(residual);
            ctx.sun = ibl::disk_light<double>{dvec3(ext_.direction), double(ext_.solid_angle), dvec3(ext_.radiance)};
        }
        ms_ = ctx.prog.end();
        required_ = ctx.opt.extract_sun == sun_extraction::on;
    }

    std::vector<table_row> rows() const override {
        const std::string what = ext_.found()
                                     ? fmt2("dir (%.3f, %.3f", ext_.direction.x, ext_.direction.y) + fmt(", %.3f)", ext_.direction.z) +
                                           fmt(", omega %.3g sr", ext_.solid_angle) + fmt(", E %.4g", ibl::luminance(dvec3(ext_.irradiance))) +
                                           fmt(" (%.0f%% of E facing it)", 100.0 * ext_.share)
                                     : std::string("none: ") + ext_.reason();
        const std::string brief = ext_.found() ? fmt("E %.4g", ibl::luminance(dvec3(ext_.irradiance))) + fmt(", %.0f%% of E facing it", 100.0 * ext_.share) +
                                                     fmt(", %.3g sr", ext_.solid_angle)
                                               : std::string("none: ") + ext_.reason();
        return {table_row{"sun", "extracted as a disk light (lights.json)", std::to_string(ext_.region_texels) + " texels", ms_, what}
                    .compact("disk light, lights.json", brief)};
    }
    std::vector<std::string> notes_after() const override {
        if (required_ && !ext_.found()) return {std::string("warning: --extract-sun on, but no sun was found: ") + ext_.reason()};
        return {};
    }
    std::vector<file_out> files() const override {
        return {{"lights.json", [this](const std::string& p) { write_text(p, lights_json()); }}};
    }
    void report(json_writer& j) const override {
        j.begin_object();
        j.key("found").value(ext_.found()).key("reason").value(ext_.reason());
        j.key("rule").value("connected texels around the peak above max(50 x median, 1e-3 x peak) luminance; a sun when their solid "
                            "angle <= 0.01 sr and they carry >= 20% of the irradiance facing them (ibl::extract_sun_in_place)");
        j.key("share").value(ext_.share).key("region_texels").value(ext_.region_texels);
        j.key("region_solid_angle").value(double(ext_.region_solid_angle));
        j.key("peak_luminance").value(ext_.peak_luminance).key("median_luminance").value(ext_.median_luminance);
        j.key("time_ms").value(ms_);
        j.end_object();
    }

private:
    std::string lights_json() const {
        json_writer j;
        j.begin_object();
        j.key("convention").value("direction: unit, towards the light, in the frame of sh.json; irradiance: E at normal incidence "
                                  "(linear RGB, not E/pi); solid_angle in sr of the equivalent uniform disk; radiance = irradiance / "
                                  "(pi sin^2 angular_radius). The baked products hold the environment without this light.");
        j.key("lights").begin_array();
        if (ext_.found()) {
            j.begin_object();
            j.key("type").value("sun");
            j.key("direction").begin_array().value(ext_.direction.x).value(ext_.direction.y).value(ext_.direction.z).end_array();
            j.key("irradiance").begin_array().value(ext_.irradiance.x).value(ext_.irradiance.y).value(ext_.irradiance.z).end_array();
            j.key("solid_angle").value(double(ext_.solid_angle));
            j.key("angular_radius").value(double(ext_.angular_radius));
            j.key("radiance").begin_array().value(ext_.radiance.x).value(ext_.radiance.y).value(ext_.radiance.z).end_array();
            j.end_object();
        }
        j.end_array();
        if (!ext_.found()) j.key("none_because").value(ext_.reason());
        j.end_object();
        return j.str() + "\n";
    }

    ibl::sun_extraction<float> ext_;
    double ms_ = 0.0;
    bool required_ = false;
};

} // namespace

std::unique_ptr<stage> make_sun_stage() { return std::make_unique<sun_stage>(); }

} // namespace ibl_bake
