// research/fast_filter_fit.cpp — the offline fit of the fast filter's tap shapes
// (include/ibl/bake/prefilter_fast.hpp), which writes include/ibl/bake/prefilter_fast_tables.hpp.
//
//   build/release/research/fast_filter_fit --write-header include/ibl/bake/prefilter_fast_tables.hpp
//   build/release/research/fast_filter_fit --show R BUDGET     one fit, every grid candidate's error,
//                                                              and the compiled-in table's shape
//   build/release/research/fast_filter_fit --fis --show R N    filtered importance sampling's error
//   build/release/research/fast_filter_fit --check             re-fits two rows of the compiled-in
//                                                              table; fails when they differ (ctest)
//   --objective natural|point   the content the shapes are fitted on (default natural, below)
//   --nearest | --trilinear     the table's reads in the objective (natural: nearest by default,
//                               the default plan's reads; point: trilinear)
//   --contrast C                point: one contrast C instead of 10, 100 and 1000
//
// Objective (default): natural illumination. Synthetic environments with the statistics of real
// illumination maps (Dror, Willsky & Adelson 2004): log-luminance of about 1 / f^2 power spectrum,
// a bright sky over a darker ground, and disk lights below the peak split's reach (the derivation
// is at natural_env below); the error is the relative RMSE of the filtered luminance against the
// exact LD of each cube (ibl::ld_texel_sum) at random texel directions, the mean over the
// environments: what ibl-bake's check reports. Fitted on that, the shapes read finer mips (biases
// -0.3 .. -0.7 at r <= 0.3) and have fewer outliers than the point-light fit (whose rows at
// r = 0.8-1 and N = 64 had tails of 0.6 and errors twice the refit's on this content);
// research/fast_tap_study.cpp measures the result on the two test HDRIs, which the fit never sees.
//
// Objective (--objective point, the first one): a 256^2 source that is one bright texel, at a face
// centre, on an edge and at a corner; its exact LD response E at direction R is the kernel about
// R integrated over the source's bilinear reconstruction of that texel (8 x 8 sub-samples of the
// 3 x 3 texels around it, exact sub-sample solid angles), and the filter's response F is the
// fast table read through the source's exact-solid-angle mips with trilinear reads, as prefilter
// reads them. On a uniform background B = max E / c (the bright texel's filtered peak c times the
// background: c = 10, 100, 1000) the filtered result is B + F against B + E; the error is the RMS
// of the relative error (F - E) / (B + E) over R within pi/2 of the texel (the rings about the
// texel that make_dirs lays out to pi/2 + 0.5, 16 azimuths, weighted by solid angle), the mean
// over the three positions and contrasts. With --nearest, or with contrasts of 2-10, its biases
// move to +0 .. +0.5, while on real HDRIs finer reads do better: a point light is not the content
// that decides the error there.
//
// Search per (weight, roughness, samples N): the spiral's tail exponent on a grid of 5 (0.8 .. 3.4)
// and the lod bias on a grid of 7 (-1 .. 1), then a local refinement of both about the best point.
// Roughness 0.05 .. 1 in steps of 0.05; N = 8 .. 2048 (powers of two); both LD weights. Each row
// also records filtered importance sampling's error with the same N (bias 0.5, Hammersley,
// trilinear). 360 fits take about 17 minutes on 2 cores (release build; 19 min with another build running).

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include <ibl/bake/prefilter.hpp>
#include <ibl/core/frame.hpp>
#include <ibl/env/cube_geometry.hpp>
#include <ibl/env/cubemap.hpp>
#include <ibl/reference/ld_irradiance.hpp>
#include <ibl/reference/radiance.hpp>

