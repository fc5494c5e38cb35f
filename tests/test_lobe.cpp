// tests/test_lobe.cpp — the lobe concept (sampling/lobe.hpp): the GGX lobe is the prefilter's
// unchanged default (bit for bit), and a researcher's Beckmann lobe runs through all three
// integrators without a copied loop: the DFG quadrature (as a brdf_model, white furnace against
// the reference integral), the prefilter (white furnace, closed-form LD of a polynomial
// environment) and reference_ld.
//
// Figures are printed when IBL_TEST_VERBOSE is set; the assertions do not depend on it.

#include <ibl/brdf/model.hpp>
#include <ibl/env/cubemap.hpp>
#include <ibl/bake/dfg.hpp>
#include <ibl/bake/prefilter.hpp>
#include <ibl/reference/radiance.hpp>
#include <ibl/reference/ld_irradiance.hpp>
#include <ibl/sampling/lobe.hpp>

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <iostream>

#include "support/ld_poly.hpp"
#include "support/stats.hpp"

namespace {

using dvec2 = ibl::vec2<double>;
using dvec3 = ibl::vec3<double>;
constexpr double kPi = 3.141592653589793238462643383279502884;

bool verbose() {
    static const bool v = std::getenv("IBL_TEST_VERBOSE") != nullptr;
    return v;
}
#define LOBE_REPORT(expr)                                                                                \
    do {                                                                                                 \
        if (verbose()) std::cout << expr << '\n';                                                       \
    } while (0)

/// Beckmann D(theta) = exp(-tan^2 / alpha^2) / (pi alpha^2 cos^4), alpha = r^2.
double beckmann_d(double cos_theta, double alpha) {
    const double c2 = cos_theta * cos_theta;
    const double t2 = (1 - c2) / c2;
    return cos_theta > 0 ? std::exp(-t2 / (alpha * alpha)) / (kPi * alpha * alpha * c2 * c2) : 0.0;
}

/// A researcher's lobe: Beckmann drawn exactly from D (n.h): tan^2 = -alpha^2 ln(1 - u).
struct beckmann_lobe {
    static double alpha(double r) { return std::max(r * r, 1e-4); }
    static dvec3 sample(const dvec2& u, double r) {
        const double a = alpha(r);
        const double t2 = -a * a * std::log1p(-u.x);
        const double c = 1 / std::sqrt(1 + t2), s = std::sqrt(t2) * c;
        return {s * std::cos(2 * kPi * u.y), s * std::sin(2 * kPi * u.y), c};
    }
    static double pdf(const dvec3& h, double r) { return beckmann_d(h.z, alpha(r)) * std::max(h.z, 0.0); }
    static double ld_weight(const dvec3&, double) { return 1.0; }
};

/// The same Beckmann kernel drawn from the GGX sampler: ld_weight = D_beckmann / D_ggx.
struct beckmann_via_ggx_lobe {
    static dvec3 sample(const dvec2& u, double r) { return ibl::sample_ggx_ndf(u, beckmann_lobe::alpha(r)); }
    static double pdf(const dvec3& h, double r) { return ibl::ggx_ndf_pdf(h, beckmann_lobe::alpha(r)); }
    static double ld_weight(const dvec3& h, double r) {
        const double a = beckmann_lobe::alpha(r);
        return beckmann_d(h.z, a) / ibl::ndf_ggx(h, a);
    }
};
static_assert(ibl::ld_lobe<beckmann_lobe> && ibl::ld_lobe<beckmann_via_ggx_lobe>);
static_assert(ibl::lobe_mirror_limit<beckmann_lobe>() && !ibl::lobe_mirror_limit<ibl::charlie_lobe>());

/// The Beckmann BRDF model of examples/dfg_custom_model.cpp (Walter's rational Smith G1).
struct beckmann_smith {
    template <class T> static T alpha(T roughness) { return ibl::alpha_from_roughness(roughness); }
    template <class T> static T tan2_over_alpha2(T n_dot_h, T alpha) {
        const T c = ibl::saturate(n_dot_h);
        const T a = ibl::clamp_alpha(alpha);
        return (T(1) - c) * (T(1) + c) / (c * c * a * a + ibl::min_normal_v<T>);
    }
    template <class T> static T ndf(T n_dot_h, T alpha) {
        const T a = ibl::clamp_alpha(alpha);
        const T c = ibl::saturate(n_dot_h);
        const T c2 = c * c;
        return n_dot_h > T(0) ? std::exp(-tan2_over_alpha2(n_dot_h, alpha)) / (ibl::pi_v<T> * a * a * c2 * c2) : T(0);
    }
    template <class T> static T g1_over_mu(T mu, T alpha) {
        const T m = ibl::saturate(mu);
        const T s = ibl::sin_from_cos(m);
        const T as = ibl::clamp_alpha(alpha) * s;
        const T a = m / (as + ibl::min_normal_v<T>);
        const T fit = (T(3.535) + T(2.181) * a) / (as * (T(1) + T(2.276) * a + T(2.577) * a * a) + ibl::min_normal_v<T>);
        return a < T(1.6) ? fit : T(1) / (m + ibl::min_normal_v<T>);
    }
    template <class T> static T visibility(T n_dot_v, T n_dot_l, T roughness) {
        const T a = alpha(roughness);
        return T(0.25) * g1_over_mu(n_dot_v, a) * g1_over_mu(n_dot_l, a);
    }
    template <class T> static T sample_weight(T n_dot_v, T n_dot_l, T n_dot_h, T v_dot_h, T roughness) {
        const T x = tan2_over_alpha2(n_dot_h, alpha(roughness));
        const T ratio = (T(1) + x) * (T(1) + x) * std::exp(-x);
        return ibl::weight_ggx_sampled(visibility(n_dot_v, n_dot_l, roughness), n_dot_l, n_dot_h, v_dot_h) * ratio;
    }
};
static_assert(ibl::brdf_model<beckmann_smith, double>);

ibl::cubemap<float> ones_cube(int n) {
    ibl::cubemap<float> c(n);
    c.fill(0, [](int, int, int) { return ibl::vec3<float>(1.0f); });
    c.generate_mips();
    return c;
}

bool bit_equal(const ibl::cubemap<float>& a, const ibl::cubemap<float>& b) {
    if (a.levels() != b.levels()) return false;
    for (int l = 0; l < a.levels(); ++l)
        for (int f = 0; f < 6; ++f)
            for (int y = 0; y < a.size(l); ++y)
                for (int x = 0; x < a.size(l); ++x)
                    if (std::memcmp(&a.texel(f, x, y, l), &b.texel(f, x, y, l), sizeof(ibl::vec3<float>)) != 0) return false;
    return true;
}

/// Checks prefilter<Lobe> on the polynomial environment against its closed-form LD per level.
template <class Lobe> void check_poly_chain(const char* name, const ibl::prefilter_options& o, double rough_of_level0) {
    const ibl_test::poly_env env;
    const ibl::cubemap<float> m = ibl::prefilter<Lobe>(env, o);
    for (int l = ibl::lobe_mirror_limit<Lobe>() ? 1 : 0; l < m.levels(); ++l) {
        const double r = l == 0 ? rough_of_level0 : o.policy.roughness(double(l), m.levels());
        const double a = beckmann_lobe::alpha(r);
        const dvec2 mom = ibl_test::kernel_moments_quadrature([&](double th) { return beckmann_d(std::cos(th), a); });
        const auto table = ibl::make_ld_table_for<float, Lobe>(env, r, ibl::prefilter_samples(o, l, m.levels()), o.method, o.lod_bias);
        const double bound = ibl_test::moment_bound(env, ibl_test::moments_of(table), mom);
        double worst = 0;
        const int n = m.size(l);
        for (int f = 0; f < 6; ++f)
            for (int y = 0; y < n; ++y)
                for (int x = 0; x < n; ++x) {
                    const dvec3 d = ibl::cube_texel_direction<double>(f, x, y, n);
                    worst = std::max(worst, std::fabs(double(m.texel(f, x, y, l).x) - env.ld(d, mom.x, mom.y)));
                }
        LOBE_REPORT(name << " level " << l << " (r = " << r << "): max |LD - closed form| = " << worst << ", moment bound "
                         << bound);
        // The estimate is the table's moments applied to the polynomial (see test_sheen.cpp).
        CHECK(worst <= bound + 16 * double(ibl::epsilon_v<float>));
    }
}

} // namespace

