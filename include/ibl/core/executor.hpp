#pragma once
// ibl/core/executor.hpp — the executor hook: how integrators spread independent work.
//
// An executor is any callable `ex(count, fn)` that calls `fn(begin, end)` on disjoint ranges
// [begin, end) covering [0, count), possibly concurrently, and returns when all calls have
// finished. Engines pass a lambda that hands the ranges to their job system. The library ships
//   serial_executor  — one call fn(0, count) on the calling thread;
//   thread_executor  — persistent std::thread workers taking chunks from a shared counter (host only).
//
// Determinism: integrators never let a result depend on the partition. Items are computed
// independently, and reductions go through parallel_reduce_blocks, which fixes the block size
// from the problem (not from the executor) and combines block results in block order.

#include "config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <exception>
#include <memory>
#include <mutex>
#include <thread>
#include <utility>
#include <vector>
#if defined(__unix__) || defined(__APPLE__)
#include <unistd.h>
#endif

namespace ibl {

namespace detail {

/// Persistent workers for thread_executor: a call hands its range to the workers that wait here
/// instead of starting and joining threads (a wake-up costs a small fraction of a thread's start
/// and join: docs/ARCHITECTURE.md, "Determinism and executors"), and the range is taken in chunks from a shared counter, so that a thread whose
/// items are cheap takes more of them (a face row's cost varies with where its taps and peaks
/// read). One pool per worker count, created on first use and never destroyed (its threads wait
/// on a condition variable until the process exits; no destruction order at exit to get wrong);
/// a child of fork() starts its own.
/// A worker spins for up to spin_time after a call before it blocks, and the caller spins while
/// the workers finish: calls that follow each other closely (a prefilter's levels) pass no
/// wake-up through the kernel (docs/ARCHITECTURE.md, "Determinism and executors").
/// One call at a time: a call made while the pool is busy (from another thread, or from inside a
/// job) runs on its own threads, as before the pool. An exception thrown by a chunk, on any
/// thread, stops the call's remaining chunks and is rethrown to the caller once the workers are
/// done.
class worker_pool {
public:
    explicit worker_pool(std::size_t workers) {
        threads_.reserve(workers);
        for (std::size_t k = 0; k < workers; ++k) threads_.emplace_back([this] { work(); });
    }
    worker_pool(const worker_pool&) = delete;
    worker_pool& operator=(const worker_pool&) = delete;

    /// The pool of `workers` threads (created on first use).
    static worker_pool& shared(std::size_t workers) {
        static std::mutex m;
        static std::vector<worker_pool*> pools; // index: workers; leaked on purpose (header comment)
        std::lock_guard<std::mutex> lock(m);
#if defined(__unix__) || defined(__APPLE__)
        // A child of fork() has none of the parent's workers: it starts pools of its own (the
        // parent's copies are left alone), where a call would otherwise wait for them forever.
        static pid_t owner = getpid();
        if (getpid() != owner) {
            pools.clear();
            owner = getpid();
        }
#endif
        if (pools.size() <= workers) pools.resize(workers + 1, nullptr);
        if (!pools[workers]) pools[workers] = new worker_pool(workers);
        return *pools[workers];
    }

