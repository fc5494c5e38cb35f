// tests/browser/glsl_reference.cpp — the grid of tools/viewer/numeric.frag.glsl evaluated by the
// C++ library in float (ibl/lookup.hpp, ibl/shade.hpp, ibl/sh/convolve.hpp), printed as JSON for
// run_browser_test.py --mode numeric. Each row names the function and its bound: relative `rel`
// plus absolute `abs` (docs/shaders.md derives them).

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <ibl/lookup.hpp>
#include <ibl/runtime.hpp>
#include <ibl/shade.hpp>
#include <ibl/sh/convolve.hpp>

namespace {

using ibl::vec3;
using v3 = vec3<float>;
using v4 = ibl::vec4<float>;

constexpr int width = 64;

float u64(int i) { return i == 63 ? 1.0f : float(i) * 0.015625f; }

v3 dir_of(int i) {
    const float a = float(i % 8) * 0.25f - 0.875f, b = float(i / 8) * 0.25f - 0.875f;
    return glm::normalize(v3(a, 0.5f + 0.0625f * float(i % 5), b));
}

ibl::specular_lookup_desc desc_default() { return {}; }

v4 row_value(int j, int i) {
    const float x = u64(i);
    if (j == 0) {
        const auto t = ibl::specular_lookup_taps(x, 6, desc_default());
        return {t.lod, t.weight[0], t.weight[1], float(t.level[0])};
    }
    if (j == 1) {
        const auto t = ibl::specular_lookup_taps(x, 5, ibl::specular_lookup_desc::textbook());
        return {t.lod, t.weight[0], t.weight[1], float(t.level[0])};
    }
    if (j == 2) {
        const ibl::specular_lookup_desc d{ibl::roughness_mapping::filament, ibl::level_weight::power, 2.0,
                                          ibl::level_interpolation::catmull_rom};
        const auto t = ibl::specular_lookup_taps(x, 5, d);
        return {t.weight[0], t.weight[1], t.weight[2], t.weight[3]};
    }
    if (j == 3) {
        const auto d = desc_default();
        const auto t = ibl::specular_lookup_taps(x, 6, d);
        const v3 vals[4] = {v3(0.25f + float(i) * 0.03125f, 3.0f, 0.0f), v3(1.5f, 0.125f + float(i) * 0.015625f, 2.0f),
                            v3(0.0f), v3(0.0f)};
        return {ibl::specular_blend(t, vals, d), t.weight[1]};
    }
    if (j == 4) {
        const float r = 1.0f - x;
        const auto a = ibl::dfg_lut_coord(x, r, 128u, ibl::dfg_lut_layout{});
        const auto b = ibl::dfg_lut_coord(x, r, 128u, ibl::dfg_lut_layout::uniform());
        return {a.x, a.y, b.x, b.y};
    }
    if (j == 5) {
        ibl::sh_coeffs<float, 3> c;
        for (int k = 0; k < 9; ++k) c.c[k] = v3(0.5f - 0.125f * float(k), 0.25f * float(k % 3), 0.0625f * float(k));
        const v3 n = dir_of(i);
        const v3 e = ibl::sh_shader_evaluate(c, n);
        return {e, std::fmax(e.x, 0.0f)};
    }
    const float a = float(i % 8) * 0.125f, bb = float(i / 8) * 0.0625f;
    const v3 f0(0.04f + 0.0625f * float(i % 8), 0.5f, 1.0f);
    if (j == 6) {
        const auto ms = ibl::multiscatter(f0, v3(1.0f), ibl::vec2<float>(a, bb));
        return {ms.fss_ess.x, ms.fms_ems.x, ms.diffuse_fraction.x, ms.fms_ems.z};
    }
    ibl::pbr_material<float> mat;
    mat.base_color = v3(0.75f, 0.5f, 0.25f);
    mat.metallic = float(i % 2);
    mat.roughness = x;
    const auto shader = ibl::pbr_shader<float>::from(mat, true);
    const ibl::material_terms<float> m = shader.m;
    ibl::ibl_sample<float> s;
    s.ld = v3(2.0f, 1.0f, 0.5f);
    s.irradiance_over_pi = v3(0.25f, 0.5f, 1.0f);
    s.dfg = ibl::vec2<float>(a, bb);
    const float nv = 1.0f - x;
    if (j == 7) return {shader.ambient(nv, s), 0.0f};
    if (j == 8) {
        const auto single = ibl::pbr_shader<float>::from(mat, false);
        return {single.ambient(nv, s), ibl::fresnel_schlick_roughness(nv, m.f0, m.roughness).x};
    }
    const v3 n(0.0f, 1.0f, 0.0f), v = dir_of(i), l = dir_of(63 - i);
    if (j == 9) {
        ibl::directional_light<float> light;
        light.direction = l;
        light.irradiance = v3(1.0f, 2.0f, 3.0f);
        return {ibl::shade_directional(n, v, light, m), 0.0f};
    }
    if (j == 10) {
        const auto c = ibl::make_light_cosines(n, v, l);
        return {c.n_dot_l, c.n_dot_h, c.v_dot_h, ibl::v_smith_schlick_ggx(v.y, c.n_dot_l, ibl::k_direct(x))};
    }
    if (j == 11) return {ibl::ndf_ggx(1.0f - 0.5f * x, x * x), ibl::ndf_ggx(0.875f, x * x), ibl::k_direct(x), 0.0f};
    if (j == 13) {
        const float ct = 2.0f * x - 1.0f;
        return {ibl::cap_irradiance(ct, ibl::cap_sin2(0.01f)), ibl::cap_irradiance(ct, ibl::cap_sin2(0.25f)),
                ibl::cap_irradiance(ct, ibl::cap_sin2(1.0f)), ibl::cap_irradiance(ct, 1.0f)};
    }
    if (j == 14) {
        const ibl::disk_light<float> dl{l, 0.25f, v3(1.0f, 2.0f, 3.0f)};
        return {ibl::disk_light_specular(n, v, dl, m.f0, m.f90, x), ibl::disk_light_irradiance(n, dl).x};
    }
    if (j == 15) {
        const ibl::disk_light<float> sun{l, 6.8e-5f, v3(1.0e4f, 2.0e4f, 3.0e4f)};
        ibl::pbr_material<float> mat2 = mat;
        mat2.roughness = 0.25f + 0.75f * x;
        return {ibl::shade_disk(n, v, sun, ibl::resolve_material(mat2)), 0.0f};
    }
    if (j == 16) return {ibl::lerp_direction(dir_of(i), dir_of(63 - i), 2.0f * x - 0.5f), 0.0f};
    if (j == 17) { // as ibl::specular_lobe forms its direction
        const v3 a = dir_of(i), b = dir_of(63 - i);
        const v3 d = ibl::lerp_direction(a, 2.0f * glm::dot(a, b) * a - b, x);
        return {d, glm::dot(d, a)};
    }
    if (j == 12)
        return {ibl::roughness_from_lod(ibl::roughness_mapping::filament, x * 4.0f, 4.0f),
                ibl::lod_from_roughness(ibl::roughness_mapping::filament, x, 4.0f),
                ibl::dfg_axis_coord(ibl::dfg_axis::cbrt, x), ibl::dfg_axis_coord(ibl::dfg_axis::sqrt, x)};
    return v4(0.0f);
}

/// The disk-light rows' extra relative bound: D(n.h; alpha') amplifies an error dc of n.h by
/// |d ln D / d c| = 4 c (1 - a^2) / (1 - c^2 (1 - a^2)) <= 4 / a^2 (a = alpha', at c = 1), and
/// n.h comes from vectors each normalised in float on both sides (v, l: dir_of; h: make_light_cosines),
/// so |dc| <= delta = 2^-21 (8 ulp of 1). a^2 >= alpha(r_min)^2 + tan^2(r/2) (v.h <= 1).
double disk_rel(double omega, double r_min) {
    const double c1 = omega / (2.0 * ibl::pi_v<double>), tan2_half = c1 / (2.0 - c1);
    const double a2 = r_min * r_min * r_min * r_min + tan2_half;
    return 4.0 * std::ldexp(1.0, -21) / a2;
}

/// Row 13's per-value absolute bound. acos and atan have no precision in GLSL ES 3.00 (Vulkan
/// allows 4096 ulp); assumed here: absolute error <= trig_eps = 2^-14 (SwiftShader measured
/// ~1.7e-5 on acos). Inside the straddling band E = s2 (ct acos y + u) + (atan u - u): acos
/// enters times s2 |ct|, atan (used for u >= 1/4) times 1, and E is a difference of terms of
/// that size (at the band's lower edge E -> 0 from terms ~s2 sin r), so no relative bound holds
/// there. Outside the band (the whole cap above or below) no trig is used: 1e-6.
double cap_abs_bound(int i, int col) {
    constexpr double trig_eps = 1.0 / 16384.0;
    const double omegas[3] = {0.01, 0.25, 1.0};
    const double ct = 2.0 * double(u64(i)) - 1.0;
    double s2 = 1.0;
    if (col < 3) {
        const double c1 = omegas[col] / (2.0 * ibl::pi_v<double>);
        s2 = c1 * (2.0 - c1);
    }
    if (ct * ct >= s2) return 1e-6;
    const double st = std::sqrt((1.0 - ct) * (1.0 + ct)), x = std::sqrt((1.0 - s2) / s2);
    const double y = std::fmin(1.0, std::fmax(-1.0, -x * ct / st));
    const double u = x > 0.0 ? st * std::sqrt((1.0 - y) * (1.0 + y)) / x : 0.0;
    return 1e-6 + trig_eps * (s2 * std::fabs(ct) + (x > 0.0 && u >= 0.2 ? 1.0 : 0.0)); // 0.2: margin below 1/4
}

struct row_info {
    const char* name;
    double rel, abs;
};

} // namespace

