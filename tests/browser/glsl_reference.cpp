// tests/browser/glsl_reference.cpp — the grid of tools/viewer/numeric.frag.glsl evaluated by the
// C++ library in float (ibl/runtime/lookup.hpp, ibl/runtime/shade.hpp, ibl/sh/convolve.hpp), printed as JSON for
// run_browser_test.py --mode numeric. Each row names the function and its bound: relative `rel`
// plus absolute `abs` (docs/shaders.md derives them).

#include <algorithm>
#include <cmath>
#include <limits>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include <ibl/bake/prefilter.hpp>
#include <ibl/bake/prefilter_peaks.hpp>
#include <ibl/bake/prefilter_sh.hpp>
#include <ibl/env/analytic.hpp>
#include <ibl/env/convert.hpp>
#include <ibl/env/cube_geometry.hpp>
#include <ibl/env/cubemap.hpp>
#include <ibl/reference/occluded_specular.hpp>
#include <ibl/runtime/local_probe.hpp>
#include <ibl/runtime/lookup.hpp>
#include <ibl/runtime/specular_occlusion.hpp>
#include <ibl/runtime/specular_models.hpp>
#include <ibl/runtime/shade.hpp>
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

ibl::specular_lookup_desc desc_default() { return ibl::specular_lookup_desc::accurate(); }

// ---- the runtime rows' fixtures (tools/viewer/numeric.frag.glsl: u_chain, u_taps_a, u_taps_b) ----

using v3d = vec3<double>;

/// The chain of the runtime rows: 8^2 faces, 4 levels; level l holds the smooth field
/// (1.5 + d.x + 0.5 d.y - 0.25 d.z, 1.25 - 0.5 d.x + 0.75 d.z, 1 + 0.25 d.y) (1 - l/8) at the texel
/// centres d (so every texel difference is small: see fis_bound).
const ibl::cubemap<float>& fixture_chain() {
    static const ibl::cubemap<float> chain = [] {
        ibl::cubemap<float> c(8, 4);
        for (int l = 0; l < 4; ++l) {
            const int n = c.size(l);
            const double s = 1.0 - double(l) / 8.0;
            c.fill(l, [&](int f, int x, int y) {
                const v3d d = ibl::cube_texel_direction<double>(f, x, y, n);
                return v3(float(s * (1.5 + d.x + 0.5 * d.y - 0.25 * d.z)), float(s * (1.25 - 0.5 * d.x + 0.75 * d.z)),
                          float(s * (1.0 + 0.25 * d.y)));
            });
        }
        c.update_borders();
        return c;
    }();
    return chain;
}

/// The two-tap table (lobe_taps_lut's members): 4^2 texels of 8 channels (A, B, angle0 / acos(n.v),
/// r0, w0, angle1 / acos(n.v), r1, w1), smooth in (i, j), both weights 0 at texels (0, 0) and (1, 0)
/// (the fallback), weight 0 of tap 1 on row 0.
struct taps_table {
    std::uint32_t size = 4, channels = 8;
    ibl::dfg_lut_layout layout = ibl::dfg_lut_layout::remapped(); // the GLSL side reads it remapped
    int taps = 2;
    std::vector<float> data;
};

const taps_table& fixture_taps() {
    static const taps_table t = [] {
        taps_table lut;
        lut.data.resize(4 * 4 * 8);
        for (int j = 0; j < 4; ++j)
            for (int i = 0; i < 4; ++i) {
                float* p = &lut.data[std::size_t(j * 4 + i) * 8];
                const float fi = float(i), fj = float(j);
                p[0] = 0.25f + 0.125f * fi - 0.0625f * fj;
                p[1] = 0.5f - 0.0625f * fi - 0.03125f * fj;
                p[2] = 0.125f + 0.125f * fi + 0.0625f * fj;
                p[3] = 0.125f + 0.25f * fj;
                p[4] = j == 0 && i < 2 ? 0.0f : 0.25f + 0.0625f * fi + 0.125f * fj;
                p[5] = 0.375f + 0.0625f * fi + 0.125f * fj;
                p[6] = 0.25f + 0.1875f * fj + 0.03125f * fi;
                p[7] = j == 0 ? 0.0f : 0.125f * fj + 0.0625f * fi;
            }
        return lut;
    }();
    return t;
}

ibl::specular_lookup_desc chain_lookup(bool textbook) {
    return textbook ? ibl::specular_lookup_desc::textbook() : ibl::specular_lookup_desc::accurate();
}

/// The runtime rows' view and normal: n = dir_of(i), v = dir_of((7 i + 3) mod 64).
v3 fis_n(int i) { return dir_of(i); }
v3 fis_v(int i) { return dir_of((7 * i + 3) % 64); }

/// specular_fis's tangent-space view: to_local, z clamped to >= 0, normalised.
v3 fis_view_local(const ibl::frame<float>& fr, const v3& v) {
    v3 vl = fr.to_local(v);
    vl.z = vl.z > 0.0f ? vl.z : 0.0f;
    const float len2 = glm::dot(vl, vl);
    return len2 > 0.0f ? vl / std::sqrt(len2) : v3(0.0f, 0.0f, 1.0f);
}

/// The VNDF row's inputs: a tangent-space view with z >= 1/16, u = fis_tap_point(i mod 16, 16),
/// roughness 0.25 (1 + i / 16).
v3 vndf_v(int i) {
    return glm::normalize(v3(float(i % 8) * 0.25f - 0.875f, float(i % 3) * 0.25f - 0.25f, float(i / 8) * 0.125f + 0.0625f));
}
ibl::vec2<float> vndf_u(int i) { return ibl::fis_tap_point<float>(std::uint32_t(i % 16), 16u); }
float vndf_alpha(int i) {
    const float r = 0.25f * float(1 + i / 16);
    return r * r;
}

/// Absolute error of GLSL sin / cos: GLSL ES 3.00 specifies none; Vulkan (SwiftShader's, under
/// ANGLE) requires 2^-11 on [-pi, pi], where every argument of the runtime rows lies (the "sin / cos"
/// row checks it at those arguments; SwiftShader measured 1.6e-4).
constexpr double trig_eps = 1.0 / 2048.0; // 2^-11

/// A bound on the GPU's error in sample_ggx_vndf's h (each component), recomputing the sampler's
/// intermediates in double: sin enters h_s . e1 as 2 sin_c s_half^2 (error <= 4 sin_c |s_half| eps)
/// and h_s . e2 as -sin_c sin(psi) (<= sin_c eps); with the float rounding of h_s (1e-5 |h_s|, the
/// rows' arithmetic term) that is dp, and unstretching p = (a h_s.x, a h_s.y, h_s.z) then
/// normalising moves h by <= dp / |p|, plus the final normalisation's rounding (1e-5).
double vndf_dh(const v3& v, const ibl::vec2<float>& u, float alpha) {
    const double a = ibl::clamp_alpha(double(alpha));
    v3d vs(a * v.x, a * v.y, std::fmin(std::fmax(double(v.z), 0.0), 1.0));
    vs /= std::sqrt(glm::dot(vs, vs));
    const double rho2 = vs.x * vs.x + vs.y * vs.y, rho = std::sqrt(rho2);
    const double opz = 1.0 + vs.z, omz = rho2 / opz, w = 1.0 - double(u.y);
    const double sin_c = std::sqrt(std::fmax(double(u.y) * opz * (omz + w * opz), 0.0));
    const double q = vs.z < 0.5 ? w - vs.z * (1.0 + double(u.y)) : omz - double(u.y) * opz;
    const double rms = rho + sin_c > 0.0 ? opz * w * q / (rho + sin_c) : 0.0;
    const double psi = 2.0 * ibl::pi_v<double> * (double(u.x) - 0.5), sh = std::sin(0.5 * psi);
    const double x1 = rms + 2.0 * sin_c * sh * sh, x2 = -sin_c * std::sin(psi), z = w * opz;
    const double hs_len = std::sqrt(x1 * x1 + x2 * x2 + z * z);
    const double p_len = std::sqrt(a * a * (x1 * x1 + x2 * x2) + z * z);
    const double dp = trig_eps * (4.0 * sin_c * std::fabs(sh) + sin_c) + 1e-5 * hs_len;
    return dp / p_len + 1e-5;
}

