#pragma once
// ibl/env/sun_extract.hpp — finds a sun (a compact, very bright region) in a cubemap, removes it
// from the environment and returns it as a disk light (host only: std::vector work space).
//
// Why. A sun carries most of a clear sky's irradiance in ~1e-3 sr. Baked into the environment
// it defeats the cheap diffuse products (3-band SH cannot hold it: docs/sun.md) and
// needs many specular samples. Split off, the residual environment is smooth (SH holds it) and
// the sun is shaded as an analytic disk light (runtime/shade.hpp: disk_light_irradiance, shade_disk;
// reference/disk_light.hpp: its exact LD contribution to the prefiltered chain).
//
// Rule (level 0 of the cubemap, luminance Y = 0.2126 R + 0.7152 G + 0.0722 B):
//  1. threshold = max(threshold_over_median * median(Y), threshold_over_peak * peak(Y)), the
//     median over all 6 n^2 texels (unweighted), peak the brightest texel (ties: first in face,
//     row, column order). No sun (no_bright_region) when peak <= threshold or peak <= 0.
//  2. region = the 8-connected set of texels with Y > threshold that contains the peak texel
//     (connected across face edges and corners: a neighbour is the texel containing the
//     neighbour's texel-centre direction, so a sun on an edge is one region).
//  3. too_large when the region's solid angle (sum of exact texel solid angles) exceeds
//     max_solid_angle (default 0.01 sr: ten times a 1-degree sun, 9.57e-4 sr, so that the rim
//     texels a disk partly covers fit at coarse faces: a 1-degree sun covers ~9 texels of a 64
//     face, 4.6e-3 sr).
//  4. fill: the region's texels are replaced by the harmonic interpolation of the ring around it
//     (the 4-connected neighbours outside the region): Gauss-Seidel with over-relaxation, from
//     the ring mean, until the largest change is below 1e-6 of the ring's mean luminance (at most
//     a fixed number of sweeps); it reproduces a linear gradient under the sun.
//  5. the light: excess e_t = L_t - fill_t per region texel (RGB), d_t the texel-centre direction,
//     Omega_t the exact texel solid angle;
//       direction   = normalize(sum Y(e_t) Omega_t d_t)      (power-weighted centroid)
//       irradiance  = sum e_t Omega_t (d_t . direction)       (E_sun: RGB irradiance the removed
//                                                             part delivers on a surface facing it)
//       solid_angle = sum Y(e_t) Omega_t / max_t Y(e_t)       (the uniform disk of the peak excess
//                     radiance: exact for a uniform disk that covers at least one whole texel;
//                     for an unresolved sun it is about one texel)
//       radiance    = irradiance / (pi sin^2 r), r the angular radius of a cap of solid_angle
//                     (cos r = 1 - solid_angle / (2 pi)), so the disk's irradiance facing it is
//                     exactly `irradiance` (a uniform cap of radiance L gives L pi sin^2 r).
//     For every normal whose hemisphere holds the whole region the disk light delivers the
//     removed texels' irradiance n . sum e_t Omega_t d_t exactly (in luminance; in RGB up to the
//     colour variation of the excess): the residual plus the light conserve the energy.
//  6. too_weak when the share Y(irradiance) / Y(E_total) is below min_share (default 0.2), E_total
//     the original's irradiance on the normal `direction` (the brute-force texel sum over level 0).
//  7. found: the region is filled at level 0 and the mips are rebuilt from it (generate_mips), so
//     every level of the residual is the box filter of the filled base. Otherwise the cubemap is
//     left unchanged.
// Only the brightest region is extracted (call again for a second sun). Cost: 6 n^2 (luminance,
// median by nth_element, the share's texel sum) plus the region and the mip rebuild.
// Determinism: a fixed function of the texels (fixed orders; the executor spreads only the mips).

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "../core/color.hpp"
#include "../core/constants.hpp"
#include "../core/executor.hpp"
#include "../core/math.hpp"
#include "../core/vec.hpp"
#include "cube_geometry.hpp"
#include "cubemap.hpp"