namespace {

constexpr int source_size = 256;
constexpr int sub = 8;

struct probe {
    ibl::cubemap<float> cube{1, 1};
    ibl::vec3<double> dir{};
    std::vector<ibl::vec3<double>> pts; ///< sub-sample directions of the 3 x 3 texels
    std::vector<double> val;            ///< bilinear reconstruction of the bright texel x solid angle
};

probe make_probe(int face, int x, int y) {
    probe p;
    const int n = source_size;
    p.cube = ibl::cubemap<float>(n, 0);
    p.cube.fill(0, [&](int f, int tx, int ty) {
        return ibl::vec3<float>(f == face && tx == x && ty == y ? 1.f : 0.f);
    });
    p.cube.generate_mips();
    p.dir = ibl::cube_texel_direction<double>(face, x, y, n);
    // Sub-samples of the 3 x 3 texels around (x, y) on the same face (the probes sit where the
    // 3 x 3 block may cross an edge: those sub-samples are read through the cube's seamless
    // lookup, so the reconstruction is the one the source has).
    for (int ty = y - 1; ty <= y + 1; ++ty)
        for (int tx = x - 1; tx <= x + 1; ++tx)
            for (int j = 0; j < sub; ++j)
                for (int i = 0; i < sub; ++i) {
                    const double u = (double(tx) + (i + 0.5) / sub) / n * 2.0 - 1.0;
                    const double v = (double(ty) + (j + 0.5) / sub) / n * 2.0 - 1.0;
                    if (std::fabs(u) > 1.0 || std::fabs(v) > 1.0) continue; // off the face: outside the reconstruction's support there
                    const ibl::vec3<double> d = glm::normalize(ibl::cube_face_point<double>(face, u, v));
                    const double l = double(p.cube.radiance(ibl::vec3<float>(d), 0.f).x);
                    if (!(l > 0.0)) continue;
                    const double da = (2.0 / (n * sub)) * (2.0 / (n * sub)) / std::pow(1.0 + u * u + v * v, 1.5);
                    p.pts.push_back(d);
                    p.val.push_back(l * da);
                }
    return p;
}

struct rdir {
    ibl::vec3<double> d;
    double w;          ///< solid angle it stands for
    double rho = 0.0;  ///< angle from the bright texel's direction
};

/// Output directions about dir: rings at angles from 0 out to pi/2 + 0.5, 16 azimuths.
std::vector<rdir> make_dirs(const ibl::vec3<double>& dir, double scale) {
    std::vector<rdir> out;
    const ibl::frame<double> fr = ibl::make_frame(dir);
    const double lo = std::max(0.05 * scale, 1e-4), hi = 0.5 * ibl::pi_v<double> + 0.5;
    constexpr int rings = 56, az = 16;
    double prev = 0.0;
    out.push_back({dir, 0.0, 0.0});
    std::vector<double> edges;
    for (int i = 0; i <= rings; ++i) edges.push_back(lo * std::pow(hi / lo, double(i) / rings));
    out[0].w = 2.0 * ibl::pi_v<double> * (1.0 - std::cos(0.5 * edges[0]));
    prev = 0.5 * edges[0];
    for (int i = 0; i <= rings; ++i) {
        const double rho = edges[std::size_t(i)];
        const double next = i < rings ? 0.5 * (rho + edges[std::size_t(i) + 1]) : rho;
        const double ring = 2.0 * ibl::pi_v<double> * (std::cos(prev) - std::cos(next));
        for (int j = 0; j < az; ++j) {
            const double phi = 2.0 * ibl::pi_v<double> * (j + 0.25 * (i % 4)) / az;
            out.push_back({fr.to_world(ibl::vec3<double>(std::sin(rho) * std::cos(phi), std::sin(rho) * std::sin(phi), std::cos(rho))),
                           ring / az, rho});
        }
        prev = next;
    }
    return out;
}

struct fit_case {
    ibl::ld_weight weight;
    double roughness;
    std::uint32_t budget;
};

/// The fast table's reads in the objective: false = trilinear at each tap's lod, true = the
/// nearest level round(lod) (what the fast filter's default plan reads).
bool g_nearest = false;
/// The contrasts of the objective (the bright texel's filtered peak over the background).
std::vector<double> g_contrasts{10.0, 100.0, 1000.0};

struct evaluator {
    const std::vector<probe>* probes;
    fit_case c;
    std::vector<std::vector<rdir>> dirs;
    std::vector<std::vector<double>> exact; ///< per probe, per direction: exact response

