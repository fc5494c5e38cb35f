// tests/test_runtime.cpp — the runtime approximations (ibl/runtime/specular_models.hpp) and the lobe LUT
// (bake/lobe_moments.hpp): end values of the Frostbite helpers, the G2/G1 ratio against the
// model's V and G1, the footprint roughness against the kernel solid angle it inverts, runtime FIS
// weights against the DFG albedo, exactness of every normalised variant in a constant
// environment, the lobe moments against dfg_exact and (at n.v = 1) against the G1 LD kernel
// computed by an independent 1-D quadrature, and the G1-weighted prefilter table.

#include <doctest/doctest.h>

#include <ibl/brdf/model.hpp>
#include <ibl/bake/dfg.hpp>
#include <ibl/bake/lobe_moments.hpp>
#include "../research/lobe_moment_baseline.hpp" // make_lobe_lut: the moment-matched baseline
#include <ibl/bake/prefilter.hpp>
#include <ibl/runtime/specular_models.hpp>

#include <cmath>
#include <cstdint>
#include <limits>

namespace {

using d3 = ibl::vec3<double>;
using f3 = ibl::vec3<float>;
using model = ibl::ggx_height_correlated;
constexpr double feps = std::numeric_limits<float>::epsilon();

ibl::cubemap<float> constant_chain(float value, int size = 16, int levels = 5) {
    ibl::cubemap<float> c(size, levels);
    for (int l = 0; l < levels; ++l) c.fill(l, [&](int, int, int) { return f3(value); });
    c.update_borders();
    return c;
}

d3 view_at(const d3& n, double mu) {
    const ibl::frame<double> fr = ibl::make_frame(n);
    const double s = std::sqrt((1.0 - mu) * (1.0 + mu));
    return fr.to_world(d3(0.6 * s, 0.8 * s, mu));
}

} // namespace

TEST_CASE("runtime: Frostbite dominant direction, horizon fade and specular occlusion end values") {
    CHECK(ibl::dominant_lerp_frostbite(0.0) == 1.0);
    CHECK(ibl::dominant_lerp_frostbite(1.0) == 0.0);
    for (double r = 0.0; r <= 1.0; r += 0.125) {
        const double s = ibl::dominant_lerp_frostbite(r);
        CHECK(s >= 0.0);
        CHECK(s <= 1.0 + 1e-15);
    }
    const d3 n(0.0, 0.0, 1.0), rd = glm::normalize(d3(0.8, 0.0, 0.6));
    CHECK(glm::length(ibl::lerp_direction(n, rd, 0.0) - n) == doctest::Approx(0.0));
    CHECK(glm::length(ibl::lerp_direction(n, rd, 1.0) - rd) < 1e-15);
    CHECK(glm::length(ibl::lerp_direction(n, rd, 0.4)) == doctest::Approx(1.0).epsilon(1e-14));
    CHECK(ibl::horizon_fade(rd, n) == 1.0);
    CHECK(ibl::horizon_fade(-n, n) == 0.0);
    CHECK(ibl::horizon_fade(d3(1.0, 0.0, 0.0), n) == 1.0);
    // ao = 1: no occlusion; ao = 0 at grazing: fully occluded; bounded and monotone in ao.
    for (double r : {0.0, 0.3, 1.0})
        for (double mu : {0.0, 0.5, 1.0}) {
            CHECK(ibl::specular_occlusion_lagarde(mu, 1.0, r) == doctest::Approx(1.0));
            double prev = -1.0;
            for (double ao = 0.0; ao <= 1.0; ao += 0.25) {
                const double so = ibl::specular_occlusion_lagarde(mu, ao, r);
                CHECK(so >= prev);
                CHECK(so >= 0.0);
                CHECK(so <= 1.0);
                prev = so;
            }
        }
    CHECK(ibl::specular_occlusion_lagarde(0.0, 0.0, 0.5) == 0.0);
}