    /// Runs fn on chunks of `chunk` items covering [0, count), on the workers and the calling
    /// thread; returns when every chunk is done. False (nothing run) when the pool is busy.
    template <class F> bool try_run(std::size_t count, std::size_t chunk, F& fn) {
        if (in_job_flag()) return false; // a call from inside a job (before the lock: it may be ours)
        std::unique_lock<std::mutex> busy(busy_, std::try_to_lock);
        if (!busy.owns_lock()) return false;
        job_fn_ = [](void* f, std::size_t b, std::size_t e) { (*static_cast<F*>(f))(b, e); };
        job_ = const_cast<void*>(static_cast<const void*>(std::addressof(fn)));
        count_ = count;
        chunk_ = chunk == 0 ? 1 : chunk;
        next_.store(0, std::memory_order_relaxed);
        {
            std::lock_guard<std::mutex> lock(m_);
            error_ = nullptr; // before the workers see the job
            active_ = threads_.size();
            busy_workers_.store(active_, std::memory_order_relaxed);
            ++generation_;
            seen_generation_.store(generation_, std::memory_order_release);
        }
        start_.notify_all();
        take_chunks();
        // The workers finish their last chunks about now: wait for them awake a little first.
        spin_until([this] { return busy_workers_.load(std::memory_order_acquire) == 0; });
        std::unique_lock<std::mutex> lock(m_);
        done_.wait(lock, [this] { return active_ == 0; }); // the workers read the job until then
        job_ = nullptr;
        if (error_) std::rethrow_exception(std::exchange(error_, nullptr)); // the first chunk's exception
        return true;
    }

private:
    static bool& in_job_flag() noexcept {
        thread_local bool in_job = false;
        return in_job;
    }
    /// Chunks until none is left; an exception stops the call's remaining chunks and is kept for
    /// the caller (the first one).
    void take_chunks() noexcept {
        in_job_flag() = true;
        for (;;) {
            const std::size_t b = next_.fetch_add(chunk_, std::memory_order_relaxed);
            if (b >= count_) break;
            try {
                job_fn_(job_, b, b + chunk_ < count_ ? b + chunk_ : count_);
            } catch (...) {
                next_.store(count_, std::memory_order_relaxed);
                std::lock_guard<std::mutex> lock(m_);
                if (!error_) error_ = std::current_exception();
            }
        }
        in_job_flag() = false;
    }
    /// Spins (a pause a turn) until done() or spin_time has passed; true when done() became true.
    template <class Done> static bool spin_until(Done&& done) noexcept {
        const auto until = std::chrono::steady_clock::now() + spin_time;
        for (unsigned k = 0;; ++k) {
            if (done()) return true;
#if defined(__x86_64__) || defined(__i386__)
            __builtin_ia32_pause();
#else
            std::this_thread::yield();
#endif
            if ((k & 63u) == 63u && std::chrono::steady_clock::now() >= until) return false;
        }
    }
    void work() {
        std::size_t seen = 0;
        for (;;) {
            // A call that follows the last one closely (a prefilter's levels) finds this worker
            // awake: no wake-up through the kernel.
            spin_until([&] { return seen_generation_.load(std::memory_order_acquire) != seen; });
            {
                std::unique_lock<std::mutex> lock(m_);
                start_.wait(lock, [&] { return generation_ != seen; });
                seen = generation_;
            }
            take_chunks();
            std::lock_guard<std::mutex> lock(m_);
            busy_workers_.store(active_ - 1, std::memory_order_release);
            if (--active_ == 0) done_.notify_one();
        }
    }
    static constexpr std::chrono::microseconds spin_time{300};

    std::vector<std::thread> threads_;
    std::mutex busy_; ///< held by the call in progress
    std::mutex m_;
    std::condition_variable start_, done_;
    std::size_t generation_ = 0, active_ = 0;
    void (*job_fn_)(void*, std::size_t, std::size_t) = nullptr;
    void* job_ = nullptr;
    std::size_t count_ = 0, chunk_ = 1;
    std::atomic<std::size_t> next_{0};
    std::atomic<std::size_t> seen_generation_{0}, busy_workers_{0}; ///< generation_ and active_, for the spins
    std::exception_ptr error_; ///< guarded by m_
};

} // namespace detail

/// Runs everything on the calling thread.
struct serial_executor {
    template <class F> void operator()(std::size_t count, F&& fn) const {
        if (count > 0) fn(std::size_t(0), count);
    }
};

/// Runs [0, count) on `threads` threads (the calling thread and threads - 1 persistent workers of
/// detail::worker_pool), in chunks of about count / (4 threads) items taken in turn from a shared
/// counter. threads = 0 means std::thread::hardware_concurrency(). A call made while the pool is
/// busy (from another thread, or from inside one of its own chunks) starts its own std::threads,
/// one contiguous range each. An exception thrown by fn is rethrown to the caller once every
/// thread is done (the first range's, or the first chunk's).
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
        if (detail::worker_pool::shared(n - 1).try_run(count, (count + 4 * n - 1) / (4 * n), fn)) return;
        std::vector<std::thread> pool;
        pool.reserve(n - 1);
        std::vector<std::exception_ptr> errors(n); // per range: the threads are joined before any is rethrown
        auto bound = [&](std::size_t k) { return count * k / n; };
        auto range = [&](std::size_t k) {
            try {
                fn(bound(k), bound(k + 1));
            } catch (...) {
                errors[k] = std::current_exception();
            }
        };
        for (std::size_t k = 1; k < n; ++k) pool.emplace_back(range, k);
        range(0);
        for (auto& t : pool) t.join();
        for (const std::exception_ptr& e : errors)
            if (e) std::rethrow_exception(e);
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
