// tests/test_shade.cpp — the runtime combination of the products (ibl/runtime/shade.hpp) as a
// specification: white-furnace identities of the multiple-scattering model, energy bounds of
// both ambient variants (including the documented excess of the single-scattering heuristic),
// a hand-computed Cook-Torrance value, metals without diffuse, inverse-square falloff, and a
// finiteness sweep over the stiff corners (r, n.v, n.l in {0, 1e-7.., 1}, NaN inputs).
//
// A white furnace is a constant environment of radiance L = 1: its prefiltered radiance is
// LD = 1 at every roughness and its irradiance is E = pi (E/pi = 1), whatever the DFG values are,
// so the DFG values (A, B) can be swept as free parameters over the triangle A, B >= 0, A + B <= 1.

#include <doctest/doctest.h>

#include <ibl/runtime/shade.hpp>

#include <cmath>
#include <limits>
#include <vector>

namespace {

template <class T> constexpr double eps = std::numeric_limits<T>::epsilon();
constexpr double pi = 3.141592653589793238462643383279502884;

template <class T> ibl::vec3<T> v3(double x) { return ibl::vec3<T>(T(x)); }

template <class T> bool finite3(const ibl::vec3<T>& c) {
    return std::isfinite(double(c.x)) && std::isfinite(double(c.y)) && std::isfinite(double(c.z));
}

// The DFG triangle A, B >= 0, A + B <= 1 on a 21 x 21 grid (both edges included).
template <class T> std::vector<ibl::vec2<T>> dfg_triangle() {
    std::vector<ibl::vec2<T>> out;
    for (int i = 0; i <= 20; ++i)
        for (int j = 0; i + j <= 20; ++j) out.emplace_back(T(i / 20.0), T(j / 20.0));
    return out;
}

const double f0_values[] = {0.0, 0.02, 0.04, 0.25, 0.5, 0.9, 1.0};

} // namespace

TEST_CASE_TEMPLATE("shade: diffuse IBL takes E or E/pi, as named", T, float, double) {
    const ibl::vec3<T> albedo(T(0.8), T(0.5), T(0.25));
    // Constant environment L = 2: E = 2 pi, E/pi = 2; both give albedo * L (one rounding of pi
    // and two products: 3 eps_T).
    const auto d1 = ibl::diffuse_ibl(albedo, v3<T>(2 * pi));
    const auto d2 = ibl::diffuse_ibl_over_pi(albedo, v3<T>(2));
    for (int c = 0; c < 3; ++c) {
        CHECK(double(d1[c]) == doctest::Approx(2 * double(albedo[c])).epsilon(3 * eps<T>));
        CHECK(double(d2[c]) == double(albedo[c]) * 2);
    }
}

TEST_CASE_TEMPLATE("shade: multiple scattering passes the white furnace exactly", T, float, double) {
    // Header identity: FssEss + FmsEms + Edss = 1, so ambient = 1 for L = 1 and albedo 1 whatever
    // F0 and (A, B) are. The sum of three terms each of a few roundings: 8 eps_T.
    for (const auto& dfg : dfg_triangle<T>()) {
        for (double f0 : f0_values) {
            const auto ms = ibl::multiscatter(v3<T>(f0), v3<T>(1), dfg);
            const auto amb = ibl::ambient_multiscatter(ms, v3<T>(1), v3<T>(1), v3<T>(1), T(1));
            CHECK(double(amb.x) == doctest::Approx(1.0).epsilon(8 * eps<T>));
        }
    }
}

