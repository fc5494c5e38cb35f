#pragma once
// ibl/env/cubemap.hpp — cubemap<T>: six faces with a mip chain of linear RGB, seamless filtering
// (host only: std::vector storage, exceptions on bad input).
//
// Convention: env/cube_geometry.hpp (faces +X, -X, +Y, -Y, +Z, -Z; GL sc/tc/ma table; row 0 of a
// face is t = 0, column 0 is s = 0; texel (x, y) covers [x/n, (x+1)/n] x [y/n, (y+1)/n]).
//
// Levels. Level 0 is the finest, of face size n (any n >= 1, power of two or not); level l has
// size max(1, n >> l). The full chain ends at 1 x 1 (floor(log2 n) + 1 levels). Mip generation
// is an exact box filter on the sphere: a coarse texel is the solid-angle-weighted mean of the
// pieces of the finer texels it covers (weights: exact solid angles of the overlap rectangles,
// from the antiderivative of cube_geometry.hpp, in double). So the integral of radiance over the
// sphere, sum(texel * exact texel solid angle), is the same at every level up to rounding; for
// non-power-of-two sizes a fine texel straddling two coarse texels is split between them exactly.
//
// Storage. Texels are interleaved vec3<T> (RGB together): one bilinear lookup reads two pairs of
// adjacent texels, i.e. two runs of 2 x 3 scalars, which is fewer cache lines than planar RGB.
// Every face of every level is stored with a 1-texel border, (n + 2)^2 texels, so a bilinear
// lookup reads 4 texels with no wrap logic and no branch:
//   * an edge border texel holds the texel of the neighbouring face that lies across the edge
//     (the cube unfolded about that edge: the neighbour texel at the same distance from the edge);
//   * a corner border texel, where only three texels of the cube meet, holds
//     a + ((b - a) + (c - a)) / 3 of the three (the face's corner texel a and the two edge border
//     texels b, c): the mean, written so that three equal values give that value exactly.
// Consequently a bilinear lookup is continuous across every edge (both sides blend the same two
// texels with the same weights exactly on the edge) and at the 8 corners (all three faces give
// (a + b + c) / 3 there).
//
// Mutation. texel_ref()/set_texel()/fill() write the interior and mark the borders of that level
// stale; generate_mips() (rebuilds levels >= 1 from level 0) or update_borders() (keeps all
// levels) must run before lookups, which assert this with IBL_ASSERT. update_borders(level, face)
// rebuilds one face of one level (a time-sliced producer spreads the borders over calls): the
// borders are valid again once every face of every written level has been rebuilt after its
// last write.
//
// Lookups (dir need not be unit; the zero vector maps to the centre of face +X as cube_lookup
// documents, and NaN/inf components to some texel of face +X, never out of bounds). Face
// selection uses detail::cube_lookup_select: cube_lookup written with selects instead of
// branches (bit-identical results for finite non-zero directions), because directions that jump
// between faces mispredict cube_lookup's branches.
//   bilinear(dir, level)  seamless bilinear on one level;
//   radiance(dir, lod)    trilinear: bilinear on floor(lod) and floor(lod)+1, linear in lod
//                         (lod continuous, clamped to [0, max_lod()], NaN -> 0);
//   nearest(dir, lod)     texel containing dir on level round(lod).
// Interpolation is written a + w (b - a), so equal texels give exactly that value, and texel
// centres give the texel exactly.
//
// texel_solid_angle(lod): average texel solid angle 4 pi / (6 n_l^2) at integer lods, interpolated
// log-linearly in between (= Omega_0 4^lod for power-of-two chains); lod_for_solid_angle is its
// exact inverse. exact_texel_solid_angle(x, y, level) gives the true (non-uniform) value.

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "detail/level_solid_angle.hpp"
#include "../core/constants.hpp"
#include "../core/executor.hpp"
#include "../core/limits.hpp"
#include "../core/math.hpp"
#include "../core/memory.hpp"
#include "../core/vec.hpp"
#include "cube_geometry.hpp"
#include "detail/resample.hpp"
#include "environment.hpp"

