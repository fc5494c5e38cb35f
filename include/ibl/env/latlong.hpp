#pragma once
// ibl/env/latlong.hpp — latlong<T>: an equirectangular (latitude-longitude) environment map with a
// mip chain (host only: std::vector storage, exceptions on bad input).
//
// Convention (DESIGN.md, as SampleSphericalMap in the literature). A direction (x, y, z) maps to
//   u = 0.5 + atan2(z, x) / (2 pi)          in [0, 1], the seam u = 0 ~ u = 1 is the -X half-plane
//   v = 0.5 + atan2(y, sqrt(x^2 + z^2)) / pi = 0.5 + asin(y) / pi for unit dir, in [0, 1]
// (the atan2 form is scale-invariant and accurate near the poles). Image coordinates of a
// W x H image: column = u W, row = (1 - v) H, so row 0 is the top of the image and touches +Y
// (v = 1), row H - 1 touches -Y; column 0 starts at u = 0 (azimuth -pi, direction -X). Texel
// (i, j) covers columns [i, i + 1) and rows [j, j + 1); its centre is (i + 0.5, j + 0.5).
// Inverse: phi = 2 pi (u - 0.5), lat = pi (v - 0.5), dir = (cos lat cos phi, sin lat, cos lat sin phi).
//
// Texel solid angle of row j (exact): (2 pi / W) (sin lat_top - sin lat_bottom)
//   = (4 pi / W) sin(pi (j + 0.5) / H) sin(pi / (2 H))   (the product form: no cancellation).
//
// Filtering (bilinear, on texel centres; trilinear across levels with a continuous lod):
//   * u wraps: a 1-texel border column on each side holds the opposite column, so lookups across
//     the seam blend column W - 1 and column 0 with no branch.
//   * v near the poles: all columns meet at a pole, so a value that depends on u there would be
//     discontinuous. The border rows above row 0 and below row H - 1 hold the pole value, the mean
//     of row 0 (resp. H - 1) over all columns (every texel of a row has the same solid angle),
//     placed AT the pole (half a texel beyond the last row centre instead of a whole texel). Between
//     the last row centre and the pole the lookup blends linearly to that pole value, so the
//     filtered map is continuous on the whole sphere, poles included.
//
// Levels: level l is max(1, W >> l) x max(1, H >> l); the full chain ends at the level where the
// larger side is 1. Mip generation is the exact box filter on the sphere: weights are the exact
// solid angles of the overlap pieces, (delta u) 2 pi x (delta sin(latitude)) (a box in u,
// cos-latitude weighted in v), so sum(texel * texel solid angle) is preserved at every level.
// texel_solid_angle(lod) is the AVERAGE 4 pi / (W_l H_l), interpolated log-linearly in lod (true
// texels near the poles are much smaller: filtered importance sampling over a lat-long map blurs
// less than intended near the poles). lod_for_solid_angle is its exact inverse.
//
// Mutation as for cubemap: write texels, then generate_mips() or update_borders() before lookups.
// Data from files may hold NaN/inf or small negative values (lossy EXR): sanitize() them first.

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "detail/level_solid_angle.hpp"
#include "../core/constants.hpp"
#include "../core/executor.hpp"
#include "../core/limits.hpp"
#include "../core/math.hpp"
#include "../core/vec.hpp"
#include "convert.hpp"
#include "cubemap.hpp"
#include "detail/resample.hpp"
#include "environment.hpp"

