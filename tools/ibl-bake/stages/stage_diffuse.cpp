// tools/ibl-bake/stages/stage_diffuse.cpp — the diffuse products.
//   sh          projection of the source cube onto B SH bands (--sh-bands 2..5; a scene plan picks
//               2 or 3; exact texel solid angles, ibl::project_cube), Lambert convolution. sh.json's
//               "radiance" is always the raw projection. A window (--sh-window) applies to the
//               irradiance and shader coefficients only, which are then named *_windowed:
//               auto (default): the weakest Hanning window keeping E >= 0 (ibl::sh_auto_window)
//               whenever the raw irradiance's minimum is negative in some channel, however little
//               (so the product never holds negative light); if no window can (a channel whose
//               mean radiance is negative), that channel's coefficients are clamped to 0 (E = 0
//               there); none; or a Hanning width W. The report gives the window or clamp and the
//               minimum E before and after.
//   irradiance  an irradiance cubemap of face --irradiance-size (default 32; a scene plan's map size)
//               by texel moments over level 0 (ibl::irradiance_texel_moments: exact for blocks
//               above the horizon). In the full bake beside SH; the runtime's diffuse product.
// Checks of both: E at the texel centres of an 8 x 8-per-face cube against the brute-force sum
// over every texel of the first source level of face <= 128; when a sun was extracted, also the
// runtime's E (the product plus the sun's cap irradiance) against the brute force over the
// source before extraction (what a renderer gets from the whole environment).

#include "stages/stages.hpp"

#include "io/cube_layout.hpp"

#include <algorithm>
#include <cmath>

#include <ibl/env/cube_geometry.hpp>
#include <ibl/bake/irradiance.hpp>
#include <functional>
#include <ibl/sh/convolve.hpp>
#include <ibl/sh/project.hpp>
#include <ibl/sh/window.hpp>

