// tests/test_occlusion.cpp — the occluded specular reference, the cone's ambient occlusion and the
// visible-fraction table (reference/occluded_specular.hpp, ibl/runtime/specular_occlusion.hpp).
//
// Tolerances: Monte Carlo estimates within 4 standard errors of their 16 batch means (the
// convention of test_radiance_reference.cpp: P(|t_15| > 4) = 1.2e-3, results deterministic);
// deterministic quadratures within their own convergence estimate |Q(2N) - Q(N)| (both rules
// converge at least linearly, so the difference bounds the error of the finer one), plus the
// other side's error.

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include <ibl/brdf/fresnel.hpp>
#include <ibl/brdf/ggx.hpp>
#include <ibl/brdf/model.hpp>
#include <ibl/core/frame.hpp>
#include <ibl/core/gauss_legendre.hpp>
#include <ibl/env/analytic.hpp>
#include <ibl/reference/env_importance.hpp>
#include <ibl/reference/occluded_specular.hpp>
#include <ibl/reference/radiance.hpp>
#include <ibl/runtime/specular_occlusion.hpp>

namespace {

using d3 = ibl::vec3<double>;
using model = ibl::ggx_height_correlated;
constexpr double k_sigma = 4.0;
constexpr double k_pi = 3.14159265358979323846;

d3 view_at(const d3& n, double mu, double azimuth) {
    const ibl::frame<double> f = ibl::make_frame(n);
    const double s = std::sqrt(std::max(0.0, 1.0 - mu * mu));
    return f.to_world(d3(s * std::cos(azimuth), s * std::sin(azimuth), mu));
}

/// integral over the cone of g(l) sin t dt dp in the cone's frame, Gauss-Legendre N x 2N in
/// (t, p) with the p range split at pi (the lobe about R lies at one azimuth).
template <class G> double cone_quadrature(const ibl::visibility_cone& cone, std::size_t n, G&& g) {
    const ibl::gauss_legendre_rule rt = ibl::make_gauss_legendre(n), rp = ibl::make_gauss_legendre(2 * n);
    const ibl::frame<double> f = ibl::make_frame(cone.axis);
    double sum = 0.0;
    for (std::size_t i = 0; i < rt.x.size(); ++i) {
        const double t = cone.half_angle * rt.x[i];
        for (std::size_t j = 0; j < rp.x.size(); ++j) {
            const double p = 2.0 * k_pi * rp.x[j];
            const d3 l = f.to_world(d3(std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t)));
            sum += rt.w[i] * rp.w[j] * g(l) * std::sin(t);
        }
    }
    return sum * cone.half_angle * 2.0 * k_pi;
}

/// The cone-restricted albedo of the specular lobe (channel x): integral_cone f_s (n.l)_+ dl.
double cone_albedo(const d3& n, const d3& v, double f0, double r, const ibl::visibility_cone& cone, std::size_t nodes) {
    const double alpha = model::alpha(r), nv = glm::dot(n, v);
    return cone_quadrature(cone, nodes, [&](const d3& l) {
        const double nl = glm::dot(n, l);
        if (!(nl > 0.0)) return 0.0;
        const d3 h = glm::normalize(v + l);
        return ibl::ndf_ggx(glm::dot(n, h), alpha) * model::visibility(nv, nl, r) *
               ibl::fresnel_schlick(glm::dot(v, h), f0, 1.0) * nl;
    });
}

} // namespace

