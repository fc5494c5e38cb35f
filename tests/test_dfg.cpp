// bake/dfg*, batch/dfg_kernel: split-sum DFG terms by quadrature and Monte Carlo, their
// limits, the batch kernels against the scalar paths, executor determinism, the multiple-scattering
// channel, the LUT exporter and the analytic fit. Heavy convergence figures live in
// bench/bench_dfg.cpp; here the checks are on subsets (every test runs in well under a second).
#include <doctest/doctest.h>

#include <ibl/batch.hpp>
#include <ibl/ibl.hpp>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

namespace {

/// A converged reference: the double-evaluated quadrature with 4x the default nodes per
/// dimension (its distance to 6x is 1e-10 over a 64^2 grid, bench/bench_dfg.cpp).
template <class M> ibl::vec3<double> dfg_reference(double mu, double r) {
    static const ibl::dfg_quadrature_rule rule({64, 64, 160, 64});
    return ibl::dfg_exact_abe<M>(mu, r, rule);
}

/// A user executor: one call per item, in reverse order (a partition no shipped executor makes).
struct reverse_single_executor {
    template <class F> void operator()(std::size_t count, F&& fn) const {
        for (std::size_t k = count; k-- > 0;) fn(k, k + 1);
    }
};

} // namespace

TEST_CASE_TEMPLATE("dfg: r = 0 gives the mirror limit (1 - (1 - mu)^5, (1 - mu)^5)", M, ibl::ggx_schlick_ibl,
                   ibl::ggx_height_correlated) {
    for (double mu : {1e-3, 0.05, 0.3, 0.7, 1.0}) {
        const ibl::vec2<double> lim = ibl::dfg_smooth_limit(mu);
        const ibl::vec2<double> q = ibl::dfg_exact<M>(mu, 0.0);
        // At r = 0 alpha is clamped to 2^-255 and the whole lobe is a mirror: only rounding remains.
        CHECK(std::fabs(q.x - lim.x) < 1e-9);
        CHECK(std::fabs(q.y - lim.y) < 1e-9);
        const ibl::vec2<float> mc = ibl::dfg_mc<M>(float(mu), 0.0f, 64u);
        // Float MC at r = 0: every sample is h = n with weight 1 - O(k/mu), k = 2^-32; 64 float
        // additions of values <= 1 round by at most 64 * 2^-24 = 4e-6.
        CHECK(std::fabs(mc.x - float(lim.x)) < 1e-5f);
        CHECK(std::fabs(mc.y - float(lim.y)) < 1e-5f);
    }
}

TEST_CASE_TEMPLATE("dfg: mu -> 0 stays finite and continuous", M, ibl::ggx_schlick_ibl, ibl::ggx_height_correlated) {
    for (double r : {0.0, 0.5 / 128, 0.1, 0.5, 1.0}) {
        const ibl::vec3<double> at0 = ibl::dfg_exact_abe<M>(0.0, r, ibl::default_dfg_quadrature_rule());
        CHECK(std::isfinite(at0.x));
        CHECK(std::isfinite(at0.y));
        CHECK(at0.x >= 0.0);
        CHECK(at0.y >= 0.0);
        CHECK(at0.z <= 1.0 + 1e-6); // energy conservation up to the quadrature's 1e-6
    }
    for (double r : {0.1, 0.5, 1.0}) {
        // (A, B) vary on the scale mu ~ alpha near mu = 0 (where masking sets in), so for
        // alpha >= 0.01 a step of 1e-9 moves them by O(1e-9 / alpha) << 1e-6.
        const ibl::vec3<double> at0 = ibl::dfg_exact_abe<M>(0.0, r, ibl::default_dfg_quadrature_rule());
        const ibl::vec3<double> near0 = ibl::dfg_exact_abe<M>(1e-9, r, ibl::default_dfg_quadrature_rule());
        CHECK(std::fabs(at0.x - near0.x) < 1e-6);
        CHECK(std::fabs(at0.y - near0.y) < 1e-6);
    }
    // The float MC path at exactly mu = 0 is finite too (V * n.l is formed first in the models).
    const ibl::vec2<float> mc = ibl::dfg_mc<M>(0.0f, 0.5f, 256u);
    CHECK(std::isfinite(mc.x));
    CHECK(std::isfinite(mc.y));
}

TEST_CASE_TEMPLATE("dfg: default quadrature is within 1e-6 of the converged reference", M, ibl::ggx_schlick_ibl,
                   ibl::ggx_height_correlated) {
    // Points include the worst texels of the 128^2 scan (first column, first rows) and corners.
    const double n = 128.0;
    for (double mu : {0.5 / n, 1.5 / n, 0.05, 0.3, 0.7, 127.5 / n})
        for (double r : {0.5 / n, 1.5 / n, 0.1, 0.3, 0.6, 127.5 / n}) {
            const ibl::vec2<double> q = ibl::dfg_exact<M>(mu, r);
            const ibl::vec3<double> ref = dfg_reference<M>(mu, r);
            CHECK(std::fabs(q.x - ref.x) <= 1e-6); // the dfg_exact contract
            CHECK(std::fabs(q.y - ref.y) <= 1e-6);
        }
}