namespace ibl_bake {

namespace {

constexpr int check_grid = 8;      ///< check normals: texel centres of an 8 x 8-per-face cube
constexpr int brute_max_face = 128; ///< brute-force irradiance over a source level of face <= this

double min3(const dvec3& v) { return std::min({v.x, v.y, v.z}); }

/// The brute-force level's largest face: --checks fast sums over a level of face <= 64.
int brute_face(const bake_context& ctx) { return ctx.opt.checks == check_mode::fast ? 64 : brute_max_face; }

std::vector<dvec3> check_normals() {
    std::vector<dvec3> normals;
    for (int f = 0; f < 6; ++f)
        for (int y = 0; y < check_grid; ++y)
            for (int x = 0; x < check_grid; ++x) normals.push_back(ibl::cube_texel_direction<double>(f, x, y, check_grid));
    return normals;
}

/// Mean and largest relative error of the RGB sum of E against the brute-force reference.
struct irradiance_check {
    int level = 0, face = 0;
    std::size_t normals = 0;
    double mean_rel = 0.0, max_rel = 0.0, mean_rel_raw = 0.0, max_rel_raw = 0.0, ms = 0.0;
};

template <class F> void accumulate(irradiance_check& c, const std::vector<dvec3>& normals, const std::vector<dvec3>& ref,
                                   F&& e_at, double& mean, double& max) {
    mean = max = 0.0;
    for (std::size_t i = 0; i < normals.size(); ++i) {
        const double er = ref[i].x + ref[i].y + ref[i].z;
        const dvec3 es = e_at(normals[i]);
        const double d = std::fabs(es.x + es.y + es.z - er);
        const double rel = d == 0.0 ? 0.0 : d / std::max(er, 1e-30); // 0 / 0 (a black map) is no error
        mean += rel / double(normals.size());
        max = std::max(max, rel);
    }
    c.normals = normals.size();
}

const char* sh_convention =
    "Real spherical harmonics, orthonormal over the sphere, without the Condon-Shortley phase, 'bands' bands "
    "(bands^2 coefficients, index k = l*l + l + m; bands 3 and 4 as include/ibl/sh/basis.hpp). Basis on a unit direction (x, y, z) of the world frame: "
    "Y0 = 0.282095 (1/(2 sqrt(pi))); Y1 = 0.488603 y; Y2 = 0.488603 z; Y3 = 0.488603 x "
    "(sqrt(3/(4 pi))); Y4 = 1.092548 x y; Y5 = 1.092548 y z (sqrt(15/pi)/2); "
    "Y6 = 0.315392 (3 z^2 - 1) (sqrt(5/pi)/4); Y7 = 1.092548 x z; Y8 = 0.546274 (x^2 - y^2) (sqrt(15/pi)/4). "
    "Frame: right-handed, +Y up; lat-long images map direction (x, y, z) to u = 0.5 + atan2(z, x)/(2 pi), "
    "v = 0.5 + asin(y)/pi, with the top image row at +Y (v = 1); cubemap faces +X, -X, +Y, -Y, +Z, -Z in the "
    "OpenGL orientation. 'radiance' holds L_k = integral L(w) Y_k(w) dw (linear RGB, always the raw "
    "projection); 'irradiance' holds E_k = A_l L_k with A_0 = pi, A_1 = 2 pi/3, A_2 = pi/4, "
    "A_3 = 0, A_4 = -pi/24 (after the window if one was applied: then named 'irradiance_windowed'), so that "
    "E(n) = sum_k E_k Y_k(n) = integral L(w) max(0, n.w) dw; 'irradiance_over_pi_shader' holds c_k = E_k K_k / pi "
    "for the polynomial form E(n)/pi = sum_k c_k p_k(n) with p = (1, y, z, x, x y, y z, 3 z^2 - 1, x z, x^2 - y^2) "
    "for the first 9 (the higher bands' polynomials as basis.hpp; windowed: 'irradiance_over_pi_shader_windowed') "
    "(multiply by the diffuse albedo for Lambert).";

/// The runtime's E against brute force over the whole source, when a sun was extracted.
void check_with_sun(const bake_context& ctx, const std::vector<dvec3>& normals, irradiance_check& c,
                    const std::function<dvec3(const dvec3&)>& e_product, double& mean, double& max) {
    mean = max = 0.0;
    if (!ctx.sun) return;
    const ibl::cubemap<float>& whole = ctx.whole_source();
    const std::vector<dvec3> ref = texel_sum_irradiance(whole, level_at_most(whole, brute_face(ctx)), normals, ctx.ex);
    accumulate(c, normals, ref, [&](const dvec3& n) { return e_product(n) + ibl::disk_light_irradiance(n, *ctx.sun); }, mean, max);
}

class sh_stage final : public stage {
public:
    const char* key() const override { return "sh"; }
    stage_kind kind() const override { return stage_kind::product; }
    const char* category() const override { return "diffuse"; }
    bool enabled(const bake_context& ctx) const override { return ctx.plan.diffuse.kind == ibl::diffuse_product::sh || !ctx.scene_mode; }
    double product_ms() const override { return ms_; }
    double check_ms() const override { return checked_ ? c_.ms : 0.0; }

    void run(bake_context& ctx) override {
        bands_ = ctx.opt.sh_bands > 0 ? ctx.opt.sh_bands : ctx.plan.diffuse.sh_bands == 2 ? 2 : 3;
        window_ = ctx.opt.sh_window;
        filament_ = ctx.opt.preset == bake_preset::filament;
        texels_ = 6 * ctx.source.size(0) * ctx.source.size(0);
        ctx.prog.begin("sh");
        switch (bands_) {
        case 2: project<2>(ctx); break;
        case 4: project<4>(ctx); break;
        case 5: project<5>(ctx); break;
        default: project<3>(ctx); break;
        }
        irr_ = ibl::sh_irradiance(rad_);
        shader_ = ibl::sh_shader_coeffs(rad_, ibl::sh_shader_output::irradiance_over_pi);
        ms_ = ctx.prog.end();
        if (ctx.diffuse.kind != ibl::diffuse_product::irradiance_map) { // the runtime's diffuse product
            ctx.diffuse.kind = ibl::diffuse_product::sh;
            ctx.diffuse.bands = bands_;
            ctx.diffuse.radiance = rad_;
            ctx.diffuse.shader_over_pi = shader_;
        }
        conventions_ = product_conventions(ctx, "sh", "real SH radiance coefficients; E(n) and E(n)/pi reconstructed as "
                                                      "'convention' says");
        checked_ = ctx.opt.checks != check_mode::none;
        if (checked_) check(ctx);
    }

