// research/split_sum_error.cpp — how wrong is the split sum? Outgoing radiance of glossy materials
// under an environment, by the split-sum product (what a renderer evaluates at run time) against
// the reference integral without the approximation (reference/radiance.hpp).
// Produces: no stored table; its output is the source of the split-sum figures quoted in README.md
// ("off by up to 78%"), docs/ibl-bake.md and docs/scene-format.md. Regenerate with
//   cmake --preset release && cmake --build --preset release --target split_sum_error
//   ./build/release/research/split_sum_error [latlong.exr]
//
// For each environment (the built-in default sky with its 1-degree sun, and tests/data/courtyard.exr
// read with the ibl-bake image reader), each normal / view and each material
// (r in {0.1, 0.5, 0.9} x {dielectric: base 0.8, F0 0.04; metal: F0 (0.95, 0.64, 0.54), metallic 1}).
// The reader is linked by research/CMakeLists.txt (which defines IBL_RESEARCH_DATA_DIR); a path
// argument replaces courtyard.exr.
// it prints
//   reference Lo   = integral (f_d + D V F) L (n.l) dl, MIS of BRDF and environment sampling,
//                    2^20 samples, with its standard error (from 16 independent randomisations);
//   split-sum Lo   = shade.hpp's single-scattering ambient with EXACT products, so that the table
//                    shows the error of the approximation itself, not of a bake:
//                      LD(R, r)  the GGX prefilter integral with Karis' n = v = R assumption,
//                                LD(R) = int L(l) D(h) max(R.l, 0) dl / int D(h) max(R.l, 0) dl,
//                                h = normalize(R + l), by the same MIS integrator (ld_lobe below),
//                                2^20 samples, and the denominator W in closed form;
//                      (A, B)    dfg_exact<ggx_height_correlated>(n.v, r) (converged to 1e-6);
//                      E(n)/pi   the exact irradiance, by the reference with a white Lambert lobe;
//                    combined as (1 - F_r(n.v)) base (1 - metallic) E/pi + LD (F0 A + F90 B).
// The reference uses the same diffuse term (diffuse_weighting::one_minus_fresnel_roughness), so
// both columns share the diffuse part and the difference is the specular split-sum error (plus
// Monte Carlo noise, bounded by the two standard-error columns).
//
// Columns: env, normal, n.v, material, r, Y(ref) and Y(split) (luminance of Lo), rel = Y(split) /
// Y(ref) - 1, spec_rel = the same for the specular parts only, se_ref / se_ss = relative standard
// errors of the reference and of the split-sum value (LD and E noise propagated).

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <ibl/brdf/model.hpp>
#include <ibl/core/color.hpp>
#include <ibl/core/executor.hpp>
#include <ibl/core/frame.hpp>
#include <ibl/env/analytic.hpp>
#include <ibl/env/latlong.hpp>
#include <ibl/bake/dfg.hpp>
#include <ibl/reference/env_importance.hpp>
#include <ibl/reference/radiance.hpp>
#include <ibl/sampling/ggx.hpp>
#include <ibl/runtime/shade.hpp>

#if defined(IBL_RESEARCH_DATA_DIR)
#include "io/image_io.hpp"
#endif

namespace {

using d3 = ibl::vec3<double>;
using model = ibl::ggx_height_correlated;

constexpr std::uint32_t reference_samples = 1u << 20;
constexpr std::uint32_t irradiance_samples = 1u << 18;

/// W(alpha) = int D(h) max(n.l, 0) dl with n = v: with u the GGX NDF variate, pdf_l = D / 4, so
/// W = 4 int_0^1 max(n.l(u), 0) du, n.l = (1 - a u) / (1 - b u), a = 1 + alpha^2, b = 1 - alpha^2,
/// positive for u < 1/a. With t = a u and x = b / a:
///   W = (4 / a) int_0^1 (1 - t) / (1 - x t) dt
///     = (4 / b) (1 + (2 alpha^2 / b) ln(2 alpha^2 / a))     (for x > 1/2; singular at b = 0)
///     = (4 / a) sum_{j >= 0} x^j / ((j + 1)(j + 2))          (for x <= 1/2: terms below 2^-j,
///                                                            60 terms reach double precision)
double ld_normaliser(double alpha) {
    const double a2 = alpha * alpha, a = 1.0 + a2, b = 1.0 - a2, x = b / a;
    if (x <= 0.5) {
        double s = 0.0, xp = 1.0;
        for (int j = 0; j < 60; ++j, xp *= x) s += xp / ((j + 1.0) * (j + 2.0));
        return 4.0 * s / a;
    }
    return 4.0 / b * (1.0 + (2.0 * a2 / b) * std::log(2.0 * a2 / a));
}

/// The prefilter integrand D(h) max(R.l, 0) / W as a product_lobe (parts[1]), sampled by the GGX
/// NDF about R with l = reflect(-R, h): pdf_l = D(h) (R.h) / (4 R.h) = D(h) / 4.
class ld_lobe {
public:
    ld_lobe(const d3& r_dir, double roughness)
        : frame_(ibl::make_frame(r_dir)), alpha_(model::alpha(roughness)), inv_w_(1.0 / ld_normaliser(alpha_)) {}