TEST_CASE("runtime: G2/G1 equals the model's 4 V n.v n.l / G1(v)") {
    for (double r : {0.05, 0.3, 0.7, 1.0})
        for (double mv : {0.01, 0.2, 0.7, 1.0})
            for (double ml : {0.01, 0.3, 0.9, 1.0}) {
                const double a = ibl::alpha_from_roughness(r);
                const double direct = 4.0 * model::visibility(mv, ml, r) * mv * ml / ibl::g1_smith_ggx(mv, a);
                CHECK(ibl::g2_over_g1_height_correlated(mv, ml, a) == doctest::Approx(direct).epsilon(1e-12));
            }
    CHECK(ibl::g2_over_g1_height_correlated(0.0, 0.5, 0.3) == doctest::Approx(1.0));
    CHECK(ibl::g2_over_g1_height_correlated(0.5, 0.0, 0.3) == 0.0);
}

TEST_CASE("runtime: the footprint roughness inverts the kernel solid angle pi alpha^2 4 / (1 + 3 alpha^2)") {
    for (double r : {0.05, 0.2, 0.5, 0.8, 1.0}) {
        const double a = r * r;
        const double omega = ibl::pi_v<double> * a * a * 4.0 / (1.0 + 3.0 * a * a);
        CHECK(ibl::fis_footprint_roughness(omega) == doctest::Approx(r).epsilon(1e-12));
    }
    CHECK(ibl::fis_footprint_roughness(0.0) == 0.0);
    CHECK(ibl::fis_footprint_roughness(std::nan("")) == 0.0);
    CHECK(ibl::fis_footprint_roughness(100.0) == 1.0);
    // The closed form follows the exact solid angle pi alpha^2 W(alpha), W = int D (n.l) dl
    // (4 ld_kernel-weighted mean of n.l), within the 10% stated in the header.
    for (double r : {0.1, 0.3, 0.5, 0.7, 0.9}) {
        const double a = r * r, a2 = a * a;
        double w = 0.0; // W = 4 int_0^1 max(n.l(u), 0) du over the NDF variable
        const int q = 20000;
        for (int i = 0; i < q; ++i) {
            const double u = (i + 0.5) / q, c2 = (1.0 - u) / (1.0 + (a2 - 1.0) * u), m = 2.0 * c2 - 1.0;
            if (m > 0.0) w += 4.0 * m / q;
        }
        const double ratio = w * (1.0 + 3.0 * a2) / 4.0;
        CHECK(ratio > 0.89);
        CHECK(ratio <= 1.0 + 1e-9);
    }
}

TEST_CASE("runtime: FIS weights average to the DFG albedo; normalised variants are exact in a constant environment") {
    const ibl::cubemap<float> chain = constant_chain(2.5f);
    const d3 n = glm::normalize(d3(0.3, -0.8, 0.5));
    const f3 f0(0.95f, 0.64f, 0.54f);
    for (double r : {0.2, 0.5, 0.9})
        for (double mu : {0.1, 0.5, 1.0}) {
            const d3 v = view_at(n, mu);
            const ibl::vec2<double> ab = ibl::dfg_exact<model>(mu, r);
            // Plain estimator with many taps of a constant: (A + B) L up to the QMC error of
            // 4096 points (the weight is bounded by 1 and smooth except at the horizon clip).
            ibl::runtime_fis_desc d;
            d.taps = 4096;
            d.normalise = false;
            const f3 plain = ibl::specular_fis(chain, d, f3(n), f3(v), float(r), f3(1.0f), f3(1.0f),
                                               ibl::vec2<float>(ab));
            CHECK(double(plain.x) == doctest::Approx(2.5 * (ab.x + ab.y)).epsilon(3e-3));
            for (std::uint32_t k : {1u, 4u, 16u}) {
                d.taps = k;
                d.normalise = true;
                const f3 x = ibl::specular_fis(chain, d, f3(n), f3(v), float(r), f0, f3(1.0f), ibl::vec2<float>(ab));
                const f3 want = 2.5f * ibl::split_sum_albedo(f0, f3(1.0f), ibl::vec2<float>(ab));
                for (int c = 0; c < 3; ++c) CHECK(double(x[c]) == doctest::Approx(double(want[c])).epsilon(8 * feps));
            }
        }
}

