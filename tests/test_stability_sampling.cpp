// tests/test_stability_sampling.cpp — the stability contract for the sampling layer: at the
// extreme inputs (alpha = 0 and below float resolution, grazing and normal view, variates at the
// corners of [0, 1)^2, sample counts of 1 and 2^20) every output is finite, directions are unit
// vectors in the upper hemisphere, every pdf is finite and >= 0, inverses land in [0, 1)^2, and
// the documented limits hold.

#include <ibl/sampling.hpp>

#include <doctest/doctest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

namespace {

template <class T> bool finite(const ibl::vec2<T>& u) { return std::isfinite(u.x) && std::isfinite(u.y); }
template <class T> bool finite(const ibl::vec3<T>& w) {
    return std::isfinite(w.x) && std::isfinite(w.y) && std::isfinite(w.z);
}
template <class T> bool in_unit_square(const ibl::vec2<T>& u) {
    return u.x >= T(0) && u.x < T(1) && u.y >= T(0) && u.y < T(1);
}
template <class T> bool finite_density(T p) { return std::isfinite(p) && p >= T(0); }

/// |w|^2 = 1 within 4 eps: each sampler normalises with one sqrt and a handful of products.
template <class T> bool unit(const ibl::vec3<T>& w) {
    return std::fabs(glm::dot(w, w) - T(1)) <= 4 * ibl::epsilon_v<T>;
}

/// alpha = r^2 for the perceptual roughness sweep, plus the alphas of the GGX stability list.
constexpr std::array<double, 9> kAlphas = {0.0, 1e-14, 1e-8, 1e-4, 1e-7 * 1e-7, 1e-2 * 1e-2, 0.25, 0.5, 1.0};
constexpr std::array<double, 5> kViewCos = {0.0, 1e-7, 1e-3, 0.5, 1.0};
constexpr std::array<double, 2> kViewPhi = {0.0, 2.5};

/// The corners of [0, 1)^2, the midpoint and the edge midpoints.
template <class T> std::vector<ibl::vec2<T>> corner_variates() {
    const T hi = ibl::one_minus_epsilon_v<T>;
    return {{0, 0},      {0, hi},         {hi, 0},         {hi, hi},        {T(0.5), T(0.5)},
            {0, T(0.5)}, {T(0.5), 0},     {hi, T(0.5)},    {T(0.5), hi}};
}

/// View direction with n.v = c at azimuth phi, in T (built in double, then rounded).
template <class T> ibl::vec3<T> view(double c, double phi) {
    const double s = std::sqrt((1 - c) * (1 + c));
    return ibl::vec3<T>(T(s * std::cos(phi)), T(s * std::sin(phi)), T(c));
}

} // namespace

TEST_CASE_TEMPLATE("stability: sequences at sample counts 1 and 2^20 and the largest index", T, float, double) {
    CHECK(ibl::hammersley<T>(0, 1) == ibl::vec2<T>(0, 0));
    const std::uint32_t n = 1u << 20;
    const ibl::vec2<T> last = ibl::hammersley<T>(n - 1, n);
    CHECK(in_unit_square(last));
    CHECK(last.x == T(double(n - 1) / double(n))); // exact: 20 bits fit in float's 24
    CHECK(in_unit_square(ibl::hammersley<T>(0xFFFFFFFEu, 0xFFFFFFFFu)));
    CHECK(in_unit_square(ibl::hammersley_owen<T>(0xFFFFFFFEu, 0xFFFFFFFFu, 0xFFFFFFFFu)));
    CHECK(ibl::radical_inverse<T>(0xFFFFFFFFu) < T(1));
    CHECK(ibl::radical_inverse_xor<T>(0u, 0xFFFFFFFFu) < T(1));
    CHECK(ibl::radical_inverse_owen<T>(0xFFFFFFFFu, 0xFFFFFFFFu) < T(1));
}