TEST_CASE("dfg: float and double entry points agree (the exact path computes in double)") {
    const ibl::vec2<float> f = ibl::dfg_exact<ibl::ggx_height_correlated>(0.5f, 0.3f);
    const ibl::vec2<double> d = ibl::dfg_exact<ibl::ggx_height_correlated>(0.5, 0.3);
    CHECK(double(f.x) == doctest::Approx(d.x).epsilon(1e-7)); // one float rounding of the result
    CHECK(double(f.y) == doctest::Approx(d.y).epsilon(1e-7));
}

TEST_CASE_TEMPLATE("dfg: Monte Carlo at large sample counts agrees with quadrature within its error", M,
                   ibl::ggx_schlick_ibl, ibl::ggx_height_correlated) {
    // Error scale: the standard error sigma / sqrt(N) of plain Monte Carlo with the same weights
    // (sigma measured here); a Hammersley set does at least as well, so 4 standard errors bound it.
    const std::uint32_t n = 1u << 14;
    for (double mu : {0.5 / 128, 0.2, 0.6, 0.95})
        for (double r : {0.15, 0.4, 0.8}) {
            const ibl::vec3<double> ref = dfg_reference<M>(mu, r);
            const ibl::vec3<double> v(std::sqrt((1 - mu) * (1 + mu)), 0.0, mu);
            double s2a = 0.0, s2b = 0.0;
            for (std::uint32_t i = 0; i < n; ++i) {
                const ibl::vec3<double> h = ibl::sample_ggx_ndf(ibl::hammersley<double>(i, n), M::alpha(r));
                const double vh = glm::dot(v, h);
                const double w = M::sample_weight(mu, 2 * vh * h.z - mu, h.z, vh, r);
                const double fc = ibl::pow5(1 - ibl::saturate(vh));
                s2a += ibl::sqr(w * (1 - fc) - ref.x);
                s2b += ibl::sqr(w * fc - ref.y);
            }
            const double tol_a = 4 * std::sqrt(s2a / n / n), tol_b = 4 * std::sqrt(s2b / n / n);
            const ibl::vec2<double> mc = ibl::dfg_mc<M>(mu, r, n);
            CHECK(std::fabs(mc.x - ref.x) <= tol_a);
            CHECK(std::fabs(mc.y - ref.y) <= tol_b);
            const ibl::vec2<double> vn = ibl::dfg_mc_vndf<M>(mu, r, n);
            // VNDF weights have a smaller variance than NDF ones: the same bound holds a fortiori.
            CHECK(std::fabs(vn.x - ref.x) <= tol_a);
            CHECK(std::fabs(vn.y - ref.y) <= tol_b);
        }
}

TEST_CASE_TEMPLATE("dfg: batch kernels equal the scalar (width 1) kernels lane by lane", M, ibl::ggx_schlick_ibl,
                   ibl::ggx_height_correlated) {
    constexpr std::size_t W = 16;
    const float r = 0.37f;
    const ibl::dfg_sample_table<float> tab = ibl::make_dfg_sample_table(M::alpha(r), 256u);
    float mu[W], e[W], b[W];
    for (std::size_t l = 0; l < W; ++l) mu[l] = (float(l) + 0.5f) / float(W);
    ibl::dfg_mc_lanes<M, W>(tab.hx.data(), tab.hz.data(), 256u, r, mu, e, b);
    const ibl::dfg_quadrature_rule rule(ibl::dfg_lut_default_nodes);
    double mud[W], ed[W], bd[W];
    for (std::size_t l = 0; l < W; ++l) mud[l] = double(mu[l]);
    ibl::dfg_quadrature_lanes<M, W>(rule.view(), double(r), mud, ed, bd);
    for (std::size_t l = 0; l < W; ++l) {
        float e1, b1;
        ibl::dfg_mc_lanes<M, 1>(tab.hx.data(), tab.hz.data(), 256u, r, &mu[l], &e1, &b1);
        // The same arithmetic per lane; only a different contraction into FMAs by the vectoriser
        // could separate them: a few ulp of the sum, bounded by 4 eps.
        CHECK(std::fabs(e1 - e[l]) <= 4 * ibl::epsilon_v<float> * e1);
        CHECK(std::fabs(b1 - b[l]) <= 4 * ibl::epsilon_v<float> * e1);
        double e2, b2;
        ibl::dfg_quadrature_lanes<M, 1>(rule.view(), double(r), &mud[l], &e2, &b2);
        CHECK(std::fabs(e2 - ed[l]) <= 16 * ibl::epsilon_v<double>);
        CHECK(std::fabs(b2 - bd[l]) <= 16 * ibl::epsilon_v<double>);
        // And the literature's plain loop (separate float sums of (1 - Fc) w and Fc w): 256
        // additions of terms <= w_max ~ 1.3 round by at most 256 * 1.3 * 2^-24 = 2e-5 each.
        const ibl::vec2<float> loop = ibl::dfg_mc_scalar_loop<M>(mu[l], r, 256u);
        CHECK(std::fabs(loop.x - (e1 - b1)) < 4e-5f);
        CHECK(std::fabs(loop.y - b1) < 4e-5f);
    }
}

