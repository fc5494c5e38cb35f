// research/sh_rough_study.cpp — the rough levels of a prefiltered chain by spherical-harmonic
// convolution: error against the exact LD per band count and projection level.
//
//   build/release/research/sh_rough_study [--texels N] [FILE.exr ...]   (default: the courtyard and
//                                                                         studio of tests/data, 400)
//   build/release/research/sh_rough_study --quick                        (ctest: one file, 32 texels)
//
// The LD kernel at normal view is zonal about R, so by the Funk-Hecke theorem
//     LD(R) = sum_(l,m) k_l L_lm Y_lm(R),   k_l = integral K(theta) P_l(cos theta) dOmega / integral K dOmega,
// exact for a source band-limited to B - 1. The error of a B-band reconstruction is the kernel's
// mass above band B - 1 (k_l falls like exp(-2 alpha l) for the core; the cut at the horizon
// leaves a slow k_l ~ l^-2 tail) times the source's power there, plus the projection's quadrature
// (texel centres of a mip of face m, exact texel solid angles). The reference is the one of
// fast_tap_study: ibl::ld_texel_sum over level 0 of the 256^2 source cube at N random texels of each
// level of a 256^2, 6-level chain (r = l / 5, n.l weight). Double throughout (the study measures the
// method's error, not a float kernel's).

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <span>
#include <string>
#include <vector>

#include <ibl/bake/prefilter.hpp>
#include <ibl/core/executor.hpp>
#include <ibl/reference/ld_irradiance.hpp>

#include "ld_study.hpp"

using dvec3 = ibl::vec3<double>;
using ld_study::lum;
using ld_study::texel_ref;

namespace {

/// Real orthonormal SH of bands 0..B-1 at the unit direction d (zonal about +Z, no Condon-Shortley
/// phase), index l*l + l + m: the normalised associated Legendre recurrence in z times
/// Re / Im (x + i y)^m.
void sh_eval(int B, const dvec3& d, double* y) {
    double q_mm = 0.5 / std::sqrt(ibl::pi_v<double>); // Q_00
    double cr = 1.0, ci = 0.0;                         // (x + i y)^m
    for (int m = 0; m < B; ++m) {
        if (m > 0) {
            q_mm *= std::sqrt((2.0 * m + 1.0) / (2.0 * m));
            const double nr = cr * d.x - ci * d.y, ni = cr * d.y + ci * d.x;
            cr = nr, ci = ni;
        }
        const double s = m == 0 ? 1.0 : std::sqrt(2.0);
        double q2 = 0.0, q1 = q_mm;
        for (int l = m; l < B; ++l) {
            double q;
            if (l == m) q = q_mm;
            else if (l == m + 1) q = d.z * std::sqrt(2.0 * m + 3.0) * q_mm;
            else {
                const double a = std::sqrt((4.0 * l * l - 1.0) / (double(l) * l - double(m) * m));
                const double b = std::sqrt((double(l - 1) * (l - 1) - double(m) * m) / (4.0 * (l - 1) * (l - 1) - 1.0));
                q = a * (d.z * q1 - b * q2);
            }
            if (l > m) q2 = q1, q1 = q;
            if (m == 0) y[l * l + l] = q;
            else {
                y[l * l + l + m] = s * q * cr;
                y[l * l + l - m] = s * q * ci;
            }
        }
    }
}

using ld_study::base_size;
using ld_study::chain_levels;
using ld_study::level_r;
} // namespace