TEST_CASE_TEMPLATE("shade: a white metal keeps all the energy (FssEss + FmsEms = 1)", T, float, double) {
    // F0 = F90 = 1: FssEss = Ess, FmsEms = Ems Ess / Ess = Ems, sum 1. Ess = 0 is the documented
    // exception (0/0 floored: 0); the check starts at A + B = 0.05. Division by Ess ~ 0.05
    // amplifies nothing (the numerator carries Ess): 8 eps_T.
    for (const auto& dfg : dfg_triangle<T>()) {
        if (double(dfg.x + dfg.y) < 0.049) continue;
        const auto ms = ibl::multiscatter(v3<T>(1), v3<T>(1), dfg);
        CHECK(double(ms.fss_ess.y + ms.fms_ems.y) == doctest::Approx(1.0).epsilon(8 * eps<T>));
        CHECK(double(ms.diffuse_fraction.y) <= 8 * eps<T>);
    }
    const auto zero = ibl::multiscatter(v3<T>(1), v3<T>(1), ibl::vec2<T>(T(0)));
    CHECK(finite3(zero.fms_ems));
    CHECK(double(zero.fms_ems.x) == 0.0);
}

TEST_CASE_TEMPLATE("shade: multiple-scattering energy bound for every albedo, F0, F90 in [0, 1]", T, float, double) {
    // FssEss <= Ess, FmsEms <= Favg Ems <= Ems (header), so the ambient under L = 1 is in [0, 1].
    const double albedos[] = {0.0, 0.3, 1.0};
    for (const auto& dfg : dfg_triangle<T>())
        for (double f0 : f0_values)
            for (double f90 : {0.0, 0.5, 1.0})
                for (double a : albedos) {
                    const auto ms = ibl::multiscatter(v3<T>(f0), v3<T>(f90), dfg);
                    const auto amb = ibl::ambient_multiscatter(ms, v3<T>(a), v3<T>(1), v3<T>(1), T(1));
                    CHECK(double(amb.x) >= 0.0);
                    CHECK(double(amb.x) <= 1 + 8 * eps<T>);
                    CHECK(double(ms.fss_ess.x + ms.fms_ems.x) <= 1 + 8 * eps<T>);
                }
}

TEST_CASE_TEMPLATE("shade: Favg is the cosine-weighted mean of Schlick's Fresnel (1/21)", T, float, double) {
    // 2 int_0^1 F(mu) mu dmu by a 2000-panel midpoint rule in double (error ~ 1e-7 relative:
    // h^2/24 times the second derivative of a degree-6 polynomial, <= 30 / 24 / 2000^2 ~ 3e-7).
    const double f0 = 0.04;
    double sum = 0;
    const int n = 2000;
    for (int i = 0; i < n; ++i) {
        const double mu = (i + 0.5) / n;
        sum += 2 * (f0 + (1 - f0) * std::pow(1 - mu, 5)) * mu / n;
    }
    const auto favg = ibl::fresnel_schlick_average(v3<T>(f0), v3<T>(1));
    CHECK(double(favg.x) == doctest::Approx(sum).epsilon(1e-6 + 4 * eps<T>));
    CHECK(double(favg.x) == doctest::Approx(0.04 + 0.96 / 21).epsilon(4 * eps<T>));
}