TEST_CASE("occlusion: ambient occlusion of a cone") {
    SUBCASE("about the normal: sin^2 theta_o") {
        for (const double t : {0.0, 0.3, 0.7, 1.2, 0.5 * k_pi}) CHECK(ibl::ambient_occlusion_cone(0.0, t) == doctest::Approx(std::sin(t) * std::sin(t)).epsilon(1e-14));
        CHECK(ibl::ambient_occlusion_cone(0.0, 2.0) == 1.0); // wider than the hemisphere
    }
    SUBCASE("tilted hemisphere: (1 + cos beta) / 2 (the clipped branch)") {
        for (const double beta : {0.1, 0.5, 1.0, 1.4}) {
            CAPTURE(beta);
            const double q = ibl::ambient_occlusion_cone(beta, 0.5 * k_pi, 16);
            const double q2 = ibl::ambient_occlusion_cone(beta, 0.5 * k_pi, 32);
            CHECK(std::fabs(q2 - 0.5 * (1.0 + std::cos(beta))) <= std::fabs(q2 - q) + 1e-15);
        }
    }
    SUBCASE("clipped cones against a brute-force sphere quadrature") {
        // Midpoint rule over the upper hemisphere of n in (cos theta, phi) with the cone's
        // indicator: first order at the cone's edge, so the tolerance is the rule's own halving
        // difference (times 2: the error of the coarse rule, a bound for the fine one's).
        auto brute = [](double beta, double to, int m) {
            const d3 b(std::sin(beta), 0.0, std::cos(beta));
            double s = 0.0;
            for (int i = 0; i < m; ++i)
                for (int j = 0; j < 2 * m; ++j) {
                    const double z = (i + 0.5) / m, p = 2.0 * k_pi * (j + 0.5) / (2 * m);
                    const double st = std::sqrt(1.0 - z * z);
                    const d3 l(st * std::cos(p), st * std::sin(p), z);
                    if (glm::dot(l, b) >= std::cos(to)) s += z;
                }
            return s * (1.0 / m) * (2.0 * k_pi / (2 * m)) / k_pi;
        };
        for (const auto& c : {std::pair{0.5, 1.3}, std::pair{0.9, 0.9}, std::pair{0.3, 1.75}}) {
            const double beta = c.first, to = c.second;
            CAPTURE(beta);
            CAPTURE(to);
            const double q = ibl::ambient_occlusion_cone(beta, to);
            const double b1 = brute(beta, to, 400), b2 = brute(beta, to, 800);
            CHECK(std::fabs(q - b2) <= 2.0 * std::fabs(b2 - b1) + 1e-6);
            // The default 32 nodes against 64, within the 16 -> 32 halving difference.
            CHECK(std::fabs(q - ibl::ambient_occlusion_cone(beta, to, 64)) <= std::fabs(q - ibl::ambient_occlusion_cone(beta, to, 16)) + 1e-15);
        }
    }
    SUBCASE("continuous at the horizon contacts; the inverse") {
        const double beta = 0.6, t1 = 0.5 * k_pi - beta;
        CHECK(ibl::ambient_occlusion_cone(beta, t1 + 1e-9) == doctest::Approx(std::cos(beta) * std::sin(t1) * std::sin(t1)).epsilon(1e-8));
        CHECK(ibl::ambient_occlusion_cone(beta, 0.5 * k_pi + beta - 1e-9) == doctest::Approx(1.0).epsilon(1e-8));
        for (const double ao : {0.25, 0.5, 0.75}) {
            CHECK(ibl::ambient_occlusion_cone(beta, ibl::cone_half_angle_for_ao(ao, beta)) == doctest::Approx(ao).epsilon(1e-12));
            CHECK(ibl::cone_half_angle_for_ao(ao) == doctest::Approx(std::asin(std::sqrt(ao))).epsilon(1e-14));
        }
    }
}

