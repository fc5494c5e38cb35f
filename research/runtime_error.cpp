// research/runtime_error.cpp — the runtime approximations of ibl/runtime/specular_models.hpp against the full
// integral: each variant's specular radiance against ibl::reference_radiance (MIS of the BRDF and
// the environment, no split sum), over random normals and views at fixed n.v.
// Produces: docs/results/runtime_error.txt, runtime_error_fit.txt and runtime_error_levels8.txt,
// the sources of the tables of docs/runtime.md. Regenerate with
//   cmake --preset release && cmake --build --preset release --target runtime_error
//   ./build/release/research/runtime_error > docs/results/runtime_error.txt    (38 s on 2 cores)
//   ./build/release/research/runtime_error fit > docs/results/runtime_error_fit.txt
//   ./build/release/research/runtime_error levels=8 > docs/results/runtime_error_levels8.txt
//
//   runtime_error [quick|explore|fit] [levels=N]
//     quick: 8 points per cell, 2^13 reference samples (a smoke run); explore: FIS footprint
//     scales; fit: the per-cell L1 fits of 1, 2, 3, 6 and 8 taps (bake/lobe_fit.hpp, no table)
//     against their 32^2 tables; levels=N: a chain of N levels (default 6, as ibl-bake).
//
// Environments: the built-in sky + sun (ibl::make_default_sky; integrand analytic) and
// tests/data/{courtyard,studio}.exr (integrand the lat-long map). Each is baked to a 512^2 source
// cube and prefiltered as ibl-bake does by default (256^2 base, 6 levels, linear roughness,
// filtered importance sampling, trilinear reads, lod bias 0.5, 512 samples at level 1 doubled
// per level), once with Karis's n.l weight and once with the D G1 weight (prefilter_options::
// weight). DFG: make_dfg_lut_exact 128^2 in the default layout; lobe LUTs: make_lobe_lut 64^2.
//
// Materials: metal F0 = (0.95, 0.64, 0.54) and dielectric F0 = 0.04, F90 = 1, specular lobe only
// (diffuse albedo 0: the diffuse part is the same functional in every variant and would only
// dilute the error). Cells: r in {0.1, 0.3, 0.5, 0.65, 0.8, 0.9} x n.v in {0.1, 0.15, 0.25, 0.5, 1};
// per cell P = 64 points: n uniform on the sphere, v at angle acos(n.v) from n with uniform azimuth
// (a fixed hash sequence: the same points for every variant). Metric per cell: relative RMSE of
// luminance, sqrt(mean((Y / Y_ref - 1)^2)); "ref" is the RMS relative standard error of the
// references themselves (the metric's noise floor).

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
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
#include <ibl/bake/lobe_fit.hpp>
#include <ibl/bake/lobe_moments.hpp>
#include "lobe_moment_baseline.hpp"
#include <ibl/reference/lookup_error.hpp>
#include <ibl/bake/prefilter.hpp>
#include <ibl/reference/radiance.hpp>
#include <ibl/reference/ld_irradiance.hpp>
#include <ibl/runtime/specular_models.hpp>

#include "study_envs.hpp"