TEST_CASE_TEMPLATE("shade: single-scattering ambient and its documented bound", T, float, double) {
    // ambient = (1 - F)(1 - m) + F0 A + F90 B under L = 1, albedo 1, ao 1.
    // Bound (header): <= 1 + max(0, B - F0 (1 - A)) when F90 = 1 and metallic = 0.
    const double cosines[] = {0.0, 0.25, 0.5, 1.0};
    const double roughnesses[] = {0.0, 0.5, 1.0};
    for (const auto& dfg : dfg_triangle<T>())
        for (double f0 : f0_values)
            for (double nv : cosines)
                for (double r : roughnesses) {
                    const auto f = ibl::fresnel_schlick_roughness(T(nv), v3<T>(f0), T(r));
                    const auto kd = ibl::ambient_kd(f, T(0));
                    const auto amb = ibl::ambient_single_scatter(kd, ibl::diffuse_ibl_over_pi(v3<T>(1), v3<T>(1)),
                                                                 ibl::specular_ibl(v3<T>(1), v3<T>(f0), dfg), T(1));
                    const double a = double(dfg.x), b = double(dfg.y);
                    const double bound = 1 + std::fmax(0.0, b - f0 * (1 - a));
                    CHECK(double(amb.x) <= bound + 8 * eps<T>);
                    CHECK(double(amb.x) >= 0.0);
                }
    SUBCASE("the heuristic exceeds 1 where the header says: F0 = 0, n.v = 1 gives 1 + B") {
        const ibl::vec2<T> dfg(T(0.5), T(0.1));
        const auto f = ibl::fresnel_schlick_roughness(T(1), v3<T>(0), T(0.5));
        const auto amb = ibl::ambient_single_scatter(ibl::ambient_kd(f, T(0)), v3<T>(1),
                                                     ibl::specular_ibl(v3<T>(1), v3<T>(0), dfg), T(1));
        CHECK(double(amb.x) == doctest::Approx(1.1).epsilon(4 * eps<T>));
    }
    SUBCASE("a metal is bounded by A + B <= 1") {
        for (const auto& dfg : dfg_triangle<T>()) {
            const auto spec = ibl::specular_ibl(v3<T>(1), v3<T>(0.9), dfg);
            CHECK(double(spec.x) <= 1 + 4 * eps<T>);
        }
    }
}

TEST_CASE_TEMPLATE("shade: split-sum specular is LD (F0 A + F90 B); only the products a scene has", T, float, double) {
    const ibl::vec3<T> ld(T(2), T(3), T(4));
    const ibl::vec3<T> f0(T(0.9), T(0.6), T(0.3));
    const ibl::vec2<T> dfg(T(0.75), T(0.125));
    const auto s = ibl::specular_ibl(ld, f0, dfg);
    // Two products and a sum, then one product: 4 eps_T.
    for (int c = 0; c < 3; ++c)
        CHECK(double(s[c]) ==
              doctest::Approx(double(ld[c]) * (double(f0[c]) * 0.75 + 0.125)).epsilon(4 * eps<T>));
    // F90 = 0 removes the bias term.
    const auto s0 = ibl::specular_ibl(ld, f0, v3<T>(0), dfg);
    CHECK(double(s0.x) == doctest::Approx(2 * 0.9 * 0.75).epsilon(4 * eps<T>));
    // DFG values outside [0, 1] (a broken LUT) and NaN are clamped.
    const auto sc = ibl::specular_ibl(v3<T>(1), v3<T>(1), ibl::vec2<T>(T(2), std::numeric_limits<T>::quiet_NaN()));
    CHECK(double(sc.x) == 1.0);
}

TEST_CASE_TEMPLATE("shade: metallic = 1 has no diffuse", T, float, double) {
    ibl::pbr_material<T> mat;
    mat.base_color = ibl::vec3<T>(T(0.9), T(0.6), T(0.3));
    mat.metallic = T(1);
    mat.roughness = T(0.4);
    const auto m = ibl::resolve_material(mat);
    CHECK(m.diffuse_albedo == v3<T>(0));
    CHECK(m.f0 == mat.base_color);
    CHECK(ibl::ambient_kd(ibl::vec3<T>(T(0.3)), m.metallic) == v3<T>(0));
    // Ambient with LD = 0 and a huge irradiance: single scattering gives exactly 0 ...
    ibl::ibl_sample<T> s;
    s.ld = v3<T>(0);
    s.irradiance_over_pi = v3<T>(1000);
    s.dfg = ibl::vec2<T>(T(0.6), T(0.1));
    auto single = ibl::pbr_shader<T>::from(mat, false);
    CHECK(single.ambient(T(0.7), s) == v3<T>(0));
    // ... and multiple scattering only the (diffuse-like) multiple-scattering lobe FmsEms E/pi.
    auto multi = ibl::pbr_shader<T>::from(mat, true);
    const auto ms = ibl::multiscatter(m.f0, m.f90, s.dfg);
    const auto amb = multi.ambient(T(0.7), s);
    for (int c = 0; c < 3; ++c) CHECK(double(amb[c]) == doctest::Approx(1000 * double(ms.fms_ems[c])).epsilon(4 * eps<T>));
    // Direct: the BRDF is the specular lobe alone.
    const ibl::light_cosines<T> lc{T(0.8), T(0.9), T(0.7)};
    const auto full = ibl::brdf_direct(T(0.6), lc, m);
    const auto spec = ibl::specular_brdf_direct(T(0.6), lc, m.f0, m.f90, m.roughness);
    for (int c = 0; c < 3; ++c) CHECK(double(full[c]) == doctest::Approx(double(spec[c])).epsilon(4 * eps<T>));
}

