#pragma once
// ibl/bake/prefilter_update.hpp — time-sliced prefiltering of a dynamic probe: the chain of
// bake/prefilter.hpp, computed a bounded amount of work per call (host only).
//
// A renderer that re-filters a probe at run time (a captured reflection probe, a sky that changes
// with the time of day) cannot spend a whole prefilter in one frame. prefilter_update holds the
// work of one prefilter(source, opt) as a sequence of work units, face row by face row, level by
// level in prefilter's order (prefilter_plan's levels from the mirror level 0 to the roughest, or
// the reverse when the fast filter's coarse tail reads each level's next: detail::prefilter_order),
// and step(budget) computes units until the next unit would exceed `budget` source reads ("taps").
// The units and their costs:
//     a row of a mirror level 0:          n_l taps (one read per texel);
//     a tap of a chunk of W lanes of a    W taps (the kernel works on a row in chunks of 16
//     convolved level:                    texels, the row's tail in chunks of 8, 4 and 1:
//                                         convolve_row; a texel has S_l T_l taps, S_l samples kept
//                                         after dropping n.l <= 0, T_l = 2 for trilinear reads, 1
//                                         for nearest); the last tap of a chunk also carries the
//                                         chunk's finish, 4 W taps (the lanes' frames and results),
//                                         and the last tap of a row's last chunk the row's finish,
//                                         n_l (ceil(P_l / 5) + 2 C_l) taps (P_l the peaks of the
//                                         fast filter's split at that level,
//                                         bake/prefilter_peaks.hpp, five to a tap; C_l = 1 with a
//                                         coarse tail, its bilinear read of the next level:
//                                         whole-row operations, done once the row's texels all
//                                         have their tap sums);
//     the borders of a face of a          ceil(B (4 n_l + 4) / 2) taps (two border texels to a
//     finished level:                     tap; B = 2 when a coarse tail reads the level, whose
//                                         copy before the peaks, as_next, has its borders too,
//                                         else 1: cubemap::update_borders(level, face)),
// so the cost of a call is bounded by max(budget, the dearest unit) (unit_taps: a chunk's last
// tap with its finish and the row's, or a face's borders) and proportional to the taps it reports
// (bench/bench_prefilter.cpp, BM_prefilter_update_step). Whole rows that fit go through the
// executor; a row that does not fit is computed chunk by chunk, and a chunk's taps may span calls:
// its lanes' accumulators (detail::lane_sums) are kept between calls, and convolve_lanes_part
// continues them with the same operations in the same order, at the full lane width. Every texel
// is thus computed by exactly the operations prefilter uses (the same tables, the same kernel,
// whose lanes are independent, the same order of the whole-row operations), so the finished chain
// equals prefilter(source, opt) bit for bit, whatever the budgets of the calls and the executor
// within a call.
//
// Source changes. set_source(c) restarts the pass on the new source (the rows already computed
// belong to the old one); result() keeps returning the last finished chain until the new pass
// finishes, so a renderer always reads a complete chain (double buffering). The sample tables are
// rebuilt only when the source's size or mip count changes (they depend on nothing else); the
// fast filter's peaks (bake/prefilter_peaks.hpp) are split again from each new source.
//
// Storage. The rows are written in place into the chain under construction, and a level that a
// coarse tail reads is written before its peaks into a cube of its own (as_next), row by row, so
// nothing is copied when a level or a pass finishes: the faces' borders are work units, and the
// finished chain is swapped with the previous result. An intermediate level of the fast filter
// (prefilter_options::mid_tail, bake/prefilter_fast.hpp) is a level of units like the others,
// just before the level that reads it, written only into its own cube (it has no peaks and no
// place in the chain); unit_taps of the level that reads it counts its units too.
//
// A pass starts with more units. With the fast filter's peak split (bake/prefilter_peaks.hpp)
// first the split itself: for a source whose mips do not reach 1 x 1, the mean of level 0 by
// texel solid angles, a face row per unit (1 + n / 2 taps; with a 1 x 1 level the mean is six
// reads), then its scan of level 0, a face row per unit (1 + n / 3 taps: three texels to a tap),
// its selection of the threshold (1 + H / 2 taps, H the texels above the ratio's threshold), its
// peaks, 64 to a unit (1 + 48 taps a peak: an exact solid angle each), and each output level's
// merged peak list, a level per unit (1 + 8 P taps). Until those units are
// done, the pass's rows count no peaks: total_taps() and remaining_taps() are exact from then on
// (peaks_ready()). Then the packed copy of the source that the taps read, a bordered row
// of one of its levels per unit (n + 2 taps: a texel to a tap), then, with the fast
// filter's peak split, the patch that takes the peaks out of it (1 + 8 P L taps, P peaks, L levels),
// then, when the fast filter reconstructs rough levels from spherical harmonics
// (bake/prefilter_sh.hpp), the projection of the packed source, a row of its level per unit
// (1 + ceil(m B^2 / 15) taps for m texels and B bands), then the reduction of its sums (one unit). A
// level by spherical harmonics is computed in whole rows of 16-lane chunks, 16 ceil(n_l / 16)
// ceil((B_l^2 + 146) / 32) taps plus the row's peaks (as its finish), like a mirror level's rows.
// Each kind of unit's count was set so that one thread spends about the same time a tap on each
// (2.2-2.4 ns on the VM of docs/ARCHITECTURE.md, "Dynamic probes"; the constants below give the
// measurements).
//
// Time budgets. step_for(duration) runs step in slices, each given half of the time left at the
// rate measured by the earlier slices and calls (seconds a tap, seconds_per_tap(): slices of at
// least 1024 taps move it in log space, at most 4x a slice, so a descheduled slice is forgotten
// within a few calls), reading the clock between slices only. A slice whose true rate is within
// 2x of the estimate ends within the time left, so the call ends within its budget unless one unit
// alone is dearer than what is left; the rate still differs by phase (a row's taps run on one
// thread, whole rows through the executor; a row's cost depends on where its taps read), and a
// slice that the machine stops (a virtual CPU descheduled for tens of microseconds) leaves no time
// for the next one, so the call does no more work after the stop: the halving absorbs both where a
// fixed tap budget cannot
// (bench/bench_prefilter.cpp, BM_prefilter_update_time).
//
// Costs outside the budget: set_source (and the constructor) keeps its own copy of the source (one
// copy of every texel, none when the source is moved in) and, for a first pass or a source of
// another shape, plans the levels and allocates the packed copy, the chain under construction and
// the as_next cubes (later passes reuse the storage). Measured on the courtyard at 256^2, one
// thread (bench_prefilter_hdri BM_hdri_update_set_source, with a copy): 0.48 ms, 0.96 ms while the
// peak split ran in set_source; moved in, a few microseconds (docs/ARCHITECTURE.md, "Dynamic probes").
//
// Domain: a cubemap<float> source with its mip chain (cubemap::generate_mips); the options of
// prefilter (the same checks and exceptions, at construction). budget 0 computes nothing.

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

