#pragma once
// ibl/sampling/lobe.hpp — the *lobe* concept that the prefilter (bake/prefilter.hpp) and the
// LD reference (reference/ld_irradiance.hpp) are templated on, and the two lobes the library ships:
// GGX (the default everywhere) and Charlie (sheen).
//
// A lobe is the half-vector distribution of a split-sum LD term. With N = V = R the LD kernel is
//     LD(R) = integral L(l) D(h) max(n.l, 0) dl / integral D(h) max(n.l, 0) dl,
//     l = 2 (n.h) h - n,  n.l = 2 (n.h)^2 - 1 = cos(2 theta_h)  (> 0 iff theta_h < pi/4),
// D the lobe's NDF. A lobe is a type with static member functions on double (tables are built in
// double), r the perceptual roughness in [0, 1], h a unit half vector in tangent space (z = R):
//
//   L::sample(vec2<double> u, double r) -> vec3<double>
//       A half vector for u in [0, 1)^2, with h.z > 0.
//   L::pdf(vec3<double> h, double r) -> double
//       The density of sample() per unit solid angle of h (0 where it never draws).
//   L::ld_weight(vec3<double> h, double r) -> double
//       D(h) (n.h) / pdf(h, r) times any factor that depends on r only (the estimator is normalised,
//       so such a factor cancels): 1 for a lobe drawn exactly from D (n.h) (also when the draws
//       are restricted to theta_h < pi/4, whose normalisation is a constant). A lobe drawn from
//       another proposal (a GGX sampler for a Beckmann D) returns D / D_proposal.
//   The estimator is then sum_i L(l_i) w_i / sum_i w_i, w_i = (n.l_i) ld_weight(h_i, r) over the
//   draws with n.l_i > 0, and filtered importance sampling reads the source at the solid angle
//   1 / (N pdf_l) with pdf_l = pdf(h) / (4 n.h), the density of l (v.h = n.h when V = N).
//
// Optional members (detected):
//   L::ld_pdf(vec3<double> h, double r) -> double   pdf_l in a form of the lobe's own (GGX: D / 4,
//       without the division by n.h); otherwise pdf / (4 n.h) is used.
//   static constexpr bool mirror_limit             true (the default when absent) when r = 0 is
//       the mirror (LD = L(R)): the prefilter's level 0 is then a copy of the source. false for a
//       lobe whose r -> 0 limit is not a delta at h = n (Charlie: a ring at the horizon of R);
//       level 0 is then convolved like every other level.
//   static constexpr const char* name               for reports.
//
// Writing a lobe: copy ggx_lobe, change sample / pdf (and ld_weight if the draws are not from
// D (n.h)), and static_assert(ibl::ld_lobe<my_lobe>). tests/test_lobe.cpp runs a Beckmann lobe
// through prefilter, reference_ld and (as a brdf_model) the DFG quadrature.

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include <cmath>
#include <concepts>

#include "../brdf/charlie.hpp"
#include "../brdf/ggx.hpp"
#include "../core/constants.hpp"
#include "../core/math.hpp"
#include "../core/vec.hpp"
#include "charlie.hpp"
#include "ggx.hpp"
#include "hemisphere.hpp"

namespace ibl {

/// The lobe concept (see the contract above).
template <class L>
concept ld_lobe = requires(vec2<double> u, vec3<double> h, double r) {
    { L::sample(u, r) } -> std::same_as<vec3<double>>;
    { L::pdf(h, r) } -> std::same_as<double>;
    { L::ld_weight(h, r) } -> std::same_as<double>;
};

/// pdf_l of a lobe's draw h with N = V: L::ld_pdf if present, else pdf / (4 n.h) (0 for n.h <= 0).
template <class L>
    requires ld_lobe<L>
IBL_FUNC double lobe_ld_pdf(const vec3<double>& h, double roughness) noexcept {
    if constexpr (requires { { L::ld_pdf(h, roughness) } -> std::same_as<double>; }) {
        return L::ld_pdf(h, roughness);
    } else {
        return h.z > 0.0 ? L::pdf(h, roughness) / (4.0 * h.z) : 0.0;
    }
}

/// Whether r = 0 is the mirror for lobe L (its mirror_limit member, true when absent).
template <class L> constexpr bool lobe_mirror_limit() noexcept {
    if constexpr (requires { { L::mirror_limit } -> std::convertible_to<bool>; }) {
        return bool(L::mirror_limit);
    } else {
        return true;
    }
}

/// GGX: h from sample_ggx_ndf with alpha = r^2 (pdf D (n.h), so ld_weight = 1 and pdf_l = D / 4).
struct ggx_lobe {
    static constexpr const char* name = "ggx";
    static constexpr bool mirror_limit = true;