/// fis_tap's body from a given half vector h (double): what fis_tap makes of h, so that the
/// effect of an error in h on the tap is measurable. The reference checks it reproduces fis_tap.
template <class T> ibl::runtime_tap<T> tap_from_h(const ibl::frame<T>& fr, const vec3<T>& vl, T roughness, const vec3<T>& h,
                                                  std::uint32_t count, T c, const vec3<T>& f0, const vec3<T>& f90) {
    ibl::runtime_tap<T> t;
    const T alpha = ibl::clamp_alpha(ibl::alpha_from_roughness(roughness));
    const T v_dot_h = glm::dot(vl, h);
    const vec3<T> l = T(2) * v_dot_h * h - vl;
    t.dir = fr.to_world(l);
    if (!(l.z > T(0)) || !(v_dot_h > T(0))) return t;
    const T pdf = ibl::ggx_vndf_reflected_pdf(vl, h, alpha);
    t.roughness = pdf > T(0) ? ibl::fis_footprint_roughness(c / (T(count) * pdf)) : T(1);
    t.weight = ibl::fresnel_schlick(ibl::saturate(v_dot_h), f0, f90) * ibl::g2_over_g1_height_correlated(vl.z, l.z, alpha);
    return t;
}

template <class T> vec3<T> to_d(const vec3<float>& a) { return vec3<T>(T(a.x), T(a.y), T(a.z)); }

/// The spread of f(h') over h' = normalize(h +- dh e_k) (k = x, y, z): per output value, the root
/// sum of squares of the larger change along each axis (a first-order bound of |grad f| dh that
/// also catches a discontinuity, e.g. the horizon clip, within dh).
template <class F> v4 spread(const v3d& h, double dh, F&& f) {
    const ibl::vec4<double> f0 = f(h);
    ibl::vec4<double> acc(0.0);
    for (int k = 0; k < 3; ++k) {
        ibl::vec4<double> m(0.0);
        for (double sg : {-1.0, 1.0}) {
            v3d e(0.0);
            e[k] = sg * dh;
            const ibl::vec4<double> d = glm::abs(f(glm::normalize(h + e)) - f0);
            m = glm::max(m, d);
        }
        acc += m * m;
    }
    return v4(glm::sqrt(acc));
}

/// The VNDF row's per-value bound: the spread of (h, pdf) over the error of h.
v4 vndf_bound(int i) {
    const v3 v = vndf_v(i);
    const auto u = vndf_u(i);
    const float alpha = vndf_alpha(i);
    const v3 h = ibl::sample_ggx_vndf(v, u, alpha);
    const double dh = vndf_dh(v, u, alpha);
    return spread(to_d<double>(h), dh, [&](const v3d& hh) {
        return ibl::vec4<double>(hh, ibl::ggx_vndf_reflected_pdf(to_d<double>(v), hh, double(alpha)));
    });
}

/// The tap rows' taps: k = i mod 8 of 8, roughness 0.125 (1 + i / 8), c = 1, F0 (0.04, 0.5, 1), F90 1.
struct tap_case {
    ibl::frame<float> fr;
    v3 vl, f0, f90;
    float r;
    std::uint32_t k, count;
};
tap_case tap_case_of(int i) {
    tap_case c;
    c.fr = ibl::make_frame(fis_n(i));
    c.vl = fis_view_local(c.fr, fis_v(i));
    c.r = 0.125f * float(1 + i / 8);
    c.k = std::uint32_t(i % 8);
    c.count = 8;
    c.f0 = v3(0.04f, 0.5f, 1.0f);
    c.f90 = v3(1.0f);
    return c;
}

/// A tap's bound: the spread of (dir, roughness) and of weight over the error of its h.
void tap_bounds(const ibl::frame<float>& fr, const v3& vl, float r, std::uint32_t k, std::uint32_t count, float c,
                const v3& f0, const v3& f90, v4& b_dir, v4& b_w) {
    const float alpha = ibl::clamp_alpha(ibl::alpha_from_roughness(r));
    const auto u = ibl::fis_tap_point<float>(k, count);
    const v3 h = ibl::sample_ggx_vndf(vl, u, alpha);
    const double dh = vndf_dh(vl, u, alpha);
    const ibl::frame<double> frd{to_d<double>(fr.t), to_d<double>(fr.b), to_d<double>(fr.n)};
    auto tap = [&](const v3d& hh) {
        return tap_from_h<double>(frd, to_d<double>(vl), double(r), hh, count, double(c), to_d<double>(f0), to_d<double>(f90));
    };
    b_dir = spread(to_d<double>(h), dh, [&](const v3d& hh) {
        const auto t = tap(hh);
        return ibl::vec4<double>(t.dir, t.roughness);
    });
    b_w = spread(to_d<double>(h), dh, [&](const v3d& hh) { return ibl::vec4<double>(tap(hh).weight, 0.0); });
}

/// |change| of the chain lookup over a direction error dd (+- along each axis, renormalised) and a
/// roughness error dr (root sum of squares of the larger change per axis, per channel).
v3 lookup_spread(const v3& dir, float r, double dd, double dr, const ibl::specular_lookup_desc& sd) {
    const auto& chain = fixture_chain();
    const v3 l0 = ibl::specular_lookup(chain, dir, r, sd);
    v3d acc(0.0);
    for (int k = 0; k < 4; ++k) {
        v3d m(0.0);
        for (float sg : {-1.0f, 1.0f}) {
            v3 d = dir;
            float rr = r;
            if (k < 3) d[k] += sg * float(dd);
            else rr = ibl::saturate(r + sg * float(dr));
            const v3 l1 = ibl::specular_lookup(chain, glm::normalize(d), rr, sd);
            m = glm::max(m, glm::abs(to_d<double>(l1) - to_d<double>(l0)));
        }
        acc += m * m;
    }
    return v3(glm::sqrt(acc));
}

/// Floor of a lookup direction's error: the cube coordinates (sc / |ma|, then s N - 1/2) are
/// formed in float on both sides, a few ulp of each: 2^-20 covers them.
constexpr double dir_floor = 1.0 / 1048576.0;

