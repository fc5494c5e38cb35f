#pragma once
// ibl/sh/project.hpp — projection of radiance onto the real SH basis of sh/basis.hpp:
//
//   L_k = integral over the sphere of L(w) Y_k(w) dw,   k < B*B.
//
// Three sources, one kernel. Every driver walks the sphere in "rows" of directions (a face row of
// a cube, an image row of a lat-long map, a ring of the quadrature), and for each row evaluates
//
//   sum_i w_i L(d_i) p_k(d_i)        (p_k the unnormalised polynomial of Y_k = K_k p_k)
//
// with the weights w_i the EXACT solid angle of the texel (or the quadrature weight). The row is
// cut into chunks of detail::sh_chunk directions held as structure-of-arrays in double (x[], y[],
// z[], weighted r[], g[], b[]); the polynomial terms of a chunk are evaluated in one vectorised
// loop, and the products are accumulated elementwise into sh_chunk double partial sums per
// (k, channel) that live for the whole row (one SIMD lane per chunk position, no reduction in the
// hot loop). At the end of a row the partial sums are added pairwise and the row sum goes into a
// Neumaier compensated sum. Error of a coefficient: about (n / sh_chunk + 5) eps(double)
// sum_i |w_i L_i p_k| from the rows plus 2 eps(double) from the compensated row sums, i.e. far
// below the rounding of float inputs; K_k is applied at the end, in double. Only the radiance
// values themselves are of type T.
//
// Determinism. A row (for cubes: row y of all six faces) is one block of parallel_reduce_blocks
// (core/executor.hpp): block results are combined in row order, so the coefficients are bit-identical for every executor and thread
// count. The drivers are host-only (the executor allocates); the basis itself is device-ready.
//
// Sources:
//   project_cube(n, fetch, ex)            fetch(face, x, y) -> vec3<T>: n x n texels per face,
//                                         faces and orientation of env/cube_geometry.hpp; weight =
//                                         exact texel solid angle (cube_geometry's antiderivative,
//                                         in double), direction = texel centre.
//   project_cube(cube, ex, level)         any type with cube.size(level) and
//                                         cube.texel(face, x, y, level) -> vec3<T> (ibl::cubemap).
//   project_latlong(img, ex, level)       any type with img.width(level), img.height(level) and
//                                         img.texel(x, y, level) -> vec3<T> (ibl::latlong).
//   project_latlong(W, H, fetch, ex)      fetch(x, y) -> vec3<T>; u = 0.5 + atan2(z, x)/(2pi),
//                                         v = 0.5 + asin(y)/pi, row 0 = +Y (row j covers v from
//                                         1 - j/H down to 1 - (j+1)/H); weight = exact row solid
//                                         angle / W, direction = texel centre.
//   project_function<B, T>(f, degree, ex) f(dir) -> vec3<T> or f.radiance(dir, lod) (lod 0);
//                                         the product quadrature below, EXACT (up to rounding) when
//                                         L is, on each hemisphere y >= 0 and y <= 0 separately, a
//                                         polynomial of degree <= `degree` in (x, y, z) (so for
//                                         any band-limited L of band <= degree, and for skies with
//                                         a hard horizon such as 1[y > 0] or max(0, y)).
//
// Quadrature of project_function. Poles on the +Y (up) axis. The integrand L Y_k has degree at
// most D = degree + B - 1. In y: Gauss-Legendre with N = ceil((D + 1)/2) nodes on each of [0, 1]
// and [-1, 0] (exact for degree 2N - 1 >= D on each half). In phi (angle about +Y): M = D + 1
// equally spaced points phi_j = 2pi (j + 1/2)/M (exact for trigonometric polynomials of degree
// <= M - 1 = D). A monomial x^a y^b z^c restricted to the sphere integrates over phi to 0 unless
// a and c are even, and then to a polynomial of degree a + b + c in y, so the product rule is
// exact for every polynomial of degree <= D on each hemisphere. 2N M directions in total.

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <algorithm>
#include <cmath>
#include <concepts>
#include <cstddef>
#include <cstdlib>
#include <limits>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "../core/gauss_legendre.hpp"
#include "../core/constants.hpp"
#include "../core/executor.hpp"
#include "../core/limits.hpp"
#include "../core/math.hpp"
#include "../core/sum.hpp"
#include "../core/vec.hpp"
#include "../env/cube_geometry.hpp"
#include "basis.hpp"

