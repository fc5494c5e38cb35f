#pragma once
// ibl/sh/rotate.hpp — rotation of SH coefficients, every band (B <= 5), by the recurrences of
// J. Ivanic, K. Ruedenberg, "Rotation Matrices for Real Spherical Harmonics. Direct Determination
// by Recursion", J. Phys. Chem. 100 (1996) 6342, with the corrections of J. Phys. Chem. A 102
// (1998) 9099 (Table 2; the factor of P^{-1} in V for m < 0 is sqrt(1 + delta_{m,-1})).
//
// Convention. For a rotation matrix R (GLM column-major, v' = R v), D^l(R) is the matrix with
//     Y_lm(R d) = sum_n D^l_mn(R) Y_ln(d)      for every unit d.
// sh_rotate(c, R) returns the coefficients of the environment ROTATED BY R, L'(w) = L(R^T w)
// (what was seen in direction d is now seen in direction R d):
//     c'_lm = integral L(R^T w) Y_lm(w) dw = integral L(v) Y_lm(R v) dv = sum_n D^l_mn c_ln.
//
// Band 1 is R itself permuted to the basis order (y, z, x): D^1_mn = R[p(m)][p(n)] with
// p(-1) = y, p(0) = z, p(1) = x (row, column of the mathematical matrix). Band l >= 2 follows
// from band l - 1 and band 1 (each entry a combination of at most 6 products). The recurrence
// needs our basis to be the real SH without Condon-Shortley phase (basis.hpp), which it is;
// tests/test_sh.cpp checks Y(R d) = D Y(d) for every band at random R, d.

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <cmath>

#include <glm/mat3x3.hpp>

#include "../core/vec.hpp"
#include "basis.hpp"

namespace ibl {

template <class T, int B> class sh_rotation {
public:
    /// Offset of band l's (2l+1)^2 block: sum_{j<l} (2j+1)^2 = l (2l - 1)(2l + 1) / 3.
    IBL_FUNC static constexpr int offset(int l) noexcept { return l * (2 * l - 1) * (2 * l + 1) / 3; }
    static constexpr int size = offset(B);

    /// D^l_mn, |m|, |n| <= l < B.
    IBL_FUNC T operator()(int l, int m, int n) const noexcept { return d_[offset(l) + (m + l) * (2 * l + 1) + n + l]; }

    /// The representation of the rotation matrix r (orthonormal, det = +1; GLM r[col][row]).
    IBL_FUNC static sh_rotation from_matrix(const glm::mat<3, 3, T, glm::defaultp>& r) noexcept {
        sh_rotation s;
        s.d_[0] = T(1);
        if constexpr (B > 1) {
            constexpr int p[3] = {1, 2, 0}; // basis order m = -1, 0, 1 -> world axis y, z, x
            for (int m = -1; m <= 1; ++m)
                for (int n = -1; n <= 1; ++n) s.at(1, m, n) = r[p[n + 1]][p[m + 1]];
            for (int l = 2; l < B; ++l) s.band(l);
        }
        return s;
    }

    /// Coefficients of the rotated environment (see the header comment).
    IBL_FUNC sh_coeffs<T, B> apply(const sh_coeffs<T, B>& c) const noexcept {
        sh_coeffs<T, B> out;
        for (int l = 0; l < B; ++l)
            for (int m = -l; m <= l; ++m) {
                vec3<T> acc(T(0));
                for (int n = -l; n <= l; ++n) acc += (*this)(l, m, n) * c.c[sh_index(l, n)];
                out.c[sh_index(l, m)] = acc;
            }
        return out;
    }

private:
    T d_[size > 0 ? size : 1]{};

    IBL_FUNC T& at(int l, int m, int n) noexcept { return d_[offset(l) + (m + l) * (2 * l + 1) + n + l]; }

    // P^i_{a,b} of band l from band l - 1 (Ivanic & Ruedenberg, Table 2).
    IBL_FUNC T p(int i, int l, int a, int b) const noexcept {
        const sh_rotation& s = *this;
        if (b == l) return s(1, i, 1) * s(l - 1, a, l - 1) - s(1, i, -1) * s(l - 1, a, -l + 1);
        if (b == -l) return s(1, i, 1) * s(l - 1, a, -l + 1) + s(1, i, -1) * s(l - 1, a, l - 1);
        return s(1, i, 0) * s(l - 1, a, b);
    }

    IBL_FUNC_VOID void band(int l) noexcept {
        using std::sqrt;
        for (int m = -l; m <= l; ++m) {
            const int am = m < 0 ? -m : m;
            const T d_m0 = m == 0 ? T(1) : T(0);
            for (int n = -l; n <= l; ++n) {
                const int an = n < 0 ? -n : n;
                const T denom = an == l ? T(2 * l * (2 * l - 1)) : T((l + n) * (l - n));
                const T u = sqrt(T((l + m) * (l - m)) / denom);
                const T v = T(0.5) * sqrt((T(1) + d_m0) * T((l + am - 1) * (l + am)) / denom) * (T(1) - T(2) * d_m0);
                const T w = T(-0.5) * sqrt(T((l - am - 1) * (l - am)) / denom) * (T(1) - d_m0);
                T value = T(0);
                if (u != T(0)) value += u * p(0, l, m, n);
                if (m == 0) {
                    value += v * (p(1, l, 1, n) + p(-1, l, -1, n));
                } else if (m > 0) {
                    const T vv = m == 1 ? sqrt(T(2)) * p(1, l, 0, n) : p(1, l, m - 1, n) - p(-1, l, -m + 1, n);
                    value += v * vv;
                    if (w != T(0)) value += w * (p(1, l, m + 1, n) + p(-1, l, -m - 1, n));
                } else {
                    const T vv = m == -1 ? sqrt(T(2)) * p(-1, l, 0, n) : p(1, l, m + 1, n) + p(-1, l, -m - 1, n);
                    value += v * vv;
                    if (w != T(0)) value += w * (p(1, l, m - 1, n) - p(-1, l, -m + 1, n));
                }
                at(l, m, n) = value;
            }
        }
    }
};

/// Coefficients of the environment rotated by r: L'(w) = L(r^T w).
template <class T, int B>
IBL_FUNC sh_coeffs<T, B> sh_rotate(const sh_coeffs<T, B>& c, const glm::mat<3, 3, T, glm::defaultp>& r) noexcept {
    return sh_rotation<T, B>::from_matrix(r).apply(c);
}

} // namespace ibl

#endif // IBL_DETAIL_CXX20
