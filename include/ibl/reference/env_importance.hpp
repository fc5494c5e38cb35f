#pragma once
// ibl/reference/env_importance.hpp — importance sampling of an environment by its luminance: a
// piecewise-constant distribution over the texels of a cubemap (host only: std::vector storage).
//
// Distribution. Texel i of the chosen level gets the weight
//     w_i = Y(tent_i) Omega_i,
// Y = luminance (core/color.hpp), Omega_i the exact texel solid angle (cube_texel_solid_angle) and
// tent_i the texel's value filtered with the separable weights (1/8, 3/4, 1/8) over its 3 x 3
// neighbourhood (the border texels of cubemap hold the neighbours across face edges). (1/8, 3/4,
// 1/8) is the mean over a texel of the bilinear reconstruction that cubemap::radiance performs, so
// w_i > 0 wherever the looked-up radiance is non-zero somewhere in the texel: the distribution
// covers the support of the integrand, and an estimator that samples only the environment stays
// unbiased (a raw texel weight would miss the half texel of bilinear bleed around a bright texel
// next to black ones). A defensive fraction f of the probability (T. Hesterberg, "Weighted
// average importance sampling and defensive mixture distributions", Technometrics 37(2), 1995)
// is spread over the sphere by solid angle:
//     p_i = (1 - f) w_i / sum_j w_j + f Omega_i / (4 pi),
// and a black map (sum w = 0) gets p_i = Omega_i / (4 pi). Rows are (face, y) (6 n rows of n
// texels); sampling inverts the marginal CDF over rows and then the conditional CDF within the
// row (M. Pharr, W. Jakob, G. Humphreys, "Physically Based Rendering", 4th ed., sec. A.5 /
// PiecewiseConstant2D), and p_i is recomputed as the product of the two CDF steps, so the pdf
// reported and the probability actually used agree to the last bit.
//
// Within the texel the point is uniform in the face coordinates (sc, tc) = (2 s - 1, 2 t - 1):
// the fractional positions of u.x in its row's CDF step and of u.y in its column's step are the
// offsets, so the map [0, 1)^2 -> (face, sc, tc) is piecewise affine and stratification of u is
// kept. The density of (sc, tc) is p_i / A with A = (2 / n)^2 the texel's area in (sc, tc).
// Change of measure to solid angle: the face point P = (sc, tc, 1) (in the face frame) has
// |P|^2 = 1 + sc^2 + tc^2 and d(omega) = dsc dtc / |P|^3 (cube_geometry.hpp), so
//     pdf_omega(d) = (p_i / A) |P|^3 = p_i (n^2 / 4) (1 + sc^2 + tc^2)^(3/2) = p_i (n^2 / 4) / |m|^3,
// m the major-axis component of the unit direction d (since d = P / |P| and |m| = 1 / |P|).
// Check: integral over texel i of pdf_omega d(omega) = (p_i / A) integral dsc dtc = p_i.
// tests/test_radiance_reference.cpp integrates pdf_omega over the sphere and runs a chi-square
// test of the sampler against it.
//
// Analytic environments have no texels: bake them into a cubemap first (env/convert.hpp,
// bake_cubemap) and build the distribution from that (make_cube_env_distribution does both).
// The baked cube is then only the proposal; integrators still evaluate the analytic radiance.
// Lat-long maps: bake_cubemap(latlong, n, k) likewise (the proposal need not be the integrand).

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <stdexcept>
#include <string>
#include <vector>

#include "../core/color.hpp"
#include "../core/constants.hpp"
#include "../core/limits.hpp"
#include "../core/math.hpp"
#include "../core/vec.hpp"
#include "../env/convert.hpp"
#include "../env/cube_geometry.hpp"
#include "../env/cubemap.hpp"
#include "../env/environment.hpp"

