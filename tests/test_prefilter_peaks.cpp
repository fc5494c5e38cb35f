// bake/prefilter_peaks: the fast filter's peak split. The split conserves the source (base +
// peaks = source, at level 0 and on every mip), a source with no peaks filters exactly as without
// the split, one bright texel on a dark surround filters to the closed-form kernel (checked against
// an independent double-precision quadrature of the kernel), the sky with its sun filters within a
// percent of the exact LD where the tap set alone is tens of percent off, and the time-sliced
// update reproduces the split bit for bit, also after a source change.
#include <doctest/doctest.h>

#include <ibl/bake/prefilter.hpp>
#include <ibl/bake/prefilter_peaks.hpp>
#include <ibl/bake/prefilter_update.hpp>
#include <ibl/brdf/ggx.hpp>
#include <ibl/core/executor.hpp>
#include <ibl/env/analytic.hpp>
#include <ibl/env/convert.hpp>
#include <ibl/env/cubemap.hpp>
#include <ibl/reference/ld_irradiance.hpp>

#include <cmath>
#include <cstring>
#include <vector>

namespace {

ibl::prefilter_options fast_options(std::uint32_t samples = 0) {
    ibl::prefilter_options o;
    o.method = ibl::prefilter_method::fast;
    o.samples = samples;
    return o;
}

/// A uniform cube of radiance b with one texel of radiance p (face 4, texel (x, y)), mips built.
ibl::cubemap<float> point_light(int n, float b, float p, int x, int y) {
    ibl::cubemap<float> c(n);
    c.fill(0, [&](int f, int tx, int ty) { return ibl::vec3<float>(f == 4 && tx == x && ty == y ? p : b); });
    c.generate_mips();
    return c;
}

/// The LD kernel K(c) of GGX at roughness r with the n.l weight, in double from the NDF itself.
double kernel(double c, double r) {
    if (!(c > 0.0)) return 0.0;
    const double a = ibl::alpha_from_roughness(r);
    const ibl::vec3<double> h = glm::normalize(ibl::vec3<double>(std::sqrt(1.0 - c * c), 0.0, 1.0 + c));
    return 0.25 * ibl::ndf_ggx(h, a) * c;
}

/// Its integral over the hemisphere by the midpoint rule in theta (independent of the library's
/// radial CDF): 2 pi integral K(cos t) sin t dt, on a grid geometric near 0.
double kernel_integral(double r) {
    const int m = 200000;
    double acc = 0.0;
    const double lo = 1e-7, hi = 0.5 * 3.14159265358979323846;
    double prev = 0.0;
    for (int i = 0; i <= m; ++i) {
        const double t = i == 0 ? 0.0 : lo * std::pow(hi / lo, double(i) / m);
        if (i > 0) {
            const double tm = 0.5 * (t + prev);
            acc += kernel(std::cos(tm), r) * std::sin(tm) * (t - prev);
        }
        prev = t;
    }
    return 2.0 * 3.14159265358979323846 * acc;
}

} // namespace

TEST_CASE("peak split: base plus peaks is the source on every level; nothing above the threshold remains") {
    const ibl::cubemap<float> src = ibl::bake_cubemap<float>(ibl::make_default_sky<float>(), 64, 2);
    ibl::peak_split_options po;
    const ibl::cube_peak_split<float> s = ibl::split_cube_peaks(src, po);
    REQUIRE(!s.empty());
    CHECK(s.peaks.size() <= po.max_peaks);
    CHECK(s.threshold >= po.ratio * s.mean_luminance);
    for (int l = 0; l < src.levels(); ++l) {
        const int n = src.size(l);
        std::vector<ibl::vec3<double>> sum(std::size_t(6 * n * n));
        for (int f = 0; f < 6; ++f)
            for (int y = 0; y < n; ++y)
                for (int x = 0; x < n; ++x) {
                    sum[ibl::cube_texel_index(f, x, y, n)] = ibl::vec3<double>(s.base.texel(f, x, y, l)) *
                                                              ibl::cube_texel_solid_angle<double>(x, y, n);
                    if (l == 0) CHECK(double(ibl::luminance(s.base.texel(f, x, y, 0))) <= s.threshold * (1.0 + 1e-6));
                }
        for (const ibl::cube_peak& p : s.peaks) sum[ibl::cube_texel_index(p.face, p.x >> l, p.y >> l, n)] += p.energy;
        for (int f = 0; f < 6; ++f)
            for (int y = 0; y < n; ++y)
                for (int x = 0; x < n; ++x) {
                    const ibl::vec3<double> want =
                        ibl::vec3<double>(src.texel(f, x, y, l)) * ibl::cube_texel_solid_angle<double>(x, y, n);
                    const ibl::vec3<double> got = sum[ibl::cube_texel_index(f, x, y, n)];
                    for (int k = 0; k < 3; ++k) CHECK(got[k] == doctest::Approx(want[k]).epsilon(2e-5));
                }
    }
    // max_peaks bounds the count: the threshold rises to the (max_peaks + 1)-th brightest texel.
    po.max_peaks = 3;
    const ibl::cube_peak_split<float> few = ibl::split_cube_peaks(src, po);
    CHECK(few.peaks.size() <= 3);
    CHECK(few.threshold >= s.threshold);
}

