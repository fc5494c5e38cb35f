// bake/prefilter_update: the time-sliced prefilter of a dynamic probe equals the one-shot prefilter
// bit for bit, whatever the budgets; it keeps the last finished chain across a source change.
#include <doctest/doctest.h>

#include <ibl/bake/prefilter.hpp>
#include <ibl/bake/prefilter_update.hpp>
#include <ibl/core/executor.hpp>
#include <ibl/env/analytic.hpp>
#include <ibl/env/convert.hpp>
#include <ibl/env/cubemap.hpp>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <vector>

#include "support/same_bits.hpp"

namespace {

bool same_bits(const ibl::cubemap<float>& a, const ibl::cubemap<float>& b) { return ibl_test::same_cube_bits(a, b); }

ibl::cubemap<float> sky(int n, float sun_scale) {
    auto s = ibl::make_default_sky<float>();
    ibl::cubemap<float> c = ibl::bake_cubemap<float>(s, n, 1);
    for (int f = 0; f < 6; ++f)
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) c.set_texel(f, x, y, 0, c.texel(f, x, y, 0) * (x == y ? sun_scale : 1.0f));
    c.generate_mips();
    return c;
}

ibl::prefilter_options small_options() {
    ibl::prefilter_options o;
    o.samples = 24; // a small table keeps the test fast; the schedule is prefilter's either way
    return o;
}

} // namespace

TEST_CASE("prefilter_update: any budget finishes with the one-shot chain, bit for bit") {
    const ibl::cubemap<float> src = sky(16, 1.0f);
    const ibl::prefilter_options o = small_options();
    const ibl::specular_chain ref = ibl::prefilter(src, o, ibl::serial_executor{});
    for (std::uint64_t budget : {std::uint64_t(1), std::uint64_t(700), std::uint64_t(50000), ~std::uint64_t(0) / 2}) {
        ibl::prefilter_update<> up(src, o);
        const std::uint64_t total = up.total_taps();
        std::uint64_t spent = 0, max_spent = 0;
        int calls = 0;
        while (!up.done()) {
            const std::uint64_t s = up.step(budget);
            CHECK(s > 0);
            spent += s;
            max_spent = std::max(max_spent, s);
            ++calls;
            REQUIRE(calls < 100000);
        }
        CHECK(spent == total);
        CHECK(up.remaining_taps() == 0);
        REQUIRE(up.result().has_value());
        CHECK(same_bits(*up.result(), ref));
        CHECK(up.result()->weight == ref.weight);
        // the cost of a call is bounded and the number of calls predictable: a call computes work
        // units (a tap of a chunk of lanes, a row's last tap with the row's finish, a mirror row,
        // a face's borders) until the next would exceed the budget, so it never exceeds
        // max(budget, the dearest unit), and every call but the last spends more than budget - U
        // (U the dearest unit)
        std::uint64_t unit = up.setup_unit_taps(); // a packed row of the source, the split's patch
        for (std::size_t k = 0; k < up.plan().size(); ++k) unit = std::max(unit, up.unit_taps(k));
        CHECK(max_spent <= std::max(budget, unit));
        if (budget > unit) CHECK(std::uint64_t(calls) <= (total + budget - unit) / (budget - unit + 1) + 1);
    }
}

TEST_CASE("prefilter_update: rows dearer than the budget are computed in pieces, the same bits") {
    // The fast filter with its peak split and coarse tail (whole-row finishes) and a coarse level
    // whose rows cost far more than the budget: calls stay within the budget.
    const ibl::cubemap<float> src = sky(64, 200.0f);
    ibl::prefilter_options o;
    o.method = ibl::prefilter_method::fast;
    o.samples_per_level = {0, 16, 64, 256, 8192};
    o.levels = 5;
    o.sh_rough.enabled = false; // tap sets on every level (the rough levels by SH: tests/test_prefilter_sh.cpp)
    const ibl::specular_chain ref = ibl::prefilter(src, o, ibl::serial_executor{});
    // above the dearest unit (the split's patch of about 200 peaks), below the coarsest level's rows
    for (std::uint64_t budget : {std::uint64_t(12000), std::uint64_t(16000)}) {
        ibl::prefilter_update<> up(src, o);
        std::uint64_t unit = up.setup_unit_taps(), dearest_row = 0;
        for (std::size_t k = 0; k < up.plan().size(); ++k) {
            unit = std::max(unit, up.unit_taps(k));
            dearest_row = std::max(dearest_row, up.row_taps(k));
        }
        REQUIRE(unit < budget);
        REQUIRE(dearest_row > budget); // some row needs several calls
        std::uint64_t spent = 0, max_spent = 0;
        int calls = 0;
        int exact_calls = 0;
        while (!up.done()) {
            const std::uint64_t before = up.remaining_taps();
            const bool exact = up.peaks_ready(); // before: the split's units are estimates
            const std::uint64_t s = up.step(budget, ibl::thread_executor{2});
            if (exact) {
                CHECK(up.remaining_taps() == (up.done() ? 0 : before - s));
                ++exact_calls;
            }
            spent += s;
            max_spent = std::max(max_spent, s);
            ++calls;
            REQUIRE(calls < 100000);
        }
        CHECK(exact_calls > calls / 2);
        CHECK(spent == up.total_taps());
        CHECK(max_spent <= budget);
        CHECK(same_bits(*up.result(), ref));
    }
}

