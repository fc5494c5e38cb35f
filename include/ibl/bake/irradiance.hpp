#pragma once
// ibl/bake/irradiance.hpp — diffuse irradiance of an environment (host only).
//
// Convention: the library's irradiance is E (W/m^2-like), not E / pi:
//     E(n) = integral over the hemisphere around n of L(l) max(n.l, 0) dl
// so a constant environment L gives E = pi L, and a Lambertian surface of albedo rho reflects
// radiance rho E / pi (brdf/lambert.hpp: f = rho / pi). (LearnOpenGL's irradiance map stores
// E / pi and its shader multiplies by albedo without the 1/pi; to match it divide these by pi.)
//
// Two estimators, each a sample table in tangent space (z = n) for bake/sphere_convolve.hpp:
//
//  * riemann (the literature: LearnOpenGL's irradiance convolution). In spherical coordinates
//        E = integral_0^{2 pi} integral_0^{pi/2} L cos(theta) sin(theta) dtheta dphi,
//    a midpoint rule with n_theta x n_phi nodes theta_i = (i + 1/2) dtheta, phi_j = (j + 1/2) dphi,
//    dtheta = (pi/2) / n_theta, dphi = 2 pi / n_phi:
//        E ~ dtheta dphi sum L cos sin = (pi^2 / (n_theta n_phi)) sum_ij L(theta_i, phi_j) cos sin.
//    (LearnOpenGL writes pi * (1 / N) * sum, which is this divided by pi: E / pi.) The rule is not
//    normalised: for a constant L it gives pi L times the midpoint rule's factor for
//    integral sin cos dtheta, 1 + dtheta^2 / 6 + O(dtheta^4) (the phi sum is exact), i.e.
//    a relative excess of 1.0e-4 at n_theta = 64 (the literature's sampleDelta = 0.025 has
//    n_theta = 63, n_phi = 252).
//  * cosine_importance: directions with density cos(theta) / pi (sampling/hemisphere.hpp,
//    Malley's method on the concentric disk, Hammersley points), so L cos / pdf = pi L and
//        E ~ pi (1 / N) sum L(l_i)       (exact for a constant environment).
//    Default 1024 samples, filtered (see below).
//
// Filtering (filtered = true): each node / sample reads the source lod whose texel solid angle
// matches its share of the sphere times 4^lod_bias (Krivanek & Colbert 2008, as in
// bake/prefilter.hpp): the Riemann node's own solid angle sin(theta) dtheta dphi, or
// 1 / (N pdf) = pi / (N cos theta) for cosine sampling. Without filtering every sample reads
// level 0 (the literature). Output: irradiance_cubemap gives a one-level cubemap<float> of face
// size `size` (32 by default: irradiance is smooth, its spectrum ends at SH band 2 to within 1%).
// Non-finite radiance reads as 0; samples = 0 (or n_theta, n_phi = 0) are clamped to 1.
// Limits (core/limits.hpp; std::length_error): samples and n_theta n_phi <= limits::max_samples,
// n_theta, n_phi <= limits::max_face_size, size <= limits::max_face_size, and
// irradiance_cubemap's 6 size^2 table size <= limits::max_work.
//
// Texel moments (method texel_moments, cubemap sources only: the map that holds under a sun).
// A sampled estimator misses or over-weights a small bright source, and 3-band SH cannot hold
// the clamped-cosine kink it makes (docs/sun.md gives its error on ibl::make_default_sky).
// Instead E(n) is the sum over the texels t of level 0 (finest) of
// L_t Omega_t max(0, n.d_t) (ibl::irradiance_texel_sum's brute force), made cheap by grouping the
// level-0 texels into the blocks of a coarse grid of face m (the face size of the first mip level
// whose face is <= texel_max_face; level-0 texel (x, y) goes to block (x m / n, y m / n)) and
// keeping per block two moments of the fine texels:
//     P_b = sum L_t Omega_t                         (RGB power, exact)
//     a_b = sum Y_t Omega_t d_t / sum Y_t Omega_t   (luminance-weighted mean direction, |a_b| <= 1;
//                                                    the geometric mean sum Omega d / sum Omega
//                                                    where the block is black)
// so that   E(n) = sum_b P_b max(0, n.a_b).
// For a block entirely above n's horizon, n.(sum L Omega d) = sum L Omega (n.d) is linear in n,
// so the block term is the brute-force sum exactly (in luminance; in RGB up to the colour
// variation inside the block). The only error is in blocks that the horizon of n crosses: the
// clamp is taken once at the mean direction. A sun inside one block is exact except for normals
// whose horizon crosses the sun itself. (The plain texel sum over mip level m, which puts the
// block's power at the block centre, moves a 1-degree sun by up to half a block: docs/sun.md,
// section 1, compares the two.)
// Cost: 6 n^2 once (the moments), then 6 m^2 terms per output texel (a dot product, a max, an
// RGB multiply-add, in double): 6 m^2 x 6 size^2 = 3.8e7 for m = size = 32. Default m <= 32.

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "../core/constants.hpp"
#include "../core/executor.hpp"
#include "../core/limits.hpp"
#include "../core/math.hpp"
#include "../core/vec.hpp"
#include "../env/cube_geometry.hpp"
#include "../env/cubemap.hpp"
#include "../env/environment.hpp"
#include "../sampling/hemisphere.hpp"
#include "../sampling/sequence.hpp"
#include "prefilter.hpp"
#include "sphere_convolve.hpp"