/// The full-FIS rows' per-value bound: for each tap, its direction / roughness / weight errors
/// (tap_bounds) move its lookup by lookup_spread, and the combination turns them into
///   normalised: albedo (sum w dLD + sum dw |LD - Q|) / (sum w - sum dw),  Q = sum w LD / sum w
///   plain:      (sum w dLD + sum dw LD) / K
/// per channel (first order); a channel without weight uses the fallback lookup at R and r.
v4 fis_bound(int i, std::uint32_t taps, float c, bool normalise, bool textbook, float r, const v3& f0, const v3& f90,
             const ibl::vec2<float>& dfg) {
    const auto& chain = fixture_chain();
    const auto sd = chain_lookup(textbook);
    const ibl::frame<float> fr = ibl::make_frame(fis_n(i));
    const v3 vl = fis_view_local(fr, fis_v(i));
    v3d sum(0.0), wsum(0.0), dsum(0.0), dwsum(0.0);
    struct tap_rec {
        v3d ld, w, dw;
    };
    std::vector<tap_rec> rec;
    for (std::uint32_t k = 0; k < taps; ++k) {
        const auto t = ibl::fis_tap(fr, vl, r, k, taps, c, f0, f90);
        v4 bd, bw;
        tap_bounds(fr, vl, r, k, taps, c, f0, f90, bd, bw);
        const double dd = std::sqrt(double(bd.x) * bd.x + double(bd.y) * bd.y + double(bd.z) * bd.z) + dir_floor;
        const v3d dw = to_d<double>(v3(bw.x, bw.y, bw.z)) + 1e-5 * glm::abs(to_d<double>(t.weight));
        const v3d ld = to_d<double>(ibl::specular_lookup(chain, t.dir, t.roughness, sd));
        const v3d dld = to_d<double>(lookup_spread(t.dir, t.roughness, dd, double(bd.w) + 1e-5, sd)) + 1e-5 * ld;
        const v3d w = to_d<double>(t.weight);
        sum += w * ld;
        wsum += w;
        dsum += w * dld;
        dwsum += dw;
        rec.push_back({ld, w, dw});
    }
    const v3d albedo = to_d<double>(ibl::split_sum_albedo(f0, f90, dfg));
    v3d out(0.0);
    for (int ch = 0; ch < 3; ++ch) {
        if (!normalise) {
            double e = dsum[ch];
            for (const auto& t : rec) e += t.dw[ch] * t.ld[ch];
            out[ch] = e / double(taps);
        } else if (wsum[ch] > 0.0 && wsum[ch] > dwsum[ch]) {
            const double q = sum[ch] / wsum[ch];
            double e = dsum[ch];
            for (const auto& t : rec) e += t.dw[ch] * std::fabs(t.ld[ch] - q);
            out[ch] = albedo[ch] * e / (wsum[ch] - dwsum[ch]);
        } else if (wsum[ch] > 0.0) {
            out[ch] = 1e30; // the weights' errors swamp them: no bound (the row avoids this)
        } else {
            const v3 rd = fr.to_world(v3(-vl.x, -vl.y, vl.z));
            out[ch] = albedo[ch] * (double(lookup_spread(rd, r, dir_floor, 1e-5, sd)[ch]) +
                                    1e-5 * double(ibl::specular_lookup(chain, rd, r, sd)[ch]));
            out[ch] += dwsum[ch] > 0.0 ? 1e30 : 0.0; // a weight could be > 0 on the GPU
        }
    }
    return {v3(out), 0.0f};
}

/// The taps row's per-value bound: each table channel read within 1e-5 (the sampler coordinate,
/// formed with pow and a division, within a few ulp, times N = 4 texels, times neighbouring
/// channel differences < 1), each tap direction within 2 trig_eps + 1e-5 (cos, sin of float angles;
/// normalize) plus the angle's error: f acos(n.v) with f within 1e-5 and acos within trig_eps (as
/// sin and cos: Vulkan's atan2-derived bound) plus its response to n.v's rounding (a few ulp near
/// n.v = 1, where acos has a square root: sqrt(8 eps)), the roughness within 1e-5, and the combination as
/// in fis_bound (normalised); A, B within 1e-5 enter the albedo.
v4 taps_bound(int i, float r, const v3& f0, const v3& f90, bool textbook) {
    const auto& chain = fixture_chain();
    const auto& lut = fixture_taps();
    const auto sd = chain_lookup(textbook);
    const v3 n = fis_n(i), v = fis_v(i);
    const float n_dot_v = ibl::saturate(glm::dot(n, v));
    const v3 r_dir = 2.0f * glm::dot(n, v) * n - v;
    const auto st = ibl::dfg_lut_coord(n_dot_v, r, lut.size, ibl::dfg_lut_layout::remapped());
    float p[8] = {};
    ibl::detail::table_bilinear(lut, st.x, st.y, p, 8);
    const v3 t = ibl::incidence_tangent(n, r_dir);
    constexpr double dp = 1e-5;
    const double angle_err = std::max(std::fabs(double(p[2])), std::fabs(double(p[5]))) *
                                 (trig_eps + std::sqrt(8.0 * double(std::numeric_limits<float>::epsilon()))) +
                             std::acos(double(n_dot_v)) * dp;
    const double dd = 2.0 * trig_eps + 1e-5 + angle_err + dir_floor;
    v3d sum(0.0), dsum(0.0);
    double wsum = 0.0, dwsum = 0.0;
    std::vector<v3d> lds;
    std::vector<double> ws;
    for (int k = 0; k < 2; ++k) {
        const float a = ibl::lobe_tap_angle(p[2 + 3 * k], n_dot_v), w = p[4 + 3 * k];
        if (!(w > 0.0f)) {
            // a weight of 0 interpolated from non-zero texels (bilinear weight 0) may be read as
            // up to dp, with a lookup below 3.5 (the chain's largest channel)
            dwsum += dp;
            dsum += v3d(3.5 * dp);
            continue;
        }
        const v3 d = glm::normalize(std::cos(a) * n + std::sin(a) * t);
        const v3d ld = to_d<double>(ibl::specular_lookup(chain, d, p[3 + 3 * k], sd));
        sum += double(w) * ld;
        dsum += double(w) * (to_d<double>(lookup_spread(d, p[3 + 3 * k], dd, dp, sd)) + 1e-5 * ld);
        wsum += w;
        dwsum += dp;
        lds.push_back(ld);
        ws.push_back(w);
    }
    const v3d albedo = to_d<double>(ibl::split_sum_albedo(f0, f90, ibl::vec2<float>(p[0], p[1])));
    const v3d dalbedo = dp * (glm::abs(to_d<double>(f0)) + glm::abs(to_d<double>(f90)));
    if (!(wsum > 0.0)) {
        // the fallback: both weights read exactly 0 (texels whose weights are 0 on both sides)
        const v3d ld = to_d<double>(ibl::specular_lookup(chain, r_dir, r, sd));
        return {v3(albedo * (to_d<double>(lookup_spread(r_dir, r, dir_floor, 1e-5, sd)) + 1e-5 * ld) + dalbedo * ld), 0.0f};
    }
    const v3d q = sum / wsum;
    v3d e = dsum;
    for (std::size_t k = 0; k < lds.size(); ++k) e += dp * glm::abs(lds[k] - q);
    return {v3(albedo * e / (wsum - dwsum) + dalbedo * q), 0.0f};
}


