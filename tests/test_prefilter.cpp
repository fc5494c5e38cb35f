// bake/prefilter, runtime/roughness_mip, reference/ld_irradiance, reference/metrics: the prefiltered specular mip chain.
#include <doctest/doctest.h>

#include <ibl/env/analytic.hpp>
#include <ibl/env/convert.hpp>
#include <ibl/env/cubemap.hpp>
#include <ibl/reference/metrics.hpp>
#include <ibl/bake/prefilter.hpp>
#include <ibl/reference/ld_irradiance.hpp>
#include <ibl/runtime/roughness_mip.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <vector>

namespace {

template <class T> using v3 = ibl::vec3<T>;

/// A smooth environment: L(d) = (d.x + 2 d.y + 3 d.z + 4) (1, 0.5, 0.25).
template <class T> v3<T> smooth_fn(const v3<T>& d) {
    return (d.x + T(2) * d.y + T(3) * d.z + T(4)) * v3<T>(T(1), T(0.5), T(0.25));
}

ibl::cubemap<float> constant_cube(int n, const v3<float>& c) {
    ibl::cubemap<float> cube(n);
    cube.fill(0, [&](int, int, int) { return c; });
    cube.generate_mips();
    return cube;
}

/// Largest |texel / c - 1| over every channel of every texel of every level.
double furnace_error(const ibl::cubemap<float>& m, const v3<float>& c) {
    double e = 0;
    for (int l = 0; l < m.levels(); ++l)
        for (int f = 0; f < 6; ++f)
            for (int y = 0; y < m.size(l); ++y)
                for (int x = 0; x < m.size(l); ++x)
                    for (int k = 0; k < 3; ++k)
                        e = std::max(e, std::fabs(double(m.texel(f, x, y, l)[k]) / double(c[k]) - 1.0));
    return e;
}

bool bit_equal(const ibl::cubemap<float>& a, const ibl::cubemap<float>& b) {
    if (a.levels() != b.levels()) return false;
    for (int l = 0; l < a.levels(); ++l)
        for (int f = 0; f < 6; ++f)
            for (int y = 0; y < a.size(l); ++y)
                for (int x = 0; x < a.size(l); ++x)
                    if (std::memcmp(&a.texel(f, x, y, l), &b.texel(f, x, y, l), sizeof(v3<float>)) != 0) return false;
    return true;
}

/// Reference LD of every texel of level l of a chain, by reference_ld_sky.
std::vector<v3<double>> sky_reference(const ibl::sky_environment<double>& sky, int n, double roughness) {
    return ibl::reference_faces(n, [&](const v3<double>& d) { return ibl::reference_ld_sky(sky, d, roughness, 1024, 16); });
}

} // namespace

// ---------------------------------------------------------------------------------------------
// roughness <-> mip policy