int main() {
    // Bounds: GLSL ES 3.00 highp (IEEE single storage): +, -, * correctly rounded, / and
    // inversesqrt 2.5 / 2 ulp, exp2 / log2 (3 + 2|x|) ulp, pow inherited from exp2(y log2 x).
    // A row's value passes through <= ~30 such operations: 1e-5 relative (~80 ulp) covers it; the
    // absolute term covers results that are differences of O(1) terms (1 - (FssEss + FmsEms),
    // 1 - x with x near 1): a few ulp of 1 = 1e-6.
    const row_info rows[] = {
        {"specular taps (default)", 1e-5, 1e-6},   {"specular taps (textbook)", 1e-5, 1e-6},
        {"taps (filament, power, CR)", 1e-5, 1e-6}, {"specular blend (geometric)", 1e-5, 1e-6},
        {"dfg_lut_coord", 1e-5, 1e-6},             {"sh_shader_evaluate", 1e-5, 1e-6},
        {"multiscatter terms", 1e-5, 1e-6},        {"ambient (multiscatter)", 1e-5, 1e-6},
        {"ambient (single) + F_r", 1e-5, 1e-6},    {"shade_directional", 1e-5, 1e-6},
        {"light cosines + V", 1e-5, 1e-6},         {"ndf_ggx + k_direct", 1e-5, 1e-6},
        {"mapping + dfg axes", 1e-5, 1e-6},
        {"cap_irradiance", 1e-5, 1e-6},
        {"disk_light_specular (0.25 sr)", 1e-5 + disk_rel(0.25, 0.0), 1e-6},
        {"shade_disk (sun, r >= 0.25)", 1e-5 + disk_rel(6.8e-5, 0.25), 1e-6},
        {"lerp_direction", 1e-5, 1e-6},
        {"lobe direction (+ its n.d)", 1e-5, 1e-6},
    };
    std::printf("{\"width\": %d, \"height\": 18, \"rows\": [", width);
    const int n_rows = int(sizeof(rows) / sizeof(rows[0]));
    for (int j = 0; j < n_rows; ++j) {
        std::printf("%s\n{\"row\": %d, \"name\": \"%s\", \"rel\": %g, \"abs\": %g, \"values\": [", j ? "," : "", j, rows[j].name,
                    rows[j].rel, rows[j].abs);
        for (int i = 0; i < width; ++i) {
            const v4 v = row_value(j, i);
            std::printf("%s[%.9g, %.9g, %.9g, %.9g]", i ? ", " : "", double(v.x), double(v.y), double(v.z), double(v.w));
        }
        std::printf("]");
        if (j == 13) { // per-value absolute bounds (cap_abs_bound)
            std::printf(", \"abs_values\": [");
            for (int i = 0; i < width; ++i)
                std::printf("%s[%.9g, %.9g, %.9g, %.9g]", i ? ", " : "", cap_abs_bound(i, 0), cap_abs_bound(i, 1),
                            cap_abs_bound(i, 2), cap_abs_bound(i, 3));
            std::printf("]");
        }
        std::printf("}");
    }
    std::printf("]}\n");
    return 0;
}