/// The taps row's roughness: 0 at every fourth case (the mirror row of the table, where the
/// fallback is read at grazing views), else i / 64.
float taps_r(int i) { return i % 4 == 0 ? 0.0f : u64(i); }
ibl::vec2<float> fis_dfg(int i) { return {0.125f + float(i % 8) * 0.0625f, float(i / 8) * 0.03125f}; }
v3 fis_f0(int i) { return v3(0.04f + 0.0625f * float(i % 8), 0.5f, 1.0f); }

// ---- the occlusion rows (tools/viewer/numeric.frag.glsl: u_so) ----------------------------------

/// The occlusion rows' table: make_specular_occlusion_lut 8^3 with 32^2 VNDF points per (n.v, r)
/// cell (coarse, a few ms; the rows compare the reads, not the table's accuracy). It has the
/// near-mirror step, so neighbouring texels differ by up to ~1 and filtering errors show.
const ibl::specular_occlusion_lut& fixture_so() {
    static const ibl::specular_occlusion_lut lut = ibl::make_specular_occlusion_lut(8, 32, ibl::serial_executor{});
    return lut;
}

/// The table rows' inputs (n.v, r, ao), column c of case i: c = 0, 1 between texels (multiples of
/// 1/64: never a texel centre k/7 but 0 and 1), c = 2 one axis at an edge (0 or 1), c = 3 one or
/// more axes outside [0, 1] (-0.25 or 1.5: clamped).
v3 so_point(int i, int c) {
    if (c == 0) return {u64(i), u64((17 * i + 5) % 64), u64((29 * i + 11) % 64)};
    if (c == 1) return {u64((41 * i + 7) % 64), u64((13 * i + 3) % 64), u64((7 * i + 1) % 64)};
    if (c == 2) {
        v3 p(u64((23 * i + 9) % 64), u64((37 * i + 2) % 64), u64((11 * i + 6) % 64));
        p[i % 3] = (i / 3) % 2 == 0 ? 0.0f : 1.0f;
        return p;
    }
    const float o = i % 2 == 0 ? -0.25f : 1.5f;
    v3 p(u64((19 * i + 4) % 64), u64((31 * i + 8) % 64), u64((43 * i + 10) % 64));
    if (i % 3 == 0) p.x = o;
    if (i % 5 < 2) p.y = o;
    if (i % 7 < 3) p.z = o;
    return p;
}

/// ibl_specular_occlusion_coord: (saturate(x) (size - 1) + 0.5) / size per axis, in float.
v3 so_coord(const v3& p, int size) {
    const float s = float(size - 1), n = float(size);
    return {(ibl::saturate(p.x) * s + 0.5f) / n, (ibl::saturate(p.y) * s + 0.5f) / n, (ibl::saturate(p.z) * s + 0.5f) / n};
}

float so_read(float n_dot_v, float r, float ao) {
    return ibl::specular_occlusion_lookup(fixture_so(), n_dot_v, r, ao);
}

/// The bent-normal reading (ibl::specular_occlusion_bent, in float): so(saturate(b.R), r,
/// b.n > 0 ? min(1, ao / b.n) : 1), R = 2 (n.v) n - v. Also returns its table inputs.
float so_bent(const v3& n, const v3& v, const v3& b, float r, float ao, v3* at = nullptr) {
    const v3 rd = 2.0f * glm::dot(n, v) * n - v;
    const float b_r = ibl::saturate(glm::dot(b, rd)), b_n = glm::dot(b, n);
    const float a = b_n > 0.0f ? std::fmin(1.0f, ao / b_n) : 1.0f;
    if (at) *at = v3(b_r, r, a);
    return ibl::specular_occlusion_bent(fixture_so().data.data(), fixture_so().size, n, v, b, r, ao);
}

/// The bent row's column c of case i: n = dir_of(i), v = dir_of((7 i + 3) mod 64), r = i / 64;
/// c = 0: b = normalize(n + dir_of(63 - i) / 2), ao = ((13 i + 3) mod 64) / 64; c = 1: b = n (the
/// plain reading); c = 2: b = -n (b.n < 0: ao' = 1); c = 3: b of c = 0 with ao = 31/32 (ao / b.n >= 1
/// where b.n <= 31/32: ao' clamped to 1).
struct bent_case {
    v3 n, v, b;
    float r, ao;
};
bent_case bent_case_of(int i, int c) {
    bent_case k;
    k.n = dir_of(i);
    k.v = dir_of((7 * i + 3) % 64);
    k.r = u64(i);
    k.ao = c == 3 ? 0.96875f : u64((13 * i + 3) % 64);
    k.b = c == 1 ? k.n : (c == 2 ? -k.n : glm::normalize(k.n + 0.5f * dir_of(63 - i)));
    return k;
}

/// The filter probe's column a of case i: a texture coordinate whose texel-space position
/// s N - 1/2 is exact in float, fractional along axis a only (a = 3: along all three) by
/// f = ((4099 i) mod 2^16) / 2^16 (16 fraction bits: an 8-bit weight would be off by up to 2^-9).
v3 probe_texel(int i, int a) {
    const float f = float((4099 * i) % 65536) / 65536.0f, f2 = float((1237 * i + 77) % 65536) / 65536.0f,
                f3 = float((3011 * i + 5) % 65536) / 65536.0f;
    v3 t(float(i % 7), float((3 * i + 1) % 8), float((5 * i + 2) % 8));
    if (a < 3) {
        if (a != 0) t = v3(float((3 * i + 1) % 8), t.x, float((5 * i + 2) % 8));
        if (a == 2) t = v3(float((3 * i + 1) % 8), float((5 * i + 2) % 8), float(i % 7));
        t[a] += f;
    } else {
        t = v3(float(i % 7) + f, float((3 * i + 2) % 7) + f2, float((5 * i + 3) % 7) + f3);
    }
    return t; // texel-space position; the coordinate is (t + 1/2) / 8
}

/// Exact (double) trilinear value of the table at texel-space position t (clamped to the table).
double so_exact(const v3& t) {
    const auto& lut = fixture_so();
    const int n = int(lut.size);
    int i0[3];
    double f[3];
    for (int a = 0; a < 3; ++a) {
        const double x = std::fmin(std::fmax(double(t[a]), 0.0), double(n - 1));
        i0[a] = std::min(int(x), n - 2);
        f[a] = x - double(i0[a]);
    }
    double out = 0.0;
    for (int c = 0; c < 8; ++c) {
        const int d[3] = {c & 1, (c >> 1) & 1, (c >> 2) & 1};
        double w = 1.0;
        for (int a = 0; a < 3; ++a) w *= d[a] ? f[a] : 1.0 - f[a];
        out += w * double(lut.data[std::size_t(((i0[2] + d[2]) * n + (i0[1] + d[1])) * n + (i0[0] + d[0]))]);
    }
    return out;
}

