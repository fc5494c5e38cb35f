#pragma once
// ibl/bake/prefilter_sh.hpp — the rough levels of the fast filter by spherical-harmonic
// convolution (host only). prefilter() and prefilter_update run it with prefilter_method::fast on
// a cubemap source when prefilter_options::sh_rough.enabled, for every level whose kernel needs at
// most sh_rough.max_bands bands.
//
// Why. The LD kernel at normal view (N = V = R) depends only on the angle between l and R: it is
// zonal. By the Funk-Hecke theorem its convolution with the source is a product per band,
//
//     LD(R) = sum_(l < B) sum_m k_l L_lm Y_lm(R),
//     k_l = integral K(theta) P_l(cos theta) dOmega / integral K(theta) dOmega,
//
// exact for a source band-limited to l < B, with L_lm the source's coefficients and Y_lm the real
// orthonormal basis. A rough level's kernel is wide, so its k_l fall fast: the GGX core's like
// exp(-2 alpha l), and the cut at the horizon (K = 0 for n.l <= 0) leaves a slow k_l ~ l^-2 tail of
// small amplitude. A tap set needs hundreds to thousands of taps per texel to reach a percent on
// a real HDRI at r >= 0.4 (docs/ibl-bake.md, "Fast filter"), because its error is the aliasing of
// the source's detail through footprints that vary texel to texel; the projection reads every
// source texel once and the reconstruction costs B^2 multiply-adds per output texel, about
// 5 - 25 taps' time at B = 11 - 24.
//
// Bands per level. The truncation error on a source whose band powers fall like (l + 1)^-2
// (natural illumination: Dror, Willsky & Adelson 2004) is
//
//     e(B)^2 = sum_(l >= B) (2l + 1) k_l^2 / (l + 1)^2  /  sum_(l >= 0) (2l + 1) k_l^2 / (l + 1)^2,
//
// and a level takes the smallest B with e(B) <= tolerance (sh_rough_options; k_l to l = 96). For
// GGX with the n.l weight at tolerance 5e-4 that is 24 bands at r = 0.4, 11 at 0.6, 13 at 0.8
// and 17 at 1 (the cut at the horizon); r = 0.2 would need about 60 and keeps its tap set. The peak split
// (bake/prefilter_peaks.hpp) takes a sun out of the source before the projection, so the
// truncation never rings around a light 10^4 times the sky: the projection reads the split's base.
//
// Projection. The coefficients are sums over the texels of one mip of the packed source (the
// split's base), the finest whose face is at most max(16, 2 B_max) (the coarsest level when none
// is): L_lm = sum_texels L Y_lm(d) Omega, with d the texel's centre direction and
// Omega its exact solid angle (cube_texel_solid_angle). Each face row is a work unit; the lanes'
// float sums of a face are kept per face and reduced, in a fixed order, in double, so the result
// does not depend on how the rows are split over threads or calls.
//
// Basis. Y_lm with the normalised associated-Legendre recurrence in z and Re / Im (x + i y)^m
// (no trigonometry; zonal about +Z; the basis of sh/basis.hpp for l < 5, which
// tests/test_prefilter_sh.cpp checks): with Q_l^m = P_l^m / sin^m theta normalised,
//     Q_0^0 = 1 / (2 sqrt(pi)),  Q_m^m = sqrt((2m + 1) / (2m)) Q_(m-1)^(m-1),
//     Q_l^m = a_lm (z Q_(l-1)^m - b_lm Q_(l-2)^m)  (l > m; Q_(m-1)^m = 0, a_(m+1)m = sqrt(2m + 3)),  a = sqrt((4l^2 - 1) / (l^2 - m^2)),
//                                                   b = sqrt(((l-1)^2 - m^2) / (4 (l-1)^2 - 1)),
//     Y_l0 = Q_l^0,  Y_lm = sqrt(2) Q_l^m Re (x + i y)^m,  Y_l(-m) = sqrt(2) Q_l^m Im (x + i y)^m.
// Float throughout the lanes (the recurrence is stable for these B), double for the reductions.

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <memory>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