    void init() {
        // The kernel's integral over the sphere (the library's radial CDF; the test of
        // prefilter_fast checks that CDF against an independent quadrature).
        const double norm = 2.0 * ibl::pi_v<double> * ibl::detail::make_fast_radial_cdf<ibl::ggx_lobe>(c.roughness, c.weight).total;
        for (const probe& p : *probes) {
            dirs.push_back(make_dirs(p.dir, ibl::fast_lobe_scale(c.roughness)));
            std::vector<double> e;
            for (const rdir& r : dirs.back()) {
                double acc = 0.0;
                for (std::size_t k = 0; k < p.pts.size(); ++k) {
                    const double cosang = std::clamp(glm::dot(r.d, p.pts[k]), -1.0, 1.0);
                    acc += p.val[k] * ibl::detail::fast_kernel<ibl::ggx_lobe>(std::acos(cosang), c.roughness, c.weight);
                }
                e.push_back(acc / norm);
            }
            exact.push_back(std::move(e));
        }
    }

    double error(const ibl::fast_tap_shape& shape) const {
        return error_of([&](const probe& p) {
            ibl::sphere_sample_table<double> t = ibl::make_fast_ld_table<double>(
                c.roughness, c.budget, shape, [&](double omega) { return double(p.cube.lod_for_solid_angle(float(omega))); }, c.weight);
            if (g_nearest) { // make_taps' rule: the level of floor(lod) + 1 from a fraction of 0.5 up
                const double max_lod = double(p.cube.levels() - 1);
                for (double& l : t.lod) {
                    const double c = std::clamp(l, 0.0, max_lod);
                    l = c - std::floor(c) < 0.5 ? std::floor(c) : std::floor(c) + 1.0;
                }
            }
            return t;
        });
    }
    /// The same error for filtered importance sampling with N samples (bias 0.5, trilinear).
    double error_fis(std::uint32_t samples) const {
        return error_of([&](const probe& p) {
            return ibl::make_ld_table_for<double>(p.cube, c.roughness, samples, ibl::prefilter_method::filtered_importance, 0.5, c.weight);
        });
    }
    template <class MakeTable> double error_of(MakeTable&& make_table) const {
        double total = 0.0;
        int terms = 0;
        for (std::size_t pi = 0; pi < probes->size(); ++pi) {
            const probe& p = (*probes)[pi];
            const ibl::sphere_sample_table<double> t = make_table(p);
            double wsum = 0.0;
            for (double w : t.weight) wsum += w;
            std::vector<double> got(dirs[pi].size());
            for (std::size_t k = 0; k < dirs[pi].size(); ++k) {
                const ibl::frame<double> fr = ibl::make_frame(dirs[pi][k].d);
                double acc = 0.0;
                for (std::size_t i = 0; i < t.size(); ++i) {
                    const ibl::vec3<double> l = fr.to_world(ibl::vec3<double>(t.x[i], t.y[i], t.z[i]));
                    acc += t.weight[i] * double(p.cube.radiance(ibl::vec3<float>(l), float(t.lod[i])).x);
                }
                got[k] = acc / wsum;
            }
            const double peak = *std::max_element(exact[pi].begin(), exact[pi].end());
            for (double c : g_contrasts) {
                const double bg = peak / c;
                double se = 0.0, area = 0.0;
                for (std::size_t k = 0; k < dirs[pi].size(); ++k) {
                    if (dirs[pi][k].rho >= 0.5 * ibl::pi_v<double>) continue;
                    const double e = (got[k] - exact[pi][k]) / (bg + exact[pi][k]);
                    se += e * e * dirs[pi][k].w;
                    area += dirs[pi][k].w;
                }
                total += std::sqrt(se / area);
                ++terms;
            }
        }
        return total / double(terms);
    }
};

// ---------------------------------------------------------------------------------------------
// The natural-illumination objective (--objective natural, the default). Real illumination maps
// (Dror, Willsky & Adelson 2004, "Statistical characterization of real-world illumination") have
// log-luminance with a power spectrum close to 1 / f^2 (equal variance per octave), a heavy upper
// tail from compact sources, and a bright upper hemisphere over a darker ground. The synthetic
// environments reproduce those three traits, nothing of the test HDRIs:
//   log L(d) = sigma * (sum over octaves k = 0..6 of value noise at frequency 2^(k+1), each octave
//              scaled to the same variance) + log(sky gain if d.y > 0, smoothed over 0.05 rad),
//   plus disk lights (angular radius log-uniform in [0.01, 0.1] rad, radiance log-uniform in
//   [3, 30] x the mean; brighter compact lights are the peak split's, bake/prefilter_peaks.hpp),
// with sigma (0.6 .. 1.4), the sky gain (log-uniform in 1.5 .. 30: an overcast sky over bright
// ground up to a clear sky over dark ground) and the lights drawn per environment from a fixed
// seed; 10 environments, 256 random texels each. The reference is
// the exact LD of each 256^2 cube (ibl::ld_texel_sum at ld_texel_sum_level) at random texel
// directions; the error is the relative RMSE of luminance there (what ibl-bake's check reports),
// the mean over the environments.
constexpr int natural_envs = 10;
constexpr int natural_dirs = 256;

double hash_unit(std::uint32_t a, std::uint32_t b) {
    return double(ibl::detail::rr_hash(ibl::detail::rr_hash(a * 0x9e3779b9u + 0x51ed27u) ^ (b * 0x85ebca6bu)) >> 8) * 0x1p-24;
}
/// Value noise in [-1, 1] on the integer lattice of R^3 (quintic fade, trilinear blend).
double value_noise(const ibl::vec3<double>& p, std::uint32_t seed) {
    const double fx = std::floor(p.x), fy = std::floor(p.y), fz = std::floor(p.z);
    const int ix = int(fx), iy = int(fy), iz = int(fz);
    auto fade = [](double t) { return t * t * t * (t * (t * 6.0 - 15.0) + 10.0); };
    const double ux = fade(p.x - fx), uy = fade(p.y - fy), uz = fade(p.z - fz);
    auto at = [&](int x, int y, int z) {
        const std::uint32_t h = ibl::detail::rr_hash(std::uint32_t(x) * 73856093u ^ std::uint32_t(y) * 19349663u ^ std::uint32_t(z) * 83492791u ^ seed);
        return double(h >> 8) * 0x1p-23 - 1.0;
    };
    auto lerp = [](double a, double b, double t) { return a + (b - a) * t; };
    const double x00 = lerp(at(ix, iy, iz), at(ix + 1, iy, iz), ux), x10 = lerp(at(ix, iy + 1, iz), at(ix + 1, iy + 1, iz), ux);
    const double x01 = lerp(at(ix, iy, iz + 1), at(ix + 1, iy, iz + 1), ux), x11 = lerp(at(ix, iy + 1, iz + 1), at(ix + 1, iy + 1, iz + 1), ux);
    return lerp(lerp(x00, x10, uy), lerp(x01, x11, uy), uz);
}

struct natural_env {
    ibl::cubemap<float> cube{1, 1};
    std::vector<ibl::vec3<double>> dirs;
};

natural_env make_natural_env(int e) {
    const int n = source_size;
    const std::uint32_t seed = 1000u + 17u * std::uint32_t(e);
    const double sigma = 0.6 + 0.8 * hash_unit(seed, 1);          // log-luminance std, 0.6 .. 1.4
    const double sky = std::exp(std::log(1.5) + std::log(30.0 / 1.5) * hash_unit(seed, 2)); // 1.5 .. 30
    constexpr int octaves = 7;
    std::vector<double> logl(std::size_t(6 * n * n));
    std::vector<double> oct(std::size_t(6 * n * n));
    std::fill(logl.begin(), logl.end(), 0.0);
    for (int k = 0; k < octaves; ++k) { // each octave normalised to unit variance, then summed
        double m = 0.0, m2 = 0.0;
        for (int f = 0; f < 6; ++f)
            for (int y = 0; y < n; ++y)
                for (int x = 0; x < n; ++x) {
                    const ibl::vec3<double> d = ibl::cube_texel_direction<double>(f, x, y, n);
                    const double v = value_noise(d * std::exp2(double(k + 1)) + ibl::vec3<double>(0.37 * k, 0.61 * k, 0.11 * k), seed + 101u * std::uint32_t(k));
                    oct[ibl::cube_texel_index(f, x, y, n)] = v;
                    m += v, m2 += v * v;
                }
        const double cnt = double(oct.size()), mean = m / cnt, sd = std::sqrt(std::max(1e-30, m2 / cnt - mean * mean));
        for (std::size_t i = 0; i < oct.size(); ++i) logl[i] += (oct[i] - mean) / sd;
    }
    const double norm = sigma / std::sqrt(double(octaves));
    struct disk {
        ibl::vec3<double> c;
        double cosr, gain;
    };
    std::vector<disk> lights;
    const int count = 2 + int(6.0 * hash_unit(seed, 3));
    for (int i = 0; i < count; ++i) {
        const double z = 2.0 * hash_unit(seed, 10 + 3 * i) - 1.0, phi = 2.0 * ibl::pi_v<double> * hash_unit(seed, 11 + 3 * i);
        const double rad = 0.01 * std::pow(10.0, hash_unit(seed, 12 + 3 * i));
        const double gain = 3.0 * std::pow(10.0, hash_unit(seed, 40 + i));
        const double s = std::sqrt(std::max(0.0, 1.0 - z * z));
        lights.push_back({{s * std::cos(phi), z, s * std::sin(phi)}, std::cos(rad), gain});
    }
    natural_env env;
    env.cube = ibl::cubemap<float>(n, 0);
    std::vector<double> lin(logl.size());
    double mean = 0.0;
    for (int f = 0; f < 6; ++f)
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
                const std::size_t i = ibl::cube_texel_index(f, x, y, n);
                const ibl::vec3<double> d = ibl::cube_texel_direction<double>(f, x, y, n);
                const double t = std::clamp(d.y / 0.05 * 0.5 + 0.5, 0.0, 1.0);
                lin[i] = std::exp(norm * logl[i] + t * std::log(sky));
                mean += lin[i];
            }
    mean /= double(lin.size());
    env.cube.fill(0, [&](int f, int x, int y) {
        const std::size_t i = ibl::cube_texel_index(f, x, y, n);
        const ibl::vec3<double> d = ibl::cube_texel_direction<double>(f, x, y, n);
        double v = lin[i];
        for (const disk& l : lights)
            if (glm::dot(d, l.c) >= l.cosr) v += l.gain * mean;
        return ibl::vec3<float>(float(v));
    });
    env.cube.generate_mips();
    for (int i = 0; i < natural_dirs; ++i) {
        const int f = int(6.0 * hash_unit(seed, 500 + 3 * i)), x = int(n * hash_unit(seed, 501 + 3 * i)), y = int(n * hash_unit(seed, 502 + 3 * i));
        env.dirs.push_back(ibl::cube_texel_direction<double>(f, x, y, n));
    }
    return env;
}

