// The public entry points under hostile sizes and counts (core/limits.hpp): each bound throws the
// documented exception with a message naming the function, the argument and its value, before any
// allocation or long loop; a value just inside the bound (or a small one where the bound is about
// memory) still works; level-taking accessors never read out of bounds.
#include <doctest/doctest.h>

#include <ibl/core/gauss_legendre.hpp>
#include <ibl/core/limits.hpp>
#include <ibl/env.hpp>
#include <ibl/ibl.hpp>
#include <ibl/bake/plan.hpp>
#include <ibl/sh.hpp>

#include <climits>
#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <limits>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

template <class T> using v3 = ibl::vec3<T>;

/// f() throws exactly E (not merely something derived from std::exception) and the message holds
/// every part.
template <class E, class F> void require_throw(F&& f, std::initializer_list<const char*> parts) {
    bool thrown = false;
    try {
        f();
    } catch (const E& e) {
        thrown = true;
        const std::string what = e.what();
        for (const char* p : parts) {
            INFO("message: " << what << " / expected part: " << p);
            CHECK(what.find(p) != std::string::npos);
        }
    } catch (const std::exception& e) {
        FAIL("wrong exception type, message: " << e.what());
    }
    CHECK(thrown);
}

constexpr std::uint32_t too_many = 1u << 31; // the hostile count of the reports

ibl::cubemap<float> constant_cube(int n, float v = 1.f) {
    ibl::cubemap<float> c(n);
    c.fill(0, [&](int, int, int) { return v3<float>(v); });
    c.generate_mips();
    return c;
}

} // namespace

TEST_CASE("limits: cubemap sizes are checked before allocating") {
    require_throw<std::length_error>([] { ibl::cubemap<float> c(INT_MAX); }, {"ibl::cubemap", "face size", "2147483647", "65536"});
    require_throw<std::length_error>([] { ibl::cubemap<double> c(65537, 1); }, {"ibl::cubemap", "65537"});
    // Inside the face bound but beyond the memory bound: the texel count says so.
    require_throw<std::length_error>([] { ibl::cubemap<float> c(65536, 1); }, {"stored texels", "limits::max_texels"});
    require_throw<std::invalid_argument>([] { ibl::cubemap<float> c(0); }, {"face size must be >= 1, got 0"});
    require_throw<std::invalid_argument>([] { ibl::cubemap<float> c(-5); }, {"-5"});
    // The exact memory bound: 6 (n + 2)^2 <= 2^30 for one level holds up to n = 13375.
    CHECK(ibl::cubemap_storage_texels(13375, 1) == std::size_t(6) * 13377 * 13377);
    CHECK(ibl::cubemap_storage_texels(13375, 1) <= ibl::limits::max_texels);
    require_throw<std::length_error>([] { (void)ibl::cubemap_storage_texels(13376, 1); }, {"stored texels"});
    require_throw<std::length_error>([] { ibl::cubemap<float> c(13376, 1); }, {"stored texels"});
    // A full chain of 8192 fits (documented), its storage is counted exactly.
    std::size_t chain = 0;
    for (int l = 0; l < 14; ++l) chain += 6 * std::size_t((8192 >> l) + 2) * std::size_t((8192 >> l) + 2);
    CHECK(ibl::cubemap_storage_texels(8192) == chain);
    // Small sizes still work and agree with the counter.
    const ibl::cubemap<float> small(5, 2);
    CHECK(small.levels() == 2);
    CHECK(ibl::cubemap_storage_texels(5, 2) == std::size_t(6) * (49 + 16));
}

TEST_CASE("limits: latlong sizes are checked before allocating, in every constructor") {
    require_throw<std::length_error>([] { ibl::latlong<float> l(INT_MAX, 1); }, {"ibl::latlong", "width", "2147483647"});
    require_throw<std::length_error>([] { ibl::latlong<float> l(1, INT_MAX); }, {"ibl::latlong", "height", "2147483647"});
    const std::vector<float> rgb(3);
    require_throw<std::length_error>([&] { ibl::latlong<float> l(INT_MAX, 1, std::span<const float>(rgb)); },
                                     {"width", "2147483647"});
    require_throw<std::length_error>([] { ibl::latlong<float> l(65537, 2, 1); }, {"65537"});
    require_throw<std::length_error>([] { ibl::latlong<float> l(65536, 65536, 1); }, {"stored texels"});
    require_throw<std::invalid_argument>([] { ibl::latlong<float> l(0, 4); }, {"width must be >= 1, got 0"});
    // Just inside the side bound (small in the other side): works.
    const ibl::latlong<float> wide(65536, 1, 1);
    CHECK(wide.width() == 65536);
    CHECK(ibl::latlong_storage_texels(65536, 1, 1) == std::size_t(65538) * 3);
    const ibl::latlong<float> one(1, 1, std::span<const float>(rgb));
    CHECK(one.texel(0, 0) == v3<float>(0.f));
}

