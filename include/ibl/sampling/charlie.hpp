#pragma once
// ibl/sampling/charlie.hpp — importance sampling of the Charlie sheen distribution (brdf/charlie.hpp)
// as a sample / pdf / invert triplet, isotropic, in tangent space (z = the normal).
//
// The density D(h) (n.h) per unit solid angle of h has, in s = sin(theta_h), the CDF
//     F(s) = s^k,   k = 2 + 1/alpha          (2 pi D s cos d(theta) = k s^(k - 1) ds),
// so s = u^(1/k) and phi = 2 pi u.y. Evaluated without cancellation:
//     sin(theta) = exp(log(u) / k),   cos^2(theta) = 1 - u^(2/k) = -expm1(2 log(u) / k),
// which keeps cos(theta) accurate when it is tiny (small alpha puts the samples at the horizon:
// cos ~ sqrt(2 |log u| alpha)). Inverse: u.x = s^k = exp(k log(s)) with log(s^2) as in D.
//
// Domains: u in [0, 1)^2 (including 1 - eps/2), alpha in [0, 1] (clamped with
// charlie_clamp_alpha; r -> 0 is the limit of the clamped alpha, no mirror special case: the lobe
// does not tend to the normal). Range of the sampler: unit h with h.z in (0, 1]; u.x = 0 gives
// the normal exactly. The inverse maps h.z = 0 (outside the range) to u.x = 1 - eps/2.

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <cmath>

#include "../brdf/charlie.hpp"
#include "../core/constants.hpp"
#include "../core/math.hpp"
#include "../core/vec.hpp"
#include "hemisphere.hpp"

namespace ibl {

/// Half vector h with density D_charlie(h) (n.h) per unit solid angle of h (the closed-form
/// inverse CDF of the header). Domain: u in [0, 1)^2, alpha in [0, 1] (clamped). Range: unit
/// vectors with h.z in (0, 1].
template <class T> IBL_FUNC vec3<T> sample_charlie_ndf(const vec2<T>& u, T alpha) noexcept {
    using std::exp;
    using std::expm1;
    using std::log;
    const T inv_k = T(1) / charlie_exponent(alpha);
    const T lu = log(u.x); // -inf at u.x = 0: sin = 0, cos = 1
    const T sin_theta = exp(lu * inv_k);
    const T cos_theta = safe_sqrt(-expm1(T(2) * lu * inv_k));
    return detail::spherical_direction(sin_theta, cos_theta, two_pi_v<T> * u.y);
}

/// Density of sample_charlie_ndf: D_charlie(h) max(0, n.h) per unit solid angle of h; 0 for
/// h.z <= 0. Finite: at most the peak of D.
template <class T> IBL_FUNC T charlie_ndf_pdf(const vec3<T>& h, T alpha) noexcept {
    return ndf_charlie(h, alpha) * saturate(h.z);
}

/// Inverse of sample_charlie_ndf: u.x = sin(theta)^k, u.y = phi / (2 pi). Domain: unit h with
/// h.z >= 0, alpha in [0, 1] (clamped). Range: [0, 1)^2. Where u.x is below the smallest
/// positive T (small alpha, h far from the horizon) it rounds to 0: the sampler maps all such u
/// to directions within rounding of the same polar angle, so the inverse is exact only where
/// s^k is representable.
template <class T> IBL_FUNC vec2<T> invert_charlie_ndf(const vec3<T>& h, T alpha) noexcept {
    using std::exp;
    const T k = charlie_exponent(alpha);
    const T log_s2 = detail::charlie_log_sin2(h.z * h.z, h.x * h.x + h.y * h.y);
    const T ux = exp(T(0.5) * k * log_s2);
    return vec2<T>(ux < T(1) ? ux : one_minus_epsilon_v<T>, detail::unit_from_azimuth(h.y, h.x));
}

} // namespace ibl

#endif // IBL_DETAIL_CXX20