    ibl::lobe_sample sample(const ibl::vec2<double>& u) const {
        const d3 h = ibl::sample_ggx_ndf(u, alpha_);
        const d3 l(2.0 * h.z * h.x, 2.0 * h.z * h.y, 2.0 * h.z * h.z - 1.0);
        return {frame_.to_world(l), 0.25 * ibl::ndf_ggx(h, alpha_)};
    }
    double pdf(const d3& dir) const { return 0.25 * ibl::ndf_ggx(half(frame_.to_local(dir)), alpha_); }
    ibl::lobe_value eval(const d3& dir) const {
        ibl::lobe_value g;
        const d3 l = frame_.to_local(dir);
        if (l.z > 0.0) g.parts[1] = d3(ibl::ndf_ggx(half(l), alpha_) * l.z * inv_w_);
        return g;
    }

private:
    static d3 half(const d3& l) {
        const d3 s = l + d3(0.0, 0.0, 1.0);
        const double len2 = glm::dot(s, s);
        return len2 > 0.0 ? s / std::sqrt(len2) : d3(0.0, 0.0, 1.0);
    }
    ibl::frame<double> frame_;
    double alpha_, inv_w_;
};
static_assert(ibl::product_lobe<ld_lobe>);

struct material_case {
    const char* name;
    d3 base_color;
    double metallic;
};

struct geometry {
    std::string normal_name;
    d3 n;
    d3 v;
    double n_dot_v;
};

/// Normal "up" (+Y): v opposite the sun's azimuth, so R = reflect(-v, n) has the sun's azimuth
/// and elevation 90 deg - acos(n.v) (n.v = 0.5: R is the sun centre). Normal "wall": horizontal,
/// facing the sun's azimuth; R rises from n by acos(n.v) towards +Y (n.v = 0.866: the sun).
std::vector<geometry> make_geometries(const d3& sun_dir) {
    std::vector<geometry> g;
    const d3 up(0.0, 1.0, 0.0);
    const d3 horiz = glm::normalize(d3(sun_dir.x, 0.0, sun_dir.z));
    for (const double mu : {1.0, 0.5, 0.2}) {
        const double s = std::sqrt((1.0 - mu) * (1.0 + mu));
        g.push_back({"up", up, -s * horiz + mu * up, mu});
    }
    for (const double mu : {0.866, 0.5, 0.2}) {
        const double s = std::sqrt((1.0 - mu) * (1.0 + mu));
        const d3 r = mu * horiz + s * up;             // reflected direction, angle acos(mu) from n
        g.push_back({"wall", horiz, 2.0 * mu * horiz - r, mu}); // v = reflect(-R, n)
    }
    return g;
}

double rel(double x, double ref) { return ref != 0.0 ? x / ref - 1.0 : 0.0; }

const material_case k_materials[2] = {{"dielectric", d3(0.8), 0.0}, {"metal", d3(0.95, 0.64, 0.54), 1.0}};
const double k_roughnesses[3] = {0.1, 0.5, 0.9};

/// One row: the reference and the split-sum value of a material at a geometry, with the parts.
struct row {
    ibl::radiance_estimate ref;
    d3 split{0.0}, split_spec{0.0}, split_se{0.0};
};

/// E(n)/pi by the reference with a white Lambert lobe (Lo = E / pi).
template <class Env, class Ex>
ibl::radiance_estimate irradiance_over_pi(const Env& env, const ibl::cube_env_distribution& dist, const geometry& g,
                                          std::uint32_t samples, const Ex& ex) {
    ibl::reference_material white;
    white.diffuse_albedo = d3(1.0);
    white.f0 = white.f90 = d3(0.0);
    ibl::radiance_reference_options opt;
    opt.samples = samples;
    return ibl::reference_radiance(env, dist, g.n, g.v, white, opt, ex);
}

/// LD(R, r) by the MIS integrator with the prefilter lobe.
template <class Env, class Ex>
ibl::product_estimate prefiltered(const Env& env, const ibl::cube_env_distribution& dist, const geometry& g, double r,
                                  std::uint32_t samples, const Ex& ex) {
    ibl::radiance_reference_options opt;
    opt.samples = samples;
    const d3 r_dir = 2.0 * glm::dot(g.n, g.v) * g.n - g.v;
    return ibl::integrate_product_mis(env, &dist, ld_lobe(r_dir, r), opt, ex);
}

/// Reference and split sum (shade.hpp single scattering with the exact products) of one material.
template <class Env, class Ex>
row evaluate(const Env& env, const ibl::cube_env_distribution& dist, const geometry& g, const material_case& mc,
             double r, const ibl::product_estimate& ld, const ibl::radiance_estimate& e_over_pi,
             std::uint32_t samples, const Ex& ex) {
    row out;
    const ibl::reference_material m = ibl::make_reference_material(mc.base_color, mc.metallic, r,
                                                                   ibl::diffuse_weighting::one_minus_fresnel_roughness);
    ibl::radiance_reference_options opt;
    opt.samples = samples;
    out.ref = ibl::reference_radiance<model>(env, dist, g.n, g.v, m, opt, ex);

    ibl::pbr_material<double> pm;
    pm.base_color = mc.base_color;
    pm.metallic = mc.metallic;
    pm.roughness = r;
    const ibl::pbr_shader<double> shader = ibl::pbr_shader<double>::from(pm, false);
    ibl::ibl_sample<double> s;
    s.ld = ld.value;
    s.irradiance_over_pi = e_over_pi.value;
    s.dfg = ibl::dfg_exact<model>(g.n_dot_v, r);
    out.split = shader.ambient(g.n_dot_v, s);
    const d3 spec_albedo = ibl::split_sum_albedo(shader.m.f0, shader.m.f90, s.dfg);
    out.split_spec = ld.value * spec_albedo;
    const d3 diffuse = out.split - out.split_spec; // kD base E/pi
    for (int c = 0; c < 3; ++c) { // LD and E noise propagated (independent estimates)
        const double s_ld = ld.std_error[c] * spec_albedo[c];
        const double s_e = e_over_pi.value[c] > 0.0 ? diffuse[c] / e_over_pi.value[c] * e_over_pi.std_error[c] : 0.0;
        out.split_se[c] = std::sqrt(s_ld * s_ld + s_e * s_e);
    }
    return out;
}

template <class Env>
void run_table(const char* env_name, const Env& env, const ibl::cube_env_distribution& dist, const d3& sun_dir,
               double& worst) {
    const ibl::thread_executor ex{2};
    std::printf("%-9s %-6s %5s  %-10s %4s  %12s %12s %9s %9s %8s %8s\n", "env", "normal", "n.v", "material", "r",
                "Y(ref)", "Y(split)", "rel", "spec_rel", "se_ref", "se_ss");
    for (const geometry& g : make_geometries(sun_dir)) {
        const ibl::radiance_estimate e_over_pi = irradiance_over_pi(env, dist, g, irradiance_samples, ex);
        for (const double r : k_roughnesses) {
            const ibl::product_estimate ld = prefiltered(env, dist, g, r, reference_samples, ex);
            for (const material_case& mc : k_materials) {
                const row w = evaluate(env, dist, g, mc, r, ld, e_over_pi, reference_samples, ex);
                const double y_ref = ibl::luminance(w.ref.value), y_ss = ibl::luminance(w.split);
                const double re = rel(y_ss, y_ref);
                if (std::fabs(re) > std::fabs(worst)) worst = re;
                std::printf("%-9s %-6s %5.3f  %-10s %4.1f  %12.5g %12.5g %+8.2f%% %+8.2f%% %7.3f%% %7.3f%%\n",
                            env_name, g.normal_name.c_str(), g.n_dot_v, mc.name, r, y_ref, y_ss, 100.0 * re,
                            100.0 * rel(ibl::luminance(w.split_spec), ibl::luminance(w.ref.specular)),
                            100.0 * ibl::luminance(w.ref.std_error) / y_ref,
                            100.0 * ibl::luminance(w.split_se) / y_ss);
            }
        }
    }
}

/// The pipeline's own check: under a constant white environment the split sum is exact (LD = 1,
/// E/pi = 1, and F0 A + F90 B is by definition the specular integral), so every row must agree
/// within its noise. Prints the largest |rel| and the largest |difference| / combined se.
void furnace_check(const d3& sun_dir) {
    const ibl::constant_environment<double> white{d3(1.0)};
    const ibl::cube_env_distribution dist = ibl::make_cube_env_distribution<double>(white, 8, 1);
    const ibl::serial_executor ex;
    constexpr std::uint32_t n = 1u << 16;
    double worst_rel = 0.0, worst_z = 0.0;
    for (const geometry& g : make_geometries(sun_dir)) {
        const ibl::radiance_estimate e_over_pi = irradiance_over_pi(white, dist, g, n, ex);
        for (const double r : k_roughnesses) {
            const ibl::product_estimate ld = prefiltered(white, dist, g, r, n, ex);
            for (const material_case& mc : k_materials) {
                const row w = evaluate(white, dist, g, mc, r, ld, e_over_pi, n, ex);
                for (int c = 0; c < 3; ++c) {
                    const double se = std::sqrt(w.ref.std_error[c] * w.ref.std_error[c] + w.split_se[c] * w.split_se[c]);
                    worst_rel = std::max(worst_rel, std::fabs(rel(w.split[c], w.ref.value[c])));
                    // dfg_exact's own error (<= 1e-6) is added to the noise.
                    worst_z = std::max(worst_z, std::fabs(w.split[c] - w.ref.value[c]) / (se + 1e-6));
                }
            }
        }
    }
    std::printf("white furnace check (L = 1, same rows, 2^16 samples): max |rel| %.3f%%, max |diff| / se %.2f "
                "(split sum exact here: expect noise only)\n\n",
                100.0 * worst_rel, worst_z);
}

} // namespace