TEST_CASE_TEMPLATE("roughness_mip: presets round-trip and hit their end points", T, float, double) {
    for (auto mapping : {ibl::roughness_mapping::linear, ibl::roughness_mapping::filament}) {
        const ibl::roughness_mip_policy p{mapping};
        for (int levels : {2, 5, 9}) {
            CHECK(p.roughness(T(0), levels) == T(0));
            CHECK(p.roughness(T(levels - 1), levels) == T(1));
            CHECK(p.lod(T(1), levels) == T(levels - 1));
            T prev = T(-1);
            for (int i = 0; i <= 1000; ++i) {
                const T r = T(i) / T(1000);
                const T back = p.roughness(p.lod(r, levels), levels);
                // linear: (r m) / m, two roundings: 2 eps. filament: x = r (2 - r) carries ~2 eps,
                // and 1 - x = (1 - r)^2, so r = 1 - sqrt(1 - x) is off by ~eps / (1 - r): the
                // lod itself cannot hold r more finely near r = 1 (the inverse is ill-conditioned
                // there, not unstable). r = 1 exactly round-trips exactly (checked above).
                const T eps = std::numeric_limits<T>::epsilon();
                const T tol = mapping == ibl::roughness_mapping::linear ? T(2) * eps
                                                                         : T(4) * eps + T(2) * eps / std::max(T(1) - r, eps);
                CHECK(std::fabs(back - r) <= tol);
                const T lod = p.lod(r, levels);
                CHECK(lod > prev); // strictly increasing: invertible
                prev = lod;
            }
        }
        // One level: only r = 0 exists.
        CHECK(p.roughness(T(0), 1) == T(0));
        CHECK(p.lod(T(0.7), 1) == T(0));
        // Clamps and NaN.
        CHECK(p.roughness(T(-3), 5) == T(0));
        CHECK(p.roughness(T(9), 5) == T(1));
        CHECK(p.lod(std::numeric_limits<T>::quiet_NaN(), 5) == T(0));
    }
    // Filament's curve: lod = r (2 - r) (n - 1); its inverse r = 1 - sqrt(1 - lod / (n - 1)).
    CHECK(ibl::roughness_mip_policy::filament().lod(T(0.5), 5) == doctest::Approx(3.0));
    CHECK(ibl::roughness_mip_policy::filament().roughness(T(1), 5) == doctest::Approx(1.0 - std::sqrt(0.75)));
    CHECK(ibl::roughness_mip_policy::linear().roughness(T(1), 5) == T(0.25));
}

// ---------------------------------------------------------------------------------------------
// reference and metrics

TEST_CASE("reference: LD normaliser in closed form matches a quadrature") {
    for (double r : {0.02, 0.1, 0.25, 0.5, 0.577, 0.6, 0.8, 0.95, 1.0}) {
        const double alpha = r * r;
        // W = 4 integral_0^1 max(n.l(u), 0) du by a 20000-node midpoint rule in u (the integrand
        // has a kink at u* and is smooth elsewhere: error O(1e-8) at this node count).
        const int n = 20000;
        double s = 0;
        for (int i = 0; i < n; ++i) {
            const double u = (i + 0.5) / n;
            const double c2 = (1 - u) / ((1 - u) + alpha * alpha * u);
            s += std::max(2 * c2 - 1, 0.0);
        }
        CHECK(ibl::ggx_ld_normaliser(alpha) == doctest::Approx(4 * s / n).epsilon(1e-6));
    }
    CHECK(ibl::ggx_ld_normaliser(1.0) == doctest::Approx(1.0).epsilon(1e-15)); // 4 * 1/4
}

TEST_CASE("reference: sky + sun by quadrature agrees with brute-force importance sampling") {
    const auto sky = ibl::make_default_sky<double>();
    const ibl::frame<double> fr = ibl::make_frame(sky.sun_dir);
    for (double ang : {0.0, 0.3}) {
        const v3<double> d = glm::normalize(fr.to_world(v3<double>(std::sin(ang), 0, std::cos(ang))));
        const v3<double> a = ibl::reference_ld_sky(sky, d, 0.5, 2048, 16);
        const v3<double> b = ibl::reference_ld(sky, d, 0.5, 1u << 20);
        // At r = 0.5 the lobe's pdf near the sun is ~D/4 ~ 1.3 /sr, so 2^20 samples put ~1300 in
        // the 9.6e-4 sr sun: a Monte Carlo error of ~3% on the sun's share, less with Hammersley.
        CHECK(a.x == doctest::Approx(b.x).epsilon(0.02));
    }
}

TEST_CASE("metrics: known values") {
    const std::vector<v3<double>> a = {v3<double>(1, 2, 3), v3<double>(4, 5, 6)};
    const std::vector<v3<double>> b = {v3<double>(1, 2, 3), v3<double>(2, 5, 3)};
    const ibl::error_metrics m = ibl::compare(std::span<const v3<double>>(a), std::span<const v3<double>>(b));
    CHECK(m.count == 6);
    CHECK(m.max_abs == 3.0);
    CHECK(m.rmse == doctest::Approx(std::sqrt((4.0 + 9.0) / 6.0)));
    CHECK(m.rel_rmse == doctest::Approx(std::sqrt((1.0 + 1.0) / 6.0)));
    CHECK(m.max_rel == 1.0);
    CHECK(m.max_ratio == 2.0);
    CHECK(m.min_value == 1.0);
    CHECK(m.nrmse == doctest::Approx(std::sqrt(13.0 / (1 + 4 + 9 + 4 + 25 + 9))));
    const std::vector<v3<double>> bad = {v3<double>(std::numeric_limits<double>::quiet_NaN(), 2, 3), v3<double>(2, 5, 3)};
    const ibl::error_metrics mb = ibl::compare(std::span<const v3<double>>(bad), std::span<const v3<double>>(b));
    CHECK(mb.nonfinite == 1);
    CHECK(std::isinf(mb.max_abs));
}

// ---------------------------------------------------------------------------------------------
// prefilter

TEST_CASE("prefilter: the default options are the tuned schedule (512 at level 1, doubled per level, trilinear)") {
    const ibl::prefilter_options o{};
    CHECK(o.method == ibl::prefilter_method::filtered_importance);
    CHECK(o.trilinear);
    CHECK(o.samples == 0);
    CHECK(o.samples_per_level.empty());
    const std::uint32_t fis[] = {512, 1024, 2048, 4096, 8192, 16384, 16384, 16384};
    for (int l = 1; l <= 8; ++l) {
        CHECK(ibl::prefilter_samples(o, l, 9) == fis[l - 1]);
        CHECK(ibl::default_prefilter_samples(ibl::prefilter_method::filtered_importance, l) == fis[l - 1]);
        // Plain importance sampling doubles from 1024.
        CHECK(ibl::default_prefilter_samples(ibl::prefilter_method::importance, l) == std::min<std::uint32_t>(1024u << (l - 1), 16384u));
    }
    // The doubling schedule: capped at prefilter_max_scheduled_samples, never below its start.
    CHECK(ibl::prefilter_max_scheduled_samples == 16384);
    CHECK(ibl::doubling_prefilter_samples(64, 1) == 64);
    CHECK(ibl::doubling_prefilter_samples(64, 4) == 512);
    CHECK(ibl::doubling_prefilter_samples(3000, 3) == 12000);
    CHECK(ibl::doubling_prefilter_samples(3000, 4) == 16384);
    CHECK(ibl::doubling_prefilter_samples(20000, 5) == 20000);
    CHECK(ibl::doubling_prefilter_samples(512, 0) == 512);
    CHECK(ibl::doubling_prefilter_samples(512, 1000) == 16384);
    CHECK(ibl::doubling_prefilter_samples(0, 3) == 0);
    // The equal-cost schedule (the fast filter's default): four times the samples per level, the
    // same cap, never below its start.
    const std::uint32_t fast[] = {64, 256, 1024, 4096, 16384, 16384, 16384};
    for (int l = 1; l <= 7; ++l) {
        CHECK(ibl::equal_cost_prefilter_samples(64, l) == fast[l - 1]);
        CHECK(ibl::default_prefilter_samples(ibl::prefilter_method::fast, l) == fast[l - 1]);
    }
    CHECK(ibl::equal_cost_prefilter_samples(64, 0) == 64);
    CHECK(ibl::equal_cost_prefilter_samples(3000, 3) == 16384);
    CHECK(ibl::equal_cost_prefilter_samples(20000, 5) == 20000);
    CHECK(ibl::equal_cost_prefilter_samples(8, 1000) == 16384);
    CHECK(ibl::equal_cost_prefilter_samples(0, 3) == 0);
    // An explicit count is used at every level; samples_per_level overrides it where set.
    ibl::prefilter_options c;
    c.samples = 100;
    CHECK(ibl::prefilter_samples(c, 1, 5) == 100);
    CHECK(ibl::prefilter_samples(c, 4, 5) == 100);
    c.samples_per_level = {0, 0, 300};
    CHECK(ibl::prefilter_samples(c, 1, 5) == 100);
    CHECK(ibl::prefilter_samples(c, 2, 5) == 300);
    CHECK(ibl::prefilter_samples(c, 3, 5) == 100);
    c.samples = 0;
    CHECK(ibl::prefilter_samples(c, 3, 5) == 2048);
    // The chain draws those counts: the sample table of each level has `drawn` = the schedule.
    const ibl::cubemap<float> src = ibl::bake_cubemap<float>(ibl::make_default_sky<float>(), 8, 1);
    for (int l = 1; l < 4; ++l) {
        const auto t = ibl::make_ld_table_for<float>(src, o.policy.roughness(double(l), 4), ibl::prefilter_samples(o, l, 4),
                                                     o.method, o.lod_bias);
        CHECK(t.drawn == fis[l - 1]);
    }
}

TEST_CASE("prefilter: white furnace at every texel of every level, both methods and policies") {
    const v3<float> c(0.7f, 1.0f, 3.3f);
    const ibl::cubemap<float> src = constant_cube(16, c);
    for (auto method : {ibl::prefilter_method::importance, ibl::prefilter_method::filtered_importance})
        for (auto mapping : {ibl::roughness_mapping::linear, ibl::roughness_mapping::filament}) {
            ibl::prefilter_options o;
            o.levels = 0; // full chain: 16, 8, 4, 2, 1 per face (corners, edges and poles included)
            o.method = method;
            o.policy.mapping = mapping;
            o.samples = method == ibl::prefilter_method::importance ? 256 : 0;
            for (bool tri : {false, true}) {
                o.trilinear = tri;
                const ibl::cubemap<float> out = ibl::prefilter(src, o);
                CHECK(out.levels() == 5);
                // Blocked float sums: error <= (32 + taps / 32 + 2) eps; the default schedule draws up to
                // 4096 samples at level 4 (8192 trilinear taps: <= 3.5e-5 worst case, rounding errors
                // cancel: < 4e-7 measured); 1e-5 is the spec.
                const double e = furnace_error(out, c);
                MESSAGE("furnace max relative error ", e);
                CHECK(e <= 1e-5);
            }
        }
    // The generic path (an analytic environment) and an odd output size.
    ibl::constant_environment<float> env{c};
    ibl::prefilter_options o;
    o.base_size = 7;
    o.levels = 0;
    const ibl::cubemap<float> out = ibl::prefilter(env, o);
    CHECK(out.levels() == 3);
    CHECK(furnace_error(out, c) <= 1e-6); // double accumulation in the generic path
}

TEST_CASE("prefilter: level 0 reproduces the base exactly") {
    const ibl::cubemap<float> src = ibl::bake_cubemap<float>(ibl::make_lambda_environment<float>(smooth_fn<float>), 8, 2);
    const ibl::cubemap<float> out = ibl::prefilter(src);
    for (int f = 0; f < 6; ++f)
        for (int y = 0; y < 8; ++y)
            for (int x = 0; x < 8; ++x) CHECK(out.texel(f, x, y, 0) == src.texel(f, x, y, 0));
}

TEST_CASE("prefilter: no seams on a smooth environment") {
    const int n = 16;
    const auto env = ibl::make_lambda_environment<float>(smooth_fn<float>);
    const auto env_d = ibl::make_lambda_environment<double>(smooth_fn<double>);
    const ibl::cubemap<float> src = ibl::bake_cubemap<float>(env, n, 2);
    ibl::prefilter_options o;
    o.levels = 4;
    const ibl::cubemap<float> out = ibl::prefilter(src, o);
    for (int l = 1; l < out.levels(); ++l) {
        const int m = out.size(l);
        const double r = o.policy.roughness(double(l), out.levels());
        // Error of every texel against a converged LD of the analytic function (4096 samples:
        // smooth integrand, error ~1e-5): a seam is a jump of the error across an edge.
        const auto ref = ibl::reference_faces(m, [&](const v3<double>& d) { return ibl::reference_ld(env_d, d, r, 4096); });
        auto val = [&](int f, int x, int y) { return double(out.texel(f, x, y, l).x); };
        auto err = [&](int f, int x, int y) { return val(f, x, y) - ref[std::size_t((f * m + y) * m + x)].x; };
        double edge_diff = 0, interior_diff = 0, edge_err = 0, interior_err = 0;
        for (int f = 0; f < 6; ++f) {
            for (int y = 0; y < m; ++y)
                for (int x = 0; x < m; ++x) {
                    if (x + 1 < m) {
                        interior_diff = std::max(interior_diff, std::fabs(val(f, x + 1, y) - val(f, x, y)));
                        interior_err = std::max(interior_err, std::fabs(err(f, x + 1, y) - err(f, x, y)));
                    }
                    if (y + 1 < m) {
                        interior_diff = std::max(interior_diff, std::fabs(val(f, x, y + 1) - val(f, x, y)));
                        interior_err = std::max(interior_err, std::fabs(err(f, x, y + 1) - err(f, x, y)));
                    }
                }
            for (int i = 0; i < m; ++i)
                for (int e = 0; e < 4; ++e) {
                    // Edge texel a and the texel b across the edge (found through the point one
                    // texel beyond the edge in the face plane, as the cubemap's borders are built).
                    const int x = e == 0 ? 0 : e == 1 ? m - 1 : i, y = e == 2 ? 0 : e == 3 ? m - 1 : i;
                    const double sc = 2.0 * (x + 0.5 + (e == 0 ? -1 : e == 1 ? 1 : 0)) / m - 1.0;
                    const double tc = 2.0 * (y + 0.5 + (e == 2 ? -1 : e == 3 ? 1 : 0)) / m - 1.0;
                    const ibl::cube_coord<double> cb = ibl::cube_lookup(ibl::cube_face_point(f, sc, tc));
                    const int bx = std::min(int(cb.s * m), m - 1), by = std::min(int(cb.t * m), m - 1);
                    edge_diff = std::max(edge_diff, std::fabs(val(f, x, y) - val(cb.face, bx, by)));
                    edge_err = std::max(edge_err, std::fabs(err(f, x, y) - err(cb.face, bx, by)));
                }
        }
        MESSAGE("level ", l, " (", m, "^2, r=", r, "): max |difference| across edges ", edge_diff, ", between interior neighbours ",
                interior_diff, "; max |error difference| across edges ", edge_err, ", interior ", interior_err);
        // The jump across an edge is no larger than between interior neighbours (edge texels are
        // the angularly smallest, so they are expected to be smaller) ...
        CHECK(edge_diff <= interior_diff);
        // ... and the error does not jump at edges more than inside a face.
        CHECK(edge_err <= interior_err);
    }
}

TEST_CASE("prefilter: sky + sun, filtered beats plain importance sampling at equal cost, no 10x overshoot") {
    const auto sky_d = ibl::make_default_sky<double>();
    const auto sky = ibl::make_default_sky<float>();
    // 32^2: the sun (radius 1 degree) covers 0.4 texel; 6 x 6 sub-samples resolve its area to 3%.
    const ibl::cubemap<float> src = ibl::bake_cubemap<float>(sky, 32, 6);
    ibl::prefilter_options fis; // defaults
    fis.levels = 4;
    const ibl::cubemap<float> a = ibl::prefilter(src, fis);
    for (int l = 1; l < a.levels(); ++l) {
        const double r = fis.policy.roughness(double(l), a.levels());
        const auto ref = sky_reference(sky_d, a.size(l), r);
        // Equal cost: plain IS gets as many level-0 reads as FIS has bilinear taps.
        auto table = ibl::make_ld_table_for<float>(src, r, ibl::prefilter_samples(fis, l, a.levels()), fis.method, fis.lod_bias);
        table.trilinear = fis.trilinear;
        const std::size_t taps = ibl::detail::make_taps(table, src.levels()).w.size();
        ibl::prefilter_options is = fis;
        is.method = ibl::prefilter_method::importance;
        is.samples = std::uint32_t(taps);
        const ibl::cubemap<float> b = ibl::prefilter(src, is);
        const ibl::error_metrics ea = ibl::compare_level(a, l, std::span<const v3<double>>(ref));
        const ibl::error_metrics eb = ibl::compare_level(b, l, std::span<const v3<double>>(ref));
        MESSAGE("level ", l, " r=", r, ": FIS rel RMSE ", ea.rel_rmse, " nRMSE ", ea.nrmse, " max ratio ", ea.max_ratio,
                " | IS(", taps, ") rel RMSE ", eb.rel_rmse, " nRMSE ", eb.nrmse, " max ratio ", eb.max_ratio);
        CHECK(ea.rel_rmse < eb.rel_rmse);
        CHECK(ea.max_ratio <= 10.0);
        CHECK(ea.nonfinite == 0);
    }
}

TEST_CASE("prefilter: fast cubemap path equals the generic environment path") {
    const ibl::cubemap<float> src = ibl::bake_cubemap<float>(ibl::make_default_sky<float>(), 8, 4);
    // The same cubemap behind a type that is not a cubemap: the generic per-sample evaluator
    // (env.radiance trilinear, double sums) against the packed taps (float blocked sums).
    struct wrapped {
        const ibl::cubemap<float>* c;
        v3<float> radiance(const v3<float>& d, float lod) const { return c->radiance(d, lod); }
        float texel_solid_angle(float lod) const { return c->texel_solid_angle(lod); }
        float max_lod() const { return c->max_lod(); }
        float lod_for_solid_angle(float o) const { return c->lod_for_solid_angle(o); }
        int size(int l) const { return c->size(l); }
    };
    ibl::prefilter_options o;
    o.levels = 0;
    o.trilinear = true; // what env.radiance does (also the default)
    const ibl::cubemap<float> a = ibl::prefilter(src, o);
    const ibl::cubemap<float> b = ibl::prefilter(wrapped{&src}, o);
    for (int l = 0; l < a.levels(); ++l) {
        const ibl::error_metrics m = ibl::compare_level(a, l, b, l);
        // Float rounding only: blocked float sums of <= 2 x 2048 taps (default schedule, 4 levels) of
        // values up to 3e4 against double sums, relative ~ (32 + 128) eps ~ 2e-5 of the largest
        // term; 1e-4 relative per element.
        CHECK(m.max_rel <= 1e-4);
    }
}

TEST_CASE("prefilter: deterministic for every thread count") {
    const ibl::cubemap<float> src = ibl::bake_cubemap<float>(ibl::make_default_sky<float>(), 16, 2);
    ibl::prefilter_options o;
    o.levels = 0;
    const ibl::cubemap<float> ref = ibl::prefilter(src, o, ibl::serial_executor{});
    for (unsigned t : {1u, 2u, 3u, 7u}) CHECK(bit_equal(ref, ibl::prefilter(src, o, ibl::thread_executor{t})));
}

namespace {
/// The level loop ibl-bake ran before prefilter took a level plan: the consecutive levels of
/// `plan` at face sizes max(1, base >> level), the mirror level 0 copied from the nearest source
/// level, every other level by its own table.
ibl::cubemap<float> hand_level_loop(const ibl::cubemap<float>& src, int base, const std::vector<ibl::prefilter_level>& plan) {
    ibl::cubemap<float> chain(std::max(1, base >> plan.front().level), int(plan.size()));
    for (std::size_t k = 0; k < plan.size(); ++k) {
        const ibl::prefilter_level& lp = plan[k];
        const int n = chain.size(int(k));
        if (lp.level == 0) {
            const int sl = std::clamp(int(std::lround(std::log2(double(src.size(0)) / double(n)))), 0, src.levels() - 1);
            chain.fill(int(k), [&](int f, int x, int y) {
                return src.size(sl) == n ? src.texel(f, x, y, sl)
                                         : src.radiance(ibl::cube_texel_direction<float>(f, x, y, n), float(sl));
            });
            continue;
        }
        ibl::sphere_sample_table<float> table =
            ibl::make_ld_table_for<float>(src, lp.roughness, lp.samples, ibl::prefilter_method::filtered_importance, 0.5);
        table.trilinear = lp.trilinear;
        const std::vector<v3<float>> texels = ibl::convolve_faces(src, table, n, ibl::serial_executor{});
        chain.fill(int(k), [&](int f, int x, int y) { return texels[ibl::cube_texel_index(f, x, y, n)]; });
    }
    chain.update_borders();
    return chain;
}
} // namespace

