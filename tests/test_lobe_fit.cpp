// tests/test_lobe_fit.cpp — the lobe fit (bake/lobe_fit.hpp) and the fitted-taps runtime
// (runtime.hpp): the chain kernel's normaliser and density against an independent quadrature in
// the polar angle, its mass below the horizon against a sphere quadrature, the L1 estimator over the lobe's draws against a direct quadrature of |p - q|
// over the whole sphere (p from the model's D and V, normalised by dfg_exact), the fit's exact
// answer at n.v = 1 for a G1 chain (the lobe is the kernel there), the fit against the moment match
// and against fewer taps at grazing views, the tables (A, B equal to the DFG table, weights
// summing to 1, the mirror row) and the white furnace of both runtime models; the two-part lobe
// model: its parts' weights and albedos, the B part's kernel against the whole lobe's and the
// split sum's, its tables, and its exact limits (white furnace for any F0, F90 = 0 equal to the
// one-kernel model, the mirror row equal to the split sum, the effective LD's split-sum form).
//
// Tolerances: a quadrature's own error is bounded by the change when its resolution doubles
// (smooth integrands, midpoint rules of order 2: the finer result's error is about a third of that
// change, so 1x the change is a safe bound); float storage and arithmetic by multiples of the
// float epsilon.

#include <doctest/doctest.h>

#include <ibl/brdf/model.hpp>
#include <ibl/env/cube_geometry.hpp>
#include <ibl/bake/dfg.hpp>
#include <ibl/bake/lobe_fit.hpp>
#include <ibl/runtime/specular_models.hpp>

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

namespace {

using d3 = ibl::vec3<double>;
using f3 = ibl::vec3<float>;
using model = ibl::ggx_height_correlated;
constexpr double feps = std::numeric_limits<float>::epsilon();
constexpr double pi = ibl::pi_v<double>;

/// W(r') = (pi / 2) int_0^{pi/2} D(cos(theta / 2)) w(cos theta) sin(theta) d theta, m midpoint nodes;
/// with density = true: int K(mu) dl over the sphere from ld_kernel_value (should be 1).
double polar_kernel_integral(double r, ibl::ld_weight w, int m, bool density) {
    const double alpha = ibl::clamp_alpha(ibl::alpha_from_roughness(r));
    const double norm = ibl::ld_kernel_normaliser(r, w, 4096);
    double s = 0.0;
    for (int i = 0; i < m; ++i) {
        const double t = (i + 0.5) * ibl::half_pi_v<double> / m, mu = std::cos(t);
        if (density) s += ibl::ld_kernel_value(mu, alpha, norm, w) * 2.0 * pi * std::sin(t);
        else s += 0.5 * pi * ibl::ndf_ggx(std::cos(0.5 * t), alpha) * (w == ibl::ld_weight::g1 ? ibl::g1_smith_ggx(mu, alpha) : mu) *
                  std::sin(t);
    }
    return s * ibl::half_pi_v<double> / m;
}

/// |p - q|_1 over the sphere by a midpoint rule of m x 2m nodes in (theta, phi) of l, tangent
/// frame of n, v = (sin theta_v, 0, mu).
double sphere_l1(double mu, double r, const ibl::lobe_mixture& mx, ibl::ld_weight w, int m) {
    const double alpha = ibl::clamp_alpha(ibl::alpha_from_roughness(r));
    const d3 v(std::sqrt((1.0 - mu) * (1.0 + mu)), 0.0, mu);
    const ibl::vec2<double> ab = ibl::dfg_exact<model>(mu, r);
    const double e = ab.x + ab.y;
    double norm[ibl::lobe_max_taps] = {}, ta[ibl::lobe_max_taps] = {};
    for (int k = 0; k < mx.count; ++k) {
        norm[k] = ibl::ld_kernel_normaliser(mx.taps[std::size_t(k)].roughness, w, 4096);
        ta[k] = ibl::clamp_alpha(ibl::alpha_from_roughness(mx.taps[std::size_t(k)].roughness));
    }
    double s = 0.0;
    for (int j = 0; j < m; ++j) {
        const double th = (j + 0.5) * pi / m;
        for (int i = 0; i < 2 * m; ++i) {
            const double ph = (i + 0.5) * pi / m;
            const d3 l(std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th));
            double p = 0.0;
            if (l.z > 0.0) {
                const d3 h = glm::normalize(v + l);
                p = ibl::ndf_ggx(h.z, alpha) * model::visibility(mu, l.z, r) * l.z / e;
            }
            double q = 0.0;
            for (int k = 0; k < mx.count; ++k) {
                const ibl::lobe_tap& t = mx.taps[std::size_t(k)];
                const d3 d(-std::sin(t.angle), 0.0, std::cos(t.angle));
                q += t.weight * ibl::ld_kernel_value(glm::dot(d, l), ta[k], norm[k], w);
            }
            s += std::fabs(p - q) * std::sin(th);
        }
    }
    return s * (pi / m) * (pi / m);
}

