// research/occlusion_error.cpp — specular occlusion against the occluded reference
// (reference/occluded_specular.hpp): the environment is visible only inside a cone of half-angle theta_o
// about a bent normal b, and the reference integrates f_s L V (n.l) in full (MIS, no split sum).
// Produces: docs/results/occlusion_error.txt, the source of the tables of docs/occlusion.md.
// Regenerate with
//   cmake --preset release && cmake --build --preset release --target occlusion_error
//   ./build/release/research/occlusion_error > docs/results/occlusion_error.txt    (about 2 minutes)
//
//   occlusion_error [quick]      quick: 8 points per cell, 2^12 reference samples (a smoke run)
//
// Runtime model (the unoccluded part): the split sum as research/runtime_error.cpp bakes it: a
// 512^2 source cube prefiltered to a 256^2 x 6-level chain (ibl::prefilter, ld_weight::g1,
// trilinear reads), make_dfg_lut_exact 128^2, ibl::specular_lookup at R; specular = LD(R) (F0 A +
// F90 B). Occlusion variants multiply it by a factor k:
//   none      k = 1
//   ao        k = ao
//   Lagarde   k = specular_occlusion_lagarde(n.v, ao, r) (ibl/runtime/specular_models.hpp)
//   lobe LUT  k = so(n.v, r, ao): the visible fraction of the lobe in a cone about n
//             (ibl/runtime/specular_occlusion.hpp, make_specular_occlusion_lut 16^3, 256^2 nodes per cell)
//   lobe LUT, bent   k = so(b.R, r, ao / b.n): the same table with the lobe's direction measured
//             from the bent normal (b.R for n.v) and the cone's own aperture (ao = cos(beta)
//             sin^2 theta_o inverted without the horizon clip); equal to "lobe LUT" for b = n
//   ideal     k = Y_occ / Y_unocc of the reference itself: the runtime model's own error floor
// Materials: metal F0 = (0.95, 0.64, 0.54), dielectric F0 = 0.04 (F90 = 1), specular only.
// Cells: r in {0.1, 0.3, 0.5, 0.8} x n.v in {0.15, 0.5, 1} x ao in {0.25, 0.5, 0.75} x bent-normal
// tilt beta in {0, +0.5, -0.5} rad (in the plane of incidence; + towards R), theta_o solved from
// ao for the tilt (cone_half_angle_for_ao). Per cell P points: n uniform on the sphere, v at
// acos(n.v) from n with uniform azimuth (runtime_error's hash sequence).
// Metrics per cell: relative RMSE of the specular luminance, sqrt(mean((Y / Y_ref - 1)^2)), as
// runtime_error computes it, and the RMSE of the FACTOR, sqrt(mean((k - Y_occ / Y_unocc)^2)),
// which isolates the occlusion from the runtime model's own error. "ref se" is the RMS relative
// standard error of the occluded references (the metric's noise floor).

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <functional>
#include <string>
#include <vector>

#include <ibl/brdf/model.hpp>
#include <ibl/core/color.hpp>
#include <ibl/core/executor.hpp>
#include <ibl/core/frame.hpp>
#include <ibl/env/analytic.hpp>
#include <ibl/env/convert.hpp>
#include <ibl/env/latlong.hpp>
#include <ibl/reference/env_importance.hpp>
#include <ibl/reference/lookup_error.hpp>
#include <ibl/reference/occluded_specular.hpp>
#include <ibl/bake/prefilter.hpp>
#include <ibl/reference/radiance.hpp>
#include <ibl/runtime/specular_occlusion.hpp>
#include <ibl/runtime/specular_models.hpp>

#include "study_envs.hpp"

