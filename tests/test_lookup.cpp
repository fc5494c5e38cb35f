// tests/test_lookup.cpp — the runtime lookups (ibl/runtime/lookup.hpp) and their error metrics
// (reference/lookup_error.hpp): hand cases of the specular taps (a level's own roughness returns
// that level, weights sum to 1, a constant environment is exact), the DFG layouts (texel centres
// return the texel, the remap's inverse, the uniform layout is dfg_lut.hpp's table), the default
// DFG layout's error on a dense grid against the exact quadrature, the half rounding, and the
// specular interpolation error on a smooth analytic environment whose LD has a closed form.

#include <doctest/doctest.h>

#include <ibl/brdf/model.hpp>
#include <ibl/reference/lookup_error.hpp>
#include <ibl/runtime/lookup.hpp>

#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

namespace {

using d3 = ibl::vec3<double>;
constexpr double feps = std::numeric_limits<float>::epsilon();

const ibl::specular_lookup_desc k_schemes[] = {
    ibl::specular_lookup_desc::textbook(),
    ibl::specular_lookup_desc::accurate(),
    {ibl::roughness_mapping::linear, ibl::level_weight::power, 3.0, ibl::level_interpolation::linear},
    {ibl::roughness_mapping::linear, ibl::level_weight::log, 1.0, ibl::level_interpolation::linear},
    {ibl::roughness_mapping::linear, ibl::level_weight::log, 1.0, ibl::level_interpolation::geometric},
    {ibl::roughness_mapping::linear, ibl::level_weight::lod, 1.0, ibl::level_interpolation::catmull_rom},
    {ibl::roughness_mapping::filament, ibl::level_weight::lod, 1.0, ibl::level_interpolation::linear},
    {ibl::roughness_mapping::filament, ibl::level_weight::log, 1.0, ibl::level_interpolation::catmull_rom},
};

/// A chain of face 32 and 6 levels whose texels differ everywhere (level, face, x, y all matter).
ibl::cubemap<float> distinct_chain() {
    ibl::cubemap<float> c(32, 6);
    for (int l = 0; l < c.levels(); ++l)
        c.fill(l, [&](int f, int x, int y) {
            return ibl::vec3<float>(float(1 + l) + 0.01f * float(f), 0.5f + 0.03f * float(x), 2.0f + 0.07f * float(y));
        });
    c.update_borders();
    return c;
}

} // namespace

TEST_CASE("specular taps: a level's own roughness gives that level, weights sum to 1") {
    for (const auto& d : k_schemes) {
        for (const int levels : {2, 3, 6, 9}) {
            const int m = levels - 1;
            for (int l = 0; l <= m; ++l) {
                const double r = ibl::roughness_from_lod(d.mapping, double(l), double(m));
                const ibl::specular_taps<double> s = ibl::specular_lookup_taps(r, levels, d);
                double on_level = 0.0, sum = 0.0;
                for (int k = 0; k < s.count; ++k) {
                    sum += s.weight[k];
                    if (s.level[k] == l) on_level += s.weight[k];
                }
                // r_l goes through roughness_from_lod and back through lod_from_roughness: exact for
                // the linear mapping, a few ulps for the filament one (a weight of a few eps).
                CHECK(on_level == doctest::Approx(1.0).scale(1).epsilon(1e-12));
                CHECK(sum == doctest::Approx(1.0).epsilon(1e-15));
            }
            for (int k = 0; k <= 100; ++k) {
                const ibl::specular_taps<double> s = ibl::specular_lookup_taps(0.01 * k, levels, d);
                double sum = 0.0;
                for (int q = 0; q < s.count; ++q) {
                    sum += s.weight[q];
                    CHECK(s.level[q] >= 0);
                    CHECK(s.level[q] <= m);
                }
                CHECK(sum == doctest::Approx(1.0).epsilon(1e-14));
            }
        }
    }
}

TEST_CASE("specular lookup: exact level at its roughness, constant environment exact") {
    const ibl::cubemap<float> c = distinct_chain();
    const ibl::vec3<float> dirs[] = {{0.3f, 0.8f, -0.52f}, {-1.0f, 0.0f, 0.0f}, {0.577f, 0.577f, 0.577f}};
    for (const auto& d : k_schemes) {
        for (int l = 0; l < c.levels(); ++l) {
            const float r = ibl::roughness_from_lod(d.mapping, float(l), float(c.levels() - 1));
            for (const auto& dir : dirs) {
                const ibl::vec3<float> a = ibl::specular_lookup(c, dir, r, d), b = c.bilinear(dir, l);
                // Filament: r_l in float and back leaves t of a few float ulps (weight ~ 1e-6 on a
                // neighbour level differing by 1): bound 4 eps x the level difference.
                for (int k = 0; k < 3; ++k) CHECK(double(a[k]) == doctest::Approx(double(b[k])).epsilon(4 * feps));
            }
        }
    }
    ibl::cubemap<float> one(16, 5);
    for (int l = 0; l < one.levels(); ++l) one.fill(l, [](int, int, int) { return ibl::vec3<float>(0.75f); });
    one.update_borders();
    for (const auto& d : k_schemes)
        for (int k = 0; k <= 20; ++k)
            for (const auto& dir : dirs) {
                const ibl::vec3<float> v = ibl::specular_lookup(one, dir, 0.05f * float(k), d);
                for (int q = 0; q < 3; ++q) CHECK(double(v[q]) == doctest::Approx(0.75).epsilon(2 * feps));
            }
    // A linear two-level lookup is the trilinear read at the lod it reports (what textureLod does).
    for (const auto& d : {k_schemes[0], k_schemes[2], k_schemes[3]})
    for (int k = 0; k <= 20; ++k) {
        const float r = 0.05f * float(k);
        const ibl::specular_taps<float> s = ibl::specular_lookup_taps(r, c.levels(), d);
        for (const auto& dir : dirs) {
            const ibl::vec3<float> a = ibl::specular_lookup(c, dir, r, d), b = c.radiance(dir, s.lod);
            for (int q = 0; q < 3; ++q) CHECK(double(a[q]) == doctest::Approx(double(b[q])).epsilon(4 * feps));
        }
    }
}

TEST_CASE("dfg layout: remap inverse, texel centres return the texel, uniform = dfg_lut.hpp") {
    const ibl::dfg_axis axes[] = {ibl::dfg_axis::linear, ibl::dfg_axis::sqrt, ibl::dfg_axis::cbrt};
    for (const auto a : axes)
        for (int k = 0; k <= 64; ++k) {
            const double c = k / 64.0;
            CHECK(ibl::dfg_axis_coord(a, ibl::dfg_axis_value(a, c)) == doctest::Approx(c).epsilon(1e-15));
        }
    for (const bool edge : {false, true})
        for (std::uint32_t i = 0; i < 16; ++i) {
            const double c = ibl::dfg_texel_coord<double>(i, 16, edge);
            CHECK(ibl::dfg_sampler_coord(c, 16u, edge) == doctest::Approx((i + 0.5) / 16.0).epsilon(1e-15));
        }
    // A table whose texels all differ; each layout's lookup at a texel's (n.v, r) returns it. The
    // coordinate goes through the float remap (cbrt, sqrt) and its inverse: a sampler position
    // off by a few ulps x N, i.e. a bilinear weight of ~ N eps on neighbours differing by <= 1.
    const std::uint32_t n = 16;
    ibl::dfg_lut lut{n, 2, std::vector<float>(n * n * 2)};
    for (std::uint32_t j = 0; j < n; ++j)
        for (std::uint32_t i = 0; i < n; ++i) {
            lut.data[(j * n + i) * 2] = float(i) / n;
            lut.data[(j * n + i) * 2 + 1] = float(j) / n + float(i) / (n * n);
        }
    const ibl::dfg_lut_layout layouts[] = {ibl::dfg_lut_layout::uniform(), ibl::dfg_lut_layout::remapped(),
                                           {ibl::dfg_axis::sqrt, ibl::dfg_axis::linear, false}};
    for (const auto& lay : layouts)
        for (std::uint32_t j = 0; j < n; ++j)
            for (std::uint32_t i = 0; i < n; ++i) {
                lut.layout = lay; // the lookup reads the table's own layout
                const float mu = ibl::dfg_texel_value<float>(lay.n_dot_v, i, n, lay.edge_aligned);
                const float r = ibl::dfg_texel_value<float>(lay.roughness, j, n, lay.edge_aligned);
                const ibl::vec3<float> v = ibl::dfg_lookup(lut, mu, r);
                CHECK(double(v.x) == doctest::Approx(lut.at(i, j, 0)).scale(1).epsilon(8 * n * feps));
                CHECK(double(v.y) == doctest::Approx(lut.at(i, j, 1)).scale(1).epsilon(8 * n * feps));
            }
    // The uniform layout's table and lookup are dfg_lut.hpp's, bit for bit.
    const ibl::dfg_lut a = ibl::make_dfg_lut_exact<ibl::ggx_height_correlated>(24, 3, ibl::dfg_lut_default_nodes, ibl::serial_executor{});
    const ibl::dfg_lut b = ibl::make_dfg_lut_exact<ibl::ggx_height_correlated>(24, ibl::dfg_lut_layout::uniform(), 3,
                                                                               ibl::dfg_lut_default_nodes, ibl::serial_executor{});
    CHECK(a.data == b.data);
    for (int k = 0; k <= 10; ++k) {
        const float mu = 0.1f * float(k), r = 1.0f - 0.1f * float(k);
        const ibl::vec3<float> x = a.sample(mu, r), y = ibl::dfg_lookup(b, mu, r);
        CHECK(x.x == y.x);
        CHECK(x.y == y.y);
        CHECK(x.z == y.z);
    }
}

TEST_CASE("dfg lookup: the remapped layout at 128^2 meets 1e-3 for r >= 0.05 (the uniform table does not)") {
    // Grid: n.v uniform and quadratic at 97 points each (both ends), r in [0.05, 1] at 40 points;
    // exact values by the converged quadrature (1e-6). The measured errors (research/lookup_error):
    // default 5.7e-4 (f32), 5.5e-4 (f16); uniform 8.5e-2 at n.v = 0 (its half-texel clamp).
    const ibl::dfg_error_grid g = ibl::dfg_error_grid::dense(97, 40, 0.05);
    const std::vector<ibl::vec2<double>> exact = ibl::dfg_exact_grid<ibl::ggx_height_correlated>(g);
    const ibl::dfg_lut_layout lay = ibl::dfg_lut_layout::remapped();
    const ibl::dfg_lut lut = ibl::make_dfg_lut_exact<ibl::ggx_height_correlated>(128, lay, 2);
    const ibl::dfg_lookup_report e = ibl::dfg_lookup_error(lut, g, exact);
    CHECK(e.count == exact.size());
    CHECK(e.max_abs <= 1e-3);
    const ibl::dfg_lookup_report eh = ibl::dfg_lookup_error(ibl::quantize_half_lut(lut), g, exact);
    // Half rounding adds at most half an ulp of values <= 1 (2^-12) to each texel.
    CHECK(eh.max_abs <= e.max_abs + std::ldexp(1.0, -12));
    const ibl::dfg_lut uni = ibl::make_dfg_lut_exact<ibl::ggx_height_correlated>(128, 2);
    CHECK(ibl::dfg_lookup_error(uni, g, exact).max_abs > 2e-3);
}

template <class Table>
concept lookup_names_layout = requires(const Table& t) { ibl::dfg_lookup(t, 0.5f, 0.5f, ibl::dfg_lut_layout::remapped()); };
template <class Table> concept lookup_reads_table = requires(const Table& t) { ibl::dfg_lookup(t, 0.5f, 0.5f); };