ibl::cubemap<float> constant_chain(float value, int size = 16, int levels = 5) {
    ibl::cubemap<float> c(size, levels);
    for (int l = 0; l < levels; ++l) c.fill(l, [&](int, int, int) { return f3(value); });
    c.update_borders();
    return c;
}

} // namespace

TEST_CASE("lobe fit: the chain kernel's normaliser and density against a polar-angle quadrature") {
    for (const ibl::ld_weight w : {ibl::ld_weight::n_dot_l, ibl::ld_weight::g1})
        for (const double r : {0.2, 0.5, 0.8, 1.0}) {
            const double q1 = polar_kernel_integral(r, w, 4096, false), q2 = polar_kernel_integral(r, w, 8192, false);
            const double n1 = ibl::ld_kernel_normaliser(r, w, 1024), n2 = ibl::ld_kernel_normaliser(r, w, 2048);
            CHECK(std::fabs(n2 - q2) <= std::fabs(q2 - q1) + std::fabs(n2 - n1) + 1e-12);
            CHECK(std::fabs(ibl::detail::ld_kernel_normaliser_tabulated(r, w) - n2) <= 1e-6 * n2);
            const double k1 = polar_kernel_integral(r, w, 4096, true), k2 = polar_kernel_integral(r, w, 8192, true);
            CHECK(std::fabs(k2 - 1.0) <= std::fabs(k2 - k1) + 1e-6); // 1e-6: the 4096-node normaliser
        }
}

TEST_CASE("lobe fit: the L1 estimator over the lobe's draws equals a direct quadrature over the sphere") {
    for (const double mu : {0.2, 0.6})
        for (const double r : {0.5, 0.8}) {
            ibl::lobe_mixture mx;
            mx.count = 2;
            mx.taps[0] = {0.3, 0.6 * r, 0.6};
            mx.taps[1] = {0.9, 0.5 * r, 0.4};
            const ibl::detail::lobe_points p64 = ibl::detail::make_lobe_points<model>(mu, r, 64);
            const ibl::detail::lobe_points p128 = ibl::detail::make_lobe_points<model>(mu, r, 128);
            const double e64 = ibl::detail::mixture_l1(p64, mx.taps, 2, ibl::ld_weight::g1, {});
            const double e128 = ibl::detail::mixture_l1(p128, mx.taps, 2, ibl::ld_weight::g1, {});
            const double s1 = sphere_l1(mu, r, mx, ibl::ld_weight::g1, 256), s2 = sphere_l1(mu, r, mx, ibl::ld_weight::g1, 512);
            INFO("mu " << mu << " r " << r << " estimate " << e128 << " sphere " << s2);
            CHECK(std::fabs(e128 - s2) <= std::fabs(e128 - e64) + std::fabs(s2 - s1) + 1e-3);
        }
}

TEST_CASE("lobe fit: at n.v = 1 a G1 chain's kernel is the lobe, found exactly") {
    for (const double r : {0.3, 0.6, 0.9}) {
        ibl::lobe_fit_options o;
        o.nodes = 32;
        const ibl::lobe_mixture m = ibl::fit_specular_lobe<model>(1.0, r, ibl::ld_weight::g1, o);
        INFO("r " << r << " angle " << m.taps[0].angle << " r' " << m.taps[0].roughness << " L1 " << m.l1);
        CHECK(m.count == 1);
        CHECK(std::fabs(m.taps[0].angle) < 0.02);
        CHECK(std::fabs(m.taps[0].roughness - r) < 0.01);
        CHECK(m.l1 < 0.01);
        CHECK(m.taps[0].weight == 1.0);
    }
}

