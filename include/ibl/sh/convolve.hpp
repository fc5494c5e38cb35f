#pragma once
// ibl/sh/convolve.hpp — Lambert (clamped-cosine) convolution of radiance SH: irradiance SH, its
// reconstruction E(n), the 4x4 quadratic form of Ramamoorthi & Hanrahan, shader-ready constants.
//
// Derivation. Irradiance at a surface with unit normal n is E(n) = integral of L(w) max(0, n.w) dw.
// The kernel max(0, n.w) depends only on n.w (zonal), so by the Funk-Hecke theorem
//
//   E_lm = A_l L_lm,     A_l = 2 pi integral_0^1 t P_l(t) dt            (P_l Legendre)
//
//   A_0 = pi,  A_1 = 2 pi / 3,  A_l = 0 for odd l > 1,
//   A_l = 2 pi (-1)^(l/2 - 1) / ((l + 2)(l - 1)) * l! / (2^l ((l/2)!)^2)  for even l >= 2,
//   so A_2 = pi/4, A_3 = 0, A_4 = -pi/24
// (R. Ramamoorthi, P. Hanrahan, "An Efficient Representation for Irradiance Environment Maps",
// SIGGRAPH 2001, eqs. 8-9; also "On the relationship between radiance and irradiance", JOSA A 2001).
// The same A_l are the SH coefficients of max(0, y) divided by Y_lm(+Y): the "cosine sky" of the
// tests (Funk-Hecke with f = max(0, t)).
//
// Outputs (state which one you hold!):
//   sh_coeffs from project_*          RADIANCE SH L_k.
//   sh_irradiance(L)                  IRRADIANCE SH E_k = A_l L_k; sh_evaluate(E, n) = E(n).
//   sh_irradiance_at(L, n)            E(n) directly from radiance SH.
//   irradiance_quadratic_form(L)      per channel a symmetric 4x4 M with E(n) = v^T M v,
//                                     v = (x, y, z, 1); bands 0..2 only (exact for B = 3).
//   sh_shader_coeffs(L, output)       k_k = A_l K_k L_k (divided by pi for irradiance_over_pi), so
//                                     that   E(n) [or E(n)/pi] = sum_k k_k p_k(n)
//                                     with the UNNORMALISED polynomial terms p_k of basis.hpp:
//                                     for B = 3 (nine multiply-adds):
//                                       1, y, z, x, x y, y z, 3 z^2 - 1, x z, x^2 - y^2.
//                                     E/pi is the diffuse "irradiance over pi" that multiplies
//                                     albedo directly (Lambert BRDF = albedo/pi).

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <glm/mat4x4.hpp>

#include "../core/constants.hpp"
#include "../core/vec.hpp"
#include "basis.hpp"

