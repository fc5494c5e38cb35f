#pragma once
// ibl/core/math.hpp — the named edge-case helpers. Raw sqrt(1 - x*x) or max(0, ...) does not
// appear outside core/; callers use these so that the clamp and its reason live in one place.

#include "config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <cmath>

#include "constants.hpp"

namespace ibl {

/// x*x.
template <class T> IBL_FUNC constexpr T sqr(T x) noexcept { return x * x; }

/// x^5 with three multiplications (Schlick's (1 - cos)^5).
template <class T> IBL_FUNC constexpr T pow5(T x) noexcept {
    const T x2 = x * x;
    return x2 * x2 * x;
}

/// Clamp to [0, 1]. NaN maps to 0 (both comparisons are false), so a NaN cosine or roughness
/// never propagates through a saturate.
template <class T> IBL_FUNC constexpr T saturate(T x) noexcept {
    // Two sequential two-way selects rather than a nested ternary: the same values (NaN -> 0),
    // but g++ if-converts only two-way selects in loops it has not been told to vectorise, so
    // this keeps the batch kernels' lane loops branch-free and vectorised.
    const T y = x > T(0) ? x : T(0);
    return y < T(1) ? y : T(1);
}

/// Clamp to [lo, hi]; NaN maps to lo.
template <class T> IBL_FUNC constexpr T clamp(T x, T lo, T hi) noexcept {
    const T y = x > lo ? x : lo; // sequential two-way selects: see saturate
    return y < hi ? y : hi;
}

/// Linear interpolation a + t (b - a), exact at t = 0 and t = 1.
template <class T> IBL_FUNC constexpr T lerp(T a, T b, T t) noexcept {
    return (T(1) - t) * a + t * b;
}

/// sqrt(max(x, 0)): for quantities that are non-negative in exact arithmetic but may round to a
/// tiny negative (1 - cos^2, discriminants). NaN maps to 0.
template <class T> IBL_FUNC T safe_sqrt(T x) noexcept {
    using std::sqrt;
    return sqrt(x > T(0) ? x : T(0));
}

/// asin of x clamped to [-1, 1].
template <class T> IBL_FUNC T safe_asin(T x) noexcept {
    using std::asin;
    return asin(clamp(x, T(-1), T(1)));
}

/// acos of x clamped to [-1, 1].
template <class T> IBL_FUNC T safe_acos(T x) noexcept {
    using std::acos;
    return acos(clamp(x, T(-1), T(1)));
}

/// sin(theta) from cos(theta) for theta in [0, pi]: sqrt((1 - c)(1 + c)), which keeps the
/// relative accuracy of 1 - c^2 near c = +-1 better than sqrt(1 - c*c).
template <class T> IBL_FUNC T sin_from_cos(T cos_theta) noexcept {
    return safe_sqrt((T(1) - cos_theta) * (T(1) + cos_theta));
}

/// a*a - 1 written as (a - 1)(a + 1): exact cancellation near a = 1 and exactly -1 at a = 0.
template <class T> IBL_FUNC constexpr T sqr_minus_one(T a) noexcept {
    return (a - T(1)) * (a + T(1));
}

/// copysign(1, x): +1 for +0 and positive x, -1 for -0 and negative x.
template <class T> IBL_FUNC T sign_not_zero(T x) noexcept {
    using std::copysign;
    return copysign(T(1), x);
}

/// True when x is neither NaN nor infinite.
template <class T> IBL_FUNC bool is_finite(T x) noexcept {
    using std::isfinite;
    return isfinite(x);
}

} // namespace ibl

#endif // IBL_DETAIL_CXX20