TEST_CASE("lobe fit: at grazing views the fit beats the moment match and more taps do not lose") {
    for (const double mu : {0.15, 0.5})
        for (const double r : {0.3, 0.65}) {
            double prev = 2.0;
            for (int k = 1; k <= 3; ++k) {
                ibl::lobe_fit_options o;
                o.taps = k;
                const ibl::lobe_mixture m = ibl::fit_specular_lobe<model>(mu, r, ibl::ld_weight::g1, o);
                INFO("mu " << mu << " r " << r << " taps " << k << " L1 " << m.l1 << " moments " << m.l1_moments);
                CHECK(m.l1 < m.l1_moments);
                CHECK(m.l1 <= prev + 0.01);
                double ws = 0.0;
                for (int t = 0; t < k; ++t) {
                    ws += m.taps[std::size_t(t)].weight;
                    if (t > 0) CHECK(m.taps[std::size_t(t)].angle >= m.taps[std::size_t(t - 1)].angle);
                }
                CHECK(ws == doctest::Approx(1.0).epsilon(1e-12));
                prev = m.l1;
            }
        }
}

TEST_CASE("lobe fit: tables hold the DFG terms, normalised taps and the mirror row") {
    const ibl::dfg_lut_layout lay = ibl::dfg_lut_layout::remapped();
    ibl::lobe_fit_options o;
    o.taps = 2;
    const ibl::lobe_taps_lut t = ibl::make_lobe_taps_lut<model>(6, lay, ibl::ld_weight::g1, o, ibl::serial_executor{});
    REQUIRE(t.channels == 8u);
    const ibl::dfg_lut ab = ibl::make_dfg_lut_exact<model>(6, lay, 2);
    for (std::uint32_t j = 0; j < 6; ++j)
        for (std::uint32_t i = 0; i < 6; ++i) {
            const float* p = &t.data[(j * 6 + i) * t.channels];
            CHECK(p[0] == ab.data[(j * 6 + i) * 2]);
            CHECK(p[1] == ab.data[(j * 6 + i) * 2 + 1]);
            CHECK(double(p[4] + p[7]) == doctest::Approx(1.0).epsilon(4 * feps));
            const double view = std::acos(ibl::dfg_texel_value<double>(lay.n_dot_v, i, 6, lay.edge_aligned));
            CHECK(std::fabs(double(p[2])) * view <= ibl::half_pi_v<double> + 1e-6); // within the horizon
            CHECK(std::fabs(double(p[5])) * view <= ibl::half_pi_v<double> + 1e-6);
        }
    CHECK(t.data[3 * t.channels + 2] == 1.0f); // the mirror row: one tap at R
    CHECK(t.data[3 * t.channels + 3] == 0.0f);
    CHECK(t.mean_l1 > 0.0);
    CHECK(t.max_l1 >= t.mean_l1);

    const ibl::lobe_lut l = ibl::make_lobe_lut_fitted<model>(6, lay, ibl::ld_weight::g1, {}, ibl::serial_executor{});
    for (std::uint32_t j = 1; j < 6; ++j) {
        const double r = ibl::dfg_texel_value<double>(lay.roughness, j, 6, lay.edge_aligned);
        const float* p = &l.data[(j * 6 + 5) * 4]; // the n.v = 1 column: r_eff = r
        CHECK(p[2] >= 0.0f);
        CHECK(p[2] <= 1.0f);
        if (r >= 0.2) CHECK(std::fabs(double(p[3]) - r) < 0.01);
    }
}