namespace ibl {

enum class irradiance_method : int {
    riemann = 0,           ///< midpoint rule in (theta, phi), the literature's
    cosine_importance = 1, ///< cosine-distributed Hammersley directions
    texel_moments = 2,     ///< texel sum over level 0 grouped into blocks (cubemaps only; header)
};

struct irradiance_options {
    int size = 32; ///< output face size
    irradiance_method method = irradiance_method::cosine_importance;
    std::uint32_t samples = 1024; ///< cosine_importance: directions per texel
    int n_theta = 64;            ///< riemann: polar nodes
    int n_phi = 256;             ///< riemann: azimuthal nodes
    bool filtered = true;        ///< read prefiltered source mips (see the header)
    double lod_bias = 0.5;
    int texel_max_face = 32;     ///< texel_moments: block grid face = first mip size <= this
};

namespace detail {
/// n_theta, n_phi <= limits::max_face_size and n_theta n_phi <= limits::max_samples (values < 1
/// count as 1, as the tables clamp them).
inline void check_irradiance_nodes(const char* fn, int n_theta, int n_phi) {
    check_total(fn, "n_theta", n_theta, limits::max_face_size, "limits::max_face_size");
    check_total(fn, "n_phi", n_phi, limits::max_face_size, "limits::max_face_size");
    const std::uint64_t nt = std::uint64_t(n_theta > 0 ? n_theta : 1), np = std::uint64_t(n_phi > 0 ? n_phi : 1);
    check_total(fn, "nodes n_theta * n_phi", nt * np, limits::max_samples, "limits::max_samples");
}
} // namespace detail

/// Riemann (midpoint) table: n_theta x n_phi nodes, weights cos sin, scale pi^2 / N, not
/// normalised. lod_of_solid_angle(node solid angle) gives each node's lod.
template <class S, class LodFn>
sphere_sample_table<S> make_irradiance_riemann_table(int n_theta, int n_phi, LodFn&& lod_of_solid_angle) {
    detail::check_irradiance_nodes("make_irradiance_riemann_table", n_theta, n_phi);
    const int nt = n_theta > 0 ? n_theta : 1, np = n_phi > 0 ? n_phi : 1;
    const double dt = half_pi_v<double> / double(nt), dp = two_pi_v<double> / double(np);
    sphere_sample_table<S> t;
    t.drawn = std::uint32_t(nt) * std::uint32_t(np);
    t.normalised = false;
    t.scale = S(sqr(pi_v<double>) / (double(nt) * double(np)));
    for (int i = 0; i < nt; ++i) {
        const double theta = (double(i) + 0.5) * dt;
        const double st = std::sin(theta), ct = std::cos(theta);
        const S lod = S(lod_of_solid_angle(st * dt * dp));
        for (int j = 0; j < np; ++j) {
            const double phi = (double(j) + 0.5) * dp;
            t.push(vec3<S>(vec3<double>(st * std::cos(phi), st * std::sin(phi), ct)), S(ct * st), lod);
        }
    }
    return t;
}

/// Cosine-importance table: N Hammersley directions (0 -> 1) of density cos / pi, weight 1 each
/// (L cos / pdf = pi L), scale pi, normalised by the weight sum. Point 0 of the Hammersley set
/// lies exactly on the horizon (cos = 0, density 0) and is dropped, so the estimate is pi times
/// the mean over the N - 1 others (an exactly hemispherical set: a ground below a normal pointing
/// down is not mixed with the horizon's sky). Lods use cos clamped to 1 / N (footprint <= pi sr).
template <class S, class LodFn>
sphere_sample_table<S> make_irradiance_cosine_table(std::uint32_t samples, LodFn&& lod_of_solid_angle) {
    detail::check_total("make_irradiance_cosine_table", "samples", samples, limits::max_samples, "limits::max_samples");
    const std::uint32_t n = samples > 0 ? samples : 1;
    sphere_sample_table<S> t;
    t.drawn = n;
    t.normalised = true;
    t.scale = S(pi_v<double>);
    for (std::uint32_t i = 0; i < n; ++i) {
        const vec3<double> l = sample_cosine_hemisphere(hammersley<double>(i, n));
        if (!(l.z > 0.0) && n > 1) continue;
        const double c = l.z > 1.0 / double(n) ? l.z : 1.0 / double(n);
        t.push(vec3<S>(l), S(1), S(lod_of_solid_angle(pi_v<double> / (double(n) * c))));
    }
    return t;
}

/// The irradiance table for a source and options (limits as the header says; std::length_error).
template <class S, class Env> sphere_sample_table<S> make_irradiance_table_for(const Env& env, const irradiance_options& opt) {
    if (opt.method == irradiance_method::riemann)
        detail::check_irradiance_nodes("irradiance", opt.n_theta, opt.n_phi);
    else
        detail::check_total("irradiance", "samples", opt.samples, limits::max_samples, "limits::max_samples");
    using Te = std::conditional_t<environment<Env, float>, float, double>;
    auto lod = [&](double omega) -> double {
        if (!opt.filtered) return 0.0;
        return double(env_lod_for_solid_angle<Te>(env, Te(omega * std::exp2(2.0 * opt.lod_bias))));
    };
    if (opt.method == irradiance_method::riemann) return make_irradiance_riemann_table<S>(opt.n_theta, opt.n_phi, lod);
    return make_irradiance_cosine_table<S>(opt.samples, lod);
}

/// Level-0 texels of a cubemap grouped into the blocks of a coarse grid, two moments per block
/// (see the header): E(n) = sum_b power_b max(0, n.axis_b). Blocks are stored face, y, x.
struct irradiance_texel_moments {
    int face = 0;                    ///< face size m of the block grid
    std::vector<vec3<double>> power; ///< sum over the block's texels of L Omega (RGB)
    std::vector<vec3<double>> axis;  ///< luminance-weighted mean texel direction (|axis| <= 1)

