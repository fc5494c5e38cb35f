#pragma once
// ibl/sh/window.hpp — windowing (deringing) of SH expansions.
//
// Why. A truncated series of a peaked environment (an HDR sun) rings: the 3-band irradiance of a
// directional light of intensity I is I (1/4 + t/2 + 5/32 (3 t^2 - 1)), t = cos(angle), whose
// minimum -0.0396 I at t = -8/15 is NEGATIVE light (Filament issue #744). Multiplying band l by a
// smooth window w_l trades sharpness for the absence of ringing (Sloan, "Stupid Spherical
// Harmonics (SH) Tricks", GDC 2008, section "windowing").
//
// Windows, with a width parameter W > 0 in bands (larger = weaker; strength = 1/W):
//   hanning:   w_l = (1 + cos(pi l / W)) / 2            for l < W, else 0
//   lanczos:   w_l = sin(pi l / W) / (pi l / W)  (w_0 = 1) for l < W, else 0   (sigma factors)
// Both have w_0 = 1 (the mean is kept) and w_l -> 1 as W -> infinity; at W <= 1 only band 0 is
// left, whose irradiance pi K_0 L_00 is non-negative whenever the mean radiance is.
//
// Automatic window (sh_auto_window): the largest W (the weakest window) for which the windowed
// irradiance is non-negative for every direction in every channel, found by bisection on log W
// between 1 and sh_auto_window_options::max_width (W = infinity, i.e. no window, when the
// unwindowed irradiance is already non-negative). The minimum of E(n) is found by
// sh_min_irradiance: a dense deterministic spherical Fibonacci set followed by a pattern search
// from the best sample of each channel. With B <= 5 the irradiance is a polynomial of degree <= 4
// whose basins are far wider than the 0.06 rad spacing of the default 4096 samples, so the
// sampled basin is the global one and the refinement finds its minimum to ~1e-6 rad.

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <cmath>
#include <limits>

#include "../core/constants.hpp"
#include "../core/frame.hpp"
#include "../core/limits.hpp"
#include "../core/math.hpp"
#include "../core/vec.hpp"
#include "basis.hpp"
#include "convolve.hpp"