TEST_CASE("lobe fit: both fitted runtime models are exact in a constant environment (white furnace)") {
    const ibl::dfg_lut_layout lay = ibl::dfg_lut_layout::remapped();
    ibl::lobe_fit_options o;
    o.taps = 3;
    const ibl::lobe_taps_lut t = ibl::make_lobe_taps_lut<model>(8, lay, ibl::ld_weight::g1, o, ibl::serial_executor{});
    const ibl::lobe_lut l = ibl::make_lobe_lut_fitted<model>(8, lay, ibl::ld_weight::g1, {}, ibl::serial_executor{});
    const ibl::cubemap<float> chain = constant_chain(1.5f);
    const d3 n = glm::normalize(d3(-0.2, 0.9, 0.3));
    const ibl::frame<double> fr = ibl::make_frame(n);
    for (const double mu : {0.15, 0.5, 1.0})
        for (const double r : {0.3, 0.7}) {
            const double s = std::sqrt((1.0 - mu) * (1.0 + mu));
            const d3 v = fr.to_world(d3(0.6 * s, 0.8 * s, mu));
            const f3 a = ibl::specular_lobe_taps(chain, ibl::specular_lookup_desc::accurate(), t, f3(n), f3(v), float(r), f3(1.0f), f3(1.0f));
            const f3 b = ibl::specular_lobe(chain, ibl::specular_lookup_desc::accurate(), l, f3(n), f3(v), float(r), f3(1.0f), f3(1.0f));
            const ibl::vec4<float> ab = ibl::lobe_lut_lookup(l, float(mu), float(r));
            CHECK(double(a.x) == doctest::Approx(1.5 * double(ab.x + ab.y)).epsilon(16 * feps));
            CHECK(double(b.x) == doctest::Approx(1.5 * double(ab.x + ab.y)).epsilon(16 * feps));
        }
}

TEST_CASE("lobe fit: a kernel's mass below the horizon against a direct sphere quadrature") {
    for (const double a : {0.0, 0.8, 1.3, 1.5})
        for (const double r : {0.3, 0.7}) {
            const double alpha = ibl::clamp_alpha(ibl::alpha_from_roughness(r));
            const double norm = ibl::ld_kernel_normaliser(r, ibl::ld_weight::g1, 4096);
            const d3 d(-std::sin(a), 0.0, std::cos(a));
            auto below = [&](int m) {
                double s = 0.0;
                for (int j = 0; j < m; ++j) {
                    const double th = ibl::half_pi_v<double> + (j + 0.5) * ibl::half_pi_v<double> / m; // l.z < 0
                    for (int i = 0; i < 4 * m; ++i) {
                        const double ph = (i + 0.5) * 2.0 * pi / (4 * m);
                        const d3 l(std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th));
                        s += ibl::ld_kernel_value(glm::dot(d, l), alpha, norm, ibl::ld_weight::g1) * std::sin(th);
                    }
                }
                return s * (ibl::half_pi_v<double> / m) * (2.0 * pi / (4 * m));
            };
            const double q1 = below(256), q2 = below(512);
            // The azimuthal fraction has square-root kinks where the cone of beta touches the
            // horizon: the node rule converges non-monotonically, so its error bound is the spread
            // of three resolutions.
            const double e = ibl::detail::ld_kernel_mass_below(a, r, ibl::ld_weight::g1, 8192);
            const double spread = std::max(std::fabs(e - ibl::detail::ld_kernel_mass_below(a, r, ibl::ld_weight::g1, 4096)),
                                           std::fabs(e - ibl::detail::ld_kernel_mass_below(a, r, ibl::ld_weight::g1, 2048)));
            INFO("angle " << a << " r " << r << " quadrature " << q2 << " mass_below " << e);
            CHECK(std::fabs(e - q2) <= std::fabs(q2 - q1) + spread + 1e-7);
        }
}

// ---- the two-part lobe model (make_lobe_pair_lut, specular_lobe_pair) ----------------------------

/// A chain whose radiance varies with direction (every level the same function, so that a lookup
/// at any roughness reads it at its direction): L = 1 + 0.5 x + 0.25 y^2 per channel scale.
ibl::cubemap<float> varying_chain(int size = 16, int levels = 5) {
    ibl::cubemap<float> c(size, levels);
    for (int l = 0; l < levels; ++l) {
        const int s = c.size(l);
        c.fill(l, [&](int f, int x, int y) {
            const f3 d = ibl::cube_texel_direction<float>(f, x, y, s);
            return f3(1.0f + 0.5f * d.x + 0.25f * d.y * d.y);
        });
    }
    c.update_borders();
    return c;
}