    std::vector<table_row> rows() const override {
        const std::string method = std::to_string(bands_) + "-band projection, " +
                                   (windowed_ ? fmt("Hanning window W=%.3g", width_) : std::string("no window")) +
                                   (clamped_ ? ", negative channels clamped" : "");
        std::string err = fmt2("mean rel %.3g, max rel %.3g", c_.mean_rel, c_.max_rel) +
                          fmt2(", min E %.3g -> %.3g", min3(min_before_), min3(min_after_));
        if (sun_) err += fmt2("; + sun vs whole: mean rel %.3g, max rel %.3g", sun_mean_, sun_max_);
        const std::string brief = std::to_string(bands_) + "-band SH" + (windowed_ ? fmt(", window %.3g", width_) : std::string());
        if (!checked_) return {table_row{"sh irradiance", method, std::to_string(texels_) + " texels", ms_, "not checked"}.compact(brief, "not checked")};
        return {table_row{"sh irradiance", method, std::to_string(texels_) + " texels", ms_, err}
                    .compact(brief, fmt2("max rel %.3g (mean %.3g)", c_.max_rel, c_.mean_rel))
                    .alarm(c_.max_rel, alarm_relative,
                           "few SH bands cannot hold sharp light (their limit, not a bake defect): use the irradiance map")};
    }
    std::vector<file_out> files() const override {
        std::vector<file_out> f{{"sh.json", [this](const std::string& p) { write_text(p, sh_json()); }}};
        if (filament_) f.push_back({"sh.txt", [this](const std::string& p) { write_text(p, filament_sh_txt()); }});
        return f;
    }
    void report(json_writer& j) const override;

private:
    /// Filament's cmgen SH text (--preset filament): one line "(r, g, b); // L{l}{m}" per
    /// coefficient, the shader coefficients of E / pi for its Irradiance_SphericalHarmonics
    /// polynomial (1, y, z, x, y x, y z, 3 z^2 - 1, z x, x^2 - y^2), i.e. sh.json's
    /// irradiance_over_pi_shader(_windowed), in the mirrored frame the preset bakes.
    std::string filament_sh_txt() const {
        static const char* names[9] = {"L00", "L1-1", "L10", "L11", "L2-2", "L2-1", "L20", "L21", "L22"};
        std::string t;
        for (int k = 0; k < std::min(9, bands_ * bands_); ++k) {
            char buf[160];
            std::snprintf(buf, sizeof buf, "(%.9g, %.9g, %.9g); // %s\n", shader_[k].x, shader_[k].y, shader_[k].z, names[k]);
            t += buf;
        }
        return t;
    }
    template <int B> void project(const bake_context& ctx) {
        const ibl::cubemap<float>& src = ctx.source;
        const ibl::sh_coeffs<double, B> raw = ibl::project_cube<B>(
            src.size(0), [&](int f, int x, int y) { return dvec3(src.texel(f, x, y, 0)); }, ctx.ex);
        ibl::sh_coeffs<double, B> rad = raw;
        min_before_ = min_after_ = ibl::sh_min_irradiance(raw, 4096).value;
        const bool automatic = window_.k == sh_window_choice::kind::automatic;
        bool apply = window_.k == sh_window_choice::kind::hanning;
        if (automatic) apply = min3(min_before_) < 0.0;
        if (apply && automatic) {
            const ibl::sh_auto_window_result<double, B> win = ibl::sh_auto_window(raw);
            windowed_ = std::isfinite(win.width);
            width_ = win.width;
            rad = win.radiance;
            if (!win.ok) // no window keeps E >= 0: clamp the channels that stay negative to E = 0
                for (int c = 0; c < 3; ++c)
                    if (!(win.min_after[c] >= 0.0)) {
                        clamped_ = true;
                        for (int k = 0; k < B * B; ++k) rad[k][c] = 0.0;
                    }
        } else if (apply) {
            width_ = window_.width;
            windowed_ = true;
            rad = ibl::sh_apply_window(raw, ibl::sh_window_kind::hanning, width_);
        }
        if (windowed_ || clamped_) min_after_ = ibl::sh_min_irradiance(rad, 4096).value;
        for (int k = 0; k < B * B; ++k) raw_[k] = raw[k], rad_[k] = rad[k];
    }
    void check(bake_context& ctx);
    std::string sh_json() const;