TEST_CASE("ggx_lobe is the bit-identical default of make_ld_table, prefilter and reference_ld") {
    // The table against the literature's loop written out (GGX NDF draws, n.l weights, D / 4).
    for (double r : {0.2, 0.7}) {
        auto lod = [](double omega) { return std::log2(omega); };
        const auto t = ibl::make_ld_table<float>(r, 256, lod);
        const auto g = ibl::make_ld_table<float, ibl::ggx_lobe>(r, 256, lod);
        ibl::sphere_sample_table<float> lit;
        const double alpha = r * r;
        for (std::uint32_t i = 0; i < 256; ++i) {
            const dvec3 h = ibl::sample_ggx_ndf(ibl::hammersley<double>(i, 256), alpha);
            const double nl = 2 * h.z * h.z - 1;
            if (!(nl > 0)) continue;
            lit.push(ibl::vec3<float>(dvec3(2 * h.z * h.x, 2 * h.z * h.y, nl)), float(nl),
                     float(lod(1.0 / (256.0 * 0.25 * ibl::ndf_ggx(h, alpha)))));
        }
        CHECK(t.weight == lit.weight);
        CHECK(t.lod == lit.lod);
        CHECK(t.x == lit.x);
        CHECK(t.z == lit.z);
        CHECK(g.weight == t.weight);
        CHECK(g.lod == t.lod);
    }
    ibl::cubemap<float> src(16);
    src.fill(0, [](int f, int x, int y) { return ibl::vec3<float>(float(f + 1), float(x) * 0.1f, float(y) * 0.05f); });
    src.generate_mips();
    ibl::prefilter_options o;
    o.levels = 4;
    o.samples = 64;
    CHECK(bit_equal(ibl::prefilter(src, o), ibl::prefilter<ibl::ggx_lobe>(src, o)));
    const ibl_test::poly_env env;
    const dvec3 R = glm::normalize(dvec3(0.2, 0.9, -0.3));
    const dvec3 a = ibl::reference_ld(env, R, 0.4, 1024), b = ibl::reference_ld<ibl::ggx_lobe>(env, R, 0.4, 1024);
    CHECK(std::memcmp(&a, &b, sizeof a) == 0);
}