TEST_CASE("peak split: a source with nothing above the threshold filters as without the split, bit for bit") {
    ibl::sky_environment<float> sky = ibl::make_default_sky<float>();
    sky.sun_radiance = ibl::vec3<float>(0.f);
    const ibl::cubemap<float> src = ibl::bake_cubemap<float>(sky, 32, 2);
    ibl::prefilter_options on = fast_options(16), off = on;
    off.peaks.enabled = false;
    REQUIRE(ibl::split_cube_peaks(src, on.peaks).empty());
    const ibl::specular_chain a = ibl::prefilter(src, on, ibl::serial_executor{});
    const ibl::specular_chain b = ibl::prefilter(src, off, ibl::serial_executor{});
    for (int l = 0; l < a.levels(); ++l)
        for (int f = 0; f < 6; ++f)
            for (int y = 0; y < a.size(l); ++y)
                for (int x = 0; x < a.size(l); ++x) {
                    const ibl::vec3<float> p = a.texel(f, x, y, l), q = b.texel(f, x, y, l);
                    CHECK(std::memcmp(&p, &q, sizeof p) == 0);
                }
}

TEST_CASE("peak split: one bright texel filters to the closed-form kernel around it") {
    constexpr int n = 64;
    const float b = 1.f, p = 4e4f;
    const ibl::cubemap<float> src = point_light(n, b, p, 20, 41);
    const ibl::vec3<double> d = glm::normalize(ibl::cube_texel_direction<double>(4, 20, 41, n));
    const double energy = double(p - b) * ibl::cube_texel_solid_angle<double>(20, 41, n);
    // With or without the coarse tail: the tail reads the next level without its peaks (the base is
    // uniform here), and every level adds the peaks through its own whole kernel, so the response
    // is the closed form either way (0.03-0.06 % relative RMS).
    for (const bool tail : {false, true}) {
        ibl::prefilter_options o = fast_options(16);
        o.levels = 4;
        o.coarse_tail = tail;
        const ibl::specular_chain chain = ibl::prefilter(src, o, ibl::serial_executor{});
        for (int l = 1; l < chain.levels(); ++l) {
            const double r = o.policy.roughness(double(l), chain.levels());
            const double norm = kernel_integral(r);
            const int m = chain.size(l);
            double e2 = 0.0, w2 = 0.0;
            for (int f = 0; f < 6; ++f)
                for (int y = 0; y < m; ++y)
                    for (int x = 0; x < m; ++x) {
                        const ibl::vec3<double> R = glm::normalize(ibl::cube_texel_direction<double>(f, x, y, m));
                        const double want = double(b) + energy * kernel(glm::dot(R, d), r) / norm;
                        const double got = double(chain.texel(f, x, y, l).y);
                        e2 += (got - want) * (got - want) / (want * want);
                        w2 += 1.0;
                    }
            CAPTURE(l);
            CAPTURE(tail);
            CHECK(std::sqrt(e2 / w2) < 0.01);
        }
    }
}