namespace ibl {

enum class sh_window_kind { hanning, lanczos };

/// Window factor w_l of band l for width W (> 0; +infinity gives 1).
template <class T> IBL_FUNC T sh_window_factor(sh_window_kind kind, int l, T width) noexcept {
    using std::cos;
    using std::sin;
    if (l == 0) return T(1);
    if (!(T(l) < width)) return T(0);
    const T x = pi_v<T> * T(l) / width;
    return kind == sh_window_kind::hanning ? T(0.5) * (T(1) + cos(x)) : sin(x) / x;
}

/// Coefficients multiplied band by band by the window of `kind` and `width`.
template <class T, int B>
IBL_FUNC sh_coeffs<T, B> sh_apply_window(const sh_coeffs<T, B>& c, sh_window_kind kind, T width) noexcept {
    T w[B];
    for (int l = 0; l < B; ++l) w[l] = sh_window_factor(kind, l, width);
    return sh_scale_bands(c, w);
}

/// Largest Fibonacci sample count of sh_min_value (2^20 SH evaluations: well past the 4096 that
/// resolve every basin for B <= 5), and the smallest pattern-search step (about 40 halvings).
inline constexpr int sh_max_min_samples = 1 << 20;
inline constexpr double sh_min_step_floor = 1e-12;

/// Minimum of each channel of a function given by SH coefficients, and where it occurs.
template <class T> struct sh_minimum {
    vec3<T> value;  ///< per-channel minimum found
    vec3<T> dir[3]; ///< unit direction of each channel's minimum
};

namespace detail {
/// Point i of an n-point spherical Fibonacci set (deterministic, near-uniform).
template <class T> IBL_FUNC vec3<T> sh_fibonacci_dir(int i, int n) noexcept {
    using std::cos;
    using std::sin;
    constexpr T golden_angle = T(2.39996322972865332223L); // pi (3 - sqrt 5)
    const T y = T(1) - (T(2) * T(i) + T(1)) / T(n);
    const T r = sin_from_cos(y);
    const T phi = golden_angle * T(i);
    return {r * cos(phi), y, r * sin(phi)};
}
} // namespace detail

/// Per-channel minimum over the sphere of f(n) = sum_k c_k Y_k(n) (pass irradiance SH to minimise
/// irradiance). `samples` Fibonacci directions, then a pattern search (8 tangent directions,
/// step halved on failure, down to `min_step` radians) from the best sample of each channel.
/// Device-callable, so it never throws: samples is clamped to [1, sh_max_min_samples] and min_step
/// to >= sh_min_step_floor (a NaN min_step counts as that floor), which bounds the work.
template <class T, int B>
IBL_FUNC sh_minimum<T> sh_min_value(const sh_coeffs<T, B>& c, int samples = 4096, T min_step = T(1e-6)) noexcept {
    using std::cos;
    using std::sin;
    using std::sqrt;
    samples = samples < 1 ? 1 : (samples > sh_max_min_samples ? sh_max_min_samples : samples);
    if (!(min_step >= T(sh_min_step_floor))) min_step = T(sh_min_step_floor);
    sh_minimum<T> best;
    for (int ch = 0; ch < 3; ++ch) {
        best.value[ch] = T(0);
        best.dir[ch] = vec3<T>(T(0), T(1), T(0));
    }
    for (int i = 0; i < samples; ++i) {
        const vec3<T> d = detail::sh_fibonacci_dir<T>(i, samples);
        const vec3<T> v = sh_evaluate(c, d);
        for (int ch = 0; ch < 3; ++ch)
            if (i == 0 || v[ch] < best.value[ch]) {
                best.value[ch] = v[ch];
                best.dir[ch] = d;
            }
    }
    for (int ch = 0; ch < 3; ++ch) {
        T step = T(2) * sqrt(four_pi_v<T> / T(samples > 0 ? samples : 1));
        vec3<T> d = best.dir[ch];
        T v = best.value[ch];
        while (step > min_step) {
            const frame<T> f = make_frame(d);
            bool moved = false;
            for (int j = 0; j < 8; ++j) {
                const T a = T(j) * (pi_v<T> / T(4));
                const vec3<T> t = cos(a) * f.t + sin(a) * f.b;
                const vec3<T> cand = glm::normalize(cos(step) * d + sin(step) * t);
                const T cv = sh_evaluate(c, cand)[ch];
                if (cv < v) {
                    v = cv;
                    d = cand;
                    moved = true;
                    break;
                }
            }
            if (!moved) step *= T(0.5);
        }
        best.value[ch] = v;
        best.dir[ch] = d;
    }
    return best;
}

/// Per-channel minimum of the irradiance E(n) of radiance SH (see sh_min_value).
template <class T, int B>
IBL_FUNC sh_minimum<T> sh_min_irradiance(const sh_coeffs<T, B>& radiance, int samples = 4096) noexcept {
    return sh_min_value(sh_irradiance(radiance), samples);
}

struct sh_auto_window_options {
    sh_window_kind kind = sh_window_kind::hanning;
    double max_width = 1024.0; ///< widest window tried (w_l > 1 - 1e-5 for l <= 4 with hanning)
    int iterations = 40;       ///< bisection steps on log W (relative width resolution 2^-40 * ln 1024)
    int samples = 4096;        ///< Fibonacci directions of the minimum search
};

template <class T, int B> struct sh_auto_window_result {
    sh_coeffs<T, B> radiance;  ///< windowed radiance SH (irradiance = sh_irradiance of it)
    T width;                   ///< chosen W; +infinity when no window was needed
    vec3<T> min_before;        ///< per-channel minimum irradiance of the input
    vec3<T> min_after;         ///< per-channel minimum irradiance after windowing (>= 0 if ok)
    bool ok;                   ///< false if even W = 1 (band 0 alone) is negative (L_00 < 0), or for
                               ///< a non-finite coefficient or max_width (then width is NaN)
};

namespace detail {
template <class T> IBL_FUNC T sh_min3(const vec3<T>& v) noexcept {
    return v.x < v.y ? (v.x < v.z ? v.x : v.z) : (v.y < v.z ? v.y : v.z);
}

/// Every coefficient and max_width finite.
template <class T, int B> IBL_FUNC bool sh_window_inputs_finite(const sh_coeffs<T, B>& radiance, double max_width) noexcept {
    bool finite = is_finite(max_width);
    for (int k = 0; k < B * B; ++k)
        finite = finite && is_finite(radiance.c[k].x) && is_finite(radiance.c[k].y) && is_finite(radiance.c[k].z);
    return finite;
}

/// max_width clamped to [1, 2^20], iterations to [0, 64].
IBL_FUNC sh_auto_window_options sh_window_options_clamped(const sh_auto_window_options& options_in) noexcept {
    sh_auto_window_options options = options_in;
    options.max_width = options.max_width < 1.0 ? 1.0 : (options.max_width > 0x1p20 ? 0x1p20 : options.max_width);
    options.iterations = options.iterations < 0 ? 0 : (options.iterations > 64 ? 64 : options.iterations);
    return options;
}

/// log W of the widest window in [1, max_width] found to keep the minimum irradiance >= 0, by
/// bisection on log W (invariant: the minimum at exp(lo) >= 0, at exp(hi) < 0 or untested hi);
/// min_lo enters as the minimum at W = 1 (>= 0) and leaves as the minimum at the returned width.
template <class T, int B>
IBL_FUNC T sh_window_log_width(const sh_coeffs<T, B>& radiance, const sh_auto_window_options& options, vec3<T>& min_lo) noexcept {
    using std::exp;
    using std::log;
    auto min_at = [&](T width) {
        return sh_min_irradiance(sh_apply_window(radiance, options.kind, width), options.samples).value;
    };
    T lo = T(0), hi = T(log(options.max_width));
    const vec3<T> min_hi = min_at(exp(hi));
    if (sh_min3(min_hi) >= T(0)) {
        min_lo = min_hi;
        return hi;
    }
    for (int it = 0; it < options.iterations; ++it) {
        const T mid = T(0.5) * (lo + hi);
        const vec3<T> m = min_at(exp(mid));
        if (sh_min3(m) >= T(0)) {
            lo = mid;
            min_lo = m;
        } else {
            hi = mid;
        }
    }
    return lo;
}
} // namespace detail

/// The weakest window of options.kind keeping the irradiance non-negative in every channel.
/// Device-callable, so it never throws: a non-finite coefficient or a non-finite max_width gives
/// ok = false, width = NaN and the input unchanged (no search); max_width is clamped to
/// [1, 2^20], iterations to [0, 64] and samples as sh_min_value clamps them, which bounds the work.
template <class T, int B>
IBL_FUNC sh_auto_window_result<T, B> sh_auto_window(const sh_coeffs<T, B>& radiance,
                                                     const sh_auto_window_options& options_in = {}) noexcept {
    using std::exp;
    if (!detail::sh_window_inputs_finite(radiance, options_in.max_width)) {
        const T nan = std::numeric_limits<T>::quiet_NaN();
        return {radiance, nan, vec3<T>(nan), vec3<T>(nan), false};
    }
    const sh_auto_window_options options = detail::sh_window_options_clamped(options_in);
    const vec3<T> min_before = sh_min_irradiance(radiance, options.samples).value;
    if (detail::sh_min3(min_before) >= T(0)) return {radiance, std::numeric_limits<T>::infinity(), min_before, min_before, true};
    vec3<T> min_lo = sh_min_irradiance(sh_apply_window(radiance, options.kind, T(1)), options.samples).value;
    if (detail::sh_min3(min_lo) < T(0)) // negative mean radiance: no window can help
        return {sh_apply_window(radiance, options.kind, T(1)), T(1), min_before, min_lo, false};
    const T width = exp(detail::sh_window_log_width(radiance, options, min_lo));
    return {sh_apply_window(radiance, options.kind, width), width, min_before, min_lo, true};
}

} // namespace ibl

#endif // IBL_DETAIL_CXX20