TEST_CASE("lobe LUT: moments against dfg_exact and, at n.v = 1, the G1 LD kernel") {
    for (double r : {0.2, 0.5, 0.8})
        for (double mu : {0.1, 0.5, 0.9}) {
            const ibl::lobe_moments m = ibl::specular_lobe_moments<model>(mu, r, 256);
            const ibl::vec2<double> ab = ibl::dfg_exact<model>(mu, r);
            CHECK(m.albedo == doctest::Approx(ab.x + ab.y).epsilon(2e-3));
            // The mean lies between n and R: 0 <= phi <= theta.
            CHECK(m.phi >= 0.0);
            CHECK(m.phi <= std::acos(mu) + 1e-9);
            CHECK(m.lerp >= 0.0);
            CHECK(m.lerp <= 1.0);
        }
    // At n.v = 1 the lobe D G2/(4 n.v n.l) n.l = D G1(l)/4 is the G1 LD kernel: matching its mean
    // resultant length (2-D VNDF quadrature) against the kernel's (1-D NDF quadrature) returns r.
    // 1 - rho is dominated by GGX's heavy tail near the horizon, where the midpoint rules are
    // coarsest: at 1024^2 nodes the match converged to 0.6% at r = 0.2 (0.1% at r >= 0.4).
    for (double r : {0.2, 0.4, 0.6, 0.8}) {
        const ibl::lobe_moments m = ibl::specular_lobe_moments<model>(1.0, r, 1024);
        CHECK(std::fabs(m.mean.x) < 1e-12);
        CHECK(ibl::ld_matched_roughness(m.rho, ibl::ld_weight::g1, 8192) == doctest::Approx(r).epsilon(r < 0.3 ? 8e-3 : 2e-3));
        // The n.l kernel is narrower than the lobe (n.l falls faster than G1): it needs a larger r.
        CHECK(ibl::ld_matched_roughness(m.rho, ibl::ld_weight::n_dot_l, 8192) > r);
    }
    double prev = 2.0;
    for (double r = 0.05; r <= 1.0; r += 0.05) {
        const double rho = ibl::ld_kernel_rho(r, ibl::ld_weight::g1);
        CHECK(rho < prev);
        prev = rho;
    }
}

TEST_CASE("lobe LUT: the one-tap lookup of a constant environment is the DFG albedo") {
    const ibl::dfg_lut_layout lay = ibl::dfg_lut_layout::remapped();
    const ibl::lobe_lut lut = ibl::make_lobe_lut<model>(8, lay, ibl::ld_weight::g1, 32, ibl::serial_executor{});
    REQUIRE(lut.data.size() == 8u * 8u * 4u);
    const ibl::cubemap<float> chain = constant_chain(1.5f);
    const d3 n = glm::normalize(d3(-0.2, 0.9, 0.3));
    for (double mu : {0.15, 0.5, 1.0})
        for (double r : {0.3, 0.7}) {
            const d3 v = view_at(n, mu);
            const f3 x = ibl::specular_lobe(chain, ibl::specular_lookup_desc::accurate(), lut, f3(n), f3(v), float(r),
                                            f3(1.0f), f3(1.0f));
            const ibl::vec4<float> p = ibl::lobe_lut_lookup(lut, float(mu), float(r));
            CHECK(double(x.x) == doctest::Approx(1.5 * double(p.x + p.y)).epsilon(8 * feps));
            CHECK(p.w >= 0.0f);
            CHECK(p.w <= 1.0f);
        }
    // Texel values: the mirror row holds s = 1, r_eff = 0.
    CHECK(lut.data[2] == 1.0f);
    CHECK(lut.data[3] == 0.0f);
}