#include "../batch/sphere_kernel.hpp"
#include "../core/executor.hpp"
#include "../core/vec.hpp"
#include "../env/cube_geometry.hpp"
#include "../env/cubemap.hpp"
#include "../runtime/chain.hpp"
#include "../sampling/lobe.hpp"
#include "prefilter.hpp"
#include "sphere_convolve.hpp"

namespace ibl {

template <class Lobe = ggx_lobe>
    requires ld_lobe<Lobe>
class prefilter_update {
public:
    /// Plans the pass of prefilter<Lobe>(source, opt) and starts it (on its own copy of the source,
    /// or on the source moved in). Throws as prefilter.
    explicit prefilter_update(cubemap<float> source, prefilter_options opt = {}) : opt_(std::move(opt)) {
        set_source(std::move(source));
    }

    /// Restarts the pass on a new source; result() keeps the last finished chain until the new
    /// pass finishes. Throws as prefilter (a new size may exceed the limits). The pass reads its
    /// own copy of the source (the caller may change `source` at once): a copy of every texel of
    /// every level; moving the source in (set_source(std::move(c))) saves it.
    void set_source(const cubemap<float>& source) {
        const bool same_shape = source_ && source_->size(0) == source.size(0) && source_->levels() == source.levels();
        source_ = source;
        restart(same_shape);
    }
    void set_source(cubemap<float>&& source) {
        const bool same_shape = source_ && source_->size(0) == source.size(0) && source_->levels() == source.levels();
        source_ = std::move(source);
        restart(same_shape);
    }

    /// Computes work units (header comment) until the next would exceed `budget` taps (at least
    /// one unit when budget > 0 and the pass is not finished): whole face rows through the
    /// executor (rows are independent), a row's chunks of lanes and the taps of a chunk on the
    /// calling thread. Returns the taps computed; finishing a pass publishes it as result().
    template <class Executor = serial_executor>
    std::uint64_t step(std::uint64_t budget, Executor&& ex = Executor{}) {
        return step_units(budget, ex, true);
    }

    /// Computes work units for about `budget` of wall time instead of a number of taps (header
    /// comment, "Time budgets"): slices of step(taps), each given half of the time left at the
    /// rate measured so far (kept across calls), until the time left holds less than a lane tap
    /// (16 taps) at that rate or the next unit does not fit the slice. At least one unit when
    /// budget > 0 and the pass is not finished (as step). Returns the taps computed; the finished
    /// chain is the same as with step (the same units in the same order).
    template <class Rep, class Period, class Executor = serial_executor>
    std::uint64_t step_for(std::chrono::duration<Rep, Period> budget, Executor&& ex = Executor{}) {
        using clock = std::chrono::steady_clock;
        const double total = std::chrono::duration<double>(budget).count();
        if (!(total > 0.0)) return 0;
        const clock::time_point start = clock::now();
        double elapsed = 0.0;
        std::uint64_t spent = 0;
        while (!pass_done_) {
            const double fit = 0.5 * (total - elapsed) / seconds_per_tap_;
            std::uint64_t k = fit < 1e15 ? std::uint64_t(std::max(0.0, fit)) : std::uint64_t(1e15);
            if (k < detail::convolve_width) {
                if (spent > 0) break;
                k = 1; // progress: one unit even above the budget
            }
            const clock::time_point t0 = clock::now();
            const std::uint64_t t = step_units(k, ex, spent == 0); // the first slice makes progress
            const clock::time_point t1 = clock::now();
            elapsed = std::chrono::duration<double>(t1 - start).count();
            if (t >= 1024) { // the rate, from slices long enough for the clock (a few microseconds)
                const double rate = std::chrono::duration<double>(t1 - t0).count() / double(t);
                if (rate > 0.0 && std::isfinite(rate)) {
                    // In log space, a slice of 2^16 taps or more all the way, a shorter one by its
                    // share but at least an eighth; a factor of 4 at most a slice, so that one
                    // descheduled slice neither stalls the next calls nor takes long to forget.
                    const double a = std::clamp(double(t) / 65536.0, 0.125, 1.0);
                    seconds_per_tap_ *= std::pow(std::clamp(rate / seconds_per_tap_, 0.25, 4.0), a);
                }
            }
            spent += t;
            if (t == 0) break; // the next unit is dearer than the slice
        }
        return spent;
    }
    /// The rate step_for plans with (seconds a tap, as measured by its calls so far: slices of at
    /// least 1024 taps move it in log space, by at most a factor of 4 a slice).
    double seconds_per_tap() const noexcept { return seconds_per_tap_; }

