// tests/test_radiance_reference.cpp — the outgoing-radiance reference without the split sum
// (reference/radiance.hpp) and its environment distribution (reference/env_importance.hpp).
//
// Tolerances on Monte Carlo estimates are in units of the estimator's own standard error (from
// 16 independent randomisations): |estimate - truth| <= 4 se. With 16 batches the studentised
// error is t-distributed with 15 degrees of freedom; P(|t_15| > 4) = 1.2e-3 per check, and the
// results are deterministic, so a check that passes once passes always (the bound documents how
// surprising a failure would be, not a flake rate).

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include <ibl/brdf/fresnel.hpp>
#include <ibl/brdf/model.hpp>
#include <ibl/core/executor.hpp>
#include <ibl/core/frame.hpp>
#include <ibl/env/analytic.hpp>
#include <ibl/env/convert.hpp>
#include <ibl/env/cubemap.hpp>
#include <ibl/bake/dfg.hpp>
#include <ibl/reference/env_importance.hpp>
#include <ibl/reference/radiance.hpp>

#include "support/stats.hpp"

namespace {

using ibl::vec2;
using ibl::vec3;
using d3 = vec3<double>;

constexpr double k_sigma = 4.0; // see the file header

/// A 4 x 4-per-face cubemap with luminance spanning 0 .. 50 and some black texels: a
/// discontinuous distribution, the hard case for pdf and sampler agreement.
ibl::cubemap<float> make_checker_cube(int n = 4) {
    ibl::cubemap<float> c(n, 1);
    ibl_test::uniform_rng rng(7);
    c.fill(0, [&](int f, int x, int y) {
        const double r = rng.next<double>();
        const bool black = (x + y + f) % 5 == 0;
        const float v = black ? 0.0f : float(0.1 + 50.0 * r * r * r);
        return vec3<float>(v, 0.5f * v, 0.25f * v);
    });
    c.update_borders();
    return c;
}

/// Integral over face `f` of g(unit dir) d(omega), Gauss-Legendre per texel of an n x n grid in
/// (sc, tc) with d(omega) = dsc dtc / (1 + sc^2 + tc^2)^(3/2) (cube_geometry.hpp).
template <class G> double face_integral(int f, int n, int nodes, G&& g) {
    const ibl_test::gauss_legendre gl(nodes);
    double acc = 0.0;
    const double h = 2.0 / n;
    for (int ty = 0; ty < n; ++ty)
        for (int tx = 0; tx < n; ++tx)
            for (int j = 0; j < nodes; ++j)
                for (int i = 0; i < nodes; ++i) {
                    const double sc = -1.0 + h * (tx + 0.5 + 0.5 * gl.x[std::size_t(i)]);
                    const double tc = -1.0 + h * (ty + 0.5 + 0.5 * gl.x[std::size_t(j)]);
                    const double r2 = 1.0 + sc * sc + tc * tc;
                    const d3 d = ibl::cube_face_point(f, sc, tc) / std::sqrt(r2);
                    acc += 0.25 * h * h * gl.w[std::size_t(i)] * gl.w[std::size_t(j)] * g(d) / (r2 * std::sqrt(r2));
                }
    return acc;
}

/// Integral of g over the cap of angular radius `radius` about `axis`: midpoint rule in the polar
/// angle rho (density sin rho) and azimuth; relative error O((radius / nodes)^2) for smooth g.
template <class G> d3 cap_integral(const d3& axis, double radius, int nodes, G&& g) {
    const ibl::frame<double> fr = ibl::make_frame(axis);
    const int n_psi = 4 * nodes;
    const double d_rho = radius / nodes, d_psi = ibl::two_pi_v<double> / n_psi;
    d3 acc(0.0);
    for (int i = 0; i < nodes; ++i) {
        const double rho = (i + 0.5) * d_rho;
        for (int j = 0; j < n_psi; ++j) {
            const double psi = (j + 0.5) * d_psi;
            const d3 l = fr.to_world(d3(std::sin(rho) * std::cos(psi), std::sin(rho) * std::sin(psi), std::cos(rho)));
            acc += g(l) * (std::sin(rho) * d_rho * d_psi);
        }
    }
    return acc;
}

/// |a - b| <= k_sigma * sqrt(se_a^2 + se_b^2) + slack, per channel.
void check_agree(const d3& a, const d3& se_a, const d3& b, const d3& se_b, double slack = 0.0) {
    for (int c = 0; c < 3; ++c) {
        const double tol = k_sigma * std::sqrt(se_a[c] * se_a[c] + se_b[c] * se_b[c]) + slack;
        CHECK(std::fabs(a[c] - b[c]) <= tol);
    }
}

/// View direction with cosine mu to n, azimuth phi in n's Duff frame.
d3 view_at(const d3& n, double mu, double phi) {
    const ibl::frame<double> fr = ibl::make_frame(n);
    const double s = ibl::sin_from_cos(mu);
    return fr.to_world(d3(s * std::cos(phi), s * std::sin(phi), mu));
}

ibl::sky_environment<double> smooth_sky() {
    ibl::sky_environment<double> s = ibl::make_default_sky<double>();
    s.sun_radiance = d3(0.0);
    return s;
}

} // namespace

