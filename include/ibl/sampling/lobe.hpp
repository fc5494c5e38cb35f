#pragma once
// ibl/sampling/lobe.hpp — the *lobe* concept that the prefilter (integrate/prefilter.hpp) and the
// LD reference (integrate/reference.hpp) are templated on, and the two lobes the library ships:
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

/// Charlie (sheen): h from D_charlie (n.h) restricted to theta_h < pi/4, the half vectors whose
/// l is above the horizon. With s = sin(theta_h), k = 2 + 1/alpha, the restricted CDF is
/// (sqrt(2) s)^k, so sqrt(2) s = u^(1/k):
///   s^2 = u^(2/k) / 2,  n.l = cos(2 theta_h) = 1 - u^(2/k) = -expm1(2 log(u) / k),
///   pdf_h = D (n.h) / F,  F = 2^(-k/2) (the untruncated mass below pi/4),
///   pdf_l = pdf_h / (4 n.h) = (k / (4 pi)) (2 s^2)^(1/(2 alpha)) = (k / (4 pi)) u^(1/(1 + 2 alpha)).
/// No draw is wasted: the untruncated sampler puts all but 2^(-k/2) of its draws below the horizon
/// (all but 2^-51 at alpha = 0.01). ld_weight = F is a constant and returns 1. As r -> 0 the lobe
/// tends to the ring theta_l = pi/2 about R (not a mirror: mirror_limit = false).
struct charlie_lobe {
    static constexpr const char* name = "charlie";
    static constexpr bool mirror_limit = false;

    IBL_FUNC static vec3<double> sample(const vec2<double>& u, double roughness) noexcept {
        using std::exp;
        using std::expm1;
        using std::log;
        const double inv_k = 1.0 / charlie_exponent(alpha_from_roughness(roughness));
        const double lu = log(u.x);
        const double s2 = 0.5 * exp(2.0 * lu * inv_k); // <= 1/2
        const double n_dot_l = -expm1(2.0 * lu * inv_k);  // = 1 - 2 s^2, in (0, 1]
        const double sin_theta = safe_sqrt(s2);
        const double cos_theta = safe_sqrt(0.5 * (1.0 + n_dot_l)); // cos^2 = 1 - s^2
        return detail::spherical_direction(sin_theta, cos_theta, two_pi_v<double> * u.y);
    }
    IBL_FUNC static double pdf(const vec3<double>& h, double roughness) noexcept {
        return h.z > 0.0 ? 4.0 * h.z * ld_pdf(h, roughness) : 0.0;
    }
    IBL_FUNC static double ld_weight(const vec3<double>&, double) noexcept { return 1.0; }
    /// (k / (4 pi)) (2 s^2)^(1/(2 alpha)) for theta_h < pi/4, 0 beyond.
    IBL_FUNC static double ld_pdf(const vec3<double>& h, double roughness) noexcept {
        using std::exp;
        using std::log;
        using std::log1p;
        const double a = charlie_clamp_alpha(alpha_from_roughness(roughness));
        const double t2 = h.x * h.x + h.y * h.y;
        const double n_dot_l = h.z * h.z - t2; // cos(2 theta_h)
        if (!(n_dot_l > 0.0) || !(h.z > 0.0)) return 0.0;
        const double log_2s2 = n_dot_l < 0.5 ? log1p(-n_dot_l) : log(2.0 * t2);
        return (2.0 + 1.0 / a) * inv_four_pi_v<double> * exp(log_2s2 * (0.5 / a));
    }
};

static_assert(ld_lobe<ggx_lobe> && ld_lobe<charlie_lobe>);

} // namespace ibl

#endif // IBL_DETAIL_CXX20