int main(int argc, char** argv) {
    const ld_study::args args = ld_study::parse(argc, argv);
    const int texels = args.texels;
    const bool quick = args.quick;
    const ibl::ld_weight w = ibl::ld_weight::n_dot_l;
    const std::vector<int> bands = quick ? std::vector<int>{8} : std::vector<int>{6, 8, 10, 12, 16, 20, 24, 32};
    const int max_b = *std::max_element(bands.begin(), bands.end());
    ibl::thread_executor ex{2};
    int bad = 0;
    for (const std::string& file : args.files) {
        const ibl::cubemap<float> cube = ld_study::source_cube(ld_study::load_latlong(file), base_size, ex);
        std::vector<std::vector<texel_ref>> refs(chain_levels);
        for (int l = 1; l < chain_levels; ++l) refs[std::size_t(l)] = ld_study::level_refs(cube, 0, l, base_size >> l, texels, level_r(l), w, ex);
        std::printf("\n%s: 256^2 source, levels 2-5 of a 6-level chain (r = l/5), n.l weight, %d texels per level; "
                    "reference ibl::ld_texel_sum over level 0\n\n",
                    file.substr(file.find_last_of('/') + 1).c_str(), texels);
        // The library: ibl::prefilter's fast filter (tool default: split and coarse tail) with and
        // without the rough levels by spherical harmonics, levels 1-5.
        std::printf("| ibl::prefilter fast | levels by SH (bands) | levels 1-5 rel RMSE |\n|---|---|---|\n");
        for (std::uint32_t n0 : quick ? std::vector<std::uint32_t>{16u} : std::vector<std::uint32_t>{16u, 32u, 48u, 64u}) {
            std::array<std::array<double, chain_levels>, 2> err{};
            for (int sh = 0; sh < 2; ++sh) {
                ibl::prefilter_options o;
                o.method = ibl::prefilter_method::fast;
                o.levels = chain_levels;
                for (int l = 0; l < chain_levels; ++l) o.samples_per_level.push_back(ibl::equal_cost_prefilter_samples(n0, l));
                o.weight = w;
                o.sh_rough.enabled = sh == 1; // the default
                const ibl::specular_chain ch = ibl::prefilter(cube, o, ex);
                std::string b;
                for (int l = 1; l < chain_levels; ++l) {
                    ibl::prefilter_level lp;
                    lp.level = l, lp.roughness = level_r(l);
                    const int nb = ibl::detail::prefilter_sh_bands<ibl::ggx_lobe>(o, lp);
                    if (!b.empty()) b.push_back(' ');
                    if (nb) b.append(std::to_string(nb));
                    else b.push_back('-');
                }
                std::printf("| %u x 4^(l-1) samples | %s |", n0, b.c_str());
                for (int l = 1; l < chain_levels; ++l) {
                    const double e = ld_study::rel_rmse(refs[std::size_t(l)], [&](int f, int x, int y) { return ch.texel(f, x, y, l); });
                    bad += std::isfinite(e) ? 0 : 1;
                    err[std::size_t(sh)][std::size_t(l)] = e;
                    std::printf(" %.3g", e);
                }
                std::printf(" |\n");
                std::fflush(stdout);
            }
            // --quick (ctest): the levels by spherical harmonics below the tap sets on levels 2-5.
            for (int l = 2; l < chain_levels; ++l)
                if (!(err[1][std::size_t(l)] < err[0][std::size_t(l)])) {
                    std::printf("level %d: spherical harmonics %g not below the tap set %g\n", l, err[1][std::size_t(l)], err[0][std::size_t(l)]);
                    ++bad;
                }
        }
        std::printf("\n| projected from (face) | bands | levels 2-5 rel RMSE |\n|---|---|---|\n");
        for (int pl : quick ? std::vector<int>{3} : std::vector<int>{1, 2, 3}) {
            const int m = cube.size(pl);
            // Project level pl once to max_b bands (the lower band counts are its prefixes).
            const int nc = max_b * max_b;
            std::vector<std::array<std::vector<double>, 3>> part(6);
            ex(6, [&](std::size_t b, std::size_t e) {
                std::vector<double> y(static_cast<std::size_t>(nc));
                for (std::size_t f = b; f < e; ++f) {
                    for (auto& c : part[f]) c.assign(std::size_t(nc), 0.0);
                    for (int ty = 0; ty < m; ++ty)
                        for (int tx = 0; tx < m; ++tx) {
                            const dvec3 d = ibl::cube_texel_direction<double>(int(f), tx, ty, m);
                            const double om = ibl::cube_texel_solid_angle<double>(tx, ty, m);
                            const dvec3 L(cube.texel(int(f), tx, ty, pl));
                            sh_eval(max_b, d, y.data());
                            for (int i = 0; i < nc; ++i) {
                                const double v = y[std::size_t(i)] * om;
                                part[f][0][std::size_t(i)] += v * L.x;
                                part[f][1][std::size_t(i)] += v * L.y;
                                part[f][2][std::size_t(i)] += v * L.z;
                            }
                        }
                }
            });
            std::array<std::vector<double>, 3> coef;
            for (int c = 0; c < 3; ++c) {
                coef[std::size_t(c)].assign(std::size_t(nc), 0.0);
                for (int f = 0; f < 6; ++f)
                    for (int i = 0; i < nc; ++i) coef[std::size_t(c)][std::size_t(i)] += part[std::size_t(f)][std::size_t(c)][std::size_t(i)];
            }
            for (int B : bands) {
                std::printf("| level %d (%d^2) | %d |", pl, m, B);
                std::vector<double> y(static_cast<std::size_t>(max_b * max_b));
                for (int l = 2; l < chain_levels; ++l) {
                    const std::vector<double> kl = ibl::detail::zonal_band_factors<ibl::ggx_lobe>(B, level_r(l), w);
                    double s = 0;
                    for (const texel_ref& t : refs[std::size_t(l)]) {
                        sh_eval(B, t.dir, y.data());
                        dvec3 v(0.0);
                        for (int bl = 0; bl < B; ++bl)
                            for (int mm = -bl; mm <= bl; ++mm) {
                                const std::size_t i = std::size_t(bl * bl + bl + mm);
                                const double g = kl[std::size_t(bl)] * y[i];
                                v.x += g * coef[0][i], v.y += g * coef[1][i], v.z += g * coef[2][i];
                            }
                        const double a = lum(v), b = lum(t.ref);
                        s += (a - b) * (a - b) / (b * b);
                    }
                    const double e = std::sqrt(s / double(refs[std::size_t(l)].size()));
                    bad += std::isfinite(e) ? 0 : 1;
                    std::printf(" %.3g", e);
                }
                std::printf(" |\n");
                std::fflush(stdout);
            }
        }
    }
    return bad ? 1 : 0;
}
