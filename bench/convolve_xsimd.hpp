#pragma once
// bench/convolve_xsimd.hpp — BENCH ONLY: the face-row kernel of the cubemap spherical convolution
// (ibl::detail::convolve_row, include/ibl/batch/sphere_kernel.hpp) written with explicit xsimd
// batches, so that bench_prefilter can measure whether hand-written SIMD beats the library's
// auto-vectorised lanes. The shipping headers never include xsimd; this file is the measured
// alternative and nothing else.
//
// Same work per output texel as convolve_lanes: per tap, rotate the tap direction into the
// texel's tangent frame, select the cube face (tie rule X before Y before Z) and the clamped face
// coordinates, address the 2 x 2 bordered texels of the tap's level, blend bilinearly
// (a + w (b - a)) and accumulate w * value in float in blocks of tap_block taps whose sums are added
// to the totals; the result is scaled by taps.factor. The lanes are B = batch<float, Arch>::size
// texels of the row; a row tail shorter than B runs the library's width-1 form.
//
// Two ways to read the texels, both with the same lane stage:
//  * gather: full structure of arrays; every corner's R, G and B is a gather of B lanes
//    (12 gathers per tap), and the accumulators are per-channel batches.
//  * rows:   the lane stage writes each lane's texel index and weights, then every lane blends its
//    four float4 texels as 4-wide batches (RGB + padding), as the library's second lane loop does
//    (4-wide batches: SSE2 on x86, NEON on ARM; IBL_BENCH_XSIMD_ROWS says the variant exists).
#include <ibl/batch/sphere_kernel.hpp>

// GCC 12's AVX-512 intrinsics start from a self-initialised "undefined" vector
// (_mm512_undefined_*: `__m512i __Y = __Y;`), which -Wmaybe-uninitialized reports wherever such an
// intrinsic is inlined (GCC bug 105593). The false positive is silenced for the
// intrinsic headers and this file only; the warning stays on for everything else.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#include <xsimd/xsimd.hpp>

#include <cstddef>
#include <cstdint>