TEST_CASE("prefilter_update: an executor within a call, a level plan, the G1 weight and the Charlie lobe") {
    const ibl::cubemap<float> src = sky(8, 3.0f);
    ibl::prefilter_options o = small_options();
    o.weight = ibl::ld_weight::g1;
    o.level_plan = {{1, 0.3, 16, true}, {2, 0.6, 32, false}, {3, 1.0, 8, true}};
    const ibl::specular_chain ref = ibl::prefilter(src, o);
    ibl::prefilter_update<> up(src, o);
    while (!up.done()) up.step(900, ibl::thread_executor{2});
    CHECK(same_bits(*up.result(), ref));

    ibl::prefilter_options c = small_options();
    const ibl::specular_chain cref = ibl::prefilter<ibl::charlie_lobe>(src, c);
    ibl::prefilter_update<ibl::charlie_lobe> cu(src, c);
    cu.finish();
    CHECK(same_bits(*cu.result(), cref));
}

TEST_CASE("prefilter_update: a source change restarts the pass; the last finished chain stays readable") {
    const ibl::cubemap<float> a = sky(16, 1.0f), b = sky(16, 40.0f);
    const ibl::prefilter_options o = small_options();
    ibl::prefilter_update<> up(a, o);
    CHECK_FALSE(up.result().has_value());
    up.finish();
    const ibl::specular_chain ref_a = ibl::prefilter(a, o), ref_b = ibl::prefilter(b, o);
    CHECK(same_bits(*up.result(), ref_a));
    up.step(up.total_taps() / 3);
    up.set_source(b); // mid-pass: the rows of a are dropped
    CHECK_FALSE(up.done());
    CHECK(up.remaining_taps() == up.total_taps());
    up.step(up.total_taps() / 2);
    CHECK(same_bits(*up.result(), ref_a)); // still the finished chain of a
    up.finish();
    CHECK(same_bits(*up.result(), ref_b));
    // a source of another size re-plans (smaller chain) and still matches
    const ibl::cubemap<float> s8 = sky(8, 2.0f);
    up.set_source(s8);
    up.finish();
    CHECK(same_bits(*up.result(), ibl::prefilter(s8, o)));
}

TEST_CASE("prefilter_update: the fast filter's split and packing restart with each source, in budgeted units") {
    // Sources with different peaks (a brighter diagonal), the packed copy's storage reused: every
    // pass equals the one-shot chain, and the pass's first units (the packing) stay within the budget.
    ibl::cubemap<float> a = sky(32, 1.0f), b = sky(32, 500.0f);
    ibl::prefilter_options o;
    o.method = ibl::prefilter_method::fast;
    o.samples_per_level = {0, 8, 16, 32, 64};
    o.levels = 5;
    ibl::prefilter_update<> up(a, o);
    int pass = 0;
    for (const ibl::cubemap<float>* src : {&a, &b, &a, &b}) {
        if (pass++ % 2 == 0) up.set_source(*src); // a copy
        else up.set_source(ibl::cubemap<float>(*src)); // moved in
        const std::uint64_t budget = 2 * up.setup_unit_taps();
        std::uint64_t unit = up.setup_unit_taps(), first = 0;
        for (std::size_t k = 0; k < up.plan().size(); ++k) unit = std::max(unit, up.unit_taps(k));
        int calls = 0;
        while (!up.done()) {
            const std::uint64_t s = up.step(budget);
            CHECK(s <= std::max(budget, unit));
            if (calls++ == 0) first = s;
            REQUIRE(calls < 1000000);
        }
        CHECK(first <= budget);
        CHECK(same_bits(*up.result(), ibl::prefilter(*src, o, ibl::serial_executor{})));
    }
}