struct natural_evaluator {
    const std::vector<natural_env>* envs;
    fit_case c;
    std::vector<std::vector<double>> exact; ///< per environment, per direction: exact LD (luminance = any channel)

    void init() {
        for (const natural_env& e : *envs) {
            const std::vector<ibl::vec3<double>> ld = ibl::ld_texel_sum(e.cube, ibl::ld_texel_sum_level(e.cube, c.roughness),
                                                                        std::span<const ibl::vec3<double>>(e.dirs), c.roughness, c.weight);
            std::vector<double> v;
            for (const auto& x : ld) v.push_back(x.x);
            exact.push_back(std::move(v));
        }
    }
    double error(const ibl::fast_tap_shape& shape) const {
        return error_of([&](const ibl::cubemap<float>& cube) {
            ibl::sphere_sample_table<double> t = ibl::make_fast_ld_table<double>(
                c.roughness, c.budget, shape, [&](double omega) { return double(cube.lod_for_solid_angle(float(omega))); }, c.weight);
            if (g_nearest) {
                const double max_lod = double(cube.levels() - 1);
                for (double& l : t.lod) {
                    const double q = std::clamp(l, 0.0, max_lod);
                    l = q - std::floor(q) < 0.5 ? std::floor(q) : std::floor(q) + 1.0;
                }
            }
            return t;
        });
    }
    double error_fis(std::uint32_t samples) const {
        return error_of([&](const ibl::cubemap<float>& cube) {
            return ibl::make_ld_table_for<double>(cube, c.roughness, samples, ibl::prefilter_method::filtered_importance, 0.5, c.weight);
        });
    }
    template <class MakeTable> double error_of(MakeTable&& make_table) const {
        double total = 0.0;
        for (std::size_t ei = 0; ei < envs->size(); ++ei) {
            const natural_env& e = (*envs)[ei];
            const ibl::sphere_sample_table<double> t = make_table(e.cube);
            double wsum = 0.0;
            for (double w : t.weight) wsum += w;
            double se = 0.0;
            for (std::size_t k = 0; k < e.dirs.size(); ++k) {
                const ibl::frame<double> fr = ibl::make_frame(e.dirs[k]);
                double acc = 0.0;
                for (std::size_t i = 0; i < t.size(); ++i) {
                    const ibl::vec3<double> l = fr.to_world(ibl::vec3<double>(t.x[i], t.y[i], t.z[i]));
                    acc += t.weight[i] * double(e.cube.radiance(ibl::vec3<float>(l), float(t.lod[i])).x);
                }
                const double rel = (acc / wsum - exact[ei][k]) / exact[ei][k];
                se += rel * rel;
            }
            total += std::sqrt(se / double(e.dirs.size()));
        }
        return total / double(envs->size());
    }
};