TEST_CASE("dfg table: built with the defaults, read with the default lookup, it answers its own integrand") {
    // The trap this guards: a table built in one layout and read as another gave (0.688, 0.0014)
    // at (n.v, r) = (0.5, 0.5) where the integrand is (0.835, 0.0223), with no error. Every table
    // now records its layout and every lookup reads it from the table.
    using M = ibl::ggx_height_correlated;
    const ibl::vec2<double> exact = ibl::dfg_exact<M>(0.5, 0.5);
    for (const ibl::dfg_lut& lut : {ibl::make_dfg_lut_exact<M>(32), ibl::make_dfg_lut_exact<M>(32, ibl::dfg_lut_layout::remapped()),
                                    ibl::make_dfg_lut_mc<M>(32, 4096)}) {
        CAPTURE(lut.layout.name());
        CHECK(lut.model == "ggx_height_correlated");
        const ibl::vec3<float> v = ibl::dfg_lookup(lut, 0.5f, 0.5f);
        CHECK(double(v.x) == doctest::Approx(exact.x).scale(1).epsilon(3e-3));
        CHECK(double(v.y) == doctest::Approx(exact.y).scale(1).epsilon(1e-3));
        const ibl::vec3<float> w = lut.sample(0.5f, 0.5f); // the table's own read: the same
        CHECK(w.x == v.x);
        CHECK(w.y == v.y);
    }
    // The defaults are the textbook table, read by texture(lut, vec2(n.v, r)).
    CHECK(ibl::make_dfg_lut_exact<M>(8).layout == ibl::dfg_lut_layout::uniform());
    CHECK(ibl::dfg_lut_layout{} == ibl::dfg_lut_layout::uniform());
    CHECK(ibl::dfg_lut_coord(0.3f, 0.7f, 32u, ibl::dfg_lut{}.layout) == ibl::vec2<float>(0.3f, 0.7f));
    // A lookup that names another layout than the table's does not compile (it takes none).
    static_assert(!lookup_names_layout<ibl::dfg_lut>);
    static_assert(lookup_reads_table<ibl::dfg_lut>);
    // Layout names round-trip (what files record).
    for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b)
            for (bool e : {false, true}) {
                const ibl::dfg_lut_layout l{ibl::dfg_axis(a), ibl::dfg_axis(b), e};
                CHECK(ibl::parse_dfg_lut_layout(l.name()) == l);
            }
    CHECK_THROWS_AS((void)ibl::parse_dfg_lut_layout("cbrt"), std::invalid_argument);
    CHECK(ibl::dfg_lut_layout::remapped().name() == "remapped");
}

TEST_CASE("round_through_half: IEEE binary16 rounding") {
    CHECK(ibl::round_through_half(1.0f) == 1.0f);
    CHECK(ibl::round_through_half(65504.0f) == 65504.0f);
    CHECK(ibl::round_through_half(1e6f) == 65504.0f);
    CHECK(ibl::round_through_half(-1e6f) == -65504.0f);
    // The half's ulp at 1 is 2^-10: 1 + 2^-11 and 1 + 3 x 2^-11 are ties, to the even neighbour.
    CHECK(ibl::round_through_half(1.0f + 1.0f / 2048.0f) == 1.0f);
    CHECK(ibl::round_through_half(1.0f + 3.0f / 2048.0f) == 1.0f + 1.0f / 512.0f);
    CHECK(ibl::round_through_half(1.0f + 1.5f / 2048.0f) == 1.0f + 1.0f / 1024.0f);
    CHECK(ibl::round_through_half(std::ldexp(1.0f, -24)) == std::ldexp(1.0f, -24)); // smallest subnormal
    CHECK(ibl::round_through_half(std::ldexp(1.0f, -26)) == 0.0f);
    CHECK(std::isinf(ibl::round_through_half(std::numeric_limits<float>::infinity())));
    for (int k = 0; k < 1000; ++k) { // relative error <= 2^-11 in the normal range
        const float x = 0.001f + 37.3f * float(k);
        CHECK(std::fabs(double(ibl::round_through_half(x)) - x) <= std::ldexp(double(x), -11));
    }
}

namespace {
/// For L(d) = 2 + d.y, LD(R, r) = 2 + R.y m1(r) with m1 = int (n.l)^2 du / int n.l du over the GGX
/// variate u in [0, 1/a] (reference.hpp: n.l = (1 - a u)/(1 - b u), a = 1 + alpha^2,
/// b = 1 - alpha^2; the l-density is D/4 in u, and R.l = n.l with n = R). Gauss-Legendre in u,
/// 2048 midpoint nodes: the integrand is smooth on [0, 1/a] (a pole at 1/b > 1/a).
double m1(double r) {
    const double al = r * r, a2 = al * al, a = 1.0 + a2, b = 1.0 - a2;
    const int n = 4096;
    double s1 = 0, s2 = 0;
    for (int i = 0; i < n; ++i) {
        const double u = (i + 0.5) / (n * a);
        const double nl = (1.0 - a * u) / (1.0 - b * u);
        s1 += nl;
        s2 += nl * nl;
    }
    return s2 / s1;
}
} // namespace