TEST_CASE("prefilter: a level plan equals the hand level loop and the one-shot chain bit for bit") {
    const ibl::cubemap<float> src = ibl::bake_cubemap<float>(ibl::make_lambda_environment<float>(smooth_fn<float>), 16, 2);
    ibl::prefilter_options o;
    o.levels = 5;
    // The default plan: levels 0..4, the policy's roughness, the schedule, trilinear reads.
    const std::vector<ibl::prefilter_level> plan = ibl::prefilter_plan(o, 16);
    REQUIRE(plan.size() == 5);
    for (int l = 0; l < 5; ++l) {
        CHECK(plan[std::size_t(l)].level == l);
        CHECK(plan[std::size_t(l)].roughness == o.policy.roughness(double(l), 5));
        CHECK(plan[std::size_t(l)].samples == ibl::prefilter_samples(o, l, 5));
        CHECK(plan[std::size_t(l)].trilinear);
    }
    const ibl::cubemap<float> one_shot = ibl::prefilter(src, o, ibl::serial_executor{});
    ibl::prefilter_options given = o;
    given.level_plan = plan;
    CHECK(bit_equal(ibl::prefilter(src, given, ibl::serial_executor{}), one_shot));

    // Levels 2..3 of the same chain: the one-shot chain's levels 2 and 3, texel for texel.
    given.level_plan = {plan[2], plan[3]};
    const ibl::cubemap<float> part = ibl::prefilter(src, given, ibl::serial_executor{});
    REQUIRE(part.levels() == 2);
    CHECK(part.size(0) == 4);
    for (int k = 0; k < 2; ++k)
        for (int f = 0; f < 6; ++f)
            for (int y = 0; y < part.size(k); ++y)
                for (int x = 0; x < part.size(k); ++x)
                    CHECK(std::memcmp(&part.texel(f, x, y, k), &one_shot.texel(f, x, y, k + 2), sizeof(v3<float>)) == 0);

    // Per-level samples and reads, the mirror level from the nearest source level (base 8: level
    // 1 of the 16^2 source, copied; base 6: read at lod 1), against the hand loop.
    for (int base : {16, 8, 6}) {
        ibl::prefilter_options p;
        p.base_size = base;
        p.level_plan = {{0, 0.0, 0, false}, {1, 0.3, 64, false}, {2, 0.55, 200, true}};
        CHECK(bit_equal(ibl::prefilter(src, p, ibl::serial_executor{}), hand_level_loop(src, base, p.level_plan)));
        p.level_plan.erase(p.level_plan.begin());
        CHECK(bit_equal(ibl::prefilter(src, p, ibl::serial_executor{}), hand_level_loop(src, base, p.level_plan)));
    }
    // Levels that are not consecutive are refused.
    ibl::prefilter_options bad;
    bad.level_plan = {{1, 0.3, 64, true}, {3, 0.6, 64, true}};
    CHECK_THROWS_AS((void)ibl::prefilter(src, bad), std::invalid_argument);
}

TEST_CASE("prefilter: LD is smooth as r -> 1 and finite at r = 1") {
    auto sky = ibl::make_default_sky<float>();
    sky.sun_radiance = v3<float>(0.f);
    const ibl::cubemap<float> src = ibl::bake_cubemap<float>(sky, 8, 2);
    const v3<float> d = glm::normalize(v3<float>(0.3f, 0.5f, -0.8f));
    v3<float> prev(0.f);
    for (double r : {0.97, 0.98, 0.99, 0.995, 1.0}) {
        const auto t = ibl::make_ld_table_for<float>(src, r, 1024, ibl::prefilter_method::importance, 0.0);
        const v3<float> v = ibl::convolve_direction<float>(src, t, d);
        CHECK(std::isfinite(v.x));
        // d LD / d r is O(LD): steps of <= 0.01 in r change LD by well under 2%.
        if (r > 0.97) CHECK(std::fabs(v.x - prev.x) <= 0.02f * v.x);
        prev = v;
    }
}