/// The largest difference of neighbouring texels along each axis over the cells a read at
/// (n.v, r, ao) may use: the cell of specular_occlusion_table and, where a fraction lies within
/// 1e-3 of a cell boundary, the neighbouring cell (the GPU may round to it; the read is continuous).
v3d so_cell_diffs(const v3& p) {
    const auto& lut = fixture_so();
    const int n = int(lut.size);
    int lo[3], hi[3];
    for (int a = 0; a < 3; ++a) {
        const double x = double(ibl::saturate(p[a])) * double(n - 1);
        const int i = std::min(int(x), n - 2);
        const double f = x - double(i);
        lo[a] = f < 1e-3 && i > 0 ? i - 1 : i;
        hi[a] = f > 1.0 - 1e-3 && i < n - 2 ? i + 1 : i;
    }
    auto at = [&](int i, int j, int k) { return double(lut.data[std::size_t((k * n + j) * n + i)]); };
    v3d d(0.0);
    for (int k = lo[2]; k <= hi[2] + 1; ++k)
        for (int j = lo[1]; j <= hi[1] + 1; ++j)
            for (int i = lo[0]; i <= hi[0] + 1; ++i) {
                if (i <= hi[0]) d.x = std::fmax(d.x, std::fabs(at(i + 1, j, k) - at(i, j, k)));
                if (j <= hi[1]) d.y = std::fmax(d.y, std::fabs(at(i, j + 1, k) - at(i, j, k)));
                if (k <= hi[2]) d.z = std::fmax(d.z, std::fabs(at(i, j, k + 1) - at(i, j, k)));
            }
    return d;
}

/// Error of the GPU's filter fraction against the C++'s f = fl(x (N - 1)) - i (N = 8): the shader
/// forms s = (x (N - 1) + 1/2) / N (the product, possibly fused, and the sum each within half an
/// ulp of values < 8: 2^-22; the division by 8 is exact) and the texture unit s N - 1/2 (exact: the
/// operands share s N's ulp grid) and its fraction (exact). 2^-20 covers both with a factor 2.
/// The filter's own weights are taken as float (measured: the probe row).
constexpr double so_frac_eps = 1.0 / 1048576.0; // 2^-20

/// A table read's absolute bound at (n.v, r, ao) whose inputs carry absolute errors din: per axis
/// the largest texel difference times the fraction's error (so_frac_eps + (N - 1) din).
double so_bound(const v3& p, const v3d& din) {
    const v3d d = so_cell_diffs(p);
    double e = 0.0;
    for (int a = 0; a < 3; ++a) e += d[a] * (so_frac_eps + 7.0 * din[a]);
    return e;
}

v4 occlusion_row(int j, int i) {
    if (j == 28) {
        const v3 c = so_coord(so_point(i, 0), 8);
        return {c, so_coord(so_point(i, 3), 32).x};
    }
    if (j == 29) {
        v4 o;
        for (int c = 0; c < 4; ++c) {
            const v3 p = so_point(i, c);
            o[c] = so_read(p.x, p.y, p.z);
        }
        return o;
    }
    if (j == 30) {
        v4 o;
        for (int c = 0; c < 4; ++c) {
            const bent_case k = bent_case_of(i, c);
            o[c] = so_bent(k.n, k.v, k.b, k.r, k.ao);
        }
        return o;
    }
    if (j == 31) {
        v4 o;
        for (int a = 0; a < 4; ++a) o[a] = float(so_exact(probe_texel(i, a)));
        return o;
    }
    return v4(0.0f);
}

/// The occlusion rows' per-value absolute bounds (the 1e-6 arithmetic floor plus what the
/// fraction's error makes of the texel differences; the bent row adds its inputs' errors: b.R
/// and b.n are dots of unit vectors formed in float on both sides, within 2^-21, and ao / b.n
/// carries 2^-21 / b.n relative plus the division's 2^-22).
bool occlusion_abs_bound(int j, int i, v4& out) {
    if (j == 29) {
        for (int c = 0; c < 4; ++c) out[c] = float(1e-6 + so_bound(so_point(i, c), v3d(0.0)));
        return true;
    }
    if (j == 30) {
        for (int c = 0; c < 4; ++c) {
            const bent_case k = bent_case_of(i, c);
            v3 at;
            so_bent(k.n, k.v, k.b, k.r, k.ao, &at);
            const float b_n = glm::dot(k.b, k.n);
            const double eps = std::ldexp(1.0, -21);
            const double da = b_n > 0.0f && at.z < 1.0f ? double(at.z) * (eps / double(b_n) + eps / 2.0) : 0.0;
            out[c] = float(1e-6 + so_bound(at, v3d(eps, 0.0, da)));
        }
        return true;
    }
    return false;
}

/// The probe row's texel differences along its fractional axis (run_browser_test.py divides the
/// error by them: the filter's effective weight error); column 3 (all axes) reports 0.
double probe_dt(int i, int a) {
    if (a == 3) return 0.0;
    v3 t0 = probe_texel(i, a), t1 = t0;
    t0[a] = std::floor(t0[a]);
    t1[a] = t0[a] + 1.0f;
    return so_exact(t1) - so_exact(t0);
}

v4 runtime_row(int j, int i) {
    if (j >= 28) return occlusion_row(j, i);
    const float x = u64(i);
    if (j == 18) {
        const v3 g = dir_of(63 - i) * v3(1.0f, -1.0f, 1.0f);
        return {ibl::dominant_lerp_frostbite(x), ibl::horizon_fade(dir_of(i), g),
                ibl::specular_occlusion_lagarde(1.0f - x, float(i % 8) * 0.125f, x),
                ibl::specular_occlusion_lagarde(x, float(i / 8) * 0.125f + 0.0625f, 1.0f - x)};
    }
    if (j == 19) {
        const auto tp = ibl::fis_tap_point<float>(std::uint32_t(i), std::uint32_t(8 + i % 24));
        return {ibl::g2_over_g1_height_correlated(1.0f - x, float(i % 8) * 0.125f, x), ibl::fis_footprint_roughness(4.0f * x),
                tp.x, tp.y};
    }
    if (j == 20) { // sin / cos at the VNDF row's azimuths and at angles x pi/2 (double reference)
        const auto u = vndf_u(i);
        const float psi = ibl::two_pi_v<float> * (u.x - 0.5f), a = x * ibl::half_pi_v<float>;
        return v4(ibl::vec4<double>(std::sin(double(0.5f * psi)), std::sin(double(psi)), std::cos(double(a)),
                                    std::sin(double(a))));
    }
    if (j == 21) {
        const v3 v = vndf_v(i);
        const v3 h = ibl::sample_ggx_vndf(v, vndf_u(i), vndf_alpha(i));
        return {h, ibl::ggx_vndf_reflected_pdf(v, h, vndf_alpha(i))};
    }
    if (j == 22 || j == 23) {
        const tap_case c = tap_case_of(i);
        const auto t = ibl::fis_tap(c.fr, c.vl, c.r, c.k, c.count, 1.0f, c.f0, c.f90);
        return j == 22 ? v4(t.dir, t.roughness) : v4(t.weight, 0.0f);
    }
    if (j == 24 || j == 25) { // specular_fis on the fixture chain: normalised 8 taps textbook / plain 16 taps default, c = 2
        ibl::runtime_fis_desc d;
        d.taps = j == 24 ? 8u : 16u;
        d.footprint_scale = j == 24 ? 1.0f : 2.0f;
        d.normalise = j == 24;
        d.lookup = chain_lookup(j == 24);
        return {ibl::specular_fis(fixture_chain(), d, fis_n(i), fis_v(i), x, fis_f0(i), v3(1.0f), fis_dfg(i)), 0.0f};
    }
    if (j == 26)
        return {ibl::specular_lobe_taps(fixture_chain(), chain_lookup(false), fixture_taps(), fis_n(i),
                                        fis_v(i), taps_r(i), fis_f0(i), v3(1.0f)),
                0.0f};
    if (j == 27) { // incidence tangent; every fourth case R = n (the frame's tangent)
        const v3 n = dir_of(i), r = i % 4 == 0 ? n : dir_of(63 - i);
        return {ibl::incidence_tangent(n, r), 0.0f};
    }
    return v4(0.0f);
}