#include "../batch/sphere_kernel.hpp"
#include "../core/constants.hpp"
#include "../core/gauss_legendre.hpp"
#include "../core/vec.hpp"
#include "../env/cube_geometry.hpp"
#include "../runtime/ld_weight.hpp"
#include "../sampling/lobe.hpp"
#include "prefilter_fast.hpp"

namespace ibl {

/// The rough levels by spherical harmonics (header comment). Read by prefilter_method::fast on a
/// cubemap source.
struct sh_rough_options {
    bool enabled = true;
    /// A level whose kernel needs more bands than this keeps its tap set (cost B^2 per texel).
    int max_bands = 24;
    /// Truncation error per level on natural illumination (header comment: e(B)).
    double tolerance = 5e-4;
};

namespace detail {

/// Most bands sh_rough reads (the lanes' accumulators and the recurrence tables are sized by it).
inline constexpr int sh_rough_band_limit = 32;

/// k_l, l < count, of the LD kernel of lobe L (bake/prefilter_fast.hpp's fast_kernel), normalised
/// to k_0 = 1: Gauss-Legendre (24 nodes) on panels in theta growing geometrically from a fiftieth
/// of the lobe's scale to pi / 2, in double.
template <class Lobe> std::vector<double> zonal_band_factors(int count, double roughness, ld_weight weight) {
    std::vector<double> k(std::size_t(std::max(count, 1)), 0.0);
    const gauss_legendre_rule gl = make_gauss_legendre_symmetric(24);
    const double half_pi = 0.5 * pi_v<double>;
    const double s = std::max(1e-4, fast_lobe_scale(roughness));
    std::vector<double> edges{0.0};
    for (double t = 0.02 * s; t < half_pi; t *= 1.4) edges.push_back(t);
    edges.push_back(half_pi);
    // A panel's nodes side by side: the Legendre recurrence of each node is a chain of divisions,
    // so the nodes' chains run together (vectorised) while each k_l still adds the nodes' terms
    // one after another in node order, as a loop node by node would.
    const std::size_t nodes = gl.x.size();
    std::vector<double> f(nodes), mu(nodes), p0(nodes), p1(nodes);
    for (std::size_t e = 0; e + 1 < edges.size(); ++e) {
        const double a = edges[e], b = edges[e + 1];
        for (std::size_t i = 0; i < nodes; ++i) {
            const double t = 0.5 * (a + b) + 0.5 * (b - a) * gl.x[i];
            f[i] = fast_kernel<Lobe>(t, roughness, weight) * std::sin(t) * 0.5 * (b - a) * gl.w[i];
            mu[i] = std::cos(t);
            p0[i] = 1.0; // P_l
            p1[i] = mu[i]; // P_(l+1)
        }
        for (std::size_t l = 0; l < k.size(); ++l) {
            double acc = k[l];
            for (std::size_t i = 0; i < nodes; ++i) acc += f[i] * p0[i];
            k[l] = acc;
            const double c1 = 2.0 * double(l) + 3.0, c0 = double(l) + 1.0, d = double(l) + 2.0;
            for (std::size_t i = 0; i < nodes; ++i) {
                const double p2 = (c1 * mu[i] * p1[i] - c0 * p0[i]) / d;
                p0[i] = p1[i];
                p1[i] = p2;
            }
        }
    }
    const double k0 = k[0];
    for (double& v : k) v = k0 > 0.0 ? v / k0 : 0.0;
    return k;
}

/// Band factors computed for the band choice (header comment: k_l to l = 96).
inline constexpr int sh_rough_factor_count = 97;
/// zonal_band_factors to l = 96 (a level's factors are their first B: each k_l is computed the
/// same way whatever the count), memoised for GGX like the fast filter's radial CDFs.
template <class Lobe> std::shared_ptr<const std::vector<double>> lobe_band_factors(double roughness, ld_weight weight) {
    if constexpr (std::is_same_v<Lobe, ggx_lobe>)
        return fast_memo<std::pair<double, int>, std::vector<double>>(std::pair<double, int>(roughness, int(weight)), [&] {
            return zonal_band_factors<ggx_lobe>(sh_rough_factor_count, roughness, weight);
        });
    else
        return std::make_shared<const std::vector<double>>(zonal_band_factors<Lobe>(sh_rough_factor_count, roughness, weight));
}

/// The bands a level of roughness r needs at `tolerance` (header comment), or 0 when more than
/// max_bands (the level keeps its tap set).
template <class Lobe> int sh_rough_bands(double roughness, ld_weight weight, const sh_rough_options& o) {
    if (!o.enabled || !(o.tolerance > 0.0)) return 0;
    const int cap = std::clamp(o.max_bands, 0, sh_rough_band_limit);
    const std::shared_ptr<const std::vector<double>> kp = lobe_band_factors<Lobe>(roughness, weight); // kept alive
    const std::vector<double>& k = *kp;
    std::vector<double> tail(k.size() + 1, 0.0); // tail[B] = sum_(l >= B)
    for (std::size_t l = k.size(); l-- > 0;)
        tail[l] = tail[l + 1] + (2.0 * double(l) + 1.0) * k[l] * k[l] / ((double(l) + 1.0) * (double(l) + 1.0));
    for (int b = 1; b <= cap; ++b)
        if (std::sqrt(tail[std::size_t(b)] / tail[0]) <= o.tolerance) return b;
    return 0;
}

/// The recurrence's constants for B bands (header comment, "Basis").
struct sh_recurrence {
    int bands = 0;
    std::vector<float> a, b;    ///< a_lm, b_lm at l * bands + m (l >= m + 1)
    std::vector<float> mm;      ///< sqrt((2m + 1) / (2m)) (m >= 1)
    explicit sh_recurrence(int B = 0) : bands(B) {
        a.assign(std::size_t(B * B), 0.f), b.assign(std::size_t(B * B), 0.f);
        mm.assign(std::size_t(std::max(B, 1)), 0.f);
        for (int m = 0; m < B; ++m) {
            mm[std::size_t(m)] = m > 0 ? float(std::sqrt((2.0 * m + 1.0) / (2.0 * m))) : 1.f;
            for (int l = m + 1; l < B; ++l) { // l = m + 1: a = sqrt(2m + 3), b = 0
                const double L = l, M = m;
                a[std::size_t(l * B + m)] = float(std::sqrt((4.0 * L * L - 1.0) / (L * L - M * M)));
                b[std::size_t(l * B + m)] = float(std::sqrt(((L - 1.0) * (L - 1.0) - M * M) / (4.0 * (L - 1.0) * (L - 1.0) - 1.0)));
            }
        }
    }
};

/// Index of (l, m) in the B^2 coefficients (l * l + l + m, as sh/basis.hpp).
constexpr std::size_t sh_index(int l, int m) noexcept { return std::size_t(l * l + l + m); }

/// The kernels' coefficient layout: m outer, l = m .. B - 1 inner, six floats per (l, m): the
/// cosine term's R G B, then the sine term's (0 for m = 0). Pairs of B bands: B (B + 1) / 2.
constexpr std::size_t sh_pair_count(int B) noexcept { return std::size_t(B * (B + 1) / 2); }

/// Eight float lanes for the two kernels below. GCC 12 does not vectorise their lane loops (the
/// recurrence's loop-carried lane arrays are left to the basic-block vectoriser, which gives up:
/// 0.6-0.7 ns per texel and coefficient on the 2-core VM, against 0.12 ns with this type); GCC and
/// Clang with AVX get their vector extension (one register), other builds the same arithmetic
/// lane by lane (a 32-byte vector without AVX would change the functions' ABI).
#if defined(__GNUC__) && defined(__AVX__)
using sh_f8 = float __attribute__((vector_size(32)));
inline sh_f8 sh_splat(float v) noexcept { return sh_f8{v, v, v, v, v, v, v, v}; }
inline sh_f8 sh_load(const float* p) noexcept {
    sh_f8 v;
    __builtin_memcpy(&v, p, sizeof v);
    return v;
}
inline float sh_lane(const sh_f8& v, std::size_t k) noexcept { return v[k]; }
/// p[0..8) += v.
inline void sh_add(float* p, const sh_f8& v) noexcept {
    const sh_f8 s = sh_load(p) + v;
    __builtin_memcpy(p, &s, sizeof s);
}
#else
struct sh_f8 {
    float v[8];
    friend sh_f8 operator+(sh_f8 a, const sh_f8& b) noexcept {
        for (int k = 0; k < 8; ++k) a.v[k] += b.v[k];
        return a;
    }
    friend sh_f8 operator-(sh_f8 a, const sh_f8& b) noexcept {
        for (int k = 0; k < 8; ++k) a.v[k] -= b.v[k];
        return a;
    }
    friend sh_f8 operator*(sh_f8 a, const sh_f8& b) noexcept {
        for (int k = 0; k < 8; ++k) a.v[k] *= b.v[k];
        return a;
    }
    friend sh_f8 operator*(float s, sh_f8 a) noexcept {
        for (int k = 0; k < 8; ++k) a.v[k] *= s;
        return a;
    }
    sh_f8& operator+=(const sh_f8& b) noexcept { return *this = *this + b; }
    sh_f8& operator*=(float s) noexcept { return *this = s * *this; }
};
inline sh_f8 sh_splat(float s) noexcept { return sh_f8{{s, s, s, s, s, s, s, s}}; }
inline sh_f8 sh_load(const float* p) noexcept {
    sh_f8 v;
    for (int k = 0; k < 8; ++k) v.v[k] = p[k];
    return v;
}
inline float sh_lane(const sh_f8& v, std::size_t k) noexcept { return v.v[k]; }
inline void sh_add(float* p, const sh_f8& v) noexcept {
    for (int k = 0; k < 8; ++k) p[k] += v.v[k];
}
#endif

/// Unit centre directions of W texels from x0 of row y of face `face` (n x n); lanes past the
/// row's end repeat its last texel.
template <std::size_t W> inline void sh_row_directions(int face, int x0, int y, int n, float* dx, float* dy, float* dz) noexcept {
    const float inv = 1.f / float(n);
    const float tc = 2.f * ((float(y) + 0.5f) * inv) - 1.f;
    with_cube_face_point<float>(face, [&](auto point) {
        for (std::size_t k = 0; k < W; ++k) {
            const int x = std::min(x0 + int(k), n - 1);
            const vec3<float> d = glm::normalize(point(2.f * ((float(x) + 0.5f) * inv) - 1.f, tc));
            dx[k] = d.x, dy[k] = d.y, dz[k] = d.z;
        }
    });
}

/// The projection of a packed source level onto B bands (header comment, "Projection"). A row's
/// texels (in segments of up to `segment`) run through the recurrence together, m outer, l inner,
/// so that each (l, m) is six dot products over the segment in registers; their lane partials are
/// added to the face's sums (per face, in row order); coefficients() reduces them in double.
class sh_projection {
public:
    static constexpr std::size_t lanes = 8;
    static constexpr std::size_t segment = 64;
    sh_projection() = default;
    sh_projection(int bands, int level, int face_size) : rec_(bands), level_(level), n_(face_size) {
        sums_.assign(std::size_t(6) * sh_pair_count(bands) * 6 * lanes, 0.f);
        const std::vector<double> solid = cube_face_solid_angles<double>(face_size);
        solid_.assign(solid.begin(), solid.end()); // float of each
    }
    [[nodiscard]] int bands() const noexcept { return rec_.bands; }
    [[nodiscard]] int level() const noexcept { return level_; }
    [[nodiscard]] int face_size() const noexcept { return n_; }
    /// Work items: the rows of the projected level (6 n); a face's rows must be added in order.
    [[nodiscard]] std::size_t rows() const noexcept { return std::size_t(6 * n_); }
    /// Zeroes the sums (a new source).
    void clear() noexcept { std::fill(sums_.begin(), sums_.end(), 0.f); }
    /// Adds row `row` (face row / n, y = row % n) of the packed source's level: every face's rows
    /// in order, faces independent (each has its own sums).
    void add_row(const packed_cube& src, std::size_t row) noexcept {
        const int face = int(row) / n_, y = int(row) % n_;
        const packed_cube::level& lv = src.levels[std::size_t(level_)];
        const float* data = src.data.data() + 4 * (std::size_t(lv.offset) + std::size_t(face) * std::size_t(lv.face_stride) +
                                                   std::size_t(y + 1) * std::size_t(lv.stride) + 1);
        float* acc = sums_.data() + std::size_t(face) * sh_pair_count(rec_.bands) * 6 * lanes;
        for (int x0 = 0; x0 < n_; x0 += int(segment)) segment_sums(data, 4, face, x0, y, acc);
    }
    /// The coefficients of a constant 1 projected by the same operations (every texel's weight its
    /// solid angle): sh_level's normalisation.
    [[nodiscard]] std::vector<double> unit_coefficients() const {
        sh_projection u(*this);
        u.clear();
        static const float one[4] = {1.f, 1.f, 1.f, 1.f};
        for (std::size_t row = 0; row < rows(); ++row) {
            const int face = int(row) / n_, y = int(row) % n_;
            float* acc = u.sums_.data() + std::size_t(face) * sh_pair_count(rec_.bands) * 6 * lanes;
            for (int x0 = 0; x0 < n_; x0 += int(segment)) u.segment_sums(one, 0, face, x0, y, acc);
        }
        return u.coefficients();
    }
    /// The coefficients in the kernels' layout (sh_pair_count(B) x 6: per (l, m) the cosine and sine
    /// sums of R G B, without the basis's sqrt(2) for m > 0), faces and lanes in order, in double.
    [[nodiscard]] std::vector<double> coefficients() const {
        const std::size_t np = sh_pair_count(rec_.bands) * 6;
        std::vector<double> c(np, 0.0);
        for (std::size_t f = 0; f < 6; ++f)
            for (std::size_t i = 0; i < np; ++i) {
                const float* p = sums_.data() + (f * np + i) * lanes;
                double s = 0.0;
                for (std::size_t k = 0; k < lanes; ++k) s += double(p[k]);
                c[i] += s;
            }
        return c;
    }

private:
    /// Texel x of the row reads data[step x .. step x + 3) (step 0: one texel for all).
    void segment_sums(const float* data, std::size_t step, int face, int x0, int y, float* acc) const noexcept {
        constexpr std::size_t S = segment, L = lanes, C = S / L;
        const int B = rec_.bands;
        const int count = std::min(int(S), n_ - x0);
        const std::size_t chunks = (std::size_t(count) + L - 1) / L;
        sh_f8 dx[C], dy[C], dz[C], w[3][C], cr[C], ci[C], qmm[C], q1[C], q2[C], wc[3][C], ws[3][C];
        for (std::size_t c = 0; c < chunks; ++c) {
            float fx[L], fy[L], fz[L], fw[3][L];
            sh_row_directions<L>(face, x0 + int(c * L), y, n_, fx, fy, fz);
            for (std::size_t k = 0; k < L; ++k) {
                const int x = x0 + int(c * L + k);
                const bool in = x < n_;
                const float om = in ? solid_[std::size_t(y * n_ + x)] : 0.f;
                const float* t = data + step * std::size_t(in ? x : 0);
                fw[0][k] = om * t[0], fw[1][k] = om * t[1], fw[2][k] = om * t[2];
            }
            dx[c] = sh_load(fx), dy[c] = sh_load(fy), dz[c] = sh_load(fz);
            for (std::size_t ch = 0; ch < 3; ++ch) w[ch][c] = sh_load(fw[ch]);
            cr[c] = sh_splat(1.f), ci[c] = sh_splat(0.f), qmm[c] = sh_splat(0.28209479177387814f);
        }
        std::size_t pair = 0;
        for (int m = 0; m < B; ++m) {
            const float f = rec_.mm[std::size_t(m)];
            for (std::size_t c = 0; c < chunks; ++c) {
                if (m > 0) {
                    const sh_f8 nr = cr[c] * dx[c] - ci[c] * dy[c], ni = cr[c] * dy[c] + ci[c] * dx[c];
                    cr[c] = nr, ci[c] = ni, qmm[c] *= f;
                }
                for (std::size_t ch = 0; ch < 3; ++ch) wc[ch][c] = w[ch][c] * cr[c], ws[ch][c] = w[ch][c] * ci[c];
                q1[c] = qmm[c], q2[c] = sh_splat(0.f);
            }
            for (int l = m; l < B; ++l, ++pair) {
                // l = m: Q_m^m; above, the recurrence (a_(m+1)m = sqrt(2m + 3), b = 0 starts it)
                const float a = l > m ? rec_.a[std::size_t(l * B + m)] : 1.f, b = l > m ? rec_.b[std::size_t(l * B + m)] : 0.f;
                sh_f8 s0 = sh_splat(0.f), s1 = s0, s2 = s0, s3 = s0, s4 = s0, s5 = s0;
                for (std::size_t c = 0; c < chunks; ++c) {
                    sh_f8 q = q1[c];
                    if (l > m) {
                        q = a * (dz[c] * q1[c] - b * q2[c]);
                        q2[c] = q1[c], q1[c] = q;
                    }
                    s0 += q * wc[0][c], s1 += q * wc[1][c], s2 += q * wc[2][c];
                    s3 += q * ws[0][c], s4 += q * ws[1][c], s5 += q * ws[2][c];
                }
                float* p = acc + pair * 6 * L;
                sh_add(p, s0), sh_add(p + L, s1), sh_add(p + 2 * L, s2), sh_add(p + 3 * L, s3), sh_add(p + 4 * L, s4), sh_add(p + 5 * L, s5);
            }
        }
    }