TEST_CASE("env distribution: the pdf integrates to 1 over the sphere and to p_i over each texel") {
    for (const bool tent : {true, false}) {
        CAPTURE(tent);
        const ibl::cubemap<float> cube = make_checker_cube();
        const ibl::cube_env_distribution dist(cube, {0, tent, 0.0});
        const int n = dist.size();
        double total = 0.0, prob_sum = 0.0, max_texel_err = 0.0;
        for (int f = 0; f < 6; ++f) {
            total += face_integral(f, n, 6, [&](const d3& d) { return dist.pdf(d); });
            for (int y = 0; y < n; ++y)
                for (int x = 0; x < n; ++x) {
                    // One texel: its (sc, tc) rectangle, 6 x 6 Gauss-Legendre (pdf smooth inside).
                    const ibl_test::gauss_legendre gl(6);
                    double acc = 0.0;
                    const double h = 2.0 / n;
                    for (int j = 0; j < 6; ++j)
                        for (int i = 0; i < 6; ++i) {
                            const double sc = -1.0 + h * (x + 0.5 + 0.5 * gl.x[std::size_t(i)]);
                            const double tc = -1.0 + h * (y + 0.5 + 0.5 * gl.x[std::size_t(j)]);
                            const double r2 = 1.0 + sc * sc + tc * tc;
                            const d3 d = ibl::cube_face_point(f, sc, tc) / std::sqrt(r2);
                            acc += 0.25 * h * h * gl.w[std::size_t(i)] * gl.w[std::size_t(j)] * dist.pdf(d) /
                                   (r2 * std::sqrt(r2));
                        }
                    const double p = dist.texel_probability(f, x, y);
                    prob_sum += p;
                    max_texel_err = std::max(max_texel_err, std::fabs(acc - p));
                }
        }
        // pdf * (1 + sc^2 + tc^2)^(-3/2) is constant on each texel: Gauss-Legendre is exact up to
        // rounding of ~100 terms of size <= 1 (1e-13 is ~500 ulps).
        CHECK(total == doctest::Approx(1.0).epsilon(1e-13));
        CHECK(prob_sum == doctest::Approx(1.0).epsilon(1e-13));
        CHECK(max_texel_err < 1e-14);
        // Black texels (with no bright neighbours when unfiltered) get probability 0; with the
        // tent filter every texel next to a lit one is positive.
        int zero = 0;
        for (int f = 0; f < 6; ++f)
            for (int y = 0; y < n; ++y)
                for (int x = 0; x < n; ++x) zero += dist.texel_probability(f, x, y) == 0.0 ? 1 : 0;
        if (tent)
            CHECK(zero == 0);
        else
            CHECK(zero > 0);
    }
}

