#pragma once
// ibl/reference/metrics.hpp — error metrics of a computed product against a reference (host only).
//
// Elements are the RGB components of texels: a texel of three channels is three elements. All
// sums are in double (the inputs may be float), in element order (deterministic).
//
//   max_abs        max |a - b|
//   rmse           sqrt(mean (a - b)^2)
//   nrmse          rmse / sqrt(mean b^2)           (normalised RMSE: dominated by bright regions)
//   rel_rmse       sqrt(mean ((a - b) / |b|)^2)    (RMS of the per-element relative error: a
//                  firefly on a dim texel weighs as much as on a bright one). Elements whose
//                  reference magnitude is below `floor` use `floor` as denominator.
//   max_rel        max |a - b| / max(|b|, floor)
//   max_ratio      max a / b over elements with b > floor ("largest overshoot": 10 means some
//                  element is 10 times its reference)
//   min_value      min a (negative lobes, ringing)
// Non-finite elements of a make max_abs, rmse, ... infinite/NaN (they are errors, not skipped);
// `nonfinite` counts them.

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <cmath>
#include <cstddef>
#include <limits>
#include <span>
#include <stdexcept>
#include <string>

#include "../core/vec.hpp"
#include "../env/cubemap.hpp"

namespace ibl {

struct error_metrics {
    double max_abs = 0;
    double rmse = 0;
    double nrmse = 0;
    double rel_rmse = 0;
    double max_rel = 0;
    double max_ratio = 0;
    double min_value = std::numeric_limits<double>::infinity();
    std::size_t count = 0;     ///< elements compared
    std::size_t nonfinite = 0; ///< non-finite elements of a
};

/// Accumulates the metrics element by element; finish() forms the means.
class error_accumulator {
public:
    explicit error_accumulator(double floor = 1e-30) noexcept : floor_(floor) {}

    void add(double a, double b) noexcept {
        const double d = a - b;
        const double ab = std::fabs(b);
        const double den = ab > floor_ ? ab : floor_;
        m_.max_abs = std::fabs(d) > m_.max_abs || !std::isfinite(d) ? std::fabs(d) : m_.max_abs;
        sq_ += d * d;
        ref_sq_ += b * b;
        rel_sq_ += (d / den) * (d / den);
        const double rel = std::fabs(d) / den;
        m_.max_rel = rel > m_.max_rel || !std::isfinite(rel) ? rel : m_.max_rel;
        if (b > floor_ && a / b > m_.max_ratio) m_.max_ratio = a / b;
        if (a < m_.min_value) m_.min_value = a;
        if (!std::isfinite(a)) ++m_.nonfinite;
        ++m_.count;
    }
    template <class A, class B> void add(const vec3<A>& a, const vec3<B>& b) noexcept {
        for (int k = 0; k < 3; ++k) add(double(a[k]), double(b[k]));
    }

    [[nodiscard]] error_metrics finish() const noexcept {
        error_metrics m = m_;
        if (m.count == 0) {
            m.min_value = 0;
            return m;
        }
        const double n = double(m.count);
        m.rmse = std::sqrt(sq_ / n);
        m.nrmse = ref_sq_ > 0 ? std::sqrt(sq_ / ref_sq_) : m.rmse;
        m.rel_rmse = std::sqrt(rel_sq_ / n);
        if (m.nonfinite > 0) m.max_abs = std::numeric_limits<double>::infinity();
        return m;
    }

private:
    double floor_;
    error_metrics m_{};
    double sq_ = 0, ref_sq_ = 0, rel_sq_ = 0;
};

/// Metrics of a against b, element-wise over two arrays of texels of equal length (extra
/// elements of the longer array are ignored).
template <class A, class B>
[[nodiscard]] error_metrics compare(std::span<const vec3<A>> a, std::span<const vec3<B>> b, double floor = 1e-30) {
    error_accumulator acc(floor);
    const std::size_t n = a.size() < b.size() ? a.size() : b.size();
    for (std::size_t i = 0; i < n; ++i) acc.add(a[i], b[i]);
    return acc.finish();
}

namespace detail {
template <class C> void check_metric_level(const C& c, int level, const char* arg) {
    if (level < 0 || level >= c.levels())
        throw std::invalid_argument(std::string("ibl::compare_level: ") + arg + " = " + std::to_string(level) +
                                    " outside [0, " + std::to_string(c.levels()) + ")");
}
} // namespace detail

/// Metrics over every interior texel of one level of two cubemaps of equal size at that level
/// (the levels may sit at different indices: a_level, b_level). Throws std::invalid_argument for a
/// level outside its cubemap's chain.
template <class A, class B>
[[nodiscard]] error_metrics compare_level(const cubemap<A>& a, int a_level, const cubemap<B>& b, int b_level,
                                          double floor = 1e-30) {
    detail::check_metric_level(a, a_level, "a_level");
    detail::check_metric_level(b, b_level, "b_level");
    error_accumulator acc(floor);
    const int n = a.size(a_level);
    if (n != b.size(b_level)) return acc.finish();
    for (int f = 0; f < 6; ++f)
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) acc.add(a.texel(f, x, y, a_level), b.texel(f, x, y, b_level));
    return acc.finish();
}

/// Metrics of a level against an array of reference texels in cubemap texel order
/// (face, then row y, then column x). Throws std::invalid_argument for a level outside the chain.
template <class A, class B>
[[nodiscard]] error_metrics compare_level(const cubemap<A>& a, int level, std::span<const vec3<B>> ref,
                                          double floor = 1e-30) {
    detail::check_metric_level(a, level, "level");
    error_accumulator acc(floor);
    const int n = a.size(level);
    if (ref.size() < std::size_t(6) * std::size_t(n) * std::size_t(n)) return acc.finish();
    std::size_t i = 0;
    for (int f = 0; f < 6; ++f)
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) acc.add(a.texel(f, x, y, level), ref[i++]);
    return acc.finish();
}

} // namespace ibl

#endif // IBL_DETAIL_CXX20