TEST_CASE("dfg: tables are bit-identical for every executor partition") {
    // 24 = 16 + 8 texels per row: the 16-lane kernel and the width-1 tail both run.
    const auto ref = ibl::make_dfg_lut_exact<ibl::ggx_height_correlated>(24, 3, ibl::dfg_lut_default_nodes,
                                                                         ibl::serial_executor{});
    const auto t2 = ibl::make_dfg_lut_exact<ibl::ggx_height_correlated>(24, 3, ibl::dfg_lut_default_nodes,
                                                                        ibl::thread_executor{2});
    const auto t5 = ibl::make_dfg_lut_exact<ibl::ggx_height_correlated>(24, 3, ibl::dfg_lut_default_nodes,
                                                                        ibl::thread_executor{5});
    const auto rv = ibl::make_dfg_lut_exact<ibl::ggx_height_correlated>(24, 3, ibl::dfg_lut_default_nodes,
                                                                        reverse_single_executor{});
    const std::size_t bytes = ref.data.size() * sizeof(float);
    CHECK(std::memcmp(ref.data.data(), t2.data.data(), bytes) == 0);
    CHECK(std::memcmp(ref.data.data(), t5.data.data(), bytes) == 0);
    CHECK(std::memcmp(ref.data.data(), rv.data.data(), bytes) == 0);
    const auto m1 = ibl::make_dfg_lut_mc<ibl::ggx_schlick_ibl>(20, 64, 2, ibl::serial_executor{});
    const auto m2 = ibl::make_dfg_lut_mc<ibl::ggx_schlick_ibl>(20, 64, 2, ibl::thread_executor{3});
    CHECK(std::memcmp(m1.data.data(), m2.data.data(), m1.data.size() * sizeof(float)) == 0);
}

TEST_CASE_TEMPLATE("dfg: the exact table is within 1e-5 of the reference (16^2 texels of a 128^2 table)", M,
                   ibl::ggx_schlick_ibl, ibl::ggx_height_correlated) {
    // The rows and columns of a 128^2 table, subsampled (first column and first row included),
    // through the same 16-lane float-evaluated kernel the table uses.
    const ibl::dfg_quadrature_rule rule(ibl::dfg_lut_default_nodes);
    constexpr std::size_t W = 16;
    double worst = 0.0;
    for (int j = 0; j < 128; j += 9) {
        const double r = (j + 0.5) / 128.0;
        double mu[W], e[W], b[W];
        for (std::size_t l = 0; l < W; ++l) mu[l] = (double(l) * 8.0 + 0.5) / 128.0;
        ibl::dfg_quadrature_lanes<M, W, float>(rule.view(), r, mu, e, b);
        for (std::size_t l = 0; l < W; ++l) {
            const ibl::vec3<double> ref = dfg_reference<M>(mu[l], r);
            worst = std::fmax(worst, std::fmax(std::fabs(e[l] - b[l] - ref.x), std::fabs(b[l] - ref.y)));
        }
    }
    CHECK(worst <= 1e-5); // the target for tables (full-table figure: bench, 4.8e-6)
}