TEST_CASE("limits: level-taking accessors are safe for any level") {
    ibl::cubemap<float> c(8); // 4 levels: 8, 4, 2, 1
    CHECK(c.size(99) == 1);   // clamped to the chain
    CHECK(c.size(-3) == 8);
    CHECK(c.size(INT_MAX) == 1);
    CHECK(c.size(2) == 2);
    CHECK(std::isfinite(c.exact_texel_solid_angle(0, 0, 99)));
    require_throw<std::invalid_argument>([&] { c.fill(99, [](int, int, int) { return v3<float>(1.f); }); },
                                         {"ibl::cubemap::fill", "level = 99"});
    require_throw<std::invalid_argument>([&] { c.fill(-1, [](int, int, int) { return v3<float>(1.f); }); }, {"level = -1"});
    ibl::latlong<float> l(8, 4); // 4 levels
    CHECK(l.width(99) == 1);
    CHECK(l.height(99) == 1);
    CHECK(l.width(-1) == 8);
    require_throw<std::invalid_argument>([&] { l.fill(4, [](int, int) { return v3<float>(1.f); }); },
                                         {"ibl::latlong::fill", "level = 4"});
    // project_cube / project_latlong check the level instead of reading level 99's texels.
    const ibl::cubemap<float> cube = constant_cube(4);
    require_throw<std::invalid_argument>([&] { (void)ibl::project_cube<3>(cube, ibl::serial_executor{}, 99); },
                                         {"ibl::project_cube", "level = 99"});
    l.update_borders();
    require_throw<std::invalid_argument>([&] { (void)ibl::project_latlong<3>(l, ibl::serial_executor{}, 4); },
                                         {"ibl::project_latlong", "level = 4"});
    const auto sh = ibl::project_cube<3>(cube, ibl::serial_executor{}, 2); // the last level: works
    CHECK(sh.c[0].x == doctest::Approx(std::sqrt(4.0 * ibl::pi_v<double>)).epsilon(1e-5));
}