namespace ibl {

namespace detail {
/// cube_lookup without data-dependent branches (selects only): the same face, s and t bit for
/// bit, including the X-before-Y-before-Z tie rule and the zero/NaN fallback. Random directions
/// make the branches of cube_lookup mispredict (timings: docs/ARCHITECTURE.md, "Environments").
template <class T> IBL_FUNC cube_coord<T> cube_lookup_select(const vec3<T>& r) noexcept {
    using std::fabs;
    const T ax = fabs(r.x), ay = fabs(r.y), az = fabs(r.z);
    const bool xm = (ax >= ay) & (ax >= az); // & not &&: no short-circuit branch
    const bool ym = (!xm) & (ay >= az);
    // 0/1 weights instead of ternaries: compilers keep these as arithmetic (ternaries on floats
    // were turned back into branches). Exact: the unselected terms are +-0.
    const T wx = T(xm), wy = T(ym), wz = T(1) - wx - wy;
    const T ma = wx * ax + wy * ay + wz * az;
    const T major = wx * r.x + wy * r.y + wz * r.z;
    const bool neg = !(major >= T(0));
    const T sg = T(1) - T(2) * T(neg);
    //        +-X: sc = -+z, tc = -y;  +-Y: sc = x, tc = +-z;  +-Z: sc = +-x, tc = -y
    const T sc = wx * (-sg * r.z) + wy * r.x + wz * (sg * r.x);
    const T tc = wy * (sg * r.z) - (T(1) - wy) * r.y;
    const int face = 2 * (int(!xm) + int((!xm) & (!ym))) + int(neg);
    const bool ok = (ma > T(0)) & (ma <= std::numeric_limits<T>::max()); // zero, NaN, inf: fallback
    const T inv = T(1) / (ma + T(!ok));
    // A bad direction gives face 0 and s, t = 0.5 or NaN (0 * inf); callers clamp (NaN -> 0).
    return {face * int(ok), T(0.5) * (T(ok) * (sc * inv) + T(1)), T(0.5) * (T(ok) * (tc * inv) + T(1))};
}
} // namespace detail

/// Texels a cubemap of face size `size` and `levels` levels stores (borders and every level
/// included: sum over levels of 6 (n_l + 2)^2), levels = 0 meaning the full chain. Throws
/// std::invalid_argument for size < 1 or levels outside [0, floor(log2 size) + 1], and
/// std::length_error for size > limits::max_face_size or a total above limits::max_texels.
inline std::size_t cubemap_storage_texels(int size, int levels = 0) {
    detail::check_arg("cubemap", "face size", size, 1, limits::max_face_size, "limits::max_face_size");
    const int full = detail::full_chain_levels(size);
    if (levels < 0 || levels > full)
        throw std::invalid_argument("ibl::cubemap: levels = " + std::to_string(levels) + " outside [0, " +
                                    std::to_string(full) + "] for face size " + std::to_string(size));
    if (levels == 0) levels = full;
    std::uint64_t total = 0; // <= 17 * 6 * 65538^2 < 2^39: no overflow
    for (int l = 0; l < levels; ++l) {
        const std::uint64_t st = std::uint64_t(size >> l > 0 ? size >> l : 1) + 2;
        total += 6 * st * st;
    }
    detail::check_total("cubemap", "stored texels", total, limits::max_texels, "limits::max_texels");
    return std::size_t(total);
}

template <class T> class cubemap {
public:
    using scalar_type = T;
    using value_type = vec3<T>;

    /// Face size n >= 1 at level 0; levels = 0 means the full chain down to 1 x 1. Texels are 0.
    /// Throws std::invalid_argument for size < 1 or levels outside [0, full chain], and
    /// std::length_error for size > limits::max_face_size or more than limits::max_texels stored
    /// texels (cubemap_storage_texels), before allocating.
    explicit cubemap(int size, int levels = 0) : cubemap(size, levels, detail::for_overwrite) {
        std::fill(data_.begin(), data_.end(), vec3<T>(T(0)));
    }

    /// The same layout with every texel (borders included) left to the caller, who writes each
    /// interior texel of every level and then calls update_borders() before any read: the
    /// library's producers whose workers write the levels (prefilter), so that the memory is first
    /// touched by the threads that fill it (core/memory.hpp). In builds without NDEBUG the
    /// texels start as quiet NaN, so that a texel left unwritten shows in tests.
    cubemap(int size, int levels, detail::for_overwrite_t) {
        const std::size_t total = cubemap_storage_texels(size, levels);
        if (levels == 0) levels = detail::full_chain_levels(size);
        std::size_t offset = 0;
        for (int l = 0; l < levels; ++l) {
            level_info li;
            li.n = size >> l > 0 ? size >> l : 1;
            li.stride = li.n + 2;
            li.offset = offset;
            li.omega = T(four_pi_v<double> / (6.0 * double(li.n) * double(li.n)));
            li.log2_omega = T(std::log2(four_pi_v<double> / (6.0 * double(li.n) * double(li.n))));
            offset += 6 * std::size_t(li.stride) * std::size_t(li.stride);
            levels_.push_back(li);
        }
        IBL_ASSERT(offset == total);
        data_.resize(total);
#ifndef NDEBUG
        std::fill(data_.begin(), data_.end(), vec3<T>(std::numeric_limits<T>::quiet_NaN()));
#endif
    }

    /// Face size of a level. Safe for any level: a level outside [0, levels()) is clamped to the
    /// chain (size(99) is the coarsest level's size), as bilinear() clamps its level.
    [[nodiscard]] int size(int level = 0) const noexcept { return levels_[std::size_t(clamp_level(level))].n; }
    [[nodiscard]] int levels() const noexcept { return int(levels_.size()); }
    [[nodiscard]] T max_lod() const noexcept { return T(levels_.size() - 1); }
    /// True when the borders match the interiors (lookups are allowed).
    [[nodiscard]] bool borders_valid() const noexcept { return !borders_dirty_; }

    // ---- texel access (interior texels, x, y in [0, size(level))) ---------------------------
    // Precondition (hot path, noexcept: checked by IBL_ASSERT in debug builds, not in release):
    // 0 <= face < 6, 0 <= level < levels(), x and y in [0, size(level)). fill() throws instead.

    [[nodiscard]] const vec3<T>& texel(int face, int x, int y, int level = 0) const noexcept {
        return data_[index(face, x, y, level)];
    }
    /// Writable texel; marks the borders of its level stale (call generate_mips() or update_borders()).
    [[nodiscard]] vec3<T>& texel_ref(int face, int x, int y, int level = 0) noexcept {
        const std::size_t i = index(face, x, y, level);
        borders_dirty_ = true;
        levels_[std::size_t(level)].stale_faces = all_faces;
        return data_[i];
    }
    void set_texel(int face, int x, int y, int level, const vec3<T>& v) noexcept { texel_ref(face, x, y, level) = v; }

    /// Sets every texel of a level to fn(face, x, y); marks the borders stale. Throws
    /// std::invalid_argument unless 0 <= level < levels().
    template <class F> void fill(int level, F&& fn) {
        if (level < 0 || level >= levels())
            throw std::invalid_argument("ibl::cubemap::fill: level = " + std::to_string(level) + " outside [0, " +
                                        std::to_string(levels()) + ")");
        const int n = size(level);
        for (int f = 0; f < 6; ++f)
            for (int y = 0; y < n; ++y)
                for (int x = 0; x < n; ++x) data_[index(f, x, y, level)] = vec3<T>(fn(f, x, y));
        borders_dirty_ = true;
        levels_[std::size_t(level)].stale_faces = all_faces;
    }

    /// Exact solid angle (steradians) of texel (x, y) of a level (the same on every face).
    [[nodiscard]] T exact_texel_solid_angle(int x, int y, int level = 0) const noexcept {
        return T(cube_texel_solid_angle<double>(x, y, size(level)));
    }

    // ---- environment concept ----------------------------------------------------------------

    /// Average texel solid angle at a continuous lod (see the header comment).
    [[nodiscard]] T texel_solid_angle(T lod) const noexcept {
        return detail::level_texel_solid_angle(levels_, lod, max_lod());
    }

    /// The lod whose average texel solid angle is omega, clamped to [0, max_lod()]; 0 for NaN.
    [[nodiscard]] T lod_for_solid_angle(T omega) const noexcept {
        return detail::level_lod_for_solid_angle(levels_, omega, max_lod());
    }

    /// Trilinear radiance (seamless bilinear on two levels, linear in the continuous lod).
    [[nodiscard]] vec3<T> radiance(const vec3<T>& dir, T lod = T(0)) const noexcept {
        IBL_ASSERT(!borders_dirty_);
        const cube_coord<T> c = face_coord(dir);
        const T l = clamp(lod, T(0), max_lod());
        const int l0 = int(l);
        const T f = l - T(l0);
        vec3<T> v = bilinear_unchecked(c.face, c.s, c.t, l0);
        if (f > T(0)) v += f * (bilinear_unchecked(c.face, c.s, c.t, l0 + 1) - v);
        return v;
    }

    /// Seamless bilinear lookup on one level (level clamped to the chain).
    [[nodiscard]] vec3<T> bilinear(const vec3<T>& dir, int level = 0) const noexcept {
        IBL_ASSERT(!borders_dirty_);
        const cube_coord<T> c = face_coord(dir);
        return bilinear_unchecked(c.face, c.s, c.t, clamp_level(level));
    }

    /// Seamless bilinear lookup at face texture coordinates (s, t), clamped to [0, 1].
    [[nodiscard]] vec3<T> bilinear(int face, T s, T t, int level = 0) const noexcept {
        IBL_ASSERT(!borders_dirty_ && face >= 0 && face < 6);
        return bilinear_unchecked(face, clamp(s, T(0), T(1)), clamp(t, T(0), T(1)), clamp_level(level));
    }

    /// Texel containing dir on level round(lod) (lod clamped to [0, max_lod()], NaN -> 0).
    [[nodiscard]] vec3<T> nearest(const vec3<T>& dir, T lod = T(0)) const noexcept {
        const cube_coord<T> c = face_coord(dir);
        const int l = int(clamp(lod, T(0), max_lod()) + T(0.5));
        const int n = size(l);
        const int x = min_int(int(c.s * T(n)), n - 1);
        const int y = min_int(int(c.t * T(n)), n - 1);
        return data_[index(c.face, x, y, l)];
    }

    // ---- building -----------------------------------------------------------------------------

    /// Rebuilds levels 1.. from level 0 by the exact spherical box filter, then all borders.
    /// Work is spread over coarse rows through the executor; the result does not depend on it.
    template <class Executor = serial_executor> void generate_mips(Executor&& ex = Executor{}) {
        for (int l = 1; l < levels(); ++l) downsample(l, ex);
        update_borders();
    }

    /// The interior texel (g, gx, gy) that border texel (x, y) of `face` of an n x n level copies
    /// (update_borders; exactly one of x, y outside [0, n)).
    static void border_source(int face, int x, int y, int n, int& g, int& gx, int& gy) noexcept {
        fold_border(face, x, y, n, g, gx, gy);
    }

    /// The sources of one edge of border texels at once: edge e of `face` (0: x = -1, 1: x = n,
    /// 2: y = -1, 3: y = n; i along it from 0 to n - 1) copies texel (x0 + dx i, y0 + dy i) of face
    /// g, the same texels as border_source (the fold is affine along an edge; tests/test_cubemap.cpp
    /// checks every texel of every edge up to n = 64).
    struct border_edge {
        int g = 0, x0 = 0, y0 = 0, dx = 0, dy = 0;
    };
    static border_edge border_edge_source(int face, int e, int n) noexcept {
        auto at = [&](int i, int& g, int& gx, int& gy) {
            const int xs[4] = {-1, n, i, i}, ys[4] = {i, i, -1, n};
            fold_border(face, xs[e], ys[e], n, g, gx, gy);
        };
        border_edge b;
        at(0, b.g, b.x0, b.y0);
        if (n > 1) {
            int g, x1, y1;
            at(n - 1, g, x1, y1);
            b.dx = (x1 - b.x0) / (n - 1), b.dy = (y1 - b.y0) / (n - 1);
        }
        return b;
    }

    /// Rebuilds the 1-texel borders of every face of every level from the interiors.
    void update_borders() {
        for (int l = 0; l < levels(); ++l) {
            for (int f = 0; f < 6; ++f) build_face_borders(l, f);
            levels_[std::size_t(l)].stale_faces = 0;
        }
        borders_dirty_ = false;
    }

    /// Rebuilds the borders of one face of one level from the interiors (its own and its four
    /// neighbours'): update_borders() in 6 levels() pieces. Lookups are allowed again once every
    /// face of every level written since the last rebuild has been rebuilt. Throws
    /// std::invalid_argument unless 0 <= level < levels() and 0 <= face < 6.
    void update_borders(int level, int face) {
        if (level < 0 || level >= levels() || face < 0 || face >= 6)
            throw std::invalid_argument("ibl::cubemap::update_borders: level " + std::to_string(level) + ", face " +
                                        std::to_string(face) + " outside [0, " + std::to_string(levels()) + ") x [0, 6)");
        build_face_borders(level, face);
        levels_[std::size_t(level)].stale_faces &= std::uint8_t(~(1u << face));
        bool stale = false;
        for (const level_info& li : levels_) stale = stale || li.stale_faces != 0;
        borders_dirty_ = stale;
    }

    /// Replaces non-finite components (and negative ones when zero_negative) of every texel of
    /// every level by 0, then rebuilds the borders. Returns the number of texels changed.
    /// Run it before generate_mips() so that bad level-0 texels do not spread into the mips.
    std::size_t sanitize(bool zero_negative = true) {
        std::size_t changed = 0;
        for (int l = 0; l < levels(); ++l) {
            const int n = size(l);
            for (int f = 0; f < 6; ++f)
                for (int y = 0; y < n; ++y)
                    for (int x = 0; x < n; ++x) {
                        changed += detail::sanitize_texel(data_[index(f, x, y, l)], zero_negative) ? 1 : 0;
                    }
        }
        update_borders();
        return changed;
    }

private:
    struct level_info {
        int n = 1;               ///< face size
        int stride = 3;          ///< n + 2 (row length including the border)
        std::size_t offset = 0;  ///< index of the first stored texel of face 0 (with border)
        T omega = T(0);          ///< average texel solid angle 4 pi / (6 n^2)
        T log2_omega = T(0);
        std::uint8_t stale_faces = 0; ///< bit f: face f's borders predate a write to this level
    };
    static constexpr std::uint8_t all_faces = 0x3f;

    static int min_int(int a, int b) noexcept { return a < b ? a : b; }
    /// Face and (s, t) clamped to [0, 1] (NaN -> 0: bad directions read a valid texel).
    static cube_coord<T> face_coord(const vec3<T>& dir) noexcept {
        cube_coord<T> c = detail::cube_lookup_select(dir);
        c.s = clamp(c.s, T(0), T(1));
        c.t = clamp(c.t, T(0), T(1));
        return c;
    }
    int clamp_level(int level) const noexcept {
        return level < 0 ? 0 : (level >= levels() ? levels() - 1 : level);
    }

    /// Storage index of (face, x, y) with x, y in [-1, n] (border included).
    std::size_t index(int face, int x, int y, int level) const noexcept {
        IBL_ASSERT(level >= 0 && level < levels());
        const level_info& li = levels_[std::size_t(level)];
        IBL_ASSERT(face >= 0 && face < 6 && x >= -1 && x <= li.n && y >= -1 && y <= li.n);
        const std::size_t st = std::size_t(li.stride);
        return li.offset + std::size_t(face) * st * st + std::size_t(y + 1) * st + std::size_t(x + 1);
    }

    /// Bilinear on one level; s, t in [0, 1] (up to rounding), level valid. Texel centre x sits
    /// at bordered coordinate x + 1, so the bordered coordinate of s is s n + 0.5 in [0.5, n + 0.5].
    vec3<T> bilinear_unchecked(int face, T s, T t, int level) const noexcept {
        const level_info& li = levels_[std::size_t(level)];
        const T fx = s * T(li.n) + T(0.5);
        const T fy = t * T(li.n) + T(0.5);
        const int x0 = min_int(int(fx), li.n); // fx >= 0: truncation is floor
        const int y0 = min_int(int(fy), li.n);
        const T wx = fx - T(x0);
        const T wy = fy - T(y0);
        const std::size_t st = std::size_t(li.stride);
        const vec3<T>* p = data_.data() + li.offset + std::size_t(face) * st * st + std::size_t(y0) * st +
                           std::size_t(x0);
        const vec3<T> top = p[0] + wx * (p[1] - p[0]);
        const vec3<T> bot = p[st] + wx * (p[st + 1] - p[st]);
        return top + wy * (bot - top);
    }

    /// Face texel across the edge from border texel (x, y) of `face` (exactly one of x, y is
    /// outside [0, n)). The border texel centre is a point of the face plane just beyond the edge;
    /// folding the cube about the edge moves it onto the neighbour face at the same distance from
    /// the edge. Integer coordinates scaled by n keep this exact.
    static void fold_border(int face, int x, int y, int n, int& g, int& gx, int& gy) noexcept {
        const double a = double(2 * x + 1 - n), b = double(2 * y + 1 - n), dn = double(n);
        const vec3<double> ma = cube_face_point<double>(face, 0.0, 0.0);
        const vec3<double> sa = cube_face_point<double>(face, 1.0, 0.0) - ma;
        const vec3<double> ta = cube_face_point<double>(face, 0.0, 1.0) - ma;
        vec3<double> p = dn * ma + a * sa + b * ta; // components are integers, |overflow| = n + 1
        for (int k = 0; k < 3; ++k) {
            if (std::fabs(p[k]) > dn) {
                p[k] = std::copysign(dn, p[k]);
                for (int j = 0; j < 3; ++j)
                    if (ma[j] != 0.0) p[j] = ma[j] * (dn - 1.0);
                break;
            }
        }
        const cube_coord<double> c = cube_lookup(p);
        g = c.face;
        gx = min_int(int(c.s * dn), n - 1); // s n sits at a texel centre (integer + 0.5)
        gy = min_int(int(c.t * dn), n - 1);
    }

    /// The borders of one face of a level: its edges from the neighbours' interiors, then its corners.
    void build_face_borders(int level, int f) {
        const int n = size(level);
        for (int e = 0; e < 4; ++e) {
            const border_edge b = border_edge_source(f, e, n);
            for (int i = 0; i < n; ++i) {
                const int x = e == 0 ? -1 : e == 1 ? n : i, y = e == 2 ? -1 : e == 3 ? n : i;
                data_[index(f, x, y, level)] = data_[index(b.g, b.x0 + b.dx * i, b.y0 + b.dy * i, level)];
            }
        }
        const int cx[2] = {-1, n}, ix[2] = {0, n - 1};
        for (int u = 0; u < 2; ++u)
            for (int v = 0; v < 2; ++v) {
                const vec3<T> a = data_[index(f, ix[u], ix[v], level)];
                const vec3<T> b = data_[index(f, cx[u], ix[v], level)];
                const vec3<T> c = data_[index(f, ix[u], cx[v], level)];
                data_[index(f, cx[u], cx[v], level)] = a + ((b - a) + (c - a)) / T(3);
            }
    }

    /// Level `level` from level - 1: per coarse texel, sum over overlap pieces of
    /// w (fine - ref) in double with w the exact piece solid angle and ref the first fine texel,
    /// then ref + sum / sum(w). (The shift by ref makes a constant region exact.)
    template <class Executor> void downsample(int level, Executor& ex) {
        const int n = size(level - 1), m = size(level);
        const std::vector<detail::grid_piece> pieces = detail::grid_overlap(n, m);
        const auto ranges = detail::coarse_ranges(pieces, m);
        const std::size_t k_count = pieces.size();
        std::vector<double> bound(k_count + 1); // x (and y) boundaries in face coordinates [-1, 1]
        bound[0] = 2.0 * pieces[0].lo - 1.0;
        for (std::size_t k = 0; k < k_count; ++k) bound[k + 1] = 2.0 * pieces[k].hi - 1.0;

        ex(std::size_t(m), [&](std::size_t row_begin, std::size_t row_end) {
            std::vector<double> f_lo(k_count + 1), f_hi(k_count + 1);
            std::vector<vec3<double>> acc(static_cast<std::size_t>(6 * m)), ref(static_cast<std::size_t>(6 * m));
            std::vector<double> wsum(static_cast<std::size_t>(m));
            for (std::size_t cy = row_begin; cy < row_end; ++cy) {
                const auto [yb, ye] = ranges[cy];
                for (int f = 0; f < 6; ++f)
                    for (int cx = 0; cx < m; ++cx) {
                        const auto& first = pieces[std::size_t(ranges[std::size_t(cx)].first)];
                        ref[std::size_t(f * m + cx)] =
                            vec3<double>(data_[index(f, first.fine, pieces[std::size_t(yb)].fine, level - 1)]);
                        acc[std::size_t(f * m + cx)] = vec3<double>(0.0);
                    }
                std::fill(wsum.begin(), wsum.end(), 0.0);
                for (std::size_t k = 0; k <= k_count; ++k)
                    f_lo[k] = detail::cube_area_antiderivative(bound[k], bound[std::size_t(yb)]);
                for (int yk = yb; yk < ye; ++yk) {
                    const int fy = pieces[std::size_t(yk)].fine;
                    for (std::size_t k = 0; k <= k_count; ++k)
                        f_hi[k] = detail::cube_area_antiderivative(bound[k], bound[std::size_t(yk) + 1]);
                    for (std::size_t k = 0; k < k_count; ++k) {
                        const double w = (f_hi[k + 1] - f_hi[k]) - (f_lo[k + 1] - f_lo[k]);
                        const int cx = pieces[k].coarse, fx = pieces[k].fine;
                        wsum[std::size_t(cx)] += w;
                        for (int f = 0; f < 6; ++f) {
                            const std::size_t j = std::size_t(f * m + cx);
                            acc[j] += w * (vec3<double>(data_[index(f, fx, fy, level - 1)]) - ref[j]);
                        }
                    }
                    std::swap(f_lo, f_hi);
                }
                for (int f = 0; f < 6; ++f)
                    for (int cx = 0; cx < m; ++cx) {
                        const std::size_t j = std::size_t(f * m + cx);
                        data_[index(f, cx, int(cy), level)] = vec3<T>(ref[j] + acc[j] / wsum[std::size_t(cx)]);
                    }
            }
        });
    }

    std::vector<level_info> levels_;
    std::vector<vec3<T>, detail::default_init_allocator<vec3<T>>> data_;
    bool borders_dirty_ = false;
};

static_assert(environment<cubemap<float>, float>);
static_assert(environment<cubemap<double>, double>);

} // namespace ibl

#endif // IBL_DETAIL_CXX20
