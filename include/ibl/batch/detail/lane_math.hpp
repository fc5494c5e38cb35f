#pragma once
// ibl/batch/detail/lane_math.hpp — branch-free elementary functions for the lanes of the batch
// kernels. The C library's exp/acos/cos are calls that g++ does not vectorise (no vector math
// library without -ffast-math), so the kernels use these polynomial forms instead. Each states its
// domain and its error; all are pure arithmetic, selects and (for exp) an exponent-field build.

#include "../../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <bit>
#include <cstddef>
#include <cstdint>
#include <utility>

#include "../../core/constants.hpp"
#include "../../core/math.hpp"

namespace ibl::detail {

/// Horner evaluation c[0] + x (c[1] + x (c[2] + ...)) written out at compile time (a fold over an
/// index sequence): straight-line code, so the lane loops around it stay vectorisable.
template <std::size_t N, std::size_t... I>
IBL_FUNC constexpr double horner_unrolled(const double (&c)[N], double x, std::index_sequence<I...>) noexcept {
    double p = c[N - 1];
    ((p = p * x + c[N - 2 - I]), ...);
    return p;
}
template <std::size_t N> IBL_FUNC constexpr double horner(const double (&c)[N], double x) noexcept {
    return horner_unrolled(c, x, std::make_index_sequence<N - 1>{});
}

/// cos(x) for x in [0, pi]: cos(x) = -sin(z), z = x - pi/2 in [-pi/2, pi/2], Taylor series of sin
/// to z^19 in nested form (truncation < (pi/2)^21 / 21! = 2.6e-15; rounding a few ulp).
template <class T> IBL_FUNC constexpr T lane_cos_0_pi(T x) noexcept {
    const T z = x - half_pi_v<T>;
    const T z2 = z * z;
    T p = T(1) - z2 * T(1.0 / (18.0 * 19.0));
    p = T(1) - z2 * T(1.0 / (16.0 * 17.0)) * p;
    p = T(1) - z2 * T(1.0 / (14.0 * 15.0)) * p;
    p = T(1) - z2 * T(1.0 / (12.0 * 13.0)) * p;
    p = T(1) - z2 * T(1.0 / (10.0 * 11.0)) * p;
    p = T(1) - z2 * T(1.0 / (8.0 * 9.0)) * p;
    p = T(1) - z2 * T(1.0 / (6.0 * 7.0)) * p;
    p = T(1) - z2 * T(1.0 / (4.0 * 5.0)) * p;
    p = T(1) - z2 * T(1.0 / (2.0 * 3.0)) * p;
    return -z * p;
}

/// Maclaurin coefficients of asin: c_k = (2k)! / (4^k k!^2 (2k + 1)), from
/// c_k = c_{k-1} (2k - 1)^2 / ((2k)(2k + 1)), evaluated at compile time.
struct asin_series {
    static constexpr int terms = 22;
    double c[terms];
    constexpr asin_series() : c{} {
        c[0] = 1.0;
        for (int k = 1; k < terms; ++k)
            c[k] = c[k - 1] * double((2 * k - 1) * (2 * k - 1)) / double((2 * k) * (2 * k + 1));
    }
};
inline constexpr asin_series asin_coefficients{};

/// asin(a) for a in [0, 1/2] by its Maclaurin series sum_k c_k a^(2k+1) to k = 21 (truncation
/// < c_22 4^-22 / 2 < 1e-16), Horner from the top term down.
IBL_FUNC constexpr double lane_asin_half(double a) noexcept {
    return a * horner(asin_coefficients.c, a * a);
}

/// acos(x) for x in [-1, 1] (clamped; NaN -> acos(-1) = pi), branch-free: |x| <= 1/2:
/// pi/2 - asin(x); x > 1/2: 2 asin(sqrt((1 - x)/2)); x < -1/2: pi - 2 asin(sqrt((1 + x)/2)).
/// Absolute error below 1e-15 (series) plus rounding.
IBL_FUNC double lane_acos(double x) noexcept {
    const double c = clamp(x, -1.0, 1.0);
    const double ac = c < 0.0 ? -c : c;
    const bool mid = ac <= 0.5;
    const double a = mid ? ac : safe_sqrt(0.5 * (1.0 - ac));
    const double s = lane_asin_half(a);                     // asin(a) >= 0
    const double small = mid ? half_pi_v<double> - s : 2.0 * s; // acos(|x|)
    return c < 0.0 ? pi_v<double> - small : small;
}

/// e^y - 1 for y in [0, 64] (the quadrature's radial variable): y = n ln 2 + r, |r| <= ln2 / 2
/// (Cody-Waite split of ln 2), expm1(r) by its Taylor series to r^13 (truncation < 2e-16
/// relative), then 2^n (1 + expm1(r)) - 1 = 2^n expm1(r) + (2^n - 1), exact in the last step
/// for n = 0, so small y keeps full relative accuracy. 2^n is built in the exponent field.
IBL_FUNC double lane_expm1_nonneg(double y) noexcept {
    constexpr double ln2_hi = 0x1.62e42fee00000p-1; // ln 2 with trailing zero bits: n ln2_hi exact
    constexpr double ln2_lo = 0x1.a39ef35793c76p-33;
    const double yc = clamp(y, 0.0, 64.0);
    const double nf = double(std::int64_t(yc * (1.0 / 0x1.62e42fefa39efp-1) + 0.5)); // round, yc >= 0
    const double r = (yc - nf * ln2_hi) - nf * ln2_lo;
    constexpr double inv_fact[13] = {1.0, 1.0 / 2, 1.0 / 6, 1.0 / 24, 1.0 / 120, 1.0 / 720, 1.0 / 5040,
                                     1.0 / 40320, 1.0 / 362880, 1.0 / 3628800, 1.0 / 39916800,
                                     1.0 / 479001600, 1.0 / 6227020800.0};
    const double em_r = r * horner(inv_fact, r); // expm1(r) = r sum_k r^k / (k + 1)!
    const double two_n = std::bit_cast<double>(std::uint64_t(std::int64_t(nf) + 1023) << 52);
    return two_n * em_r + (two_n - 1.0);
}

} // namespace ibl::detail

#endif // IBL_DETAIL_CXX20