TEST_CASE("Beckmann through DFG: white furnace of the quadrature against the reference integral") {
    // Constant environment L = 1, F0 = F90 = 1, no diffuse: the reference's specular part is the
    // directional albedo E = A + B that dfg_exact integrates (different method: MIS Monte Carlo of
    // the full integral with its own standard error). E <= 1: Smith masking conserves energy.
    const ibl::constant_environment<double> white{ibl::vec3<double>(1.0)};
    ibl::reference_material mat;
    mat.diffuse_albedo = dvec3(0.0);
    mat.f0 = dvec3(1.0);
    mat.f90 = dvec3(1.0);
    // E <= 1 holds for the exact separable Smith-Beckmann G = G1(v) G1(l); the model uses Walter's
    // rational fit of G1, so E <= q^2 with q the largest ratio fit / exact (Lambda of Walter 2007
    // eq. 25: (erf(a) - 1) / 2 + exp(-a^2) / (2 a sqrt(pi)), a = mu / (alpha sin)).
    double q = 1.0;
    for (int i = 1; i <= 4000; ++i) {
        const double a = 4.0 * i / 4000.0;
        const double lambda = 0.5 * (std::erf(a) - 1.0) + std::exp(-a * a) / (2.0 * a * std::sqrt(kPi));
        const double fit = a < 1.6 ? (3.535 * a + 2.181 * a * a) / (1 + 2.276 * a + 2.577 * a * a) : 1.0;
        q = std::max(q, fit * (1.0 + lambda));
    }
    LOBE_REPORT("largest G1 fit / exact: " << q);
    ibl::radiance_reference_options ro;
    ro.samples = 1u << 16;
    ro.strategy = ibl::radiance_strategy::brdf;
    for (double r : {0.2, 0.5, 0.9})
        for (double mu : {0.1, 0.5, 0.95}) {
            const dvec2 ab = ibl::dfg_exact<beckmann_smith>(mu, r);
            const double e = ab.x + ab.y;
            mat.roughness = r;
            const dvec3 v(std::sqrt(1 - mu * mu), 0, mu);
            const ibl::radiance_estimate ref = ibl::reference_radiance<beckmann_smith>(white, nullptr, dvec3(0, 0, 1), v, mat, ro);
            LOBE_REPORT("Beckmann E(" << mu << ", " << r << ") = " << e << ", reference " << ref.specular.x << " +- "
                                      << ref.std_error_specular.x);
            CHECK(e <= q * q + 1e-6); // quadrature converged to 1e-6 (dfg_exact)
            CHECK(std::fabs(e - ref.specular.x) <= 4 * ref.std_error_specular.x + 1e-6);
        }
}