TEST_CASE("prefilter: the G1 weight replaces n.l in the LD table and keeps a constant environment exact") {
    const auto lod0 = [](double) { return 0.0; };
    const ibl::sphere_sample_table<double> a = ibl::make_ld_table<double>(0.6, 64, lod0);
    const ibl::sphere_sample_table<double> b = ibl::make_ld_table<double>(0.6, 64, lod0, ibl::ld_weight::g1);
    REQUIRE(a.size() == b.size());
    const double alpha = ibl::alpha_from_roughness(0.6);
    for (std::size_t i = 0; i < a.size(); ++i) {
        CHECK(a.weight[i] == doctest::Approx(a.z[i]));
        CHECK(b.weight[i] == doctest::Approx(ibl::g1_smith_ggx(b.z[i], alpha)));
    }
    ibl::cubemap<float> src = constant_chain(3.0f, 16, 1);
    src.generate_mips();
    ibl::prefilter_options o;
    o.levels = 4;
    o.samples = 64;
    o.weight = ibl::ld_weight::g1;
    const ibl::cubemap<float> out = ibl::prefilter(src, o);
    for (int l = 0; l < out.levels(); ++l)
        CHECK(double(out.texel(2, 0, 0, l).y) == doctest::Approx(3.0).epsilon(16 * feps));
}

TEST_CASE("specular_chain: prefilter records its weight and mapping; lookups read the mapping and refuse a lobe table of another weight") {
    ibl::cubemap<float> src(16, 1);
    src.fill(0, [](int f, int x, int) { return f3(1.0f + float(f) + 0.1f * float(x)); });
    src.update_borders();
    src.generate_mips();
    ibl::prefilter_options o;
    o.samples = 32;
    o.policy = ibl::roughness_mip_policy::filament();
    const ibl::specular_chain chain = ibl::prefilter(src, o);
    CHECK(chain.weight == ibl::ld_weight::n_dot_l);
    CHECK(chain.mapping == ibl::roughness_mapping::filament);
    // The default description names the linear mapping; the chain's own (filament) is used, as a
    // plain cubemap read with the filament description gives.
    const ibl::cubemap<float>& plain = chain;
    const f3 dir = glm::normalize(f3(0.3f, 0.5f, -0.8f));
    for (float r : {0.1f, 0.35f, 0.6f, 0.9f}) {
        const f3 a = ibl::specular_lookup(chain, dir, r);
        const f3 b = ibl::specular_lookup(plain, dir, r, ibl::specular_lookup_desc::textbook(ibl::roughness_mapping::filament));
        const f3 c = ibl::specular_lookup(plain, dir, r); // the caller's (linear) description, as given
        CHECK(a == b);
        if (r == 0.35f) CHECK(a != c);
    }
    // A lobe table fitted to the G1 weight read over this n.l chain is refused, naming both.
    const ibl::lobe_lut g1 = ibl::make_lobe_lut<model>(4, ibl::dfg_lut_layout::uniform(), ibl::ld_weight::g1, 16);
    const f3 n(0.0f, 1.0f, 0.0f), v = glm::normalize(f3(0.0f, 1.0f, 0.5f));
    CHECK_THROWS_WITH_AS((void)ibl::specular_lobe(chain, {}, g1, n, v, 0.5f, f3(1.0f), f3(1.0f)),
                         "ibl::specular_lobe: the lobe table was fitted to the G1 chain weight, the chain is n.l-weighted",
                         std::invalid_argument);
    CHECK_NOTHROW((void)ibl::specular_lobe(plain, {}, g1, n, v, 0.5f, f3(1.0f), f3(1.0f))); // a plain cubemap: unknown
    const ibl::lobe_lut nl = ibl::make_lobe_lut<model>(4, ibl::dfg_lut_layout::uniform(), ibl::ld_weight::n_dot_l, 16);
    CHECK_NOTHROW((void)ibl::specular_lobe(chain, {}, nl, n, v, 0.5f, f3(1.0f), f3(1.0f)));
}
