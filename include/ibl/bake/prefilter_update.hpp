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
//     a texel of a convolved level:       S_l T_l taps (S_l samples kept after dropping n.l <= 0,
//                                         T_l = 2 for trilinear reads, 1 for nearest), and the
//                                         last texel of a row also carries the row's finish,
//                                         n_l (ceil(P_l / 8) + C_l) taps (P_l the peaks of the fast
//                                         filter's split at that level, bake/prefilter_peaks.hpp,
//                                         eight to a tap; C_l = 1 with a coarse tail, its read of
//                                         the next level: whole-row operations, done once the
//                                         row's texels all have their tap sums),
// so the cost of a call is bounded by max(budget, the dearest unit) (unit_taps: a texel of the
// roughest level, or a row's last texel with the finish) and proportional to the taps it reports
// (bench/bench_prefilter.cpp, BM_prefilter_update_step). A row may thus be computed over several
// calls; every texel is computed by exactly the operations prefilter uses (the same tables, the
// same kernel, whose lanes are independent, the same order of the whole-row operations), so the
// finished chain equals prefilter(source, opt) bit for bit, whatever the budgets of the calls and
// the executor within a call.
//
// Source changes. set_source(c) restarts the pass on the new source (the rows already computed
// belong to the old one); result() keeps returning the last finished chain until the new pass
// finishes, so a renderer always reads a complete chain (double buffering). The sample tables are
// rebuilt only when the source's size or mip count changes (they depend on nothing else); the
// fast filter's peaks (bake/prefilter_peaks.hpp) are split again from each new source.
//
// Costs outside the budget: the constructor and set_source copy the source (kept for the mirror
// level), pack it into the kernel's layout (passes over its texels) and allocate the chain under
// construction (a first pass; later passes reuse the storage of the result they replace: the rows
// are written in place and the finished chain is swapped in, with only its borders to fill); a
// finished level that a coarse tail reads is copied with its borders (one pass over its texels).
// All are linear and small next to the convolution (hundreds of taps per texel).
//
// Domain: a cubemap<float> source with its mip chain (cubemap::generate_mips); the options of
// prefilter (the same checks and exceptions, at construction). budget 0 computes nothing.

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

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
    /// Plans the pass of prefilter<Lobe>(source, opt) and starts it. Throws as prefilter.
    explicit prefilter_update(const cubemap<float>& source, prefilter_options opt = {}) : opt_(std::move(opt)) {
        set_source(source);
    }

    /// Restarts the pass on a new source; result() keeps the last finished chain until the new
    /// pass finishes. Throws as prefilter (a new size may exceed the limits).
    void set_source(const cubemap<float>& source) {
        const bool same_shape = source_ && source_->size(0) == source.size(0) && source_->levels() == source.levels();
        source_ = source;
        serial_executor ex;
        src_.emplace(*source_, opt_, ex);
        if (!same_shape) plan_levels();
        else // the tables stay; the peaks of the fast filter's split belong to the source
            for (std::size_t k = 0; k < levels_.size(); ++k)
                if (!levels_[k].mirror) {
                    levels_[k].conv.peaks = src_->level_peaks(plan_[k]);
                    set_convolved_costs(levels_[k]);
                }
        // The chain under construction (the rows are written into it; outside the budget).
        if (!back_ || back_->levels() != int(levels_.size()) || back_->size(0) != first_size_)
            back_.emplace(first_size_, int(levels_.size()));
        pos_ = 0;
        level_ = order_.front();
        row_ = 0;
        col_ = 0;
        pass_done_ = false;
    }

    /// Computes work units (header comment) until the next would exceed `budget` taps (at least
    /// one unit when budget > 0 and the pass is not finished), through the executor (the pieces of
    /// rows are independent). Returns the taps computed; finishing a pass publishes it as result().
    template <class Executor = serial_executor>
    std::uint64_t step(std::uint64_t budget, Executor&& ex = Executor{}) {
        std::uint64_t spent = 0;
        while (!pass_done_ && spent < budget) {
            const level_work& lw = levels_[level_];
            const std::size_t rows_total = std::size_t(6 * lw.n);
            if (lw.mirror) {
                std::size_t rows = std::size_t(std::min<std::uint64_t>(rows_total - row_, (budget - spent) / lw.taps_per_row));
                if (rows == 0 && spent == 0) rows = 1; // progress: one unit even above the budget
                if (rows == 0) break;
                pieces_.clear();
                for (std::size_t r = row_; r < row_ + rows; ++r) pieces_.push_back({r, 0, lw.n, true});
                spent += rows * lw.taps_per_row;
                row_ += rows;
            } else {
                // Whole rows while they fit, then the texels of the next row that fit without its
                // last (which carries the row's finish).
                pieces_.clear();
                std::uint64_t s = spent;
                std::size_t r = row_;
                int x = col_;
                while (r < rows_total) {
                    const std::uint64_t left = std::uint64_t(lw.n - x), room = budget - s;
                    const std::uint64_t rest = left * lw.texel_taps + lw.finish_taps;
                    if (rest <= room) {
                        pieces_.push_back({r, x, lw.n, true});
                        s += rest;
                        ++r;
                        x = 0;
                        if (s == budget) break;
                        continue;
                    }
                    const std::uint64_t k = std::min(room / lw.texel_taps, left - 1);
                    if (k > 0) {
                        pieces_.push_back({r, x, x + int(k), false});
                        s += k * lw.texel_taps;
                        x += int(k);
                    } else if (s == 0) { // progress: one unit even above the budget
                        const bool last = left == 1;
                        pieces_.push_back({r, x, x + 1, last});
                        s += lw.texel_taps + (last ? lw.finish_taps : 0);
                        if (last) ++r, x = 0;
                        else ++x;
                    }
                    break;
                }
                if (pieces_.empty()) break;
                spent = s;
                row_ = r;
                col_ = x;
            }
            run_pieces(ex);
            if (row_ == rows_total) next_level();
        }
        return spent;
    }

    /// Runs the rest of the pass (no budget).
    template <class Executor = serial_executor> void finish(Executor&& ex = Executor{}) {
        while (!pass_done_) step(remaining_taps(), ex);
    }

    /// True after a pass finished and no new one started (set_source restarts).
    bool done() const noexcept { return pass_done_; }
    /// The last finished chain (empty before the first pass finishes).
    const std::optional<specular_chain>& result() const noexcept { return result_; }
    /// Taps of a whole pass, and those still to compute in the current one.
    std::uint64_t total_taps() const noexcept {
        std::uint64_t t = 0;
        for (const level_work& lw : levels_) t += std::uint64_t(6 * lw.n) * lw.taps_per_row;
        return t;
    }
    std::uint64_t remaining_taps() const noexcept {
        if (pass_done_) return 0;
        std::uint64_t t = std::uint64_t(6 * levels_[level_].n - int(row_)) * levels_[level_].taps_per_row -
                          std::uint64_t(col_) * levels_[level_].texel_taps;
        for (std::size_t p = pos_ + 1; p < order_.size(); ++p)
            t += std::uint64_t(6 * levels_[order_[p]].n) * levels_[order_[p]].taps_per_row;
        return t;
    }
    /// The pass's plan (prefilter_plan of the options for this source).
    const std::vector<prefilter_level>& plan() const noexcept { return plan_; }
    /// Face size of output level k, the taps of one of its rows and of its dearest work unit
    /// (k < plan().size(); header comment): a budget of at least the largest unit_taps keeps every
    /// call within the budget.
    int level_size(std::size_t k) const noexcept { return levels_[k].n; }
    std::uint64_t row_taps(std::size_t k) const noexcept { return levels_[k].taps_per_row; }
    std::uint64_t unit_taps(std::size_t k) const noexcept {
        const level_work& lw = levels_[k];
        return lw.mirror ? lw.taps_per_row : lw.texel_taps + lw.finish_taps;
    }