    /// Runs the rest of the pass (no budget).
    template <class Executor = serial_executor> void finish(Executor&& ex = Executor{}) {
        while (!pass_done_) step(remaining_taps(), ex);
    }

    /// True after a pass finished and no new one started (set_source restarts).
    bool done() const noexcept { return pass_done_; }
    /// The last finished chain (empty before the first pass finishes).
    const std::optional<specular_chain>& result() const noexcept { return result_; }
    /// Taps of a whole pass, and those still to compute in the current one. Both are exact once
    /// peaks_ready(); before, the split's units (header comment) count the texels its scan kept so
    /// far and the levels' rows count no peaks, so they grow as the split finds them.
    std::uint64_t total_taps() const noexcept {
        std::uint64_t t = whole_split_taps() + setup_taps(0) + patch_taps() + sh_taps(0);
        for (const level_work& lw : levels_) t += level_taps(lw);
        return t;
    }
    std::uint64_t remaining_taps() const noexcept {
        if (pass_done_) return 0;
        const std::uint64_t sh = sh_done_ ? 0 : sh_taps(sh_row_);
        if (!packed_) {
            std::uint64_t t = split_taps() + setup_taps(pack_item_) + patch_taps() + sh;
            for (const level_work& w : levels_) t += level_taps(w);
            return t;
        }
        const level_work& lw = levels_[level_];
        std::uint64_t t = std::uint64_t(6 - face_) * lw.border_taps + sh;
        if (row_ < std::size_t(6 * lw.n)) {
            t += std::uint64_t(6 * lw.n - int(row_)) * lw.taps_per_row;
            if (!lw.whole_rows()) // the texels of the row's finished chunks and the taps of its current chunk
                t -= std::uint64_t(lw.chunks[chunk_].first) * lw.texel_taps + std::uint64_t(lw.chunks[chunk_].second) * tap_;
        }
        for (std::size_t p = pos_ + 1; p < order_.size(); ++p) t += level_taps(levels_[order_[p]]);
        return t;
    }
    /// True once the pass's peak split and every level's merged peaks are done (its first units):
    /// from then on the pass's taps are known exactly.
    bool peaks_ready() const noexcept {
        return split_selected_ && split_peak_ >= src_->split_peaks() && peaks_level_ >= plan_.size();
    }
    /// The pass's plan (prefilter_plan of the options for this source).
    const std::vector<prefilter_level>& plan() const noexcept { return plan_; }
    /// Face size of output level k, the taps of one of its rows and of its dearest work unit
    /// (k < plan().size(); header comment): a budget of at least the largest unit_taps keeps every
    /// call within the budget.
    int level_size(std::size_t k) const noexcept { return levels_[k].n; }
    std::uint64_t row_taps(std::size_t k) const noexcept { return levels_[k].taps_per_row; }
    /// The dearest of a pass's first units (a packed row of the source, the split's patch, a row of
    /// the projection by spherical harmonics).
    std::uint64_t setup_unit_taps() const noexcept {
        const std::uint64_t split = std::max({src_->split_rows() > 0 ? split_row_taps() : std::uint64_t(0),
                                              src_->split_mean_rows() > 0 ? split_mean_row_taps() : std::uint64_t(0),
                                              src_->split_pending() ? split_select_taps() : std::uint64_t(0),
                                              peak_build_taps(std::min<std::size_t>(peak_build_unit, std::max(src_->split_peaks(), src_->split_pending() ? std::size_t(opt_.peaks.max_peaks) : std::size_t(0)))),
                                              level_peaks_taps()});
        return std::max({split, pack_unit_taps(), patch_taps(), src_->sh_rows() > 0 ? std::max(sh_row_taps(), sh_finish_taps()) : std::uint64_t(0)});
    }
    /// (A level that reads an intermediate level, prefilter_options::mid_tail, counts that
    /// level's units too.)
    std::uint64_t unit_taps(std::size_t k) const noexcept {
        const std::uint64_t own = work_unit_taps(levels_[k]);
        return levels_[k].mid >= 0 ? std::max(own, work_unit_taps(levels_[std::size_t(levels_[k].mid)])) : own;
    }

private:
    /// step's loop; progress: at least one unit even when it exceeds the budget (step), else none
    /// that does (step_for's slices after the first).
    template <class Executor> std::uint64_t step_units(std::uint64_t budget, Executor& ex, bool progress) {
        std::uint64_t spent = 0;
        bool stop = false;
        // A unit of c taps does not fit: it exceeds what is left, and this is not the call's first
        // unit (step makes progress with one unit even above the budget).
        const auto no_room = [&](std::uint64_t c) { return (spent > 0 || !progress) && c > budget - spent; };
        while (!pass_done_ && !stop && spent < budget) {
            if (!split_selected_) { // the pass's first units: the peak split's mean (without a 1 x 1 level) and scan, a row per unit, then its selection
                if (split_mean_row_ < src_->split_mean_rows()) {
                    const std::uint64_t c = split_mean_row_taps();
                    if (no_room(c)) break;
                    src_->split_mean_row(*source_, split_mean_row_++);
                    if (split_mean_row_ == src_->split_mean_rows()) src_->split_mean_finish();
                    spent += c;
                    continue;
                }
                if (src_->split_pending() && split_row_ < src_->split_rows()) {
                    const std::uint64_t c = split_row_taps();
                    if (no_room(c)) break;
                    src_->split_row(*source_, split_row_++);
                    spent += c;
                    continue;
                }
                if (src_->split_pending()) {
                    const std::uint64_t c = split_select_taps();
                    if (no_room(c)) break;
                    src_->split_select();
                    spent += c;
                }
                split_selected_ = true;
                continue;
            }
            if (split_peak_ < src_->split_peaks()) { // the peaks, peak_build_unit a unit
                const std::size_t e = std::min(src_->split_peaks(), split_peak_ + peak_build_unit);
                const std::uint64_t c = peak_build_taps(e - split_peak_);
                if (no_room(c)) break;
                src_->split_build(*source_, split_peak_, e);
                split_peak_ = e;
                spent += c;
                continue;
            }
            if (peaks_level_ < plan_.size()) { // each output level's merged peaks, a level per unit
                const std::uint64_t c = level_peaks_taps();
                if (no_room(c)) break;
                level_work& w = levels_[peaks_level_];
                if (!w.mirror) {
                    w.conv.peaks = src_->level_peaks(plan_[peaks_level_]);
                    set_convolved_costs(w);
                }
                ++peaks_level_;
                spent += c;
                continue;
            }
            if (!packed_) { // then the packed copy of the source, then the split's patch
                if (pack_item_ < src_->pack_items()) {
                    const std::uint64_t c = pack_item_taps(pack_item_);
                    if (no_room(c)) break;
                    src_->pack(*source_, pack_item_, pack_item_ + 1);
                    ++pack_item_;
                    spent += c;
                    continue;
                }
                if (no_room(patch_taps())) break;
                serial_executor one;
                src_->finish_packing(*source_, one);
                packed_ = true;
                spent += patch_taps();
                continue;
            }
            if (sh_row_ < src_->sh_rows()) { // the projection of the levels by spherical harmonics, a row per unit
                if (no_room(sh_row_taps())) break;
                src_->sh_add_row(sh_row_++);
                spent += sh_row_taps();
                continue;
            }
            if (!sh_done_) { // then the reduction of its sums and the levels' coefficients, one unit
                if (src_->sh_rows() > 0) {
                    if (no_room(sh_finish_taps())) break;
                    src_->sh_finish();
                    for (level_work& w : levels_) src_->sh_fill(w.conv);
                    spent += sh_finish_taps();
                }
                sh_done_ = true;
                continue;
            }
            const level_work& lw = levels_[level_];
            const std::size_t rows_total = std::size_t(6 * lw.n);
            if (row_ == rows_total) { // the finished level's borders, a face per unit
                if (no_room(lw.border_taps)) break;
                if (lw.chain >= 0) back_->update_borders(lw.chain, int(face_));
                if (lw.as_next) levels_[level_].as_next->update_borders(0, int(face_));
                spent += lw.border_taps;
                if (++face_ == 6) next_level();
                continue;
            }
            if (chunk_ == 0 && tap_ == 0) { // at the start of a row: whole rows, in parallel
                std::size_t rows = std::size_t(std::min<std::uint64_t>(rows_total - row_, (budget - spent) / lw.taps_per_row));
                if (lw.whole_rows() && rows == 0 && spent == 0 && progress) rows = 1; // progress: one unit even above the budget
                if (rows > 0) {
                    run_rows(row_, row_ + rows, ex);
                    spent += rows * lw.taps_per_row;
                    row_ += rows;
                    continue;
                }
                if (lw.whole_rows()) break;
            }
            // A row that does not fit: its chunks of lanes, and the taps of a chunk, while they fit.
            const std::uint64_t count = lw.conv.taps.w.size();
            while (true) {
                const auto [x0, w] = lw.chunks[chunk_];
                const bool last = chunk_ + 1 == lw.chunks.size();
                const std::uint64_t lanes = std::uint64_t(w), fin = lanes * lw.chunk_taps + (last ? lw.finish_taps : 0);
                const std::uint64_t left = count - tap_, room = budget - spent;
                std::uint64_t k = left;
                bool complete = true;
                if (left * lanes + fin > room) { // the taps that fit, short of the one that carries the finish
                    k = std::min<std::uint64_t>(room / lanes, fin > 0 && left > 0 ? left - 1 : left);
                    complete = false;
                    if (k == 0) {
                        if (spent > 0 || !progress) {
                            stop = true;
                            break;
                        }
                        complete = left <= 1; // progress: one unit even above the budget
                        k = complete ? left : 1;
                    }
                }
                run_chunk_taps(x0, w, tap_ + std::size_t(k));
                spent += k * lanes + (complete ? fin : 0);
                tap_ += std::size_t(k);
                if (!complete) {
                    stop = true;
                    break;
                }
                finish_chunk(x0, w);
                tap_ = 0;
                if (++chunk_ < lw.chunks.size()) continue;
                chunk_ = 0;
                finish_row();
                ++row_;
                break;
            }
        }
        return spent;
    }