TEST_CASE_TEMPLATE("stability: disk and hemisphere warps at the corners of the square", T, float, double) {
    for (const ibl::vec2<T>& u : corner_variates<T>()) {
        CAPTURE(u.x);
        CAPTURE(u.y);
        const ibl::vec2<T> d = ibl::sample_concentric_disk(u);
        CHECK(finite(d));
        CHECK(glm::dot(d, d) <= T(1) + 2 * ibl::epsilon_v<T>); // |d|^2 = r^2 (cos^2 + sin^2), r <= 1
        const ibl::vec2<T> du = ibl::invert_concentric_disk(d);
        CHECK(finite(du));
        CHECK((du.x >= T(0) && du.x <= T(1) && du.y >= T(0) && du.y <= T(1)));

        const ibl::vec3<T> wu = ibl::sample_uniform_hemisphere(u);
        CHECK(finite(wu));
        CHECK(unit(wu));
        CHECK(wu.z >= T(0));
        CHECK(in_unit_square(ibl::invert_uniform_hemisphere(wu)));

        const ibl::vec3<T> wc = ibl::sample_cosine_hemisphere(u);
        CHECK(finite(wc));
        CHECK(unit(wc));
        CHECK(wc.z >= T(0));
        CHECK(finite_density(ibl::cosine_hemisphere_pdf(wc.z)));
        const ibl::vec2<T> uc = ibl::invert_cosine_hemisphere(wc);
        CHECK(finite(uc));
        CHECK((uc.x >= T(0) && uc.x <= T(1) && uc.y >= T(0) && uc.y <= T(1)));
    }
    // The pole and the horizon as inputs of the inverses.
    CHECK(in_unit_square(ibl::invert_uniform_hemisphere(ibl::vec3<T>(0, 0, 1))));
    CHECK(in_unit_square(ibl::invert_uniform_hemisphere(ibl::vec3<T>(-1, 0, 0))));
    CHECK(ibl::invert_cosine_hemisphere(ibl::vec3<T>(0, 0, 1)) == ibl::vec2<T>(T(0.5), T(0.5)));
}

TEST_CASE_TEMPLATE("stability: GGX NDF sampling sweep", T, float, double) {
    int zero_density_samples = 0;
    for (double alpha_d : kAlphas) {
        const T alpha = T(alpha_d);
        CAPTURE(alpha);
        for (const ibl::vec2<T>& u : corner_variates<T>()) {
            CAPTURE(u.x);
            CAPTURE(u.y);
            const ibl::vec3<T> h = ibl::sample_ggx_ndf(u, alpha);
            REQUIRE(finite(h));
            CHECK(unit(h));
            CHECK(h.z > T(0));
            if (alpha == T(0)) CHECK(h == ibl::vec3<T>(0, 0, 1)); // the mirror limit, exactly
            if (u.x == T(0)) CHECK(h.z == T(1));                  // u.x = 0 is the normal
            const T pdf = ibl::ggx_ndf_pdf(h, alpha);
            CHECK(finite_density(pdf));
            zero_density_samples += pdf == T(0);
            const ibl::vec2<T> back = ibl::invert_ggx_ndf(h, alpha);
            CHECK(finite(back));
            CHECK(in_unit_square(back));
            for (double c : kViewCos)
                for (double phi : kViewPhi) {
                    const ibl::vec3<T> v = view<T>(c, phi);
                    CHECK(finite_density(ibl::ggx_ndf_reflected_pdf(v, h, alpha)));
                }
        }
        // The peak of the density is D(n) = 1 / (pi alpha^2) at the clamped alpha: finite.
        const T a = ibl::clamp_alpha(alpha);
        const T peak = ibl::ggx_ndf_pdf(ibl::vec3<T>(0, 0, 1), alpha);
        CHECK(std::isfinite(peak));
        // One product, one quotient and the rounded constant pi: 4 eps relative.
        CHECK(peak == doctest::Approx(ibl::inv_pi_v<T> / (a * a)).epsilon(4 * ibl::epsilon_v<T>));
    }
    CHECK(zero_density_samples == 0); // a drawn half vector always has a positive density
}