TEST_CASE("occlusion: the occluded reference") {
    const d3 n = glm::normalize(d3(0.2, 1.0, -0.3));
    ibl::reference_material m;
    m.f0 = d3(0.95, 0.64, 0.54);
    ibl::radiance_reference_options opt;
    opt.samples = 1u << 14;

    SUBCASE("theta_o = pi/2 about n: the unoccluded reference, sample for sample") {
        const ibl::sky_environment<double> sky = ibl::make_default_sky<double>();
        const ibl::cube_env_distribution dist = ibl::make_cube_env_distribution<double>(sky, 32, 2);
        for (const double r : {0.05, 0.3, 0.8}) {
            CAPTURE(r);
            m.roughness = r;
            const d3 v = view_at(n, 0.4, 0.7);
            const ibl::occluded_specular_estimate e =
                ibl::occluded_reference_specular(sky, &dist, n, v, m, ibl::visibility_cone{n, 0.5 * k_pi}, opt);
            const ibl::radiance_estimate ref = ibl::reference_radiance(sky, dist, n, v, m, opt);
            for (int c = 0; c < 3; ++c) {
                CHECK(e.unoccluded[c] == doctest::Approx(ref.specular[c]).epsilon(1e-12));
                CHECK(e.occluded[c] == doctest::Approx(ref.specular[c]).epsilon(1e-12));
            }
        }
    }
    SUBCASE("mirror regime: the exact term times V(R)") {
        const ibl::constant_environment<double> white{d3(1.0)};
        m.roughness = 0.0;
        const d3 v = view_at(n, 0.5, 0.2); // R at 60 degrees from n
        const ibl::occluded_specular_estimate in = ibl::occluded_reference_specular(white, nullptr, n, v, m, {n, 1.1}, opt);
        const ibl::occluded_specular_estimate out = ibl::occluded_reference_specular(white, nullptr, n, v, m, {n, 1.0}, opt);
        const d3 f = ibl::fresnel_schlick(0.5, m.f0, d3(1.0));
        CHECK(in.occluded.x == doctest::Approx(f.x).epsilon(1e-12));
        CHECK(out.occluded.x == 0.0);
        CHECK(out.unoccluded.x == doctest::Approx(f.x).epsilon(1e-12));
    }
    SUBCASE("constant environment: the cone-restricted albedo (independent quadrature)") {
        const ibl::constant_environment<double> white{d3(1.0)};
        struct cs {
            double mu, r, tilt, ao;
        };
        for (const cs& c : {cs{0.5, 0.5, 0.0, 0.5}, cs{0.9, 0.3, 0.0, 0.25}, cs{0.3, 0.5, 0.0, 0.75},
                            cs{0.5, 0.5, 0.5, 0.5}, cs{0.2, 0.8, -0.0, 0.25}, cs{0.7, 0.4, 0.4, 0.3}}) {
            CAPTURE(c.mu);
            CAPTURE(c.r);
            CAPTURE(c.tilt);
            CAPTURE(c.ao);
            m.roughness = c.r;
            const d3 v = view_at(n, c.mu, 1.3);
            const ibl::visibility_cone cone = ibl::make_bent_cone(n, v, c.tilt, ibl::cone_half_angle_for_ao(c.ao, c.tilt));
            CHECK(ibl::ambient_occlusion_cone(c.tilt, cone.half_angle) == doctest::Approx(c.ao).epsilon(1e-10));
            const ibl::occluded_specular_estimate e = ibl::occluded_reference_specular(white, nullptr, n, v, m, cone, opt);
            for (int ch = 0; ch < 3; ch += 2) {
                const double q1 = cone_albedo(n, v, m.f0[ch], c.r, cone, 48), q2 = cone_albedo(n, v, m.f0[ch], c.r, cone, 96);
                CHECK(std::fabs(e.occluded[ch] - q2) <= k_sigma * e.std_error_occluded[ch] + std::fabs(q2 - q1));
                CHECK(e.occluded[ch] < e.unoccluded[ch]);
            }
        }
    }
    SUBCASE("MIS with masked environment proposals agrees with BRDF sampling alone") {
        const ibl::sky_environment<double> sky = ibl::make_default_sky<double>();
        const ibl::cube_env_distribution dist = ibl::make_cube_env_distribution<double>(sky, 32, 2);
        const d3 up(0.0, 1.0, 0.0);
        for (const double r : {0.3, 0.6}) {
            CAPTURE(r);
            m.roughness = r;
            const d3 v = view_at(up, 0.6, 0.4);
            const ibl::visibility_cone cone = ibl::make_bent_cone(up, v, 0.3, 0.9);
            ibl::radiance_reference_options b = opt;
            b.strategy = ibl::radiance_strategy::brdf;
            b.samples = 1u << 16;
            const ibl::occluded_specular_estimate e1 = ibl::occluded_reference_specular(sky, &dist, up, v, m, cone, opt);
            const ibl::occluded_specular_estimate e2 = ibl::occluded_reference_specular(sky, nullptr, up, v, m, cone, b);
            const double se = std::hypot(e1.std_error_occluded.x, e2.std_error_occluded.x);
            CHECK(std::fabs(e1.occluded.x - e2.occluded.x) <= k_sigma * se);
        }
    }
}

