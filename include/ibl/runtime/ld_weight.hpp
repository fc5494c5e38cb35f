#pragma once
// ibl/runtime/ld_weight.hpp — the per-sample weight of the prefiltered LD integral
// (bake/prefilter.hpp, "LD weight"), shared by the prefilter and its references:
//     LD(R) = integral L(l) D(h) k(R.l) dl / integral D(h) k(R.l) dl,   h = normalize(R + l)
// with k(mu) = mu (ld_weight::n_dot_l, Karis 2013) or k(mu) = G1(mu) (ld_weight::g1, the GGX
// Smith masking of l: the true specular lobe at n.v = 1). ld_weight_factor(w, mu, alpha) is k.

#include "../core/config.hpp" // first: a pre-C++20 build stops there with one #error
#if IBL_DETAIL_CXX20

#include "../brdf/ggx.hpp"

namespace ibl {

/// The per-sample weight of the LD integral (bake/prefilter.hpp, "LD weight").
enum class ld_weight : int {
    n_dot_l = 0, ///< Karis 2013: D(h) n.l
    g1 = 1,      ///< D(h) G1(n.l): the specular lobe at n.v = 1
};

/// k(mu) of the header for mu = R.l (clamped to [0, 1]) and GGX alpha: mu or G1(mu).
inline double ld_weight_factor(ld_weight w, double mu, double alpha) noexcept {
    const double m = saturate(mu);
    return w == ld_weight::g1 ? g1_smith_ggx(m, alpha) : m;
}

} // namespace ibl

#endif // IBL_DETAIL_CXX20