namespace ibl_bench {

#if XSIMD_WITH_SSE2
#define IBL_BENCH_XSIMD_ROWS 1
using xsimd_float4_arch = xsimd::sse2;
#elif XSIMD_WITH_NEON64
#define IBL_BENCH_XSIMD_ROWS 1
using xsimd_float4_arch = xsimd::neon64;
#elif XSIMD_WITH_NEON
#define IBL_BENCH_XSIMD_ROWS 1
using xsimd_float4_arch = xsimd::neon;
#endif

/// The lane stage of one tap for B texels: the packed-source texel index of the (x0, y0) corner
/// (bordered coordinates) and the bilinear weights. Mirrors lane_cube_coord and convolve_lanes' first lane loop.
template <class Arch> struct xsimd_tap_address {
    using fb = xsimd::batch<float, Arch>;
    using ib = xsimd::batch<std::int32_t, Arch>;
    ib idx;
    fb wx, wy;
};

template <class Arch>
inline xsimd_tap_address<Arch> xsimd_address(const ibl::detail::packed_cube::level& lv, float lx, float ly, float lz,
                                             const xsimd::batch<float, Arch> (&f)[9]) noexcept {
    using fb = xsimd::batch<float, Arch>;
    using ib = xsimd::batch<std::int32_t, Arch>;
    // f: tx, ty, tz, bx, by, bz, nx, ny, nz.
    const fb dx = f[0] * lx + f[3] * ly + f[6] * lz;
    const fb dy = f[1] * lx + f[4] * ly + f[7] * lz;
    const fb dz = f[2] * lx + f[5] * ly + f[8] * lz;
    const fb ax = xsimd::abs(dx), ay = xsimd::abs(dy), az = xsimd::abs(dz);
    const auto xm = (ax >= ay) & (ax >= az);
    const auto ym = (~xm) & (ay >= az);
    const fb ma = xsimd::select(xm, ax, xsimd::select(ym, ay, az));
    const fb major = xsimd::select(xm, dx, xsimd::select(ym, dy, dz));
    const auto neg = major < fb(0.f);
    const fb sg = xsimd::select(neg, fb(-1.f), fb(1.f));
    const fb sc = xsimd::select(xm, -sg * dz, xsimd::select(ym, dx, sg * dx));
    const fb tc = xsimd::select(ym, sg * dz, -dy);
    const fb facef = xsimd::select(xm, fb(0.f), xsimd::select(ym, fb(2.f), fb(4.f))) + xsimd::select(neg, fb(1.f), fb(0.f));
    const fb half_inv = fb(0.5f) / ma;
    const fb s = xsimd::min(xsimd::max(sc * half_inv + 0.5f, fb(0.f)), fb(1.f));
    const fb t = xsimd::min(xsimd::max(tc * half_inv + 0.5f, fb(0.f)), fb(1.f));
    const fb fx = s * lv.nf + 0.5f, fy = t * lv.nf + 0.5f; // bordered coordinates in [0.5, n + 0.5]
    const ib x0 = xsimd::min(xsimd::to_int(fx), ib(lv.n)), y0 = xsimd::min(xsimd::to_int(fy), ib(lv.n));
    xsimd_tap_address<Arch> a;
    a.wx = fx - xsimd::to_float(x0);
    a.wy = fy - xsimd::to_float(y0);
    a.idx = ib(lv.offset) + xsimd::to_int(facef) * lv.face_stride + y0 * lv.stride + x0;
    return a;
}

/// A gather of B floats. xsimd 8.1's batch<float, A>::gather calls its kernel with explicit
/// template arguments that the AVX2 and AVX-512 overloads do not take, so it always falls back to
/// the generic element-by-element form (an extract, a scalar load and an insert per lane); where
/// the instruction set has a gather, its kernel overload is called directly (found by deduction).
template <class Arch>
inline xsimd::batch<float, Arch> xsimd_gather(const float* src, const xsimd::batch<std::int32_t, Arch>& index) noexcept {
    if constexpr (requires { xsimd::kernel::gather(src, index, Arch{}); }) return xsimd::kernel::gather(src, index, Arch{});
    else return xsimd::batch<float, Arch>::gather(src, index);
}

/// How the xsimd kernel reads the texels (see the header comment).
enum class xsimd_read { gather, rows };

/// B = batch<float, Arch>::size texels of a face row starting at x: out[0..B).
template <class Arch, xsimd_read Read>
void xsimd_convolve_lanes(const ibl::detail::packed_cube& src, const ibl::detail::tap_table& taps, int face, int x, int y, int n,
                          ibl::vec3<float>* out) noexcept {
    using fb = xsimd::batch<float, Arch>;
    using ib = xsimd::batch<std::int32_t, Arch>;
    constexpr std::size_t B = fb::size;
    static_assert(ib::size == B);
    ibl::detail::lane_frames<B> fr;
    for (std::size_t k = 0; k < B; ++k) ibl::detail::load_lane_frame(fr, k, face, x + int(k), y, n);
    const fb f[9] = {fb::load_unaligned(fr.tx), fb::load_unaligned(fr.ty), fb::load_unaligned(fr.tz),
                     fb::load_unaligned(fr.bx), fb::load_unaligned(fr.by), fb::load_unaligned(fr.bz),
                     fb::load_unaligned(fr.nx), fb::load_unaligned(fr.ny), fb::load_unaligned(fr.nz)};
    const float* data = src.data.data();
    const std::size_t count = taps.w.size();
    constexpr std::size_t tap_block = ibl::detail::tap_block;
    if constexpr (Read == xsimd_read::gather) {
        fb tot[3] = {fb(0.f), fb(0.f), fb(0.f)};
        for (std::size_t b = 0; b < count; b += tap_block) {
            fb blk[3] = {fb(0.f), fb(0.f), fb(0.f)};
            const std::size_t e = b + tap_block < count ? b + tap_block : count;
            for (std::size_t i = b; i < e; ++i) {
                const ibl::detail::packed_cube::level& lv = src.levels[std::size_t(taps.level[i])];
                const xsimd_tap_address<Arch> a = xsimd_address<Arch>(lv, taps.x[i], taps.y[i], taps.z[i], f);
                const ib p = a.idx * 4, q = p + 4 * lv.stride; // float offsets of the top and bottom rows
                const fb w(taps.w[i]);
                for (int c = 0; c < 3; ++c) {
                    const fb p0 = xsimd_gather<Arch>(data + c, p), p1 = xsimd_gather<Arch>(data + 4 + c, p);
                    const fb q0 = xsimd_gather<Arch>(data + c, q), q1 = xsimd_gather<Arch>(data + 4 + c, q);
                    const fb top = p0 + a.wx * (p1 - p0);
                    const fb bot = q0 + a.wx * (q1 - q0);
                    blk[c] += w * (top + a.wy * (bot - top));
                }
            }
            for (int c = 0; c < 3; ++c) tot[c] += blk[c];
        }
        alignas(64) float r[3][B];
        for (int c = 0; c < 3; ++c) (tot[c] * taps.factor).store_aligned(r[c]);
        for (std::size_t k = 0; k < B; ++k) out[k] = ibl::vec3<float>(r[0][k], r[1][k], r[2][k]);
    } else {
#if defined(IBL_BENCH_XSIMD_ROWS)
        using f4 = xsimd::batch<float, xsimd_float4_arch>; // one float4 texel (RGB + padding)
        static_assert(f4::size == 4);
        f4 tot[B], blk[B];
        for (std::size_t k = 0; k < B; ++k) tot[k] = f4(0.f);
        alignas(64) std::int32_t idx[B];
        alignas(64) float wx[B], wy[B];
        for (std::size_t b = 0; b < count; b += tap_block) {
            for (std::size_t k = 0; k < B; ++k) blk[k] = f4(0.f);
            const std::size_t e = b + tap_block < count ? b + tap_block : count;
            for (std::size_t i = b; i < e; ++i) {
                const ibl::detail::packed_cube::level& lv = src.levels[std::size_t(taps.level[i])];
                const xsimd_tap_address<Arch> a = xsimd_address<Arch>(lv, taps.x[i], taps.y[i], taps.z[i], f);
                a.idx.store_aligned(idx);
                a.wx.store_aligned(wx);
                a.wy.store_aligned(wy);
                const f4 w(taps.w[i]);
                const std::size_t row = 4 * std::size_t(lv.stride);
                for (std::size_t k = 0; k < B; ++k) {
                    const float* pp = data + 4 * std::size_t(idx[k]);
                    const f4 p0 = f4::load_unaligned(pp), p1 = f4::load_unaligned(pp + 4);
                    const f4 q0 = f4::load_unaligned(pp + row), q1 = f4::load_unaligned(pp + row + 4);
                    const f4 ak(wx[k]), bk(wy[k]);
                    const f4 top = p0 + ak * (p1 - p0);
                    const f4 bot = q0 + ak * (q1 - q0);
                    blk[k] += w * (top + bk * (bot - top));
                }
            }
            for (std::size_t k = 0; k < B; ++k) tot[k] += blk[k];
        }
        for (std::size_t k = 0; k < B; ++k) {
            alignas(16) float r[4];
            (tot[k] * taps.factor).store_aligned(r);
            out[k] = ibl::vec3<float>(r[0], r[1], r[2]);
        }
#else
        static_assert(Read != xsimd_read::rows, "the rows variant needs 4-wide float batches");
#endif
    }
}

/// Row y of face `face` of an n x n output level into out[0..n), in chunks of B lanes, the tail
/// (n mod B texels) with the library's width-1 form.
template <class Arch, xsimd_read Read>
void xsimd_convolve_row(const ibl::detail::packed_cube& src, const ibl::detail::tap_table& taps, int face, int y, int n,
                        ibl::vec3<float>* out) noexcept {
    constexpr int B = int(xsimd::batch<float, Arch>::size);
    int x = 0;
    for (; x + B <= n; x += B) xsimd_convolve_lanes<Arch, Read>(src, taps, face, x, y, n, out + x);
    for (; x < n; ++x) {
        ibl::detail::lane_frames<1> fr;
        ibl::detail::load_lane_frame(fr, 0, face, x, y, n);
        ibl::detail::convolve_lanes<1>(src, taps, fr, out + x);
    }
}

} // namespace ibl_bench

#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif
