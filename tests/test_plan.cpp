// tests/test_plan.cpp — the scene-driven bake plan (include/ibl/bake/plan.hpp): decisions for
// archetypal scenes, monotonicity in the error target, bad input.
#include <doctest/doctest.h>

#include <ibl/bake/plan.hpp>

#include <cmath>
#include <limits>
#include <stdexcept>

namespace {

ibl::scene_description one_class(const char* name, double metallic, double lo, double hi, double target = 0.1,
                                 int pixels = 512) {
    ibl::scene_description s;
    s.name = name;
    s.materials.push_back({name, metallic, {{lo, hi}}});
    s.error_target = target;
    s.max_reflection_pixels = pixels;
    return s;
}

int total_samples(const ibl::bake_plan& p) {
    int n = 0;
    for (const auto& l : p.specular.levels) n += int(l.samples);
    return n;
}

} // namespace

TEST_CASE("plan: rough-only scene has no sharp levels and a smaller base") {
    const ibl::bake_plan full = ibl::full_bake_plan();
    const ibl::bake_plan p = ibl::make_bake_plan(one_class("plastic", 0.0, 0.5, 1.0));
    // linear policy, 6 levels: lod(0.5) = 2.5, so level 2 (r = 0.4) is the sharpest read.
    CHECK(p.specular.first_level == 2);
    CHECK(p.specular.levels.front().roughness == doctest::Approx(0.4));
    CHECK(p.specular.levels.back().level == 5);
    CHECK(p.specular.virtual_base_size < full.specular.virtual_base_size);
    CHECK(p.source_size == p.specular.virtual_base_size);
    for (const auto& l : p.specular.levels) CHECK(l.needed);
    CHECK(p.diffuse.kind != ibl::diffuse_product::none); // dielectrics: diffuse lit by IBL (0.1: an irradiance map)
    CHECK(p.dfg.channels == 2);
    // stored lod = policy lod minus the first level
    CHECK(p.specular.stored_lod(0.5) == doctest::Approx(0.5));
    CHECK(ibl::estimate_cost(p).total_ms() * 2.0 < ibl::estimate_cost(full).total_ms());
}

TEST_CASE("plan: glossy metals need no irradiance and no rough levels") {
    const ibl::bake_plan p = ibl::make_bake_plan(one_class("metal", 1.0, 0.05, 0.35));
    CHECK(p.diffuse.kind == ibl::diffuse_product::none);
    CHECK(p.diffuse.sh_bands == 0);
    CHECK(p.specular.first_level == 0);
    CHECK(p.specular.levels.size() == 3); // lod 0.25 .. 1.75: levels 0, 1, 2
    CHECK(p.specular.levels.front().samples == 0); // the mirror level is a copy
    // at 0.1 the sharp levels need target / 1.83 (the measured product margin): cheaper than the
    // full bake, but not 2x; at 0.2 (still a product error below the full bake's) it is
    const double full_ms = ibl::estimate_cost(ibl::full_bake_plan()).total_ms();
    CHECK(ibl::estimate_cost(p).total_ms() < full_ms);
    CHECK(ibl::estimate_cost(ibl::make_bake_plan(one_class("metal", 1.0, 0.05, 0.35, 0.2))).total_ms() * 2.0 < full_ms);
    SUBCASE("diffuse not lit by IBL: no SH either for dielectrics") {
        ibl::scene_description s = one_class("plastic", 0.0, 0.3, 0.3);
        s.diffuse_ibl = false;
        CHECK(ibl::make_bake_plan(s).diffuse.kind == ibl::diffuse_product::none);
    }
}

TEST_CASE("plan: mobile gets a 32^2 DFG table and 2-band SH") {
    ibl::scene_description s = one_class("mixed", 0.5, 0.3, 0.9, 0.2, 128);
    s.diffuse_error_target = 0.5; // examples/scenes/mobile.json (2 bands, windowed: 0.451 at worst)
    const ibl::bake_plan p = ibl::make_bake_plan(s);
    CHECK(p.dfg.size == 32);
    CHECK(p.diffuse.kind == ibl::diffuse_product::sh);
    CHECK(p.diffuse.sh_bands == 2);
    CHECK(p.specular.virtual_base_size <= 128);
    CHECK(p.warnings.empty());
    SUBCASE("a band limit below what the target needs warns") {
        ibl::scene_description t = one_class("plastic", 0.0, 0.5, 0.5, 0.1);
        t.limits.max_sh_bands = 2;
        const ibl::bake_plan q = ibl::make_bake_plan(t);
        CHECK(q.diffuse.sh_bands == 2);
        CHECK_FALSE(q.warnings.empty());
    }
}

TEST_CASE("plan: multiscatter channel only when asked") {
    ibl::scene_description s = one_class("metal", 1.0, 0.4, 0.4);
    CHECK(ibl::make_bake_plan(s).dfg.channels == 2);
    s.multiscatter = true;
    CHECK(ibl::make_bake_plan(s).dfg.channels == 3);
}

TEST_CASE("plan: gaps between used roughness are kept cheaply for contiguity") {
    ibl::scene_description s = one_class("a", 0.0, 0.0, 0.0);
    s.materials.push_back({"b", 0.0, {{1.0, 1.0}}});
    const ibl::bake_plan p = ibl::make_bake_plan(s);
    REQUIRE(p.specular.levels.size() == 6);
    CHECK(p.specular.levels[0].needed);
    CHECK(p.specular.levels[5].needed);
    for (int v = 1; v < 5; ++v) {
        CHECK_FALSE(p.specular.levels[std::size_t(v)].needed);
        CHECK(p.specular.levels[std::size_t(v)].samples == 16u);
    }
}

TEST_CASE("plan: a tighter error target never costs less") {
    double prev_cost = 0.0;
    int prev_samples = 0, prev_dfg = 0, prev_bands = 0;
    for (double t : {0.5, 0.3, 0.2, 0.15, 0.1, 0.07, 0.05, 0.03, 0.02}) {
        const ibl::bake_plan p = ibl::make_bake_plan(one_class("plastic", 0.0, 0.2, 0.8, t));
        CAPTURE(t);
        CHECK(total_samples(p) >= prev_samples);
        CHECK(p.dfg.size >= prev_dfg);
        const int bands = p.diffuse.kind == ibl::diffuse_product::irradiance_map ? 4 : p.diffuse.sh_bands;
        CHECK(bands >= prev_bands);
        const double cost = ibl::estimate_cost(p).total_ms();
        CHECK(cost >= prev_cost);
        prev_cost = cost, prev_samples = total_samples(p), prev_dfg = p.dfg.size, prev_bands = bands;
    }
    // and the chosen (samples, read mode) is the cheapest meeting the encoded relation
    for (double t : {0.3, 0.2, 0.1, 0.08}) {
        const ibl::prefilter_choice c = ibl::choose_prefilter(0.6, t);
        CAPTURE(t);
        REQUIRE(c.met);
        CHECK(c.expected_error <= t);
        CHECK(ibl::prefilter_samples_for(0.6, t) == c.samples);
        const double cost = double(c.samples) * (c.trilinear ? 2.0 : 1.0);
        for (std::uint32_t n = 16; n <= 4096; n *= 2)
            for (bool tri : {false, true})
                if (double(n) * (tri ? 2.0 : 1.0) < cost) CHECK(ibl::prefilter_expected_error(0.6, n, tri) > t);
    }
    // below the measured floor: not met, the lowest error is chosen, and the plan warns
    CHECK_FALSE(ibl::choose_prefilter(0.6, 0.01).met);
    CHECK(ibl::prefilter_reachable_error(0.6) == doctest::Approx(0.070));
    CHECK_FALSE(ibl::make_bake_plan(one_class("plastic", 0.0, 0.5, 1.0, 0.01)).warnings.empty());
}

