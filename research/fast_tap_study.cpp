// research/fast_tap_study.cpp — the fast filter's tap sets against exact references on real
// HDRIs: the table "Against exact references" of docs/ibl-bake.md ("Fast filter").
//
//   build/release/research/fast_tap_study [--texels N] [FILE.exr ...]   (default: the courtyard and
//                                                                         studio of tests/data, 400)
//   build/release/research/fast_tap_study --quick                        (ctest: one file, 32 texels)
//
// What it measures. The reference is ibl::ld_texel_sum over level 0 of the 256^2 source cube (the
// exact LD of the cube the chains are filtered from: no sampling noise) at N random texels per
// level of a 256^2, 6-level chain (r = l / 5, n.l weight), and the table lists:
//   * the references ibl-bake's check used before (reference_ld at 2048 and 8192 GGX samples on
//     the lat-long map: --checks fast and full at the default quality): on a real HDRI they are as noisy as the filters are wrong, and they draw
//     filtered importance sampling's own Hammersley points (at equal counts FIS shares their error);
//   * ld_texel_sum at ld_texel_sum_level (the coarser level the check sums now) against level 0;
//   * filtered importance sampling with the default schedule (512 x 2^(l-1), trilinear, bias 0.5);
//   * the fast filter's tap set (bake/prefilter_fast.hpp, the fitted shapes, nearest reads), no peak split;
//   * candidates for its successor:
//     - the spiral with a fixed shape (tail 2.5, lod bias -0.5: finer reads);
//     - the coarse tail: level l is filtered coarse to fine as
//         LD_l(R) = (Z_rest / Z_l) [spiral of K_l - c K_(l+1)](R) + (c Z_(l+1) / Z_l) LD_(l+1)(R),
//       c the largest multiple of the next level's kernel under this one's on the hemisphere (GGX
//       tails fall as alpha^2 / theta^4, so K_l - c K_(l+1) falls as theta^-6: the heavy tail is
//       read from the finished coarser level, one bilinear tap, and the spiral's samples go to the
//       core); Z = the kernels' integrals;
//     - a polar grid: a centre disk of radius alpha / 2, then bands growing by rho, square cells,
//       each read at the lod of its solid angle (bias -0.5), weighted by its exact kernel mass.
// Taps per chain: sum over levels 1-5 of 6 n_l^2 taps_l (two per trilinear sample). The sun of an
// analytic sky is left out: the peak split (bake/prefilter_peaks.hpp) takes such lights out of
// every tap set.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <array>
#include <cstdlib>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include <ibl/bake/prefilter.hpp>
#include <ibl/core/executor.hpp>
#include <ibl/env/convert.hpp>
#include <ibl/env/latlong.hpp>
#include <ibl/reference/ld_irradiance.hpp>
#include <ibl/reference/radiance.hpp>

#include "ld_study.hpp"

using ibl::vec3;
using dvec3 = ibl::vec3<double>;
using ld_study::lum;
using ld_study::texel_ref;