TEST_CASE("occlusion: the visible fraction of the lobe and its table") {
    SUBCASE("F0 = F90 = 1 under a constant environment: the ratio occluded / unoccluded") {
        const ibl::constant_environment<double> white{d3(1.0)};
        const d3 n(0.0, 0.0, 1.0);
        ibl::reference_material m;
        m.f0 = m.f90 = d3(1.0);
        ibl::radiance_reference_options opt;
        opt.samples = 1u << 15;
        for (const auto& c : {std::pair{0.5, 0.4}, std::pair{0.15, 0.8}, std::pair{1.0, 0.2}}) {
            const double mu = c.first, r = c.second;
            CAPTURE(mu);
            CAPTURE(r);
            m.roughness = r;
            const double to = ibl::cone_half_angle_for_ao(0.5);
            const ibl::occluded_specular_estimate e =
                ibl::occluded_reference_specular(white, nullptr, n, view_at(n, mu, 0.0), m, {n, to}, opt);
            const double s1 = ibl::specular_lobe_visible_fraction(mu, r, to, 256);
            const double s2 = ibl::specular_lobe_visible_fraction(mu, r, to, 512);
            // The occluded part's se bounds the ratio's (the unoccluded part is positively
            // correlated with it and at least as large).
            CHECK(std::fabs(e.occluded.x / e.unoccluded.x - s2) <=
                  k_sigma * e.std_error_occluded.x / e.unoccluded.x + std::fabs(s2 - s1));
        }
    }
    SUBCASE("table: ends, monotone in ao, texels against the quadrature") {
        const ibl::specular_occlusion_lut lut = ibl::make_specular_occlusion_lut(9, 128, ibl::serial_executor{});
        REQUIRE(lut.data.size() == 9u * 9u * 9u);
        for (std::uint32_t j = 0; j < 9; ++j)
            for (std::uint32_t i = 0; i < 9; ++i) {
                CHECK(lut.data[(0 * 9 + j) * 9 + i] == 0.0f);
                CHECK(lut.data[(8 * 9 + j) * 9 + i] == 1.0f);
                for (std::uint32_t k = 1; k < 9; ++k) CHECK(lut.data[(k * 9 + j) * 9 + i] >= lut.data[((k - 1) * 9 + j) * 9 + i]);
            }
        // Texel (n.v = 0.5, r = 0.5, ao = 0.5): the table's 128 nodes against 256 and 512.
        const double to = std::asin(std::sqrt(0.5));
        const double s1 = ibl::specular_lobe_visible_fraction(0.5, 0.5, to, 256);
        const double s2 = ibl::specular_lobe_visible_fraction(0.5, 0.5, to, 512);
        const double t = lut.data[(4 * 9 + 4) * 9 + 4];
        const double s0 = ibl::specular_lobe_visible_fraction(0.5, 0.5, to, 128);
        CHECK(std::fabs(t - s0) < 1e-6); // float rounding of the same quadrature
        CHECK(std::fabs(t - s2) <= std::fabs(s0 - s1) + std::fabs(s1 - s2));
        CHECK(ibl::specular_occlusion_lookup(lut, 0.5f, 0.5f, 0.5f) == doctest::Approx(t).epsilon(1e-6));
        // Between texels: the trilinear mix of the eight corners (here along ao only).
        const double mid = 0.5 * (lut.data[(4 * 9 + 4) * 9 + 4] + lut.data[(5 * 9 + 4) * 9 + 4]);
        CHECK(ibl::specular_occlusion_lookup(lut, 0.5, 0.5, 0.5625) == doctest::Approx(mid).epsilon(1e-6));
        CHECK(ibl::specular_occlusion_lookup(lut, 0.5, 0.5, 2.0) == 1.0);
        CHECK(ibl::specular_occlusion_table<double>(nullptr, 0, 0.5, 0.5, 0.5) == 1.0);
    }
    SUBCASE("limits: a mirror is a step at n.v = cos theta_o; a rough lobe tends to ~ao") {
        const double to = std::acos(0.5);
        CHECK(ibl::specular_lobe_visible_fraction(0.6, 0.0, to) == doctest::Approx(1.0).epsilon(1e-9));
        CHECK(ibl::specular_lobe_visible_fraction(0.4, 0.0, to) == doctest::Approx(0.0).epsilon(1e-9));
        const double s = ibl::specular_lobe_visible_fraction(1.0, 1.0, std::asin(std::sqrt(0.5)));
        CHECK(s > 0.4);
        CHECK(s < 0.75);
    }
}

TEST_CASE("specular occlusion: the bent reading is the table at (b.R, r, min(1, ao / b.n))") {
    const ibl::specular_occlusion_lut lut = ibl::make_specular_occlusion_lut(8, 32, ibl::serial_executor{});
    const ibl::vec3<float> n(0.0f, 0.0f, 1.0f), v = glm::normalize(ibl::vec3<float>(0.6f, 0.0f, 0.8f));
    const ibl::vec3<float> r_dir = 2.0f * glm::dot(n, v) * n - v;
    for (const float ao : {0.25f, 0.5f, 0.9f})
        for (const float rough : {0.2f, 0.6f}) {
            // b = n: the plain table at (n.v, r, ao)
            CHECK(ibl::specular_occlusion_bent(lut.data.data(), lut.size, n, v, n, rough, ao) ==
                  ibl::specular_occlusion_lookup(lut, glm::dot(n, v), rough, ao));
            // a bent normal tilted towards R
            const ibl::vec3<float> b = glm::normalize(ibl::vec3<float>(-0.3f, 0.0f, 1.0f));
            const float a = std::fmin(1.0f, ao / glm::dot(b, n));
            CHECK(ibl::specular_occlusion_bent(lut.data.data(), lut.size, n, v, b, rough, ao) ==
                  ibl::specular_occlusion_lookup(lut, ibl::saturate(glm::dot(b, r_dir)), rough, a));
            // a cone facing away from n: nothing is read as occluded
            CHECK(ibl::specular_occlusion_bent(lut.data.data(), lut.size, n, v, -n, rough, ao) ==
                  ibl::specular_occlusion_lookup(lut, 0.0f, rough, 1.0f));
        }
}