TEST_CASE_TEMPLATE("shade: direct Cook-Torrance against a hand-computed value", T, float, double) {
    // n = +Z, v = (0.6, 0, 0.8), l = (0, 0.6, 0.8): n.v = n.l = 0.8, h = (0.6, 0.6, 1.6)/sqrt(3.28),
    // n.h = 1.6/sqrt(3.28), v.h = sqrt(3.28)/2. r = 0.5: alpha = 0.25, k_direct = 1.5^2/8.
    // base_color (0.8, 0.5, 0.2), metallic 0.3: F0 = 0.04*0.7 + c*0.3.
    // D = 0.2763837389849964, G = 0.8729287655176088 (textbook forms, evaluated in double by
    // hand: D = a^2 / (pi ((n.h)^2 (a^2 - 1) + 1)^2), G = prod n.w / (n.w (1 - k) + k)),
    // f = (1 - F)(1 - m) c / pi + D G F / (4 n.v n.l); L_o = f * 2 * n.l for E_perp = 2.
    const double expected[] = {0.24918140710712913, 0.1733647809334211, 0.07829691763238807};
    ibl::pbr_material<T> mat;
    mat.base_color = ibl::vec3<T>(T(0.8), T(0.5), T(0.2));
    mat.metallic = T(0.3);
    mat.roughness = T(0.5);
    const auto shader = ibl::pbr_shader<T>::from(mat);
    const ibl::vec3<T> n(T(0), T(0), T(1)), v(T(0.6), T(0), T(0.8)), l(T(0), T(0.6), T(0.8));
    ibl::directional_light<T> sun{l, v3<T>(2)};
    const auto lo = shader.directional(n, v, sun);
    // Some 40 roundings in T along the chain (D, V, F, kD, sums); the cosines are formed from
    // rounded vectors (0.6, 0.8 are not exact in binary): 64 eps_T relative.
    for (int c = 0; c < 3; ++c) CHECK(double(lo[c]) == doctest::Approx(expected[c]).epsilon(64 * eps<T>));

    SUBCASE("a point light at distance d with intensity 2 d^2 gives the same") {
        const ibl::vec3<T> p(T(1), T(2), T(3));
        const T d = T(4);
        ibl::point_light<T> bulb{p + d * l, v3<T>(2 * 16)};
        const auto lp = shader.point(p, n, v, bulb);
        for (int c = 0; c < 3; ++c) CHECK(double(lp[c]) == doctest::Approx(expected[c]).epsilon(64 * eps<T>));
        // Inverse square: twice the distance, a quarter of the radiance.
        ibl::point_light<T> far{p + T(2) * d * l, v3<T>(2 * 16)};
        const auto lf = shader.point(p, n, v, far);
        CHECK(double(lf.x) == doctest::Approx(expected[0] / 4).epsilon(64 * eps<T>));
    }
    SUBCASE("a light below the horizon contributes nothing") {
        ibl::directional_light<T> below{ibl::vec3<T>(T(0), T(0.6), T(-0.8)), v3<T>(2)};
        CHECK(shader.directional(n, v, below) == v3<T>(0));
    }
}