TEST_CASE("peak split: the sky with its sun within a few percent of the exact LD at 16 samples") {
    const ibl::sky_environment<double> sky = ibl::make_default_sky<double>();
    const ibl::cubemap<float> src = ibl::bake_cubemap<float>(sky, 64, 4);
    ibl::prefilter_options on = fast_options(16);
    on.sh_rough.enabled = false; // the split's effect on the tap sets (tests/test_prefilter_sh.cpp: the levels by SH)
    ibl::prefilter_options off = on;
    off.peaks.enabled = false;
    const ibl::specular_chain a = ibl::prefilter(src, on, ibl::thread_executor{2});
    const ibl::specular_chain c = ibl::prefilter(src, off, ibl::thread_executor{2});
    for (int l = 1; l < a.levels(); ++l) {
        const double r = on.policy.roughness(double(l), a.levels());
        double ea = 0.0, ec = 0.0, s = 0.0;
        for (int k = 0; k < 64; ++k) {
            const double z = 1.0 - 2.0 * (k + 0.5) / 64, ph = 2.399963229728653 * k, q = std::sqrt(1.0 - z * z);
            const ibl::vec3<double> dir(q * std::cos(ph), z, q * std::sin(ph));
            const ibl::cube_coord<double> cc = ibl::cube_lookup(dir);
            const int m = a.size(l), x = std::min(int(cc.s * m), m - 1), y = std::min(int(cc.t * m), m - 1);
            const ibl::vec3<double> R = glm::normalize(ibl::cube_texel_direction<double>(cc.face, x, y, m));
            const double ref = ibl::reference_ld_sky(sky, R, r, 2048, 64).y;
            ea += std::pow(double(a.texel(cc.face, x, y, l).y) - ref, 2.0);
            ec += std::pow(double(c.texel(cc.face, x, y, l).y) - ref, 2.0);
            s += ref * ref;
        }
        CAPTURE(l);
        CAPTURE(std::sqrt(ec / s));
        CHECK(std::sqrt(ea / s) < 0.03);
        CHECK(std::sqrt(ea / s) < 0.5 * std::sqrt(ec / s));
    }
}

TEST_CASE("peak split: the time-sliced update gives the same bits, also after a source change; G1 weight") {
    const ibl::cubemap<float> a = ibl::bake_cubemap<float>(ibl::make_default_sky<float>(), 16, 2);
    const ibl::cubemap<float> b = point_light(16, 0.5f, 3e3f, 3, 12);
    ibl::prefilter_options o = fast_options(16);
    o.weight = ibl::ld_weight::g1;
    REQUIRE(!ibl::split_cube_peaks(a, o.peaks).empty());
    ibl::prefilter_update<> up(a, o);
    up.finish(ibl::serial_executor{});
    up.set_source(b);
    while (!up.done()) up.step(500, ibl::thread_executor{2});
    const ibl::specular_chain ref = ibl::prefilter(b, o, ibl::serial_executor{});
    REQUIRE(up.result().has_value());
    for (int l = 0; l < ref.levels(); ++l)
        for (int f = 0; f < 6; ++f)
            for (int y = 0; y < ref.size(l); ++y)
                for (int x = 0; x < ref.size(l); ++x) {
                    const ibl::vec3<float> p = ref.texel(f, x, y, l), q = up.result()->texel(f, x, y, l);
                    CHECK(std::memcmp(&p, &q, sizeof p) == 0);
                }
}

TEST_CASE("peak split: merge keeps the energy; the merge mip follows the kernel's width") {
    const ibl::cubemap<float> src = ibl::bake_cubemap<float>(ibl::make_default_sky<float>(), 64, 2);
    const ibl::cube_peak_split<float> s = ibl::split_cube_peaks(src, ibl::peak_split_options{});
    REQUIRE(!s.empty());
    ibl::vec3<double> total(0.0);
    for (const ibl::cube_peak& p : s.peaks) total += p.energy;
    for (int mip = 0; mip < 4; ++mip) {
        ibl::vec3<double> merged(0.0);
        const std::vector<ibl::cube_peak> m = ibl::merge_cube_peaks(s.peaks, mip);
        CHECK(m.size() <= s.peaks.size());
        for (const ibl::cube_peak& p : m) {
            merged += p.energy;
            CHECK(glm::length(p.dir) == doctest::Approx(1.0).epsilon(1e-5));
        }
        for (int k = 0; k < 3; ++k) CHECK(merged[k] == doctest::Approx(total[k]).epsilon(1e-12));
    }
    // FWHM of the GGX LD kernel: K at half the width is half of K at 0 (n.l aside).
    for (const double r : {0.2, 0.4, 0.6}) {
        const double half = 0.5 * ibl::ggx_ld_fwhm(r);
        const double ratio = kernel(std::cos(half), r) / std::cos(half) / (kernel(1.0, r) / 1.0);
        CHECK(ratio == doctest::Approx(0.5).epsilon(1e-6));
    }
    CHECK(ibl::peak_merge_mip(0.2, 256, 8, 6.0, 1.0 / 16.0) == 1);
    CHECK(ibl::peak_merge_mip(1.0, 256, 8, 6.0, 1.0 / 16.0) == 1 + ibl::peak_merge_mip(1.0, 128, 8, 6.0, 1.0 / 16.0));
}