    /// E(n) for a normal n (used as given: homogeneous of degree 1 in n, NaN -> 0), double.
    [[nodiscard]] vec3<double> irradiance(const vec3<double>& n) const noexcept {
        vec3<double> s(0.0);
        for (std::size_t b = 0; b < power.size(); ++b) {
            const double c = glm::dot(n, axis[b]);
            s += power[b] * (c > 0.0 ? c : 0.0);
        }
        return s;
    }
};

/// Face size of the block grid for a source face n and a bound max_face: the size of the first
/// mip level of n whose face is <= max_face (max(1, n >> l)). Throws if max_face < 1.
inline int irradiance_moment_face(int n, int max_face) {
    if (max_face < 1)
        throw std::invalid_argument("ibl::irradiance_moment_face: max_face must be >= 1, got " + std::to_string(max_face));
    int m = n;
    while (m > max_face && m > 1) m = m >> 1 > 0 ? m >> 1 : 1;
    return m;
}

/// The block moments of level 0 of c for a block grid of face irradiance_moment_face(c.size(),
/// max_face). Non-finite radiance components read as 0. Deterministic (fixed summation order:
/// faces, rows, columns of level 0, in double). Borders are not read.
template <class T> irradiance_texel_moments make_irradiance_texel_moments(const cubemap<T>& c, int max_face = 32) {
    const int n = c.size(0);
    const int m = irradiance_moment_face(n, max_face);
    irradiance_texel_moments out;
    out.face = m;
    const std::size_t blocks = std::size_t(6) * std::size_t(m) * std::size_t(m);
    std::vector<vec3<double>> pw(blocks, vec3<double>(0.0)), yd(blocks, vec3<double>(0.0)), gd(blocks, vec3<double>(0.0));
    std::vector<double> ysum(blocks, 0.0), gsum(blocks, 0.0);
    const std::vector<double> omega = cube_face_solid_angles<double>(n);
    for (int f = 0; f < 6; ++f)
        for (int y = 0; y < n; ++y) {
            const int by = int((long long)y * m / n);
            for (int x = 0; x < n; ++x) {
                const int bx = int((long long)x * m / n);
                const std::size_t b = cube_texel_index(f, bx, by, m);
                vec3<double> L(c.texel(f, x, y, 0));
                for (int k = 0; k < 3; ++k)
                    if (!is_finite(L[k])) L[k] = 0.0;
                const double om = omega[std::size_t(y) * std::size_t(n) + std::size_t(x)];
                const vec3<double> d = cube_texel_direction<double>(f, x, y, n);
                const double w = std::max(0.0, 0.2126 * L.x + 0.7152 * L.y + 0.0722 * L.z) * om;
                pw[b] += L * om;
                yd[b] += w * d;
                ysum[b] += w;
                gd[b] += om * d;
                gsum[b] += om;
            }
        }
    out.power = std::move(pw);
    out.axis.resize(blocks);
    for (std::size_t b = 0; b < blocks; ++b) out.axis[b] = ysum[b] > 0.0 ? yd[b] / ysum[b] : gd[b] / gsum[b];
    return out;
}

/// Irradiance cubemap (one level, face `size`) of a cubemap source by texel moments (see the
/// header): E at every output texel centre from make_irradiance_texel_moments(src, max_face).
/// Work items are output face rows; the result does not depend on the executor.
/// Throws std::invalid_argument for size < 1 or max_face < 1.
template <class T, class Executor = thread_executor>
cubemap<float> irradiance_cubemap_texel_moments(const cubemap<T>& src, int size = 32, int max_face = 32, Executor&& ex = Executor{}) {
    detail::check_arg("irradiance_cubemap_texel_moments", "size", size, 1, limits::max_face_size, "limits::max_face_size");
    detail::check_arg("irradiance_cubemap_texel_moments", "max_face", max_face, 1, limits::max_face_size, "limits::max_face_size");
    const irradiance_texel_moments mom = make_irradiance_texel_moments(src, max_face);
    const int n = size;
    std::vector<vec3<float>> texels(std::size_t(6) * std::size_t(n) * std::size_t(n));
    ex(std::size_t(6 * n), [&](std::size_t b, std::size_t e) {
        for (std::size_t row = b; row < e; ++row) {
            const int f = int(row) / n, y = int(row) % n;
            for (int x = 0; x < n; ++x)
                texels[row * std::size_t(n) + std::size_t(x)] = vec3<float>(mom.irradiance(cube_texel_direction<double>(f, x, y, n)));
        }
    });
    cubemap<float> out(n, 1);
    out.fill(0, [&](int f, int x, int y) { return texels[cube_texel_index(f, x, y, n)]; });
    out.update_borders();
    return out;
}

namespace detail {
template <class Env> struct is_cubemap : std::false_type {};
template <class U> struct is_cubemap<cubemap<U>> : std::true_type {};
} // namespace detail

/// Irradiance E at one unit normal of any environment (double accumulation). texel_moments
/// (cubemaps only) builds the moments on each call (6 n^2): for many normals build
/// make_irradiance_texel_moments once.
template <class T, class Env>
    requires environment<Env, T>
[[nodiscard]] vec3<T> irradiance(const Env& env, const vec3<T>& normal, const irradiance_options& opt = {}) {
    if (opt.method == irradiance_method::texel_moments) {
        if constexpr (detail::is_cubemap<Env>::value) {
            return vec3<T>(make_irradiance_texel_moments(env, opt.texel_max_face).irradiance(vec3<double>(normal)));
        } else {
            throw std::invalid_argument("ibl::irradiance: texel_moments needs a cubemap source");
        }
    }
    return convolve_direction<T>(env, make_irradiance_table_for<double>(env, opt), normal);
}

/// Irradiance cubemap (one level, face size opt.size) of an environment: E at every texel centre.
template <class Env, class Executor = thread_executor>
cubemap<float> irradiance_cubemap(const Env& env, const irradiance_options& opt = {}, Executor&& ex = Executor{}) {
    detail::check_arg("irradiance_cubemap", "size", opt.size, 1, limits::max_face_size, "limits::max_face_size");
    if (opt.method == irradiance_method::texel_moments) {
        if constexpr (detail::is_cubemap<Env>::value) {
            return irradiance_cubemap_texel_moments(env, opt.size, opt.texel_max_face, ex);
        } else {
            throw std::invalid_argument("ibl::irradiance_cubemap: texel_moments needs a cubemap source");
        }
    }
    if (opt.method == irradiance_method::riemann)
        detail::check_irradiance_nodes("irradiance_cubemap", opt.n_theta, opt.n_phi);
    else
        detail::check_total("irradiance_cubemap", "samples", opt.samples, limits::max_samples, "limits::max_samples");
    const std::uint64_t per_texel = opt.method == irradiance_method::riemann
                                        ? std::uint64_t(opt.n_theta > 0 ? opt.n_theta : 1) * std::uint64_t(opt.n_phi > 0 ? opt.n_phi : 1)
                                        : std::uint64_t(opt.samples > 0 ? opt.samples : 1);
    detail::check_total("irradiance_cubemap", "taps 6 size^2 samples",
                        detail::work_add(0, 6 * std::uint64_t(opt.size) * std::uint64_t(opt.size), per_texel),
                        limits::max_work, "limits::max_work");
    const int n = opt.size;
    cubemap<float> out(n, 1);
    const std::vector<vec3<float>> texels = convolve_faces(env, make_irradiance_table_for<float>(env, opt), n, ex);
    out.fill(0, [&](int f, int x, int y) { return texels[cube_texel_index(f, x, y, n)]; });
    out.update_borders();
    return out;
}

/// Irradiance through the lobe-generic prefilter (bake/prefilter.hpp): a one-level cubemap of
/// face `size` holding pi times the normalised mean of the source over lobe L about each texel's
/// direction, by `samples` draws of L (filtered importance sampling: each draw reads the source
/// at the lod of its solid angle 1 / (N pdf_l), bias `lod_bias`). With the default cosine_lobe
/// this is E(n) (the cosine-importance irradiance of irradiance_cubemap, through the same
/// integrator as the specular and sheen chains); another lobe (sampling/lobe.hpp's contract)
/// gives pi times its weighted mean: a wrapped or rough diffuse kernel runs through it unchanged.
/// `lobe_roughness` is passed to the lobe (the cosine lobe ignores it). Limits as prefilter.
template <class Lobe = cosine_lobe, class Env, class Executor = thread_executor>
    requires ld_lobe<Lobe>
cubemap<float> irradiance_cubemap_lobe(const Env& env, int size, std::uint32_t samples, Executor&& ex = Executor{},
                                       double lobe_roughness = 0.0, double lod_bias = 0.5) {
    detail::check_arg("irradiance_cubemap_lobe", "size", size, 1, limits::max_face_size, "limits::max_face_size");
    detail::check_total("irradiance_cubemap_lobe", "samples", samples, limits::max_samples, "limits::max_samples");
    sphere_sample_table<float> table = make_ld_table_for<float, Lobe>(env, lobe_roughness, samples, prefilter_method::filtered_importance, lod_bias);
    table.trilinear = true;
    table.scale = float(pi_v<double>); // E = pi x the normalised lobe mean
    cubemap<float> out(size, 1);
    const std::vector<vec3<float>> texels = convolve_faces(env, table, size, ex);
    out.fill(0, [&](int f, int x, int y) { return texels[cube_texel_index(f, x, y, size)]; });
    out.update_borders();
    return out;
}

} // namespace ibl

#endif // IBL_DETAIL_CXX20