    std::vector<std::pair<std::string, std::string>> conventions_;
    int bands_ = 3, texels_ = 0;
    sh_window_choice window_;
    bool windowed_ = false, clamped_ = false, sun_ = false, filament_ = false, checked_ = true;
    double width_ = 0.0, ms_ = 0.0, sun_mean_ = 0.0, sun_max_ = 0.0;
    dvec3 min_before_{0.0}, min_after_{0.0};
    sh5 raw_{}, rad_{}, irr_{}, shader_{};
    irradiance_check c_;
};

void sh_stage::check(bake_context& ctx) {
    const auto t0 = std::chrono::steady_clock::now();
    ctx.prog.begin("check sh");
    c_.level = level_at_most(ctx.source, brute_face(ctx));
    c_.face = ctx.source.size(c_.level);
    const std::vector<dvec3> normals = check_normals();
    const std::vector<dvec3> ref = texel_sum_irradiance(ctx.source, c_.level, normals, ctx.ex);
    accumulate(c_, normals, ref, [&](const dvec3& n) { return ibl::sh_irradiance_at(rad_, n); }, c_.mean_rel, c_.max_rel);
    accumulate(c_, normals, ref, [&](const dvec3& n) { return ibl::sh_irradiance_at(raw_, n); }, c_.mean_rel_raw, c_.max_rel_raw);
    sun_ = ctx.sun.has_value();
    check_with_sun(ctx, normals, c_, [&](const dvec3& n) { return glm::max(ibl::sh_irradiance_at(rad_, n), dvec3(0.0)); }, sun_mean_,
                   sun_max_);
    ctx.prog.end();
    c_.ms = ms_since(t0);
}

std::string sh_stage::sh_json() const {
    const int count = bands_ * bands_;
    const std::string suffix = windowed_ ? "_windowed" : "";
    json_writer j;
    j.begin_object();
    j.key("bands").value(bands_);
    j.key("radiance");
    json_triples(j, raw_, count);
    j.key("irradiance" + suffix);
    json_triples(j, irr_, count);
    j.key("irradiance_over_pi_shader" + suffix);
    json_triples(j, shader_, count);
    j.key("convention").value(sh_convention);
    j.key("conventions").begin_object();
    for (const auto& [k, v] : conventions_) j.key(k).value(v);
    j.end_object();
    j.key("window").begin_object();
    j.key("applied").value(windowed_);
    j.key("kind").value("hanning");
    if (windowed_) j.key("width").value(width_);
    else j.key("width").null();
    j.key("choice").value(to_string(window_));
    j.key("rule").value("'radiance' is the raw projection. --sh-window auto: the weakest Hanning window keeping E >= 0 "
                        "(ibl::sh_auto_window) whenever the raw irradiance's minimum is negative in a channel (a channel no window "
                        "can make non-negative is clamped to 0); none; or a width W. A window scales band l of the irradiance and "
                        "shader coefficients (then named *_windowed)");
    j.key("clamp_applied").value(clamped_);
    j.key("min_irradiance_before").begin_array().value(min_before_.x).value(min_before_.y).value(min_before_.z).end_array();
    j.key("min_irradiance_after").begin_array().value(min_after_.x).value(min_after_.y).value(min_after_.z).end_array();
    j.end_object();
    j.end_object();
    return j.str() + "\n";
}

void sh_stage::report(json_writer& j) const {
    j.begin_object();
    j.key("file").value("sh.json");
    j.key("method").value(std::to_string(bands_) + "-band projection of the source cube (exact texel solid angles), Lambert convolution");
    j.key("cost").begin_object().key("bands").value(bands_).key("texels").value(texels_).end_object();
    j.key("time_ms").value(ms_);
    j.key("window_choice").value(to_string(window_));
    j.key("window_applied").value(windowed_);
    if (windowed_) j.key("window_width").value(width_);
    else j.key("window_width").null();
    j.key("clamp_applied").value(clamped_);
    j.key("min_irradiance_before").value(min3(min_before_));
    j.key("min_irradiance_after").value(min3(min_after_));
    if (!checked_) { // --checks none
        j.key("check").begin_object().key("ran").value(false).end_object();
        j.end_object();
        return;
    }
    j.key("check").begin_object();
    j.key("ran").value(checked_);
    j.key("reference").value("brute-force cosine integration over every texel of source level " + std::to_string(c_.level) + " (" +
                             std::to_string(c_.face) + "^2 faces)");
    j.key("normals").value(c_.normals);
    j.key("mean_rel").value(c_.mean_rel);
    j.key("max_rel").value(c_.max_rel);
    j.key("mean_rel_unwindowed").value(c_.mean_rel_raw);
    j.key("max_rel_unwindowed").value(c_.max_rel_raw);
    if (sun_) j.key("with_sun_vs_whole_source").begin_object().key("mean_rel").value(sun_mean_).key("max_rel").value(sun_max_).end_object();
    j.key("time_ms").value(c_.ms);
    j.end_object();
    j.end_object();
}

class irradiance_stage final : public stage {
public:
    const char* key() const override { return "irradiance"; }
    stage_kind kind() const override { return stage_kind::product; }
    const char* category() const override { return "diffuse"; }
    bool enabled(const bake_context& ctx) const override {
        return ctx.plan.diffuse.kind == ibl::diffuse_product::irradiance_map || (!ctx.scene_mode && ctx.opt.irradiance_size > 0);
    }
    double product_ms() const override { return ms_; }
    double check_ms() const override { return checked_ ? c_.ms : 0.0; }