TEST_CASE("peak split: the packed patch equals packing the split's base cube, bit for bit") {
    for (const int n : {64, 32}) {
        // Bright texels scattered over every face, on the edges and at the corners too.
        ibl::cubemap<float> src(n);
        src.fill(0, [&](int f, int x, int y) {
            const unsigned h = (unsigned(f) * 73856093u) ^ (unsigned(x) * 19349663u) ^ (unsigned(y) * 83492791u);
            const bool edge = x == 0 || y == 0 || x == n - 1 || y == n - 1;
            const bool bright = (h % 97u) == 0u || (edge && (h % 13u) == 0u) || ((x == 0 || x == n - 1) && (y == 0 || y == n - 1));
            return ibl::vec3<float>(bright ? 300.f + float(h % 7u) : 0.5f + 0.01f * float(h % 11u), 1.f, bright ? 200.f : 0.7f);
        });
        src.generate_mips();
        ibl::peak_split_options po;
        const ibl::cube_peak_split<float> s = ibl::split_cube_peaks(src, po);
        REQUIRE(s.peaks.size() > 24);
        ibl::detail::packed_cube patched = ibl::detail::pack_cube(src);
        REQUIRE(ibl::detail::patch_packed_peaks(patched, src, s.peaks, s.threshold));
        const ibl::detail::packed_cube want = ibl::detail::pack_cube(s.base);
        REQUIRE(patched.data.size() == want.data.size());
        CHECK(std::memcmp(patched.data.data(), want.data.data(), want.data.size() * sizeof(float)) == 0);
        const ibl::detail::packed_cube plain = ibl::detail::pack_cube(src);
        CHECK(std::memcmp(plain.data.data(), want.data.data(), want.data.size() * sizeof(float)) != 0);
    }
    // A chain whose mips do not nest (face 6 -> 3 -> 1) is refused: the prefilter packs the base cube.
    ibl::cubemap<float> odd(6);
    odd.fill(0, [](int f, int x, int y) { return ibl::vec3<float>(f == 1 && x == 2 && y == 3 ? 1e4f : 1.f); });
    odd.generate_mips();
    const ibl::cube_peak_split<float> so = ibl::split_cube_peaks(odd, ibl::peak_split_options{});
    REQUIRE(!so.empty());
    ibl::detail::packed_cube po = ibl::detail::pack_cube(odd);
    CHECK_FALSE(ibl::detail::patch_packed_peaks(po, odd, so.peaks, so.threshold));
}