namespace ibl {

/// Options of cube_env_distribution.
struct cube_env_distribution_options {
    int level = 0;                  ///< cubemap level the texel weights are read from
    bool tent_filter = true;        ///< (1/8, 3/4, 1/8)^2 filter (support of the bilinear lookup)
    double uniform_fraction = 0.0;  ///< defensive share f in [0, 1] spread by solid angle
};

/// One draw of cube_env_distribution::sample.
struct env_sample {
    vec3<double> dir{0.0, 0.0, 1.0}; ///< unit direction (towards the environment)
    double pdf = 0.0;                ///< per unit solid angle
    int face = 0, x = 0, y = 0;      ///< the texel drawn
};

/// Luminance-times-solid-angle distribution over the texels of a cubemap (see the header).
/// Throws std::invalid_argument for a level outside the chain, a uniform_fraction outside [0, 1]
/// or stale borders, std::length_error for a level larger than limits::max_distribution_size
/// (19 doubles per texel: choose a coarser level).
class cube_env_distribution {
public:
    template <class Tc>
    explicit cube_env_distribution(const cubemap<Tc>& cube, const cube_env_distribution_options& opt = {}) {
        if (opt.level < 0 || opt.level >= cube.levels())
            throw std::invalid_argument("ibl::cube_env_distribution: level " + std::to_string(opt.level) +
                                        " outside the cubemap's " + std::to_string(cube.levels()) + " levels");
        if (!(opt.uniform_fraction >= 0.0 && opt.uniform_fraction <= 1.0))
            throw std::invalid_argument("ibl::cube_env_distribution: uniform_fraction must be in [0, 1]");
        if (!cube.borders_valid())
            throw std::invalid_argument("ibl::cube_env_distribution: cubemap borders are stale "
                                        "(call generate_mips() or update_borders())");
        detail::check_total("cube_env_distribution", "face size of the level", cube.size(opt.level),
                            limits::max_distribution_size, "limits::max_distribution_size");
        n_ = cube.size(opt.level);
        const std::size_t n = std::size_t(n_), rows = 6 * n;
        const std::vector<double> omega = cube_face_solid_angles<double>(n_);
        std::vector<double> w(rows * n);
        double total = 0.0;
        for (int f = 0; f < 6; ++f)
            for (int y = 0; y < n_; ++y)
                for (int x = 0; x < n_; ++x) {
                    const double yv = texel_luminance(cube, f, x, y, opt);
                    const double wi = yv * omega[std::size_t(y) * n + std::size_t(x)];
                    w[cube_texel_index(f, x, y, n_)] = wi;
                    total += wi;
                }
        const double f_uni = total > 0.0 ? opt.uniform_fraction : 1.0;
        const double scale = total > 0.0 ? (1.0 - f_uni) / total : 0.0;
        for (std::size_t r = 0; r < rows; ++r)
            for (std::size_t x = 0; x < n; ++x)
                w[r * n + x] = scale * w[r * n + x] + f_uni * omega[(r % n) * n + x] * inv_four_pi_v<double>;
        build(w);
    }

    /// Face size of the level the distribution was built from.
    [[nodiscard]] int size() const noexcept { return n_; }

    /// Probability of texel (x, y) of face f (the product of the two CDF steps).
    [[nodiscard]] double texel_probability(int face, int x, int y) const noexcept {
        IBL_ASSERT(face >= 0 && face < 6 && x >= 0 && x < n_ && y >= 0 && y < n_);
        return p_[cube_texel_index(face, x, y, n_)];
    }

    /// Draws a direction. Domain: u in [0, 1)^2 (u.x picks the row (face, y) and the t offset,
    /// u.y the column x and the s offset; values outside are clamped). Range: unit directions,
    /// pdf per unit solid angle (> 0: a zero-probability texel is never drawn).
    [[nodiscard]] env_sample sample(const vec2<double>& u) const noexcept {
        const std::size_t n = std::size_t(n_), rows = 6 * n;
        double ox = 0.0, oy = 0.0;
        const std::size_t r = invert_cdf(row_cdf_.data(), rows, u.x, ox);
        const std::size_t x = invert_cdf(col_cdf_.data() + r * (n + 1), n, u.y, oy);
        env_sample s;
        s.face = int(r / n);
        s.y = int(r % n);
        s.x = int(x);
        const double inv_n = 1.0 / double(n_);
        const double sc = 2.0 * (double(s.x) + ox) * inv_n - 1.0;
        const double tc = 2.0 * (double(s.y) + oy) * inv_n - 1.0;
        const vec3<double> p = cube_face_point(s.face, sc, tc);
        const double len2 = 1.0 + sc * sc + tc * tc;
        s.dir = p * (1.0 / std::sqrt(len2));
        s.pdf = p_[(r * n) + x] * 0.25 * double(n_) * double(n_) * len2 * std::sqrt(len2);
        return s;
    }

