#pragma once
// ibl/batch/sphere_kernel.hpp — the structure-of-arrays kernel of the cubemap spherical convolution
// (the fast path of bake/sphere_convolve.hpp, which the prefilter and the irradiance
// convolution use; host only). The integrator builds the tables; this header runs them over texels.
//
//   out[k] = factor * sum_i w_i B(src, level_i, F(dir_k) l_i)
// B: the bilinear lookup on one level of the packed source, F(dir) = make_frame(dir) the tangent
// frame of output direction k, l_i the tap directions (tangent space, z = dir), w_i > 0 the tap
// weights, factor = scale / norm (norm = tap_weight_sum in the kernel's order, or 1).
//
//  * packed_cube: the source copied once into a bordered float4 layout (RGB + a fourth channel of
//    1), levels one after the other; non-finite components are stored as 0.
//  * tap_table: bilinear taps on single levels (the integrator splits a sample with fractional lod
//    into taps on floor(lod) and floor(lod) + 1: the trilinear lookup), so the kernel reads exactly
//    one level per tap and the level's size, strides and offset are loop invariants.
//  * convolve_lanes<W>: W output texels of one face row. Per tap, lane loop 1 rotates the tap
//    direction into each texel's frame, selects the face branch-free (lane_cube_coord) and forms
//    the bilinear address and weights (vectorisable); lane loop 2 reads the 2 x 2 texels and
//    accumulates, the four channels of a texel as one 4-wide operation. Loop 1 of the next tap runs
//    before loop 2 of the current one (a one-tap software pipeline), so loop 2 never reads back
//    addresses stored just before it. Accumulation is in float
//    in blocks of tap_block taps whose sums are added to the totals (error ~ (tap_block + taps /
//    tap_block) eps instead of taps * eps). The fourth channel (1 in every texel; its blend is
//    exactly 1) sums the tap weights in that order: tap_weight_sum, bit for bit, and the
//    normaliser of a normalised table, so a source of ones returns exactly 1. (That channel is
//    what keeps the blend 4-wide: a padding channel whose sum went unused was dropped by the
//    compiler, which then split the three live channels into a 2-wide and a scalar part.)
//  * convolve_row: a face row in chunks of convolve_width (16) lanes, the tail in chunks of 8, 4
//    and 1.
//  * convolve_lanes_part / lane_sums: convolve_lanes over a range of its taps, the lanes'
//    accumulators kept in between (prefilter_update's units below a texel), the same operations in
//    the same order as one call.
// Determinism: every output texel is a fixed sequence of operations on the taps and the source.

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <cstddef>
#include <vector>

#include "../core/executor.hpp"
#include "../core/frame.hpp"
#include "../core/math.hpp"
#include "../core/memory.hpp"
#include "../core/vec.hpp"
#include "../env/cube_geometry.hpp"
#include "../env/cubemap.hpp"