TEST_CASE("dfg: multiple-scattering compensation gives a white furnace") {
    const auto lut = ibl::make_dfg_lut_exact<ibl::ggx_height_correlated>(32, 3);
    // At every texel: (A + B)(1 + k) = E (1 + (1 - E)/E) = 1; float storage of A, B, k rounds by
    // ~1e-7 relative, k <= 1.5: far inside the 1e-3 target.
    for (std::uint32_t j = 0; j < lut.size; ++j)
        for (std::uint32_t i = 0; i < lut.size; ++i) {
            const double e = double(lut.at(i, j, 0)) + double(lut.at(i, j, 1));
            CHECK(std::fabs(e * (1.0 + double(lut.at(i, j, 2))) - 1.0) < 1e-3);
        }
    // The shader formulas with F0 = F90 = 1 at off-grid points.
    for (double mu : {0.01, 0.3, 0.9})
        for (double r : {0.05, 0.5, 1.0}) {
            const ibl::vec3<double> abe = ibl::dfg_exact_abe<ibl::ggx_height_correlated>(mu, r, ibl::default_dfg_quadrature_rule());
            const ibl::vec3<double> abk(abe.x, abe.y, ibl::dfg_energy_compensation(abe.z));
            const ibl::vec3<double> one(1.0);
            CHECK(ibl::specular_dfg_turquin(abk, one).x == doctest::Approx(1.0).epsilon(1e-12)); // algebraic identity
            CHECK(ibl::specular_dfg_fdez_aguera(ibl::vec2<double>(abe.x, abe.y), one).y ==
                  doctest::Approx(1.0).epsilon(1e-12));
            // A dielectric gains energy but never beyond F0 = 1's white furnace.
            const double spec = ibl::specular_dfg_turquin(abk, ibl::vec3<double>(0.04)).x;
            CHECK(spec >= ibl::specular_dfg(ibl::vec2<double>(abe.x, abe.y), ibl::vec3<double>(0.04)).x);
            CHECK(spec <= 1.0);
        }
}

TEST_CASE_TEMPLATE("dfg: the albedo E(mu, r) decreases with roughness (away from grazing)", M, ibl::ggx_schlick_ibl,
                   ibl::ggx_height_correlated) {
    for (double mu : {0.2, 0.4, 0.8, 1.0}) {
        double prev = 2.0;
        for (int j = 0; j <= 32; ++j) {
            const double e = ibl::dfg_albedo<M>(mu, j / 32.0);
            CHECK(e <= prev + 1e-6); // monotone up to the quadrature's 1e-6
            prev = e;
        }
    }
    // At grazing view it is not: masking removes energy once alpha exceeds ~mu, and rougher
    // surfaces reflect grazing light back up (E(0, r) -> 1 - O(alpha) losses). On the 128^2 grid E
    // is monotone in r for mu >= 0.18 (Schlick k_IBL) / 0.12 (height-correlated) only.
    const double mu = 0.5 / 128;
    // Measured: a dip at r ~ 1/16 (alpha ~ mu), then a rise (E(mu, 1/16) = 0.63 / 0.89, E(mu, 1/4)
    // = 0.80 / 0.99 for Schlick / height-correlated), then the decline.
    CHECK(ibl::dfg_albedo<M>(mu, 0.0625) < ibl::dfg_albedo<M>(mu, 0.0));
    CHECK(ibl::dfg_albedo<M>(mu, 0.25) > ibl::dfg_albedo<M>(mu, 0.0625));
}

TEST_CASE("dfg: the C++ header exporter round-trips the table bit for bit") {
    const auto lut = ibl::make_dfg_lut_exact<ibl::ggx_schlick_ibl>(4, 3);
    const std::string h = ibl::dfg_lut_header(lut, "dfg_lut_4", "engine", "ggx_schlick_ibl, exact");
    CHECK(h.find("inline constexpr unsigned dfg_lut_4_size = 4;") != std::string::npos);
    CHECK(h.find("inline constexpr float dfg_lut_4[48] = {") != std::string::npos);
    // Parse the literals back: max_digits10 digits reproduce each float exactly.
    const std::size_t open = h.find('{', h.find("dfg_lut_4[48]"));
    const char* p = h.c_str() + open + 1;
    for (std::size_t k = 0; k < lut.data.size(); ++k) {
        char* end = nullptr;
        const float v = std::strtof(p, &end);
        REQUIRE(end != p);
        CHECK(v == lut.data[k]);
        p = end + 2; // skip "f,"
    }
}

TEST_CASE("dfg: bilinear lookup reproduces texel centres and the Karis fit's error is what we report") {
    const auto lut = ibl::make_dfg_lut_exact<ibl::ggx_schlick_ibl>(16, 2);
    const ibl::vec3<float> s = lut.sample(float(lut.n_dot_v(3)), float(lut.roughness(5)));
    CHECK(s.x == lut.at(3, 5, 0));
    CHECK(s.y == lut.at(3, 5, 1));
    // Karis' mobile fit against the exact Schlick-GGX table: largest error 0.28 over a 128^2 grid
    // (bench); on this 16^2 grid it stays below that bound.
    double worst = 0.0;
    for (std::uint32_t j = 0; j < 16; ++j)
        for (std::uint32_t i = 0; i < 16; ++i) {
            const ibl::vec2<double> f = ibl::dfg_karis_mobile(lut.n_dot_v(i), lut.roughness(j));
            worst = std::fmax(worst, std::fmax(std::fabs(f.x - lut.at(i, j, 0)), std::fabs(f.y - lut.at(i, j, 1))));
        }
    CHECK(worst < 0.3);
    CHECK(worst > 0.01); // a fit, not the table
}
