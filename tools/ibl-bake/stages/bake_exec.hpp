#pragma once
// tools/ibl-bake/stages/bake_exec.hpp — the tool's executor (work sharing with progress) and the
// progress display.
//
// progress: one "step" at a time (begin/end, called on the main thread). On a TTY stderr a bar
// "  prefilter level 3/6 [=========>          ]  47%  1.8 s" is drawn once the step has run for a
// second (steps shorter than that print nothing), redrawn at most every 100 ms and cleared at the
// end, leaving "  prefilter: 2345 ms". When stderr is not a TTY, every step writes one log line
// when it ends ("ibl-bake: prefilter ... 2345 ms"). --quiet silences both.
//
// pool_executor: the library's executor concept (core/executor.hpp): ex(count, fn) runs fn on
// disjoint ranges covering [0, count), through ibl::thread_executor's persistent workers (chunks
// handed out dynamically, so a slow row does not stall a thread). The library's integrators make
// every item independent of the partition, so the output is bit-identical for any thread count.
// The calling thread takes chunks too and reports the fraction done.

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdio>
#include <string>
#include <thread>
#include <vector>

#include <ibl/core/executor.hpp>

namespace ibl_bake {

class progress {
public:
    progress(bool enabled, bool tty) : enabled_(enabled), tty_(tty) {}

    void begin(const std::string& step) {
        step_ = step;
        label_ = step;
        fraction_ = 0.0;
        pass_ = 0;
        drawn_ = false;
        t0_ = clock::now();
        last_draw_ = t0_;
    }
    /// A sub-label (e.g. "level 3/6") shown after the step name; the fraction restarts.
    void label(const std::string& sub) {
        label_ = sub.empty() ? step_ : step_ + " " + sub;
        fraction_ = 0.0;
        pass_ = 0;
        update(0.0);
    }
    /// A new parallel pass (one executor call) of the current step: the fraction restarts and
    /// the pass number is shown from the second pass on.
    void next_pass() {
        ++pass_;
        fraction_ = 0.0;
    }
    /// Called from the main thread only.
    void update(double fraction) {
        fraction_ = fraction;
        if (!enabled_ || !tty_) return;
        const auto now = clock::now();
        if (now - t0_ < std::chrono::seconds(1)) return;
        if (drawn_ && now - last_draw_ < std::chrono::milliseconds(100)) return;
        last_draw_ = now;
        drawn_ = true;
        constexpr int width = 30;
        const int fill = int(std::clamp(fraction, 0.0, 1.0) * width);
        std::string bar(std::size_t(width), ' ');
        for (int i = 0; i < fill; ++i) bar[std::size_t(i)] = '=';
        if (fill < width) bar[std::size_t(fill)] = '>';
        const std::string shown = pass_ > 1 ? label_ + " pass " + std::to_string(pass_) : label_;
        std::fprintf(stderr, "\r\033[K  %-34s [%s] %3d%%  %.1f s", shown.c_str(), bar.c_str(), int(100.0 * fraction),
                     seconds());
        std::fflush(stderr);
    }
    /// Ends the step; returns its duration in milliseconds.
    double end() {
        const double ms = 1e3 * seconds();
        if (enabled_) {
            if (tty_) {
                if (drawn_) std::fprintf(stderr, "\r\033[K  %s: %.0f ms\n", step_.c_str(), ms);
            } else {
                std::fprintf(stderr, "ibl-bake: %s ... %.0f ms\n", step_.c_str(), ms);
            }
            std::fflush(stderr);
        }
        return ms;
    }

private:
    using clock = std::chrono::steady_clock;
    double seconds() const { return std::chrono::duration<double>(clock::now() - t0_).count(); }

    bool enabled_, tty_, drawn_ = false;
    std::string step_, label_;
    double fraction_ = 0.0;
    int pass_ = 0;
    clock::time_point t0_{}, last_draw_{};
};

class pool_executor {
public:
    pool_executor(unsigned threads, progress* p) : threads_(threads ? threads : default_threads()), progress_(p) {}

    unsigned threads() const noexcept { return threads_; }

    template <class F> void operator()(std::size_t count, F&& fn) const {
        if (count == 0) return;
        if (progress_) progress_->next_pass();
        // The library's persistent workers (ibl::thread_executor: no thread started per call; a
        // bake makes dozens of calls, a fast prefilter tens of them within milliseconds); the
        // calling thread takes chunks too and is the one that reports the fraction done.
        std::atomic<std::size_t> done{0};
        const std::thread::id caller = std::this_thread::get_id();
        ibl::thread_executor{threads_}(count, [&](std::size_t b, std::size_t e) {
            fn(b, e);
            const std::size_t d = done.fetch_add(e - b) + (e - b);
            if (progress_ && std::this_thread::get_id() == caller) progress_->update(double(d) / double(count));
        });
        if (progress_) progress_->update(1.0);
    }

private:
    static unsigned default_threads() {
        const unsigned n = std::thread::hardware_concurrency();
        return n ? n : 1;
    }
    unsigned threads_;
    progress* progress_;
};

} // namespace ibl_bake