TEST_CASE("Beckmann through the prefilter: white furnace and the closed-form LD per level") {
    const ibl::cubemap<float> ones = ones_cube(16);
    ibl::prefilter_options o;
    o.levels = 4;
    o.samples = 256;
    for (const ibl::cubemap<float>& m : {ibl::prefilter<beckmann_lobe>(ones, o), ibl::prefilter<beckmann_via_ggx_lobe>(ones, o)}) {
        double worst = 0;
        for (int l = 0; l < m.levels(); ++l)
            for (int f = 0; f < 6; ++f)
                for (int y = 0; y < m.size(l); ++y)
                    for (int x = 0; x < m.size(l); ++x) worst = std::max(worst, std::fabs(double(m.texel(f, x, y, l).x) - 1.0));
        LOBE_REPORT("Beckmann chain white furnace: max |LD - 1| = " << worst);
        CHECK(worst <= 4 * double(ibl::epsilon_v<float>));
    }
    ibl::prefilter_options p;
    p.levels = 4;
    p.base_size = 8;
    p.samples = 1024;
    check_poly_chain<beckmann_lobe>("Beckmann (exact draws)", p, 0.0);
    check_poly_chain<beckmann_via_ggx_lobe>("Beckmann (GGX draws, weighted)", p, 0.0);
}

TEST_CASE("Beckmann through reference_ld: converges to the closed-form LD") {
    const ibl_test::poly_env env;
    const dvec3 R = glm::normalize(dvec3(-0.4, 0.1, 0.9));
    for (double r : {0.3, 0.6, 1.0}) {
        const double a = beckmann_lobe::alpha(r);
        const dvec2 mom = ibl_test::kernel_moments_quadrature([&](double th) { return beckmann_d(std::cos(th), a); });
        const double ref = env.ld(R, mom.x, mom.y);
        const double e = ibl::reference_ld<beckmann_lobe>(env, R, r, 1u << 16).x;
        const double g = ibl::reference_ld<beckmann_via_ggx_lobe>(env, R, r, 1u << 16).x;
        LOBE_REPORT("reference_ld<beckmann> r = " << r << ": " << e - ref << " (GGX draws: " << g - ref << ")");
        CHECK(std::fabs(e - ref) <= 1e-3); // 2^16 Hammersley points on a smooth integrand
        CHECK(std::fabs(g - ref) <= 1e-3);
    }
}
