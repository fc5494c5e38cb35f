#pragma once
// ibl/sh/basis.hpp — the real spherical-harmonic basis, band count B in [1, 5] (B*B functions).
//
// Definition. Orthonormal real SH WITHOUT the Condon-Shortley phase (every normalisation constant
// is positive), written as polynomials in the components (x, y, z) of a UNIT direction in the
// library's world frame (right-handed, +Y up; see DESIGN.md). No trigonometry is involved.
//
//   Y_lm = K_lm p_lm(x, y, z),     integral over the sphere of Y_lm Y_l'm' = delta_ll' delta_mm'.
//
// Frame. The usual Cartesian formulas are used verbatim on the world components, so
//   Y_1,-1 ~ y,  Y_1,0 ~ z,  Y_1,1 ~ x
// (the common graphics convention: Sloan's "Stupid SH tricks" up to the phase, Ramamoorthi &
// Hanrahan 2001 and Filament's libibl). The zonal functions Y_l0 are therefore symmetric about
// world +Z, NOT about the +Y up axis; nothing in the library depends on which axis is zonal.
//
// Ordering. Coefficient index k = l*l + l + m for (l, m), m in [-l, l]:
//
//   k  (l, m)   K_lm                    p_lm
//   0  (0, 0)   1/(2 sqrt(pi))          1
//   1  (1,-1)   sqrt(3/(4pi))           y
//   2  (1, 0)   sqrt(3/(4pi))           z
//   3  (1, 1)   sqrt(3/(4pi))           x
//   4  (2,-2)   sqrt(15/pi)/2           x y
//   5  (2,-1)   sqrt(15/pi)/2           y z
//   6  (2, 0)   sqrt(5/pi)/4            3 z^2 - 1
//   7  (2, 1)   sqrt(15/pi)/2           x z
//   8  (2, 2)   sqrt(15/pi)/4           x^2 - y^2
//   9  (3,-3)   sqrt(35/(2pi))/4        y (3 x^2 - y^2)
//  10  (3,-2)   sqrt(105/pi)/2          x y z
//  11  (3,-1)   sqrt(21/(2pi))/4        y (5 z^2 - 1)
//  12  (3, 0)   sqrt(7/pi)/4            z (5 z^2 - 3)
//  13  (3, 1)   sqrt(21/(2pi))/4        x (5 z^2 - 1)
//  14  (3, 2)   sqrt(105/pi)/4          z (x^2 - y^2)
//  15  (3, 3)   sqrt(35/(2pi))/4        x (x^2 - 3 y^2)
//  16  (4,-4)   3 sqrt(35/pi)/4         x y (x^2 - y^2)
//  17  (4,-3)   3 sqrt(35/(2pi))/4      y z (3 x^2 - y^2)
//  18  (4,-2)   3 sqrt(5/pi)/4          x y (7 z^2 - 1)
//  19  (4,-1)   3 sqrt(5/(2pi))/4       y z (7 z^2 - 3)
//  20  (4, 0)   3/(16 sqrt(pi))         35 z^4 - 30 z^2 + 3
//  21  (4, 1)   3 sqrt(5/(2pi))/4       x z (7 z^2 - 3)
//  22  (4, 2)   3 sqrt(5/pi)/8          (x^2 - y^2)(7 z^2 - 1)
//  23  (4, 3)   3 sqrt(35/(2pi))/4      x z (x^2 - 3 y^2)
//  24  (4, 4)   3 sqrt(35/pi)/16        x^2 (x^2 - 3 y^2) - y^2 (3 x^2 - y^2)
//
// In spherical coordinates about +Z (x = sin t cos f, y = sin t sin f, z = cos t) this is
// Y_lm = sqrt(2) N_l|m| P_l^|m|(cos t) cos(m f) for m > 0, sqrt(2) N_l|m| P_l^|m| sin(|m| f) for
// m < 0 and N_l0 P_l for m = 0, with N_lm = sqrt((2l+1)/(4pi) (l-m)!/(l+m)!) and P_l^m without
// the (-1)^m phase. tests/test_sh.cpp checks the table against that trigonometric definition.
//
// The polynomials assume |dir| = 1 (3z^2 - 1 stands for 3z^2 - |dir|^2); callers normalise.

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <cstddef>
#include <span>