namespace ibl {

struct sun_extract_options {
    double threshold_over_median = 50.0; ///< region threshold: this times the median luminance...
    double threshold_over_peak = 1e-3;   ///< ...or this times the peak, whichever is larger
    double max_solid_angle = 1e-2;       ///< sr: larger regions are not a sun
    double min_share = 0.2;              ///< least share of the irradiance facing the sun
    int max_fill_sweeps = 4096;          ///< bound on the fill's relaxation sweeps
};

enum class sun_status : int {
    found = 0,
    no_bright_region = 1, ///< no texel above the threshold (a smooth or black environment)
    too_large = 2,        ///< the bright region exceeds max_solid_angle
    too_weak = 3,         ///< the region carries less than min_share of the irradiance facing it
};

/// A short human-readable reason for a status.
[[nodiscard]] inline const char* sun_status_text(sun_status s) noexcept {
    switch (s) {
    case sun_status::found: return "found";
    case sun_status::no_bright_region: return "no texel above the threshold";
    case sun_status::too_large: return "bright region larger than max_solid_angle";
    default: return "bright region carries less than min_share of the irradiance facing it";
    }
}

/// The extracted light and the statistics of the decision (see the header for the definitions).
/// direction, solid_angle and radiance are the disk light (runtime/shade.hpp's disk_light<T>).
template <class T> struct sun_extraction {
    sun_status status = sun_status::no_bright_region;
    vec3<T> direction{T(0), T(1), T(0)}; ///< unit, towards the light (power-weighted centroid)
    T solid_angle = T(0);                ///< sr, of the equivalent uniform disk
    T angular_radius = T(0);             ///< radians, of that disk
    vec3<T> radiance{T(0)};              ///< of that disk: irradiance / (pi sin^2 r)
    vec3<T> irradiance{T(0)};            ///< E_sun facing the light, sum e Omega (d . direction)
    T region_solid_angle = T(0);         ///< sum of the removed texels' solid angles
    std::size_t region_texels = 0;       ///< texels removed (or found, when rejected)
    double share = 0.0;                  ///< Y(E_sun) / Y(E_total facing the light)
    double peak_luminance = 0.0, median_luminance = 0.0, threshold = 0.0;

    [[nodiscard]] bool found() const noexcept { return status == sun_status::found; }
    [[nodiscard]] const char* reason() const noexcept { return sun_status_text(status); }
};

namespace detail {
/// Level-0 texel index (face, y, x) of the texel containing the centre of texel (x + dx, y + dy)
/// of `face` extended beyond the face (crossing an edge lands on the neighbour face).
inline std::size_t sun_neighbour(int face, int x, int y, int dx, int dy, int n) {
    const int xx = x + dx, yy = y + dy;
    int g = face, gx = xx, gy = yy;
    if (xx < 0 || xx >= n || yy < 0 || yy >= n) {
        const double sc = 2.0 * (double(xx) + 0.5) / double(n) - 1.0, tc = 2.0 * (double(yy) + 0.5) / double(n) - 1.0;
        const cube_coord<double> c = cube_lookup(cube_face_point<double>(face, sc, tc));
        g = c.face;
        gx = std::clamp(int(c.s * double(n)), 0, n - 1);
        gy = std::clamp(int(c.t * double(n)), 0, n - 1);
    }
    return cube_texel_index(g, gx, gy, n);
}

inline double sun_luminance(const vec3<double>& v) { return 0.2126 * v.x + 0.7152 * v.y + 0.0722 * v.z; }

/// Level 0 of a cube as six packed n x n faces (index cube_texel_index): the texels, their solid
/// angles (one face's, shared) and their luminances (non-finite channels read as 0).
template <class T> struct sun_grid {
    const cubemap<T>& cube;
    int n;
    std::size_t nn, count;
    std::vector<double> omega, Y;

    explicit sun_grid(const cubemap<T>& c)
        : cube(c), n(c.size(0)), nn(std::size_t(n) * std::size_t(n)), count(6 * nn), omega(cube_face_solid_angles<double>(n)), Y(count) {
        for (std::size_t i = 0; i < count; ++i) Y[i] = sun_luminance(finite(i));
    }
    void coords(std::size_t i, int& f, int& x, int& y) const {
        f = int(i / nn);
        y = int((i / std::size_t(n)) % std::size_t(n));
        x = int(i % std::size_t(n));
    }
    vec3<double> finite(std::size_t i) const {
        int f, x, y;
        coords(i, f, x, y);
        vec3<double> d(cube.texel(f, x, y, 0));
        for (int k = 0; k < 3; ++k)
            if (!is_finite(d[k])) d[k] = 0.0;
        return d;
    }
    double solid_angle(std::size_t i) const { return omega[i % nn]; }
    vec3<double> direction(std::size_t i) const {
        int f, x, y;
        coords(i, f, x, y);
        return cube_texel_direction<double>(f, x, y, n);
    }
};

/// Step 1: the peak texel, the median luminance and the threshold (into out).
template <class T> std::size_t sun_statistics(const sun_grid<T>& g, const sun_extract_options& opt, sun_extraction<T>& out) {
    std::size_t peak = 0;
    for (std::size_t i = 0; i < g.count; ++i)
        if (g.Y[i] > g.Y[peak]) peak = i;
    std::vector<double> tmp = g.Y;
    auto mid = tmp.begin() + std::ptrdiff_t(g.count / 2);
    std::nth_element(tmp.begin(), mid, tmp.end());
    out.median_luminance = *mid;
    out.peak_luminance = g.Y[peak];
    out.threshold = std::max(opt.threshold_over_median * out.median_luminance, opt.threshold_over_peak * out.peak_luminance);
    return peak;
}

/// Steps 2-3: the 8-connected region of texels above the threshold grown from the peak, stopped
/// once its solid angle exceeds max_solid_angle; `in` marks its texels.
template <class T>
std::vector<std::size_t> sun_region(const sun_grid<T>& g, std::size_t peak, double threshold, double max_solid_angle,
                                    std::vector<std::uint8_t>& in, double& region_omega) {
    in.assign(g.count, 0);
    std::vector<std::size_t> region{peak};
    in[peak] = 1;
    region_omega = g.solid_angle(peak);
    for (std::size_t k = 0; k < region.size(); ++k) {
        int f, x, y;
        g.coords(region[k], f, x, y);
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                if (dx == 0 && dy == 0) continue;
                const std::size_t j = sun_neighbour(f, x, y, dx, dy, g.n);
                if (in[j] || !(g.Y[j] > threshold)) continue;
                in[j] = 1;
                region.push_back(j);
                region_omega += g.solid_angle(j);
            }
        if (region_omega > max_solid_angle) break;
    }
    return region;
}

/// Step 4, the relaxation: successive over-relaxation of the region's values `val` towards the
/// mean of their 4 neighbours `nb` (a region texel's value, or the texel outside it).
template <class T>
void sun_relax(const sun_grid<T>& g, const std::vector<std::uint8_t>& in, const std::vector<std::size_t>& nb,
               const std::vector<std::size_t>& slot, std::vector<vec3<double>>& val, int max_sweeps, double ring_luminance) {
    // Over-relaxation factor of a region of diameter ~ sqrt(texels) (Young's optimum for a
    // square of that side); any factor in (0, 2) converges to the same harmonic fill.
    const std::size_t rc = val.size();
    const double side = std::sqrt(double(rc)) + 2.0;
    const double w = 2.0 / (1.0 + std::sin(pi_v<double> / side));
    const double tol = 1e-6 * std::max(ring_luminance, 1e-300);
    for (int sweep = 0; sweep < max_sweeps; ++sweep) {
        double change = 0.0;
        for (std::size_t k = 0; k < rc; ++k) {
            vec3<double> s(0.0);
            for (int e = 0; e < 4; ++e) {
                const std::size_t j = nb[4 * k + std::size_t(e)];
                s += in[j] ? val[slot[j]] : g.finite(j);
            }
            const vec3<double> next = val[k] + w * (0.25 * s - val[k]);
            change = std::max(change, std::fabs(sun_luminance(next - val[k])));
            val[k] = next;
        }
        if (change <= tol) break;
    }
}

/// Step 4: the harmonic fill of the (sorted) region from its 4-connected ring, started at the
/// ring's mean.
template <class T>
std::vector<vec3<double>> sun_harmonic_fill(const sun_grid<T>& g, const std::vector<std::size_t>& region,
                                            const std::vector<std::uint8_t>& in, int max_sweeps) {
    const std::size_t rc = region.size();
    std::vector<std::size_t> nb(4 * rc);
    std::vector<std::size_t> slot(g.count, std::size_t(-1)); // region index of a texel
    for (std::size_t k = 0; k < rc; ++k) slot[region[k]] = k;
    vec3<double> ring_sum(0.0);
    std::size_t ring_count = 0;
    const int d4[4][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};
    for (std::size_t k = 0; k < rc; ++k) {
        int f, x, y;
        g.coords(region[k], f, x, y);
        for (int e = 0; e < 4; ++e) {
            const std::size_t j = sun_neighbour(f, x, y, d4[e][0], d4[e][1], g.n);
            nb[4 * k + std::size_t(e)] = j;
            if (!in[j]) {
                ring_sum += g.finite(j);
                ++ring_count;
            }
        }
    }
    const vec3<double> ring_mean = ring_count ? ring_sum / double(ring_count) : vec3<double>(0.0);
    std::vector<vec3<double>> val(rc, ring_mean);
    sun_relax(g, in, nb, slot, val, max_sweeps, sun_luminance(ring_mean));
    return val;
}

/// Step 5: the disk light from the region's excess over the fill (into out); false when there is
/// no excess. dir and e_sun: the light's direction and irradiance facing it.
template <class T>
bool sun_light(const sun_grid<T>& g, const std::vector<std::size_t>& region, const std::vector<vec3<double>>& val,
               sun_extraction<T>& out, vec3<double>& dir, vec3<double>& e_sun) {
    const std::size_t rc = region.size();
    vec3<double> moment(0.0);
    double peak_excess = 0.0, power_y = 0.0;
    std::vector<vec3<double>> excess(rc), dirs(rc);
    for (std::size_t k = 0; k < rc; ++k) {
        excess[k] = g.finite(region[k]) - val[k];
        dirs[k] = g.direction(region[k]);
        const double ey = sun_luminance(excess[k]), om = g.solid_angle(region[k]);
        moment += (ey * om) * dirs[k];
        power_y += ey * om;
        peak_excess = std::max(peak_excess, ey);
    }
    const double mlen = glm::length(moment);
    if (!(mlen > 0.0) || !(peak_excess > 0.0)) return false; // no excess: nothing to extract
    dir = moment / mlen;
    e_sun = vec3<double>(0.0);
    for (std::size_t k = 0; k < rc; ++k) e_sun += excess[k] * (g.solid_angle(region[k]) * glm::dot(dirs[k], dir));
    const double sa = std::min(power_y / peak_excess, two_pi_v<double>);
    const double c = sa / two_pi_v<double>; // 1 - cos r
    const double sin2 = c * (2.0 - c);
    out.direction = vec3<T>(dir);
    out.solid_angle = T(sa);
    out.angular_radius = T(std::acos(std::clamp(1.0 - c, -1.0, 1.0)));
    out.irradiance = vec3<T>(e_sun);
    out.radiance = vec3<T>(e_sun / (pi_v<double> * sin2));
    return true;
}

/// Step 6: the light's share of the irradiance facing it (brute-force texel sum of the original).
template <class T> double sun_share(const sun_grid<T>& g, const vec3<double>& dir, const vec3<double>& e_sun) {
    double e_total = 0.0;
    for (std::size_t i = 0; i < g.count; ++i) {
        const double cs = glm::dot(dir, g.direction(i));
        if (cs > 0.0) e_total += g.Y[i] * g.solid_angle(i) * cs;
    }
    return e_total > 0.0 ? sun_luminance(e_sun) / e_total : 0.0;
}
} // namespace detail