    void run(bake_context& ctx) override {
        size_ = ctx.plan.diffuse.kind == ibl::diffuse_product::irradiance_map ? ctx.plan.diffuse.map_size : ctx.opt.irradiance_size;
        ctx.prog.begin("irradiance map");
        ctx.diffuse.kind = ibl::diffuse_product::irradiance_map;
        ctx.diffuse.map = ibl::irradiance_cubemap_texel_moments(ctx.source, size_, max_face_, ctx.ex);
        ms_ = ctx.prog.end();
        map_ = &ctx.diffuse.map;
        format_ = ctx.opt.ktx2_format;
        encoding_ = ktx2_encoding_of(ctx.opt);
        attrs_ = product_conventions(ctx, "irradiance", "texel holds the irradiance E(n) (not E/pi) for the normal n through "
                                                        "it; diffuse = albedo E(n) / pi");
        checked_ = ctx.opt.checks != check_mode::none;
        if (!checked_) return;
        const auto t0 = std::chrono::steady_clock::now();
        c_.level = level_at_most(ctx.source, brute_face(ctx));
        c_.face = ctx.source.size(c_.level);
        const std::vector<dvec3> normals = check_normals();
        const std::vector<dvec3> ref = texel_sum_irradiance(ctx.source, c_.level, normals, ctx.ex);
        auto e = [&](const dvec3& n) { return dvec3(map_->radiance(fvec3(n), 0.0f)); };
        accumulate(c_, normals, ref, e, c_.mean_rel, c_.max_rel);
        sun_ = ctx.sun.has_value();
        check_with_sun(ctx, normals, c_, e, sun_mean_, sun_max_);
        c_.ms = ms_since(t0);
    }