    /// The new pass on source_ (set_source).
    void restart(bool same_shape) {
        // The peak split, the levels' peak lists and the packing in the pass's first units (into
        // the same storage when the shape is unchanged).
        if (!src_) src_.emplace(opt_);
        src_->restart_deferred(*source_);
        split_mean_row_ = 0;
        split_row_ = 0;
        split_peak_ = 0;
        split_selected_ = false;
        peaks_level_ = 0;
        pack_item_ = 0;
        packed_ = false;
        sh_row_ = 0;
        sh_done_ = false;
        if (!same_shape) {
            src_->set_first_packed(0); // every level until the plan's reads are known
            plan_levels();
            // Only the source levels that the plan reads are packed (as prefilter does); the same
            // for every source of this shape.
            src_->set_first_packed(src_->first_read_level(*source_, plan_, first_size_));
        } else { // the tables stay; the peaks of the fast filter's split belong to the source
            src_->sh_setup(detail::prefilter_sh_max_bands<Lobe>(opt_, plan_)); // the projection's rows: the pass's next units
        }
        // The levels' peak lists are units after the split (an intermediate level has none).
        for (std::size_t k = 0; k < plan_.size(); ++k)
            if (!levels_[k].mirror) {
                levels_[k].conv.peaks = {};
                set_convolved_costs(levels_[k]);
            }
        // The chain under construction (the rows are written into it; outside the budget).
        if (!back_ || back_->levels() != int(plan_.size()) || back_->size(0) != first_size_)
            back_.emplace(first_size_, int(plan_.size()));
        pos_ = 0;
        level_ = order_.front();
        row_ = 0;
        chunk_ = 0;
        tap_ = 0;
        face_ = 0;
        pass_done_ = false;
    }
    /// Peak evaluations counted as one tap in the budget (bake/prefilter_peaks.hpp: about ten
    /// vectorised float operations against a bilinear tap's rotation, face selection and reads;
    /// measured at 0.5 ns a peak and texel against 2.3-2.6 ns a tap, one thread), and the taps of a
    /// texel's coarse tail (a bilinear read of the next level's bordered face and a blend: 4.6-5.2
    /// ns a texel).
    static constexpr std::size_t peak_per_tap = 5, tail_taps_per_texel = 2;
    /// A convolved texel's work outside its taps, counted in taps a lane of a chunk (its frame,
    /// built by load_row_frames, and its result: a division and a store): a texel of T taps
    /// measured at about (T + 4) times a tap's time (2.17 ns a tap and 10.7 ns a texel, from levels
    /// of 24 and 64 taps, one thread).
    static constexpr std::size_t chunk_taps_per_lane = 4;
    /// Border texels counted as one tap (a copy from a neighbouring face, mostly one cache line per
    /// texel along a column, against a tap's 8-12 texel reads and its arithmetic; measured by
    /// bench/bench_prefilter.cpp, BM_prefilter_update_step).
    static constexpr std::size_t border_per_tap = 2;
    /// Packed texels counted as one tap: a read of the source's texel, a finiteness test per
    /// component and a 16-byte store, measured at about a tap's time (2-4 ns against 2.7-3 ns:
    /// cold source memory after a pass) by a stand-alone run of whole passes.
    static constexpr std::size_t pack_per_tap = 1;
    std::uint64_t pack_item_taps(std::size_t item) const noexcept {
        return (std::uint64_t(src_->pack_item_texels(item)) + pack_per_tap - 1) / pack_per_tap;
    }
    /// The dearest packing item: a bordered row of the finest packed level (the levels below
    /// first_packed cost nothing).
    std::uint64_t pack_unit_taps() const noexcept {
        const std::vector<detail::packed_cube::level>& lv = src_->packed_levels();
        const std::size_t f = std::size_t(src_->first_packed());
        return f < lv.size() ? (std::uint64_t(lv[f].stride) + pack_per_tap - 1) / pack_per_tap : 0;
    }
    /// The packing items from `item` on (a level's items are its bordered rows, of equal cost).
    std::uint64_t setup_taps(std::size_t item) const noexcept {
        std::uint64_t t = 0;
        std::size_t first = 0;
        int l = 0;
        for (const detail::packed_cube::level& li : src_->packed_levels()) {
            const std::size_t end = first + std::size_t(6 * li.stride);
            if (end > item && l >= src_->first_packed()) // levels below first_packed are not packed
                t += std::uint64_t(end - std::max(first, item)) * ((std::uint64_t(li.stride) + pack_per_tap - 1) / pack_per_tap);
            first = end;
            ++l;
        }
        return t;
    }
    /// The split's mean without a 1 x 1 level: a row of level 0 (a luminance and a multiply-add
    /// in double a texel, in texel order: mean_per_tap texels a tap; 1.5 ns a texel, one thread,
    /// a chain of dependent additions). Its scan: a row of level 0 (a luminance and a comparison a texel, scan_per_tap
    /// texels a tap: 0.6-0.9 ns a texel on one thread, the source just copied), its selection (a
    /// copy and a partial sort of the texels it kept, select_per_tap of them a tap), its peaks (an
    /// exact solid angle's four atan2 and a normalisation each, about 100 ns: build_taps_per_peak
    /// taps, peak_build_unit peaks a unit) and each level's merged peak list (one to three merges of
    /// the peaks' keys by a stable sort: merge_taps_per_peak taps a peak).
    static constexpr std::size_t mean_per_tap = 2, scan_per_tap = 3, select_per_tap = 2, build_taps_per_peak = 48, peak_build_unit = 64,
                                 merge_taps_per_peak = 8;
    std::uint64_t split_row_taps() const noexcept { return 1 + (std::uint64_t(first_source_size()) + scan_per_tap - 1) / scan_per_tap; }
    std::uint64_t split_mean_row_taps() const noexcept { return 1 + (std::uint64_t(first_source_size()) + mean_per_tap - 1) / mean_per_tap; }
    std::uint64_t split_select_taps() const noexcept { return 1 + (std::uint64_t(src_->split_hits()) + select_per_tap - 1) / select_per_tap; }
    static std::uint64_t peak_build_taps(std::size_t peaks) noexcept { return 1 + std::uint64_t(peaks) * build_taps_per_peak; }
    std::uint64_t level_peaks_taps() const noexcept { return 1 + std::uint64_t(src_->peak_count()) * merge_taps_per_peak; }
    int first_source_size() const noexcept { return source_ ? source_->size(0) : 1; }
    /// The split's units from the current one on (the selection and the peaks at what the scan
    /// has kept so far, at most max_peaks peaks).
    std::uint64_t split_taps() const noexcept { return split_taps_from(split_mean_row_, split_row_, split_peak_, peaks_level_); }
    /// A whole pass's split units.
    std::uint64_t whole_split_taps() const noexcept { return split_taps_from(0, 0, 0, 0); }
    std::uint64_t split_taps_from(std::size_t mean_row, std::size_t row, std::size_t peak, std::size_t level) const noexcept {
        const bool selected = split_selected_ && row >= src_->split_rows();
        std::uint64_t t = std::uint64_t(src_->split_mean_rows() - std::min(src_->split_mean_rows(), mean_row)) * split_mean_row_taps();
        t += std::uint64_t(src_->split_rows() - std::min(src_->split_rows(), row)) * split_row_taps();
        std::size_t peaks = src_->split_peaks();
        if (!selected && src_->split_rows() > 0) { // the selection, and the peaks it will keep at most
            t += split_select_taps();
            if (src_->split_pending()) peaks = std::min<std::size_t>(src_->split_hits(), opt_.peaks.max_peaks);
        }
        for (std::size_t p = peak; p < peaks; p += peak_build_unit) t += peak_build_taps(std::min<std::size_t>(peak_build_unit, peaks - p));
        return t + std::uint64_t(plan_.size() - std::min(plan_.size(), level)) * level_peaks_taps();
    }
    /// The split's patch: a few texels per peak and level of the packed copy.
    std::uint64_t patch_taps() const noexcept { return 1 + 8 * std::uint64_t(src_->peak_count()) * std::uint64_t(source_->levels()); }
    /// Coefficients of the spherical-harmonic projection (one source texel, one (l, m): a basis
    /// value and three multiply-adds) counted as one tap, and a level's reconstruction of an output
    /// texel of B bands counted as (B^2 + sh_texel_base) / sh_texel_per_tap taps: its direction, the
    /// recurrence's start and its store cost about sh_texel_base coefficients. Measured on one
    /// thread at 2.4 ns a tap: the projection at 0.16 ns a coefficient, the reconstruction at
    /// 0.076 ns a coefficient and 11 ns a texel (levels of 11, 13 and 24 bands).
    static constexpr std::size_t sh_project_per_tap = 15;
    static constexpr std::size_t sh_texel_base = 146, sh_texel_per_tap = 32;
    /// A row of the projection: n texels of B^2 coefficients (B the projection's bands).
    std::uint64_t sh_row_taps() const noexcept {
        const std::uint64_t b = std::uint64_t(src_->sh_projection_bands());
        return 1 + (std::uint64_t(src_->sh_projection_face()) * b * b + sh_project_per_tap - 1) / sh_project_per_tap;
    }
    /// The reduction of the projection's sums (six faces, eight lanes, six sums per (l, m) pair, in
    /// double; sh_reduce_per_tap of them a tap) and the levels' coefficients.
    static constexpr std::size_t sh_reduce_per_tap = 8;
    std::uint64_t sh_finish_taps() const noexcept {
        const std::uint64_t b = std::uint64_t(src_->sh_projection_bands());
        return 1 + (6 * 6 * 8 * (b * (b + 1) / 2) + sh_reduce_per_tap - 1) / sh_reduce_per_tap;
    }
    /// The projection's units from row `row` on, with the reduction.
    std::uint64_t sh_taps(std::size_t row) const noexcept {
        return src_->sh_rows() > 0 ? std::uint64_t(src_->sh_rows() - row) * sh_row_taps() + sh_finish_taps() : 0;
    }
    struct level_work {
        int n = 1;
        int chain = -1;                      ///< the output level it fills, or -1: an intermediate level (mid_tail), kept in as_next
        int tail_from = -1;                  ///< the level (index into levels_) whose as_next its coarse tail reads, or -1
        int mid = -1;                        ///< the intermediate level it reads its tail from (index into levels_), or -1
        bool mirror = false;                 ///< level 0 of a mirror lobe: a copy / one read per texel
        detail::prefilter_base_read base{};  ///< the mirror level's read
        detail::prefilter_cube_level conv{}; ///< a convolved level's taps and peaks
        double tail_roughness = -1.0;        ///< >= 0: reads its coarse tail from the next level
        std::uint64_t taps_per_row = 1;      ///< n texel_taps + finish_taps (a mirror row: n)
        std::uint64_t texel_taps = 1;        ///< a convolved texel's taps: its tap sum and its chunk's share
        std::uint64_t chunk_taps = 0;        ///< a chunk's finish a lane (its frames and results), carried by the chunk's last tap
        std::uint64_t finish_taps = 0;       ///< a convolved row's finish: its tail reads and peaks
        std::uint64_t border_taps = 1;       ///< the borders of a face (of the chain, and of as_next when kept)
        std::vector<std::pair<int, int>> chunks; ///< a row's chunks of lanes (first texel, width), as convolve_row
        std::optional<cubemap<float>> as_next; ///< this level before its peaks, which the coarse tail of the level before reads
        /// A mirror level or a level by spherical harmonics: whole rows are the units.
        bool whole_rows() const noexcept { return mirror || conv.sh.active(); }
    };
    /// The dearest work unit of a level: a face's borders, a whole row, or a chunk's tap with the row's finish.
    static std::uint64_t work_unit_taps(const level_work& lw) noexcept {
        return std::max(lw.border_taps, lw.whole_rows() ? lw.taps_per_row
                                                        : std::uint64_t(lw.chunks.front().second) * (1 + lw.chunk_taps) + lw.finish_taps);
    }
    /// The taps of a whole level: its rows and its faces' borders.
    static std::uint64_t level_taps(const level_work& lw) noexcept {
        return std::uint64_t(6 * lw.n) * lw.taps_per_row + 6 * lw.border_taps;
    }