namespace {

using d3 = ibl::vec3<double>;
using f3 = ibl::vec3<float>;
using model = ibl::ggx_height_correlated;

double seconds_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

const double k_roughness[] = {0.1, 0.3, 0.5, 0.8};
const double k_n_dot_v[] = {0.15, 0.5, 1.0};
const double k_ao[] = {0.25, 0.5, 0.75};
const double k_tilt[] = {0.0, 0.5, -0.5};
constexpr int n_r = 4, n_mu = 3, n_ao = 3, n_tilt = 3, n_var = 6;
constexpr std::uint32_t k_lut_size = 32; // samples per axis of the visible-fraction table
constexpr std::size_t k_stride = 3 * n_var + 2; // per point: rel^2, fac^2, ref var, Y_ref^2, (Y - Y_ref)^2
const char* const k_var_names[n_var] = {"none", "ao", "Lagarde", "lobe LUT", "lobe LUT, bent", "ideal"};
const char* const k_var_cost[n_var] = {"-", "1 mul", "pow + exp2", "1 3-D tap", "1 3-D tap + 2 dot", "-"};

struct material_case {
    const char* name;
    d3 f0;
};
const material_case k_materials[2] = {{"metal", d3(0.95, 0.64, 0.54)}, {"dielectric", d3(0.04)}};

const ibl::dfg_lut_layout k_layout = ibl::dfg_lut_layout::remapped();
const ibl::specular_lookup_desc k_lookup = ibl::specular_lookup_desc::accurate();

struct products {
    ibl::cubemap<float> chain{1};
    const ibl::dfg_lut* dfg = nullptr;
    const ibl::specular_occlusion_lut* so = nullptr;
};

/// The unoccluded runtime specular: split sum with the G1 chain.
f3 runtime_specular(const products& p, const f3& n, const f3& v, float n_dot_v, float r, const f3& f0) {
    const f3 abk = ibl::dfg_lookup(*p.dfg, n_dot_v, r);
    const f3 albedo = ibl::split_sum_albedo(f0, f3(1.0f), ibl::vec2<float>(abk.x, abk.y));
    const f3 rd = 2.0f * glm::dot(n, v) * n - v;
    return ibl::specular_lookup(p.chain, rd, r, k_lookup) * albedo;
}

// ---- measurement ----------------------------------------------------------------------------------

/// Sums per (material, variant, tilt, r, mu, ao): squared relative luminance error, squared factor
/// error; per (material, tilt, r, mu, ao): reference relative variance.
struct cell_sums {
    std::vector<double> rel, fac, refv, dsq, ysq; // dsq: (Y - Y_ref)^2 per variant, ysq: Y_ref^2
    std::uint32_t points = 0;
    static std::size_t cell(int t, int r, int mu, int a) { return ((std::size_t(t) * n_r + r) * n_mu + mu) * n_ao + a; }
    static constexpr std::size_t n_cells = std::size_t(n_tilt) * n_r * n_mu * n_ao;
    static std::size_t at(int m, int q, std::size_t c) { return (std::size_t(m) * n_var + q) * n_cells + c; }
    cell_sums()
        : rel(2 * n_var * n_cells, 0.0), fac(2 * n_var * n_cells, 0.0), refv(2 * n_cells, 0.0),
          dsq(2 * n_var * n_cells, 0.0), ysq(2 * n_cells, 0.0) {}
};

template <class Env>
cell_sums measure(const Env& env, const ibl::cube_env_distribution& dist, const products& prod, std::uint32_t points,
                  std::uint32_t ref_samples) {
    cell_sums c;
    c.points = points;
    for (int it = 0; it < n_tilt; ++it)
        for (int ir = 0; ir < n_r; ++ir)
            for (int im = 0; im < n_mu; ++im)
                for (int ia = 0; ia < n_ao; ++ia) {
                    const std::size_t cell = cell_sums::cell(it, ir, im, ia);
                    const double tilt = k_tilt[it], ao = k_ao[ia], r = k_roughness[ir], mu = k_n_dot_v[im];
                    const double to = ibl::cone_half_angle_for_ao(ao, tilt);
                    // per point and material: [var] rel^2, [var] fac^2, ref rel var
                    std::vector<double> buf(std::size_t(points) * 2 * k_stride, 0.0);
                    ibl::thread_executor{2}(points, [&](std::size_t b, std::size_t e) {
                        for (std::size_t k = b; k < e; ++k) {
                            d3 n, v;
                            study::make_point(std::uint32_t(k + 1000 * im), mu, n, v);
                            const ibl::visibility_cone cone = ibl::make_bent_cone(n, v, tilt, to);
                            for (int m = 0; m < 2; ++m) {
                                ibl::reference_material rm;
                                rm.diffuse_albedo = d3(0.0);
                                rm.f0 = k_materials[m].f0;
                                rm.roughness = r;
                                ibl::radiance_reference_options opt;
                                opt.samples = ref_samples;
                                opt.seed = std::uint32_t(k * 7 + 3);
                                const ibl::occluded_specular_estimate est =
                                    ibl::occluded_reference_specular<model>(env, &dist, n, v, rm, cone, opt);
                                const double y_occ = ibl::luminance(est.occluded), y_un = ibl::luminance(est.unoccluded);
                                const double ratio = y_un > 0.0 ? y_occ / y_un : 1.0;
                                const double y_rt = ibl::luminance(d3(runtime_specular(
                                    prod, f3(n), f3(v), float(mu), float(r), f3(k_materials[m].f0))));
                                const double kf[n_var] = {
                                    1.0,
                                    ao,
                                    double(ibl::specular_occlusion_lagarde(float(mu), float(ao), float(r))),
                                    double(ibl::specular_occlusion_lookup(*prod.so, float(mu), float(r), float(ao))),
                                    double(ibl::specular_occlusion_bent(prod.so->data.data(), prod.so->size, f3(n), f3(v),
                                                                        f3(cone.axis), float(r), float(ao))),
                                    ratio};
                                double* o = &buf[(k * 2 + std::size_t(m)) * k_stride];
                                for (int q = 0; q < n_var; ++q) {
                                    o[q] = y_occ > 0.0 ? ibl::sqr(kf[q] * y_rt / y_occ - 1.0) : 0.0;
                                    o[n_var + q] = ibl::sqr(kf[q] - ratio);
                                    o[2 * n_var + 2 + q] = ibl::sqr(kf[q] * y_rt - y_occ);
                                }
                                o[2 * n_var + 1] = y_occ * y_occ;
                                o[2 * n_var] = y_occ > 0.0 ? ibl::sqr(ibl::luminance(est.std_error_occluded) / y_occ) : 0.0;
                            }
                        }
                    });
                    for (std::uint32_t k = 0; k < points; ++k)
                        for (int m = 0; m < 2; ++m) {
                            const double* o = &buf[(k * 2 + std::size_t(m)) * k_stride];
                            for (int q = 0; q < n_var; ++q) {
                                c.rel[cell_sums::at(m, q, cell)] += o[q];
                                c.fac[cell_sums::at(m, q, cell)] += o[n_var + q];
                                c.dsq[cell_sums::at(m, q, cell)] += o[2 * n_var + 2 + q];
                            }
                            c.ysq[std::size_t(m) * cell_sums::n_cells + cell] += o[2 * n_var + 1];
                            c.refv[std::size_t(m) * cell_sums::n_cells + cell] += o[2 * n_var];
                        }
                }
    return c;
}

ibl::cubemap<float> bake_chain(const ibl::cubemap<float>& src) {
    ibl::prefilter_options o;
    o.levels = 6;
    o.base_size = 256;
    o.trilinear = true;
    o.samples_per_level = {0u, 512u, 1024u, 2048u, 4096u, 8192u};
    o.weight = ibl::ld_weight::g1;
    return ibl::prefilter(src, o, ibl::thread_executor{2});
}

struct env_result {
    std::string name;
    cell_sums cells;
    bool furnace = false; ///< the constant environment: the factor error of the geometry alone
};

enum class metric { factor, relative, normalised };

/// Pooled error (in %) over the cells a predicate selects: RMS of the factor error or of the
/// relative error, or the NRMSE sqrt(sum (Y - Y_ref)^2 / sum Y_ref^2).
template <class Pred>
double pooled(const std::vector<env_result>& res, int m, int q, metric mt, Pred&& pick) {
    double s = 0.0, y = 0.0;
    std::size_t cnt = 0;
    for (const env_result& e : res)
        for (int it = 0; it < n_tilt; ++it)
            for (int ir = 0; ir < n_r; ++ir)
                for (int im = 0; im < n_mu; ++im)
                    for (int ia = 0; ia < n_ao; ++ia) {
                        if (!pick(e, it, ir, im, ia)) continue;
                        const std::size_t c = cell_sums::cell(it, ir, im, ia);
                        const std::size_t i = cell_sums::at(m, q, c);
                        s += mt == metric::factor ? e.cells.fac[i] : (mt == metric::relative ? e.cells.rel[i] : e.cells.dsq[i]);
                        y += e.cells.ysq[std::size_t(m) * cell_sums::n_cells + c];
                        cnt += e.cells.points;
                    }
    if (mt == metric::normalised) return y > 0.0 ? 100.0 * std::sqrt(s / y) : 0.0;
    return cnt > 0 ? 100.0 * std::sqrt(s / double(cnt)) : 0.0;
}

template <class Pred> double pooled_ref(const std::vector<env_result>& res, int m, Pred&& pick) {
    double s = 0.0;
    std::size_t cnt = 0;
    for (const env_result& e : res)
        for (int it = 0; it < n_tilt; ++it)
            for (int ir = 0; ir < n_r; ++ir)
                for (int im = 0; im < n_mu; ++im)
                    for (int ia = 0; ia < n_ao; ++ia) {
                        if (!pick(e, it, ir, im, ia)) continue;
                        s += e.cells.refv[std::size_t(m) * cell_sums::n_cells + cell_sums::cell(it, ir, im, ia)];
                        cnt += e.cells.points;
                    }
    return cnt > 0 ? 100.0 * std::sqrt(s / double(cnt)) : 0.0;
}

void print_tables(const std::vector<env_result>& res) {
    auto tilt_name = [](int it) { return it == 0 ? "b = n" : (it == 1 ? "b tilted 0.5 rad towards R" : "b tilted 0.5 rad away from R"); };
    for (int it = 0; it < n_tilt; ++it)
        for (int m = 0; m < 2; ++m) {
            std::printf("\n### %s, %s: factor RMSE (absolute, %%) / NRMSE of Y (%%) / relative RMSE of Y (%%) per r, "
                        "pooled over the HDRIs and the sky, n.v and ao\n\n| variant | cost | r = 0.1 | 0.3 | 0.5 | 0.8 | all |\n"
                        "|---|---|---|---|---|---|---|\n",
                        tilt_name(it), k_materials[m].name);
            for (int q = 0; q < n_var; ++q) {
                std::printf("| %s | %s |", k_var_names[q], k_var_cost[q]);
                for (int ir = 0; ir <= n_r; ++ir) {
                    auto pick = [&](const env_result& e, int t, int r, int, int) {
                        return !e.furnace && t == it && (ir == n_r || r == ir);
                    };
                    std::printf(" %.1f / %.1f / %.0f |", pooled(res, m, q, metric::factor, pick),
                                pooled(res, m, q, metric::normalised, pick), pooled(res, m, q, metric::relative, pick));
                }
                std::printf("\n");
            }
            std::printf("| ref se (rel) | - |");
            for (int ir = 0; ir <= n_r; ++ir)
                std::printf(" %.2f |", pooled_ref(res, m, [&](const env_result& e, int t, int r, int, int) {
                                return !e.furnace && t == it && (ir == n_r || r == ir);
                            }));
            std::printf("\n");
        }
    // Per (n.v, ao) for b = n: the factor RMSE of ao, Lagarde and the LUT.
    for (int m = 0; m < 2; ++m) {
        std::printf("\n### b = n, %s: factor RMSE (%%) per (n.v, ao), pooled over environments and r: ao / "
                    "Lagarde / lobe LUT (HDRIs and sky)\n\n| n.v | ao = 0.25 | 0.5 | 0.75 |\n|---|---|---|---|\n",
                    k_materials[m].name);
        for (int im = 0; im < n_mu; ++im) {
            std::printf("| %.2f |", k_n_dot_v[im]);
            for (int ia = 0; ia < n_ao; ++ia) {
                auto pick = [&](const env_result& e, int t, int, int mu, int a) {
                    return !e.furnace && t == 0 && mu == im && a == ia;
                };
                std::printf(" %.1f / %.1f / %.1f |", pooled(res, m, 1, metric::factor, pick),
                            pooled(res, m, 2, metric::factor, pick), pooled(res, m, 3, metric::factor, pick));
            }
            std::printf("\n");
        }
    }
    // The white furnace: the factor error of the geometry alone (no environment structure).
    std::printf("\n### White furnace (L = 1): factor RMSE (%%) per r and tilt (b = n / towards R / away from R)\n\n"
                "| variant | material | r = 0.1 | 0.3 | 0.5 | 0.8 |\n|---|---|---|---|---|---|\n");
    for (int q = 0; q < n_var - 1; ++q)
        for (int m = 0; m < 2; ++m) {
            std::printf("| %s | %s |", k_var_names[q], k_materials[m].name);
            for (int ir = 0; ir < n_r; ++ir) {
                for (int it = 0; it < n_tilt; ++it) {
                    auto pick = [&](const env_result& e, int t, int r, int, int) { return e.furnace && t == it && r == ir; };
                    std::printf(it == 0 ? " %.1f" : " / %.1f", pooled(res, m, q, metric::factor, pick));
                }
                std::printf(" |");
            }
            std::printf("\n");
        }
    // Per environment, all cells.
    std::printf("\n### Per environment, all tilts: factor RMSE (%%) / NRMSE of Y (%%)\n\n| environment | material |");
    for (int q = 0; q < n_var; ++q) std::printf(" %s |", k_var_names[q]);
    std::printf(" ref se |\n|---|---|");
    for (int q = 0; q <= n_var; ++q) std::printf("---|");
    std::printf("\n");
    for (const env_result& e : res)
        for (int m = 0; m < 2; ++m) {
            std::printf("| %s | %s |", e.name.c_str(), k_materials[m].name);
            auto pick = [&](const env_result& x, int, int, int, int) { return &x == &e; };
            for (int q = 0; q < n_var; ++q)
                std::printf(" %.1f / %.1f |", pooled(res, m, q, metric::factor, pick), pooled(res, m, q, metric::normalised, pick));
            std::printf(" %.2f |\n", pooled_ref(res, m, pick));
        }
}

} // namespace

