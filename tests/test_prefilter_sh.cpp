// bake/prefilter_sh: the fast filter's rough levels by spherical-harmonic convolution. The basis
// against sh/basis.hpp, the band factors against the closed-form moments of the kernel, the levels
// against the exact LD (a polynomial environment in closed form, ld_texel_sum on a sky with a sun),
// the white furnace, the band choice, and prefilter_update bit for bit.
#include <doctest/doctest.h>

#include <ibl/bake/prefilter.hpp>
#include <ibl/bake/prefilter_update.hpp>
#include <ibl/core/executor.hpp>
#include <ibl/env/analytic.hpp>
#include <ibl/env/convert.hpp>
#include <ibl/env/cubemap.hpp>
#include <ibl/reference/ld_irradiance.hpp>
#include <ibl/sh/basis.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

#include "support/ld_poly.hpp"
#include "support/same_bits.hpp"

namespace {

ibl::prefilter_options sh_options(int levels = 5) {
    ibl::prefilter_options o;
    o.method = ibl::prefilter_method::fast;
    o.levels = levels;
    o.sh_rough.enabled = true;
    return o;
}

ibl::cubemap<float> sky_cube(int n) {
    const auto s = ibl::make_default_sky<float>();
    return ibl::bake_cubemap<float>(s, n, 2, ibl::serial_executor{});
}

bool same_bits(const ibl::cubemap<float>& a, const ibl::cubemap<float>& b) { return ibl_test::same_cube_bits(a, b); }

} // namespace

TEST_CASE("prefilter_sh: the reconstruction's basis is sh/basis.hpp's for bands 0-4") {
    // One coefficient at a time (plus a constant that keeps the clamped output positive) through
    // the level kernel itself: with k_l = 1 a texel reads 4 Y_00 + Y_lm at its centre direction.
    const int B = 5, n = 16;
    const ibl::vec3<double> dirs[] = {ibl::cube_texel_direction<double>(0, 3, 11, n), ibl::cube_texel_direction<double>(2, 15, 0, n),
                                      ibl::cube_texel_direction<double>(5, 7, 8, n)};
    const int at[3][3] = {{0, 3, 11}, {2, 15, 0}, {5, 7, 8}};
    for (int l = 0; l < B; ++l)
        for (int m = -l; m <= l; ++m) {
            ibl::detail::sh_level lv;
            lv.bands = B;
            lv.rec = ibl::detail::sh_recurrence(B);
            lv.k.assign(B, 1.0);
            // the projection's layout: m outer, l inner, six sums per (l, m) (cosine R G B, sine R G B)
            std::vector<double> proj(ibl::detail::sh_pair_count(B) * 6, 0.0);
            auto pair = [&](int ll, int mm) { return std::size_t(mm * B - mm * (mm - 1) / 2 + (ll - mm)); };
            proj[pair(0, 0) * 6] = 4.0 * std::sqrt(4.0 * ibl_test::ld_pi); // 4 / Y_00
            // L_lm = sqrt(2) x the cosine (sine) sum for m > 0 (m < 0): a sum of 1 / sqrt(2) is L_lm = 1
            proj[pair(l, std::abs(m)) * 6 + (m < 0 ? 3 : 0)] += m == 0 ? 1.0 : 1.0 / std::sqrt(2.0);
            lv.set_coefficients(proj, B);
            for (int i = 0; i < 3; ++i) {
                std::vector<ibl::vec3<float>> row(n);
                ibl::detail::sh_level_row(lv, at[i][0], at[i][2], n, row.data());
                const auto y = ibl::sh_basis<5>(ibl::vec3<float>(dirs[i]));
                INFO("l " << l << " m " << m << " texel " << i);
                CHECK(row[std::size_t(at[i][1])].x == doctest::Approx(4.0 + y[ibl::detail::sh_index(l, m)]).epsilon(1e-5));
                CHECK(row[std::size_t(at[i][1])].y == 0.f);
            }
        }
}