/// Finds the sun of level 0 of `cube` by the header's rule; when found, removes it in place (fill
/// at level 0, mips rebuilt through ex) and returns the light. Otherwise `cube` is unchanged.
template <class T, class Executor = serial_executor>
sun_extraction<T> extract_sun_in_place(cubemap<T>& cube, const sun_extract_options& opt = {}, Executor&& ex = Executor{}) {
    sun_extraction<T> out;
    const detail::sun_grid<T> g(cube);
    const std::size_t peak = detail::sun_statistics(g, opt, out);
    if (!(out.peak_luminance > out.threshold) || !(out.peak_luminance > 0.0)) return out;

    std::vector<std::uint8_t> in;
    double region_omega = 0.0;
    std::vector<std::size_t> region = detail::sun_region(g, peak, out.threshold, opt.max_solid_angle, in, region_omega);
    out.region_texels = region.size();
    out.region_solid_angle = T(region_omega);
    if (region_omega > opt.max_solid_angle) {
        out.status = sun_status::too_large;
        return out;
    }
    std::sort(region.begin(), region.end()); // a fixed order for the fill and the sums

    const std::vector<vec3<double>> val = detail::sun_harmonic_fill(g, region, in, opt.max_fill_sweeps);
    vec3<double> dir(0.0), e_sun(0.0);
    if (!detail::sun_light(g, region, val, out, dir, e_sun)) return out;
    out.share = detail::sun_share(g, dir, e_sun);
    if (!(out.share >= opt.min_share)) {
        out.status = sun_status::too_weak;
        return out;
    }

    // 7. remove: fill level 0, rebuild the mips
    for (std::size_t k = 0; k < region.size(); ++k) {
        int f, x, y;
        g.coords(region[k], f, x, y);
        cube.set_texel(f, x, y, 0, vec3<T>(val[k]));
    }
    cube.generate_mips(ex);
    out.status = sun_status::found;
    return out;
}

/// A sun extraction and the residual environment (a copy of the source without the sun, or an
/// unchanged copy when none was found).
template <class T> struct sun_split {
    sun_extraction<T> sun;
    cubemap<T> residual;
};

/// Copying form of extract_sun_in_place: the source is left unchanged.
template <class T, class Executor = serial_executor>
sun_split<T> extract_sun(const cubemap<T>& src, const sun_extract_options& opt = {}, Executor&& ex = Executor{}) {
    cubemap<T> residual = src;
    sun_extraction<T> s = extract_sun_in_place(residual, opt, ex);
    return {s, std::move(residual)};
}

} // namespace ibl

#endif // IBL_DETAIL_CXX20