/// The objective the fit minimises: the point light (--objective point) or natural illumination.
bool g_natural = true;
std::vector<natural_env> g_envs;

struct fit_result {
    fit_case c;
    ibl::fast_tap_shape shape;
    double error = 0.0;
    double fis_error = 0.0; ///< filtered importance sampling (bias 0.5) with the same samples
};

template <class Evaluator> fit_result fit_with(const Evaluator& ev, const fit_case& c, bool show) {
    fit_result best{c, {}, 1e30, 0.0};
    for (double tail : {0.8, 1.2, 1.7, 2.4, 3.4})
        for (double bias = -1.0; bias <= 1.01; bias += 1.0 / 3.0) {
            const ibl::fast_tap_shape s{tail, bias};
            const double e = ev.error(s);
            if (show) std::printf("tail %.2f bias %+.2f  error %.4f\n", tail, bias, e);
            if (e < best.error) best.shape = s, best.error = e;
        }
    // Local refinement of (tail, bias) about the best grid point.
    double dt = 0.1, db = 0.125;
    for (int it = 0; it < 9; ++it) {
        bool moved = false;
        for (const auto& [kt, kb] : std::array<std::pair<double, double>, 4>{{{1, 0}, {-1, 0}, {0, 1}, {0, -1}}}) {
            ibl::fast_tap_shape s = best.shape;
            s.tail *= std::exp(kt * dt);
            s.lod_bias += kb * db;
            const double e = ev.error(s);
            if (e < best.error) best.shape = s, best.error = e, moved = true;
        }
        if (!moved) dt *= 0.5, db *= 0.5;
    }
    best.fis_error = ev.error_fis(c.budget);
    return best;
}

