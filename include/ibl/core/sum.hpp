#pragma once
// ibl/core/sum.hpp — accumulation of long sums.
//
// neumaier_sum: compensated summation (A. Neumaier, 1974, improving Kahan 1965). The running
// error is bounded independently of the number of terms n: |error| <= 2 eps sum|x_i| + O(n eps^2),
// against (n - 1) eps sum|x_i| for naive accumulation. It relies on IEEE semantics: compiling
// with -ffast-math (or -fassociative-math) lets the compiler delete the compensation.
//
// pairwise_sum: recursive halving with a block of 8 naive additions at the leaves; error
// O(eps log n) sum|x_i|, no extra state, and vectorises. Used where a whole array is at hand.

#include "config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <cstddef>
#include <cmath>


namespace ibl {

template <class T> struct neumaier_sum {
    T sum{0};
    T c{0}; ///< running compensation (the low-order bits lost so far)

    IBL_FUNC_VOID void add(T x) noexcept {
        using std::fabs;
        const T t = sum + x;
        if (fabs(sum) >= fabs(x))
            c += (sum - t) + x;
        else
            c += (x - t) + sum;
        sum = t;
    }
    IBL_FUNC_VOID neumaier_sum& operator+=(T x) noexcept {
        add(x);
        return *this;
    }
    /// Merge another accumulator (for partial sums computed on separate ranges).
    IBL_FUNC_VOID void merge(const neumaier_sum& o) noexcept {
        add(o.sum);
        add(o.c);
    }
    IBL_FUNC T value() const noexcept { return sum + c; }
};

/// Pairwise sum of x[0..n). Deterministic: the tree depends only on n.
template <class T> IBL_FUNC T pairwise_sum(const T* x, std::size_t n) noexcept {
    constexpr std::size_t leaf = 8;
    if (n <= leaf) {
        T s = T(0);
        for (std::size_t i = 0; i < n; ++i) s += x[i];
        return s;
    }
    const std::size_t h = n / 2;
    return pairwise_sum(x, h) + pairwise_sum(x + h, n - h);
}

} // namespace ibl

#endif // IBL_DETAIL_CXX20