namespace {

using d3 = ibl::vec3<double>;
using f3 = ibl::vec3<float>;
using model = ibl::ggx_height_correlated;

double seconds_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

const double k_roughness[] = {0.1, 0.3, 0.5, 0.65, 0.8, 0.9};
const double k_n_dot_v[] = {0.1, 0.15, 0.25, 0.5, 1.0};
constexpr int n_r = 6, n_mu = 5;

struct material_case {
    const char* name;
    d3 f0;
};
const material_case k_materials[2] = {{"metal", d3(0.95, 0.64, 0.54)}, {"dielectric", d3(0.04)}};

/// The baked products a variant reads.
struct products {
    ibl::cubemap<float> chain_nl{1}, chain_g1{1};
    const ibl::dfg_lut* dfg = nullptr;
    const ibl::lobe_lut* lobe_nl = nullptr;
    const ibl::lobe_lut* lobe_g1 = nullptr;
    const ibl::lobe_lut* lobe_fit_g1 = nullptr;
    const ibl::lobe_lut* lobe_fit_nl = nullptr;
    const ibl::lobe_taps_lut* taps2_g1 = nullptr;
    const ibl::lobe_taps_lut* taps3_g1 = nullptr;
    /// The G1-weighted LD of the environment itself at (dir, r) (GGX IS in double, 8192 samples;
    /// fit mode: the mixtures read without the chain's storage and interpolation).
    std::function<d3(const d3&, double)> exact_ld;
};

struct shading_point {
    f3 n, v;
    float n_dot_v, roughness;
    f3 f0;
};

using variant_fn = std::function<f3(const products&, const shading_point&)>;
struct variant {
    const char* name;
    const char* cost; // chain textureLod / LUT taps
    variant_fn fn;
};

const ibl::dfg_lut_layout k_layout = ibl::dfg_lut_layout::remapped();
const ibl::specular_lookup_desc k_lookup = ibl::specular_lookup_desc::accurate(); // default two-tap lookup (lookup.hpp)

f3 albedo_of(const products& p, const shading_point& s) {
    const f3 abk = ibl::dfg_lookup(*p.dfg, s.n_dot_v, s.roughness);
    return ibl::split_sum_albedo(s.f0, f3(1.0f), ibl::vec2<float>(abk.x, abk.y));
}

f3 split(const ibl::cubemap<float>& chain, const products& p, const shading_point& s, const f3& dir) {
    return ibl::specular_lookup(chain, dir, s.roughness, k_lookup) * albedo_of(p, s);
}

f3 reflect_dir(const shading_point& s) { return 2.0f * glm::dot(s.n, s.v) * s.n - s.v; }

f3 fis(const ibl::cubemap<float>& chain, const products& p, const shading_point& s, std::uint32_t taps, float scale,
       bool normalise) {
    ibl::runtime_fis_desc d;
    d.taps = taps;
    d.footprint_scale = scale;
    d.normalise = normalise;
    const f3 abk = ibl::dfg_lookup(*p.dfg, s.n_dot_v, s.roughness);
    return ibl::specular_fis(chain, d, s.n, s.v, s.roughness, s.f0, f3(1.0f), ibl::vec2<float>(abk.x, abk.y));
}

int g_levels = 6;    ///< chain levels (levels=N on the command line)
double g_leak = 0.0; ///< leak_weight of the per-cell fits (leak=X)

/// Fitted mixtures per (r, n.v) cell and tap count (index [kernels][count - 1][r][mu]; kernels 0:
/// of any roughness, 1: the chain's stored levels read by one trilinear textureLod each).
struct fitted_cells {
    std::vector<ibl::lobe_mixture> m[2][8];
    const ibl::lobe_mixture& at(int count, bool levels, const shading_point& s) const {
        int ir = 0, im = 0;
        for (int i = 0; i < n_r; ++i)
            if (std::fabs(float(k_roughness[i]) - s.roughness) < 1e-6f) ir = i;
        for (int i = 0; i < n_mu; ++i)
            if (std::fabs(float(k_n_dot_v[i]) - s.n_dot_v) < 1e-6f) im = i;
        return m[levels ? 1 : 0][count - 1][std::size_t(ir * n_mu + im)];
    }
};
fitted_cells g_fits;

std::vector<double> chain_level_roughness() {
    std::vector<double> r(static_cast<std::size_t>(g_levels));
    for (int l = 0; l < g_levels; ++l) r[std::size_t(l)] = double(l) / double(g_levels - 1);
    return r;
}

void make_fits(ibl::ld_weight w) {
    for (int lv = 0; lv < 2; ++lv)
        for (int c : {1, 2, 3, 6, 8}) {
            if (lv == 1 && c == 8) continue;
            g_fits.m[lv][c - 1].assign(std::size_t(n_r * n_mu), {});
            ibl::thread_executor{2}(std::size_t(n_r * n_mu), [&](std::size_t b, std::size_t e) {
                for (std::size_t i = b; i < e; ++i) {
                    ibl::lobe_fit_options o;
                    o.taps = c;
                    o.nodes = 32;
                    o.iterations = 150;
                    o.leak_weight = g_leak;
                    if (lv == 1) o.level_roughness = chain_level_roughness();
                    g_fits.m[lv][c - 1][i] = ibl::fit_specular_lobe<model>(k_n_dot_v[i % n_mu], k_roughness[i / n_mu], w, o);
                }
            });
        }
}

f3 mixture(const ibl::cubemap<float>& chain, const products& p, const shading_point& s, int count, bool levels = false,
           bool exact = false) {
    const ibl::lobe_mixture& mx = g_fits.at(count, levels, s);
    const ibl::specular_lookup_desc textbook = ibl::specular_lookup_desc::textbook();
    const f3 r_dir = reflect_dir(s);
    f3 t = r_dir - glm::dot(s.n, r_dir) * s.n;
    const float tl = glm::length(t);
    t = tl > 1e-6f ? t / tl : ibl::make_frame(s.n).t;
    f3 sum(0.0f);
    for (int k = 0; k < mx.count; ++k) {
        const auto& tp = mx.taps[std::size_t(k)];
        const f3 d = float(std::cos(tp.angle)) * s.n + float(std::sin(tp.angle)) * t;
        sum += float(tp.weight) * (exact    ? f3(p.exact_ld(d3(d), tp.roughness))
                                   : levels ? ibl::specular_lookup(chain, d, float(tp.roughness / (g_levels - 1)), textbook)
                                            : ibl::specular_lookup(chain, d, float(tp.roughness), k_lookup));
    }
    return sum * albedo_of(p, s);
}

/// The fitted tables (G1 chain): one tap (the lobe LUT format), 2 and 3 taps.
void add_fitted_table_variants(std::vector<variant>& v) {
    v.push_back({"fitted lobe LUT, G1", "2 + 1", [](const products& p, const shading_point& s) {
                     return ibl::specular_lobe(p.chain_g1, k_lookup, *p.lobe_fit_g1, s.n, s.v, s.roughness, s.f0,
                                               f3(1.0f));
                 }});
    v.push_back({"fitted 2 taps LUT, G1", "4 + 2", [](const products& p, const shading_point& s) {
                     return ibl::specular_lobe_taps(p.chain_g1, k_lookup, *p.taps2_g1, s.n, s.v, s.roughness, s.f0,
                                                    f3(1.0f));
                 }});
    v.push_back({"fitted 3 taps LUT, G1", "6 + 3", [](const products& p, const shading_point& s) {
                     return ibl::specular_lobe_taps(p.chain_g1, k_lookup, *p.taps3_g1, s.n, s.v, s.roughness, s.f0,
                                                    f3(1.0f));
                 }});
}

std::vector<variant> make_fit_variants() {
    std::vector<variant> v;
    v.push_back({"split sum, G1 chain", "2 + 1", [](const products& p, const shading_point& s) {
                     return split(p.chain_g1, p, s, reflect_dir(s));
                 }});
    v.push_back({"lobe LUT, G1", "2 + 1", [](const products& p, const shading_point& s) {
                     return ibl::specular_lobe(p.chain_g1, k_lookup, *p.lobe_g1, s.n, s.v, s.roughness, s.f0,
                                               f3(1.0f));
                 }});
    add_fitted_table_variants(v);
    v.push_back({"L1 fit 1 tap, G1", "2 + 1", [](const products& p, const shading_point& s) { return mixture(p.chain_g1, p, s, 1); }});
    v.push_back({"L1 fit 2 taps, G1", "4 + 2", [](const products& p, const shading_point& s) { return mixture(p.chain_g1, p, s, 2); }});
    v.push_back({"L1 fit 3 taps, G1", "6 + 3", [](const products& p, const shading_point& s) { return mixture(p.chain_g1, p, s, 3); }});
    v.push_back({"L1 fit 6 taps, G1", "12 + 5", [](const products& p, const shading_point& s) { return mixture(p.chain_g1, p, s, 6); }});
    v.push_back({"L1 fit 8 taps, G1", "16 + 7", [](const products& p, const shading_point& s) { return mixture(p.chain_g1, p, s, 8); }});
    v.push_back({"L1 fit 1 tap, exact LD", "-", [](const products& p, const shading_point& s) {
                     return mixture(p.chain_g1, p, s, 1, false, true);
                 }});
    v.push_back({"L1 fit 2 taps, exact LD", "-", [](const products& p, const shading_point& s) {
                     return mixture(p.chain_g1, p, s, 2, false, true);
                 }});
    v.push_back({"L1 fit 6 taps, exact LD", "-", [](const products& p, const shading_point& s) {
                     return mixture(p.chain_g1, p, s, 6, false, true);
                 }});
    v.push_back({"L1 fit 1 tap, stored levels, G1", "1 + 1", [](const products& p, const shading_point& s) {
                     return mixture(p.chain_g1, p, s, 1, true);
                 }});
    v.push_back({"L1 fit 2 taps, stored levels, G1", "2 + 2", [](const products& p, const shading_point& s) {
                     return mixture(p.chain_g1, p, s, 2, true);
                 }});
    v.push_back({"L1 fit 3 taps, stored levels, G1", "3 + 3", [](const products& p, const shading_point& s) {
                     return mixture(p.chain_g1, p, s, 3, true);
                 }});
    v.push_back({"L1 fit 6 taps, stored levels, G1", "6 + 5", [](const products& p, const shading_point& s) {
                     return mixture(p.chain_g1, p, s, 6, true);
                 }});
    v.push_back({"FIS 16, normalised, G1", "16 + 1", [](const products& p, const shading_point& s) {
                     return fis(p.chain_g1, p, s, 16, 1.0f, true);
                 }});
    return v;
}

std::vector<variant> make_variants(bool explore) {
    std::vector<variant> v;
    v.push_back({"split sum, n.l chain", "2 + 1", [](const products& p, const shading_point& s) {
                     return split(p.chain_nl, p, s, reflect_dir(s));
                 }});
    v.push_back({"split sum, G1 chain", "2 + 1", [](const products& p, const shading_point& s) {
                     return split(p.chain_g1, p, s, reflect_dir(s));
                 }});
    v.push_back({"Frostbite dominant dir, n.l", "2 + 1", [](const products& p, const shading_point& s) {
                     return split(p.chain_nl, p, s,
                                  ibl::lerp_direction(s.n, reflect_dir(s), ibl::dominant_lerp_frostbite(s.roughness)));
                 }});
    v.push_back({"Frostbite dominant dir, G1", "2 + 1", [](const products& p, const shading_point& s) {
                     return split(p.chain_g1, p, s,
                                  ibl::lerp_direction(s.n, reflect_dir(s), ibl::dominant_lerp_frostbite(s.roughness)));
                 }});
    v.push_back({"lobe LUT, n.l", "2 + 1", [](const products& p, const shading_point& s) {
                     return ibl::specular_lobe(p.chain_nl, k_lookup, *p.lobe_nl, s.n, s.v, s.roughness, s.f0,
                                               f3(1.0f));
                 }});
    v.push_back({"lobe LUT, G1", "2 + 1", [](const products& p, const shading_point& s) {
                     return ibl::specular_lobe(p.chain_g1, k_lookup, *p.lobe_g1, s.n, s.v, s.roughness, s.f0,
                                               f3(1.0f));
                 }});
    v.push_back({"fitted lobe LUT, n.l", "2 + 1", [](const products& p, const shading_point& s) {
                     return ibl::specular_lobe(p.chain_nl, k_lookup, *p.lobe_fit_nl, s.n, s.v, s.roughness, s.f0,
                                               f3(1.0f));
                 }});
    add_fitted_table_variants(v);
    v.push_back({"FIS 4, normalised, G1", "4 + 1", [](const products& p, const shading_point& s) {
                     return fis(p.chain_g1, p, s, 4, 1.0f, true);
                 }});
    v.push_back({"FIS 8, normalised, G1", "8 + 1", [](const products& p, const shading_point& s) {
                     return fis(p.chain_g1, p, s, 8, 1.0f, true);
                 }});
    v.push_back({"FIS 16, normalised, G1", "16 + 1", [](const products& p, const shading_point& s) {
                     return fis(p.chain_g1, p, s, 16, 1.0f, true);
                 }});
    v.push_back({"FIS 32, normalised, G1", "32 + 1", [](const products& p, const shading_point& s) {
                     return fis(p.chain_g1, p, s, 32, 1.0f, true);
                 }});
    v.push_back({"FIS 64, normalised, G1", "64 + 1", [](const products& p, const shading_point& s) {
                     return fis(p.chain_g1, p, s, 64, 1.0f, true);
                 }});
    v.push_back({"FIS 16, plain, G1", "16 + 0", [](const products& p, const shading_point& s) {
                     return fis(p.chain_g1, p, s, 16, 1.0f, false);
                 }});
    v.push_back({"FIS 8, normalised, n.l", "8 + 1", [](const products& p, const shading_point& s) {
                     return fis(p.chain_nl, p, s, 8, 1.0f, true);
                 }});
    if (explore) {
        for (const float c : {0.25f, 4.0f})
            for (const std::uint32_t k : {4u, 8u}) {
                static std::vector<std::string> names;
                names.push_back("FIS " + std::to_string(k) + ", normalised, G1, c = " + (c < 1.0f ? "1/4" : "4"));
                v.push_back({names.back().c_str(), k == 4 ? "4 + 1" : "8 + 1",
                             [k, c](const products& p, const shading_point& s) { return fis(p.chain_g1, p, s, k, c, true); }});
            }
    }
    return v;
}

// ---- measurement ------------------------------------------------------------------------------

/// Squared relative errors and reference variances summed per (material, variant, r, mu).
struct cell_sums {
    std::vector<double> sq;   // [m][var][r][mu]
    std::vector<double> ref;  // [m][r][mu] relative se^2
    std::vector<double> dsq;  // [m][var][r][mu] (Y - Y_ref)^2
    std::vector<double> ysq;  // [m][r][mu] Y_ref^2
    std::size_t nv = 0;
    std::uint32_t points = 0;
    std::size_t at(int m, std::size_t var, int r, int mu) const { return ((std::size_t(m) * nv + var) * n_r + r) * n_mu + mu; }
    std::size_t at_ref(int m, int r, int mu) const { return (std::size_t(m) * n_r + r) * n_mu + mu; }
    double rmse(int m, std::size_t var, int r, int mu) const { return std::sqrt(sq[at(m, var, r, mu)] / points); }
    double ref_se(int m, int r, int mu) const { return std::sqrt(ref[at_ref(m, r, mu)] / points); }
    /// sqrt(sum (Y - Y_ref)^2 / sum Y_ref^2): the error relative to the cell's energy.
    double nrmse(int m, std::size_t var, int r, int mu) const {
        const double y = ysq[at_ref(m, r, mu)];
        return y > 0.0 ? std::sqrt(dsq[at(m, var, r, mu)] / y) : 0.0;
    }
};

template <class Env>
cell_sums measure(const Env& env, const ibl::cube_env_distribution& dist, const products& prod,
                  const std::vector<variant>& vars, std::uint32_t points, std::uint32_t ref_samples) {
    cell_sums c;
    c.nv = vars.size();
    c.points = points;
    c.sq.assign(2 * vars.size() * n_r * n_mu, 0.0);
    c.ref.assign(2 * n_r * n_mu, 0.0);
    c.dsq.assign(2 * vars.size() * n_r * n_mu, 0.0);
    c.ysq.assign(2 * n_r * n_mu, 0.0);
    for (int ir = 0; ir < n_r; ++ir)
        for (int im = 0; im < n_mu; ++im) {
            // Per point: [m][var] squared relative error and [m] reference relative variance.
            std::vector<double> sq(std::size_t(points) * 2 * vars.size()), rv(std::size_t(points) * 2);
            std::vector<double> dq(sq.size()), yq(rv.size());
            ibl::thread_executor{2}(points, [&](std::size_t b, std::size_t e) {
                for (std::size_t k = b; k < e; ++k) {
                    d3 n, v;
                    study::make_point(std::uint32_t(k + 1000 * im), k_n_dot_v[im], n, v);
                    for (int m = 0; m < 2; ++m) {
                        ibl::reference_material rm;
                        rm.diffuse_albedo = d3(0.0);
                        rm.f0 = k_materials[m].f0;
                        rm.roughness = k_roughness[ir];
                        ibl::radiance_reference_options opt;
                        opt.samples = ref_samples;
                        opt.seed = std::uint32_t(k * 7 + 3);
                        const ibl::radiance_estimate ref = ibl::reference_radiance<model>(env, dist, n, v, rm, opt);
                        const double y_ref = ibl::luminance(ref.specular);
                        yq[k * 2 + m] = y_ref * y_ref;
                        rv[k * 2 + m] = y_ref > 0.0 ? ibl::sqr(ibl::luminance(ref.std_error_specular) / y_ref) : 0.0;
                        const shading_point s{f3(n), f3(v), float(k_n_dot_v[im]), float(k_roughness[ir]),
                                              f3(k_materials[m].f0)};
                        for (std::size_t q = 0; q < vars.size(); ++q) {
                            const double y = ibl::luminance(d3(vars[q].fn(prod, s)));
                            sq[(k * 2 + m) * vars.size() + q] = y_ref > 0.0 ? ibl::sqr(y / y_ref - 1.0) : 0.0;
                            dq[(k * 2 + m) * vars.size() + q] = ibl::sqr(y - y_ref);
                        }
                    }
                }
            });
            for (std::uint32_t k = 0; k < points; ++k)
                for (int m = 0; m < 2; ++m) {
                    c.ref[c.at_ref(m, ir, im)] += rv[k * 2 + m];
                    c.ysq[c.at_ref(m, ir, im)] += yq[k * 2 + m];
                    for (std::size_t q = 0; q < vars.size(); ++q) {
                        c.sq[c.at(m, q, ir, im)] += sq[(k * 2 + m) * vars.size() + q];
                        c.dsq[c.at(m, q, ir, im)] += dq[(k * 2 + m) * vars.size() + q];
                    }
                }
        }
    return c;
}

std::vector<std::uint32_t> tool_samples(int levels) {
    std::vector<std::uint32_t> s(std::size_t(levels), 0u);
    for (int l = 1; l < levels; ++l) s[std::size_t(l)] = std::min<std::uint32_t>(512u << (l - 1), 16384u);
    return s;
}


ibl::cubemap<float> bake_chain(const ibl::cubemap<float>& src, ibl::ld_weight w) {
    ibl::prefilter_options o;
    o.levels = g_levels;
    o.base_size = 256;
    o.trilinear = true;
    o.samples_per_level = tool_samples(g_levels);
    o.weight = w;
    return ibl::prefilter(src, o, ibl::thread_executor{2});
}

struct env_result {
    std::string name;
    cell_sums cells;
};

void print_env(const env_result& e, const std::vector<variant>& vars) {
    for (int m = 0; m < 2; ++m) {
        std::printf("\n### %s, %s: relative RMSE / NRMSE (%%) per n.v, pooled over r in {0.3, 0.5, 0.65, 0.8}\n\n",
                    e.name.c_str(), k_materials[m].name);
        std::printf("| variant | taps | n.v = 0.1 | 0.15 | 0.25 | 0.5 | 1 |\n|---|---|---|---|---|---|---|\n");
        for (std::size_t q = 0; q < vars.size(); ++q) {
            std::printf("| %s | %s |", vars[q].name, vars[q].cost);
            for (int im = 0; im < n_mu; ++im) {
                double s = 0.0, t = 0.0;
                for (int ir = 1; ir <= 4; ++ir) {
                    s += ibl::sqr(e.cells.rmse(m, q, ir, im));
                    t += ibl::sqr(e.cells.nrmse(m, q, ir, im));
                }
                std::printf(" %.1f / %.1f |", 100.0 * std::sqrt(s / 4.0), 100.0 * std::sqrt(t / 4.0));
            }
            std::printf("\n");
        }
        std::printf("| reference se | - |");
        for (int im = 0; im < n_mu; ++im) {
            double worst = 0.0;
            for (int ir = 0; ir < n_r; ++ir) worst = std::max(worst, e.cells.ref_se(m, ir, im));
            std::printf(" %.2f |", 100.0 * worst);
        }
        std::printf("\n");
    }
}

void print_detail(const env_result& e, const std::vector<variant>& vars, std::size_t q, int m) {
    std::printf("\n%s, %s, %s: relative RMSE / NRMSE (%%), rows r, columns n.v\n\n| r | 0.1 | 0.15 | 0.25 | 0.5 | 1 |\n"
                "|---|---|---|---|---|---|\n",
                e.name.c_str(), k_materials[m].name, vars[q].name);
    for (int ir = 0; ir < n_r; ++ir) {
        std::printf("| %.2f |", k_roughness[ir]);
        for (int im = 0; im < n_mu; ++im)
            std::printf(" %.1f / %.1f |", 100.0 * e.cells.rmse(m, q, ir, im), 100.0 * e.cells.nrmse(m, q, ir, im));
        std::printf("\n");
    }
}

} // namespace