TEST_CASE("limits: DFG tables, nodes and sample counts") {
    using M = ibl::ggx_height_correlated;
    require_throw<std::invalid_argument>([] { (void)ibl::make_dfg_lut_exact<M>(0); }, {"ibl::make_dfg_lut_exact", "size", "got 0"});
    require_throw<std::length_error>([] { (void)ibl::make_dfg_lut_exact<M>(4097); }, {"size = 4097", "limits::max_dfg_lut_size"});
    require_throw<std::invalid_argument>([] { (void)ibl::make_dfg_lut_exact<M>(4, 4); }, {"channels must be 2 or 3, got 4"});
    require_throw<std::invalid_argument>([] { (void)ibl::make_dfg_lut_exact<M>(4, 3, ibl::dfg_quadrature_nodes{0, 0, 0, 0}); },
                                         {"ibl::make_dfg_lut_exact", "nodes.full_y", "got 0"});
    require_throw<std::invalid_argument>([] { (void)ibl::make_dfg_lut_exact<M>(4, 3, ibl::dfg_quadrature_nodes{4, 4, 4, 0}); },
                                         {"nodes.partial_phi"});
    require_throw<std::length_error>([] { (void)ibl::make_dfg_lut_exact<M>(4, 3, ibl::dfg_quadrature_nodes{257, 4, 4, 4}); },
                                     {"nodes.full_y = 257", "limits::max_quadrature_nodes"});
    // Each count within its bound, but the table's total work is not.
    require_throw<std::length_error>(
        [] { (void)ibl::make_dfg_lut_exact<M>(4096, 3, ibl::dfg_quadrature_nodes{256, 256, 256, 256}); },
        {"evaluations", "limits::max_work"});
    require_throw<std::invalid_argument>([] { (void)ibl::dfg_exact<M>(0.5, 0.5, ibl::dfg_quadrature_nodes{0, 0, 0, 0}); },
                                         {"ibl::dfg_quadrature_rule", "nodes.full_y"});
    // Just inside: one node per count and a 1 x 1 table give finite values, k included.
    const ibl::dfg_lut tiny = ibl::make_dfg_lut_exact<M>(1, 3, ibl::dfg_quadrature_nodes{1, 1, 1, 1}, ibl::serial_executor{});
    REQUIRE(tiny.valid());
    const v3<float> t = tiny.sample(0.5f, 0.5f);
    CHECK((std::isfinite(t.x) && std::isfinite(t.y) && std::isfinite(t.z)));
    const auto big_nodes = ibl::dfg_exact<M>(0.5, 0.5, ibl::dfg_quadrature_nodes{256, 256, 256, 256});
    CHECK(big_nodes.x + big_nodes.y == doctest::Approx(ibl::dfg_albedo<M>(0.5, 0.5)).epsilon(1e-5));

    // Monte Carlo tables: zero samples would make E = 0 and k = inf.
    require_throw<std::invalid_argument>([] { (void)ibl::make_dfg_lut_mc<M>(8, 0, 3); }, {"ibl::make_dfg_lut_mc", "samples", "got 0"});
    require_throw<std::length_error>([] { (void)ibl::make_dfg_lut_mc<M>(8, ibl::limits::max_samples + 1); },
                                     {"samples = 16777217", "limits::max_samples"});
    require_throw<std::length_error>([] { (void)ibl::make_dfg_lut_mc<M>(4096, 4096); }, {"limits::max_work"});
    const ibl::dfg_lut mc1 = ibl::make_dfg_lut_mc<M>(4, 1, 3, ibl::serial_executor{});
    for (float v : mc1.data) CHECK(std::isfinite(v));

    // Scalar Monte Carlo estimators: 2^31 samples would ask for 16 GB (dfg_mc) or minutes.
    require_throw<std::length_error>([] { (void)ibl::dfg_mc<M>(0.5f, 0.5f, too_many); }, {"ibl::dfg_mc", "samples = 2147483648"});
    require_throw<std::length_error>([] { (void)ibl::dfg_mc_scalar_loop<M>(0.5f, 0.5f, too_many); }, {"ibl::dfg_mc_scalar_loop"});
    require_throw<std::length_error>([] { (void)ibl::dfg_mc_vndf<M>(0.5f, 0.5f, too_many); }, {"ibl::dfg_mc_vndf"});
    require_throw<std::length_error>([] { (void)ibl::make_dfg_sample_table(0.25f, too_many); }, {"ibl::make_dfg_sample_table"});
    CHECK(ibl::dfg_mc<M>(0.5f, 0.5f, 0u) == ibl::vec2<float>(0.f)); // documented: 0 samples give 0
    // Exactly at the bound (no table: the VNDF estimator, double sums): works and converges.
    const auto at_bound = ibl::dfg_mc_vndf<M>(0.5, 0.5, ibl::limits::max_samples);
    CHECK(at_bound.x + at_bound.y == doctest::Approx(ibl::dfg_albedo<M>(0.5, 0.5)).epsilon(1e-3));

    // A default or mismatched table samples as 0 instead of reading out of bounds.
    const ibl::dfg_lut empty{};
    CHECK(empty.sample(0.5f, 0.5f) == v3<float>(0.f));
    ibl::dfg_lut short_data{4, 3, std::vector<float>(5, 1.f)};
    CHECK(!short_data.valid());
    CHECK(short_data.sample(0.9f, 0.9f) == v3<float>(0.f));
    require_throw<std::invalid_argument>([&] { (void)ibl::dfg_lut_header(short_data, "lut"); }, {"ibl::write_dfg_lut_header", "5 floats"});
    CHECK(!ibl::dfg_lut_header(tiny, "lut").empty());
}