TEST_CASE("peak split: a level above max_level_peaks merges coarser, max_level_steps mips at most, keeping the energy; the row cut stays within its bound") {
    // A grey cube with an extended bright patch (1600 texels at 60 x the grey): about 1024 peaks.
    constexpr int n = 128;
    ibl::cubemap<float> src(n);
    src.fill(0, [&](int f, int x, int y) {
        const bool patch = f == 2 && x >= 30 && x < 70 && y >= 40 && y < 80;
        return ibl::vec3<float>(patch ? 60.f + 0.25f * float((x * 7 + y * 3) % 11) : 1.f, patch ? 55.f : 0.9f, 0.8f);
    });
    src.generate_mips();
    const ibl::peak_split_options po;
    const ibl::cube_peak_split<float> s = ibl::split_cube_peaks(src, po);
    REQUIRE(s.peaks.size() > 900); // at most max_peaks (ties at the threshold stay in the base)
    auto energy = [](const ibl::peak_level& pl) {
        double e = 0.0;
        for (std::size_t j = 0; j < pl.size(); ++j) e += double(pl.er[j]);
        return e;
    };
    const ibl::peak_level all = ibl::make_peak_level(s.peaks, n, src.levels(), 0.2, ibl::ld_weight::n_dot_l, po.footprint,
                                                     po.max_merge_angle, s.mean_luminance, po.cut, 0);
    const int mip = ibl::peak_merge_mip(0.2, n, src.levels() - 1, po.footprint, po.max_merge_angle);
    CHECK(all.size() == ibl::merge_cube_peaks(s.peaks, mip).size());
    CHECK(all.size() > 128);
    // above the cap with one step allowed: merged one mip coarser (and no further)
    const std::size_t coarser = ibl::merge_cube_peaks(s.peaks, mip + 1).size();
    for (const std::uint32_t cap : {128u, 16u}) {
        const ibl::peak_level pl = ibl::make_peak_level(s.peaks, n, src.levels(), 0.2, ibl::ld_weight::n_dot_l, po.footprint,
                                                        po.max_merge_angle, s.mean_luminance, po.cut, cap, 1);
        CHECK(pl.size() == coarser);
        CHECK(pl.size() < all.size());
        CHECK(energy(pl) == doctest::Approx(energy(all)).epsilon(1e-5));
    }
    // two steps (prefilter's default, max_level_steps): a second mip coarser while still above the cap
    const std::size_t two = ibl::merge_cube_peaks(s.peaks, mip + 2).size();
    REQUIRE(coarser > 16);
    const ibl::peak_level pl16 = ibl::make_peak_level(s.peaks, n, src.levels(), 0.2, ibl::ld_weight::n_dot_l, po.footprint,
                                                      po.max_merge_angle, s.mean_luminance, po.cut, 16, po.max_level_steps);
    CHECK(po.max_level_steps == 2);
    CHECK(pl16.size() == two);
    CHECK(energy(pl16) == doctest::Approx(energy(all)).epsilon(1e-5));
    const ibl::peak_level pl_cap = ibl::make_peak_level(s.peaks, n, src.levels(), 0.2, ibl::ld_weight::n_dot_l, po.footprint,
                                                        po.max_merge_angle, s.mean_luminance, po.cut, std::uint32_t(coarser), 2);
    CHECK(pl_cap.size() == coarser); // at the cap after one step: no second
    const ibl::peak_level roomy = ibl::make_peak_level(s.peaks, n, src.levels(), 0.2, ibl::ld_weight::n_dot_l, po.footprint,
                                                       po.max_merge_angle, s.mean_luminance, po.cut, std::uint32_t(all.size()));
    CHECK(roomy.size() == all.size()); // at the cap: the footprint rule's merge
    // A rough level merges at max_merge_angle already: never coarser, whatever the cap.
    const int rough_mip = ibl::peak_merge_mip(1.0, n, src.levels() - 1, po.footprint, po.max_merge_angle);
    const ibl::peak_level rough = ibl::make_peak_level(s.peaks, n, src.levels(), 1.0, ibl::ld_weight::n_dot_l, po.footprint,
                                                       po.max_merge_angle, s.mean_luminance, po.cut, 1);
    CHECK(rough.size() == ibl::merge_cube_peaks(s.peaks, rough_mip).size());
    CHECK(2.0 / double(n >> (rough_mip + 1)) > po.max_merge_angle);
    // The row cut: against every peak added (cut = 0), each texel's luminance is lower by at most
    // cut times the larger of its row's darkest texel and 1e-2 of the mean luminance.
    ibl::prefilter_options on = fast_options(16), exact = fast_options(16);
    exact.peaks.cut = 0.0;
    const ibl::specular_chain a = ibl::prefilter(src, on, ibl::serial_executor{});
    const ibl::specular_chain b = ibl::prefilter(src, exact, ibl::serial_executor{});
    int differ = 0;
    double worst = 0.0;
    for (int l = 1; l < a.levels(); ++l) {
        const int m = a.size(l);
        for (int f = 0; f < 6; ++f)
            for (int y = 0; y < m; ++y) {
                double darkest = 1e300;
                for (int x = 0; x < m; ++x) darkest = std::min(darkest, double(ibl::luminance(b.texel(f, x, y, l))));
                const double bound = on.peaks.cut * std::max(darkest, 1e-2 * s.mean_luminance);
                for (int x = 0; x < m; ++x) {
                    const double la = ibl::luminance(a.texel(f, x, y, l)), lb = ibl::luminance(b.texel(f, x, y, l));
                    differ += la != lb ? 1 : 0;
                    worst = std::max(worst, (lb - la) / bound);
                    CHECK(lb - la <= bound + 1e-5 * lb);
                    CHECK(la - lb <= 1e-5 * lb);
                }
            }
    }
    MESSAGE("row cut: " << differ << " texels differ, the largest by " << worst << " of the bound");
    CHECK(differ > 0); // the cut skipped something
}