/// f(the objective's evaluator for case c, initialised).
template <class F> auto with_evaluator(const std::vector<probe>& probes, const fit_case& c, F&& f) {
    if (g_natural) {
        natural_evaluator ev{&g_envs, c, {}};
        ev.init();
        return f(ev);
    }
    evaluator ev{&probes, c, {}, {}};
    ev.init();
    return f(ev);
}

fit_result fit(const std::vector<probe>& probes, const fit_case& c, bool show) {
    return with_evaluator(probes, c, [&](const auto& ev) { return fit_with(ev, c, show); });
}

} // namespace

int main(int argc, char** argv) {
    std::string header;
    double show_r = -1.0;
    std::uint32_t show_budget = 0;
    bool fis = false, check = false, nearest_set = false;
    for (int i = 1; i < argc; ++i) {
        if (!std::strcmp(argv[i], "--write-header") && i + 1 < argc) header = argv[++i];
        else if (!std::strcmp(argv[i], "--fis")) fis = true;
        else if (!std::strcmp(argv[i], "--check")) check = true;
        else if (!std::strcmp(argv[i], "--nearest")) g_nearest = true, nearest_set = true;
        else if (!std::strcmp(argv[i], "--trilinear")) g_nearest = false, nearest_set = true;
        else if (!std::strcmp(argv[i], "--objective") && i + 1 < argc) {
            const std::string o = argv[++i];
            if (o != "point" && o != "natural") {
                std::fprintf(stderr, "fast_filter_fit: --objective point|natural, got %s\n", o.c_str());
                return 2;
            }
            g_natural = o == "natural";
        }
        else if (!std::strcmp(argv[i], "--contrast") && i + 1 < argc) g_contrasts = {std::atof(argv[++i])};
        else if (!std::strcmp(argv[i], "--show") && i + 2 < argc) show_r = std::atof(argv[i + 1]), show_budget = std::uint32_t(std::atoi(argv[i + 2])), i += 2;
        else {
            std::fprintf(stderr, "usage: fast_filter_fit [--write-header PATH] [--fis] [--show R N] [--check] [--objective point|natural] [--nearest|--trilinear] [--contrast C]\n");
            return 2;
        }
    }
    if (!nearest_set) g_nearest = g_natural; // natural: the reads of the default plan (the nearest level)
    if (g_natural)
        for (int e = 0; e < natural_envs; ++e) g_envs.push_back(make_natural_env(e));
    const int n = source_size;
    std::vector<probe> probes;
    probes.push_back(make_probe(4, n / 2, n / 2));     // face centre
    probes.push_back(make_probe(4, n - 1, n / 2 + 3)); // on an edge
    probes.push_back(make_probe(4, n - 1, n - 1));     // at a corner
    if (check) {
        int bad = 0;
        for (const fit_case& c : {fit_case{ibl::ld_weight::n_dot_l, 0.5, 16}, fit_case{ibl::ld_weight::g1, 0.3, 8}}) {
            const fit_result r = fit(probes, c, false);
            for (const ibl::fast_shape_row& row : ibl::fast_shape_rows) {
                if (row.weight != c.weight || row.budget != c.budget || std::fabs(row.roughness - c.roughness) > 1e-9) continue;
                const bool same = std::fabs(row.shape.tail - r.shape.tail) < 1e-3 && std::fabs(row.shape.lod_bias - r.shape.lod_bias) < 1e-3 &&
                                  std::fabs(row.error - r.error) < 1e-3;
                std::printf("%s r %.2f N %u: table tail %.4f bias %+.4f error %.4f, refit %.4f %+.4f %.4f: %s\n",
                            c.weight == ibl::ld_weight::g1 ? "g1" : "nl", c.roughness, c.budget, row.shape.tail, row.shape.lod_bias,
                            row.error, r.shape.tail, r.shape.lod_bias, r.error, same ? "same" : "DIFFERENT");
                bad += same ? 0 : 1;
            }
        }
        return bad ? 1 : 0;
    }
    if (show_r >= 0.0 && fis) {
        const double e = with_evaluator(probes, {ibl::ld_weight::n_dot_l, show_r, show_budget},
                                        [&](const auto& ev) { return ev.error_fis(show_budget); });
        std::printf("fis r %.2f samples %u: error %.4f\n", show_r, show_budget, e);
        return 0;
    }
    if (show_r >= 0.0) {
        const fit_result r = fit(probes, {ibl::ld_weight::n_dot_l, show_r, show_budget}, true);
        const ibl::fast_tap_shape cur = ibl::fast_shape(show_r, show_budget, ibl::ld_weight::n_dot_l);
        const double cur_e = with_evaluator(probes, {ibl::ld_weight::n_dot_l, show_r, show_budget},
                                            [&](const auto& ev) { return ev.error(cur); });
        std::printf("the compiled-in table: tail %.4f bias %+.4f  error %.4f\n", cur.tail, cur.lod_bias, cur_e);
        std::printf("best: tail %.4f bias %+.4f  error %.4f (FIS with %u samples: %.4f)\n", r.shape.tail, r.shape.lod_bias,
                    r.error, show_budget, r.fis_error);
        return 0;
    }
    std::vector<fit_case> cases;
    for (ibl::ld_weight w : {ibl::ld_weight::n_dot_l, ibl::ld_weight::g1})
        for (int ri = 1; ri <= 20; ++ri)
            for (std::uint32_t b : {8u, 16u, 32u, 64u, 128u, 256u, 512u, 1024u, 2048u}) cases.push_back({w, 0.05 * ri, b});
    std::vector<fit_result> results(cases.size());
    std::atomic<std::size_t> next{0};
    auto work = [&] {
        for (std::size_t k; (k = next++) < cases.size();) {
            results[k] = fit(probes, cases[k], false);
            std::fprintf(stderr, "%s r %.2f samples %3u: tail %.3f bias %+.3f  error %.4f  FIS %.4f\n",
                         cases[k].weight == ibl::ld_weight::g1 ? "g1 " : "n.l", cases[k].roughness, cases[k].budget,
                         results[k].shape.tail, results[k].shape.lod_bias, results[k].error, results[k].fis_error);
        }
    };
    std::thread other(work);
    work();
    other.join();
    if (header.empty()) return 0;
    std::ofstream f(header);
    f << "#pragma once\n"
         "// ibl/bake/prefilter_fast_tables.hpp — the fast filter's tap shapes (bake/prefilter_fast.hpp), per\n"
         "// LD weight, roughness and sample budget, and each shape's error on the fit's content (relative RMSE).\n"
         "// Generated by research/fast_filter_fit.cpp (`fast_filter_fit --write-header PATH`); do not edit.\n\n"
         "#include \"../core/config.hpp\" // first: a pre-C++20 build stops there with one #error\n"
         "#if IBL_DETAIL_CXX20\n\n#include <cstdint>\n\n#include \"../runtime/ld_weight.hpp\"\n\nnamespace ibl {\n\n"
         "/// One fast-filter table shape (bake/prefilter_fast.hpp): the spiral's tail exponent and lod bias.\n"
         "struct fast_tap_shape {\n    double tail = 1.0;\n    double lod_bias = 0.5;\n};\n\n"
         "/// A tabulated shape: its LD weight, roughness and samples, its error on the fit's content (the\n"
         "/// objective: relative RMSE against the exact LD on synthetic natural illumination, nearest-level\n"
         "/// reads; bake/prefilter_fast.hpp) and that of filtered importance sampling with the same samples\n"
         "/// (bias 0.5, Hammersley, trilinear reads: twice the taps).\n"
         "struct fast_shape_row {\n    ld_weight weight = ld_weight::n_dot_l;\n    double roughness = 0.0;\n"
         "    std::uint32_t budget = 0;\n    fast_tap_shape shape{};\n    double error = 0.0;\n    double fis_error = 0.0;\n};\n\n"
         "inline constexpr fast_shape_row fast_shape_rows[] = {\n";
    char line[256];
    for (const fit_result& r : results) {
        std::snprintf(line, sizeof line, "    {ld_weight::%s, %.2f, %u, {%.4f, %.4f}, %.4f, %.4f},\n",
                      r.c.weight == ibl::ld_weight::g1 ? "g1" : "n_dot_l", r.c.roughness, r.c.budget, r.shape.tail,
                      r.shape.lod_bias, r.error, r.fis_error);
        f << line;
    }
    f << "};\n\n} // namespace ibl\n\n#endif // IBL_DETAIL_CXX20\n";
    std::printf("wrote %s (%zu shapes)\n", header.c_str(), results.size());
    return 0;
}
