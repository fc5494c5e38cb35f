// reference/ld_irradiance.hpp: ld_texel_sum, the exact GGX LD of a cubemap level constant over each
// texel, against a one-dimensional polar quadrature of the kernel (a linear environment), the
// sub-texel rule for narrow lobes, reference_ld at many samples, and its determinism and edge cases.
#include <doctest/doctest.h>

#include <ibl/core/executor.hpp>
#include <ibl/env/analytic.hpp>
#include <ibl/env/convert.hpp>
#include <ibl/env/cube_geometry.hpp>
#include <ibl/env/cubemap.hpp>
#include <ibl/reference/ld_irradiance.hpp>
#include <ibl/sampling/sequence.hpp>

#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <vector>

namespace {

using dv = ibl::vec3<double>;

/// mean of cos(theta) under the LD kernel K(theta) = D(theta / 2) k(cos theta) over l's hemisphere
/// about R: a midpoint rule in theta with 2^18 nodes (K is symmetric about R, so a linear
/// environment a + b.l has LD(R) = a + (b.R) mean).
double kernel_mean_cos(double r, ibl::ld_weight w) {
    const double alpha = ibl::alpha_from_roughness(r), a2 = alpha * alpha;
    const int q = 1 << 18;
    double num = 0.0, den = 0.0;
    for (int i = 0; i < q; ++i) {
        const double t = (double(i) + 0.5) * (0.5 * ibl::pi_v<double>) / double(q);
        const double ch = std::cos(0.5 * t), sh = std::sin(0.5 * t);
        const double d = sh * sh + a2 * ch * ch;
        const double k = a2 / (ibl::pi_v<double> * d * d) * ibl::ld_weight_factor(w, std::cos(t), alpha) * std::sin(t);
        num += k * std::cos(t);
        den += k;
    }
    return num / den;
}

std::vector<dv> spread_dirs(std::uint32_t n) {
    std::vector<dv> out;
    for (std::uint32_t k = 0; k < n; ++k) {
        const ibl::vec2<double> u = ibl::hammersley<double>(k, n);
        const double z = 2.0 * u.x - 1.0, s = std::sqrt(std::max(0.0, 1.0 - z * z)), phi = ibl::two_pi_v<double> * (u.y + 0.1);
        out.push_back(glm::normalize(dv(s * std::cos(phi), z, s * std::sin(phi))));
    }
    return out;
}

template <class F> ibl::cubemap<float> cube_of(int n, F&& fn) {
    ibl::cubemap<float> c(n, 1);
    c.fill(0, [&](int f, int x, int y) { return ibl::vec3<float>(fn(ibl::cube_texel_direction<double>(f, x, y, n))); });
    c.update_borders();
    return c;
}

bool same_bits(const dv& a, const dv& b) { return std::memcmp(&a, &b, sizeof a) == 0; }

} // namespace

// A linear environment 2 + (0.6, -0.3, 0.9).l sampled at the texel centres: the centre rule of a
// smooth integrand, so the sum converges to the closed form like 1 / n^2. Bound 2e-4 relative at
// n = 96 (measured worst 5.7e-5 at r = 0.1, which takes the sub-texel rule: the lobe, 2 alpha =
// 0.02, is 1 texel wide; <= 7e-6 at r >= 0.3, both weights).
TEST_CASE("ld_texel_sum: a linear environment against the polar quadrature of the kernel") {
    const dv b(0.6, -0.3, 0.9);
    const int n = 96;
    const ibl::cubemap<float> c = cube_of(n, [&](const dv& d) { return dv(2.0 + glm::dot(b, d)); });
    // The float texels round 2 + b.d; the exact values are what the closed form integrates.
    const std::vector<dv> dirs = spread_dirs(24);
    for (ibl::ld_weight w : {ibl::ld_weight::n_dot_l, ibl::ld_weight::g1})
        for (double r : {0.1, 0.3, 0.6, 1.0}) {
            const double mean = kernel_mean_cos(r, w);
            const std::vector<dv> got = ibl::ld_texel_sum(c, 0, dirs, r, w, ibl::thread_executor{2});
            double worst = 0.0;
            for (std::size_t i = 0; i < dirs.size(); ++i) {
                const double want = 2.0 + glm::dot(b, dirs[i]) * mean;
                worst = std::max(worst, std::abs(got[i].x - want) / want);
            }
            INFO("r = " << r << ", g1 = " << (w == ibl::ld_weight::g1) << ", worst " << worst);
            CHECK(worst < 2e-4);
        }
}