int main(int argc, char** argv) {
    const bool quick = argc > 1 && std::strcmp(argv[1], "quick") == 0;
    const bool explore = argc > 1 && std::strcmp(argv[1], "explore") == 0;
    const bool fit_mode = argc > 1 && std::strcmp(argv[1], "fit") == 0;
    for (int a = 1; a < argc; ++a)
        if (std::strncmp(argv[a], "levels=", 7) == 0) g_levels = std::clamp(std::atoi(argv[a] + 7), 2, 9);
        else if (std::strncmp(argv[a], "leak=", 5) == 0) g_leak = std::atof(argv[a] + 5);
    std::printf("chain: 256^2, %d levels, linear roughness l / %d\n", g_levels, g_levels - 1);
    const std::uint32_t points = quick || explore ? 8 : 64;
    const std::uint32_t ref_samples = quick || explore ? 1u << 13 : 1u << 15;
    const auto t0 = std::chrono::steady_clock::now();
    std::printf("Runtime approximations against the full integral (reference_radiance, MIS, %u samples, 16 "
                "batches); %u points per cell; model %s\n",
                ref_samples, points, model::name);

    const ibl::dfg_lut dfg = ibl::make_dfg_lut_exact<model>(128, k_layout, 2, ibl::dfg_lut_default_nodes,
                                                            ibl::thread_executor{2});
    const ibl::lobe_lut lobe_nl = ibl::make_lobe_lut<model>(64, k_layout, ibl::ld_weight::n_dot_l, 96, ibl::thread_executor{2});
    const ibl::lobe_lut lobe_g1 = ibl::make_lobe_lut<model>(64, k_layout, ibl::ld_weight::g1, 96, ibl::thread_executor{2});
    std::printf("tables: DFG 128^2, lobe LUTs 64^2 (n.l, G1): %.1f s\n", seconds_since(t0));
    if (fit_mode) make_fits(ibl::ld_weight::g1);
    std::printf("fits: %.1f s\n", seconds_since(t0));
    ibl::lobe_fit_options fo;
    const auto tf = std::chrono::steady_clock::now();
    const ibl::lobe_lut lobe_fit_g1 = ibl::make_lobe_lut_fitted<model>(32, k_layout, ibl::ld_weight::g1, fo, ibl::thread_executor{2});
    const ibl::lobe_lut lobe_fit_nl = ibl::make_lobe_lut_fitted<model>(32, k_layout, ibl::ld_weight::n_dot_l, fo, ibl::thread_executor{2});
    std::printf("fitted lobe LUTs 32^2 (G1, n.l): %.1f s\n", seconds_since(tf));
    fo.taps = 2;
    fo.nodes = 32; // the multi-tap tables: finer fits (16 nodes and 40 iterations lose 3.5% pooled)
    fo.iterations = 150;
    const auto tf2 = std::chrono::steady_clock::now();
    const ibl::lobe_taps_lut taps2_g1 = ibl::make_lobe_taps_lut<model>(32, k_layout, ibl::ld_weight::g1, fo, ibl::thread_executor{2});
    std::printf("fitted 2-tap LUT 32^2: %.1f s, L1 max %.3f mean %.3f\n", seconds_since(tf2), taps2_g1.max_l1, taps2_g1.mean_l1);
    fo.taps = 3;
    const auto tf3 = std::chrono::steady_clock::now();
    const ibl::lobe_taps_lut taps3_g1 = ibl::make_lobe_taps_lut<model>(32, k_layout, ibl::ld_weight::g1, fo, ibl::thread_executor{2});
    std::printf("fitted 3-tap LUT 32^2: %.1f s, L1 max %.3f mean %.3f\n", seconds_since(tf3), taps3_g1.max_l1, taps3_g1.mean_l1);
    const std::vector<variant> vars = fit_mode ? make_fit_variants() : make_variants(explore);

    std::vector<env_result> results;
    auto run = [&](const std::string& name, const auto& integrand, const ibl::cubemap<float>& src,
                   const ibl::cube_env_distribution& dist) {
        const auto t1 = std::chrono::steady_clock::now();
        products p;
        p.chain_nl = bake_chain(src, ibl::ld_weight::n_dot_l);
        p.chain_g1 = bake_chain(src, ibl::ld_weight::g1);
        p.dfg = &dfg;
        p.lobe_nl = &lobe_nl;
        p.lobe_g1 = &lobe_g1;
        p.lobe_fit_g1 = &lobe_fit_g1;
        p.lobe_fit_nl = &lobe_fit_nl;
        p.taps2_g1 = &taps2_g1;
        p.taps3_g1 = &taps3_g1;
        p.exact_ld = [&integrand](const d3& dir, double r) {
            return ibl::reference_ld(integrand, dir, r, 8192, ibl::ld_weight::g1);
        };
        std::printf("%s: chains baked %.1f s\n", name.c_str(), seconds_since(t1));
        results.push_back({name, measure(integrand, dist, p, vars, points, ref_samples)});
        std::printf("%s: measured %.1f s\n", name.c_str(), seconds_since(t1));
        std::fflush(stdout);
    };
    study::for_each_environment(run);

    for (const env_result& e : results) print_env(e, vars);

    // The target: metals under the HDRIs (not the sky), r in {0.3, 0.5, 0.65, 0.8}, n.v in
    // {0.15, 0.25, 0.5, 1}: worst cell and pooled RMSE per variant.
    std::printf("\n### Target: metal, HDRIs, r 0.3..0.8, n.v 0.15..1: worst cell / pooled (%%)\n\n"
                "| variant | taps | rel RMSE worst cell | at (env, r, n.v) | rel RMSE pooled | NRMSE worst | NRMSE pooled |\n"
                "|---|---|---|---|---|---|---|\n");
    for (std::size_t q = 0; q < vars.size(); ++q) {
        double worst = 0.0, pooled = 0.0, nworst = 0.0, npooled = 0.0;
        int cnt = 0;
        std::string where;
        for (const env_result& e : results) {
            if (e.name == "sky + sun") continue;
            for (int ir = 1; ir <= 4; ++ir)
                for (int im = 1; im < n_mu; ++im) {
                    const double x = e.cells.rmse(0, q, ir, im);
                    const double y = e.cells.nrmse(0, q, ir, im);
                    npooled += y * y;
                    nworst = std::max(nworst, y);
                    pooled += x * x;
                    ++cnt;
                    if (x > worst) {
                        worst = x;
                        char buf[96];
                        std::snprintf(buf, sizeof buf, "%s, %.2f, %.2f", e.name.c_str(), k_roughness[ir], k_n_dot_v[im]);
                        where = buf;
                    }
                }
        }
        std::printf("| %s | %s | %.1f | %s | %.1f | %.1f | %.1f |\n", vars[q].name, vars[q].cost, 100.0 * worst,
                    where.c_str(), cnt > 0 ? 100.0 * std::sqrt(pooled / cnt) : 0.0, 100.0 * nworst,
                    cnt > 0 ? 100.0 * std::sqrt(npooled / cnt) : 0.0);
    }
    // Per-cell tables: a few variants, every variant in fit mode.
    for (const env_result& e : results)
        for (std::size_t q = 0; q < vars.size(); ++q)
            if (fit_mode || q == 0 || q == 3 || q == 5 || q == 8) print_detail(e, vars, q, 0);
    std::printf("\ntotal time %.1f s\n", seconds_since(t0));
    return 0;
}