TEST_CASE("plan: larger on-screen reflections need more resolution (capped by the source)") {
    int prev = 0;
    for (int px : {16, 64, 256, 1024, 4096}) {
        const int base = ibl::make_bake_plan(one_class("chrome", 1.0, 0.0, 0.1, 0.1, px)).specular.virtual_base_size;
        CHECK(base >= prev);
        CHECK(base <= 256);
        prev = base;
    }
    CHECK(prev == 256);
    // lobe-width rule: rougher levels need fewer texels
    CHECK(ibl::face_size_for_roughness(0.2, 0.25, 4096) > ibl::face_size_for_roughness(0.6, 0.25, 4096));
    CHECK(ibl::face_size_for_roughness(0.0, 0.25, 64) == 64); // mirror: the cap
}

TEST_CASE("plan: bad scene input") {
    SUBCASE("roughness outside [0, 1] is clamped with a warning") {
        const ibl::bake_plan p = ibl::make_bake_plan(one_class("x", 0.0, -0.5, 1.5));
        CHECK(p.warnings.size() == 2);
        CHECK(p.specular.first_level == 0);
        CHECK(p.specular.levels.back().level == 5);
    }
    SUBCASE("metallic outside [0, 1] is clamped with a warning") {
        const ibl::bake_plan p = ibl::make_bake_plan(one_class("x", 2.0, 0.5, 0.5));
        CHECK(p.warnings.size() == 1);
        CHECK(p.diffuse.kind == ibl::diffuse_product::none);
    }
    SUBCASE("NaN and impossible values throw") {
        const double nan = std::numeric_limits<double>::quiet_NaN();
        CHECK_THROWS_AS((void)ibl::make_bake_plan(one_class("x", 0.0, nan, 0.5)), std::invalid_argument);
        CHECK_THROWS_AS((void)ibl::make_bake_plan(one_class("x", nan, 0.5, 0.5)), std::invalid_argument);
        CHECK_THROWS_AS((void)ibl::make_bake_plan(one_class("x", 0.0, 0.5, 0.5, 0.0)), std::invalid_argument);
        CHECK_THROWS_AS((void)ibl::make_bake_plan(one_class("x", 0.0, 0.5, 0.5, nan)), std::invalid_argument);
        CHECK_THROWS_AS((void)ibl::make_bake_plan(one_class("x", 0.0, 0.5, 0.5, 0.1, 0)), std::invalid_argument);
        ibl::scene_description empty;
        CHECK_THROWS_AS((void)ibl::make_bake_plan(empty), std::invalid_argument);
        ibl::scene_description no_r = one_class("x", 0.0, 0.5, 0.5);
        no_r.materials[0].roughness.clear();
        CHECK_THROWS_AS((void)ibl::make_bake_plan(no_r), std::invalid_argument);
    }
}

TEST_CASE("plan: measured tables") {
    // DFG: the encoded errors fall with size, and the rule picks the smallest size within target / 8
    for (int i = 1; i < 5; ++i) CHECK(ibl::dfg_interp_error[i] < ibl::dfg_interp_error[i - 1]);
    CHECK(ibl::dfg_size_for(0.2) == 32);
    CHECK(ibl::dfg_size_for(0.05) == 128);
    CHECK(ibl::dfg_size_for(1e-6) == 256);
    CHECK(ibl::sh3_irradiance_error < ibl::sh2_irradiance_error);
    // prefilter: the envelope never rises with N; rows interpolate linearly in r
    for (int i = 0; i < 5; ++i)
        for (int j = 1; j < 7; ++j) {
            CHECK(ibl::prefilter_error_nearest[i][j] <= ibl::prefilter_error_nearest[i][j - 1]);
            CHECK(ibl::prefilter_error_trilinear[i][j] <= ibl::prefilter_error_trilinear[i][j - 1]);
        }
    CHECK(ibl::prefilter_expected_error(0.0, 256, false) == doctest::Approx(ibl::prefilter_error_nearest[0][2]));
    CHECK(ibl::prefilter_expected_error(0.5, 1024, true) ==
          doctest::Approx(0.5 * (ibl::prefilter_error_trilinear[1][4] + ibl::prefilter_error_trilinear[2][4])));
    CHECK(ibl::prefilter_expected_error(1.0, 16, false) == doctest::Approx(2.0 * ibl::prefilter_error_nearest[4][0]));
}