TEST_CASE("specular interpolation error on a smooth environment matches its closed form") {
    // L(d) = 2 + d.y: LD is linear in R.y with slope m1(r), so the blend of exact levels is known
    // in closed form per direction (for the linear blend it is off by R.y (sum_k w_k m1(r_k) -
    // m1(r))); the metric's interpolation part must equal that.
    // The chain holds the exact LD at its texel centres (levels part: bilinear on the cube only).
    const int levels = 6;
    ibl::cubemap<float> chain(32, levels);
    for (int l = 0; l < levels; ++l) {
        const double rl = double(l) / (levels - 1), ml = m1(rl);
        chain.fill(l, [&](int f, int x, int y) {
            const d3 dir = ibl::cube_texel_direction<double>(f, x, y, chain.size(l));
            return ibl::vec3<float>(float(2.0 + dir.y * ml));
        });
    }
    chain.update_borders();
    const std::vector<d3> dirs = ibl::lookup_error_directions(4, d3(0.0, 1.0, 0.0), 1, 0.05);
    auto ref = [](std::span<const d3> ds, double r) {
        std::vector<d3> out;
        const double m = m1(r);
        for (const auto& d : ds) out.push_back(d3(2.0 + glm::normalize(d).y * m));
        return out;
    };
    const std::vector<double> rs = {0.25, 0.3, 0.5, 0.7, 0.9};
    for (const auto& desc : {ibl::specular_lookup_desc::textbook(), ibl::specular_lookup_desc::accurate()}) {
        const auto rep = ibl::specular_lookup_error(chain, desc, rs, dirs, ref);
        REQUIRE(rep.size() == rs.size());
        for (const auto& x : rep) {
            const ibl::specular_taps<double> s = ibl::specular_lookup_taps(x.roughness, levels, desc);
            // The scheme's blend (linear or geometric) of the closed-form level values, per direction.
            double sq = 0.0;
            for (const auto& d : dirs) {
                const double y = glm::normalize(d).y, exact = 2.0 + y * m1(x.roughness);
                d3 v[4];
                for (int k = 0; k < s.count; ++k) v[k] = d3(2.0 + y * m1(double(s.level[k]) / (levels - 1)));
                sq += ibl::sqr((ibl::specular_blend(s, v, desc).x - exact) / exact);
            }
            CHECK(x.interpolation.rel_rmse == doctest::Approx(std::sqrt(sq / double(dirs.size()))).epsilon(1e-9));
            // m1 lies in [0, 1] and changes by < 1 between levels: the blend is off by < 0.2 of
            // LD's variable part; the lookup's bilinear part (the levels column) stays small
            // because the cube's texel directions are smooth (face 32 .. 1).
            CHECK(x.interpolation.rel_rmse < 0.2);
        }
    }
}

TEST_CASE("lookup_error: the lobe-generic texel-sum LD equals the GGX one for ggx_lobe") {
    ibl::cubemap<float> c(8);
    c.fill(0, [](int f, int x, int y) { return ibl::vec3<float>(0.1f + 0.2f * f, 0.05f * x + 0.3f, 0.07f * y + 0.1f); });
    c.generate_mips();
    std::vector<ibl::vec3<double>> dirs;
    for (int f = 0; f < 6; ++f) dirs.push_back(ibl::cube_texel_direction<double>(f, 3, 4, 8));
    for (const double r : {0.2, 0.5, 1.0}) {
        const auto a = ibl::reference_ld_texel_sum(c, 0, std::span<const ibl::vec3<double>>(dirs), r);
        const auto b = ibl::reference_ld_texel_sum_lobe<ibl::ggx_lobe>(c, 0, std::span<const ibl::vec3<double>>(dirs), r);
        for (std::size_t i = 0; i < dirs.size(); ++i)
            for (int k = 0; k < 3; ++k) CHECK(b[i][k] == doctest::Approx(a[i][k]).epsilon(1e-12));
    }
}