TEST_CASE("prefilter_sh: band factors of the LD kernel match its moments; the band choice") {
    // k_1 = E[n.l] and k_2 = (3 E[(n.l)^2] - 1) / 2 under the normalised kernel (P_1, P_2).
    for (double r : {0.3, 0.6, 1.0})
        for (ibl::ld_weight w : {ibl::ld_weight::n_dot_l, ibl::ld_weight::g1}) {
            const std::vector<double> k = ibl::detail::zonal_band_factors<ibl::ggx_lobe>(3, r, w);
            const ibl_test::gauss_legendre gl(24);
            auto K = [&](double t) { return ibl::detail::fast_kernel<ibl::ggx_lobe>(t, r, w) * std::sin(t); };
            const double z = ibl_test::graded_integral(K, 0.0, 0.5 * ibl_test::ld_pi, 30, gl);
            const double m1 = ibl_test::graded_integral([&](double t) { return K(t) * std::cos(t); }, 0.0, 0.5 * ibl_test::ld_pi, 30, gl) / z;
            const double m2 =
                ibl_test::graded_integral([&](double t) { return K(t) * std::cos(t) * std::cos(t); }, 0.0, 0.5 * ibl_test::ld_pi, 30, gl) / z;
            CHECK(k[0] == 1.0);
            CHECK(k[1] == doctest::Approx(m1).epsilon(1e-9));
            CHECK(k[2] == doctest::Approx(1.5 * m2 - 0.5).epsilon(1e-8));
        }
    // Wider kernels need fewer bands; r = 0.2 needs more than the cap and keeps its tap set.
    ibl::sh_rough_options o;
    o.enabled = true;
    const int b04 = ibl::detail::sh_rough_bands<ibl::ggx_lobe>(0.4, ibl::ld_weight::n_dot_l, o);
    const int b06 = ibl::detail::sh_rough_bands<ibl::ggx_lobe>(0.6, ibl::ld_weight::n_dot_l, o);
    CHECK(ibl::detail::sh_rough_bands<ibl::ggx_lobe>(0.2, ibl::ld_weight::n_dot_l, o) == 0);
    CHECK(b04 > b06);
    CHECK(b06 > 0);
    CHECK(b04 <= o.max_bands);
    o.max_bands = b04 - 1;
    CHECK(ibl::detail::sh_rough_bands<ibl::ggx_lobe>(0.4, ibl::ld_weight::n_dot_l, o) == 0);
    o.enabled = false;
    CHECK(ibl::detail::sh_rough_bands<ibl::ggx_lobe>(0.6, ibl::ld_weight::n_dot_l, o) == 0);
}

TEST_CASE("prefilter_sh: white furnace, and a polynomial environment's LD in closed form") {
    // A constant source stays constant; L = a + b.d + d^T C d (bands 0-2) filters to its closed
    // form through the kernel's first two moments: the projection's only error is its quadrature
    // (texel centres of a 16^2 or 32^2 level, exact solid angles: a constant leaks about 1e-4 into
    // the cube's own band-4 harmonic).
    const int n = 64;
    ibl::cubemap<float> white(n, 1);
    white.fill(0, [](int, int, int) { return ibl::vec3<float>(2.f, 1.f, 0.5f); });
    white.generate_mips();
    const ibl_test::poly_env env;
    ibl::cubemap<float> poly(n, 1);
    poly.fill(0, [&](int f, int x, int y) {
        return ibl::vec3<float>(env.radiance(ibl::cube_texel_direction<double>(f, x, y, n), 0.0));
    });
    poly.generate_mips();
    for (ibl::ld_weight w : {ibl::ld_weight::n_dot_l, ibl::ld_weight::g1}) {
        ibl::prefilter_options o = sh_options();
        o.weight = w;
        const ibl::specular_chain cw = ibl::prefilter(white, o, ibl::serial_executor{});
        const ibl::specular_chain cp = ibl::prefilter(poly, o, ibl::serial_executor{});
        int sh_levels = 0;
        for (int l = 1; l < cw.levels(); ++l) {
            ibl::prefilter_level lp;
            lp.level = l;
            lp.roughness = o.policy.roughness(double(l), cw.levels());
            if (ibl::detail::prefilter_sh_bands<ibl::ggx_lobe>(o, lp) == 0) continue;
            ++sh_levels;
            const std::vector<double> k = ibl::detail::zonal_band_factors<ibl::ggx_lobe>(3, lp.roughness, w);
            const double m1 = k[1], m2 = (2.0 * k[2] + 1.0) / 3.0;
            double worst_w = 0.0, worst_p = 0.0;
            const int m = cw.size(l);
            for (int f = 0; f < 6; ++f)
                for (int y = 0; y < m; ++y)
                    for (int x = 0; x < m; ++x) {
                        const ibl::vec3<float> v = cw.texel(f, x, y, l);
                        worst_w = std::max({worst_w, double(std::abs(v.x / 2.f - 1.f)), double(std::abs(v.y - 1.f)), double(std::abs(v.z / 0.5f - 1.f))});
                        const ibl::vec3<double> R = ibl::cube_texel_direction<double>(f, x, y, m);
                        const double want = env.ld(R, m1, m2);
                        worst_p = std::max(worst_p, std::abs(double(cp.texel(f, x, y, l).x) / want - 1.0));
                    }
            CHECK(worst_w < 2e-4);
            CHECK(worst_p < 2e-4);
        }
        CHECK(sh_levels >= 3);
    }
}

