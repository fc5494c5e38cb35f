#pragma once
// tools/ibl-bake/stages/stage.hpp — the interface of a bake stage and the context the stages share.
//
// Each stage (stages.hpp lists them; pipeline.hpp runs them)
//   * decides from the plan whether it runs (enabled),
//   * computes its product into the shared bake_context, then checks it against its reference
//     (run: product time and check time are kept apart),
//   * returns its rows of the printed table, free-text notes, the files it writes and its section
//     of report.json.
//
// Every step is deterministic (the library's integrators are partition-independent and the
// stages' own loops compute each item independently), so the outputs do not depend on --threads.

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <ibl/env/analytic.hpp>
#include <ibl/env/cubemap.hpp>
#include <ibl/env/latlong.hpp>
#include <ibl/bake/dfg_lut.hpp>
#include <ibl/bake/lobe_fit.hpp>
#include <ibl/bake/lobe_moments.hpp>
#include <ibl/bake/plan.hpp>
#include <ibl/sh/basis.hpp>
#include <ibl/runtime/shade.hpp>

#include "stages/bake_exec.hpp"
#include "options/bake_options.hpp"
#include "io/image_io.hpp"
#include "io/json.hpp"
#include "io/source_input.hpp"
#include "report/report_table.hpp"

namespace ibl_bake {

using dvec3 = ibl::vec3<double>;
using fvec3 = ibl::vec3<float>;
using sh3 = ibl::sh_coeffs<double, 3>;
using sh5 = ibl::sh_coeffs<double, 5>; ///< SH storage of every band count the tool bakes (2..5)

/// Solid-angle-weighted mean luminance and log-average luminance exp(mean log(1e-4 + Y)).
struct luminance_stats {
    double mean = 0.0, log_average = 0.0;
};

/// The diffuse product as a renderer evaluates it.
struct diffuse_data {
    ibl::diffuse_product kind = ibl::diffuse_product::none;
    int bands = 0;               ///< SH: 2..5 (stored as 5 bands, the bands above zero)
    sh5 radiance{};              ///< SH radiance after the window, if one was applied
    sh5 shader_over_pi{};        ///< sh_shader_coeffs(radiance, irradiance_over_pi)
    ibl::cubemap<float> map{1};  ///< irradiance map (E, not E/pi)

    /// E(n)/pi as the shader computes it (SH: the polynomial form, clamped at 0).
    dvec3 irradiance_over_pi(const dvec3& n) const;
};

/// Measured time of the products by category (checks excluded).
struct product_times {
    double source = 0, specular = 0, diffuse = 0, dfg = 0, lobe = 0;
    double total() const { return source + specular + diffuse + dfg + lobe; }
};

/// Everything the stages share: settings, the plan, the source and the products so far.
struct bake_context {
    bake_context(const bake_options& o, const quality_settings& q, progress& p, pool_executor& e)
        : opt(o), qs(q), prog(p), ex(e) {}

    const bake_options& opt;
    quality_settings qs;
    progress& prog;
    pool_executor& ex;

    // plan (the plan stage)
    bool scene_mode = false;
    ibl::scene_description scene;
    ibl::plan_settings set;
    ibl::bake_plan plan; ///< what is baked
    ibl::bake_plan full; ///< the full bake (for a scene: what it is compared with)

    // source (the source stage)
    source_env src;
    ibl::cubemap<float> source{1};
    dvec3 light{0.0, 1.0, 0.0}; ///< direction of the brightest source texel
    luminance_stats lstats;

    // the sun (the sun stage): when extracted, `source` is the residual and `original` the cube
    // before; every product is of the residual, and the runtime adds the sun as a disk light
    std::optional<ibl::disk_light<double>> sun;
    std::optional<ibl::cubemap<float>> original;
    /// The source before extraction (the environment every full-integral check compares with).
    const ibl::cubemap<float>& whole_source() const { return original ? *original : source; }

    // products (the product stages)
    std::optional<ibl::cubemap<float>> chain; ///< the stored levels of plan.specular
    std::optional<ibl::dfg_lut> lut;
    std::optional<ibl::lobe_lut> lobe; ///< the lobe LUT (--runtime lobe): (A, B, s_A, r_A)
    std::optional<ibl::lobe_lut> lobe_b; ///< its B-part kernel table (f_B, r_B, 0, 0)
    std::optional<ibl::lobe_taps_lut> taps; ///< the two-tap table (--runtime taps2)
    diffuse_data diffuse;
    /// specular.ktx2 as written (encoded once, by the specular stage: the block formats take time)
    /// and as a renderer decodes it.
    struct stored_ktx2 {
        std::vector<unsigned char> bytes;
        ibl::cubemap<float> decoded{1};
        double encode_ms = 0.0;
    };
    std::shared_ptr<const stored_ktx2> specular_file;
    product_times measured; ///< filled by the pipeline after each product stage

    // the scene's targets (the target_check stage): one line per missed target
    std::vector<std::string> target_misses;
};

/// A file a stage writes: its name in DIR and the function writing it to a path.
struct file_out {
    std::string name;
    std::function<void(const std::string& path)> write;
};

enum class stage_kind {
    setup,   ///< plan, source: inputs of every product
    product, ///< its time counts as bake time (report "measured_ms")
    check    ///< measures products against references; not a product
};

class stage {
public:
    virtual ~stage() = default;
    /// Its key in report.json.
    virtual const char* key() const = 0;
    virtual stage_kind kind() const = 0;
    /// Whether the plan (and the options) select this stage.
    virtual bool enabled(const bake_context& ctx) const = 0;
    /// Computes the product (or the check) into ctx.
    virtual void run(bake_context& ctx) = 0;
    virtual std::vector<table_row> rows() const = 0;
    /// Lines printed before (pre) or after the table.
    virtual std::vector<std::string> notes_before() const { return {}; }
    virtual std::vector<std::string> notes_after() const { return {}; }
    virtual std::vector<file_out> files() const { return {}; }
    /// Writes the value of key() (one JSON value, usually an object).
    virtual void report(json_writer& j) const = 0;
    /// Time of the product itself (checks excluded); product stages only.
    virtual double product_ms() const { return 0.0; }
    /// Time of its reference checks (0 when none ran: --checks none).
    virtual double check_ms() const { return 0.0; }
    /// The product category of measured_ms: "source", "specular", "diffuse", "dfg" or "lobe_lut".
    virtual const char* category() const { return ""; }
};

} // namespace ibl_bake