TEST_CASE("limits: Gauss-Legendre node counts") {
    require_throw<std::invalid_argument>([] { (void)ibl::make_gauss_legendre(0); }, {"ibl::make_gauss_legendre", "n must be >= 1"});
    require_throw<std::length_error>([] { (void)ibl::make_gauss_legendre(4097); }, {"n = 4097"});
    const ibl::gauss_legendre_rule r = ibl::make_gauss_legendre(ibl::limits::max_gauss_legendre_nodes);
    double sum = 0.0;
    for (double w : r.w) sum += w;
    CHECK(sum == doctest::Approx(1.0).epsilon(1e-12));
}

TEST_CASE("limits: prefilter sample counts, sizes and total work") {
    const ibl::cubemap<float> src = constant_cube(2, 0.5f);
    ibl::prefilter_options o;
    o.samples = too_many;
    require_throw<std::length_error>([&] { (void)ibl::prefilter(src, o); }, {"ibl::prefilter", "samples = 2147483648"});
    o.samples = 0;
    o.samples_per_level = {0, 64, too_many};
    o.base_size = 8;
    require_throw<std::length_error>([&] { (void)ibl::prefilter(src, o); }, {"samples_per_level[2] = 2147483648"});
    o.samples_per_level.clear();
    o.base_size = 65537;
    require_throw<std::length_error>([&] { (void)ibl::prefilter(src, o); }, {"base_size = 65537"});
    o.base_size = -1;
    require_throw<std::invalid_argument>([&] { (void)ibl::prefilter(src, o); }, {"base_size must be >= 0, got -1"});
    // Every count within its bound, the total taps not: refused before the output is allocated.
    const ibl::constant_environment<float> env;
    o.base_size = 4096;
    o.samples = 4096;
    require_throw<std::length_error>([&] { (void)ibl::prefilter(env, o); }, {"ibl::prefilter", "taps", "limits::max_work"});
    require_throw<std::length_error>(
        [&] { (void)ibl::make_ld_table_for<float>(src, 0.5, too_many, ibl::prefilter_method::filtered_importance, 0.5); },
        {"ibl::make_ld_table_for", "samples = 2147483648"});
    require_throw<std::length_error>([] { (void)ibl::make_ld_table<float>(0.5, too_many, [](double) { return 0.0; }); },
                                     {"ibl::make_ld_table"});
    ibl::sphere_sample_table<float> table;
    require_throw<std::invalid_argument>([&] { (void)ibl::convolve_faces(src, table, 0); }, {"ibl::convolve_faces", "n must be >= 1"});
    // Inside: a tiny source with many samples still works (the furnace holds).
    o.base_size = 2;
    o.samples = 1u << 16;
    const ibl::cubemap<float> out = ibl::prefilter(src, o);
    CHECK(out.texel(0, 0, 0, 1).x == doctest::Approx(0.5).epsilon(1e-5));
}

TEST_CASE("limits: bake_cubemap, latlong_to_cubemap and cube_texel_mean sub-samples") {
    const ibl::constant_environment<float> env;
    require_throw<std::length_error>([&] { (void)ibl::bake_cubemap<float>(env, 4, 100000); },
                                     {"ibl::bake_cubemap", "sub-samples per axis k = 100000", "limits::max_subsamples"});
    require_throw<std::length_error>([&] { (void)ibl::bake_cubemap<float>(env, 4, 65); }, {"k = 65"});
    require_throw<std::length_error>([&] { (void)ibl::bake_cubemap<float>(env, INT_MAX, 1); }, {"face size n = 2147483647"});
    // n and k each within bounds, 6 n^2 k^2 not (837^2 * 6 * 4096 > 2^34).
    require_throw<std::length_error>([&] { (void)ibl::bake_cubemap<float>(env, 837, 64); }, {"6 n^2 k^2", "limits::max_work"});
    const ibl::cubemap<float> at_k = ibl::bake_cubemap<float>(env, 1, 64); // k at its bound
    CHECK(at_k.texel(3, 0, 0) == v3<float>(1.f));
    const ibl::latlong<float> ll = [] {
        ibl::latlong<float> l(8, 4);
        l.fill(0, [](int, int) { return v3<float>(2.f); });
        l.generate_mips();
        return l;
    }();
    require_throw<std::length_error>([&] { (void)ibl::latlong_to_cubemap(ll, 4, 100000); },
                                     {"ibl::latlong_to_cubemap", "k = 100000"});
    CHECK(ibl::latlong_to_cubemap(ll, 2, 2).texel(0, 1, 1) == v3<float>(2.f));
    require_throw<std::invalid_argument>([&] { (void)ibl::cube_texel_mean(env, 6, 0, 0, 4, 1); }, {"ibl::cube_texel_mean", "face 6"});
    require_throw<std::invalid_argument>([&] { (void)ibl::cube_texel_mean(env, 0, 4, 0, 4, 1); }, {"outside"});
    require_throw<std::length_error>([&] { (void)ibl::cube_texel_mean(env, 0, 0, 0, 4, 65); }, {"k = 65"});
    // The distribution's own bake: named and bounded (face size of the proposal too).
    require_throw<std::length_error>([&] { (void)ibl::make_cube_env_distribution<float>(env, 4, 65); },
                                     {"ibl::make_cube_env_distribution", "k = 65"});
    require_throw<std::length_error>([&] { (void)ibl::make_cube_env_distribution<float>(env, 4097, 1); },
                                     {"n = 4097", "limits::max_distribution_size"});
    const ibl::cube_env_distribution d = ibl::make_cube_env_distribution<float>(env, 4, 1);
    CHECK(d.size() == 4);
}

