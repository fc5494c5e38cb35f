#pragma once
// ibl/core/executor.hpp — the executor hook: how integrators spread independent work.
//
// An executor is any callable `ex(count, fn)` that calls `fn(begin, end)` on disjoint ranges
// [begin, end) covering [0, count), possibly concurrently, and returns when all calls have
// finished. Engines pass a lambda that hands the ranges to their job system. The library ships
//   serial_executor  — one call fn(0, count) on the calling thread;
//   thread_executor  — std::thread workers, each taking contiguous chunks (host only).
//
// Determinism: integrators never let a result depend on the partition. Items are computed
// independently, and reductions go through parallel_reduce_blocks, which fixes the block size
// from the problem (not from the executor) and combines block results in block order.

#include "config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <cstddef>
#include <thread>
#include <vector>

namespace ibl {

/// Runs everything on the calling thread.
struct serial_executor {
    template <class F> void operator()(std::size_t count, F&& fn) const {
        if (count > 0) fn(std::size_t(0), count);
    }
};

/// Splits [0, count) into at most `threads` contiguous chunks run on std::threads (the calling
/// thread takes the first). threads = 0 means std::thread::hardware_concurrency().
struct thread_executor {
    unsigned threads = 0;

    template <class F> void operator()(std::size_t count, F&& fn) const {
        if (count == 0) return;
        std::size_t n = threads ? threads : std::thread::hardware_concurrency();
        if (n == 0) n = 1;
        if (n > count) n = count;
        if (n == 1) {
            fn(std::size_t(0), count);
            return;
        }
        std::vector<std::thread> pool;
        pool.reserve(n - 1);
        auto bound = [&](std::size_t k) { return count * k / n; };
        for (std::size_t k = 1; k < n; ++k)
            pool.emplace_back([&fn, b = bound(k), e = bound(k + 1)] { fn(b, e); });
        fn(bound(0), bound(1));
        for (auto& t : pool) t.join();
    }
};

/// Deterministic reduction: computes partial = block_fn(block) for blocks 0..blocks-1 through the
/// executor, then folds them left to right with combine(acc, partial) starting from init. The
/// result depends only on the blocks, never on how the executor partitions them.
template <class R, class Executor, class BlockFn, class Combine>
R parallel_reduce_blocks(Executor&& ex, std::size_t blocks, R init, BlockFn&& block_fn, Combine&& combine) {
    std::vector<R> partial(blocks, init);
    ex(blocks, [&](std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i) partial[i] = block_fn(i);
    });
    R acc = init;
    for (std::size_t i = 0; i < blocks; ++i) acc = combine(acc, partial[i]);
    return acc;
}

} // namespace ibl

#endif // IBL_DETAIL_CXX20