    static void set_convolved_costs(level_work& lw) noexcept {
        const std::uint64_t b = std::uint64_t(lw.conv.sh.bands);
        lw.chunk_taps = lw.conv.sh.active() ? 0 : chunk_taps_per_lane;
        lw.texel_taps = lw.conv.sh.active() ? (b * b + sh_texel_base + sh_texel_per_tap - 1) / sh_texel_per_tap
                                            : std::max<std::uint64_t>(1, lw.conv.taps.w.size()) + lw.chunk_taps;
        // a level by spherical harmonics computes its rows in chunks of 16 lanes (a row's last chunk whole)
        const std::uint64_t lanes = lw.conv.sh.active() ? std::uint64_t((lw.n + 15) / 16 * 16) : std::uint64_t(lw.n);
        lw.finish_taps = std::uint64_t(lw.n) * ((lw.conv.peaks.size() + peak_per_tap - 1) / peak_per_tap +
                                                (lw.conv.tail_share > 0.f ? tail_taps_per_texel : 0u));
        lw.taps_per_row = lanes * lw.texel_taps + lw.finish_taps;
        lw.chunks.clear();
        int x = 0;
        for (const int w : {int(detail::convolve_width), 8, 4, 1})
            for (; x + w <= lw.n; x += w) lw.chunks.emplace_back(x, w);
    }