TEST_CASE("two-part lobe: the parts' Schlick weights sum to 1 and their albedos are the DFG terms") {
    for (const double vh : {0.0, 0.3, 0.9, 1.0})
        CHECK(ibl::lobe_fresnel_part_weight(ibl::lobe_fresnel_part::a, vh) + ibl::lobe_fresnel_part_weight(ibl::lobe_fresnel_part::b, vh) ==
              doctest::Approx(1.0).epsilon(1e-15));
    for (const double mu : {0.2, 0.7})
        for (const double r : {0.3, 0.8}) {
            const ibl::vec2<double> ab = ibl::dfg_exact<model>(mu, r);
            double e[2] = {0.0, 0.0}, e2[2] = {0.0, 0.0};
            for (int part = 0; part < 2; ++part)
                for (const std::uint32_t q : {128u, 256u}) {
                    const ibl::detail::lobe_points p = ibl::detail::make_lobe_points<model>(
                        mu, r, q, part == 0 ? ibl::lobe_fresnel_part::a : ibl::lobe_fresnel_part::b);
                    (q == 128u ? e : e2)[part] = p.weight_sum / (double(q) * double(q));
                }
            INFO("mu " << mu << " r " << r << " A " << ab.x << " " << e2[0] << " B " << ab.y << " " << e2[1]);
            CHECK(std::fabs(e2[0] - ab.x) <= std::fabs(e2[0] - e[0]) + 1e-4);
            CHECK(std::fabs(e2[1] - ab.y) <= std::fabs(e2[1] - e[1]) + 1e-4);
        }
}

TEST_CASE("two-part lobe: the B part's own kernel is closer to it than the whole lobe's kernel and the split sum's (R, r)") {
    for (const double mu : {0.15, 0.5, 0.9})
        for (const double r : {0.3, 0.5, 0.7}) {
            ibl::lobe_fit_options ob;
            ob.part = ibl::lobe_fresnel_part::b;
            const ibl::lobe_mixture fb = ibl::fit_specular_lobe<model>(mu, r, ibl::ld_weight::g1, ob);
            const ibl::lobe_mixture fw = ibl::fit_specular_lobe<model>(mu, r, ibl::ld_weight::g1);
            const ibl::detail::lobe_points pb = ibl::detail::make_lobe_points<model>(mu, r, 32, ibl::lobe_fresnel_part::b);
            std::array<ibl::lobe_tap, ibl::lobe_max_taps> split{};
            split[0] = {std::acos(mu), r, 1.0};
            const double l1_b = ibl::detail::mixture_l1(pb, fb.taps, 1, ibl::ld_weight::g1, {});
            const double l1_w = ibl::detail::mixture_l1(pb, fw.taps, 1, ibl::ld_weight::g1, {});
            const double l1_s = ibl::detail::mixture_l1(pb, split, 1, ibl::ld_weight::g1, {});
            INFO("mu " << mu << " r " << r << " B fit " << l1_b << " whole kernel " << l1_w << " (R, r) " << l1_s);
            CHECK(l1_b < l1_w);
            CHECK(l1_b < l1_s);
            CHECK(fb.taps[0].angle >= 0.0);
            CHECK(fb.taps[0].angle <= ibl::half_pi_v<double>);
        }
}

TEST_CASE("two-part lobe: the table's A part is the one-kernel table; the B table's mirror row sits at R") {
    const ibl::dfg_lut_layout lay = ibl::dfg_lut_layout::remapped();
    const ibl::lobe_pair_lut p = ibl::make_lobe_pair_lut<model>(6, lay, ibl::ld_weight::g1, {}, ibl::serial_executor{});
    const ibl::lobe_lut l = ibl::make_lobe_lut_fitted<model>(6, lay, ibl::ld_weight::g1, {}, ibl::serial_executor{});
    REQUIRE(p.a.data.size() == l.data.size());
    REQUIRE(p.b.data.size() == l.data.size());
    for (std::size_t k = 0; k < l.data.size(); ++k) CHECK(p.a.data[k] == l.data[k]);
    CHECK(p.b.size == 6u);
    CHECK(p.b.layout == lay);
    for (std::uint32_t i = 0; i < 6; ++i) { // row r = 0: at R (1), roughness 0
        CHECK(p.b.data[i * 4] == 1.0f);
        CHECK(p.b.data[i * 4 + 1] == 0.0f);
    }
    for (std::size_t k = 0; k < 36; ++k) {
        CHECK(p.b.data[k * 4 + 1] >= 0.0f);
        CHECK(p.b.data[k * 4 + 1] <= 1.0f);
        CHECK(p.b.data[k * 4 + 2] == 0.0f);
        CHECK(p.b.data[k * 4 + 3] == 0.0f);
    }
}