    /// Density per unit solid angle of unit direction d (see the header): p_i (n^2/4) / |m|^3.
    /// The zero vector and NaN directions get the density of the centre of face +X's texel that
    /// cube_lookup assigns them (finite).
    [[nodiscard]] double pdf(const vec3<double>& d) const noexcept {
        using std::fabs;
        const cube_coord<double> c = cube_lookup(d);
        const int x = texel_index(c.s), y = texel_index(c.t);
        const double len = std::sqrt(glm::dot(d, d));
        const double m = std::max({fabs(d.x), fabs(d.y), fabs(d.z)});
        const double m_unit = len > 0.0 && m > 0.0 ? m / len : 1.0;
        return texel_probability(c.face, x, y) * 0.25 * double(n_) * double(n_) / (m_unit * m_unit * m_unit);
    }

private:
    template <class Tc>
    static double texel_luminance(const cubemap<Tc>& cube, int f, int x, int y, const cube_env_distribution_options& opt) {
        auto lum = [&](int xx, int yy) {
            const double l = double(luminance(vec3<double>(cube.texel(f, xx, yy, opt.level))));
            return is_finite(l) && l > 0.0 ? l : 0.0; // negative / non-finite texels carry no weight
        };
        if (!opt.tent_filter) return lum(x, y);
        static constexpr double k[3] = {0.125, 0.75, 0.125};
        double acc = 0.0;
        for (int j = -1; j <= 1; ++j)
            for (int i = -1; i <= 1; ++i) acc += k[i + 1] * k[j + 1] * lum(x + i, y + j); // borders: x, y in [-1, n]
        return acc;
    }

    int texel_index(double s) const noexcept {
        const int i = int(clamp(s, 0.0, 1.0) * double(n_));
        return i < n_ ? i : n_ - 1;
    }

    /// Index k with cdf[k] <= u < cdf[k + 1] (cdf has count + 1 entries from 0 to 1) and the
    /// offset (u - cdf[k]) / (cdf[k + 1] - cdf[k]) in [0, 1).
    static std::size_t invert_cdf(const double* cdf, std::size_t count, double u, double& offset) noexcept {
        const double uc = clamp(u, 0.0, one_minus_epsilon_v<double>);
        const double* it = std::upper_bound(cdf, cdf + count + 1, uc);
        std::size_t k = std::size_t(it - cdf);
        k = k > 0 ? k - 1 : 0;
        k = k < count ? k : count - 1;
        const double width = cdf[k + 1] - cdf[k];
        const double o = width > 0.0 ? (uc - cdf[k]) / width : 0.5;
        offset = o < 1.0 ? clamp(o, 0.0, 1.0) : one_minus_epsilon_v<double>;
        return k;
    }

    /// CDFs from the texel probabilities (already summing to 1 up to rounding).
    void build(const std::vector<double>& w) {
        const std::size_t n = std::size_t(n_), rows = 6 * n;
        row_cdf_.assign(rows + 1, 0.0);
        col_cdf_.assign(rows * (n + 1), 0.0);
        std::vector<double> row_sum(rows, 0.0);
        for (std::size_t r = 0; r < rows; ++r) {
            double* c = col_cdf_.data() + r * (n + 1);
            for (std::size_t x = 0; x < n; ++x) c[x + 1] = c[x] + w[r * n + x];
            row_sum[r] = c[n];
            for (std::size_t x = 1; x <= n; ++x)
                c[x] = row_sum[r] > 0.0 ? c[x] / row_sum[r] : double(x) / double(n);
            c[n] = 1.0;
            row_cdf_[r + 1] = row_cdf_[r] + row_sum[r];
        }
        const double total = row_cdf_[rows];
        for (std::size_t r = 1; r <= rows; ++r) row_cdf_[r] /= total;
        row_cdf_[rows] = 1.0;
        p_.assign(rows * n, 0.0);
        for (std::size_t r = 0; r < rows; ++r) {
            const double pr = row_cdf_[r + 1] - row_cdf_[r];
            const double* c = col_cdf_.data() + r * (n + 1);
            for (std::size_t x = 0; x < n; ++x) p_[r * n + x] = pr * (c[x + 1] - c[x]);
        }
    }

    int n_ = 1;
    std::vector<double> row_cdf_; ///< 6 n + 1 entries, rows (face, y) in order
    std::vector<double> col_cdf_; ///< per row n + 1 entries
    std::vector<double> p_;       ///< texel probabilities, the products of the CDF steps
};

/// Distribution of any environment: bakes it into a cubemap of face size n with k x k
/// sub-samples per texel (bake_cubemap, level 0 only) and builds the distribution from that.
/// The cube is only the proposal; estimators keep evaluating env itself. n and k as bake_cubemap
/// (n also <= limits::max_distribution_size).
template <class T, class Env>
    requires environment<Env, T>
cube_env_distribution make_cube_env_distribution(const Env& env, int n, int k,
                                                 const cube_env_distribution_options& opt = {}) {
    detail::check_bake_args("make_cube_env_distribution", n, k);
    detail::check_total("make_cube_env_distribution", "n", n, limits::max_distribution_size,
                        "limits::max_distribution_size");
    const cubemap<T> cube = bake_cubemap<T>(env, n, k, serial_executor{}, 1);
    return cube_env_distribution(cube, opt);
}

} // namespace ibl

#endif // IBL_DETAIL_CXX20
