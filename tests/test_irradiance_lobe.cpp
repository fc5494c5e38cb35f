// tests/test_irradiance_lobe.cpp — irradiance through the lobe-generic prefilter
// (irradiance_cubemap_lobe with sampling/lobe.hpp's cosine_lobe).
//   * white furnace: a constant environment L gives pi L at every texel (the estimator is
//     normalised, every draw weighs 1): float rounding only;
//   * a linear environment L(d) = a + b d.k (analytic, evaluated per draw: no lods) has the exact
//     irradiance E(n) = pi (a + (2/3) b n.k); the estimate is pi (a + b mean_i(F(n) l_i).k) over
//     the table's draws l_i, so its error is at most pi |b| |mean_i l_i - (0, 0, 2/3)|: the bound is
//     computed from the table itself (the first-moment error of the cosine-warped Hammersley set),
//     plus float rounding of the stored texel;
//   * the cosine lobe's contract: pdf integrates to 1 over h (as a density of h), ld_weight
//     times n.l is 1, and its draws give the same directions as the cosine-importance table.

#include <doctest/doctest.h>

#include <cmath>

#include <ibl/env/analytic.hpp>
#include <ibl/env/cube_geometry.hpp>
#include <ibl/env/cubemap.hpp>
#include <ibl/bake/irradiance.hpp>
#include <ibl/sampling/hemisphere.hpp>
#include <ibl/sampling/lobe.hpp>
#include <ibl/sampling/sequence.hpp>

using dvec3 = ibl::vec3<double>;
using fvec3 = ibl::vec3<float>;

TEST_CASE("irradiance lobe: white furnace gives pi L") {
    ibl::cubemap<float> c(16);
    for (int l = 0; l < c.levels(); ++l) c.fill(l, [](int, int, int) { return fvec3(0.7f, 0.2f, 1.5f); });
    c.update_borders();
    const ibl::cubemap<float> e = ibl::irradiance_cubemap_lobe(c, 8, 256);
    for (int f = 0; f < 6; ++f)
        for (int y = 0; y < 8; ++y)
            for (int x = 0; x < 8; ++x) {
                const fvec3 v = e.texel(f, x, y, 0);
                CHECK(v.x == doctest::Approx(ibl::pi_v<double> * 0.7).epsilon(4e-7));
                CHECK(v.y == doctest::Approx(ibl::pi_v<double> * 0.2).epsilon(4e-7));
                CHECK(v.z == doctest::Approx(ibl::pi_v<double> * 1.5).epsilon(4e-7));
            }
}

TEST_CASE("irradiance lobe: a linear environment within the sample set's first-moment bound") {
    const dvec3 k = glm::normalize(dvec3(0.3, 0.8, -0.5));
    const double a = 1.0, b = 0.75;
    const auto env = ibl::make_lambda_environment<double>([&](const dvec3& d) { return dvec3(a + b * glm::dot(d, k)); });
    for (const std::uint32_t n : {64u, 1024u}) {
        const ibl::sphere_sample_table<double> t =
            ibl::make_ld_table_for<double, ibl::cosine_lobe>(env, 0.0, n, ibl::prefilter_method::importance, 0.0);
        dvec3 mean(0.0);
        double w = 0.0;
        for (std::size_t i = 0; i < t.x.size(); ++i) {
            mean += t.weight[i] * dvec3(t.x[i], t.y[i], t.z[i]);
            w += t.weight[i];
        }
        const double delta = glm::length(mean / w - dvec3(0.0, 0.0, 2.0 / 3.0));
        const ibl::cubemap<float> e = ibl::irradiance_cubemap_lobe(env, 6, n);
        double worst = 0.0;
        for (int f = 0; f < 6; ++f)
            for (int y = 0; y < 6; ++y)
                for (int x = 0; x < 6; ++x) {
                    const dvec3 nn = ibl::cube_texel_direction<double>(f, x, y, 6);
                    const double exact = ibl::pi_v<double> * (a + 2.0 / 3.0 * b * glm::dot(nn, k));
                    const double got = e.texel(f, x, y, 0).x;
                    const double bound = ibl::pi_v<double> * std::fabs(b) * delta * (1.0 + 1e-9) + 4e-7 * std::fabs(exact);
                    CHECK(std::fabs(got - exact) <= bound);
                    worst = std::max(worst, std::fabs(got - exact));
                }
        MESSAGE("N = " << n << ": first-moment error " << delta << ", worst |E - exact| " << worst);
    }
}

TEST_CASE("irradiance lobe: the cosine lobe keeps its contract") {
    // ld_weight x n.l = 1 for every draw; the draws are the cosine-importance table's directions
    for (std::uint32_t i = 1; i < 512; ++i) {
        const ibl::vec2<double> u = ibl::hammersley<double>(i, 512);
        const dvec3 h = ibl::cosine_lobe::sample(u, 0.0);
        const double n_dot_l = 2.0 * h.z * h.z - 1.0;
        const dvec3 l(2.0 * h.z * h.x, 2.0 * h.z * h.y, n_dot_l);
        const dvec3 want = ibl::sample_cosine_hemisphere(u);
        CHECK(glm::length(l - want) <= 8e-16);
        if (n_dot_l > 1e-6) {
            CHECK(n_dot_l * ibl::cosine_lobe::ld_weight(h, 0.0) == doctest::Approx(1.0).epsilon(1e-12));
            CHECK(ibl::cosine_lobe::ld_pdf(h, 0.0) == doctest::Approx(n_dot_l / ibl::pi_v<double>).epsilon(1e-12));
        }
    }
    // pdf(h) integrates to 1 over the hemisphere of h (midpoint rule in (cos theta_h, phi): the
    // density is n.l / pi * 4 n.h, a polynomial in cos theta_h of degree 3: 4000 nodes leave < 1e-7)
    double sum = 0.0;
    const int m = 4000;
    for (int i = 0; i < m; ++i) {
        const double c = (i + 0.5) / m, s = std::sqrt(1.0 - c * c);
        sum += ibl::cosine_lobe::pdf(dvec3(s, 0.0, c), 0.0) * (1.0 / m) * 2.0 * ibl::pi_v<double>;
    }
    CHECK(sum == doctest::Approx(1.0).epsilon(1e-6));
}
