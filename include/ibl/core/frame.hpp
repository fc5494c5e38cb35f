#pragma once
// ibl/core/frame.hpp — orthonormal bases.
//
// make_frame(n) builds the tangent frame of a unit vector n without branches, after
// T. Duff, J. Burgess, P. Christensen, C. Hery, A. Kensler, M. Liani, R. Villemin,
// "Building an Orthonormal Basis, Revisited", JCGT 6(1), 2017 (Listing 3). The frame is
// continuous everywhere except across the plane n.z = 0 where sign(n.z) flips, and it is exact
// (no catastrophic cancellation) at n = (0, 0, -1), the singular point of Frisvad's original.
//
// Local (tangent) space: x = t, y = b, z = n; to_local/to_world are the two rotations.

#include "config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include "math.hpp"
#include "vec.hpp"

namespace ibl {

template <class T> struct frame {
    vec3<T> t; ///< tangent (local x)
    vec3<T> b; ///< bitangent (local y)
    vec3<T> n; ///< normal (local z)

    /// Components of a world vector in this frame.
    IBL_FUNC vec3<T> to_local(const vec3<T>& w) const noexcept {
        return {glm::dot(w, t), glm::dot(w, b), glm::dot(w, n)};
    }
    /// World vector from components in this frame.
    IBL_FUNC vec3<T> to_world(const vec3<T>& l) const noexcept { return l.x * t + l.y * b + l.z * n; }
};

/// Right-handed orthonormal frame (t, b, n) with cross(t, b) = n, for unit n (Duff et al. 2017).
template <class T> IBL_FUNC frame<T> make_frame(const vec3<T>& n) noexcept {
    const T s = sign_not_zero(n.z);
    const T a = T(-1) / (s + n.z);
    const T b = n.x * n.y * a;
    return {vec3<T>(T(1) + s * n.x * n.x * a, s * b, -s * n.x), vec3<T>(b, s + n.y * n.y * a, -n.y), n};
}

} // namespace ibl

#endif // IBL_DETAIL_CXX20
