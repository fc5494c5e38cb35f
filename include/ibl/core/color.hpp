#pragma once
// ibl/core/color.hpp — colour helpers for linear RGB with Rec. 709 / sRGB primaries.

#include "config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include "vec.hpp"

namespace ibl {

/// Relative luminance Y of linear Rec. 709 RGB (ITU-R BT.709 coefficients).
template <class T> IBL_FUNC T luminance(const vec3<T>& rgb) noexcept {
    return T(0.2126) * rgb.r + T(0.7152) * rgb.g + T(0.0722) * rgb.b;
}

} // namespace ibl

#endif // IBL_DETAIL_CXX20
