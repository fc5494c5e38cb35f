#pragma once
// ibl/bake/prefilter_peaks.hpp — the fast filter's peak split: the brightest texels of a cubemap
// source are taken out of what the tap set reads and added back exactly, texel by texel, through
// the closed-form GGX LD kernel (host only). prefilter() runs it with prefilter_method::fast and
// prefilter_options::peaks.enabled (the default) on a cubemap source and the GGX lobe.
//
// Why. A tap set of N samples per texel reads the source at the lods of its samples' shares of
// the sphere; a light much smaller than those footprints and much brighter than its surround (a
// sun 10^4 times the sky, a studio's lamps) is then smeared over the footprints or missed between
// samples, and the filtered level shows it as blotches. The error grows with the light's contrast,
// not with the smoothness of the rest: without its sun the built-in sky filters to 1-4 % relative
// RMSE with 16 samples, with it to 13-190 % at 4-64 samples (docs/ibl-bake.md, "Fast filter").
// The split removes that dependence:
//
//     S = B + P,   LD[S] = LD[B] + LD[P],
//
// with B the source whose texels above a luminance threshold T are scaled down to luminance T
// (the colour kept) and P the remainder, non-zero on at most max_peaks level-0 texels. B has a
// bounded contrast (its largest luminance is T) and goes through the tap set; P is integrated
// exactly: LD of a texel of energy E_j = Omega_j P_j (Omega_j its exact solid angle) at direction
// d_j is E_j K(R.d_j) / integral K, with the LD kernel of the chain's weight (bake/prefilter.hpp)
// in closed form. With N = V = R, c = R.l and q = ((1 - c) + alpha^2 (1 + c)) / 2:
//
//     K(c) = D(h) / 4 w(c) = alpha^2 w(c) / (4 pi q^2),    w = c (n.l) or G1(c) (ld_weight::g1),
//
// for c > 0 (0 beyond the hemisphere), and integral K over the hemisphere is the fast filter's
// radial quadrature total (bake/prefilter_fast.hpp). The kernel is evaluated at the texel's
// centre direction; for that to be the texel's integral within a percent, the peaks of output
// level l are merged into the texels of the source mip m_l whose angular size is at most the
// kernel's full width at half maximum over `footprint` and at most max_merge_angle (GGX: FWHM
// 2.57 alpha, so level 1 at r = 0.2 merges 2 x 2 texels of a 256^2 source): a merged peak
// carries the summed energy at the luminance-energy centroid of its texels. The threshold is
//
//     T = max(ratio * mean luminance, luminance of the (max_peaks + 1)-th brightest texel),
//
// so a source with nothing above ratio times its mean has no peaks and filters exactly as without
// the split, and the cost of the exact part is bounded: at most max_peaks kernel evaluations per
// output texel, and fewer after the merge: a level with more than max_level_peaks (128) merged
// peaks merges them a mip coarser while it has more, max_level_steps (2) times at most (merged
// texels up to 4x the footprint rule's, at most max_merge_angle); peaks behind a row's hemisphere,
// and the faintest within the row cut, are
// skipped per row. Each evaluation is about ten float operations, vectorised over a face row.
// Many peaks mean an extended bright region, each of its texels faint next to the whole (the
// courtyard's 1024 brightest texels carry 0.4 % of its energy); there the coarser merge changes no
// level's error measurably, while lowering max_peaks would leave a studio's lamps in the tap set
// (research/peak_budget_study, docs/ibl-bake.md).
//
// Determinism: the peak lists depend only on the source and the options; each output texel adds
// its peaks in list order after the tap sum, the same operations in prefilter and
// prefilter_update.

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include "../batch/sphere_kernel.hpp"
#include "../brdf/ggx.hpp"
#include "../core/color.hpp"
#include "../core/constants.hpp"
#include "../core/executor.hpp"
#include "../core/math.hpp"
#include "../core/memory.hpp"
#include "../core/vec.hpp"
#include "../env/cube_geometry.hpp"
#include "../env/cubemap.hpp"
#include "../runtime/ld_weight.hpp"
#include "../sampling/lobe.hpp"
#include "prefilter_fast.hpp"