namespace ibl {

/// A_l of the clamped cosine (the header comment): pi, 2pi/3, pi/4, 0, -pi/24, ...
template <class T> IBL_FUNC constexpr T lambert_band_factor(int l) noexcept {
    if (l == 0) return pi_v<T>;
    if (l == 1) return T(2) * pi_v<T> / T(3);
    if (l % 2 == 1) return T(0);
    // l! / (2^l ((l/2)!)^2) = binomial(l, l/2) / 2^l, accumulated as a product of ratios.
    T central = T(1);
    for (int i = 1; i <= l / 2; ++i) central *= T(l / 2 + i) / T(4 * i);
    const T sign = (l / 2 - 1) % 2 == 0 ? T(1) : T(-1);
    return sign * T(2) * pi_v<T> / (T(l + 2) * T(l - 1)) * central;
}

/// Irradiance SH from radiance SH: E_lm = A_l L_lm.
template <class T, int B> IBL_FUNC sh_coeffs<T, B> sh_irradiance(const sh_coeffs<T, B>& radiance) noexcept {
    T a[B];
    for (int l = 0; l < B; ++l) a[l] = lambert_band_factor<T>(l);
    return sh_scale_bands(radiance, a);
}

/// Irradiance E(n) at unit normal n from radiance SH.
template <class T, int B>
IBL_FUNC vec3<T> sh_irradiance_at(const sh_coeffs<T, B>& radiance, const vec3<T>& n) noexcept {
    return sh_evaluate(sh_irradiance(radiance), n);
}

/// Per-channel 4x4 quadratic forms: E_c(n) = v^T m[c] v with v = (n.x, n.y, n.z, 1).
template <class T> struct sh_quadratic_form {
    glm::mat<4, 4, T, glm::defaultp> m[3];

    IBL_FUNC vec3<T> evaluate(const vec3<T>& n) const noexcept {
        const vec4<T> v(n, T(1));
        return {glm::dot(v, m[0] * v), glm::dot(v, m[1] * v), glm::dot(v, m[2] * v)};
    }
};

/// The quadratic form of the 3-band irradiance (Ramamoorthi & Hanrahan 2001, eq. 12), derived for
/// this library's basis. With E_k = A_l L_k and E(n) = sum_k K_k E_k p_k(n), collecting monomials
/// (3z^2 - 1 contributes 3 K_6 E_6 to z^2 and -K_6 E_6 to the constant):
///
///   M = [ K8 E8      K4 E4/2   K7 E7/2   K3 E3/2 ]      (rows/columns x, y, z, 1)
///       [ K4 E4/2   -K8 E8     K5 E5/2   K1 E1/2 ]
///       [ K7 E7/2    K5 E5/2   3 K6 E6   K2 E2/2 ]
///       [ K3 E3/2    K1 E1/2   K2 E2/2   K0 E0 - K6 E6 ]
///
/// In R&H's notation (their Y_1,-1 ~ y, Y_10 ~ z, Y_11 ~ x: the same axes as ours, so nothing is
/// permuted) the products are c1 = K8 A2 = 0.429043, c2 = K3 A1 / 2 = 0.511664,
/// c3 = 3 K6 A2 = 0.743125, c4 = K0 A0 = 0.886227, c5 = K6 A2 = 0.247708, times their L_lm.
/// For B > 3 the band-4 term (A_4 = -pi/24) is NOT in M (it is quartic); band 3 has A_3 = 0.
template <class T, int B>
IBL_FUNC sh_quadratic_form<T> irradiance_quadratic_form(const sh_coeffs<T, B>& radiance) noexcept {
    static_assert(B >= 3, "the quadratic form needs bands 0..2");
    const T a0 = lambert_band_factor<T>(0), a1 = lambert_band_factor<T>(1), a2 = lambert_band_factor<T>(2);
    sh_quadratic_form<T> q;
    for (int ch = 0; ch < 3; ++ch) {
        auto e = [&](int k, T a) { return sh_norm<T>(k) * a * radiance.c[k][ch]; };
        const T h = T(0.5);
        glm::mat<4, 4, T, glm::defaultp> m(T(0));
        // glm is column-major (m[col][row]); M is symmetric, so each pair is written twice.
        auto set = [&](int i, int j, T v) {
            m[i][j] = v;
            m[j][i] = v;
        };
        set(0, 0, e(8, a2));
        set(1, 1, -e(8, a2));
        set(2, 2, T(3) * e(6, a2));
        set(3, 3, e(0, a0) - e(6, a2));
        set(0, 1, h * e(4, a2));
        set(1, 2, h * e(5, a2));
        set(0, 2, h * e(7, a2));
        set(0, 3, h * e(3, a1));
        set(1, 3, h * e(1, a1));
        set(2, 3, h * e(2, a1));
        q.m[ch] = m;
    }
    return q;
}

/// What sh_shader_coeffs folds in.
enum class sh_shader_output {
    irradiance,        ///< sum_k k_k p_k(n) = E(n)
    irradiance_over_pi ///< sum_k k_k p_k(n) = E(n) / pi  (multiply by albedo for Lambert diffuse)
};

/// Shader-ready constants k_k = A_l K_k L_k (/ pi): see the header comment for the terms p_k.
template <class T, int B>
IBL_FUNC sh_coeffs<T, B> sh_shader_coeffs(const sh_coeffs<T, B>& radiance, sh_shader_output output) noexcept {
    sh_coeffs<T, B> r;
    const T scale = output == sh_shader_output::irradiance_over_pi ? inv_pi_v<T> : T(1);
    for (int l = 0; l < B; ++l) {
        const T a = lambert_band_factor<T>(l) * scale;
        for (int m = -l; m <= l; ++m) {
            const int k = sh_index(l, m);
            r.c[k] = (a * sh_norm<T>(k)) * radiance.c[k];
        }
    }
    return r;
}

/// What a shader does with sh_shader_coeffs: sum_k k_k p_k(n) (B*B multiply-adds).
template <class T, int B> IBL_FUNC vec3<T> sh_shader_evaluate(const sh_coeffs<T, B>& k, const vec3<T>& n) noexcept {
    vec3<T> r(T(0));
    detail::sh_poly_terms<B>(n.x, n.y, n.z, [&](int i, T p) { r += p * k.c[i]; });
    return r;
}

} // namespace ibl

#endif // IBL_DETAIL_CXX20