TEST_CASE("limits: irradiance options") {
    const ibl::cubemap<float> src = constant_cube(4, 1.f);
    ibl::irradiance_options o;
    o.size = 65537;
    require_throw<std::length_error>([&] { (void)ibl::irradiance_cubemap(src, o); }, {"ibl::irradiance_cubemap", "size = 65537"});
    o.size = 0;
    require_throw<std::invalid_argument>([&] { (void)ibl::irradiance_cubemap(src, o); }, {"size must be >= 1, got 0"});
    o.size = 4;
    o.samples = too_many;
    require_throw<std::length_error>([&] { (void)ibl::irradiance_cubemap(src, o); }, {"samples = 2147483648"});
    require_throw<std::length_error>([&] { (void)ibl::irradiance(src, v3<float>(0.f, 1.f, 0.f), o); },
                                     {"ibl::irradiance", "samples = 2147483648"});
    o.samples = 1024;
    o.method = ibl::irradiance_method::riemann;
    o.n_theta = INT_MAX;
    require_throw<std::length_error>([&] { (void)ibl::irradiance_cubemap(src, o); }, {"n_theta = 2147483647"});
    o.n_theta = 65536;
    o.n_phi = 65536;
    require_throw<std::length_error>([&] { (void)ibl::irradiance_cubemap(src, o); }, {"n_theta * n_phi", "limits::max_samples"});
    require_throw<std::length_error>([] { (void)ibl::make_irradiance_riemann_table<float>(4, INT_MAX, [](double) { return 0.0; }); },
                                     {"ibl::make_irradiance_riemann_table", "n_phi = 2147483647"});
    require_throw<std::length_error>([] { (void)ibl::make_irradiance_cosine_table<float>(too_many, [](double) { return 0.0; }); },
                                     {"ibl::make_irradiance_cosine_table"});
    // Total work: a large output with many samples.
    o.method = ibl::irradiance_method::cosine_importance;
    o.size = 4096;
    o.samples = 4096;
    require_throw<std::length_error>([&] { (void)ibl::irradiance_cubemap(src, o); }, {"taps", "limits::max_work"});
    // Inside: n_theta at its bound (65536 polar nodes, one azimuth: the phi sum is exact for a
    // constant source, so E = pi (1 + dtheta^2 / 6)).
    o.size = 1;
    o.n_theta = 65536;
    o.n_phi = 1;
    o.method = ibl::irradiance_method::riemann;
    o.filtered = false;
    const v3<float> e = ibl::irradiance(src, v3<float>(0.f, 1.f, 0.f), o);
    CHECK(e.x == doctest::Approx(ibl::pi_v<double>).epsilon(1e-4));
}