int main(int argc, char** argv) {
    const bool quick = argc > 1 && std::strcmp(argv[1], "quick") == 0;
    const std::uint32_t points = quick ? 8 : 32;
    const std::uint32_t ref_samples = quick ? 1u << 12 : 1u << 14;
    const auto t0 = std::chrono::steady_clock::now();
    std::printf("Specular occlusion against the occluded reference (occluded_reference_specular, MIS, %u samples, 16 "
                "batches); %u points per cell; model %s\n",
                ref_samples, points, model::name);
    const ibl::dfg_lut dfg = ibl::make_dfg_lut_exact<model>(128, k_layout, 2, ibl::dfg_lut_default_nodes,
                                                            ibl::thread_executor{2});
    const auto ts = std::chrono::steady_clock::now();
    const ibl::specular_occlusion_lut so = ibl::make_specular_occlusion_lut<model>(k_lut_size, 256, ibl::thread_executor{2});
    std::printf("tables: DFG 128^2, visible-fraction LUT %u^3 (256^2 nodes per cell): %.1f s (LUT %.1f s)\n",
                k_lut_size, seconds_since(t0), seconds_since(ts));
    {
        // The table's interpolation error: trilinear reads at cell midpoints against the quadrature.
        double sq = 0.0, worst = 0.0;
        int cnt = 0;
        const int cells = int(k_lut_size) - 1, stride = std::max(1, cells / 8);
        for (int k = 0; k < cells; k += stride)
            for (int j = std::max(1, cells / 10); j < cells; j += stride)
                for (int i = 0; i < cells; i += stride) {
                    const double mu = (i + 0.5) / cells, r = (j + 0.5) / cells, ao = (k + 0.5) / cells;
                    const double ex = ibl::specular_lobe_visible_fraction<model>(mu, r, std::asin(std::sqrt(ao)), 256);
                    const double d = double(ibl::specular_occlusion_lookup(so, float(mu), float(r), float(ao))) - ex;
                    sq += d * d;
                    worst = std::max(worst, std::fabs(d));
                    ++cnt;
                }
        std::printf("LUT interpolation at cell midpoints (a subset, r >= 0.1): RMS %.4f, max %.4f\n", std::sqrt(sq / cnt), worst);
    }

    std::vector<env_result> results;
    auto run = [&](const std::string& name, const auto& integrand, const ibl::cubemap<float>& src,
                   const ibl::cube_env_distribution& dist) {
        const auto t1 = std::chrono::steady_clock::now();
        products p;
        p.chain = bake_chain(src);
        p.dfg = &dfg;
        p.so = &so;
        std::printf("%s: chain baked %.1f s\n", name.c_str(), seconds_since(t1));
        results.push_back({name, measure(integrand, dist, p, points, ref_samples), name == "white furnace"});
        std::printf("%s: measured %.1f s\n", name.c_str(), seconds_since(t1));
        std::fflush(stdout);
    };
    {
        const ibl::constant_environment<double> white{d3(1.0)};
        const ibl::cubemap<float> src = ibl::bake_cubemap<float>(white, 64, 1, ibl::thread_executor{2});
        const ibl::cube_env_distribution dist = ibl::make_cube_env_distribution<double>(white, 8, 1);
        run("white furnace", white, src, dist);
    }
    study::for_each_environment(run);
    print_tables(results);
    std::printf("\ntotal time %.1f s\n", seconds_since(t0));
    return 0;
}