    std::vector<table_row> rows() const override {
        std::string err = fmt2("mean rel %.3g, max rel %.3g", c_.mean_rel, c_.max_rel);
        if (sun_) err += fmt2("; + sun vs whole: mean rel %.3g, max rel %.3g", sun_mean_, sun_max_);
        const std::string cost = std::to_string(size_) + "^2, blocks <= " + std::to_string(max_face_) + "^2";
        if (!checked_) return {table_row{"irradiance map", "texel moments over level 0", cost, ms_, "not checked"}.compact("texel moments", "not checked")};
        return {table_row{"irradiance map", "texel moments over level 0", cost, ms_, err}
                    .compact("texel moments", fmt2("max rel %.3g (mean %.3g)", c_.max_rel, c_.mean_rel))
                    .alarm(c_.max_rel, alarm_relative, "the map is > 5% off the brute-force integral: raise --irradiance-size")};
    }
    std::vector<file_out> files() const override {
        std::vector<file_out> f;
        for (int face = 0; face < 6; ++face)
            f.push_back({std::string("irradiance_") + face_names[face] + ".exr",
                         [this, face](const std::string& p) { write_exr(p, face_image(*map_, face, 0), attrs_); }});
        f.push_back({"irradiance.ktx2", [this](const std::string& p) {
                         write_ktx2_cubemap(p, cubemap_to_rgb32f(*map_), ktx2_format_of(format_), "ibl-bake " + version_string(),
                                            attrs_, encoding_);
                     }});
        return f;
    }
    void report(json_writer& j) const override {
        j.begin_object();
        j.key("files").value("irradiance_{px,nx,py,ny,pz,nz}.exr, irradiance.ktx2");
        j.key("method").value("irradiance cubemap by texel moments over source level 0 (ibl::irradiance_cubemap_texel_moments); texels hold E");
        j.key("cost").begin_object().key("size").value(size_).key("block_face").value(max_face_).end_object();
        j.key("time_ms").value(ms_);
        if (!checked_) { // --checks none
            j.key("check").begin_object().key("ran").value(false).end_object();
            j.end_object();
            return;
        }
        j.key("check").begin_object();
        j.key("ran").value(checked_);
        j.key("reference").value("brute-force cosine integration over every texel of source level " + std::to_string(c_.level));
        j.key("normals").value(c_.normals).key("mean_rel").value(c_.mean_rel).key("max_rel").value(c_.max_rel);
        if (sun_) j.key("with_sun_vs_whole_source").begin_object().key("mean_rel").value(sun_mean_).key("max_rel").value(sun_max_).end_object();
        j.key("time_ms").value(c_.ms);
        j.end_object();
        j.end_object();
    }

private:
    int size_ = 32, max_face_ = 32;
    ktx2_storage format_ = ktx2_storage::rgba16f;
    ktx2_encoding encoding_;
    std::vector<std::pair<std::string, std::string>> attrs_;
    const ibl::cubemap<float>* map_ = nullptr;
    double ms_ = 0.0, sun_mean_ = 0.0, sun_max_ = 0.0;
    bool sun_ = false, checked_ = true;
    irradiance_check c_;
};

} // namespace

std::unique_ptr<stage> make_sh_stage() { return std::make_unique<sh_stage>(); }
std::unique_ptr<stage> make_irradiance_stage() { return std::make_unique<irradiance_stage>(); }

} // namespace ibl_bake