#include "../core/vec.hpp"

namespace ibl {

/// Number of coefficients of a B-band expansion.
template <int B> inline constexpr int sh_count = B * B;

/// Index of (l, m) in the coefficient arrays: l*l + l + m.
IBL_FUNC constexpr int sh_index(int l, int m) noexcept { return l * l + l + m; }

/// Band l of coefficient index k (floor(sqrt(k))).
IBL_FUNC constexpr int sh_band_of(int k) noexcept {
    int l = 0;
    while ((l + 1) * (l + 1) <= k) ++l;
    return l;
}

/// Normalisation constant K_k of basis function k (table above), k in [0, 25); 0 outside.
/// A switch rather than a table: folds to a constant once k is known, and needs no array in
/// device memory.
template <class T> IBL_FUNC constexpr T sh_norm(int k) noexcept {
    switch (k) {
    case 0: return T(0.282094791773878143474L);                                  // 1/(2 sqrt(pi))
    case 1: case 2: case 3: return T(0.488602511902919921586L);                  // sqrt(3/(4pi))
    case 4: case 5: case 7: return T(1.09254843059207907054L);                   // sqrt(15/pi)/2
    case 6: return T(0.315391565252520006031L);                                  // sqrt(5/pi)/4
    case 8: return T(0.546274215296039535272L);                                  // sqrt(15/pi)/4
    case 9: case 15: return T(0.590043589926643510346L);                         // sqrt(35/(2pi))/4
    case 10: return T(2.89061144264055405539L);                                  // sqrt(105/pi)/2
    case 11: case 13: return T(0.457045799464465736158L);                        // sqrt(21/(2pi))/4
    case 12: return T(0.373176332590115391414L);                                 // sqrt(7/pi)/4
    case 14: return T(1.44530572132027702769L);                                  // sqrt(105/pi)/4
    case 16: return T(2.50334294179670453835L);                                  // 3 sqrt(35/pi)/4
    case 17: case 23: return T(1.77013076977993053104L);                         // 3 sqrt(35/(2pi))/4
    case 18: return T(0.946174695757560018093L);                                 // 3 sqrt(5/pi)/4
    case 19: case 21: return T(0.669046543557289167952L);                        // 3 sqrt(5/(2pi))/4
    case 20: return T(0.105785546915204303803L);                                 // 3/(16 sqrt(pi))
    case 22: return T(0.473087347878780009046L);                                 // 3 sqrt(5/pi)/8
    case 24: return T(0.625835735449176134587L);                                 // 3 sqrt(35/pi)/16
    default: return T(0);
    }
}

/// B*B scalars, one per basis function (basis values, polynomial terms, window factors...).
template <class T, int B> struct sh_values {
    static_assert(B >= 1 && B <= 5, "ibl::sh supports 1 to 5 bands");
    static constexpr int count = B * B;
    T v[count]{};
    IBL_FUNC T& operator[](int k) noexcept { return v[k]; }
    IBL_FUNC const T& operator[](int k) const noexcept { return v[k]; }
};

/// RGB coefficients of a B-band expansion: c[k] holds the three channels of coefficient k.
/// A plain aggregate (no heap, no std:: containers), usable in device code; zero-initialised.
template <class T, int B> struct sh_coeffs {
    static_assert(B >= 1 && B <= 5, "ibl::sh supports 1 to 5 bands");
    using value_type = T;
    static constexpr int bands = B;
    static constexpr int count = B * B;
    vec3<T> c[count]{};
    IBL_FUNC vec3<T>& operator[](int k) noexcept { return c[k]; }
    IBL_FUNC const vec3<T>& operator[](int k) const noexcept { return c[k]; }
};

template <class T, int B>
IBL_FUNC sh_coeffs<T, B> operator+(const sh_coeffs<T, B>& a, const sh_coeffs<T, B>& b) noexcept {
    sh_coeffs<T, B> r;
    for (int k = 0; k < B * B; ++k) r.c[k] = a.c[k] + b.c[k];
    return r;
}
template <class T, int B>
IBL_FUNC sh_coeffs<T, B> operator-(const sh_coeffs<T, B>& a, const sh_coeffs<T, B>& b) noexcept {
    sh_coeffs<T, B> r;
    for (int k = 0; k < B * B; ++k) r.c[k] = a.c[k] - b.c[k];
    return r;
}
template <class T, int B> IBL_FUNC sh_coeffs<T, B> operator*(T s, const sh_coeffs<T, B>& a) noexcept {
    sh_coeffs<T, B> r;
    for (int k = 0; k < B * B; ++k) r.c[k] = s * a.c[k];
    return r;
}

/// Multiplies band l of `a` by band_factor[l] (convolution with a zonal kernel, windowing).
template <class T, int B>
IBL_FUNC sh_coeffs<T, B> sh_scale_bands(const sh_coeffs<T, B>& a, const T (&band_factor)[B]) noexcept {
    sh_coeffs<T, B> r;
    for (int l = 0; l < B; ++l)
        for (int m = -l; m <= l; ++m) r.c[sh_index(l, m)] = band_factor[l] * a.c[sh_index(l, m)];
    return r;
}

namespace detail {
/// The single source of the basis: calls emit(k, p_k(x, y, z)) for k < B*B with the unnormalised
/// polynomial terms of the table. V is the arithmetic type (a scalar or one SIMD lane of a loop
/// the compiler vectorises); k is a compile-time constant after inlining.
template <int B, class V, class Emit> IBL_FUNC_VOID void sh_poly_terms(V x, V y, V z, Emit&& emit) noexcept {
    emit(0, V(1));
    if constexpr (B > 1) {
        emit(1, y);
        emit(2, z);
        emit(3, x);
    }
    if constexpr (B > 2) {
        const V x2 = x * x, y2 = y * y, z2 = z * z;
        emit(4, x * y);
        emit(5, y * z);
        emit(6, V(3) * z2 - V(1));
        emit(7, x * z);
        emit(8, x2 - y2);
        if constexpr (B > 3) {
            const V a = V(3) * x2 - y2; // y (3x^2 - y^2), z (x^2 - y^2) ...
            const V b = x2 - V(3) * y2;
            const V c = V(5) * z2 - V(1);
            emit(9, y * a);
            emit(10, x * y * z);
            emit(11, y * c);
            emit(12, z * (V(5) * z2 - V(3)));
            emit(13, x * c);
            emit(14, z * (x2 - y2));
            emit(15, x * b);
            if constexpr (B > 4) {
                const V d = V(7) * z2 - V(1);
                const V e = V(7) * z2 - V(3);
                emit(16, x * y * (x2 - y2));
                emit(17, y * z * a);
                emit(18, x * y * d);
                emit(19, y * z * e);
                emit(20, (V(35) * z2 - V(30)) * z2 + V(3));
                emit(21, x * z * e);
                emit(22, (x2 - y2) * d);
                emit(23, x * z * b);
                emit(24, x2 * b - y2 * a);
            }
        }
    }
}
} // namespace detail

/// The B*B basis values Y_k(dir) of a unit direction.
template <int B, class T> IBL_FUNC sh_values<T, B> sh_basis(const vec3<T>& dir) noexcept {
    sh_values<T, B> r;
    detail::sh_poly_terms<B>(dir.x, dir.y, dir.z, [&](int k, T p) { r.v[k] = sh_norm<T>(k) * p; });
    return r;
}

/// The unnormalised polynomial terms p_k(dir) (Y_k = K_k p_k): what a shader forms.
template <int B, class T> IBL_FUNC sh_values<T, B> sh_poly(const vec3<T>& dir) noexcept {
    sh_values<T, B> r;
    detail::sh_poly_terms<B>(dir.x, dir.y, dir.z, [&](int k, T p) { r.v[k] = p; });
    return r;
}

/// Batch evaluation over structure-of-arrays unit directions: for i < count,
///   out[k * stride + i] = Y_k(x[i], y[i], z[i]),  k < B*B   (planar outputs, stride >= count).
/// The output planes must not overlap the inputs. Directions are processed in blocks of
/// detail::sh_batch_block: the block is evaluated into a local planar buffer (fixed trip count,
/// compile-time plane offsets: the loop vectorises with one SIMD lane per direction), then copied
/// to the planes (with a runtime stride, the compiler cannot prove the planes disjoint, so the
/// kernel does not store to them directly).
namespace detail {
inline constexpr int sh_batch_block = 32;

template <int B, int N, class T>
IBL_FUNC_VOID void sh_basis_block(const T* IBL_RESTRICT x, const T* IBL_RESTRICT y, const T* IBL_RESTRICT z,
                                  T (&buf)[B * B][N]) noexcept {
    for (int i = 0; i < N; ++i)
        sh_poly_terms<B>(x[i], y[i], z[i], [&](int k, T p) { buf[k][i] = sh_norm<T>(k) * p; });
}
} // namespace detail

template <int B, class T>
IBL_FUNC_VOID void sh_basis_batch(const T* IBL_RESTRICT x, const T* IBL_RESTRICT y, const T* IBL_RESTRICT z,
                                  std::size_t count, T* IBL_RESTRICT out, std::size_t stride) noexcept {
    constexpr int n = detail::sh_batch_block;
    T buf[B * B][n];
    std::size_t i0 = 0;
    for (; i0 + n <= count; i0 += n) {
        detail::sh_basis_block<B, n>(x + i0, y + i0, z + i0, buf);
        for (int k = 0; k < B * B; ++k)
            for (int i = 0; i < n; ++i) out[std::size_t(k) * stride + i0 + std::size_t(i)] = buf[k][i];
    }
    for (std::size_t i = i0; i < count; ++i) // tail: the same kernel at width 1
        detail::sh_poly_terms<B>(x[i], y[i], z[i], [&](int k, T p) { out[std::size_t(k) * stride + i] = sh_norm<T>(k) * p; });
}

/// Span front end of sh_basis_batch: out holds B*B planes of x.size() values each.
template <int B, class T>
inline void sh_basis_batch(std::span<const T> x, std::span<const T> y, std::span<const T> z, std::span<T> out) noexcept {
    IBL_ASSERT(y.size() == x.size() && z.size() == x.size());
    IBL_ASSERT(out.size() >= std::size_t(B * B) * x.size());
    sh_basis_batch<B>(x.data(), y.data(), z.data(), x.size(), out.data(), x.size());
}

/// Reconstruction f(dir) = sum_k c_k Y_k(dir) (radiance from radiance SH, irradiance from
/// irradiance SH: whatever the coefficients hold).
template <class T, int B> IBL_FUNC vec3<T> sh_evaluate(const sh_coeffs<T, B>& c, const vec3<T>& dir) noexcept {
    vec3<T> r(T(0));
    detail::sh_poly_terms<B>(dir.x, dir.y, dir.z, [&](int k, T p) { r += (sh_norm<T>(k) * p) * c.c[k]; });
    return r;
}

/// Coefficients of a Dirac delta of radiant intensity `intensity` (W/sr-like units: radiance
/// integrated over the source's solid angle) from unit direction dir: c_k = intensity Y_k(dir).
template <int B, class T>
IBL_FUNC sh_coeffs<T, B> sh_project_directional(const vec3<T>& dir, const vec3<T>& intensity) noexcept {
    sh_coeffs<T, B> r;
    detail::sh_poly_terms<B>(dir.x, dir.y, dir.z, [&](int k, T p) { r.c[k] = (sh_norm<T>(k) * p) * intensity; });
    return r;
}

} // namespace ibl

#endif // IBL_DETAIL_CXX20