TEST_CASE_TEMPLATE("stability: GGX visible-normal sampling sweep", T, float, double) {
    int zero_density_samples = 0, total = 0;
    for (double alpha_d : kAlphas) {
        const T alpha = T(alpha_d);
        CAPTURE(alpha);
        for (double c : kViewCos)
            for (double phi : kViewPhi) {
                const ibl::vec3<T> v = view<T>(c, phi);
                CAPTURE(c);
                CAPTURE(phi);
                // G1(v) / n.v stays finite down to n.v = 0, where it is 2 / alpha (clamped alpha).
                const T g1_over = ibl::ggx_g1_over_n_dot_v(v.z, alpha);
                CHECK(std::isfinite(g1_over));
                CHECK(g1_over > T(0));
                for (const ibl::vec2<T>& u : corner_variates<T>()) {
                    CAPTURE(u.x);
                    CAPTURE(u.y);
                    const ibl::vec3<T> h = ibl::sample_ggx_vndf(v, u, alpha);
                    REQUIRE(finite(h));
                    CHECK(unit(h));
                    CHECK(h.z > T(0));
                    if (alpha == T(0)) CHECK(h == ibl::vec3<T>(0, 0, 1)); // the mirror limit, exactly
                    // u.y = 0 is the cap's pole: h_s is the half vector of v_s and n, = n at v = n.
                    if (c == 1.0 && u.y == T(0)) CHECK(h == ibl::vec3<T>(0, 0, 1));
                    // Visible: v.h >= 0 up to the rounding of h and of the dot product (the corner
                    // u = (1/2, 1 - eps/2) maps onto the support edge v.h = 0, see the header).
                    CHECK(glm::dot(v, h) >= -4 * ibl::epsilon_v<T>);
                    const T pdf = ibl::ggx_vndf_pdf(v, h, alpha);
                    CHECK(finite_density(pdf));
                    zero_density_samples += pdf == T(0);
                    ++total;
                    CHECK(finite_density(ibl::ggx_vndf_reflected_pdf(v, h, alpha)));
                    CHECK(finite_density(ibl::ggx_ndf_reflected_pdf(v, h, alpha)));
                    const ibl::vec2<T> back = ibl::invert_ggx_vndf(v, h, alpha);
                    CHECK(finite(back));
                    CHECK(in_unit_square(back));
                }
            }
        // Grazing view: G1(v)/n.v = 2 / alpha (clamped); a few roundings in the closed form.
        const T a = ibl::clamp_alpha(alpha);
        CHECK(ibl::ggx_g1_over_n_dot_v(T(0), alpha) == doctest::Approx(T(2) / a).epsilon(4 * ibl::epsilon_v<T>));
        // Normal view, h = n: the VNDF equals the NDF pdf, 1 / (pi alpha^2).
        CHECK(ibl::ggx_vndf_pdf(ibl::vec3<T>(0, 0, 1), ibl::vec3<T>(0, 0, 1), alpha) ==
              doctest::Approx(ibl::inv_pi_v<T> / (a * a)).epsilon(4 * ibl::epsilon_v<T>));
    }
    // Zero density only where it is the exact limit: alpha = 0 at grazing view (h = n, v.h = 0)
    // and the corner that maps onto the support edge. 2 x 9 of the former per type, at most 2 more.
    CHECK(zero_density_samples <= 2 * 9 + 2);
    CHECK(total == int(kAlphas.size() * kViewCos.size() * kViewPhi.size() * 9));
}

TEST_CASE_TEMPLATE("stability: out-of-range alpha and NaN are clamped, never NaN", T, float, double) {
    const T nan = std::numeric_limits<T>::quiet_NaN();
    const ibl::vec2<T> u(T(0.3), T(0.7));
    const ibl::vec3<T> v = view<T>(0.5, 1.0);
    // NaN and negative alpha are the mirror regime of the samplers (documented).
    CHECK(ibl::sample_ggx_ndf(u, nan) == ibl::vec3<T>(0, 0, 1));
    CHECK(ibl::sample_ggx_vndf(v, u, T(-1)) == ibl::vec3<T>(0, 0, 1));
    // alpha > 1 is clamped to 1.
    CHECK(ibl::sample_ggx_ndf(u, T(2)) == ibl::sample_ggx_ndf(u, T(1)));
    CHECK(ibl::sample_ggx_vndf(v, u, T(2)) == ibl::sample_ggx_vndf(v, u, T(1)));
    CHECK(finite_density(ibl::ggx_ndf_pdf(ibl::vec3<T>(0, 0, 1), nan)));
    CHECK(finite_density(ibl::ggx_vndf_pdf(v, ibl::vec3<T>(0, 0, 1), nan)));
    // View below the horizon is clamped to grazing.
    const ibl::vec3<T> below = view<T>(-0.5, 0.3);
    CHECK(finite(ibl::sample_ggx_vndf(below, u, T(0.5))));
    CHECK(finite_density(ibl::ggx_vndf_pdf(below, ibl::vec3<T>(0, 0, 1), T(0.5))));
}
