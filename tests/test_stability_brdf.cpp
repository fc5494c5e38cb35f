// tests/test_stability_brdf.cpp — the stability contract of the BRDF layer: every function finite on
// the sweep r in {0, 1e-7, 1e-4, 1e-2, 0.5, 1} x n.v, n.l in {0, 1e-7, 1e-3, 0.5, 1}, the limits that
// exist are met exactly, and inputs outside the domain are clamped as documented.
//
// Geometry for the sample weights: v = (sin_v, 0, n.v) and l = (+-sin_l, 0, n.l) (the same azimuth,
// and the opposite one — the plane of mirror reflection), h = normalize(v + l), n.h = h.z, v.h = v.h;
// where v + l = 0 (n.v = n.l = 0, opposite azimuths) h = n, the limit along n.v = n.l -> 0.

#include <doctest/doctest.h>

#include <ibl/brdf.hpp>

#include <cmath>
#include <initializer_list>
#include <limits>

namespace {

template <class T> constexpr T sweep_roughness[] = {T(0), T(1e-7), T(1e-4), T(1e-2), T(0.5), T(1)};
template <class T> constexpr T sweep_cosine[] = {T(0), T(1e-7), T(1e-3), T(0.5), T(1)};

template <class T> bool finite(T x) { return std::isfinite(x); }
template <class T> bool finite(const ibl::vec3<T>& x) { return finite(x.x) && finite(x.y) && finite(x.z); }

template <class T> struct half_vector_geometry {
    T n_dot_h, v_dot_h;
};
template <class T> half_vector_geometry<T> geometry(T n_dot_v, T n_dot_l, bool opposite_azimuth) {
    const ibl::vec3<T> v(ibl::sin_from_cos(n_dot_v), T(0), n_dot_v);
    const ibl::vec3<T> l((opposite_azimuth ? T(-1) : T(1)) * ibl::sin_from_cos(n_dot_l), T(0), n_dot_l);
    const ibl::vec3<T> sum = v + l;
    const T len = glm::length(sum);
    const ibl::vec3<T> h = len > T(0) ? sum / len : ibl::vec3<T>(T(0), T(0), T(1));
    return {h.z, glm::dot(v, h)};
}

template <class M, class T> void check_model(T n_dot_v, T n_dot_l, T r) {
    const T vis = M::visibility(n_dot_v, n_dot_l, r);
    CHECK(finite(vis));
    CHECK(vis > T(0));
    CHECK(vis * n_dot_l * n_dot_v * T(4) <= T(1) + T(8) * ibl::epsilon_v<T>); // = G <= 1 (8 roundings)
    if (n_dot_l == T(0)) CHECK(vis * n_dot_l == T(0));
    CHECK(finite(M::ndf(T(1), M::alpha(r))));
    for (const bool opposite : {false, true}) {
        CAPTURE(opposite);
        const half_vector_geometry<T> g = geometry(n_dot_v, n_dot_l, opposite);
        const T w = M::sample_weight(n_dot_v, n_dot_l, g.n_dot_h, g.v_dot_h, r);
        CHECK(finite(w));
        CHECK(w >= T(0));
        if (n_dot_l == T(0)) CHECK(w == T(0));
    }
}

} // namespace