TEST_CASE("prefilter_update: budget 0 does nothing; bad options throw as prefilter does") {
    const ibl::cubemap<float> src = sky(8, 1.0f);
    ibl::prefilter_update<> up(src, small_options());
    CHECK(up.step(0) == 0);
    CHECK(up.remaining_taps() == up.total_taps());
    ibl::prefilter_options bad = small_options();
    bad.level_plan = {{1, 0.3, 16, true}, {3, 0.6, 16, true}};
    CHECK_THROWS_AS(ibl::prefilter_update<>(src, bad), std::invalid_argument);
    bad = small_options();
    bad.levels = -3;
    CHECK_THROWS_AS(ibl::prefilter_update<>(src, bad), std::invalid_argument);
}

TEST_CASE("prefilter_update: a time budget finishes with the one-shot chain, bit for bit, and makes progress") {
    // Only the bits and the progress are checked here (timing is the benchmark's:
    // bench/bench_prefilter.cpp, BM_prefilter_update_time).
    const ibl::cubemap<float> src = sky(32, 200.0f);
    ibl::prefilter_options o;
    o.method = ibl::prefilter_method::fast;
    const ibl::specular_chain ref = ibl::prefilter(src, o, ibl::serial_executor{});
    for (const auto budget : {std::chrono::microseconds(1), std::chrono::microseconds(30), std::chrono::microseconds(2000)}) {
        ibl::prefilter_update<> up(src, o);
        CHECK(up.step_for(std::chrono::microseconds(0)) == 0); // nothing for no time
        std::uint64_t spent = 0;
        int calls = 0;
        while (!up.done()) {
            const std::uint64_t s = up.step_for(budget, ibl::thread_executor{2});
            CHECK(s > 0); // at least one unit a call
            spent += s;
            ++calls;
            REQUIRE(calls < 200000);
        }
        CHECK(spent == up.total_taps());
        CHECK(up.seconds_per_tap() > 0.0);
        CHECK(same_bits(*up.result(), ref));
    }
}

TEST_CASE("prefilter_update: a source whose mips stop above 1 x 1 is split in units too, the same bits") {
    // The split's mean then reads level 0 by texel solid angles, a face row per unit, before its
    // scan: set_source does none of it, every call stays within max(budget, the dearest unit), and
    // each pass equals the one-shot chain.
    const ibl::cubemap<float> full = sky(32, 400.0f);
    ibl::cubemap<float> part(32, 3); // 32, 16, 8: no 1 x 1 level
    for (int f = 0; f < 6; ++f)
        for (int y = 0; y < 32; ++y)
            for (int x = 0; x < 32; ++x) part.set_texel(f, x, y, 0, full.texel(f, x, y, 0));
    part.generate_mips();
    REQUIRE(part.size(part.levels() - 1) == 8);
    ibl::prefilter_options o;
    o.method = ibl::prefilter_method::fast;
    o.samples_per_level = {0, 8, 16, 32};
    o.levels = 4;
    const ibl::specular_chain ref = ibl::prefilter(part, o, ibl::serial_executor{});
    for (std::uint64_t budget : {std::uint64_t(1), std::uint64_t(40), std::uint64_t(3000), ~std::uint64_t(0) / 2}) {
        ibl::prefilter_update<> up(part, o);
        CHECK_FALSE(up.peaks_ready()); // the split is the pass's first units, not set_source's work
        std::uint64_t unit = up.setup_unit_taps();
        for (std::size_t k = 0; k < up.plan().size(); ++k) unit = std::max(unit, up.unit_taps(k));
        std::uint64_t spent = 0;
        int calls = 0;
        while (!up.done()) {
            const std::uint64_t s = up.step(budget);
            CHECK(s <= std::max(budget, unit));
            spent += s;
            REQUIRE(++calls < 10000000);
        }
        CHECK(spent == up.total_taps());
        CHECK(same_bits(*up.result(), ref));
    }
    // The split found the diagonal's peaks (it is not empty), as the one-shot's.
    ibl::prefilter_options none = o;
    none.peaks.enabled = false;
    CHECK_FALSE(same_bits(ref, ibl::prefilter(part, none, ibl::serial_executor{})));
}