    IBL_FUNC static vec3<double> sample(const vec2<double>& u, double roughness) noexcept {
        return sample_ggx_ndf(u, alpha_from_roughness(roughness));
    }
    IBL_FUNC static double pdf(const vec3<double>& h, double roughness) noexcept {
        return ggx_ndf_pdf(h, alpha_from_roughness(roughness));
    }
    IBL_FUNC static double ld_weight(const vec3<double>&, double) noexcept { return 1.0; }
    /// D(h) / 4: the density of l = reflect(-n, h) per unit solid angle of l.
    IBL_FUNC static double ld_pdf(const vec3<double>& h, double roughness) noexcept {
        return 0.25 * ndf_ggx(h, alpha_from_roughness(roughness));
    }
};

/// The clamped-cosine lobe about N (= R in the prefilter's frame): the diffuse kernel, so that the
/// lobe-generic prefilter is also an irradiance integrator (bake/irradiance.hpp
/// irradiance_cubemap_lobe: E = pi x the lobe's normalised mean). l is drawn with density
/// cos(theta_l) / pi (sample_cosine_hemisphere), h = normalize(l + n); ld_weight cancels the
/// estimator's n.l factor (weight 1 per draw); roughness is unused. A user-defined diffuse lobe
/// (a wrapped cosine, a rough diffuse model's kernel) follows the same pattern.
struct cosine_lobe {
    static constexpr const char* name = "cosine";
    static constexpr bool mirror_limit = false;

    IBL_FUNC static vec3<double> sample(const vec2<double>& u, double) noexcept {
        const vec3<double> l = sample_cosine_hemisphere(u);
        const vec3<double> h(l.x, l.y, l.z + 1.0);
        const double len = std::sqrt(h.x * h.x + h.y * h.y + h.z * h.z);
        return h / len;
    }
    /// Density of h: pdf_l |dl/dh| = (n.l / pi) 4 (n.h) with n.l = 2 (n.h)^2 - 1.
    IBL_FUNC static double pdf(const vec3<double>& h, double roughness) noexcept { return 4.0 * h.z * ld_pdf(h, roughness); }
    IBL_FUNC static double ld_pdf(const vec3<double>& h, double) noexcept {
        const double n_dot_l = 2.0 * h.z * h.z - 1.0;
        return n_dot_l > 0.0 ? n_dot_l * inv_pi_v<double> : 0.0;
    }
    /// 1 / (n.l): every draw of the (already cosine-distributed) set weighs the same.
    IBL_FUNC static double ld_weight(const vec3<double>& h, double) noexcept {
        const double n_dot_l = 2.0 * h.z * h.z - 1.0;
        return n_dot_l > 0.0 ? 1.0 / n_dot_l : 0.0;
    }
};

namespace detail {
/// The Charlie LD kernel's radial variable: z >= 0 with CDF
///   G(z) = int_0^z e^-t (1 - e^(-a t)) dt / M,  M = a / (1 + a),
/// i.e. G = -expm1(-z) + e^-z expm1(-a z) / a, and 1 - G = e^-z (1 + (1 - e^(-a z)) / a) (the form
/// used for u >= 1/2: no cancellation near 1). Solved for G(z) = u by Newton's method safeguarded
/// by bisection on a bracket (G is increasing; G' = e^-z (1 - e^(-a z)) (1 + a) / a); converges to
/// double rounding within a few tens of steps.
IBL_FUNC double charlie_ld_radial(double u, double a) noexcept {
    using std::exp;
    using std::expm1;
    using std::fabs;
    using std::log1p;
    if (!(u > 0.0)) return 0.0;
    const bool upper = u >= 0.5;
    const double target = upper ? 1.0 - u : u; // exact for u >= 1/2
    auto f = [&](double z) { // G(z) - u, or (1 - G(z)) - (1 - u), decreasing in z
        const double e = exp(-z);
        const double em = -expm1(-a * z); // 1 - e^(-a z)
        return upper ? e * (1.0 + em / a) - target : (-expm1(-z) - e * em / a) - target;
    };
    auto df = [&](double z) { return exp(-z) * (-expm1(-a * z)) * ((1.0 + a) / a); }; // G'
    double lo = 0.0, hi = 800.0; // G(800) = 1 in double
    double z = 1.0 - log1p(-u);   // the a -> 0 (Gamma(2)) scale
    if (!(z < hi)) z = 0.5 * hi;
    for (int it = 0; it < 200; ++it) {
        const double v = f(z);
        const bool below = upper ? v > 0.0 : v < 0.0; // z below the root
        (below ? lo : hi) = z;
        const double d = df(z);
        double zn = d > 0.0 ? z + (upper ? v : -v) / d : 0.5 * (lo + hi);
        if (!(zn > lo && zn < hi)) zn = 0.5 * (lo + hi);
        if (fabs(zn - z) <= 1e-15 * z || hi - lo <= 1e-15 * hi) return zn;
        z = zn;
    }
    return z;
}
} // namespace detail

/// Charlie (sheen): l drawn with density exactly proportional to the LD kernel D_charlie(h) (n.l)
/// (N = V = R), so that every draw has the same weight. With s = sin(theta_h), k = 2 + 1/alpha,
/// F = 2^(-k/2) (the mass of D (n.h) below theta_h = pi/4), the restricted CDF variable
/// u' = (sqrt(2) s)^k and z = -ln(u'): D (n.h) d(omega_h) = F e^-z dz dphi / (2 pi) and
///   n.l = cos(2 theta_h) = 1 - 2 s^2 = 1 - e^(-a z),  a = 2 / k,
/// so the kernel is proportional to e^-z (1 - e^(-a z)) dz dphi: z from the CDF G of
/// detail::charlie_ld_radial (Newton), then 2 s^2 = e^(-a z). Densities:
///   pdf_l = D(h) (n.l) / W,  W = integral D (n.l) dl = 4 F a / (1 + a),
///   D / (4 F) = (k / (4 pi)) (2 s^2)^(1/(2 alpha)),   pdf_h = 4 (n.h) pdf_l,
///   ld_weight = D (n.h) / pdf_h = W / (4 n.l): returned as 1 / n.l (with n.l = 2 h.z^2 - 1, the
///   table's own expression, so the table weights n.l ld_weight are 1 to rounding).
/// Sampling D (n.h) instead (weights n.l) fails for small alpha: the weights span n.l ~ 2 alpha
/// to n.l = 1 (u' = 1 is the normal) and a quasi-random point set with u.x = 0 gives one draw the
/// weight of thousands. As r -> 0 the kernel tends to the ring theta_l = pi/2 about R (not a
/// mirror: mirror_limit = false).
/// alpha is clamped to min_alpha = 2^-16 (r >= 2^-8): the table forms n.l = 2 h.z^2 - 1 from the
/// half vector, with an absolute error ~3e-16 in double, while the draws have n.l ~ 2 alpha z; at
/// 2^-16 that leaves a relative error <= 1e-6 for all but the draws within 1e-5 of the horizon.
/// The kernel at min_alpha differs from the r = 0 ring by E[n.l] = 2a / (1 + 2a) ~ 6e-5.
struct charlie_lobe {
    static constexpr const char* name = "charlie";
    static constexpr bool mirror_limit = false;
    static constexpr double min_alpha = 0x1p-16;