// ---- the local-probe rows (tools/viewer/numeric.frag.glsl: probe_room, probe_point, probe_dir) ----
ibl::probe_box<float> probe_room() { return ibl::probe_box<float>::axis_aligned(v3(-2.0f, -1.0f, -1.5f), v3(2.5f, 1.5f, 3.0f)); }
v3 probe_point(int i) { return v3(float(i % 8) * 0.5f - 1.75f, float(i / 8) * 0.25f - 0.875f, float(i % 5) * 0.5f - 1.0f); }
v3 probe_dir(int i) { return dir_of(i) * v3(i % 2 == 1 ? 1.0f : -1.0f, i % 3 == 0 ? -1.0f : 1.0f, 1.0f); }

v4 local_probe_row(int j, int i) {
    const float x = u64(i);
    const ibl::probe_box<float> b = probe_room();
    const v3 c(0.25f, 0.5f, -0.25f), p = probe_point(i), r = probe_dir(i);
    if (j == 32) {
        const ibl::parallax_lookup<float> l = ibl::parallax_correct(b, c, p, r);
        const ibl::parallax_tap<float> tap = ibl::parallax_split_tap(b, c, p, r, x, i % ibl::parallax_split_taps);
        const v3 d = l.direction + 0.5f * tap.direction;
        return {d.x, d.y, d.z, l.d_shading + tap.roughness};
    }
    const ibl::probe_sphere<float> sph{v3(0.25f, 0.0f, 0.5f), 3.0f};
    const ibl::parallax_lookup<float> s = ibl::parallax_correct(sph, c, p, r);
    const float w[4] = {ibl::influence_weight(b, 0.5f, p), ibl::influence_weight(sph, 0.75f, p), x, 1.0f - x};
    const int pr[4] = {i % 3, 1, 0, i % 2};
    float contrib[4];
    const float fb = ibl::blend_probe_weights(w, pr, 4, contrib);
    const float ro = ibl::corrected_roughness(x, ibl::parallax_correct(b, c, p, r)) + ibl::corrected_roughness(1.0f - x, s);
    return {ibl::corrected_roughness(x, s.d_shading, s.d_probe), s.d_probe + ro, fb, contrib[0] + 2.0f * contrib[1]};
}