// A sharp environment (a checker of 1 and 50 at 8 texels per square) against reference_ld with
// 2^20 samples reading it nearest (the same piecewise-constant function): agreement to the IS
// noise at r = 0.4 (measured worst 3.6e-4 over six directions; bound 3e-3).
TEST_CASE("ld_texel_sum: agrees with importance sampling of the same piecewise-constant cube") {
    const int n = 32;
    ibl::cubemap<float> c(n, 1);
    c.fill(0, [&](int f, int x, int y) { return ibl::vec3<float>(((x / 8 + y / 8 + f) % 2) ? 50.f : 1.f); });
    c.update_borders();
    struct nearest_env {
        const ibl::cubemap<float>* c;
        int n;
        ibl::vec3<float> radiance(const ibl::vec3<float>& d, float) const {
            const ibl::cube_coord<float> q = ibl::cube_lookup(d);
            const int x = std::min(n - 1, int(q.s * float(n))), y = std::min(n - 1, int(q.t * float(n)));
            return c->texel(q.face, x, y, 0);
        }
    } env{&c, n};
    const std::vector<dv> dirs = spread_dirs(6);
    const std::vector<dv> got = ibl::ld_texel_sum(c, 0, dirs, 0.4);
    for (std::size_t i = 0; i < dirs.size(); ++i) {
        const dv want = ibl::reference_ld(env, dirs[i], 0.4, 1u << 20);
        INFO("direction " << i << ": " << got[i].x << " vs " << want.x);
        CHECK(std::abs(got[i].x - want.x) / want.x < 3e-3);
    }
}

TEST_CASE("ld_texel_sum: deterministic on any executor; a constant cube gives its constant") {
    const auto sky = ibl::make_default_sky<float>();
    const ibl::cubemap<float> c = ibl::bake_cubemap<float>(sky, 16, 2);
    const std::vector<dv> dirs = spread_dirs(17);
    for (double r : {0.05, 0.5}) {
        const std::vector<dv> a = ibl::ld_texel_sum(c, 0, dirs, r);
        const std::vector<dv> b = ibl::ld_texel_sum(c, 0, dirs, r, ibl::ld_weight::n_dot_l, ibl::thread_executor{3});
        for (std::size_t i = 0; i < dirs.size(); ++i) CHECK(same_bits(a[i], b[i]));
    }
    const ibl::cubemap<float> k = cube_of(8, [](const dv&) { return dv(3.0); });
    for (const dv& v : ibl::ld_texel_sum(k, 0, dirs, 0.7)) CHECK(v.y == doctest::Approx(3.0).epsilon(1e-14));
}

TEST_CASE("ld_texel_sum: bad inputs: invalid level throws, zero or NaN directions give 0, NaN radiance reads 0") {
    ibl::cubemap<float> c = cube_of(8, [](const dv&) { return dv(1.0); });
    CHECK_THROWS_AS(ibl::ld_texel_sum(c, 1, std::vector<dv>{dv(0, 0, 1)}, 0.5), std::invalid_argument);
    CHECK_THROWS_AS(ibl::ld_texel_sum(c, -1, std::vector<dv>{dv(0, 0, 1)}, 0.5), std::invalid_argument);
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const std::vector<dv> z = ibl::ld_texel_sum(c, 0, std::vector<dv>{dv(0.0), dv(nan, 0, 1)}, 0.5);
    CHECK(z[0].x == 0.0);
    CHECK(z[1].x == 0.0);
    c.texel_ref(0, 3, 3, 0) = ibl::vec3<float>(std::numeric_limits<float>::infinity(), std::numeric_limits<float>::quiet_NaN(), 1.f);
    const std::vector<dv> v = ibl::ld_texel_sum(c, 0, std::vector<dv>{dv(1, 0, 0)}, nan); // NaN roughness: 0, sub-texels
    CHECK(std::isfinite(v[0].x));
    CHECK(std::isfinite(v[0].y));
}

TEST_CASE("ld_texel_sum_level: the coarsest level with texels <= min(alpha / 10, 1 / 32)") {
    const ibl::cubemap<float> c(256); // 256, 128, ..., 1
    CHECK(ibl::ld_texel_sum_level(c, 0.0) == 0);
    CHECK(ibl::ld_texel_sum_level(c, 0.2) == 0); // alpha / 10 = 0.004 < 2 / 256
    CHECK(ibl::ld_texel_sum_level(c, 0.4) == 1); // 0.016 >= 2 / 128
    CHECK(ibl::ld_texel_sum_level(c, 0.6) == 2); // min(0.036, 1 / 32) = 2 / 64
    CHECK(ibl::ld_texel_sum_level(c, 1.0) == 2);
    CHECK(ibl::ld_texel_sum_level(c, 7.0) == 2);                                      // clamped to 1
    CHECK(ibl::ld_texel_sum_level(c, std::numeric_limits<double>::quiet_NaN()) == 0); // NaN: 0
    CHECK(ibl::ld_texel_sum_level(ibl::cubemap<float>(32), 1.0) == 0);
    // On a smooth source the coarser level agrees with level 0 far below the documented 2e-4.
    const auto sky = ibl::make_default_sky<float>();
    ibl::sky_environment<float> no_sun = sky;
    no_sun.sun_radiance = ibl::vec3<float>(0.f);
    const ibl::cubemap<float> s = ibl::bake_cubemap<float>(no_sun, 128, 2);
    const std::vector<dv> dirs = spread_dirs(16);
    const int lv = ibl::ld_texel_sum_level(s, 0.8);
    REQUIRE(lv == 1); // 64^2
    const std::vector<dv> a = ibl::ld_texel_sum(s, 0, dirs, 0.8), b = ibl::ld_texel_sum(s, lv, dirs, 0.8);
    for (std::size_t i = 0; i < dirs.size(); ++i) CHECK(std::abs(b[i].y - a[i].y) / a[i].y < 2e-4);
}