TEST_CASE("two-part lobe: white furnace, F90 = 0 is the one-kernel model, the mirror is the split sum") {
    const ibl::dfg_lut_layout lay = ibl::dfg_lut_layout::remapped();
    const ibl::lobe_pair_lut p = ibl::make_lobe_pair_lut<model>(8, lay, ibl::ld_weight::g1, {}, ibl::serial_executor{});
    const ibl::cubemap<float> flat = constant_chain(1.5f), chain = varying_chain();
    const ibl::specular_lookup_desc sd = ibl::specular_lookup_desc::accurate();
    const d3 n = glm::normalize(d3(-0.2, 0.9, 0.3));
    const ibl::frame<double> fr = ibl::make_frame(n);
    const f3 dielectric(0.04f), metal(0.95f, 0.64f, 0.54f);
    for (const double mu : {0.15, 0.5, 1.0})
        for (const double r : {0.0, 0.3, 0.7}) {
            const double s = std::sqrt((1.0 - mu) * (1.0 + mu));
            const f3 v(fr.to_world(d3(0.6 * s, 0.8 * s, mu)));
            const ibl::vec4<float> ab = ibl::lobe_lut_lookup(p.a, float(mu), float(r));
            for (const f3& f0 : {dielectric, metal}) {
                INFO("mu " << mu << " r " << r << " f0 " << f0.y);
                // a constant environment: exactly (F0 A + F90 B) L
                const f3 w = ibl::specular_lobe_pair(flat, sd, p.a, p.b, f3(n), v, float(r), f0, f3(1.0f));
                for (int c = 0; c < 3; ++c)
                    CHECK(double(w[c]) == doctest::Approx(1.5 * double(f0[c] * ab.x + ab.y)).epsilon(16 * feps));
                // F90 = 0: only the A part, read by the one-kernel table's kernel
                const f3 a2 = ibl::specular_lobe_pair(chain, sd, p.a, p.b, f3(n), v, float(r), f0, f3(0.0f));
                const f3 a1 = ibl::specular_lobe(chain, sd, p.a, f3(n), v, float(r), f0, f3(0.0f));
                for (int c = 0; c < 3; ++c) CHECK(double(a2[c]) == doctest::Approx(double(a1[c])).epsilon(4 * feps));
                // the effective LD in the split sum's form gives the same specular
                const f3 nf(n);
                const f3 r_dir = 2.0f * glm::dot(nf, v) * nf - v;
                const ibl::vec4<float> pb = ibl::lobe_lut_lookup(p.b, float(mu), float(r));
                const f3 ld_a = ibl::specular_lookup(chain, ibl::lerp_direction(nf, r_dir, ab.z), ab.w, sd);
                const f3 ld_b = ibl::specular_lookup(chain, ibl::lobe_pair_direction_b(nf, r_dir, pb.x, float(mu)), pb.y, sd);
                const f3 ld = ibl::lobe_pair_ld(ld_a, ld_b, f0, f3(1.0f), ibl::vec2<float>(ab.x, ab.y));
                const f3 full = ibl::specular_lobe_pair(chain, sd, p.a, p.b, nf, v, float(r), f0, f3(1.0f));
                for (int c = 0; c < 3; ++c)
                    CHECK(double(ld[c] * (f0[c] * ab.x + ab.y)) == doctest::Approx(double(full[c])).epsilon(16 * feps));
                if (r == 0.0) { // the mirror row: both kernels at R with roughness 0, the split sum
                    const f3 split = ibl::specular_lookup(chain, r_dir, 0.0f, sd) * (f0 * ab.x + f3(ab.y));
                    for (int c = 0; c < 3; ++c) CHECK(double(full[c]) == doctest::Approx(double(split[c])).epsilon(16 * feps));
                }
            }
        }
}