namespace ibl {

namespace detail {

inline constexpr int sh_chunk = 32; ///< directions per SoA chunk = partial sums per row and coefficient

/// Compensated double accumulators of sum w L p_k, one per (coefficient, channel).
template <int B> struct sh_accumulator {
    neumaier_sum<double> s[B * B][3];

    void merge(const sh_accumulator& o) noexcept {
        for (int k = 0; k < B * B; ++k)
            for (int ch = 0; ch < 3; ++ch) s[k][ch].merge(o.s[k][ch]);
    }
    template <class T> [[nodiscard]] sh_coeffs<T, B> result() const noexcept {
        sh_coeffs<T, B> r;
        for (int k = 0; k < B * B; ++k) {
            const double kk = sh_norm<double>(k);
            r.c[k] = vec3<T>(T(kk * s[k][0].value()), T(kk * s[k][1].value()), T(kk * s[k][2].value()));
        }
        return r;
    }
};

/// The partial sums of one row: one double sum per (coefficient, channel, chunk position i), so
/// the accumulation is an elementwise multiply-add over the chunk (no reduction inside the hot
/// loop: every compiler vectorises it without reassociation).
template <int B> struct sh_row_sums {
    alignas(64) double s[B * B][3][sh_chunk] = {};

    /// Adds the row's sums (the 32 chunk positions added in a fixed tree) to the compensated
    /// accumulator.
    void finish(sh_accumulator<B>& acc) const noexcept {
        static_assert(sh_chunk == 32, "the fixed reduction tree assumes 32 positions");
        for (int k = 0; k < B * B; ++k)
            for (int ch = 0; ch < 3; ++ch) {
                const double* v = s[k][ch];
                double t[8];
                for (int l = 0; l < 8; ++l) t[l] = (v[l] + v[l + 8]) + (v[l + 16] + v[l + 24]);
                acc.s[k][ch].add(((t[0] + t[1]) + (t[2] + t[3])) + ((t[4] + t[5]) + (t[6] + t[7])));
            }
    }
};

/// One chunk of directions and weighted radiance in structure-of-arrays form (double).
template <int B> struct sh_chunk_buffer {
    alignas(64) double x[sh_chunk];
    alignas(64) double y[sh_chunk];
    alignas(64) double z[sh_chunk];
    alignas(64) double r[sh_chunk]; ///< weight * radiance, red
    alignas(64) double g[sh_chunk];
    alignas(64) double b[sh_chunk];
    alignas(64) double p[B * B][sh_chunk]; ///< polynomial terms p_k of each direction
};

/// Adds (r, g, b)[i] p_k(x[i], y[i], z[i]) for i < m to the row sums (position by position).
template <int B> void sh_accumulate_chunk(sh_chunk_buffer<B>& c, int m, sh_row_sums<B>& sums) noexcept {
    for (int i = 0; i < m; ++i)
        sh_poly_terms<B>(c.x[i], c.y[i], c.z[i], [&](int k, double v) { c.p[k][i] = v; });
    for (int k = 0; k < B * B; ++k)
        for (int i = 0; i < m; ++i) {
            const double pk = c.p[k][i];
            sums.s[k][0][i] += c.r[i] * pk;
            sums.s[k][1][i] += c.g[i] * pk;
            sums.s[k][2][i] += c.b[i] * pk;
        }
}

template <class T> void sh_store_weighted(double* r, double* g, double* b, int i, double w, const vec3<T>& L) noexcept {
    r[i] = w * double(L.x);
    g[i] = w * double(L.y);
    b[i] = w * double(L.z);
}

/// Exact texel solid angles of an n x n face from the antiderivative F(a, b) of cube_geometry.hpp
/// on the grid a_i = (2i - n)/n. a_{n-i} = -a_i exactly (integer numerator), F is odd in each
/// argument and symmetric, so only the quadrant a, b >= 0 with a <= b is evaluated
/// ((n/2 + 1)^2 / 2 arctangents instead of 4 n^2). Texel weights are differences of grid values,
/// so the 6 n^2 weights telescope to 4 pi up to the rounding of the final sum.
class cube_weight_table {
public:
    explicit cube_weight_table(int n) : n_(n), k_(n / 2 + 1), f_(std::size_t(k_) * std::size_t(k_)) {
        const double inv = 1.0 / double(n);
        for (int i = 0; i < k_; ++i)
            for (int j = i; j < k_; ++j) {
                const double a = double(2 * i + (n & 1)) * inv, b = double(2 * j + (n & 1)) * inv;
                const double f = detail::cube_area_antiderivative(a, b);
                f_[std::size_t(i) * k_ + j] = f;
                f_[std::size_t(j) * k_ + i] = f;
            }
    }
    /// F(a_i, a_j) for grid indices i, j in [0, n].
    [[nodiscard]] double grid(int i, int j) const noexcept {
        const int ti = 2 * i - n_, tj = 2 * j - n_;
        const double s = double((ti > 0) - (ti < 0)) * double((tj > 0) - (tj < 0));
        return s * f_[std::size_t(std::abs(ti) / 2) * k_ + std::size_t(std::abs(tj) / 2)];
    }
    /// Exact solid angle of texel (x, y) (any face).
    [[nodiscard]] double texel(int x, int y) const noexcept {
        return grid(x + 1, y + 1) - grid(x, y + 1) - grid(x + 1, y) + grid(x, y);
    }

private:
    int n_, k_;
    std::vector<double> f_;
};

/// Gauss-Legendre nodes and weights on [-1, 1] (n >= 1; weights sum to 2, nodes ascend):
/// core/gauss_legendre.hpp's rule.
inline void gauss_legendre(int n, std::vector<double>& node, std::vector<double>& weight) {
    gauss_legendre_rule r = make_gauss_legendre_symmetric(std::size_t(n));
    node = std::move(r.x);
    weight = std::move(r.w);
}

/// A row of a "latitude ring" source (lat-long row or quadrature ring): directions
/// (cos_lat cos phi_i, sin_lat, cos_lat sin phi_i) with one weight for the whole row;
/// radiance(i, dir) -> vec3<T> gives the radiance of entry i (dir rounded to T).
template <int B, class T, class Radiance>
sh_accumulator<B> sh_ring_row(const double* cos_phi, const double* sin_phi, int count, double sin_lat, double cos_lat,
                              double weight, Radiance&& radiance) {
    sh_accumulator<B> acc;
    sh_row_sums<B> sums;
    sh_chunk_buffer<B> c;
    for (int i0 = 0; i0 < count; i0 += sh_chunk) {
        const int m = std::min(sh_chunk, count - i0);
        for (int i = 0; i < m; ++i) {
            c.x[i] = cos_lat * cos_phi[i0 + i];
            c.y[i] = sin_lat;
            c.z[i] = cos_lat * sin_phi[i0 + i];
        }
        for (int i = 0; i < m; ++i)
            sh_store_weighted(c.r, c.g, c.b, i, weight, vec3<T>(radiance(i0 + i, vec3<T>(T(c.x[i]), T(c.y[i]), T(c.z[i])))));
        sh_accumulate_chunk<B>(c, m, sums);
    }
    sums.finish(acc);
    return acc;
}

/// level >= 0, and level < src.levels() when the source type has levels().
template <class Src> void check_sh_level(const char* fn, const Src& src, int level) {
    int count = std::numeric_limits<int>::max();
    if constexpr (requires { { src.levels() } -> std::convertible_to<int>; }) count = int(src.levels());
    if (level < 0 || level >= count)
        throw std::invalid_argument(std::string("ibl::") + fn + ": level = " + std::to_string(level) +
                                    " outside [0, " + std::to_string(count) + ")");
}

template <class F, class T>
concept sh_direction_callable = requires(const F& f, vec3<T> d) {
    { f(d) } -> std::convertible_to<vec3<T>>;
};
template <class F, class T>
concept sh_radiance_source = requires(const F& f, vec3<T> d) {
    { f.radiance(d, T(0)) } -> std::convertible_to<vec3<T>>;
};

} // namespace detail

/// Projection of an n x n-per-face cube given texel by texel: fetch(face, x, y) -> vec3<T> is the
/// radiance of texel (x, y) of face 0..5 (cube_geometry.hpp). Returns radiance SH coefficients.
/// Throws std::invalid_argument for n < 1, std::length_error for n > limits::max_face_size.
template <int B, class Fetch, class Executor = serial_executor>
auto project_cube(int n, Fetch&& fetch, Executor&& ex = {}) {
    using V = std::remove_cvref_t<decltype(fetch(0, 0, 0))>;
    using T = typename V::value_type;
    detail::check_arg("project_cube", "n", n, 1, limits::max_face_size, "limits::max_face_size");
    const detail::cube_weight_table table(n);
    const double inv_n = 1.0 / double(n);
    using dvec = vec3<double>;
    // Block y holds row y of all six faces: the texel solid angles and the lengths of the face
    // points depend only on (x, y), so they are computed once per block for the six faces.
    auto row = [&](std::size_t block) {
        detail::sh_accumulator<B> acc;
        detail::sh_row_sums<B> sums;
        const int y = int(block);
        const double tc = double(2 * y + 1 - n) * inv_n;
        const double tc2p1 = tc * tc + 1.0;
        detail::sh_chunk_buffer<B> c;
        alignas(64) double w[detail::sh_chunk], sc[detail::sh_chunk], inv_len[detail::sh_chunk];
        for (int i0 = 0; i0 < n; i0 += detail::sh_chunk) {
            const int m = std::min(detail::sh_chunk, n - i0);
            for (int i = 0; i < m; ++i) w[i] = table.texel(i0 + i, y);
            for (int i = 0; i < m; ++i) {
                sc[i] = double(2 * (i0 + i) + 1 - n) * inv_n;
                inv_len[i] = 1.0 / std::sqrt(sc[i] * sc[i] + tc2p1);
            }
            for (int face = 0; face < 6; ++face) {
                // face point (sc, tc) = e_n + sc e_s + tc e_t (cube_face_point is affine)
                const dvec e_n = cube_face_point(face, 0.0, 0.0);
                const dvec e_s = cube_face_point(face, 1.0, 0.0) - e_n;
                const dvec base = e_n + tc * (cube_face_point(face, 0.0, 1.0) - e_n);
                for (int i = 0; i < m; ++i) {
                    c.x[i] = (base.x + sc[i] * e_s.x) * inv_len[i];
                    c.y[i] = (base.y + sc[i] * e_s.y) * inv_len[i];
                    c.z[i] = (base.z + sc[i] * e_s.z) * inv_len[i];
                }
                for (int i = 0; i < m; ++i)
                    detail::sh_store_weighted(c.r, c.g, c.b, i, w[i], vec3<T>(fetch(face, i0 + i, y)));
                detail::sh_accumulate_chunk<B>(c, m, sums);
            }
        }
        sums.finish(acc);
        return acc;
    };
    const auto acc = parallel_reduce_blocks(ex, std::size_t(n), detail::sh_accumulator<B>{}, row,
                                            [](detail::sh_accumulator<B> a, const detail::sh_accumulator<B>& b) {
                                                a.merge(b);
                                                return a;
                                            });
    return acc.template result<T>();
}

/// Projection of level `level` of a cube object with the face-texel accessor interface
///   cube.size(level) -> int (face size), cube.texel(face, x, y, level) -> vec3<T>
/// (ibl::cubemap<T> satisfies it). Throws std::invalid_argument for level < 0, or level >=
/// cube.levels() when the type has levels().
template <int B, class Cube, class Executor = serial_executor>
    requires requires(const Cube& c) {
        { c.size(0) } -> std::convertible_to<int>;
        c.texel(0, 0, 0, 0);
    }
auto project_cube(const Cube& cube, Executor&& ex = {}, int level = 0) {
    detail::check_sh_level("project_cube", cube, level);
    return project_cube<B>(
        int(cube.size(level)), [&](int face, int x, int y) { return cube.texel(face, x, y, level); },
        std::forward<Executor>(ex));
}

/// Projection of a width x height lat-long image, fetch(x, y) -> vec3<T> (x = column from u = 0,
/// y = row from the top = +Y). Row j spans latitudes [lat_b, lat_t] = pi/2 - [(j+1), j] pi/H; its
/// texels have the exact solid angle (2pi/W)(sin lat_t - sin lat_b), evaluated as
/// (2pi/W) 2 cos(lat_c) sin(pi/(2H)) (no cancellation at the poles).
/// Throws std::invalid_argument for a side < 1, std::length_error for a side > limits::max_face_size.
template <int B, class Fetch, class Executor = serial_executor>
auto project_latlong(int width, int height, Fetch&& fetch, Executor&& ex = {}) {
    using V = std::remove_cvref_t<decltype(fetch(0, 0))>;
    using T = typename V::value_type;
    detail::check_arg("project_latlong", "width", width, 1, limits::max_face_size, "limits::max_face_size");
    detail::check_arg("project_latlong", "height", height, 1, limits::max_face_size, "limits::max_face_size");
    std::vector<double> cos_phi(static_cast<std::size_t>(width)), sin_phi(static_cast<std::size_t>(width));
    for (int i = 0; i < width; ++i) {
        const double phi = two_pi_v<double> * (double(i) + 0.5) / double(width) - pi_v<double>;
        cos_phi[std::size_t(i)] = std::cos(phi);
        sin_phi[std::size_t(i)] = std::sin(phi);
    }
    const double half_row = pi_v<double> / (2.0 * double(height));
    const double row_factor = two_pi_v<double> / double(width) * 2.0 * std::sin(half_row);
    auto row = [&](std::size_t block) {
        const int j = int(block);
        const double lat = half_pi_v<double> - (2.0 * double(j) + 1.0) * half_row;
        const double s = std::sin(lat), c = std::cos(lat);
        return detail::sh_ring_row<B, T>(cos_phi.data(), sin_phi.data(), width, s, c, row_factor * c,
                                         [&](int i, const vec3<T>&) { return vec3<T>(fetch(i, j)); });
    };
    const auto acc = parallel_reduce_blocks(ex, std::size_t(height), detail::sh_accumulator<B>{}, row,
                                            [](detail::sh_accumulator<B> a, const detail::sh_accumulator<B>& b) {
                                                a.merge(b);
                                                return a;
                                            });
    return acc.template result<T>();
}

/// Projection of level `level` of a lat-long image object with the accessor interface
///   img.width(level), img.height(level) -> int, img.texel(x, y, level) -> vec3<T>
/// (ibl::latlong<T> satisfies it; same orientation as the fetch overload). Level checked as
/// project_cube's.
template <int B, class Image, class Executor = serial_executor>
    requires requires(const Image& img) {
        { img.width(0) } -> std::convertible_to<int>;
        { img.height(0) } -> std::convertible_to<int>;
        img.texel(0, 0, 0);
    }
auto project_latlong(const Image& img, Executor&& ex = {}, int level = 0) {
    detail::check_sh_level("project_latlong", img, level);
    return project_latlong<B>(
        int(img.width(level)), int(img.height(level)), [&](int x, int y) { return img.texel(x, y, level); },
        std::forward<Executor>(ex));
}

/// Node counts of project_function's quadrature for a given `degree` (see the header comment).
template <int B> struct sh_quadrature_size {
    int nodes_per_hemisphere; ///< N (Gauss-Legendre in y on each half)
    int azimuths;             ///< M (uniform in phi)
    int exact_degree;         ///< D = degree + B - 1: integrand degree integrated exactly
};
/// degree is clamped to [0, limits::max_sh_degree] (no int overflow; project_function throws above).
template <int B> [[nodiscard]] inline sh_quadrature_size<B> sh_quadrature_for(int degree) noexcept {
    const int d = std::clamp(degree, 0, limits::max_sh_degree) + B - 1;
    return {(d + 2) / 2, d + 1, d};
}

/// Projection of a direction -> radiance function (f(dir) -> vec3<T>) or of an environment
/// (f.radiance(dir, lod) -> vec3<T>, read at lod 0) by the deterministic product quadrature of
/// the header comment: exact for radiance that is a polynomial of degree <= `degree` on each
/// hemisphere (y >= 0, y <= 0), spectrally convergent for smooth radiance as `degree` grows.
/// Rings (one per y node) are the blocks of the executor. A negative degree counts as 0;
/// degree > limits::max_sh_degree throws std::length_error.
template <int B, class T, class F, class Executor = serial_executor>
    requires detail::sh_direction_callable<F, T> || detail::sh_radiance_source<F, T>
sh_coeffs<T, B> project_function(const F& f, int degree, Executor&& ex = {}) {
    detail::check_total("project_function", "degree", degree, limits::max_sh_degree, "limits::max_sh_degree");
    const auto q = sh_quadrature_for<B>(degree);
    std::vector<double> node, weight;
    detail::gauss_legendre(q.nodes_per_hemisphere, node, weight);
    const int m = q.azimuths;
    std::vector<double> cos_phi(static_cast<std::size_t>(m)), sin_phi(static_cast<std::size_t>(m));
    for (int i = 0; i < m; ++i) {
        const double phi = two_pi_v<double> * (double(i) + 0.5) / double(m);
        cos_phi[std::size_t(i)] = std::cos(phi);
        sin_phi[std::size_t(i)] = std::sin(phi);
    }
    const int n = q.nodes_per_hemisphere;
    auto ring = [&](std::size_t block) {
        // rings 0..n-1: y in (0, 1); rings n..2n-1: y in (-1, 0). y = (1 + t)/2 on [0, 1].
        const int i = int(block % std::size_t(n));
        const double y = 0.5 * (1.0 + node[std::size_t(i)]) * (block < std::size_t(n) ? 1.0 : -1.0);
        const double cos_lat = sin_from_cos(y);
        const double w = 0.5 * weight[std::size_t(i)] * two_pi_v<double> / double(m);
        return detail::sh_ring_row<B, T>(cos_phi.data(), sin_phi.data(), m, y, cos_lat, w, [&](int, const vec3<T>& d) {
            if constexpr (detail::sh_direction_callable<F, T>)
                return vec3<T>(f(d));
            else
                return vec3<T>(f.radiance(d, T(0)));
        });
    };
    const auto acc = parallel_reduce_blocks(ex, std::size_t(2 * n), detail::sh_accumulator<B>{}, ring,
                                            [](detail::sh_accumulator<B> a, const detail::sh_accumulator<B>& b) {
                                                a.merge(b);
                                                return a;
                                            });
    return acc.template result<T>();
}

} // namespace ibl

#endif // IBL_DETAIL_CXX20