namespace ibl {

/// (u, v) in [0, 1]^2 of a direction (need not be unit). The zero vector maps to (0.5, 0.5).
template <class T> IBL_FUNC vec2<T> latlong_uv(const vec3<T>& dir) noexcept {
    using std::atan2;
    using std::sqrt;
    const T u = T(0.5) + atan2(dir.z, dir.x) * inv_two_pi_v<T>;
    // v = 0.5 + asin(y)/pi written as (polar angle from -Y)/pi: atan2(0, 1) = 0 and
    // atan2(0, -1) = pi_T make both poles exact (v = 0 and 1) in any rounding/contraction mode,
    // and atan2 keeps full accuracy near the poles where asin(y) would not.
    // The zero vector (and NaN) maps to the equator, v = 0.5, as before.
    const T r = sqrt(dir.x * dir.x + dir.z * dir.z);
    const T v = (r > T(0) || dir.y != T(0)) ? atan2(r, -dir.y) / pi_v<T> : T(0.5);
    return {u, v};
}

/// Unit direction of (u, v) in [0, 1]^2.
template <class T> IBL_FUNC vec3<T> latlong_direction(T u, T v) noexcept {
    using std::cos;
    using std::sin;
    const T phi = two_pi_v<T> * (u - T(0.5));
    const T lat = pi_v<T> * (v - T(0.5));
    const T cl = cos(lat);
    return {cl * cos(phi), sin(lat), cl * sin(phi)};
}

/// Exact solid angle of one texel of row j of a W x H lat-long image (row 0 at +Y).
template <class T> IBL_FUNC T latlong_texel_solid_angle(int j, int width, int height) noexcept {
    using std::sin;
    const T h = T(height);
    return four_pi_v<T> / T(width) * sin(pi_v<T> * (T(j) + T(0.5)) / h) * sin(pi_v<T> / (T(2) * h));
}

/// Texels a latlong of width x height with `levels` levels stores (borders and every level
/// included: sum over levels of (w_l + 2)(h_l + 2)), levels = 0 meaning the full chain. Throws
/// std::invalid_argument for a side < 1 or levels outside [0, full chain], std::length_error for
/// a side > limits::max_face_size or a total above limits::max_texels.
inline std::size_t latlong_storage_texels(int width, int height, int levels = 0) {
    detail::check_arg("latlong", "width", width, 1, limits::max_face_size, "limits::max_face_size");
    detail::check_arg("latlong", "height", height, 1, limits::max_face_size, "limits::max_face_size");
    const int full = detail::full_chain_levels(width > height ? width : height);
    if (levels < 0 || levels > full)
        throw std::invalid_argument("ibl::latlong: levels = " + std::to_string(levels) + " outside [0, " +
                                    std::to_string(full) + "] for " + std::to_string(width) + " x " +
                                    std::to_string(height));
    if (levels == 0) levels = full;
    std::uint64_t total = 0; // <= 17 * 65538^2 < 2^37: no overflow
    for (int l = 0; l < levels; ++l) {
        const std::uint64_t w = std::uint64_t(width >> l > 0 ? width >> l : 1) + 2;
        const std::uint64_t h = std::uint64_t(height >> l > 0 ? height >> l : 1) + 2;
        total += w * h;
    }
    detail::check_total("latlong", "stored texels", total, limits::max_texels, "limits::max_texels");
    return std::size_t(total);
}

template <class T> class latlong {
public:
    using scalar_type = T;
    using value_type = vec3<T>;

    /// width, height >= 1; levels = 0 means the full chain. Texels are 0. Throws
    /// std::invalid_argument for a size < 1 or levels outside [0, full chain], std::length_error
    /// for a side > limits::max_face_size or more than limits::max_texels stored texels
    /// (latlong_storage_texels), before allocating.
    latlong(int width, int height, int levels = 0) { init(width, height, levels); }

    /// Level 0 from interleaved linear RGB floats, row 0 = top (+Y), rgb.size() = 3 W H.
    /// Copies only: call sanitize() if the data may hold NaN/inf/negatives, then generate_mips().
    latlong(int width, int height, std::span<const float> rgb, int levels = 0) {
        init(width, height, levels);
        if (rgb.size() != std::size_t(3) * std::size_t(width) * std::size_t(height))
            throw std::invalid_argument("ibl::latlong: expected 3 * " + std::to_string(width) + " * " +
                                        std::to_string(height) + " floats, got " + std::to_string(rgb.size()));
        fill(0, [&](int x, int y) {
            const std::size_t i = 3 * (std::size_t(y) * std::size_t(width) + std::size_t(x));
            return vec3<T>(T(rgb[i]), T(rgb[i + 1]), T(rgb[i + 2]));
        });
    }

    /// Size of a level. Safe for any level: one outside [0, levels()) is clamped to the chain.
    [[nodiscard]] int width(int level = 0) const noexcept { return levels_[std::size_t(clamp_level(level))].w; }
    [[nodiscard]] int height(int level = 0) const noexcept { return levels_[std::size_t(clamp_level(level))].h; }
    [[nodiscard]] int levels() const noexcept { return int(levels_.size()); }
    [[nodiscard]] T max_lod() const noexcept { return T(levels_.size() - 1); }
    [[nodiscard]] bool borders_valid() const noexcept { return !borders_dirty_; }

    // Texel access. Precondition (hot path, noexcept: IBL_ASSERT in debug builds, unchecked in
    // release): 0 <= level < levels(), x in [0, width(level)), y in [0, height(level)).
    [[nodiscard]] const vec3<T>& texel(int x, int y, int level = 0) const noexcept {
        return data_[index(x, y, level)];
    }
    [[nodiscard]] vec3<T>& texel_ref(int x, int y, int level = 0) noexcept {
        borders_dirty_ = true;
        return data_[index(x, y, level)];
    }
    void set_texel(int x, int y, int level, const vec3<T>& v) noexcept { texel_ref(x, y, level) = v; }

    /// Sets every texel of a level to fn(x, y); marks the borders stale. Throws
    /// std::invalid_argument unless 0 <= level < levels().
    template <class F> void fill(int level, F&& fn) {
        if (level < 0 || level >= levels())
            throw std::invalid_argument("ibl::latlong::fill: level = " + std::to_string(level) + " outside [0, " +
                                        std::to_string(levels()) + ")");
        for (int y = 0; y < height(level); ++y)
            for (int x = 0; x < width(level); ++x) data_[index(x, y, level)] = vec3<T>(fn(x, y));
        borders_dirty_ = true;
    }

    /// Exact solid angle of a texel of row y of a level.
    [[nodiscard]] T exact_texel_solid_angle(int y, int level = 0) const noexcept {
        return T(latlong_texel_solid_angle<double>(y, width(level), height(level)));
    }

    // ---- environment concept ----------------------------------------------------------------

    [[nodiscard]] T texel_solid_angle(T lod) const noexcept {
        return detail::level_texel_solid_angle(levels_, lod, max_lod());
    }

    /// The lod whose average texel solid angle is omega, clamped to [0, max_lod()]; 0 for NaN.
    [[nodiscard]] T lod_for_solid_angle(T omega) const noexcept {
        return detail::level_lod_for_solid_angle(levels_, omega, max_lod());
    }

    /// Trilinear radiance: bilinear on floor(lod) and floor(lod) + 1 (lod clamped, NaN -> 0).
    [[nodiscard]] vec3<T> radiance(const vec3<T>& dir, T lod = T(0)) const noexcept {
        IBL_ASSERT(!borders_dirty_);
        const vec2<T> uv = latlong_uv(dir);
        const T u = clamp(uv.x, T(0), T(1)), v = clamp(uv.y, T(0), T(1));
        const T l = clamp(lod, T(0), max_lod());
        const int l0 = int(l);
        const T f = l - T(l0);
        vec3<T> r = bilinear_unchecked(u, v, l0);
        if (f > T(0)) r += f * (bilinear_unchecked(u, v, l0 + 1) - r);
        return r;
    }

    /// Bilinear lookup at (u, v) (clamped to [0, 1]; u wraps through the border) on one level.
    [[nodiscard]] vec3<T> bilinear(T u, T v, int level = 0) const noexcept {
        IBL_ASSERT(!borders_dirty_);
        const int l = level < 0 ? 0 : (level >= levels() ? levels() - 1 : level);
        return bilinear_unchecked(clamp(u, T(0), T(1)), clamp(v, T(0), T(1)), l);
    }

    [[nodiscard]] vec3<T> bilinear(const vec3<T>& dir, int level = 0) const noexcept {
        const vec2<T> uv = latlong_uv(dir);
        return bilinear(uv.x, uv.y, level);
    }

    /// Texel containing dir on level round(lod).
    [[nodiscard]] vec3<T> nearest(const vec3<T>& dir, T lod = T(0)) const noexcept {
        const vec2<T> uv = latlong_uv(dir);
        const int l = int(clamp(lod, T(0), max_lod()) + T(0.5));
        const int w = width(l), h = height(l);
        const int x = min_int(int(clamp(uv.x, T(0), T(1)) * T(w)), w - 1);
        const int y = min_int(int((T(1) - clamp(uv.y, T(0), T(1))) * T(h)), h - 1);
        return data_[index(x, y, l)];
    }

    // ---- building -----------------------------------------------------------------------------

    template <class Executor = serial_executor> void generate_mips(Executor&& ex = Executor{}) {
        for (int l = 1; l < levels(); ++l) downsample(l, ex);
        update_borders();
    }

    void update_borders() {
        for (int l = 0; l < levels(); ++l) build_borders(l);
        borders_dirty_ = false;
    }

    /// Replaces non-finite components (and negative ones when zero_negative) of every texel of
    /// every level by 0, rebuilds the borders, and returns the number of texels changed.
    std::size_t sanitize(bool zero_negative = true) {
        std::size_t changed = 0;
        for (int l = 0; l < levels(); ++l)
            for (int y = 0; y < height(l); ++y)
                for (int x = 0; x < width(l); ++x) {
                    changed += detail::sanitize_texel(data_[index(x, y, l)], zero_negative) ? 1 : 0;
                }
        update_borders();
        return changed;
    }

private:
    struct level_info {
        int w = 1, h = 1;
        int stride = 3; ///< w + 2
        std::size_t offset = 0;
        T omega = T(0); ///< average texel solid angle 4 pi / (w h)
        T log2_omega = T(0);
    };

    static int min_int(int a, int b) noexcept { return a < b ? a : b; }
    int clamp_level(int level) const noexcept {
        return level < 0 ? 0 : (level >= levels() ? levels() - 1 : level);
    }

    void init(int width, int height, int levels) {
        const std::size_t total = latlong_storage_texels(width, height, levels);
        if (levels == 0) levels = detail::full_chain_levels(width > height ? width : height);
        std::size_t offset = 0;
        for (int l = 0; l < levels; ++l) {
            level_info li;
            li.w = width >> l > 0 ? width >> l : 1;
            li.h = height >> l > 0 ? height >> l : 1;
            li.stride = li.w + 2;
            li.offset = offset;
            const double omega = four_pi_v<double> / (double(li.w) * double(li.h));
            li.omega = T(omega);
            li.log2_omega = T(std::log2(omega));
            offset += std::size_t(li.stride) * std::size_t(li.h + 2);
            levels_.push_back(li);
        }
        IBL_ASSERT(offset == total);
        data_.assign(total, vec3<T>(T(0)));
    }

    /// Storage index of (x, y), x in [-1, w], y in [-1, h] (border included).
    std::size_t index(int x, int y, int level) const noexcept {
        IBL_ASSERT(level >= 0 && level < levels());
        const level_info& li = levels_[std::size_t(level)];
        IBL_ASSERT(x >= -1 && x <= li.w && y >= -1 && y <= li.h);
        return li.offset + std::size_t(y + 1) * std::size_t(li.stride) + std::size_t(x + 1);
    }

    /// u, v in [0, 1]. Bordered column of u: u W + 0.5 in [0.5, W + 0.5]. Row: fy = (1 - v) H - 0.5
    /// in [-0.5, H - 0.5], stretched by 2 beyond the first/last row centre so that the pole
    /// (fy = -0.5 or H - 0.5) lands on the border row (-1 or H): fy + min(fy, 0) + max(fy - (H-1), 0).
    vec3<T> bilinear_unchecked(T u, T v, int level) const noexcept {
        const level_info& li = levels_[std::size_t(level)];
        const T fx = u * T(li.w) + T(0.5);
        T fy = (T(1) - v) * T(li.h) - T(0.5);
        const T below = fy - T(li.h - 1);
        fy += (fy < T(0) ? fy : T(0)) + (below > T(0) ? below : T(0));
        fy += T(1); // bordered row coordinate in [0, H + 1]
        const int x0 = min_int(int(fx), li.w);
        const int y0 = min_int(int(fy), li.h);
        const T wx = fx - T(x0);
        const T wy = fy - T(y0);
        const std::size_t st = std::size_t(li.stride);
        const vec3<T>* p = data_.data() + li.offset + std::size_t(y0) * st + std::size_t(x0);
        const vec3<T> top = p[0] + wx * (p[1] - p[0]);
        const vec3<T> bot = p[st] + wx * (p[st + 1] - p[st]);
        return top + wy * (bot - top);
    }

    /// Mean of a row (all its texels have the same solid angle), exact for a constant row.
    vec3<T> row_mean(int y, int level) const {
        const vec3<double> ref(data_[index(0, y, level)]);
        vec3<double> acc(0.0);
        const int w = width(level);
        for (int x = 0; x < w; ++x) acc += vec3<double>(data_[index(x, y, level)]) - ref;
        return vec3<T>(ref + acc / double(w));
    }

    void build_borders(int level) {
        const int w = width(level), h = height(level);
        for (int y = 0; y < h; ++y) {
            data_[index(-1, y, level)] = data_[index(w - 1, y, level)];
            data_[index(w, y, level)] = data_[index(0, y, level)];
        }
        const vec3<T> north = row_mean(0, level), south = row_mean(h - 1, level);
        for (int x = -1; x <= w; ++x) {
            data_[index(x, -1, level)] = north;
            data_[index(x, h, level)] = south;
        }
    }

    /// Exact spherical box filter from level - 1 (see the header comment); rows through ex.
    template <class Executor> void downsample(int level, Executor& ex) {
        const int wf = width(level - 1), hf = height(level - 1), wc = width(level), hc = height(level);
        const std::vector<detail::grid_piece> xp = detail::grid_overlap(wf, wc);
        const std::vector<detail::grid_piece> yp = detail::grid_overlap(hf, hc);
        const auto xr = detail::coarse_ranges(xp, wc);
        const auto yr = detail::coarse_ranges(yp, hc);
        ex(std::size_t(hc), [&](std::size_t row_begin, std::size_t row_end) {
            std::vector<vec3<double>> acc(static_cast<std::size_t>(wc)), ref(static_cast<std::size_t>(wc));
            std::vector<double> wsum(static_cast<std::size_t>(wc));
            for (std::size_t cy = row_begin; cy < row_end; ++cy) {
                const auto [yb, ye] = yr[cy];
                for (int cx = 0; cx < wc; ++cx) {
                    const int fx0 = xp[std::size_t(xr[std::size_t(cx)].first)].fine;
                    ref[std::size_t(cx)] = vec3<double>(data_[index(fx0, yp[std::size_t(yb)].fine, level - 1)]);
                    acc[std::size_t(cx)] = vec3<double>(0.0);
                    wsum[std::size_t(cx)] = 0.0;
                }
                for (int yk = yb; yk < ye; ++yk) {
                    const detail::grid_piece& py = yp[std::size_t(yk)];
                    // delta sin(latitude) = cos(pi lo) - cos(pi hi), in product form
                    const double wy = 2.0 * std::sin(pi_v<double> * 0.5 * (py.lo + py.hi)) *
                                      std::sin(pi_v<double> * 0.5 * (py.hi - py.lo));
                    for (const detail::grid_piece& px : xp) {
                        const double w = wy * (px.hi - px.lo);
                        const std::size_t cx = std::size_t(px.coarse);
                        wsum[cx] += w;
                        acc[cx] += w * (vec3<double>(data_[index(px.fine, py.fine, level - 1)]) - ref[cx]);
                    }
                }
                for (int cx = 0; cx < wc; ++cx)
                    data_[index(cx, int(cy), level)] =
                        vec3<T>(ref[std::size_t(cx)] + acc[std::size_t(cx)] / wsum[std::size_t(cx)]);
            }
        });
    }

    std::vector<level_info> levels_;
    std::vector<vec3<T>> data_;
    bool borders_dirty_ = false;
};

static_assert(environment<latlong<float>, float>);
static_assert(environment<latlong<double>, double>);

/// latlong -> cubemap of face size n by k x k supersampling of each texel (bake_cubemap), reading
/// the lat-long map at `lod` (0 = finest, bilinear). Deterministic for any executor. Throws as
/// bake_cubemap (n, k and their work bounded by limits::max_face_size, max_subsamples, max_work).
template <class T, class Executor = serial_executor>
cubemap<T> latlong_to_cubemap(const latlong<T>& src, int n, int k, Executor&& ex = Executor{}, int levels = 0,
                              T lod = T(0)) {
    detail::check_bake_args("latlong_to_cubemap", n, k);
    return bake_cubemap<T>(src, n, k, std::forward<Executor>(ex), levels, lod);
}

} // namespace ibl

#endif // IBL_DETAIL_CXX20