TEST_CASE("env distribution: sampling histogram matches the pdf (chi-square at 1%)") {
    const ibl::cubemap<float> cube = make_checker_cube();
    const ibl::cube_env_distribution dist(cube, {0, true, 0.1});
    // Cells: 24 bands in y = cos(polar angle about +Y) x 48 in azimuth: equal solid angle, and
    // not aligned with the cube's texels, so the test does not rely on the (sc, tc) Jacobian.
    constexpr int nz = 24, nphi = 48, sub = 12;
    constexpr std::uint32_t samples = 200000;
    auto cell_of = [&](const d3& d) {
        const int iz = std::min(nz - 1, int((d.y + 1.0) * 0.5 * nz));
        double phi = std::atan2(d.z, d.x);
        if (phi < 0) phi += ibl::two_pi_v<double>;
        const int ip = std::min(nphi - 1, int(phi / ibl::two_pi_v<double> * nphi));
        return iz * nphi + ip;
    };
    std::vector<double> observed(nz * nphi, 0.0), expected(nz * nphi, 0.0);
    ibl_test::uniform_rng rng(1234);
    for (std::uint32_t i = 0; i < samples; ++i) {
        const double ux = rng.next<double>(), uy = rng.next<double>();
        const ibl::env_sample s = dist.sample({ux, uy});
        REQUIRE(s.pdf > 0.0);
        REQUIRE(std::fabs(glm::length(s.dir) - 1.0) < 1e-14);
        // The pdf reported by sample() is the one pdf() evaluates (same texel, same Jacobian);
        // they may differ only for draws on a texel edge (measure zero) — none with double u.
        REQUIRE(s.pdf == doctest::Approx(dist.pdf(s.dir)).epsilon(1e-12));
        observed[std::size_t(cell_of(s.dir))] += 1.0;
    }
    // Expected counts: sub x sub midpoint rule per cell in (y, phi), d(omega) = dy dphi.
    const double dz = 2.0 / nz, dp = ibl::two_pi_v<double> / nphi;
    for (int iz = 0; iz < nz; ++iz)
        for (int ip = 0; ip < nphi; ++ip) {
            double acc = 0.0;
            for (int a = 0; a < sub; ++a)
                for (int b = 0; b < sub; ++b) {
                    const double y = -1.0 + dz * (iz + (a + 0.5) / sub);
                    const double phi = dp * (ip + (b + 0.5) / sub);
                    const double s = ibl::sin_from_cos(y);
                    acc += dist.pdf(d3(s * std::cos(phi), y, s * std::sin(phi)));
                }
            expected[std::size_t(iz * nphi + ip)] = samples * acc * dz * dp / (sub * sub);
        }
    const ibl_test::chi2_result r = ibl_test::chi2_test(observed, expected);
    MESSAGE("env distribution chi-square: statistic " << r.statistic << ", dof " << r.dof << ", p " << r.p_value);
    // Expected counts carry the midpoint rule's O(1 / grid) error in cells crossed by texel edges
    // (the pdf jumps there): measured 4e-3 of the total on this 288 x 576 grid (1e-3 at 1000 x
    // 2000). The exact normalisation is the previous test's; here 1e-2 only guards the grid.
    CHECK(r.expected_total == doctest::Approx(double(samples)).epsilon(1e-2));
    CHECK(r.p_value > 0.01);
}