int main(int argc, char** argv) {
    const auto t0 = std::chrono::steady_clock::now();
    std::printf("Split-sum error: split-sum ambient (exact LD, DFG, E) against the reference integral\n"
                "model %s, single scattering, diffuse kD = 1 - F_roughness(n.v); reference %u samples (MIS),\n"
                "LD %u samples, E %u samples; rel = Y(split)/Y(ref) - 1 (Y = luminance)\n\n",
                model::name, reference_samples, reference_samples, irradiance_samples);

    const ibl::sky_environment<double> sky0 = ibl::make_default_sky<double>();
    furnace_check(sky0.sun_dir);

    // ---- the built-in sky: analytic integrand, proposal baked to a 128^2 cube (4 x 4 sub-samples)
    const ibl::sky_environment<double> sky = ibl::make_default_sky<double>();
    double worst_sky = 0.0;
    {
        const ibl::cube_env_distribution dist = ibl::make_cube_env_distribution<double>(sky, 128, 4);
        run_table("sky", sky, dist, sky.sun_dir, worst_sky);
    }
    std::printf("\nlargest |rel| (sky): %.2f%%\n\n", 100.0 * std::fabs(worst_sky));

#if defined(IBL_RESEARCH_DATA_DIR)
    const std::string path = argc > 1 ? argv[1] : std::string(IBL_RESEARCH_DATA_DIR) + "/courtyard.exr";
    try {
        ibl_bake::read_report report;
        const ibl_bake::image_rgb32f img = ibl_bake::read_latlong(path, {}, &report);
        ibl::latlong<float> map(img.width, img.height, std::span<const float>(img.rgb), 1);
        map.update_borders();
        // Proposal: the map baked to a 256^2 cube (2 x 2 sub-samples); the integrand is the map.
        const ibl::cube_env_distribution dist = ibl::make_cube_env_distribution<float>(map, 256, 2);
        std::printf("%s: %dx%d %s, max %.4g, %zu negative values clamped to 0\n", path.c_str(), img.width,
                    img.height, report.format.c_str(), double(report.max_value), report.negative_values);
        double worst = 0.0;
        run_table("courtyard", map, dist, sky.sun_dir, worst);
        std::printf("\nlargest |rel| (courtyard): %.2f%%\n", 100.0 * std::fabs(worst));
    } catch (const std::exception& e) {
        std::printf("courtyard skipped: %s\n", e.what());
    }
#else
    (void)argc;
    (void)argv;
    std::printf("courtyard skipped: built without the ibl-bake image reader (ibl_bake_io)\n");
#endif
    const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("\ntotal time %.1f s\n", secs);
    return 0;
}