namespace ibl {

/// The peak split of the fast filter (header comment). Used by prefilter_method::fast on cubemap
/// sources with the GGX lobe; ignored otherwise.
struct peak_split_options {
    bool enabled = true;
    /// Luminance threshold as a multiple of the source's mean luminance (solid-angle weighted).
    double ratio = 16.0;
    /// At most this many level-0 texels are peaks (the threshold rises to keep it).
    std::uint32_t max_peaks = 1024;
    /// A merged peak's texel is at most the kernel's full width at half maximum / footprint, and
    /// at most max_merge_angle radians (the rough levels' kernels are wide but not smooth at the
    /// horizon, where n.l cuts them off).
    double footprint = 6.0;
    double max_merge_angle = 1.0 / 16.0;
    /// Per face row, the faintest peaks whose summed largest contributions stay below cut times the
    /// row's darkest tap-set result (at least 1e-2 of the mean luminance) are skipped; 0 keeps every
    /// peak that is in front of some texel of the row (the GPU filter's sum).
    double cut = 1e-3;
    /// A level with more merged peaks than this (0: no limit) merges them a mip coarser, again
    /// while there are still more, at most max_level_steps mips (its merged texels up to 2^steps
    /// times the footprint rule's, at most max_merge_angle): many peaks are an extended bright
    /// region, each of its texels faint next to the whole. Two steps rather than one: a 128^2
    /// chain's level 1 on the courtyard evaluates 94 merged peaks a texel instead of 307, with
    /// the same error (docs/ibl-bake.md, "Fast filter").
    std::uint32_t max_level_peaks = 128;
    std::uint32_t max_level_steps = 2;
};

/// One peak: its direction (unit) and its energy (Omega times the radiance above the threshold).
struct cube_peak {
    vec3<float> dir{0.f, 0.f, 1.f};
    vec3<double> energy{0.0};
    double weight = 0.0; ///< the luminance energy behind dir (the merge's centroid weight)
    float luminance = 0.f; ///< the level-0 texel's luminance (split peaks; the base keeps threshold / luminance of it)
    int face = 0, x = 0, y = 0;
};

/// The split of a source (header comment): the base the tap set reads and the level-0 peaks.
template <class T> struct cube_peak_split {
    cubemap<T> base{1};
    std::vector<cube_peak> peaks; ///< level-0 texels, ordered by face, row, column
    double mean_luminance = 0.0, threshold = 0.0;
    [[nodiscard]] bool empty() const noexcept { return peaks.empty(); }
};

/// Splits a cubemap source (with its mip chain) at T = max(ratio mean, the (max_peaks + 1)-th
/// brightest luminance). With no texel above T the base is left empty (base.size() == 1 and no
/// peaks): the caller reads the source itself. Non-finite texels count as 0.
///
/// Cost: one pass over level 0 (luminance), a selection only when more than max_peaks texels are
/// above ratio times the mean, a copy of the source, and the mips patched where peaks were taken
/// out: a level whose face is half its finer level's (the box filter nests) loses, per texel,
/// the peaks' energy over its exact solid angle; any other chain is rebuilt (generate_mips).
namespace detail {
/// True when every level's face is half its finer level's (the box-filter mips nest).
template <class T> bool peak_mips_nest(const cubemap<T>& src) noexcept {
    for (int l = 1; l < src.levels(); ++l)
        if (src.size(l - 1) != 2 * src.size(l)) return false;
    return true;
}

/// double(l) > t for a float l (>= 0, finite) is l >= least_float_above(t), so the scans compare
/// floats (they vectorise).
inline float least_float_above(double v) noexcept {
    if (!(v < double(std::numeric_limits<float>::max()))) return std::numeric_limits<float>::infinity();
    float f = float(v);
    while (!(double(f) > v)) f = std::nextafter(f, std::numeric_limits<float>::infinity());
    return f;
}
/// A level-0 texel's luminance as the split reads it (non-finite or negative: 0).
template <class T> float peak_texel_luminance(const cubemap<T>& src, int f, int x, int y) noexcept {
    const float l = float(luminance(src.texel(f, x, y, 0)));
    return std::isfinite(l) && l > 0.f ? l : 0.f;
}

/// The split's scan of level 0 in units of one face row (prefilter_update spreads it over its
/// calls; find_cube_peaks runs the rows through its executor): peak_scan_start finds the mean
/// and the ratio's threshold from a 1 x 1 coarsest level (false, nothing started, without one),
/// peak_scan_row(r) keeps row r's texels above it, and peak_scan_finish selects the threshold
/// and builds the peaks (peaks_from_hits: select_peak_threshold, then make_cube_peak of each).
/// The same peaks as one find_cube_peaks.
struct peak_scan {
    int n = 0;
    double mean = 0.0, t = 0.0;
    float above_t = 0.f;
    std::vector<std::vector<std::pair<std::size_t, float>>> rows; ///< per face row: (cube_texel_index, luminance)
    std::size_t hits = 0;                                         ///< texels kept so far
};
/// The scan of an n-texel level 0 whose luminance has this mean: the ratio's threshold, no rows
/// scanned yet.
inline void peak_scan_reset(const peak_split_options& opt, int n, double mean, peak_scan& sc) {
    sc.n = n;
    sc.mean = mean;
    sc.t = std::isfinite(opt.ratio) && opt.ratio > 0.0 ? opt.ratio * mean : 0.0;
    sc.above_t = least_float_above(sc.t);
    sc.rows.resize(std::size_t(6 * n));
    for (auto& r : sc.rows) r.clear();
    sc.hits = 0;
}
/// Without a 1 x 1 level the mean comes from level 0 by texel solid angles (omega: the face's
/// cube_face_solid_angles), summed texel by texel in texel order: peak_mean_row(r) adds face row r
/// (face n + y) to acc, rows in order, then peak_scan_reset(opt, n, acc / 4 pi, sc).
template <class T>
void peak_mean_row(const cubemap<T>& src, const std::vector<double>& omega, std::size_t r, double& acc) noexcept {
    const int n = src.size(0), f = int(r) / n, y = int(r) % n;
    const double* w = omega.data() + std::size_t(y) * std::size_t(n);
    for (int x = 0; x < n; ++x) acc += double(peak_texel_luminance(src, f, x, y)) * w[x];
}
template <class T> bool peak_scan_start(const cubemap<T>& src, const peak_split_options& opt, peak_scan& sc) {
    const int top = src.levels() - 1;
    if (src.size(top) != 1) return false;
    // The mean: the coarsest level's texels are exact solid-angle means (cubemap::generate_mips),
    // so a chain down to 1 x 1 gives it in six reads.
    double acc = 0.0;
    for (int f = 0; f < 6; ++f) {
        const double l = double(luminance(src.texel(f, 0, 0, top)));
        acc += std::isfinite(l) && l > 0.0 ? l : 0.0;
    }
    peak_scan_reset(opt, src.size(0), acc / 6.0, sc);
    return true;
}
/// Row r (face n + y) of the scan (rows without a texel above skipped at once: the count
/// vectorises); `row` is scratch of n floats. Rows are independent (any order, any thread; hits
/// is then the caller's to add up).
template <class T> std::size_t peak_scan_row(const cubemap<T>& src, peak_scan& sc, std::size_t r, float* row) noexcept {
    const int n = sc.n, f = int(r) / n, y = int(r) % n;
    for (int x = 0; x < n; ++x) row[x] = peak_texel_luminance(src, f, x, y);
    int in_row = 0;
    for (int x = 0; x < n; ++x) in_row += row[x] >= sc.above_t ? 1 : 0;
    std::vector<std::pair<std::size_t, float>>& out = sc.rows[r];
    out.clear();
    if (in_row == 0) return 0;
    out.reserve(std::size_t(in_row));
    for (int x = 0; x < n; ++x)
        if (row[x] >= sc.above_t) out.emplace_back(cube_texel_index(f, x, y, n), row[x]);
    return out.size();
}
/// The threshold that keeps at most max_peaks of the texels above t (in cube_texel_index order),
/// those others taken out of hits.
inline double select_peak_threshold(const peak_split_options& opt, std::vector<std::pair<std::size_t, float>>& hits, double t) {
    if (hits.size() <= opt.max_peaks) return t;
    // The (max_peaks + 1)-th brightest texel is among these texels above t: the selection runs
    // over those only (a few thousand, not the whole level), and the texels above the new
    // threshold are among them, in the same order.
    std::vector<float> sorted(hits.size());
    for (std::size_t i = 0; i < hits.size(); ++i) sorted[i] = hits[i].second;
    const std::size_t k = hits.size() - 1 - std::size_t(opt.max_peaks);
    std::nth_element(sorted.begin(), sorted.begin() + std::ptrdiff_t(k), sorted.end());
    t = std::max(t, double(sorted[k]));
    const float above_t = least_float_above(t);
    std::erase_if(hits, [&](const std::pair<std::size_t, float>& h) { return !(h.second >= above_t); });
    return t;
}
/// The peak of a texel above the threshold t (hit: its cube_texel_index and luminance).
template <class T> cube_peak make_cube_peak(const cubemap<T>& src, const std::pair<std::size_t, float>& hit, double t) noexcept {
    const int n = src.size(0);
    const std::size_t nn = std::size_t(n) * std::size_t(n), i = hit.first;
    const int f = int(i / nn), y = int((i % nn) / std::size_t(n)), x = int(i % std::size_t(n));
    const float l = hit.second;
    const vec3<double> v(src.texel(f, x, y, 0));
    const double om = cube_texel_solid_angle<double>(x, y, n);
    cube_peak p;
    p.dir = normalize(cube_texel_direction<float>(f, x, y, n));
    p.energy = v * ((1.0 - t / double(l)) * om);
    p.weight = (double(l) - t) * om;
    p.luminance = l;
    p.face = f, p.x = x, p.y = y;
    return p;
}
/// The peaks from the texels above t (in cube_texel_index order): the threshold raised to keep
/// at most max_peaks of them, then each peak (the exact solid angle's four atan2 make this the
/// split's dearest serial part otherwise: through the executor).
template <class T, class Executor>
cube_peak_split<T> peaks_from_hits(const cubemap<T>& src, const peak_split_options& opt, std::vector<std::pair<std::size_t, float>>& hits,
                                   double t, double mean, Executor& ex) {
    cube_peak_split<T> s;
    s.mean_luminance = mean;
    t = select_peak_threshold(opt, hits, t);
    s.threshold = t;
    if (!(t > 0.0)) return s;
    s.peaks.resize(hits.size());
    ex(hits.size(), [&](std::size_t b, std::size_t e) {
        for (std::size_t h = b; h < e; ++h) s.peaks[h] = make_cube_peak(src, hits[h], t);
    });
    return s;
}
/// The texels the scan kept, in cube_texel_index order.
inline std::vector<std::pair<std::size_t, float>> peak_scan_hits(const peak_scan& sc) {
    std::vector<std::pair<std::size_t, float>> hits;
    std::size_t total = 0;
    for (const auto& rh : sc.rows) total += rh.size();
    hits.reserve(total);
    for (const auto& rh : sc.rows) hits.insert(hits.end(), rh.begin(), rh.end());
    return hits;
}
template <class T, class Executor> cube_peak_split<T> peak_scan_finish(const cubemap<T>& src, const peak_split_options& opt, peak_scan& sc, Executor& ex) {
    std::vector<std::pair<std::size_t, float>> hits = peak_scan_hits(sc);
    return peaks_from_hits(src, opt, hits, sc.t, sc.mean, ex);
}

/// The peaks and the threshold of split_cube_peaks, without the base.
template <class T, class Executor>
cube_peak_split<T> find_cube_peaks(const cubemap<T>& src, const peak_split_options& opt, Executor& ex) {
    if (!opt.enabled) return {};
    const int n = src.size(0);
    peak_scan sc;
    if (!peak_scan_start(src, opt, sc)) {
        // No 1 x 1 level: the mean of level 0 by texel solid angles first (in texel order).
        const std::vector<double> omega = cube_face_solid_angles<double>(n);
        double acc = 0.0;
        for (std::size_t r = 0; r < std::size_t(6 * n); ++r) peak_mean_row(src, omega, r, acc);
        peak_scan_reset(opt, n, acc / four_pi_v<double>, sc);
    }
    // One pass over level 0, each row its own.
    ex(std::size_t(6 * n), [&](std::size_t b, std::size_t e) {
        std::vector<float> row(static_cast<std::size_t>(n));
        for (std::size_t r = b; r < e; ++r) peak_scan_row(src, sc, r, row.data());
    });
    return peak_scan_finish(src, opt, sc, ex);
}
} // namespace detail

/// Splits a cubemap source (with its mip chain) at T = max(ratio mean, the (max_peaks + 1)-th
/// brightest luminance). With no texel above T the base is left empty (base.size() == 1 and no
/// peaks): the caller reads the source itself. Non-finite texels count as 0.
///
/// Cost: one pass over level 0 (luminance), a selection only when more than max_peaks texels are
/// above ratio times the mean, a copy of the source, and the mips patched where peaks were taken
/// out: a level whose face is half its finer level's (the box filter nests) loses, per texel,
/// the peaks' energy over its exact solid angle; any other chain is rebuilt (generate_mips).
/// (prefilter patches its packed copy of the source the same way instead of copying the cube:
/// detail::patch_packed_peaks.)
template <class T, class Executor = serial_executor>
cube_peak_split<T> split_cube_peaks(const cubemap<T>& src, const peak_split_options& opt, Executor&& ex = Executor{}) {
    cube_peak_split<T> s = detail::find_cube_peaks(src, opt, ex);
    if (s.peaks.empty()) return s;
    const double t = s.threshold;
    s.base = src;
    for (const cube_peak& p : s.peaks) {
        vec3<T>& v = s.base.texel_ref(p.face, p.x, p.y, 0);
        v = vec3<T>(vec3<double>(v) * (t / double(p.luminance)));
    }
    if (!detail::peak_mips_nest(src)) {
        s.base.generate_mips(ex);
        return s;
    }
    for (int l = 1; l < src.levels(); ++l) {
        const int m = src.size(l);
        for (const cube_peak& p : s.peaks) {
            const int cx = p.x >> l, cy = p.y >> l;
            vec3<T>& v = s.base.texel_ref(p.face, cx, cy, l);
            const vec3<double> d = p.energy / cube_texel_solid_angle<double>(cx, cy, m);
            v = vec3<T>(max(vec3<double>(v) - d, vec3<double>(0.0)));
        }
    }
    s.base.update_borders();
    return s;
}

namespace detail {

/// The base of a float source's split written into its packed copy (pack_cube(src)): the same
/// texels, by the same operations, as pack_cube(split_cube_peaks(src).base), without copying
/// the cube: the patched interior texels, the border texels that copy them, and the face
/// corners. Returns false (nothing written) when the mips do not nest.
inline bool patch_packed_peaks(packed_cube& p, const cubemap<float>& src, const std::vector<cube_peak>& peaks, double t) {
    if (!peak_mips_nest(src) || int(p.levels.size()) != src.levels()) return false;
    std::vector<std::uint8_t> mark;
    // The solid angles of the patched texels of the current coarse row, each computed once: the
    // peaks come in face, row, column order, so those of one coarse row are consecutive.
    std::vector<double> row_omega;
    std::vector<int> touched;
    for (int l = std::max(p.first, 0); l < src.levels(); ++l) { // unpacked levels have nothing to patch
        const packed_cube::level& li = p.levels[std::size_t(l)];
        const int n = li.n;
        auto at = [&](int f, int x, int y) {
            return p.data.data() + 4 * (std::size_t(li.offset) + std::size_t(f) * std::size_t(li.face_stride) +
                                        std::size_t(y + 1) * std::size_t(li.stride) + std::size_t(x + 1));
        };
        row_omega.assign(std::size_t(n), 0.0);
        touched.clear();
        int row_face = -1, row_y = -1;
        bool on_edge = false; // a patched texel on a face's edge: some border (or corner) copies it
        for (const cube_peak& pk : peaks) {
            const int x = pk.x >> l, y = pk.y >> l;
            float* q = at(pk.face, x, y);
            const vec3<float> v(q[0], q[1], q[2]);
            vec3<float> w;
            if (l == 0) {
                w = vec3<float>(vec3<double>(v) * (t / double(pk.luminance)));
            } else {
                if (pk.face != row_face || y != row_y) {
                    for (const int i : touched) row_omega[std::size_t(i)] = 0.0;
                    touched.clear();
                    row_face = pk.face, row_y = y;
                }
                double& om = row_omega[std::size_t(x)];
                if (om == 0.0) om = cube_texel_solid_angle<double>(x, y, n), touched.push_back(x);
                w = vec3<float>(max(vec3<double>(v) - pk.energy / om, vec3<double>(0.0)));
            }
            for (int k = 0; k < 3; ++k) q[k] = is_finite(w[k]) ? w[k] : 0.f;
            on_edge = on_edge || x == 0 || y == 0 || x == n - 1 || y == n - 1;
        }
        if (!on_edge) continue; // no border texel copies a patched one, no corner averages one
        mark.assign(std::size_t(6) * std::size_t(n) * std::size_t(n), 0);
        for (const cube_peak& pk : peaks) mark[cube_texel_index(pk.face, pk.x >> l, pk.y >> l, n)] = 1;
        for (int f = 0; f < 6; ++f) {
            for (int e = 0; e < 4; ++e) {
                const cubemap<float>::border_edge b = cubemap<float>::border_edge_source(f, e, n);
                for (int i = 0; i < n; ++i) {
                    const int gx = b.x0 + b.dx * i, gy = b.y0 + b.dy * i;
                    if (!mark[cube_texel_index(b.g, gx, gy, n)]) continue;
                    const int x = e == 0 ? -1 : e == 1 ? n : i, y = e == 2 ? -1 : e == 3 ? n : i;
                    const float* from = at(b.g, gx, gy);
                    float* to = at(f, x, y);
                    for (int k = 0; k < 3; ++k) to[k] = from[k];
                }
            }
            const int cx[2] = {-1, n}, ix[2] = {0, n - 1};
            for (int u = 0; u < 2; ++u)
                for (int v = 0; v < 2; ++v) {
                    const float* a = at(f, ix[u], ix[v]);
                    const float* b = at(f, cx[u], ix[v]);
                    const float* c = at(f, ix[u], cx[v]);
                    const vec3<float> va(a[0], a[1], a[2]), vb(b[0], b[1], b[2]), vc(c[0], c[1], c[2]);
                    const vec3<float> corner = va + ((vb - va) + (vc - va)) / 3.f;
                    float* q = at(f, cx[u], cx[v]);
                    for (int k = 0; k < 3; ++k) q[k] = is_finite(corner[k]) ? corner[k] : 0.f;
                }
        }
    }
    return true;
}
} // namespace detail

/// The peaks merged into the texels of source mip m (face size n >> m): summed energy at the
/// luminance-energy centroid, in face, row, column order of the merged texels.
inline std::vector<cube_peak> merge_cube_peaks(const std::vector<cube_peak>& peaks, int mip) {
    if (mip <= 0) return peaks;
    // The merged texel of each peak as one key in face, row, column order; a stable sort keeps
    // each merged texel's peaks in list order, so their sums add in that order.
    int m = 1; // merged face size bound: keys need only be ordered, not dense
    for (const cube_peak& p : peaks) m = std::max(m, std::max(p.x, p.y) + 1);
    m = (m + (1 << mip) - 1) >> mip;
    auto key_of = [&](const cube_peak& p) {
        return (std::uint64_t(p.face) * std::uint64_t(m) + std::uint64_t(p.y >> mip)) * std::uint64_t(m) + std::uint64_t(p.x >> mip);
    };
    std::vector<std::pair<std::uint64_t, std::uint32_t>> order(peaks.size());
    for (std::size_t i = 0; i < peaks.size(); ++i) order[i] = {key_of(peaks[i]), std::uint32_t(i)};
    std::stable_sort(order.begin(), order.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    std::vector<cube_peak> out;
    for (std::size_t i = 0; i < order.size();) {
        const cube_peak& first = peaks[order[i].second];
        cube_peak q;
        q.face = first.face, q.x = first.x >> mip, q.y = first.y >> mip;
        q.energy = vec3<double>(0.0);
        vec3<double> centroid(0.0);
        std::size_t j = i;
        for (; j < order.size() && order[j].first == order[i].first; ++j) {
            const cube_peak& p = peaks[order[j].second];
            q.energy += p.energy;
            q.weight += p.weight;
            centroid += p.weight * vec3<double>(p.dir);
        }
        const double len = length(centroid);
        if (len > 0.0) q.dir = vec3<float>(centroid / len);
        out.push_back(q);
        i = j;
    }
    return out;
}

/// The LD kernel's full width at half maximum of the GGX lobe at roughness r (radians): 2 theta
/// with K(theta) = K(0) / 2, from q(theta)^2 = 2 q(0)^2 (the n.l factor ignored), at most pi.
inline double ggx_ld_fwhm(double roughness) noexcept {
    const double a2 = std::pow(std::max(alpha_from_roughness(std::clamp(roughness, 0.0, 1.0)), 1e-4), 2.0);
    if (a2 >= 1.0) return pi_v<double>;
    const double one_minus_c = 2.0 * (std::sqrt(2.0) - 1.0) * a2 / (1.0 - a2);
    return std::min(pi_v<double>, 2.0 * std::acos(std::max(-1.0, 1.0 - one_minus_c)));
}

/// The source mip whose texels merge the peaks of a level at roughness r: the coarsest mip m of an
/// n0-texel level 0 (at most max_mip) whose texel at the face centre, 2 / (n0 >> m) radians, is at
/// most min(fwhm / footprint, max_angle).
inline int peak_merge_mip(double roughness, int n0, int max_mip, double footprint, double max_angle) noexcept {
    const double want = std::min(ggx_ld_fwhm(roughness) / std::max(footprint, 1.0), max_angle);
    int m = 0;
    while (m < max_mip && (n0 >> (m + 1)) >= 1 && 2.0 / double(n0 >> (m + 1)) <= want) ++m;
    return m;
}

/// The peaks of one output level ready for the row kernel: directions and energies pre-scaled by
/// alpha^2 / (4 pi integral K), and per peak the cosine beyond which it lies behind a row.
struct peak_level {
    std::vector<float> px, py, pz, er, eg, eb;
    std::vector<float> lum; ///< luminance of (er, eg, eb): the row cut's bound
    float a2 = 0.f, half_a2 = 0.f;
    float floor = 0.f; ///< the cut's floor: 1e-2 times the source's mean luminance
    float cut = 0.f;   ///< peak_split_options::cut
    bool g1 = false;
    [[nodiscard]] std::size_t size() const noexcept { return px.size(); }
};

/// Builds a level's peak list: the split's peaks merged at peak_merge_mip, with the kernel of the
/// GGX lobe at roughness r and the LD weight.
inline peak_level make_peak_level(const std::vector<cube_peak>& peaks, int n0, int source_levels, double roughness,
                                  ld_weight weight, double footprint, double max_angle, double mean_luminance,
                                  double cut = 1e-3, std::uint32_t max_level_peaks = 0, std::uint32_t max_level_steps = 2) {
    peak_level pl;
    if (peaks.empty()) return pl;
    const double r = std::clamp(std::isfinite(roughness) ? roughness : 0.0, 0.0, 1.0);
    const double a = std::max(alpha_from_roughness(r), 1e-4), a2 = a * a;
    const double norm = 2.0 * pi_v<double> * detail::ggx_fast_radial_cdf(r, weight)->total;
    if (!(norm > 0.0)) return pl;
    const double scale = a2 / (4.0 * pi_v<double> * norm);
    int mip = peak_merge_mip(r, n0, source_levels - 1, footprint, max_angle);
    std::vector<cube_peak> merged = merge_cube_peaks(peaks, mip);
    // Too many: a mip coarser, at most max_level_steps times (merged texels up to 2^steps times
    // the footprint rule's, never above max_angle: a rough level's horizon cut is what that bound
    // protects).
    for (std::uint32_t step = 0; step < max_level_steps && max_level_peaks > 0 && merged.size() > max_level_peaks &&
                                 mip < source_levels - 1 && (n0 >> (mip + 1)) >= 1 && 2.0 / double(n0 >> (mip + 1)) <= max_angle;
         ++step)
        merged = merge_cube_peaks(peaks, ++mip);
    for (const cube_peak& p : merged) {
        pl.px.push_back(p.dir.x), pl.py.push_back(p.dir.y), pl.pz.push_back(p.dir.z);
        pl.er.push_back(float(p.energy.x * scale)), pl.eg.push_back(float(p.energy.y * scale)),
            pl.eb.push_back(float(p.energy.z * scale));
        pl.lum.push_back(float(luminance(p.energy) * scale));
    }
    pl.floor = float(1e-2 * mean_luminance);
    pl.cut = std::isfinite(cut) && cut > 0.0 ? float(cut) : 0.f;
    pl.a2 = float(a2);
    pl.half_a2 = float(0.5 * a2);
    pl.g1 = weight == ld_weight::g1;
    return pl;
}

namespace detail {

/// Lanes of the peak kernel (a face row in chunks of this many texels, the tail padded).
inline constexpr int peak_lanes = 16;

/// Buckets of the row cut: peak bounds by their power of two below the row's budget.
inline constexpr int peak_cut_buckets = 48;

/// Adds the peaks of a level to row y of face `face` of its n x n output: out[x] += sum_j
/// E_j K(R_x . d_j) / integral K (header comment), the peaks in list order. Per row, a peak is
/// skipped when it lies beyond the hemisphere of every texel of the row, or when it is among the
/// faintest peaks whose largest contributions to the row, summed, stay below `cut` (1e-3 by
/// default) of the row's darkest tap-set result (at least 1e-2 of the source's mean luminance):
/// the skipped peaks together change no texel of the row by more than `cut` relative. The faintest
/// are found without sorting: the bounds fall into buckets by their power of two below that
/// budget, and whole buckets are skipped, faintest first, while their sums stay within it.
inline void splat_peaks_row(const peak_level& pl, int face, int y, int n, vec3<float>* out) {
    if (pl.size() == 0) return;
    // The row's bounding cone: its middle texel's direction and the larger angle to its ends.
    const vec3<float> mid = normalize(cube_texel_direction<float>(face, n / 2, y, n));
    const vec3<float> e0 = normalize(cube_texel_direction<float>(face, 0, y, n));
    const vec3<float> e1 = normalize(cube_texel_direction<float>(face, n - 1, y, n));
    const float cos_half = std::min(dot(mid, e0), dot(mid, e1));
    const float sin_half = std::sqrt(std::max(0.f, 1.f - cos_half * cos_half));
    const float ha2 = pl.half_a2, a2 = pl.a2, one_minus_a2 = 1.f - pl.a2;
    float darkest = luminance(out[0]);
    for (int x = 1; x < n; ++x) darkest = std::min(darkest, luminance(out[x]));
    const float budget = pl.cut * std::max(darkest, pl.floor);
    // Per-thread scratch: a row allocates nothing once its thread has seen the level's size.
    struct scratch {
        std::vector<float> bound_all; // per peak: its largest contribution to the row, or -1 behind it
        std::vector<std::uint32_t> live;
        std::vector<int> bucket;
    };
    thread_local scratch tls;
    scratch& sc = tls; // one access of the thread-local object
    std::vector<float>& bound_all = sc.bound_all;
    std::vector<std::uint32_t>& live = sc.live;
    std::vector<int>& bucket = sc.bucket;
    const std::size_t np = pl.size();
    bound_all.resize(np);
    {
        // The largest cosine between the peak and a texel of the row: cos(max(0, a - half)), a
        // the angle to the middle texel (1 inside the cone); behind the row when it is <= 0
        // (w(c) <= 1 for both weights). A loop without branches: it vectorises.
        const float* px = pl.px.data();
        const float* py = pl.py.data();
        const float* pz = pl.pz.data();
        const float* lum = pl.lum.data();
        float* bd = bound_all.data();
        for (std::size_t j = 0; j < np; ++j) {
            const float ca = std::clamp(mid.x * px[j] + mid.y * py[j] + mid.z * pz[j], -1.f, 1.f);
            const float c_max = ca >= cos_half ? 1.f : ca * cos_half + std::sqrt(std::max(0.f, 1.f - ca * ca)) * sin_half;
            const float qb = 0.5f * (1.f - c_max) + ha2 * (1.f + c_max);
            bd[j] = c_max > 0.f ? lum[j] / (qb * qb) : -1.f;
        }
    }
    live.clear();
    for (std::size_t j = 0; j < np; ++j)
        if (bound_all[j] >= 0.f) live.push_back(std::uint32_t(j));
    if (budget > 0.f && !live.empty()) {
        // Bucket b holds the bounds in [budget 2^-(b+1), budget 2^-b) (the last one everything
        // fainter; bounds >= budget are never skipped): skip buckets from the faintest while
        // their running sum stays within the budget.
        double sum[peak_cut_buckets] = {};
        auto bucket_of = [&](float v) {
            if (!(v < budget)) return -1;
            if (!(v > 0.f)) return peak_cut_buckets - 1;
            const float q = v / budget; // in (0, 1): q in [2^(e-1), 2^e), e <= 0
            const std::uint32_t bits = std::bit_cast<std::uint32_t>(q);
            int e = int((bits >> 23) & 0xffu) - 126; // normal q: frexp's exponent
            if ((bits >> 23) == 0u) std::frexp(q, &e); // subnormal
            return std::min(-e, peak_cut_buckets - 1);
        };
        bucket.resize(live.size()); // -1: never skipped
        for (std::size_t i = 0; i < live.size(); ++i) {
            const float b = bound_all[live[i]];
            if ((bucket[i] = bucket_of(b)) >= 0) sum[bucket[i]] += double(b);
        }
        double skipped = 0.0;
        int first_kept = peak_cut_buckets; // buckets >= first_kept are skipped
        for (int b = peak_cut_buckets - 1; b >= 0 && skipped + sum[b] <= double(budget); --b)
            skipped += sum[b], first_kept = b;
        std::size_t k = 0;
        for (std::size_t i = 0; i < live.size(); ++i)
            if (bucket[i] < first_kept) live[k++] = live[i]; // -1 < first_kept too
        live.resize(k);
    }
    if (live.empty()) return;
    constexpr int W = peak_lanes;
    const float inv = 1.f / float(n);
    const float tc = 2.f * ((float(y) + 0.5f) * inv) - 1.f;
    with_cube_face_point<float>(face, [&](auto point) {
    for (int x0 = 0; x0 < n; x0 += W) {
        // the lanes' texel directions (cube_texel_direction with the face chosen once; lanes past
        // the row's end repeat its last texel and are not written)
        float dx[W], dy[W], dz[W], ar[W], ag[W], ab[W];
        for (int k = 0; k < W; ++k) {
            const float sc = 2.f * ((float(std::min(x0 + k, n - 1)) + 0.5f) * inv) - 1.f;
            const vec3<float> d = normalize(point(sc, tc));
            dx[k] = d.x, dy[k] = d.y, dz[k] = d.z;
            ar[k] = ag[k] = ab[k] = 0.f;
        }
        for (const std::uint32_t j : live) {
            const float px = pl.px[j], py = pl.py[j], pz = pl.pz[j];
            const float er = pl.er[j], eg = pl.eg[j], eb = pl.eb[j];
            if (pl.g1) {
                for (int k = 0; k < W; ++k) {
                    const float c = dx[k] * px + dy[k] * py + dz[k] * pz;
                    const float cp = c > 0.f ? c : 0.f;
                    const float q = 0.5f * (1.f - cp) + ha2 * (1.f + cp);
                    const float g = 2.f / (cp + std::sqrt(a2 + one_minus_a2 * cp * cp)); // G1 / n.l
                    const float kk = cp * g / (q * q);
                    ar[k] += er * kk, ag[k] += eg * kk, ab[k] += eb * kk;
                }
            } else {
                for (int k = 0; k < W; ++k) {
                    const float c = dx[k] * px + dy[k] * py + dz[k] * pz;
                    const float cp = c > 0.f ? c : 0.f;
                    const float q = 0.5f * (1.f - cp) + ha2 * (1.f + cp);
                    const float kk = cp / (q * q);
                    ar[k] += er * kk, ag[k] += eg * kk, ab[k] += eb * kk;
                }
            }
        }
        for (int k = 0; k < W && x0 + k < n; ++k) out[x0 + k] += vec3<float>(ar[k], ag[k], ab[k]);
    }
    });
}

} // namespace detail

} // namespace ibl

#endif // IBL_DETAIL_CXX20
