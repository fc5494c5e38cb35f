#pragma once
// ibl/env/cube_geometry.hpp — the cubemap convention of the library, in one place.
//
// Faces are indexed 0..5 = +X, -X, +Y, -Y, +Z, -Z (the order of GL_TEXTURE_CUBE_MAP_POSITIVE_X + i
// and of KTX). A direction r selects the face of its major axis ma and face coordinates
// (sc, tc) by the table of the OpenGL 4.6 specification (section 8.13, table 8.19):
//
//   face  ma    sc    tc        direction from (sc, tc), sc, tc in [-1, 1]
//   +X    +rx   -rz   -ry       ( 1,  -tc, -sc)
//   -X    -rx   +rz   -ry       (-1,  -tc,  sc)
//   +Y    +ry   +rx   +rz       ( sc,  1,   tc)
//   -Y    -ry   +rx   -rz       ( sc, -1,  -tc)
//   +Z    +rz   +rx   -ry       ( sc, -tc,  1)
//   -Z    -rz   -rx   -ry       (-sc, -tc, -1)
//
// s = (sc/|ma| + 1)/2 and t = (tc/|ma| + 1)/2 are the texture coordinates in [0, 1]; row 0 of a
// face image is t = 0 and column 0 is s = 0. Texel (x, y) of an N x N face covers
// s in [x/N, (x+1)/N], t in [y/N, (y+1)/N]; its centre is ((x + 0.5)/N, (y + 0.5)/N).
//
// Ties between axes (directions exactly on a cube edge or corner) are broken in the order
// X before Y before Z, so every direction has exactly one face.
//
// Exact solid angle of a face rectangle [a0, a1] x [b0, b1] (in sc, tc): the area element of the
// cube face z = 1 seen from the centre is d(omega) = da db / (1 + a^2 + b^2)^(3/2), whose
// antiderivative is F(a, b) = atan(a b / sqrt(1 + a^2 + b^2)); the rectangle's solid angle is
// F(a1,b1) - F(a0,b1) - F(a1,b0) + F(a0,b0). The six faces sum to 4 pi.

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <cmath>
#include <cstddef>
#include <vector>

#include "../core/constants.hpp"
#include "../core/vec.hpp"