private:
    /// Peak evaluations counted as one tap in the budget (bake/prefilter_peaks.hpp: about ten
    /// vectorised float operations against a bilinear tap's rotation, face selection and reads).
    static constexpr std::size_t peak_per_tap = 8;
    struct level_work {
        int n = 1;
        bool mirror = false;                 ///< level 0 of a mirror lobe: a copy / one read per texel
        detail::prefilter_base_read base{};  ///< the mirror level's read
        detail::prefilter_cube_level conv{}; ///< a convolved level's taps and peaks
        double tail_roughness = -1.0;        ///< >= 0: reads its coarse tail from the next level
        std::uint64_t taps_per_row = 1;      ///< n texel_taps + finish_taps (a mirror row: n)
        std::uint64_t texel_taps = 1;        ///< a convolved texel's tap sum
        std::uint64_t finish_taps = 0;       ///< a convolved row's finish: its tail reads and peaks
        std::vector<vec3<float>> before_peaks; ///< the texels before the peaks, when the level before reads this one
        std::optional<cubemap<float>> as_next; ///< this level as the previous one's coarse tail reads it
    };

    /// A piece of a row: texels [x0, x1) of row `row`; finish: the row's whole-row operations after them.
    struct piece {
        std::size_t row = 0;
        int x0 = 0, x1 = 0;
        bool finish = false;
    };

    static void set_convolved_costs(level_work& lw) noexcept {
        lw.texel_taps = std::max<std::uint64_t>(1, lw.conv.taps.w.size());
        lw.finish_taps = std::uint64_t(lw.n) * ((lw.conv.peaks.size() + peak_per_tap - 1) / peak_per_tap +
                                                (lw.conv.tail_share > 0.f ? 1u : 0u));
        lw.taps_per_row = std::uint64_t(lw.n) * lw.texel_taps + lw.finish_taps;
    }

    void plan_levels() {
        const int base = detail::prefilter_base_size(*source_, opt_.base_size);
        plan_ = prefilter_plan<Lobe>(opt_, base);
        detail::check_prefilter_work(opt_, plan_, base);
        first_size_ = std::max(1, base >> plan_.front().level);
        levels_.clear();
        for (std::size_t k = 0; k < plan_.size(); ++k) {
            const prefilter_level& lp = plan_[k];
            level_work lw;
            lw.n = std::max(1, first_size_ >> int(k));
            lw.mirror = lobe_mirror_limit<Lobe>() && lp.level == 0;
            if (lw.mirror) {
                lw.base = detail::prefilter_base_mode(*source_, lw.n, lp.trilinear);
                lw.taps_per_row = std::uint64_t(lw.n);
            } else {
                lw.tail_roughness = detail::prefilter_tail_roughness<Lobe>(opt_, plan_, k, first_size_);
                lw.conv = src_->level(*source_, lp, lw.tail_roughness);
                set_convolved_costs(lw);
            }
            levels_.push_back(std::move(lw));
        }
        for (std::size_t k = 1; k < levels_.size(); ++k)
            if (levels_[k - 1].tail_roughness >= 0.0)
                levels_[k].before_peaks.assign(std::size_t(6) * std::size_t(levels_[k].n) * std::size_t(levels_[k].n), vec3<float>(0.0f));
        order_ = detail::prefilter_order<Lobe>(opt_, plan_, first_size_);
    }

    template <class Executor> void run_pieces(Executor& ex) {
        level_work& lw = levels_[level_];
        const int n = lw.n;
        const cubemap<float>* next =
            lw.tail_roughness >= 0.0 && level_ + 1 < levels_.size() && levels_[level_ + 1].as_next ? &*levels_[level_ + 1].as_next : nullptr;
        // The rows' storage, taken before the work items (texel_ref marks the borders stale).
        outs_.resize(pieces_.size());
        for (std::size_t i = 0; i < pieces_.size(); ++i)
            outs_[i] = &back_->texel_ref(int(pieces_[i].row) / n, 0, int(pieces_[i].row) % n, int(level_));
        ex(pieces_.size(), [&](std::size_t b, std::size_t e) {
            for (std::size_t i = b; i < e; ++i) {
                const piece& p = pieces_[i];
                vec3<float>* out = outs_[i];
                if (lw.mirror) {
                    detail::prefilter_base_row(*source_, n, lw.base, p.row, out);
                    continue;
                }
                src_->row_taps(lw.conv, p.row, n, p.x0, p.x1, out);
                if (p.finish)
                    src_->row_finish(lw.conv, p.row, n, out, next,
                                     lw.before_peaks.empty() ? nullptr : lw.before_peaks.data() + p.row * std::size_t(n));
            }
        });
    }

    void next_level() {
        row_ = 0;
        col_ = 0;
        // The finished level as the coarse tail of the level before it in the plan.
        if (level_ > 0 && levels_[level_ - 1].tail_roughness >= 0.0) {
            const level_work& lw = levels_[level_];
            levels_[level_].as_next =
                detail::prefilter_tail_cube(lw.n, [&](int f, int x, int y) { return lw.before_peaks[cube_texel_index(f, x, y, lw.n)]; });
        }
        if (++pos_ < order_.size()) {
            level_ = order_[pos_];
            return;
        }
        // The finished chain becomes the result; the previous result's storage becomes the chain
        // under construction of the next pass (no copy; a first pass leaves it to set_source).
        back_->update_borders();
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
    int col_ = 0;                ///< the next texel of row_ (a convolved row computed in pieces)
    std::vector<piece> pieces_;  ///< the current call's pieces
    std::vector<vec3<float>*> outs_; ///< their rows in the chain under construction
    bool pass_done_ = false;
    std::optional<specular_chain> result_;
    std::optional<cubemap<float>> back_; ///< the chain under construction (rows written in place)
};

} // namespace ibl

#endif // IBL_DETAIL_CXX20