TEST_CASE("radiance reference: white furnace") {
    const ibl::constant_environment<double> white{d3(1.0)};
    const ibl::cube_env_distribution dist = ibl::make_cube_env_distribution<double>(white, 8, 1);
    const d3 n = glm::normalize(d3(0.2, 1.0, -0.3));
    ibl::radiance_reference_options opt;
    opt.samples = 4096;

    SUBCASE("specular only, F0 = F90 = 1: Lo = E(n.v, r) = A + B of dfg_exact") {
        ibl::reference_material m;
        m.diffuse_albedo = d3(0.0);
        m.f0 = m.f90 = d3(1.0);
        for (const std::pair<double, double>& q : {std::pair{1.0, 0.5}, {0.5, 0.25}, {0.2, 0.8}, {0.05, 1.0}, {0.7, 0.08}}) {
            const double mu = q.first, r = q.second; // (not a structured binding: CAPTURE needs a variable)
            CAPTURE(mu);
            CAPTURE(r);
            m.roughness = r;
            const ibl::radiance_estimate e = ibl::reference_radiance(white, dist, n, view_at(n, mu, 1.0), m, opt);
            const vec2<double> ab = ibl::dfg_exact<ibl::ggx_height_correlated>(mu, r);
            // dfg_exact converges to <= 1e-6 (bake/dfg.hpp).
            CHECK(std::fabs(e.value.x - (ab.x + ab.y)) <= k_sigma * e.std_error.x + 1e-6);
            CHECK(e.value.x == e.value.y); // F = 1 and L = 1 in every channel: identical channels
            // 4096 samples against an integrand of variance < 1: se well below 1%.
            CHECK(e.std_error.x < 3e-3);
            CHECK(e.diffuse == d3(0.0));
        }
    }
    SUBCASE("Lambert only, albedo 1: Lo = 1") {
        ibl::reference_material m;
        m.diffuse_albedo = d3(1.0);
        m.f0 = m.f90 = d3(0.0);
        const d3 v = view_at(n, 0.3, 2.0);
        const ibl::radiance_estimate mis = ibl::reference_radiance(white, dist, n, v, m, opt);
        CHECK(std::fabs(mis.value.x - 1.0) <= k_sigma * mis.std_error.x + 1e-12);
        CHECK(mis.std_error.x < 1e-2); // MIS weights make the estimator non-constant, but tame
        // Cosine sampling alone: f cos / pdf = 1 for every sample (zero variance up to rounding).
        ibl::radiance_reference_options brdf = opt;
        brdf.strategy = ibl::radiance_strategy::brdf;
        const ibl::radiance_estimate b = ibl::reference_radiance(white, dist, n, v, m, brdf);
        CHECK(b.value.x == doctest::Approx(1.0).epsilon(1e-12));
        CHECK(b.std_error.x < 1e-12);
    }
}

TEST_CASE("radiance reference: MIS, BRDF-only and env-only agree on a smooth sky") {
    const ibl::sky_environment<double> sky = smooth_sky();
    const ibl::cubemap<double> cube = ibl::bake_cubemap<double>(sky, 16, 2);
    const ibl::cube_env_distribution dist(cube);
    const d3 n = glm::normalize(d3(0.3, 1.0, 0.2));
    const d3 v = view_at(n, 0.6, 0.7);
    ibl::radiance_reference_options opt;
    opt.samples = 4096;
    const ibl::reference_material dielectric = ibl::make_reference_material(d3(0.8), 0.0, 0.3);
    const ibl::reference_material metal = ibl::make_reference_material(d3(0.95, 0.64, 0.54), 1.0, 0.7);
    for (const auto* m : {&dielectric, &metal}) {
        CAPTURE(m->roughness);
        // Analytic sky (the cube is only the proposal) and the baked cube itself as integrand.
        for (const bool on_cube : {false, true}) {
            CAPTURE(on_cube);
            ibl::radiance_estimate e[3];
            const ibl::radiance_strategy st[3] = {ibl::radiance_strategy::mis, ibl::radiance_strategy::brdf,
                                                  ibl::radiance_strategy::env};
            for (int k = 0; k < 3; ++k) {
                ibl::radiance_reference_options o = opt;
                o.strategy = st[k];
                e[k] = on_cube ? ibl::reference_radiance(cube, dist, n, v, *m, o)
                               : ibl::reference_radiance(sky, dist, n, v, *m, o);
                CHECK(e[k].value.x > 0.0);
                // A smooth sky: every technique converges to a relative se < 1% at 4096 samples.
                CHECK(e[k].std_error.x < 1e-2 * e[k].value.x);
            }
            check_agree(e[0].value, e[0].std_error, e[1].value, e[1].std_error);
            check_agree(e[0].value, e[0].std_error, e[2].value, e[2].std_error);
            check_agree(e[1].value, e[1].std_error, e[2].value, e[2].std_error);
        }
    }
}