namespace ibl {

enum class cube_face : int { px = 0, nx = 1, py = 2, ny = 3, pz = 4, nz = 5 };

/// Face index and texture coordinates (s, t) in [0, 1] of a cube face point.
template <class T> struct cube_coord {
    int face; ///< 0..5 = +X, -X, +Y, -Y, +Z, -Z
    T s;
    T t;
};

/// Unnormalised direction of face point (face, sc, tc), sc, tc in [-1, 1] (the table above).
template <class T> IBL_FUNC vec3<T> cube_face_point(int face, T sc, T tc) noexcept {
    switch (face) {
    case 0: return {T(1), -tc, -sc};
    case 1: return {T(-1), -tc, sc};
    case 2: return {sc, T(1), tc};
    case 3: return {sc, T(-1), -tc};
    case 4: return {sc, -tc, T(1)};
    default: return {-sc, -tc, T(-1)};
    }
}

namespace detail {
/// cube_face_point of a face fixed at compile time (the same components, no switch).
template <int F, class T> IBL_FUNC vec3<T> cube_face_point_of(T sc, T tc) noexcept {
    if constexpr (F == 0) return {T(1), -tc, -sc};
    else if constexpr (F == 1) return {T(-1), -tc, sc};
    else if constexpr (F == 2) return {sc, T(1), tc};
    else if constexpr (F == 3) return {sc, T(-1), -tc};
    else if constexpr (F == 4) return {sc, -tc, T(1)};
    else return {-sc, -tc, T(-1)};
}
/// fn(point) with point(sc, tc) == cube_face_point(face, sc, tc) for that face (face outside
/// [0, 5] reads as 5, as cube_face_point's default): the face is chosen once, so a loop over a
/// row's texels inside fn has no switch and vectorises.
template <class T, class Fn> IBL_FUNC_VOID void with_cube_face_point(int face, Fn&& fn) {
    switch (face) {
    case 0: fn([](T sc, T tc) { return cube_face_point_of<0, T>(sc, tc); }); break;
    case 1: fn([](T sc, T tc) { return cube_face_point_of<1, T>(sc, tc); }); break;
    case 2: fn([](T sc, T tc) { return cube_face_point_of<2, T>(sc, tc); }); break;
    case 3: fn([](T sc, T tc) { return cube_face_point_of<3, T>(sc, tc); }); break;
    case 4: fn([](T sc, T tc) { return cube_face_point_of<4, T>(sc, tc); }); break;
    default: fn([](T sc, T tc) { return cube_face_point_of<5, T>(sc, tc); }); break;
    }
}
} // namespace detail

/// Unit direction through texture coordinates (s, t) in [0, 1] of a face.
template <class T> IBL_FUNC vec3<T> cube_direction(int face, T s, T t) noexcept {
    return glm::normalize(cube_face_point(face, T(2) * s - T(1), T(2) * t - T(1)));
}

/// Unit direction through the centre of texel (x, y) of an n x n face.
template <class T> IBL_FUNC vec3<T> cube_texel_direction(int face, int x, int y, int n) noexcept {
    const T inv = T(1) / T(n);
    return cube_direction(face, (T(x) + T(0.5)) * inv, (T(y) + T(0.5)) * inv);
}

/// Index of texel (x, y) of face `face` in six packed n x n faces (face-major, then rows, then
/// columns: the layout of the bakers' per-texel results).
IBL_FUNC std::size_t cube_texel_index(int face, int x, int y, int n) noexcept {
    return (std::size_t(face) * std::size_t(n) + std::size_t(y)) * std::size_t(n) + std::size_t(x);
}

/// Face and (s, t) of a direction (need not be unit; must be non-zero). For the zero vector and
/// NaN components the result is face +X with s = t = 0.5 (a documented clamp, never UB).
template <class T> IBL_FUNC cube_coord<T> cube_lookup(const vec3<T>& r) noexcept {
    using std::fabs;
    const T ax = fabs(r.x), ay = fabs(r.y), az = fabs(r.z);
    int face;
    T sc, tc, ma;
    if (ax >= ay && ax >= az) {
        ma = ax;
        face = r.x >= T(0) ? 0 : 1;
        sc = r.x >= T(0) ? -r.z : r.z;
        tc = -r.y;
    } else if (ay >= az) {
        ma = ay;
        face = r.y >= T(0) ? 2 : 3;
        sc = r.x;
        tc = r.y >= T(0) ? r.z : -r.z;
    } else {
        ma = az;
        face = r.z >= T(0) ? 4 : 5;
        sc = r.z >= T(0) ? r.x : -r.x;
        tc = -r.y;
    }
    if (!(ma > T(0))) return {0, T(0.5), T(0.5)};
    const T inv = T(1) / ma;
    return {face, T(0.5) * (sc * inv + T(1)), T(0.5) * (tc * inv + T(1))};
}

namespace detail {
template <class T> IBL_FUNC T cube_area_antiderivative(T a, T b) noexcept {
    using std::atan2;
    using std::sqrt;
    return atan2(a * b, sqrt(a * a + b * b + T(1)));
}
} // namespace detail

/// Exact solid angle of the face rectangle [a0, a1] x [b0, b1] in face coordinates sc, tc in
/// [-1, 1] (the same for every face). Accurate to a few ulps of T for rectangles down to a few
/// ulps of width when computed in double; in float, small texels lose relative accuracy to the
/// cancellation of the four terms (about eps / texel solid angle), so use T = double for tables.
template <class T> IBL_FUNC T cube_rect_solid_angle(T a0, T b0, T a1, T b1) noexcept {
    using detail::cube_area_antiderivative;
    return cube_area_antiderivative(a1, b1) - cube_area_antiderivative(a0, b1) -
           cube_area_antiderivative(a1, b0) + cube_area_antiderivative(a0, b0);
}

/// Exact solid angle of texel (x, y) of an n x n face (independent of the face).
template <class T> IBL_FUNC T cube_texel_solid_angle(int x, int y, int n) noexcept {
    const T inv = T(2) / T(n);
    return cube_rect_solid_angle(T(x) * inv - T(1), T(y) * inv - T(1), T(x + 1) * inv - T(1),
                                 T(y + 1) * inv - T(1));
}

/// The exact solid angles of an n x n face's texels, row by row (y n + x; the same on every
/// face): each is cube_texel_solid_angle<T>(x, y, n) bit for bit (the same four antiderivative
/// values, subtracted in the same order), from the (n + 1)^2 corner values instead of four per
/// texel. Host only.
template <class T> std::vector<T> cube_face_solid_angles(int n) {
    const std::size_t m = std::size_t(n > 0 ? n : 0), c = m + 1;
    const T inv = T(2) / T(n);
    std::vector<T> corner(c * c);
    for (std::size_t j = 0; j < c; ++j)
        for (std::size_t i = 0; i < c; ++i)
            corner[j * c + i] = detail::cube_area_antiderivative(T(int(i)) * inv - T(1), T(int(j)) * inv - T(1));
    std::vector<T> out(m * m);
    for (std::size_t y = 0; y < m; ++y)
        for (std::size_t x = 0; x < m; ++x)
            out[y * m + x] = corner[(y + 1) * c + x + 1] - corner[(y + 1) * c + x] - corner[y * c + x + 1] + corner[y * c + x];
    return out;
}

} // namespace ibl

#endif // IBL_DETAIL_CXX20