TEST_CASE_TEMPLATE("BRDF stability sweep: finite everywhere, exact limits", T, float, double) {
    using v3 = ibl::vec3<T>;
    const v3 f0(T(0.04), T(0.5), T(1));
    for (const T r : sweep_roughness<T>) {
        CAPTURE(r);
        const T alpha = ibl::alpha_from_roughness(r);
        const T k_i = ibl::k_ibl(r), k_d = ibl::k_direct(r);
        CHECK((k_i >= T(0) && k_i <= T(0.5)));
        CHECK((k_d >= T(0.125) && k_d <= T(0.5)));
        // Limits that hold for every roughness, bit for bit.
        for (const T k : {k_i, k_d}) {
            CHECK(ibl::g_smith_schlick_ggx(T(1), T(1), k) == T(1));
            CHECK(ibl::g1_schlick_ggx(T(0), k) == T(0));
            CHECK(ibl::v_smith_schlick_ggx(T(1), T(1), k) == T(0.25));
        }
        CHECK(ibl::g1_smith_ggx(T(0), alpha) == T(0));
        CHECK(ibl::g1_smith_ggx(T(1), alpha) == T(1));
        CHECK(ibl::g2_smith_ggx_correlated(T(1), T(1), alpha) == T(1));
        CHECK(ibl::v_smith_ggx_correlated(T(1), T(1), alpha) == T(0.25));
        // The corner convention: V(0, 0) = 0.5 / min_normal (documented), finite.
        CHECK(ibl::v_smith_ggx_correlated(T(0), T(0), alpha) == T(0.5) / ibl::min_normal_v<T>);
        CHECK(ibl::fresnel_schlick_roughness(T(1), f0, r) == f0);
        // The NDFs at the sweep's half-vector cosines (and the vector forms at the same angles).
        for (const T c : sweep_cosine<T>) {
            CAPTURE(c);
            const v3 h(ibl::sin_from_cos(c), T(0), c);
            for (const T d : {ibl::ndf_ggx(c, alpha), ibl::ndf_ggx(h, alpha), ibl::ndf_blinn_phong(c, alpha),
                              ibl::ndf_blinn_phong(h, alpha)}) {
                CHECK(finite(d));
                CHECK(d >= T(0));
            }
            CHECK(finite(ibl::lambda_ggx(c, alpha)));
            const v3 fr = ibl::fresnel_schlick_roughness(c, f0, r);
            CHECK(finite(fr));
            CHECK((fr.x >= f0.x && fr.x <= T(1)));
        }
        for (const T nv : sweep_cosine<T>)
            for (const T nl : sweep_cosine<T>) {
                CAPTURE(nv);
                CAPTURE(nl);
                for (const T k : {k_i, k_d}) {
                    const T g = ibl::g_smith_schlick_ggx(nv, nl, k);
                    CHECK((g >= T(0) && g <= T(1)));
                    const T v = ibl::v_smith_schlick_ggx(nv, nl, k);
                    CHECK(finite(v));
                    CHECK(v > T(0));
                }
                const T g2 = ibl::g2_smith_ggx_correlated(nv, nl, alpha);
                CHECK((g2 >= T(0) && g2 <= T(1)));
                if (nv == T(0) || nl == T(0)) CHECK(g2 == T(0));
                const T v = ibl::v_smith_ggx_correlated(nv, nl, alpha);
                CHECK(finite(v));
                CHECK(v > T(0));
                check_model<ibl::ggx_schlick_ibl>(nv, nl, r);
                check_model<ibl::ggx_height_correlated>(nv, nl, r);
            }
    }
    // Fresnel limits at every cosine of the sweep's ends.
    CHECK(ibl::fresnel_schlick(T(1), f0, v3(T(0.9))) == f0);
    CHECK(ibl::fresnel_schlick(T(0), f0, v3(T(0.9))) == v3(T(0.9)));
}

