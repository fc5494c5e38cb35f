#pragma once
// ibl/runtime/dfg_fit.hpp — analytic approximations of the split-sum DFG terms, for comparison
// with the exact table (their measured errors: bench/bench_dfg.cpp and the test suite).
//
// Karis' EnvBRDFApprox (B. Karis, "Physically Based Shading on Mobile", Unreal Engine blog, 2014),
// fitted to the UE4 split-sum LUT (GGX + Schlick-GGX):
//   c0 = (-1, -0.0275, -0.572, 0.022),  c1 = (1, 0.0425, 1.04, -0.04),  r = roughness c0 + c1,
//   a004 = min(r.x^2, exp2(-9.28 n.v)) r.x + r.y,  (A, B) = (-1.04, 1.04) a004 + r.zw.
// Largest absolute error against the exact 128^2 table (texel centres): see bench/bench_dfg.cpp.

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <cmath>

#include "../core/math.hpp"
#include "../core/vec.hpp"

namespace ibl {

/// Karis 2014 EnvBRDFApprox: (A, B) from n.v and perceptual roughness (both clamped to [0, 1]).
template <class T> IBL_FUNC vec2<T> dfg_karis_mobile(T n_dot_v, T roughness) noexcept {
    using std::exp2;
    const T mu = saturate(n_dot_v);
    const T r = saturate(roughness);
    const vec4<T> c0(T(-1), T(-0.0275), T(-0.572), T(0.022));
    const vec4<T> c1(T(1), T(0.0425), T(1.04), T(-0.04));
    const vec4<T> q = r * c0 + c1;
    const T m = exp2(T(-9.28) * mu);
    const T a004 = (q.x * q.x < m ? q.x * q.x : m) * q.x + q.y;
    return vec2<T>(T(-1.04) * a004 + q.z, T(1.04) * a004 + q.w);
}

} // namespace ibl

#endif // IBL_DETAIL_CXX20