    sh_recurrence rec_{};
    int level_ = 0, n_ = 1;
    std::vector<float> sums_;  ///< [face][(l, m) pair][cosine R G B, sine R G B][lane]
    std::vector<float> solid_; ///< exact texel solid angles of the projected level
};

/// A level reconstructed from the projection: B bands, per (l, m) pair (the kernels' layout) k_l
/// times the source's coefficients with the basis's normalisation folded in.
struct sh_level {
    int bands = 0;
    sh_recurrence rec{};
    std::vector<double> k;   ///< k_l, l < bands
    std::vector<float> coef; ///< sh_pair_count(bands) x 6 (set by set_coefficients)
    /// Per texel of the level (cube_texel_index), the reconstruction of a constant 1 projected by
    /// the same operations (sh_projection::unit_coefficients); the level divides by it, so a white
    /// source stays exactly white and the projection's quadrature error on the mean cancels.
    std::shared_ptr<const std::vector<float>> norm;
    [[nodiscard]] bool active() const noexcept { return bands > 0; }
    /// The level's coefficients from the projection's (sh_projection::coefficients of
    /// proj_bands >= bands): Y_l0 = Q, and for m > 0 the sqrt(2) of the projection's basis times the
    /// sqrt(2) of the reconstruction's.
    void set_coefficients(const std::vector<double>& proj, int proj_bands) {
        coef.assign(sh_pair_count(bands) * 6, 0.f);
        std::size_t pair = 0;
        for (int m = 0; m < bands; ++m)
            for (int l = m; l < bands; ++l, ++pair) {
                // the projection's pair of (l, m): its m rows hold proj_bands - m' entries each
                const std::size_t pp = std::size_t(m) * std::size_t(proj_bands) - std::size_t(m) * std::size_t(m - 1) / 2 + std::size_t(l - m);
                const double g = k[std::size_t(l)] * (m > 0 ? 2.0 : 1.0);
                for (std::size_t i = 0; i < 6; ++i) coef[pair * 6 + i] = float(g * proj[pp * 6 + i]);
            }
    }
};

/// Sixteen float lanes in one register where the target has AVX-512 (GCC and Clang's vector
/// extension): the reconstruction's sixteen texels as one chunk instead of two of sh_f8, the same
/// operations per lane (the same bits), about 8 % of a 256^2 fast chain (docs/ARCHITECTURE.md,
/// "Compiler flags for speed").
#if defined(__GNUC__) && defined(__AVX512F__)
#define IBL_DETAIL_SH_F16 1
using sh_f16 = float __attribute__((vector_size(64)));
inline float sh_lane_of(const sh_f16& v, std::size_t k) noexcept { return v[k]; }
#endif
inline float sh_lane_of(const sh_f8& v, std::size_t k) noexcept { return sh_lane(v, k); }
template <class V> inline V sh_splat_as(float s) noexcept {
    if constexpr (std::is_same_v<V, sh_f8>) return sh_splat(s);
    else return V{} + s;
}
template <class V> inline V sh_load_as(const float* p) noexcept {
    V v;
    __builtin_memcpy(&v, p, sizeof v);
    return v;
}

/// Texels [x, x + 16) of row y of face `face` of an n x n level from its coefficients (header
/// comment, "Basis"): sixteen lanes, in chunks of L (16 with AVX-512; else two chunks of eight side
/// by side, whose two independent recurrences hide each other's latency), per m the cosine and sine
/// sums over l in registers, then times Re / Im (x + i y)^m. Lanes past the row's end are computed
/// on its last texel and not written.
template <class V, std::size_t L>
inline void sh_level_lanes(const sh_level& lv, int face, int x, int y, int n, vec3<float>* out, const float* norm) noexcept {
    constexpr std::size_t C = 16 / L; // chunks of L lanes
    V dx[C], dy[C], dz[C];
    for (std::size_t c = 0; c < C; ++c) {
        float fx[L], fy[L], fz[L];
        sh_row_directions<L>(face, x + int(L * c), y, n, fx, fy, fz);
        dx[c] = sh_load_as<V>(fx), dy[c] = sh_load_as<V>(fy), dz[c] = sh_load_as<V>(fz);
    }
    const sh_recurrence& rec = lv.rec;
    const int B = rec.bands;
    const float* cf = lv.coef.data();
    V r[C], g[C], b[C], cr[C], ci[C], qmm[C];
    for (std::size_t c = 0; c < C; ++c)
        r[c] = g[c] = b[c] = ci[c] = sh_splat_as<V>(0.f), cr[c] = sh_splat_as<V>(1.f), qmm[c] = sh_splat_as<V>(0.28209479177387814f);
    for (int m = 0; m < B; ++m) {
        V s0[C], s1[C], s2[C], s3[C], s4[C], s5[C], q1[C], q2[C];
        const float f = rec.mm[std::size_t(m)];
        for (std::size_t c = 0; c < C; ++c) {
            if (m > 0) {
                const V nr = cr[c] * dx[c] - ci[c] * dy[c], ni = cr[c] * dy[c] + ci[c] * dx[c];
                cr[c] = nr, ci[c] = ni, qmm[c] *= f;
            }
            const V q = qmm[c];
            s0[c] = cf[0] * q, s1[c] = cf[1] * q, s2[c] = cf[2] * q, s3[c] = cf[3] * q, s4[c] = cf[4] * q, s5[c] = cf[5] * q;
            q1[c] = q, q2[c] = sh_splat_as<V>(0.f);
        }
        cf += 6;
        for (int l = m + 1; l < B; ++l, cf += 6) { // a_(m+1)m = sqrt(2m + 3), b = 0 starts the recurrence
            const float a = rec.a[std::size_t(l * B + m)], bb = rec.b[std::size_t(l * B + m)];
            const float c0 = cf[0], c1 = cf[1], c2 = cf[2], c3 = cf[3], c4 = cf[4], c5 = cf[5];
            for (std::size_t c = 0; c < C; ++c) {
                const V q = a * (dz[c] * q1[c] - bb * q2[c]);
                q2[c] = q1[c], q1[c] = q;
                s0[c] += c0 * q, s1[c] += c1 * q, s2[c] += c2 * q, s3[c] += c3 * q, s4[c] += c4 * q, s5[c] += c5 * q;
            }
        }
        for (std::size_t c = 0; c < C; ++c) {
            r[c] += cr[c] * s0[c] + ci[c] * s3[c];
            g[c] += cr[c] * s1[c] + ci[c] * s4[c];
            b[c] += cr[c] * s2[c] + ci[c] * s5[c];
        }
    }
    // Radiance is not negative: the truncation's ringing around a light above the split's threshold
    // (or any light, without the split) is clamped at 0. norm (the row's): divided by it.
    for (std::size_t k = 0; k < L * C && x + int(k) < n; ++k) {
        vec3<float> v(std::max(0.f, sh_lane_of(r[k / L], k % L)), std::max(0.f, sh_lane_of(g[k / L], k % L)),
                      std::max(0.f, sh_lane_of(b[k / L], k % L)));
        if (norm && norm[x + int(k)] > 0.f) v /= norm[x + int(k)];
        out[x + int(k)] = v;
    }
}
inline void sh_level_lanes16(const sh_level& lv, int face, int x, int y, int n, vec3<float>* out, const float* norm) noexcept {
#if defined(IBL_DETAIL_SH_F16)
    sh_level_lanes<sh_f16, 16>(lv, face, x, y, n, out, norm);
#else
    sh_level_lanes<sh_f8, 8>(lv, face, x, y, n, out, norm);
#endif
}
/// Row y of face `face` of an n x n level from its coefficients, sixteen texels at a time, divided
/// by the level's norm.
inline void sh_level_row(const sh_level& lv, int face, int y, int n, vec3<float>* out) noexcept {
    const float* norm = lv.norm ? lv.norm->data() + cube_texel_index(face, 0, y, n) : nullptr;
    for (int x = 0; x < n; x += 16) sh_level_lanes16(lv, face, x, y, n, out, norm);
}

/// The norm of an n x n level (sh_level::norm) from the projection's unit coefficients (of
/// proj_bands bands): the level's k_l applied to them, reconstructed at every texel (face rows
/// through the executor: rows are independent).
template <class Executor>
std::vector<float> sh_level_norm(const sh_level& lv, const std::vector<double>& unit, int proj_bands, int n, Executor& ex) {
    sh_level u;
    u.bands = lv.bands;
    u.rec = lv.rec;
    u.k = lv.k;
    u.set_coefficients(unit, proj_bands);
    std::vector<float> norm(static_cast<std::size_t>(6 * n * n));
    ex(std::size_t(6 * n), [&](std::size_t b, std::size_t e) {
        std::vector<vec3<float>> row(static_cast<std::size_t>(n));
        for (std::size_t r = b; r < e; ++r) {
            const int f = int(r) / n, y = int(r) % n;
            sh_level_row(u, f, y, n, row.data());
            for (int x = 0; x < n; ++x) norm[cube_texel_index(f, x, y, n)] = row[std::size_t(x)].x;
        }
    });
    return norm;
}

/// The projection's unit coefficients (B bands, face m), memoised: they depend on nothing else.
inline std::shared_ptr<const std::vector<double>> sh_unit_coefficients(const sh_projection& p) {
    return fast_memo<std::pair<int, int>, std::vector<double>>(std::pair<int, int>(p.bands(), p.face_size()),
                                                             [&] { return p.unit_coefficients(); });
}
/// The norm of a level of lobe L (its k_l in lv) at face size n for the projection p, memoised for
/// GGX (by roughness, weight, bands, the projection's bands and face, n).
template <class Lobe, class Executor>
std::shared_ptr<const std::vector<float>> sh_level_norm_for(const sh_level& lv, double roughness, ld_weight weight, const sh_projection& p, int n,
                                                            Executor& ex) {
    auto make = [&] { return sh_level_norm(lv, *sh_unit_coefficients(p), p.bands(), n, ex); };
    if constexpr (std::is_same_v<Lobe, ggx_lobe>) {
        using key = std::tuple<double, int, int, int, int, int>;
        return fast_memo<key, std::vector<float>>(key(roughness, int(weight), lv.bands, p.bands(), p.face_size(), n), make);
    } else {
        return std::make_shared<const std::vector<float>>(make());
    }
}

/// The packed level the projection for B bands reads: the finest whose face is at most
/// max(16, 2 B) (the coarsest level when none is).
inline int sh_projection_level(const packed_cube& p, int bands) noexcept {
    const int cap = std::max(16, 2 * bands);
    for (std::size_t l = 0; l < p.levels.size(); ++l)
        if (p.levels[l].n <= cap) return int(l);
    return int(p.levels.size()) - 1;
}

} // namespace detail
} // namespace ibl

#endif // IBL_DETAIL_CXX20