    void plan_levels() {
        const int base = detail::prefilter_base_size(*source_, opt_.base_size);
        plan_ = prefilter_plan<Lobe>(opt_, base);
        detail::check_prefilter_work(opt_, plan_, base);
        detail::check_prefilter_mid_work<Lobe>(opt_, plan_, base);
        first_size_ = std::max(1, base >> plan_.front().level);
        // The projection of the levels by spherical harmonics (its rows: the pass's units after the packing).
        src_->sh_setup(detail::prefilter_sh_max_bands<Lobe>(opt_, plan_));
        levels_.clear();
        // The output levels at their plan index, then the intermediate levels (mid_tail), each
        // computed just before the level that reads it, as prefilter does.
        std::vector<level_work> mids;
        for (std::size_t k = 0; k < plan_.size(); ++k) {
            const prefilter_level& lp = plan_[k];
            level_work lw;
            lw.n = std::max(1, first_size_ >> int(k));
            lw.chain = int(k);
            lw.mirror = lobe_mirror_limit<Lobe>() && lp.level == 0;
            if (lw.mirror) {
                lw.base = detail::prefilter_base_mode(*source_, lw.n, lp.trilinear);
                lw.taps_per_row = std::uint64_t(lw.n);
            } else {
                lw.tail_roughness = detail::prefilter_tail_roughness<Lobe>(opt_, plan_, k, first_size_, true);
                const double rm = detail::prefilter_mid_roughness<Lobe>(opt_, plan_, k, first_size_, true);
                serial_executor one;
                if (rm >= 0.0) {
                    level_work m;
                    m.n = std::max(1, lw.n / 2);
                    m.tail_roughness = lw.tail_roughness;
                    m.tail_from = int(k) + 1;
                    m.conv = src_->mid_level(*source_, lp, rm, lw.tail_roughness, m.n, one);
                    set_convolved_costs(m);
                    lw.conv = src_->level(*source_, src_->mid_owner(lp), rm, lw.n, one);
                    lw.tail_roughness = rm;
                    lw.mid = lw.tail_from = int(plan_.size() + mids.size());
                    mids.push_back(std::move(m));
                } else {
                    lw.conv = src_->level(*source_, lp, lw.tail_roughness, lw.n, one);
                    if (lw.tail_roughness >= 0.0) lw.tail_from = int(k) + 1;
                }
                set_convolved_costs(lw);
            }
            levels_.push_back(std::move(lw));
        }
        for (level_work& m : mids) levels_.push_back(std::move(m));
        // A level that a coarse tail reads keeps a copy before its peaks (an intermediate level: itself).
        for (std::size_t k = 0; k < levels_.size(); ++k)
            if (const int t = levels_[k].tail_from; t >= 0) levels_[std::size_t(t)].as_next.emplace(levels_[std::size_t(t)].n, 1);
        for (level_work& lw : levels_) { // a face's edges (4 n) and corners, in each cube that keeps the level
            const std::uint64_t cubes = (lw.chain >= 0 ? 1u : 0u) + (lw.as_next ? 1u : 0u);
            lw.border_taps = (std::uint64_t(4 * lw.n + 4) * cubes + border_per_tap - 1) / border_per_tap;
        }
        order_.clear();
        for (const std::size_t k : detail::prefilter_order<Lobe>(opt_, plan_, first_size_, true)) {
            if (levels_[k].mid >= 0) order_.push_back(std::size_t(levels_[k].mid));
            order_.push_back(k);
        }
    }