TEST_CASE("radiance reference: a sky with a sun — oracle agreement and error against BRDF sampling") {
    const ibl::sky_environment<double> sky = ibl::make_default_sky<double>();
    // Proposal: the sky baked at 64 x 64 per face, 4 x 4 sub-samples (the sun covers ~2 texels).
    const ibl::cube_env_distribution dist = ibl::make_cube_env_distribution<double>(sky, 64, 4);
    // n = +Y, v such that R = reflect(-v, n) points at the sun centre (n.v = sin 30 deg = 0.5).
    const d3 n(0.0, 1.0, 0.0);
    const d3 v(-sky.sun_dir.x, sky.sun_dir.y, -sky.sun_dir.z);
    for (const double r : {0.3, 0.6}) {
        CAPTURE(r);
        const ibl::reference_material m = ibl::make_reference_material(d3(0.8), 0.0, r);
        // Oracle: L = sky + sun superpose. Sky part: BRDF sampling of the sunless sky at 2^16
        // samples; sun part: sun_radiance * integral over the cap of f cos (cap_integral,
        // 48 x 192 nodes: relative error ~(r_sun / 48)^2 ~ 1e-7).
        ibl::radiance_reference_options big;
        big.samples = 1u << 16;
        big.strategy = ibl::radiance_strategy::brdf;
        const ibl::radiance_estimate sky_part = ibl::reference_radiance(smooth_sky(), nullptr, n, v, m, big);
        const ibl::brdf_lobe<> lobe(n, v, m);
        const d3 cap = cap_integral(sky.sun_dir, sky.sun_angular_radius, 48, [&](const d3& l) {
            const ibl::lobe_value g = lobe.eval(l);
            return g.parts[0] + g.parts[1];
        });
        const d3 oracle = sky_part.value + sky.sun_radiance * cap;

        ibl::radiance_reference_options opt;
        opt.samples = 4096;
        const ibl::radiance_estimate mis = ibl::reference_radiance(sky, dist, n, v, m, opt);
        opt.strategy = ibl::radiance_strategy::brdf;
        const ibl::radiance_estimate brdf = ibl::reference_radiance(sky, dist, n, v, m, opt);
        check_agree(mis.value, mis.std_error, oracle, sky_part.std_error, 1e-6 * oracle.x);
        // The sun dominates: Lo is several times the sunless value.
        CHECK(oracle.x > 2.0 * sky_part.value.x);
        const double ratio = brdf.std_error.x / mis.std_error.x;
        MESSAGE("sun, r = " << r << ": Lo = " << oracle.x << ", MIS " << mis.value.x << " +- " << mis.std_error.x
                            << ", BRDF-only " << brdf.value.x << " +- " << brdf.std_error.x
                            << "; se ratio BRDF/MIS = " << ratio);
        // The acceptance figure of the estimator: at equal samples MIS's error is several times
        // smaller (measured 9.3x at r = 0.3 and 40x at r = 0.6; 4x is the floor we promise).
        CHECK(ratio > 4.0);
        // The residual MIS error is the sun's edge: texels the cap covers partly are sampled by
        // their mean luminance, and a draw in them hits or misses the sun (relative variance
        // ~ (1 - c) / c at coverage c): ~1.5% at 4096 samples, falling as 1/sqrt(samples).
        CHECK(mis.std_error.x < 0.03 * mis.value.x);
    }
}