TEST_CASE("limits: references and the radiance reference") {
    const ibl::constant_environment<double> env;
    const v3<double> up(0.0, 1.0, 0.0);
    require_throw<std::length_error>([&] { (void)ibl::reference_ld(env, up, 0.5, too_many); }, {"ibl::reference_ld", "samples = 2147483648"});
    require_throw<std::length_error>([&] { (void)ibl::reference_irradiance(env, up, too_many); }, {"ibl::reference_irradiance"});
    const ibl::sky_environment<double> sky;
    require_throw<std::length_error>([&] { (void)ibl::reference_ld_sky(sky, up, 0.5, 64, INT_MAX); },
                                     {"ibl::reference_ld_sky", "cap_nodes = 2147483647"});
    require_throw<std::length_error>([&] { (void)ibl::reference_irradiance_sky(sky, up, too_many); },
                                     {"ibl::reference_irradiance_sky", "sky_samples"});
    require_throw<std::invalid_argument>([] { (void)ibl::reference_faces(0, [](const v3<double>&) { return v3<double>(1.0); }); },
                                         {"ibl::reference_faces"});
    require_throw<std::length_error>([] { (void)ibl::reference_faces(65536, [](const v3<double>&) { return v3<double>(1.0); }); },
                                     {"texels 6 n^2"});
    CHECK(ibl::reference_faces(1, [](const v3<double>&) { return v3<double>(1.0); }).size() == 6);

    const ibl::reference_material m = ibl::make_reference_material(v3<double>(0.5), 0.0, 0.5);
    ibl::radiance_reference_options o;
    o.samples = too_many;
    require_throw<std::length_error>([&] { (void)ibl::reference_radiance(env, nullptr, up, up, m, o); },
                                     {"ibl::integrate_product_mis", "samples = 2147483648"});
    o.samples = 1024;
    o.batches = 1u << 20;
    require_throw<std::length_error>([&] { (void)ibl::reference_radiance(env, nullptr, up, up, m, o); },
                                     {"batches = 1048576", "limits::max_batches"});
    o.batches = ibl::limits::max_batches; // inside: one draw per batch
    const ibl::radiance_estimate r = ibl::reference_radiance(env, nullptr, up, up, m, o);
    CHECK(r.samples == ibl::limits::max_batches);
    CHECK(std::isfinite(r.value.x));
}

TEST_CASE("limits: SH projection sizes and degree") {
    auto fetch = [](int, int, int) { return v3<double>(1.0); };
    require_throw<std::invalid_argument>([&] { (void)ibl::project_cube<3>(0, fetch); }, {"ibl::project_cube", "n must be >= 1"});
    require_throw<std::length_error>([&] { (void)ibl::project_cube<3>(INT_MAX, fetch); }, {"n = 2147483647"});
    auto fetch2 = [](int, int) { return v3<double>(1.0); };
    require_throw<std::length_error>([&] { (void)ibl::project_latlong<3>(INT_MAX, 2, fetch2); }, {"ibl::project_latlong", "width"});
    require_throw<std::invalid_argument>([&] { (void)ibl::project_latlong<3>(4, -2, fetch2); }, {"height must be >= 1, got -2"});
    auto one = [](const v3<double>&) { return v3<double>(1.0); };
    require_throw<std::length_error>([&] { (void)ibl::project_function<3, double>(one, INT_MAX); },
                                     {"ibl::project_function", "degree = 2147483647"});
    const auto q = ibl::sh_quadrature_for<3>(INT_MAX); // noexcept: clamped, no overflow
    CHECK(q.exact_degree == ibl::limits::max_sh_degree + 2);
    const auto c = ibl::project_function<3, double>(one, ibl::limits::max_sh_degree); // at the bound
    CHECK(c.c[0].x == doctest::Approx(std::sqrt(4.0 * ibl::pi_v<double>)).epsilon(1e-10));
}