    /// Whole rows [begin, end) of the current level, through the executor.
    template <class Executor> void run_rows(std::size_t begin, std::size_t end, Executor& ex) {
        level_work& lw = levels_[level_];
        const int n = lw.n;
        // The rows' storage, taken before the work items (texel_ref marks the borders stale).
        outs_.resize(end - begin);
        befores_.resize(end - begin);
        for (std::size_t r = begin; r < end; ++r) {
            outs_[r - begin] = row_out(r);
            befores_[r - begin] = row_before_peaks(r);
        }
        const cubemap<float>* next = next_level_cube();
        ex(end - begin, [&](std::size_t b, std::size_t e) {
            for (std::size_t i = b; i < e; ++i) {
                const std::size_t r = begin + i;
                vec3<float>* out = outs_[i];
                if (lw.mirror) detail::prefilter_base_row(*source_, n, lw.base, r, out);
                else src_->row(lw.conv, r, n, out, next, befores_[i]);
            }
        });
    }

    /// Row r of the current level: in the chain under construction, or in as_next for an
    /// intermediate level.
    vec3<float>* row_out(std::size_t r) {
        level_work& lw = levels_[level_];
        const int n = lw.n;
        if (lw.chain < 0) return &lw.as_next->texel_ref(int(r) / n, 0, int(r) % n, 0);
        return &back_->texel_ref(int(r) / n, 0, int(r) % n, lw.chain);
    }
    /// Row r of the current level before its peaks, in as_next (null when no level reads it, and
    /// for an intermediate level, which has no peaks).
    vec3<float>* row_before_peaks(std::size_t r) {
        level_work& lw = levels_[level_];
        return lw.as_next && lw.chain >= 0 ? &lw.as_next->texel_ref(int(r) / lw.n, 0, int(r) % lw.n, 0) : nullptr;
    }
    const cubemap<float>* next_level_cube() const {
        const level_work& lw = levels_[level_];
        return lw.tail_from >= 0 && levels_[std::size_t(lw.tail_from)].as_next ? &*levels_[std::size_t(lw.tail_from)].as_next : nullptr;
    }
    template <std::size_t W> detail::lane_sums<W>& sums() noexcept {
        if constexpr (W == 16) return sums16_;
        else if constexpr (W == 8) return sums8_;
        else if constexpr (W == 4) return sums4_;
        else return sums1_;
    }
    template <std::size_t W> void chunk_taps(int x0, std::size_t end) {
        const level_work& lw = levels_[level_];
        const int n = lw.n, face = int(row_) / n, y = int(row_) % n;
        detail::lane_sums<W>& st = sums<W>();
        if (tap_ == 0) st = detail::lane_sums<W>{};
        detail::lane_frames<W> fr;
        detail::load_row_frames<W>(fr, face, x0, y, n);
        src_->lanes_part(lw.conv, fr, st, end);
    }
    /// Taps [tap_, end) of the current row's chunk at x0 of w lanes.
    void run_chunk_taps(int x0, int w, std::size_t end) {
        static_assert(detail::convolve_width == 16, "the chunk widths of prefilter_update");
        if (w == 16) chunk_taps<16>(x0, end);
        else if (w == 8) chunk_taps<8>(x0, end);
        else if (w == 4) chunk_taps<4>(x0, end);
        else chunk_taps<1>(x0, end);
    }
    /// The outputs of the finished chunk at x0 of w lanes.
    void finish_chunk(int x0, int w) {
        const level_work& lw = levels_[level_];
        vec3<float>* out = row_out(row_) + x0;
        if (w == 16) detail::convolve_lanes_result(lw.conv.taps, sums16_, out);
        else if (w == 8) detail::convolve_lanes_result(lw.conv.taps, sums8_, out);
        else if (w == 4) detail::convolve_lanes_result(lw.conv.taps, sums4_, out);
        else detail::convolve_lanes_result(lw.conv.taps, sums1_, out);
    }
    /// The whole-row operations of the current row once its chunks are done.
    void finish_row() {
        level_work& lw = levels_[level_];
        src_->row_finish(lw.conv, row_, lw.n, row_out(row_), next_level_cube(), row_before_peaks(row_));
    }