namespace {

double cdf_at_theta(const ibl::detail::fast_radial_cdf& c, double t) {
    auto it = std::lower_bound(c.theta.begin(), c.theta.end(), t);
    if (it == c.theta.begin()) return 0.0;
    if (it == c.theta.end()) return 1.0;
    const std::size_t i = std::size_t(it - c.theta.begin());
    const double f = (t - c.theta[i - 1]) / (c.theta[i] - c.theta[i - 1]);
    return c.cdf[i - 1] + f * (c.cdf[i] - c.cdf[i - 1]);
}

// Polar grid: a centre disk of radius theta0, then bands growing by rho up to pi/2, each of
// m = round(2 pi theta_mid / width x aspect) cells with its tap at the band's mass-median radius.
ibl::sphere_sample_table<float> polar_table(const ibl::cubemap<float>& cube, double r, double theta0, double rho,
                                            double aspect, double bias, bool tri, ibl::ld_weight w, double tmax = 0.5 * M_PI) {
    const ibl::detail::fast_radial_cdf c = ibl::detail::make_fast_radial_cdf<ibl::ggx_lobe>(r, w);
    ibl::sphere_sample_table<float> t;
    t.trilinear = tri;
    auto lod = [&](double omega) { return double(cube.lod_for_solid_angle(float(omega * std::exp2(2.0 * bias)))); };
    // centre tap
    {
        const double m = cdf_at_theta(c, theta0);
        const double om = 2.0 * M_PI * (1.0 - std::cos(theta0));
        t.push(vec3<float>(0, 0, 1), float(m), float(lod(om)));
    }
    double lo = theta0;
    int band = 0;
    while (lo < tmax - 1e-9) {
        double hi = std::min(tmax, lo * rho);
        if (tmax - hi < 0.3 * (hi - lo)) hi = tmax;
        const double c0 = cdf_at_theta(c, lo), c1 = cdf_at_theta(c, hi);
        const double mid = ibl::detail::fast_cdf_at(c, 0.5 * (c0 + c1));
        const int m = std::max(3, int(std::lround(2.0 * M_PI * 0.5 * (lo + hi) / (hi - lo) * aspect)));
        const double om = 2.0 * M_PI * (std::cos(lo) - std::cos(hi)) / m;
        const double off = (band % 2) * 0.5;
        for (int j = 0; j < m; ++j) {
            const double ph = 2.0 * M_PI * (j + off) / m;
            t.push(vec3<float>(float(std::sin(mid) * std::cos(ph)), float(std::sin(mid) * std::sin(ph)), float(std::cos(mid))),
                   float((c1 - c0) / m), float(lod(om)));
        }
        lo = hi;
        ++band;
    }
    t.drawn = std::uint32_t(t.size());
    return t;
}

/// A kernel and its radial CDF (ibl::detail::make_radial_cdf_of on the grid of roughness r).
struct kernel_tab {
    ibl::detail::fast_radial_cdf cdf;
    std::function<double(double)> k;
    [[nodiscard]] double total() const { return cdf.total; }
};
template <class K> kernel_tab tabulate(K kf, double r) {
    return {ibl::detail::make_radial_cdf_of(r, kf), std::function<double(double)>(kf)};
}
ibl::sphere_sample_table<float> spiral_table(const ibl::cubemap<float>& cube, const kernel_tab& c, std::uint32_t n,
                                             double tail, double bias, bool tri) {
    const double norm = 2.0 * M_PI * c.total();
    auto warp = [&](double x) { return 1.0 - std::pow(1.0 - x, tail); };
    ibl::sphere_sample_table<float> t;
    t.trilinear = tri;
    for (std::uint32_t i = 0; i < n; ++i) {
        const double u0 = warp(double(i) / n), u1 = i + 1 == n ? 1.0 : warp(double(i + 1) / n);
        const double mass = u1 - u0;
        const double theta = ibl::detail::fast_cdf_at(c.cdf, warp((i + 0.5) / n));
        const double k = c.k(theta);
        if (!(mass > 0) || !(k > 0)) continue;
        const double omega = mass / (k / norm);
        const double phi = 2.399963229728653 * i;
        t.push(vec3<float>(float(std::sin(theta) * std::cos(phi)), float(std::sin(theta) * std::sin(phi)), float(std::cos(theta))),
               float(mass), float(cube.lod_for_solid_angle(float(omega * std::exp2(2.0 * bias)))));
    }
    t.drawn = n;
    return t;
}

double rel_rmse(const std::vector<vec3<float>>& tex, int n, const std::vector<texel_ref>& refs) {
    return ld_study::rel_rmse(refs, [&](int f, int x, int y) { return tex[ibl::cube_texel_index(f, x, y, n)]; });
}
struct design {
    std::string name;
    // The table of level l (roughness r) for a source; reuse > 0 marks the coarse-tail designs.
    std::function<ibl::sphere_sample_table<float>(const ibl::cubemap<float>&, int, double)> table;
    bool reuse = false;
    double tail = 1.0, bias = 0.0;
    std::uint32_t n0 = 0;
    double max_share = 1.0; ///< coarse tail: the largest share of the kernel read from the next level
    bool library = false;   ///< ibl::prefilter itself (method fast, coarse_tail = reuse)
    bool peaks = false;     ///< library: with the peak split (the tool's default)
};

/// Per level of the chain, the rel RMSE of luminance at the reference texels and the taps.
struct chain_result {
    std::vector<double> err;
    double taps = 0;
};

using ld_study::base_size;
using ld_study::chain_levels;
using ld_study::level_r;
std::uint32_t doubling(std::uint32_t n0, int l) { return ibl::doubling_prefilter_samples(n0, l); }

chain_result run_design(const design& d, const ibl::cubemap<float>& cube, const std::vector<std::vector<texel_ref>>& refs,
                        ibl::ld_weight w, ibl::thread_executor& ex) {
    chain_result res;
    res.err.assign(chain_levels, 0.0);
    if (d.library) {
        ibl::prefilter_options o;
        o.method = ibl::prefilter_method::fast;
        o.levels = chain_levels;
        o.samples_per_level.assign(std::size_t(chain_levels), 0u);
        for (int l = 1; l < chain_levels; ++l) o.samples_per_level[std::size_t(l)] = doubling(d.n0, l);
        o.samples = d.n0;
        o.weight = w;
        o.peaks.enabled = d.peaks;
        o.coarse_tail = d.reuse;
        o.sh_rough.enabled = false; // the tap sets on every level (sh_rough_study measures the rough levels by SH)
        const ibl::specular_chain ch = ibl::prefilter(cube, o, ex);
        for (int l = 1; l < chain_levels; ++l) {
            const int n = ch.size(l);
            std::vector<vec3<float>> out(std::size_t(6 * n * n));
            for (int f = 0; f < 6; ++f)
                for (int y = 0; y < n; ++y)
                    for (int x = 0; x < n; ++x) out[ibl::cube_texel_index(f, x, y, n)] = ch.texel(f, x, y, l);
            res.err[std::size_t(l)] = rel_rmse(out, n, refs[std::size_t(l)]);
            const auto t = ibl::make_ld_table_for<float>(cube, level_r(l), doubling(d.n0, l), ibl::prefilter_method::fast, 0.0, w);
            res.taps += 6.0 * n * n * double(t.size() + (d.reuse && (n / 2) >= ibl::detail::prefilter_coarse_tail_min_face ? 1 : 0));
        }
        return res;
    }
    ibl::cubemap<float> next(1, 1); // the coarser level just computed (coarse-tail designs)
    for (int l = chain_levels - 1; l >= 1; --l) {
        const int n = base_size >> l;
        const double r = level_r(l);
        std::vector<vec3<float>> out;
        if (d.reuse && l + 1 < chain_levels) {
            const double r1 = level_r(l + 1);
            auto K0 = [&](double t) { return ibl::detail::fast_kernel<ibl::ggx_lobe>(t, r, w); };
            auto K1 = [&](double t) { return ibl::detail::fast_kernel<ibl::ggx_lobe>(t, r1, w); };
            double c = 1e300; // the largest multiple of K1 under K0 on the hemisphere
            for (int i = 1; i < 4000; ++i) {
                const double t = 0.5 * M_PI * i / 4000.0;
                if (K1(t) > 0 && K0(t) > 0) c = std::min(c, K0(t) / K1(t));
            }
            const kernel_tab k0 = tabulate(K0, r), k1 = tabulate(K1, r1);
            c = std::min(c, d.max_share * k0.total() / k1.total());
            const kernel_tab rest = tabulate([&](double t) { return K0(t) - c * K1(t); }, r);
            const double a_rest = rest.total() / k0.total(), a_next = c * k1.total() / k0.total();
            const std::uint32_t ns = doubling(d.n0, l);
            const ibl::fast_tap_shape fs = ibl::fast_shape(r, ns, w);
            const auto t = d.tail > 0 ? spiral_table(cube, rest, ns, d.tail, d.bias, false) : spiral_table(cube, rest, ns, fs.tail, fs.lod_bias, false);
            res.taps += 6.0 * n * n * double(t.size() + 1);
            const auto tex = ibl::convolve_faces(cube, t, n, ex);
            out.resize(tex.size());
            for (int f = 0; f < 6; ++f)
                for (int y = 0; y < n; ++y)
                    for (int x = 0; x < n; ++x) {
                        const std::size_t i = ibl::cube_texel_index(f, x, y, n);
                        const vec3<float> dir = ibl::cube_texel_direction<float>(f, x, y, n);
                        out[i] = tex[i] * float(a_rest) + float(a_next) * vec3<float>(next.radiance(dir, 0.f));
                    }
        } else {
            const auto t = d.table(cube, l, r);
            res.taps += 6.0 * n * n * double(t.size()) * (t.trilinear ? 2.0 : 1.0);
            out = ibl::convolve_faces(cube, t, n, ex);
        }
        res.err[std::size_t(l)] = rel_rmse(out, n, refs[std::size_t(l)]);
        next = ibl::cubemap<float>(n, 1);
        next.fill(0, [&](int f, int x, int y) { return out[ibl::cube_texel_index(f, x, y, n)]; });
        next.update_borders();
    }
    return res;
}
} // namespace