TEST_CASE("radiance reference: mirror limit, grazing view and rough extreme are finite and right") {
    const ibl::sky_environment<double> sky = smooth_sky();
    const ibl::cube_env_distribution dist = ibl::make_cube_env_distribution<double>(sky, 16, 2);
    const d3 n = glm::normalize(d3(0.4, 1.0, 0.1));
    ibl::radiance_reference_options opt;
    opt.samples = 2048;

    SUBCASE("r = 0, specular only: Lo = F(n.v) L(reflect(-v, n)) exactly") {
        ibl::reference_material m = ibl::make_reference_material(d3(0.0), 0.0, 0.0);
        for (const double mu : {1.0, 0.5, 0.1, 0.0}) {
            CAPTURE(mu);
            const d3 v = view_at(n, mu, 0.3);
            const d3 refl = 2.0 * glm::dot(n, v) * n - v;
            const d3 expect = ibl::fresnel_schlick(std::max(0.0, glm::dot(n, v)), m.f0, m.f90) * sky.radiance(refl);
            const ibl::radiance_estimate e = ibl::reference_radiance(sky, dist, n, v, m, opt);
            for (int c = 0; c < 3; ++c) CHECK(e.value[c] == doctest::Approx(expect[c]).epsilon(1e-12));
            CHECK(e.std_error == d3(0.0));
        }
    }
    SUBCASE("near-mirror r = 0.03 (sampled) approaches the mirror value") {
        const d3 v = view_at(n, 0.5, 0.3);
        ibl::reference_material m = ibl::make_reference_material(d3(0.0), 0.0, 0.03);
        const ibl::radiance_estimate e = ibl::reference_radiance(sky, dist, n, v, m, opt);
        m.roughness = 0.0;
        const ibl::radiance_estimate mirror = ibl::reference_radiance(sky, dist, n, v, m, opt);
        // alpha = 9e-4: the lobe spans ~1e-3 rad, over which the sky changes by < 1e-3 relative,
        // and the albedo E(0.5, 0.03) differs from F(0.5) by < 1e-3 (dfg_exact): 0.5% is ample.
        CHECK(e.value.x == doctest::Approx(mirror.value.x).epsilon(5e-3));
        CHECK(e.std_error.x < 1e-3 * e.value.x);
    }
    SUBCASE("n.v = 0 (grazing) and r in {0, 0.5, 1}: finite, non-negative, strategies agree") {
        const d3 v = view_at(n, 0.0, 1.1);
        for (const double r : {0.0, 0.5, 1.0}) {
            CAPTURE(r);
            const ibl::reference_material m = ibl::make_reference_material(d3(0.5, 0.6, 0.7), 0.0, r);
            const ibl::radiance_estimate e = ibl::reference_radiance(sky, dist, n, v, m, opt);
            ibl::radiance_reference_options b = opt;
            b.strategy = ibl::radiance_strategy::brdf;
            const ibl::radiance_estimate eb = ibl::reference_radiance(sky, dist, n, v, m, b);
            for (int c = 0; c < 3; ++c) {
                CHECK(std::isfinite(e.value[c]));
                CHECK(std::isfinite(e.std_error[c]));
                CHECK(e.value[c] >= 0.0);
            }
            check_agree(e.value, e.std_error, eb.value, eb.std_error);
        }
    }
    SUBCASE("r = 1 and n.v = 1: finite, agrees with BRDF sampling") {
        const d3 v = n;
        const ibl::reference_material m = ibl::make_reference_material(d3(0.95, 0.64, 0.54), 1.0, 1.0);
        const ibl::radiance_estimate e = ibl::reference_radiance(sky, dist, n, v, m, opt);
        ibl::radiance_reference_options b = opt;
        b.strategy = ibl::radiance_strategy::brdf;
        const ibl::radiance_estimate eb = ibl::reference_radiance(sky, dist, n, v, m, b);
        check_agree(e.value, e.std_error, eb.value, eb.std_error);
        CHECK(std::isfinite(e.value.x));
    }
}

TEST_CASE("radiance reference: deterministic, independent of the executor") {
    const ibl::sky_environment<double> sky = ibl::make_default_sky<double>();
    const ibl::cube_env_distribution dist = ibl::make_cube_env_distribution<double>(sky, 16, 2);
    const d3 n(0.0, 1.0, 0.0);
    const d3 v = view_at(n, 0.4, 0.5);
    const ibl::reference_material m = ibl::make_reference_material(d3(0.8), 0.0, 0.4);
    ibl::radiance_reference_options opt;
    opt.samples = 1024;
    const ibl::radiance_estimate a = ibl::reference_radiance(sky, dist, n, v, m, opt);
    const ibl::radiance_estimate b = ibl::reference_radiance(sky, dist, n, v, m, opt, ibl::thread_executor{2});
    CHECK(a.value == b.value);
    CHECK(a.std_error == b.std_error);
    opt.seed = 1;
    const ibl::radiance_estimate c = ibl::reference_radiance(sky, dist, n, v, m, opt);
    CHECK(c.value != a.value); // another seed is another randomisation
    check_agree(a.value, a.std_error, c.value, c.std_error);
}