TEST_CASE("prefilter_sh: the rough levels against the exact LD of a sky with a sun; other sources keep their taps") {
    // The built-in sky with its sun (the peak split takes the sun out of the projection and adds
    // it back exactly): the levels by spherical harmonics are within a percent of ld_texel_sum,
    // below the same filter's tap sets.
    const ibl::cubemap<float> src = sky_cube(64);
    const ibl::thread_executor ex{2};
    ibl::prefilter_options with = sh_options(), without = sh_options();
    without.sh_rough.enabled = false;
    const ibl::specular_chain a = ibl::prefilter(src, with, ex), b = ibl::prefilter(src, without, ex);
    for (int l = 2; l < a.levels(); ++l) {
        const int m = a.size(l);
        const double r = with.policy.roughness(double(l), a.levels());
        std::vector<ibl::vec3<double>> dirs;
        std::vector<ibl::vec3<int>> at;
        for (int i = 0; i < 60; ++i) {
            const int f = i % 6, x = (i * 7) % m, y = (i * 13 + 3) % m;
            dirs.push_back(ibl::cube_texel_direction<double>(f, x, y, m));
            at.emplace_back(f, x, y);
        }
        const std::vector<ibl::vec3<double>> ref = ibl::ld_texel_sum(src, 0, std::span<const ibl::vec3<double>>(dirs), r, with.weight, ex);
        double ea = 0.0, eb = 0.0;
        for (std::size_t i = 0; i < ref.size(); ++i) {
            const double y = ibl::luminance(ref[i]);
            const double ya = ibl::luminance(ibl::vec3<double>(a.texel(at[i].x, at[i].y, at[i].z, l)));
            const double yb = ibl::luminance(ibl::vec3<double>(b.texel(at[i].x, at[i].y, at[i].z, l)));
            ea += (ya - y) * (ya - y) / (y * y), eb += (yb - y) * (yb - y) / (y * y);
        }
        ea = std::sqrt(ea / double(ref.size())), eb = std::sqrt(eb / double(ref.size()));
        INFO("level " << l << ": sh " << ea << ", taps " << eb);
        CHECK(ea < 1e-2);
        CHECK(ea < eb);
    }
    // An analytic source has no texels to project: the option changes nothing.
    const auto sky = ibl::make_default_sky<float>();
    ibl::prefilter_options o = sh_options(3);
    o.base_size = 8;
    o.samples = 16;
    const ibl::specular_chain s1 = ibl::prefilter(sky, o, ibl::serial_executor{});
    o.sh_rough.enabled = false;
    const ibl::specular_chain s0 = ibl::prefilter(sky, o, ibl::serial_executor{});
    CHECK(same_bits(s1, s0));
}

TEST_CASE("prefilter_sh: prefilter_update equals the one-shot chain bit for bit, in budgeted units") {
    const ibl::cubemap<float> a = sky_cube(32);
    ibl::cubemap<float> b = a;
    for (int f = 0; f < 6; ++f)
        for (int y = 0; y < 32; ++y)
            for (int x = 0; x < 32; ++x) b.set_texel(f, x, y, 0, a.texel(f, x, y, 0) * (x == y ? 40.f : 1.f));
    b.generate_mips();
    for (ibl::ld_weight w : {ibl::ld_weight::n_dot_l, ibl::ld_weight::g1}) {
        ibl::prefilter_options o = sh_options();
        o.weight = w;
        o.samples_per_level = {0, 8, 32, 128, 512};
        for (std::uint64_t budget : {std::uint64_t(300), std::uint64_t(20000), ~std::uint64_t(0) / 2}) {
            ibl::prefilter_update<> up(a, o);
            for (const ibl::cubemap<float>* src : {static_cast<const ibl::cubemap<float>*>(&a), static_cast<const ibl::cubemap<float>*>(&b)}) {
                up.set_source(*src);
                std::uint64_t spent = 0, most = 0;
                int calls = 0;
                while (!up.done()) {
                    const std::uint64_t s = up.step(budget, ibl::thread_executor{2});
                    spent += s, most = std::max(most, s);
                    REQUIRE(++calls < 1000000);
                }
                // the pass's taps and units, known exactly once its peak split is done (peaks_ready)
                std::uint64_t unit = up.setup_unit_taps();
                for (std::size_t k = 0; k < up.plan().size(); ++k) unit = std::max(unit, up.unit_taps(k));
                CHECK(spent == up.total_taps());
                CHECK(most <= std::max(budget, unit));
                CHECK(same_bits(*up.result(), ibl::prefilter(*src, o, ibl::thread_executor{2})));
            }
        }
    }
}