    void next_level() {
        row_ = 0;
        chunk_ = 0;
        tap_ = 0;
        face_ = 0;
        if (++pos_ < order_.size()) {
            level_ = order_[pos_];
            return;
        }
        // The finished chain (every face's borders rebuilt) becomes the result; the previous
        // result's storage becomes the chain under construction of the next pass (no copy; a
        // first pass leaves it to set_source).
        IBL_ASSERT(back_->borders_valid());
        if (result_) {
            std::swap(static_cast<cubemap<float>&>(*result_), *back_);
        } else {
            result_.emplace(std::move(*back_), opt_.weight, opt_.policy.mapping);
            back_.reset();
        }
        pos_ = 0;
        level_ = order_.front();
        pass_done_ = true;
    }

    prefilter_options opt_;
    std::optional<cubemap<float>> source_;
    std::optional<detail::prefilter_cube_source<Lobe, float>> src_;
    std::vector<prefilter_level> plan_;
    std::vector<level_work> levels_;
    int first_size_ = 1;
    std::vector<std::size_t> order_; ///< the levels in the order prefilter computes them
    std::size_t pos_ = 0, level_ = 0, row_ = 0;
    std::size_t chunk_ = 0, tap_ = 0;   ///< row_'s current chunk of lanes and its next tap (a row over several calls)
    std::size_t face_ = 0;              ///< after the level's last row: the next face whose borders to build
    std::size_t split_mean_row_ = 0;    ///< the next row of the split's mean (a source without a 1 x 1 level)
    std::size_t split_row_ = 0;         ///< the next row of the peak split's scan (the pass's first units)
    bool split_selected_ = false;       ///< the split's selection done (or none due)
    std::size_t split_peak_ = 0;        ///< the next peak to build
    std::size_t peaks_level_ = 0;       ///< the next output level whose merged peaks to make
    std::size_t pack_item_ = 0;         ///< the next packing item of the pass's first units
    std::size_t sh_row_ = 0;            ///< the next row of the projection by spherical harmonics
    bool sh_done_ = false;              ///< its sums reduced and the levels' coefficients set
    bool packed_ = false;               ///< the packed copy (and its patch) done
    detail::lane_sums<16> sums16_{};    ///< the current chunk's sums (by its width)
    detail::lane_sums<8> sums8_{};
    detail::lane_sums<4> sums4_{};
    detail::lane_sums<1> sums1_{};
    std::vector<vec3<float>*> outs_;    ///< the rows of a call's whole rows in the chain under construction
    std::vector<vec3<float>*> befores_; ///< and in as_next (or null)
    bool pass_done_ = false;
    /// step_for's rate: starts slow (10 ns a tap, about three times this VM's one-thread rate) so
    /// that a first call ends early rather than late, then follows the measured one.
    double seconds_per_tap_ = 1e-8;
    std::optional<specular_chain> result_;
    std::optional<cubemap<float>> back_; ///< the chain under construction (rows written in place)
};

} // namespace ibl

#endif // IBL_DETAIL_CXX20