int main(int argc, char** argv) {
    const ld_study::args args = ld_study::parse(argc, argv);
    const int texels = args.texels;
    const bool quick = args.quick;
    const ibl::ld_weight w = ibl::ld_weight::n_dot_l;
    std::vector<design> designs;
    if (!quick) designs.push_back({"fis default (512, trilinear)", [&](const ibl::cubemap<float>& c, int l, double r) {
                           auto t = ibl::make_ld_table_for<float>(c, r, doubling(512, l), ibl::prefilter_method::filtered_importance, 0.5, w);
                           t.trilinear = true;
                           return t;
                       }});
    for (std::uint32_t n0 : {8u, 16u, 32u, 64u, 128u, 256u}) {
        if (quick && n0 > 16) break;
        designs.push_back({"fast, fitted shapes, " + std::to_string(n0), [=](const ibl::cubemap<float>& c, int l, double r) {
                               auto t = ibl::make_ld_table_for<float>(c, r, doubling(n0, l), ibl::prefilter_method::fast, 0.0, w);
                               t.trilinear = false;
                               return t;
                           }});
        if (!quick) {
            designs.push_back({"ibl::prefilter fast, coarse tail (the default), " + std::to_string(n0), nullptr, true, 0.0, 0.0, n0, 1.0, true});
            designs.push_back({"ibl::prefilter fast, coarse tail and peak split (the tool's default), " + std::to_string(n0), nullptr, true,
                               0.0, 0.0, n0, 1.0, true, true});
        }
    }
    for (std::uint32_t n0 : {16u, 32u, 64u, 128u}) {
        if (quick && n0 > 16) break;
        designs.push_back({"spiral tail 2.5 bias -0.5, " + std::to_string(n0), [=](const ibl::cubemap<float>& c, int l, double r) {
                               return spiral_table(c, tabulate([&](double t) { return ibl::detail::fast_kernel<ibl::ggx_lobe>(t, r, w); }, r),
                                                   doubling(n0, l), 2.5, -0.5, false);
                           }});
        design d{"coarse tail + spiral 2.5 / -0.5, " + std::to_string(n0), designs.back().table, true, 2.5, -0.5, n0};
        designs.push_back(d);
    }
    for (double rho : {1.5, 2.0}) {
        if (quick) break;
        designs.push_back({"polar grid rho " + std::to_string(rho).substr(0, 3) + " bias -0.5", [=](const ibl::cubemap<float>& c, int, double r) {
                               const double a = std::max(r * r, 1e-3);
                               return polar_table(c, r, 0.5 * a, rho, 1.0, -0.5, false, w);
                           }});
    }
    ibl::thread_executor ex{2};
    for (const std::string& file : args.files) {
        const ibl::latlong<float> map = ld_study::load_latlong(file);
        const ibl::cubemap<float> cube = ld_study::source_cube(map, base_size, ex);
        std::vector<std::vector<texel_ref>> refs(chain_levels);
        // Per level: the old check's references (reference_ld at 2048 and 8192 samples on the
        // lat-long map) and ld_texel_sum at ld_texel_sum_level against the exact texel sum at level 0.
        std::vector<std::array<double, 3>> floor(chain_levels);
        std::vector<int> sum_level(chain_levels, 0);
        for (int l = 1; l < chain_levels; ++l) {
            const double r = level_r(l);
            auto& rl = refs[std::size_t(l)];
            rl = ld_study::level_refs(cube, 0, l, base_size >> l, texels, r, w, ex);
            const std::vector<dvec3> dirs = ld_study::directions(rl);
            sum_level[std::size_t(l)] = ibl::ld_texel_sum_level(cube, r);
            const std::vector<dvec3> coarse = ibl::ld_texel_sum(cube, sum_level[std::size_t(l)], std::span<const dvec3>(dirs), r, w, ex);
            std::vector<std::array<dvec3, 3>> check(rl.size());
            ex(rl.size(), [&](std::size_t b, std::size_t e) {
                for (std::size_t i = b; i < e; ++i) {
                    check[i] = {ibl::reference_ld(map, dirs[i], r, 2048, w), ibl::reference_ld(map, dirs[i], r, 8192, w), coarse[i]};
                }
            });
            for (int q = 0; q < 3; ++q) {
                double s = 0;
                for (std::size_t i = 0; i < rl.size(); ++i) {
                    const double a = lum(check[i][std::size_t(q)]), b = lum(rl[i].ref);
                    s += (a - b) * (a - b) / (b * b);
                }
                floor[std::size_t(l)][std::size_t(q)] = std::sqrt(s / double(rl.size()));
            }
        }
        std::printf("\n%s: 256^2, 6 levels (r = l/5), n.l weight, %d texels per level, reference: ibl::ld_texel_sum over "
                    "level 0 of the 256^2 source cube (exact)\n\n",
                    file.substr(file.find_last_of('/') + 1).c_str(), texels);
        std::printf("| tap set (samples at level 1, doubling) | taps per chain | levels 1-5 rel RMSE |\n|---|---|---|\n");
        std::printf("| reference_ld on the lat-long map, 2048 samples (the old --checks fast) | - |");
        for (int l = 1; l < chain_levels; ++l) std::printf(" %.3g", floor[std::size_t(l)][0]);
        std::printf(" |\n| reference_ld on the lat-long map, 8192 samples (the old --checks full) | - |");
        for (int l = 1; l < chain_levels; ++l) std::printf(" %.3g", floor[std::size_t(l)][1]);
        std::printf(" |\n| ld_texel_sum at ld_texel_sum_level (levels");
        for (int l = 1; l < chain_levels; ++l) std::printf(" %d", sum_level[std::size_t(l)]);
        std::printf("; the check's reference) | - |");
        for (int l = 1; l < chain_levels; ++l) std::printf(" %.3g", floor[std::size_t(l)][2]);
        std::printf(" |\n");
        std::vector<chain_result> results;
        for (const design& d : designs) {
            const chain_result cr = run_design(d, cube, refs, w, ex);
            results.push_back(cr);
            std::printf("| %s | %.2f M |", d.name.c_str(), cr.taps * 1e-6);
            for (int l = 1; l < chain_levels; ++l) std::printf(" %.3g", cr.err[std::size_t(l)]);
            std::printf(" |\n");
            std::fflush(stdout);
        }
        // --quick (ctest): every figure finite, and the coarse tail below the same spiral without
        // it on levels 1 and 2 (the designs are pushed as pairs: spiral, then coarse tail).
        int bad = 0;
        for (std::size_t i = 0; i < designs.size(); ++i)
            for (int l = 1; l < chain_levels; ++l) bad += std::isfinite(results[i].err[std::size_t(l)]) ? 0 : 1;
        for (std::size_t i = 1; i < designs.size(); ++i)
            if (designs[i].reuse && !designs[i - 1].reuse)
                for (int l = 1; l <= 2; ++l)
                    if (!(results[i].err[std::size_t(l)] < results[i - 1].err[std::size_t(l)])) {
                        std::printf("coarse tail not below the spiral at level %d: %g >= %g\n", l, results[i].err[std::size_t(l)],
                                    results[i - 1].err[std::size_t(l)]);
                        ++bad;
                    }
        if (quick && bad) return 1;
    }
    return 0;
}