    /// The lobe's alpha: r^2 clamped to [min_alpha, 1].
    IBL_FUNC static double alpha(double roughness) noexcept { return clamp(alpha_from_roughness(roughness), min_alpha, 1.0); }

    IBL_FUNC static vec3<double> sample(const vec2<double>& u, double roughness) noexcept {
        using std::exp;
        using std::expm1;
        const double a = 2.0 / charlie_exponent(alpha(roughness));
        const double z = detail::charlie_ld_radial(u.x, a);
        const double n_dot_l = -expm1(-a * z);          // 1 - 2 s^2, in [0, 1)
        const double sin_theta = safe_sqrt(0.5 * exp(-a * z));
        const double cos_theta = safe_sqrt(0.5 * (1.0 + n_dot_l)); // cos^2 = 1 - s^2
        return detail::spherical_direction(sin_theta, cos_theta, two_pi_v<double> * u.y);
    }
    IBL_FUNC static double pdf(const vec3<double>& h, double roughness) noexcept {
        return h.z > 0.0 ? 4.0 * h.z * ld_pdf(h, roughness) : 0.0;
    }
    /// 1 / n.l (see above); 0 below the horizon.
    IBL_FUNC static double ld_weight(const vec3<double>& h, double) noexcept {
        const double n_dot_l = 2.0 * h.z * h.z - 1.0;
        return n_dot_l > 0.0 ? 1.0 / n_dot_l : 0.0;
    }
    /// D (n.l) / W = (k / (4 pi)) (2 s^2)^(1/(2 alpha)) (n.l) (1 + a) / a for theta_h < pi/4, 0 beyond.
    IBL_FUNC static double ld_pdf(const vec3<double>& h, double roughness) noexcept {
        using std::exp;
        using std::log;
        using std::log1p;
        const double al = alpha(roughness);
        const double k = charlie_exponent(al), a = 2.0 / k;
        const double t2 = h.x * h.x + h.y * h.y;
        const double n_dot_l = h.z * h.z - t2; // cos(2 theta_h)
        if (!(n_dot_l > 0.0) || !(h.z > 0.0)) return 0.0;
        const double log_2s2 = n_dot_l < 0.5 ? log1p(-n_dot_l) : log(2.0 * t2);
        return k * inv_four_pi_v<double> * exp(log_2s2 * (0.5 / al)) * n_dot_l * ((1.0 + a) / a);
    }
};

static_assert(ld_lobe<ggx_lobe> && ld_lobe<charlie_lobe>);

} // namespace ibl

#endif // IBL_DETAIL_CXX20