v4 row_value(int j, int i) {
    if (j >= 32) return local_probe_row(j, i);
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
        const auto a = ibl::dfg_lut_coord(x, r, 128u, ibl::dfg_lut_layout::remapped());
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
    if (j >= 18) return runtime_row(j, i);
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


/// The runtime rows' per-value absolute bounds (replacing the row's abs; the 1e-5 relative term
/// stays): the arithmetic's 1e-6 plus what the errors of sin and of the inputs become (above).
bool runtime_abs_bound(int j, int i, v4& out) {
    if (j >= 28) return occlusion_abs_bound(j, i, out);
    const v4 base(1e-6f);
    if (j == 21) {
        out = base + vndf_bound(i);
        return true;
    }
    if (j == 22 || j == 23) {
        const tap_case c = tap_case_of(i);
        v4 bd, bw;
        tap_bounds(c.fr, c.vl, c.r, c.k, c.count, 1.0f, c.f0, c.f90, bd, bw);
        out = base + (j == 22 ? bd : bw);
        return true;
    }
    if (j == 24 || j == 25) {
        out = base + fis_bound(i, j == 24 ? 8u : 16u, j == 24 ? 1.0f : 2.0f, j == 24, j == 24, u64(i), fis_f0(i), v3(1.0f),
                               fis_dfg(i));
        return true;
    }
    if (j == 26) {
        out = base + taps_bound(i, taps_r(i), fis_f0(i), v3(1.0f), false);
        return true;
    }
    if (j == 27) { // t = normalize(R - (n.R) n): an error 2^-21 of the unit inputs over |R - (n.R) n|
        const v3 n = dir_of(i), r = i % 4 == 0 ? n : dir_of(63 - i);
        const v3 t = r - glm::dot(n, r) * n;
        const float len = std::sqrt(glm::dot(t, t));
        out = base + v4(len > 1e-6f ? float(std::ldexp(1.0, -21)) / len : 0.0f);
        return true;
    }
    return false;
}

/// The fixtures as JSON for the page (run_browser_test.py serves them): the chain's levels (faces
/// +X..-Z, rows from t = 0, RGB), the two RGBA halves of the taps table and the occlusion table
/// (size^3 floats in specular_occlusion_lut's order: x = n.v fastest, then r, then ao).
void print_fixtures() {
    const auto& chain = fixture_chain();
    std::printf("{\"chain\": [");
    for (int l = 0; l < chain.levels(); ++l) {
        const int n = chain.size(l);
        std::printf("%s{\"size\": %d, \"faces\": [", l ? ", " : "", n);
        for (int f = 0; f < 6; ++f) {
            std::printf("%s[", f ? ", " : "");
            for (int y = 0; y < n; ++y)
                for (int x = 0; x < n; ++x) {
                    const v3 t = chain.texel(f, x, y, l);
                    std::printf("%s%.9g, %.9g, %.9g", x || y ? ", " : "", double(t.x), double(t.y), double(t.z));
                }
            std::printf("]");
        }
        std::printf("]}");
    }
    const auto& lut = fixture_taps();
    std::printf("], \"taps\": {\"size\": %u, \"a\": [", lut.size);
    for (int half = 0; half < 2; ++half) {
        if (half) std::printf("], \"b\": [");
        for (std::uint32_t k = 0; k < lut.size * lut.size; ++k)
            for (int c = 0; c < 4; ++c)
                std::printf("%s%.9g", k || c ? ", " : "", double(lut.data[k * 8 + std::size_t(4 * half + c)]));
    }
    const auto& so = fixture_so();
    std::printf("]}, \"so\": {\"size\": %u, \"data\": [", so.size);
    for (std::size_t k = 0; k < so.data.size(); ++k) std::printf("%s%.9g", k ? ", " : "", double(so.data[k]));
    std::printf("]}}\n");
}

/// The prefilter test's fixtures (tools/viewer/prefilter.frag.glsl, ibl_prefilter.glsl): the default
/// sky baked to 64^2 (level 0 as "source"), split by the fast filter's peak split (split_cube_peaks:
/// its sun, 4 texels, leaves the tap set's source) and the split's base packed as the C++ kernel
/// reads it (detail::pack_cube, 256 texels per row), and per LD weight (n.l, g1) and convolved level
/// of the fast filter's chain (ibl::prefilter, method fast, default plan, peaks.cut = 0: every peak
/// in front of a row, the GPU's plain sum) its single-level taps as the kernel runs them
/// (make_ld_table_for + detail::make_taps), its merged peaks as the row kernel adds them
/// (make_peak_level: direction and pre-scaled energy, a2, the weight; 4 peaks at level 1, merged to
/// 2 from level 2), its spherical-harmonic texture when the level is reconstructed from the split's
/// base's projection (prefilter_options::sh_rough, on by default: ibl_prefilter_sh's coefficients,
/// norm and recurrence constants), the intermediate level its coarse tail reads where the level has
/// one (prefilter_options::mid_tail, forced here: its roughness, face and taps) and the chain's
/// texels (face, row, column) the GLSL must reproduce.
void print_prefilter_fixtures() {
    constexpr int size = 64, width = 256;
    const ibl::cubemap<float> src = ibl::bake_cubemap<float>(ibl::make_default_sky<float>(), size, 2);
    ibl::prefilter_options o;
    o.method = ibl::prefilter_method::fast;
    o.peaks.enabled = true;
    o.peaks.cut = 0.0; // every peak in front of some texel of a row: the GLSL's plain sum over the list
    // The intermediate coarse tail (mid_tail) forced on this small chain: by default it starts at a
    // 256^2 chain (the refilter test's --size 256 checks the default rule), and a 64^2 one puts it
    // on level 1 (r = 0.22 on a 16^2 face, its tail from level 2) when min_texels is 0.
    o.mid_tail.min_texels = 0.0;
    // What prefilter's cubemap source holds (detail::prefilter_cube_source): the split's base packed
    // when there are peaks, else the source.
    const ibl::cube_peak_split<float> split = ibl::split_cube_peaks(src, o.peaks, ibl::serial_executor{});
    const ibl::cubemap<float>& base = split.empty() ? src : split.base;
    const ibl::detail::packed_cube packed = ibl::detail::pack_cube(base);
    const std::size_t texels = packed.data.size() / 4, height = (texels + width - 1) / width;
    std::printf("{\"width\": %d, \"height\": %zu, \"size\": %d, \"source_peaks\": %zu, \"threshold\": %.17g, "
                "\"mean_luminance\": %.17g, \"packed\": [",
                width, height, size, split.peaks.size(), split.threshold, split.mean_luminance);
    for (std::size_t k = 0; k < width * height * 4; ++k)
        std::printf("%s%.9g", k ? ", " : "", k < packed.data.size() ? double(packed.data[k]) : 0.0);
    std::printf("], \"source\": ["); // level 0 of the source (face, row, column; RGB): the viewer's split reads it
    for (int f = 0; f < 6; ++f)
        for (int y = 0; y < size; ++y)
            for (int x = 0; x < size; ++x) {
                const ibl::vec3<float> v = src.texel(f, x, y, 0);
                std::printf("%s%.9g, %.9g, %.9g", f || y || x ? ", " : "", double(v.x), double(v.y), double(v.z));
            }
    std::printf("], \"levels\": [");
    bool first = true;
    // Both LD weights (the peak kernel's two forms), each a chain of its own.
    for (const ibl::ld_weight weight : {ibl::ld_weight::n_dot_l, ibl::ld_weight::g1}) {
        o.weight = weight;
        const ibl::specular_chain chain = ibl::prefilter(src, o, ibl::serial_executor{});
        const std::vector<ibl::prefilter_level> plan = ibl::prefilter_plan(o, size);
        // The levels by spherical harmonics (bake/prefilter_sh.hpp): the split's base projected as
        // prefilter_cube_source::sh_project does, onto the plan's most bands.
        const int max_bands = ibl::detail::prefilter_sh_max_bands<ibl::ggx_lobe>(o, plan);
        ibl::detail::sh_projection proj;
        std::vector<double> coefs, unit;
        if (max_bands > 0) {
            const int pl = ibl::detail::sh_projection_level(packed, max_bands);
            proj = ibl::detail::sh_projection(max_bands, pl, packed.levels[std::size_t(pl)].n);
            for (std::size_t row = 0; row < proj.rows(); ++row) proj.add_row(packed, row);
            coefs = proj.coefficients();
            unit = *ibl::detail::sh_unit_coefficients(proj);
        }
        for (std::size_t l = 0; l < plan.size(); ++l) {
            const ibl::prefilter_level& lp = plan[l];
            if (lp.level == 0) continue; // the mirror level is a copy
            // The coarse tail (prefilter_options::coarse_tail): the rest kernel's taps and the share of
            // the next level (the GPU reads its own next level before its peaks, as the C++ does).
            const double rn = ibl::detail::prefilter_tail_roughness<ibl::ggx_lobe>(o, plan, l, size, true);
            // With an intermediate level (rm >= 0) the level's tail reads it, and its own tap set has
            // prefilter_mid_own_samples; the intermediate level's taps (prefilter_mid_samples at rm,
            // its tail from the next level) are printed as the level's "mid".
            const double rm = ibl::detail::prefilter_mid_roughness<ibl::ggx_lobe>(o, plan, l, size, true);
            const double tail_r = rm >= 0.0 ? rm : rn;
            const std::uint32_t own = rm >= 0.0 ? ibl::detail::prefilter_mid_own_samples(o, lp.samples) : lp.samples;
            const ibl::detail::fast_coarse_tail tail =
                tail_r >= 0.0 ? ibl::detail::fast_tail_of<ibl::ggx_lobe>(lp.roughness, tail_r, o.weight) : ibl::detail::fast_coarse_tail{};
            const auto print_taps = [&](double r, std::uint32_t samples, double next_r) {
                ibl::sphere_sample_table<float> table =
                    ibl::make_ld_table_for<float>(src, r, samples, o.method, o.lod_bias, o.weight, next_r);
                table.trilinear = lp.trilinear;
                const ibl::detail::tap_table taps = ibl::detail::make_taps(table, int(packed.levels.size()));
                std::printf("\"count\": %zu, \"factor\": %.9g, \"taps\": [", taps.w.size(), double(taps.factor));
                for (std::size_t i = 0; i < taps.w.size(); ++i)
                    std::printf("%s%.9g, %.9g, %.9g, %.9g", i ? ", " : "", double(taps.x[i]), double(taps.y[i]),
                                double(taps.z[i]), double(taps.w[i]));
                std::printf("], \"info\": [");
                for (std::size_t i = 0; i < taps.w.size(); ++i) {
                    const ibl::detail::packed_cube::level& lv = packed.levels[std::size_t(taps.level[i])];
                    std::printf("%s%d, %d, %d, %d", i ? ", " : "", lv.n, lv.stride, lv.face_stride, lv.offset);
                }
                std::printf("]");
            };
            const int n = chain.size(int(l));
            std::printf("%s{\"level\": %d, \"n\": %d, \"roughness\": %.17g, \"plan_samples\": %u, \"samples\": %u, "
                        "\"trilinear\": %s, \"weight\": \"%s\", ",
                        first ? "" : ", ", int(l), n, lp.roughness, lp.samples, own, lp.trilinear ? "true" : "false",
                        o.weight == ibl::ld_weight::g1 ? "g1" : "nl");
            first = false;
            print_taps(lp.roughness, own, tail_r);
            if (rm >= 0.0) {
                const std::uint32_t ms = ibl::detail::prefilter_mid_samples(o, lp.samples);
                const ibl::detail::fast_coarse_tail mt = ibl::detail::fast_tail_of<ibl::ggx_lobe>(rm, rn, o.weight);
                std::printf(", \"mid\": {\"roughness\": %.17g, \"n\": %d, \"samples\": %u, \"next_roughness\": %.17g, "
                            "\"tail_share\": %.9g, ",
                            rm, chain.size(int(l) + 1), ms, rn, double(float(mt.share)));
                print_taps(rm, ms, rn);
                std::printf("}");
            }
            // The level's peaks as the row kernel adds them (prefilter_cube_source::level_peaks).
            const ibl::peak_level pl =
                split.empty() ? ibl::peak_level{}
                              : ibl::make_peak_level(split.peaks, size, base.levels(), lp.roughness, o.weight,
                                                     o.peaks.footprint, o.peaks.max_merge_angle, split.mean_luminance,
                                                     o.peaks.cut, o.peaks.max_level_peaks, o.peaks.max_level_steps);
            std::printf(", \"peak_count\": %zu, \"a2\": %.9g, \"g1\": %s, \"next_roughness\": %.17g, \"tail_share\": %.9g, "
                        "\"next_n\": %d",
                        pl.size(), double(pl.a2), pl.g1 ? "true" : "false", tail_r, double(float(tail.share)),
                        l + 1 < plan.size() ? chain.size(int(l) + 1) : 0);
            // A level by spherical harmonics: ibl_prefilter_sh's texture (pairs x 3 texels, row by row).
            const int bands = ibl::detail::prefilter_sh_bands<ibl::ggx_lobe>(o, lp);
            std::printf(", \"sh_bands\": %d, \"projection_bands\": %d, \"projection_face\": %d, \"sh\": [", bands, max_bands,
                        max_bands > 0 ? proj.face_size() : 0);
            if (bands > 0) {
                ibl::detail::sh_level sl, su;
                sl.bands = su.bands = bands;
                sl.rec = su.rec = ibl::detail::sh_recurrence(bands);
                const auto k = ibl::detail::lobe_band_factors<ibl::ggx_lobe>(lp.roughness, o.weight);
                sl.k.assign(k->begin(), k->begin() + bands);
                su.k = sl.k;
                sl.set_coefficients(coefs, max_bands);
                su.set_coefficients(unit, max_bands);
                const std::size_t pairs = ibl::detail::sh_pair_count(bands);
                std::vector<float> tex(pairs * 12, 0.f);
                std::size_t p = 0;
                for (int m = 0; m < bands; ++m)
                    for (int j = m; j < bands; ++j, ++p) {
                        for (std::size_t c = 0; c < 3; ++c) {
                            tex[4 * p + c] = sl.coef[6 * p + c];
                            tex[4 * (pairs + p) + c] = sl.coef[6 * p + 3 + c];
                        }
                        tex[4 * p + 3] = su.coef[6 * p];
                        tex[4 * (pairs + p) + 3] = su.coef[6 * p + 3];
                        const std::size_t r = 4 * (2 * pairs + p);
                        tex[r] = j > m ? sl.rec.a[std::size_t(j * bands + m)] : 1.f;
                        tex[r + 1] = j > m ? sl.rec.b[std::size_t(j * bands + m)] : 0.f;
                        tex[r + 2] = sl.rec.mm[std::size_t(m)];
                    }
                for (std::size_t i = 0; i < tex.size(); ++i) std::printf("%s%.9g", i ? ", " : "", double(tex[i]));
            }
            std::printf("], \"peaks\": [");
            for (std::size_t j = 0; j < pl.size(); ++j)
                std::printf("%s%.9g, %.9g, %.9g, %.9g, %.9g, %.9g", j ? ", " : "", double(pl.px[j]), double(pl.py[j]),
                            double(pl.pz[j]), double(pl.er[j]), double(pl.eg[j]), double(pl.eb[j]));
            std::printf("], \"expect\": [");
            for (int f = 0; f < 6; ++f)
                for (int y = 0; y < n; ++y)
                    for (int x = 0; x < n; ++x) {
                        const ibl::vec3<float> v = chain.texel(f, x, y, int(l));
                        std::printf("%s%.9g, %.9g, %.9g", f || y || x ? ", " : "", double(v.x), double(v.y), double(v.z));
                    }
            std::printf("]}");
        }
    }
    std::printf("]}\n");
}

int main(int argc, char** argv) {
    if (argc > 1 && std::strcmp(argv[1], "--fixtures") == 0) {
        print_fixtures();
        return 0;
    }
    if (argc > 1 && std::strcmp(argv[1], "--prefilter-fixtures") == 0) {
        print_prefilter_fixtures();
        return 0;
    }
    // tap_from_h (the tap rows' bounds perturb its h) must be fis_tap's body: same taps, bit for bit.
    for (int i = 0; i < width; ++i) {
        const tap_case c = tap_case_of(i);
        const float alpha = ibl::clamp_alpha(ibl::alpha_from_roughness(c.r));
        const v3 h = ibl::sample_ggx_vndf(c.vl, ibl::fis_tap_point<float>(c.k, c.count), alpha);
        const auto a = ibl::fis_tap(c.fr, c.vl, c.r, c.k, c.count, 1.0f, c.f0, c.f90);
        const auto b = tap_from_h<float>(c.fr, c.vl, c.r, h, c.count, 1.0f, c.f0, c.f90);
        if (!(a.dir == b.dir && a.weight == b.weight && a.roughness == b.roughness)) {
            std::fprintf(stderr, "glsl_reference: tap_from_h differs from ibl::fis_tap at case %d\n", i);
            return 1;
        }
    }
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
        {"frostbite, horizon, occlusion", 1e-5, 1e-6},
        {"g2/g1, footprint r, tap point", 1e-5, 1e-6},
        {"sin / cos (trig_eps)", 0.0, trig_eps},
        {"VNDF h + reflected pdf", 1e-5, 0.0},
        {"fis_tap dir + roughness", 1e-5, 0.0},
        {"fis_tap weight", 1e-5, 0.0},
        {"specular_fis (8, normalised)", 1e-5, 0.0},
        {"specular_fis (16, plain, c=2)", 1e-5, 0.0},
        {"specular_lobe_taps2", 1e-5, 0.0},
        {"incidence_tangent", 1e-5, 0.0},
        {"so coord (8, 32)", 1e-5, 1e-6},
        {"so table (8^3 R32F)", 1e-5, 0.0},
        {"so bent", 1e-5, 0.0},
        {"so filter probe (texel exact)", 1e-5, 1e-6},
        {"local probe: parallax", 1e-5, 1e-6},
        {"local probe: roughness, influence, blend", 1e-5, 1e-6},
    };
    const int n_rows = int(sizeof(rows) / sizeof(rows[0]));
    std::printf("{\"width\": %d, \"height\": %d, \"rows\": [", width, n_rows);
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
        v4 b;
        if (runtime_abs_bound(j, 0, b)) {
            std::printf(", \"abs_values\": [");
            for (int i = 0; i < width; ++i) {
                runtime_abs_bound(j, i, b);
                std::printf("%s[%.9g, %.9g, %.9g, %.9g]", i ? ", " : "", double(b.x), double(b.y), double(b.z), double(b.w));
            }
            std::printf("]");
        }
        if (j == 31) { // the filter probe's texel differences (run_browser_test.py: effective weight error)
            std::printf(", \"probe_dt\": [");
            for (int i = 0; i < width; ++i)
                std::printf("%s[%.9g, %.9g, %.9g, %.9g]", i ? ", " : "", probe_dt(i, 0), probe_dt(i, 1), probe_dt(i, 2),
                            probe_dt(i, 3));
            std::printf("]");
        }
        std::printf("}");
    }
    std::printf("]}\n");
    return 0;
}
