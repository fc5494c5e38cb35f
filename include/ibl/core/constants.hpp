#pragma once
// ibl/core/constants.hpp — mathematical constants as variable templates over the scalar type,
// and the named numerical thresholds that the stability contract relies on.

#include "config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <limits>

namespace ibl {

template <class T> inline constexpr T pi_v = T(3.141592653589793238462643383279502884L);
template <class T> inline constexpr T two_pi_v = T(6.283185307179586476925286766559005768L);
template <class T> inline constexpr T four_pi_v = T(12.56637061435917295385057353311801154L);
template <class T> inline constexpr T half_pi_v = T(1.570796326794896619231321691639751442L);
template <class T> inline constexpr T inv_pi_v = T(0.318309886183790671537767526745028724L);
template <class T> inline constexpr T inv_two_pi_v = T(0.159154943091895335768883763372514362L);
template <class T> inline constexpr T inv_four_pi_v = T(0.079577471545947667884441881686257181L);

/// Largest value of T strictly below 1 (1 - eps/2). Uniform variates live in [0, 1); samplers
/// are tested at this corner.
template <class T> inline constexpr T one_minus_epsilon_v = T(1) - std::numeric_limits<T>::epsilon() / T(2);

/// Machine epsilon of T (distance from 1 to the next larger value).
template <class T> inline constexpr T epsilon_v = std::numeric_limits<T>::epsilon();

/// Smallest positive normal number of T. Used as the floor of denominators that vanish only at
/// an exact corner of a domain (e.g. n.v = n.l = 0), so that the quotient stays finite and its
/// product with the vanishing factor gives 0, never NaN.
template <class T> inline constexpr T min_normal_v = std::numeric_limits<T>::min();

} // namespace ibl

#endif // IBL_DETAIL_CXX20