TEST_CASE_TEMPLATE("BRDF inputs outside the domain are clamped as documented", T, float, double) {
    constexpr T nan = std::numeric_limits<T>::quiet_NaN();
    constexpr T inf = std::numeric_limits<T>::infinity();
    SUBCASE("roughness: NaN -> 0, below 0 -> 0, above 1 -> 1") {
        for (const T bad : {nan, T(-1), -inf}) {
            CHECK(ibl::alpha_from_roughness(bad) == T(0));
            CHECK(ibl::k_ibl(bad) == T(0));
            CHECK(ibl::ggx_height_correlated::visibility(T(0.5), T(0.3), bad) ==
                  ibl::ggx_height_correlated::visibility(T(0.5), T(0.3), T(0)));
            CHECK(ibl::ggx_schlick_ibl::sample_weight(T(0.5), T(0.3), T(0.9), T(0.7), bad) ==
                  ibl::ggx_schlick_ibl::sample_weight(T(0.5), T(0.3), T(0.9), T(0.7), T(0)));
            CHECK(ibl::fresnel_schlick_roughness(T(0.2), T(0.04), bad) == ibl::fresnel_schlick_roughness(T(0.2), T(0.04), T(0)));
        }
        for (const T big : {T(2), inf}) {
            CHECK(ibl::alpha_from_roughness(big) == T(1));
            CHECK(ibl::k_direct(big) == T(0.5));
            CHECK(ibl::ggx_schlick_ibl::visibility(T(0.5), T(0.3), big) ==
                  ibl::ggx_schlick_ibl::visibility(T(0.5), T(0.3), T(1)));
        }
    }
    SUBCASE("cosines: clamped to [0, 1], NaN -> 0") {
        for (const T a : {T(1e-4), T(0.25), T(1)}) {
            CHECK(ibl::v_smith_ggx_correlated(T(-0.5), T(0.3), a) == ibl::v_smith_ggx_correlated(T(0), T(0.3), a));
            CHECK(ibl::v_smith_ggx_correlated(T(1.5), T(0.3), a) == ibl::v_smith_ggx_correlated(T(1), T(0.3), a));
            CHECK(ibl::v_smith_ggx_correlated(nan, T(0.3), a) == ibl::v_smith_ggx_correlated(T(0), T(0.3), a));
            CHECK(ibl::g2_smith_ggx_correlated(nan, nan, a) == T(0));
            CHECK(ibl::ndf_blinn_phong(T(-0.1), a) == T(0));
            CHECK(ibl::ndf_blinn_phong(nan, a) == T(0));
            CHECK(ibl::ndf_blinn_phong(T(1.5), a) == ibl::ndf_blinn_phong(T(1), a));
        }
        CHECK(ibl::g1_schlick_ggx(T(-1), T(0.1)) == T(0));
        CHECK(ibl::g1_schlick_ggx(T(2), T(0.1)) == T(1));
        CHECK(ibl::v_smith_schlick_ggx(nan, nan, T(0.1)) == ibl::v_smith_schlick_ggx(T(0), T(0), T(0.1)));
        // Weights: 0 below the horizon, 0 for n.h <= 0 (never sampled), NaN -> 0; v.h clamped.
        CHECK(ibl::ggx_height_correlated::sample_weight(T(0.5), T(-0.1), T(0.9), T(0.7), T(0.5)) == T(0));
        CHECK(ibl::ggx_height_correlated::sample_weight(T(0.5), nan, T(0.9), T(0.7), T(0.5)) == T(0));
        CHECK(ibl::ggx_height_correlated::sample_weight(T(0.5), T(0.3), T(0), T(0.7), T(0.5)) == T(0));
        CHECK(ibl::ggx_height_correlated::sample_weight(T(0.5), T(0.3), nan, T(0.7), T(0.5)) == T(0));
        CHECK(ibl::ggx_schlick_ibl::sample_weight(T(0.5), T(0.3), T(0.9), T(-0.2), T(0.5)) == T(0));
    }
    SUBCASE("k and alpha: k clamped to [schlick_min_k_v, 1], alpha to [ggx_min_alpha_v, 1]") {
        CHECK(ibl::g1_schlick_ggx(T(0.5), T(-1)) == ibl::g1_schlick_ggx(T(0.5), ibl::schlick_min_k_v<T>));
        CHECK(ibl::g1_schlick_ggx(T(0.5), nan) == ibl::g1_schlick_ggx(T(0.5), ibl::schlick_min_k_v<T>));
        CHECK(ibl::v_smith_schlick_ggx(T(0), T(0), T(0)) == T(1) / (T(4) * ibl::schlick_min_k_v<T> * ibl::schlick_min_k_v<T>));
        CHECK(ibl::g1_schlick_ggx(T(0.5), T(3)) == ibl::g1_schlick_ggx(T(0.5), T(1)));
        CHECK(ibl::v_smith_ggx_correlated(T(0.5), T(0.3), T(-1)) == ibl::v_smith_ggx_correlated(T(0.5), T(0.3), T(0)));
        CHECK(ibl::v_smith_ggx_correlated(T(0.5), T(0.3), T(7)) == ibl::v_smith_ggx_correlated(T(0.5), T(0.3), T(1)));
        CHECK(finite(ibl::ndf_blinn_phong(T(1), T(0))));
        CHECK(ibl::ndf_blinn_phong_exponent(T(0.5), -inf) == ibl::ndf_blinn_phong_exponent(T(0.5), T(0)));
        CHECK(finite(ibl::ndf_blinn_phong_exponent(T(1), inf)));
    }
    SUBCASE("Fresnel: cos NaN -> 0 (F90); metallic NaN -> 0; IOR NaN -> 0") {
        CHECK(ibl::fresnel_schlick(nan, T(0.04)) == T(1));
        CHECK(ibl::fresnel_schlick_roughness(nan, T(0.04), T(0.5)) == T(0.5));
        CHECK(finite(ibl::f0_from_ior(nan, nan)));
        CHECK(finite(ibl::f0_from_ior(inf, inf)));
        CHECK(ibl::f0_from_metallic(ibl::vec3<T>(T(0.7)), nan) == ibl::vec3<T>(T(0.04)));
    }
}