namespace ibl {

namespace detail {

/// Taps per accumulation block of the fast path (see the header comment).
inline constexpr std::size_t tap_block = 32;

/// A cubemap copied into float4 texels (RGB + 1: the kernel's weight channel), every face with
/// its 1-texel border, levels one after the other. Non-finite components are stored as 0.
struct packed_cube {
    struct level {
        int n = 1;           ///< face size
        int stride = 3;      ///< n + 2
        int face_stride = 9; ///< (n + 2)^2 texels
        int offset = 0;      ///< texel index of (face 0, x = -1, y = -1)
        float nf = 1.f;      ///< float(n)
    };
    std::vector<level> levels;
    /// Levels below this one are left unpacked (no reader: the fast filter's taps of a 256^2
    /// source read its 64^2 mip and coarser); pack_cube_rows skips their items.
    int first = 0;
    /// 4 floats per texel: R, G, B, 1; packed_layout leaves it to pack_cube_rows, which writes
    /// every texel of every level, borders included (core/memory.hpp).
    std::vector<float, default_init_allocator<float>> data;
};

/// The layout of c's packed copy: its levels and storage (unwritten); pack_cube_rows fills it.
template <class T> packed_cube packed_layout(const cubemap<T>& c) {
    packed_cube p;
    std::size_t total = 0;
    for (int l = 0; l < c.levels(); ++l) {
        packed_cube::level li;
        li.n = c.size(l);
        li.stride = li.n + 2;
        li.face_stride = li.stride * li.stride;
        li.offset = int(total);
        li.nf = float(li.n);
        total += std::size_t(6) * std::size_t(li.face_stride);
        p.levels.push_back(li);
    }
    p.data.resize(4 * total);
    return p;
}
/// The work items of packing: the bordered rows (n + 2 per face) of every face of every level, in order.
inline std::size_t packed_rows(const packed_cube& p) noexcept {
    std::size_t rows = 0;
    for (const packed_cube::level& li : p.levels) rows += std::size_t(6 * li.stride);
    return rows;
}
/// The level of packing item `item` (item < packed_rows(p)).
inline std::size_t packed_row_level(const packed_cube& p, std::size_t item) noexcept {
    std::size_t l = 0;
    for (std::size_t first = 0; l + 1 < p.levels.size(); ++l) {
        const std::size_t rows = std::size_t(6 * p.levels[l].stride);
        if (item < first + rows) break;
        first += rows;
    }
    return l;
}
/// Copies packing items [b, e) of c into p (packed_layout(c)): non-finite components as 0, the
/// fourth channel 1; items of levels below p.first are skipped. The items are independent: any partition gives the same copy.
template <class T> void pack_cube_rows(packed_cube& p, const cubemap<T>& c, std::size_t b, std::size_t e) noexcept {
    std::size_t l = 0, first = 0;
    for (std::size_t item = b; item < e; ++item) {
        while (item >= first + std::size_t(6 * p.levels[l].stride)) first += std::size_t(6 * p.levels[l++].stride);
        if (int(l) < p.first) continue;
        const packed_cube::level& li = p.levels[l];
        const int f = int((item - first) / std::size_t(li.stride)), y = int((item - first) % std::size_t(li.stride)) - 1;
        float* q = p.data.data() + 4 * (std::size_t(li.offset) + std::size_t(f) * std::size_t(li.face_stride) +
                                        std::size_t(y + 1) * std::size_t(li.stride));
        // The bordered row is contiguous in the cubemap (x = -1 .. n); a plain loop over it vectorises.
        const vec3<T>* v = &c.texel(f, -1, y, int(l));
        for (int x = 0; x < li.stride; ++x, q += 4) {
            for (int k = 0; k < 3; ++k) q[k] = is_finite(v[x][k]) ? float(v[x][k]) : 0.f;
            q[3] = 1.f;
        }
    }
}

/// The packed copy of c; the face rows of every level are copied through the executor (a plain
/// copy: the result does not depend on it).
template <class T, class Executor = serial_executor> packed_cube pack_cube(const cubemap<T>& c, Executor&& ex = Executor{}) {
    IBL_ASSERT(c.borders_valid());
    packed_cube p = packed_layout(c);
    ex(packed_rows(p), [&](std::size_t b, std::size_t e) { pack_cube_rows(p, c, b, e); });
    return p;
}

/// The fast path's table: bilinear taps on single levels, in tap_block-sized blocks.
struct tap_table {
    std::vector<float> x, y, z, w;
    std::vector<int> level;
    float factor = 1.f;      ///< scale / norm, norm summed in the kernel's blocked order
    float scale = 1.f;       ///< the table's scale
    bool normalised = false; ///< norm = tap_weight_sum (else 1)
};

/// Sum of the tap weights in the kernel's order (block partial sums of tap_block taps added to the
/// total, as convolve_lanes accumulates its weight channel, which equals this bit for bit), so that
/// factor = scale / tap_weight_sum makes a source of ones return exactly scale.
inline float tap_weight_sum(const tap_table& t) noexcept {
    float total = 0.f;
    for (std::size_t b = 0; b < t.w.size(); b += tap_block) {
        float part = 0.f;
        const std::size_t e = b + tap_block < t.w.size() ? b + tap_block : t.w.size();
        for (std::size_t i = b; i < e; ++i) part += t.w[i];
        total += part;
    }
    return total;
}

/// W lanes of output directions (unit) with their tangent frames.
template <std::size_t W> struct lane_frames {
    float tx[W], ty[W], tz[W], bx[W], by[W], bz[W], nx[W], ny[W], nz[W];
};

/// Face selection and face texture coordinates of a (non-zero, finite) direction for the lane
/// loops: the table of env/cube_geometry.hpp with the tie rule X before Y before Z, as float
/// selects only (no bool-to-float conversions, no branches), so the loop around it vectorises.
/// Agrees with cube_lookup on face and (s, t) up to rounding (s = 0.5 sc / ma + 0.5).
IBL_FUNC_VOID void lane_cube_coord(float dx, float dy, float dz, int& face, float& s, float& t) noexcept {
    const float ax = dx < 0.f ? -dx : dx, ay = dy < 0.f ? -dy : dy, az = dz < 0.f ? -dz : dz;
    const bool xm = (ax >= ay) & (ax >= az);
    const bool ym = (!xm) & (ay >= az);
    const float ma = xm ? ax : (ym ? ay : az);
    const float major = xm ? dx : (ym ? dy : dz);
    const bool neg = major < 0.f;
    const float sg = neg ? -1.f : 1.f;
    const float sc = xm ? -sg * dz : (ym ? dx : sg * dx);
    const float tc = ym ? sg * dz : -dy;
    face = (xm ? 0 : (ym ? 2 : 4)) + (neg ? 1 : 0);
    const float half_inv = 0.5f / ma;
    const float s0 = sc * half_inv + 0.5f, t0 = tc * half_inv + 0.5f;
    s = s0 > 0.f ? (s0 < 1.f ? s0 : 1.f) : 0.f;
    t = t0 > 0.f ? (t0 < 1.f ? t0 : 1.f) : 0.f;
}

/// The addresses and bilinear weights of one tap for W lanes (lane loop 1's output).
template <std::size_t W> struct lane_taps {
    int idx[W];         ///< texel index of the 2 x 2 block's top-left texel
    float wx[W], wy[W]; ///< bilinear weights within the block
    int stride = 3;     ///< the tap level's row stride
    float w = 0.f;      ///< the tap's weight
};

/// Lane loop 1 for tap i: rotate the tap direction into each lane's frame, select the face
/// (branch-free) and address the 2 x 2 texels.
template <std::size_t W>
inline void lane_tap_address(const packed_cube& src, const tap_table& taps, const lane_frames<W>& fr, std::size_t i,
                             lane_taps<W>& o) noexcept {
    const float lx = taps.x[i], ly = taps.y[i], lz = taps.z[i];
    const packed_cube::level& lv = src.levels[std::size_t(taps.level[i])];
    const float nf = lv.nf;
    const int n = lv.n, st = lv.stride, fs = lv.face_stride, off = lv.offset;
    o.stride = st;
    o.w = taps.w[i];
    for (std::size_t k = 0; k < W; ++k) {
        const float dx = fr.tx[k] * lx + fr.bx[k] * ly + fr.nx[k] * lz;
        const float dy = fr.ty[k] * lx + fr.by[k] * ly + fr.ny[k] * lz;
        const float dz = fr.tz[k] * lx + fr.bz[k] * ly + fr.nz[k] * lz;
        int face;
        float s, t;
        lane_cube_coord(dx, dy, dz, face, s, t);
        const float fx = s * nf + 0.5f; // bordered coordinate, in [0.5, n + 0.5]
        const float fy = t * nf + 0.5f;
        const int ix = int(fx), iy = int(fy);
        const int x0 = ix < n ? ix : n, y0 = iy < n ? iy : n;
        o.wx[k] = fx - float(x0);
        o.wy[k] = fy - float(y0);
        o.idx[k] = off + face * fs + y0 * st + x0;
    }
}

/// The accumulators of W lanes part-way through a tap table: convolve_lanes split over several
/// calls of convolve_lanes_part (prefilter_update's units below a texel), the same operations in
/// the same order as one call.
template <std::size_t W> struct lane_sums {
    float tot[W][4] = {};
    float blk[W][4] = {};
    std::size_t next = 0; ///< the next tap
};

/// Taps [st.next, end) of convolve_lanes (end <= the table's size), continuing from st.
template <std::size_t W>
void convolve_lanes_part(const packed_cube& src, const tap_table& taps, const lane_frames<W>& fr, lane_sums<W>& st,
                         std::size_t end) noexcept {
    const float* data = src.data.data();
    const std::size_t count = taps.w.size();
    std::size_t i = st.next;
    // Local accumulators (the state's may alias the source's floats for the compiler).
    float tot[W][4], blk[W][4];
    for (std::size_t k = 0; k < W; ++k)
        for (int c = 0; c < 4; ++c) tot[k][c] = st.tot[k][c], blk[k][c] = st.blk[k][c];
    lane_taps<W> lt[2];
    if (i < end) lane_tap_address(src, taps, fr, i, lt[i & 1]);
    while (i < end) {
        const std::size_t b = i - i % tap_block; // the block of tap i
        const std::size_t e = b + tap_block < count ? b + tap_block : count;
        const std::size_t stop = e < end ? e : end;
        if (i == b)
            for (std::size_t k = 0; k < W; ++k)
                for (int c = 0; c < 4; ++c) blk[k][c] = 0.f;
        for (; i < stop; ++i) {
            const lane_taps<W>& cur = lt[i & 1];
            if (i + 1 < end) lane_tap_address(src, taps, fr, i + 1, lt[(i + 1) & 1]);
            // Lane loop 2: bilinear blend (a + w (b - a), exact on equal texels) and accumulate,
            // four channels at a time (RGB + the weight channel).
            const std::size_t rs = std::size_t(cur.stride);
            const float w = cur.w;
            for (std::size_t k = 0; k < W; ++k) {
                const float* p = data + 4 * std::size_t(cur.idx[k]);
                const float* q = p + 4 * rs;
                const float a = cur.wx[k], bw = cur.wy[k];
                for (int c = 0; c < 4; ++c) {
                    const float top = p[c] + a * (p[4 + c] - p[c]);
                    const float bot = q[c] + a * (q[4 + c] - q[c]);
                    blk[k][c] += w * (top + bw * (bot - top));
                }
            }
        }
        if (i == e)
            for (std::size_t k = 0; k < W; ++k)
                for (int c = 0; c < 4; ++c) tot[k][c] += blk[k][c];
    }
    for (std::size_t k = 0; k < W; ++k)
        for (int c = 0; c < 4; ++c) st.tot[k][c] = tot[k][c], st.blk[k][c] = blk[k][c];
    st.next = i;
}

/// The W outputs once every tap is in st (st.next == the table's size).
template <std::size_t W> void convolve_lanes_result(const tap_table& taps, const lane_sums<W>& st, vec3<float>* out) noexcept {
    for (std::size_t k = 0; k < W; ++k) {
        // tot[k][3] == tap_weight_sum(taps); reading it keeps the fourth channel (see the header).
        const float f = taps.normalised ? (st.tot[k][3] > 0.f ? taps.scale / st.tot[k][3] : 0.f) : taps.factor;
        out[k] = vec3<float>(st.tot[k][0] * f, st.tot[k][1] * f, st.tot[k][2] * f);
    }
}

/// Convolves W output directions (one chunk of a face row): out[k] = factor * sum w L, factor
/// computed per lane from its weight channel for a normalised table (the same float division as
/// make_taps', on the same sum: the same bits as taps.factor). Software-pipelined by one tap: lane
/// loop 1 of tap i + 1 runs before lane loop 2 of tap i, so the addresses that loop 2 reads back
/// were stored a whole tap earlier (read straight after their vector stores they stall the
/// pipeline at every tap: docs/ARCHITECTURE.md, "The batch kernel"). The arithmetic per texel
/// is unchanged by the order.
template <std::size_t W>
void convolve_lanes(const packed_cube& src, const tap_table& taps, const lane_frames<W>& fr, vec3<float>* out) noexcept {
    lane_sums<W> st;
    convolve_lanes_part(src, taps, fr, st, taps.w.size());
    convolve_lanes_result(taps, st, out);
}

/// Lane width of the fast path: a face row is processed in chunks of W, its tail in chunks of 8,
/// 4 and 1 (every width computes a texel by the same operations; docs/ARCHITECTURE.md, "The batch kernel").
inline constexpr std::size_t convolve_width = 16;

/// Lane k of fr: the tangent frame of texel (x, y) of face `face` of an n x n level.
template <std::size_t W>
inline void load_lane_frame(lane_frames<W>& fr, std::size_t k, int face, int x, int y, int n) noexcept {
    const frame<float> f = make_frame(cube_texel_direction<float>(face, x, y, n));
    fr.tx[k] = f.t.x, fr.ty[k] = f.t.y, fr.tz[k] = f.t.z;
    fr.bx[k] = f.b.x, fr.by[k] = f.b.y, fr.bz[k] = f.b.z;
    fr.nx[k] = f.n.x, fr.ny[k] = f.n.y, fr.nz[k] = f.n.z;
}

/// The frames of W consecutive texels x0 .. x0 + W - 1 of row y of a face (x0 + W <= n): the
/// values of load_lane_frame, computed with the face chosen once so that the lane loop vectorises
/// (a per-texel frame costs about as much as a tap: at the fast filter's 8 samples a texel, the
/// per-lane form was a fifth of the kernel's time).
template <std::size_t W> inline void load_row_frames(lane_frames<W>& fr, int face, int x0, int y, int n) noexcept {
    const float inv = 1.f / float(n);
    const float tc = 2.f * ((float(y) + 0.5f) * inv) - 1.f;
    with_cube_face_point<float>(face, [&](auto point) {
        for (std::size_t k = 0; k < W; ++k) {
            const float sc = 2.f * ((float(x0 + int(k)) + 0.5f) * inv) - 1.f;
            const frame<float> f = make_frame(glm::normalize(point(sc, tc)));
            fr.tx[k] = f.t.x, fr.ty[k] = f.t.y, fr.tz[k] = f.t.z;
            fr.bx[k] = f.b.x, fr.by[k] = f.b.y, fr.bz[k] = f.b.z;
            fr.nx[k] = f.n.x, fr.ny[k] = f.n.y, fr.nz[k] = f.n.z;
        }
    });
}

/// Chunks of W lanes of texels [x, x1) of row y while they fit (out: the row's start); returns the
/// first texel not done.
template <std::size_t W>
inline int convolve_chunks(const packed_cube& src, const tap_table& taps, int face, int x, int x1, int y, int n,
                           vec3<float>* out) {
    for (; x + int(W) <= x1; x += int(W)) {
        lane_frames<W> fr;
        load_row_frames<W>(fr, face, x, y, n);
        convolve_lanes<W>(src, taps, fr, out + x);
    }
    return x;
}

/// Convolves row y of face `face` of an n x n output level into out[0..n): chunks of
/// convolve_width lanes, then 8, 4 and 1 (prefilter_update keeps the same chunks).
inline void convolve_row(const packed_cube& src, const tap_table& taps, int face, int y, int n, vec3<float>* out) {
    int x = convolve_chunks<convolve_width>(src, taps, face, 0, n, y, n, out);
    x = convolve_chunks<8>(src, taps, face, x, n, y, n, out);
    x = convolve_chunks<4>(src, taps, face, x, n, y, n, out);
    convolve_chunks<1>(src, taps, face, x, n, y, n, out);
}

} // namespace detail

} // namespace ibl

#endif // IBL_DETAIL_CXX20