TEST_CASE("prefilter: sample counts 0, 1 and 2^20; 1x1 faces; bad input") {
    const v3<float> c(2.f, 1.f, 0.5f);
    SUBCASE("1 sample; 0 samples are clamped to 1") {
        const ibl::cubemap<float> src = constant_cube(4, c);
        ibl::prefilter_options o;
        o.samples = 1;
        const ibl::cubemap<float> one = ibl::prefilter(src, o);
        // One sample = at most two taps (trilinear): (w0 c + w1 c) / (w0 + w1), a few roundings.
        CHECK(furnace_error(one, c) <= 1e-6);
        const auto t0 = ibl::make_ld_table<float>(0.5, 0, [](double) { return 0.0; });
        const auto t1 = ibl::make_ld_table<float>(0.5, 1, [](double) { return 0.0; });
        CHECK(t0.drawn == 1);
        CHECK(t0.size() == 1);
        CHECK((t0.x == t1.x && t0.z == t1.z && t0.weight == t1.weight));
        CHECK(t0.z[0] == 1.f); // Hammersley point 0 is u = (0, 0): h = n, l = R (a mirror lookup)
    }
    SUBCASE("2^20 samples on a tiny cubemap") {
        const ibl::cubemap<float> src = constant_cube(2, c);
        ibl::prefilter_options o;
        o.samples = 1u << 20;
        const ibl::cubemap<float> out = ibl::prefilter(src, o);
        CHECK(out.levels() == 2);
        // Blocked float sums of ~2^20 taps: (32 + 2^15) eps ~ 2e-3 worst case, random-walk ~1e-5.
        CHECK(furnace_error(out, c) <= 1e-4);
    }
    SUBCASE("1x1 per face") {
        const ibl::cubemap<float> src = constant_cube(1, c);
        const ibl::cubemap<float> out = ibl::prefilter(src);
        CHECK(out.levels() == 1);
        CHECK(out.texel(3, 0, 0, 0) == c);
        ibl::prefilter_options o;
        o.base_size = 4; // output larger than the source
        o.levels = 0;
        const ibl::cubemap<float> up = ibl::prefilter(src, o);
        CHECK(up.levels() == 3);
        CHECK(furnace_error(up, c) <= 1e-5);
    }
    SUBCASE("NaN and inf radiance in the source read as 0") {
        ibl::cubemap<float> src(8);
        src.fill(0, [&](int f, int x, int y) {
            return f == 2 && x == 3 && y == 4 ? v3<float>(std::numeric_limits<float>::quiet_NaN()) : c;
        });
        src.set_texel(4, 1, 1, 0, v3<float>(std::numeric_limits<float>::infinity()));
        src.generate_mips();
        const ibl::cubemap<float> out = ibl::prefilter(src);
        for (int l = 0; l < out.levels(); ++l)
            for (int f = 0; f < 6; ++f)
                for (int y = 0; y < out.size(l); ++y)
                    for (int x = 0; x < out.size(l); ++x) {
                        const v3<float> v = out.texel(f, x, y, l);
                        CHECK((std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z)));
                        CHECK(v.x <= c.x * 1.00001f);
                    }
        CHECK(out.texel(2, 3, 4, 0) == v3<float>(0.f));
    }
    SUBCASE("invalid options throw") {
        ibl::prefilter_options o;
        o.levels = -2; // -1 is prefilter_options::automatic
        CHECK_THROWS_AS((void)ibl::prefilter(constant_cube(2, c), o), std::invalid_argument);
        CHECK_THROWS_AS((void)ibl::prefilter(ibl::constant_environment<float>{c}), std::invalid_argument);
    }
}