TEST_CASE_TEMPLATE("shade: finite for finite inputs at every stiff corner", T, float, double) {
    const T tiny = std::numeric_limits<T>::denorm_min();
    const T cosines[] = {T(0), T(1e-7), tiny, T(0.5), T(1)};
    const T roughnesses[] = {T(0), T(1e-4), T(0.5), T(1)};
    const ibl::vec2<T> dfgs[] = {{T(0), T(0)}, {T(1), T(0)}, {T(0), T(1)}, {T(0.5), T(0.25)}};
    const ibl::vec3<T> n(T(0), T(0), T(1));
    int checked = 0;
    for (T r : roughnesses)
        for (T metallic : {T(0), T(1)})
            for (T nv : cosines) {
                ibl::pbr_material<T> mat;
                mat.base_color = ibl::vec3<T>(T(1), T(0.5), T(0));
                mat.metallic = metallic;
                mat.roughness = r;
                const ibl::vec3<T> v(ibl::sin_from_cos(nv), T(0), nv);
                for (bool multi : {false, true}) {
                    const auto sh = ibl::pbr_shader<T>::from(mat, multi);
                    for (const auto& dfg : dfgs) {
                        const auto amb = sh.ambient(nv, {v3<T>(1e4), v3<T>(1e4), dfg});
                        CHECK(finite3(amb));
                        ++checked;
                    }
                    for (T nl : cosines) {
                        // l in the plane of v (mirror direction when nl == nv: the GGX peak at r = 0)
                        // and out of it.
                        const ibl::vec3<T> l_mirror(-ibl::sin_from_cos(nl), T(0), nl);
                        const ibl::vec3<T> l_side(T(0), ibl::sin_from_cos(nl), nl);
                        for (const auto& l : {l_mirror, l_side}) {
                            const auto lo = sh.directional(n, v, {l, v3<T>(1e3)});
                            CHECK(finite3(lo));
                            CHECK(double(lo.x) >= 0.0);
                            ++checked;
                        }
                    }
                    // l = -v (zero half vector), a light at the shading point.
                    CHECK(finite3(sh.directional(n, v, {-v, v3<T>(1)})));
                    CHECK(finite3(sh.point(v3<T>(0), n, v, {v3<T>(0), v3<T>(1)})));
                }
            }
    CHECK(checked > 1000);

    SUBCASE("the r = 0 mirror peak is large but finite") {
        ibl::pbr_material<T> mat;
        mat.roughness = T(0);
        const auto sh = ibl::pbr_shader<T>::from(mat);
        const ibl::vec3<T> v(T(0), T(0), T(1));
        const auto lo = sh.directional(n, v, {v, v3<T>(1)});
        CHECK(finite3(lo));
        CHECK(double(lo.x) > 1e10); // D = 1/(pi alpha_min^2), alpha_min = 2^-31 (float) / 2^-255
    }
}

TEST_CASE_TEMPLATE("shade: NaN scalars are clamped (documented), NaN colours stay in their channel", T, float, double) {
    const T nan = std::numeric_limits<T>::quiet_NaN();
    ibl::pbr_material<T> mat;
    mat.metallic = nan;
    mat.roughness = nan;
    mat.ambient_occlusion = nan;
    const auto m = ibl::resolve_material(mat);
    CHECK(m.metallic == T(0));
    CHECK(m.roughness == T(0));
    CHECK(m.ambient_occlusion == T(0));
    const auto sh = ibl::pbr_shader<T>::from(mat);
    const ibl::vec3<T> n(T(0), T(0), T(1));
    CHECK(finite3(sh.ambient(nan, {v3<T>(1), v3<T>(1), ibl::vec2<T>(nan, nan)})));
    // A NaN light direction gives cosines NaN -> 0: no light.
    CHECK(sh.directional(n, n, {v3<T>(nan), v3<T>(1)}) == v3<T>(0));
    // A NaN colour channel propagates in that channel only.
    const auto d = ibl::diffuse_ibl(ibl::vec3<T>(nan, T(1), T(1)), v3<T>(pi));
    CHECK(std::isnan(double(d.x)));
    CHECK(std::isfinite(double(d.y)));
}