TEST_CASE("limits: sh_auto_window and sh_min_value on bad input") {
    ibl::sh_coeffs<float, 3> ringing{};
    ringing.c[0] = v3<float>(1.f);
    ringing.c[2] = v3<float>(1.5f); // a strong linear term: negative irradiance below
    const auto good = ibl::sh_auto_window(ringing);
    CHECK(good.ok);
    CHECK(good.min_after.x >= 0.f);

    ibl::sh_coeffs<float, 3> bad = ringing;
    bad.c[4].y = std::numeric_limits<float>::quiet_NaN();
    const auto r = ibl::sh_auto_window(bad);
    CHECK_FALSE(r.ok);
    CHECK(std::isnan(r.width));
    bad = ringing;
    bad.c[0].z = std::numeric_limits<float>::infinity();
    CHECK_FALSE(ibl::sh_auto_window(bad).ok);
    ibl::sh_auto_window_options opt;
    opt.max_width = std::numeric_limits<double>::quiet_NaN();
    CHECK_FALSE(ibl::sh_auto_window(ringing, opt).ok);
    // Hostile counts are clamped (device-callable: no exceptions) and the result stays right.
    opt = {};
    opt.iterations = INT_MAX;
    opt.samples = -7;
    opt.max_width = 1e300;
    const auto clamped = ibl::sh_auto_window(ringing, opt);
    CHECK(clamped.ok);
    CHECK(clamped.min_after.x >= 0.f);
    const auto m = ibl::sh_min_value(ringing, 0, std::numeric_limits<float>::quiet_NaN());
    CHECK(std::isfinite(m.value.x));
    CHECK(m.value.x == doctest::Approx(ibl::sh_min_value(ringing).value.x).epsilon(1e-4));
}

TEST_CASE("limits: bake plan settings") {
    ibl::scene_description s;
    s.materials = {{"m", 0.0, {{0.2, 0.8}}}};
    ibl::plan_settings set;
    set.levels = INT_MAX;
    require_throw<std::length_error>([&] { (void)ibl::make_bake_plan(s, set); },
                                     {"ibl::make_bake_plan", "plan_settings.levels = 2147483647"});
    require_throw<std::length_error>([&] { (void)ibl::full_bake_plan(set); }, {"ibl::full_bake_plan", "plan_settings.levels"});
    set.levels = 0;
    require_throw<std::invalid_argument>([&] { (void)ibl::make_bake_plan(s, set); }, {"levels must be >= 1, got 0"});
    set = {};
    set.max_base_size = 65537;
    require_throw<std::length_error>([&] { (void)ibl::make_bake_plan(s, set); }, {"max_base_size = 65537"});
    set = {};
    set.texel_fraction = std::numeric_limits<double>::quiet_NaN();
    require_throw<std::invalid_argument>([&] { (void)ibl::make_bake_plan(s, set); }, {"texel_fraction"});
    set = {};
    set.filler_samples = too_many;
    require_throw<std::length_error>([&] { (void)ibl::make_bake_plan(s, set); }, {"filler_samples = 2147483648"});
    set = {};
    set.source_subsamples = 100000;
    require_throw<std::length_error>([&] { (void)ibl::make_bake_plan(s, set); }, {"source_subsamples = 100000"});
    set = {};
    require_throw<std::length_error>([&] { (void)ibl::full_bake_plan(set, too_many); }, {"samples = 2147483648"});
    require_throw<std::length_error>([&] { (void)ibl::full_bake_plan(set, 512, true, INT_MAX); }, {"dfg_size = 2147483647"});
    // At the bounds: the full chain of the largest face works, shifts stay defined.
    set.levels = ibl::limits::max_plan_levels;
    set.max_base_size = ibl::limits::max_face_size;
    const ibl::bake_plan p = ibl::make_bake_plan(s, set);
    CHECK(p.specular.virtual_base_size <= ibl::limits::max_face_size);
    CHECK(!p.specular.levels.empty());
    const ibl::bake_plan f = ibl::full_bake_plan(set);
    CHECK(f.specular.levels.size() == std::size_t(ibl::limits::max_plan_levels));
    CHECK(f.specular.levels.back().size == 1);
}

TEST_CASE("limits: compare_level checks its levels") {
    const ibl::cubemap<float> a = constant_cube(4), b = constant_cube(4);
    require_throw<std::invalid_argument>([&] { (void)ibl::compare_level(a, 99, b, 0); }, {"ibl::compare_level", "a_level = 99"});
    require_throw<std::invalid_argument>([&] { (void)ibl::compare_level(a, 0, b, -1); }, {"b_level = -1"});
    const std::vector<v3<float>> ref(6, v3<float>(1.f));
    require_throw<std::invalid_argument>([&] { (void)ibl::compare_level(a, 3, std::span<const v3<float>>(ref)); }, {"level = 3"});
    CHECK(ibl::compare_level(a, 2, std::span<const v3<float>>(ref)).max_abs == 0.0);
}
