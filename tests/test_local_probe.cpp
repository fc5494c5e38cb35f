// tests/test_local_probe.cpp — runtime/local_probe.hpp: ray-proxy exits against brute-force
// marching and closed forms (axis-aligned and oriented boxes, spheres), the parallax-corrected
// direction against the geometry it stands for (the ray from the capture point along it meets the
// proxy where the reflection ray does), the distance-based roughness' limits and monotonicity, its
// oblique-wall form (closed form, limits, and the cosines against finite differences of the lookup
// map's solid-angle scale), the lobe split's taps (closed forms, from the capture point, mirrors;
// in the analytic room below the single lookup at r = 0.4 and 0.8),
// influence weights (range, zero outside, Lipschitz bound 1 / fade), and the blend (contributions
// and fallback sum to one, priorities, continuity along paths).

#include <doctest/doctest.h>

#include <ibl/runtime/local_probe.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

namespace {

using dvec3 = ibl::vec3<double>;

dvec3 random_unit(std::mt19937_64& rng) {
    std::normal_distribution<double> n(0.0, 1.0);
    for (;;) {
        const dvec3 v(n(rng), n(rng), n(rng));
        const double l = glm::length(v);
        if (l > 1e-6) return v / l;
    }
}

ibl::probe_box<double> rotated_box(std::mt19937_64& rng) {
    ibl::probe_box<double> b;
    b.center = dvec3(0.3, -0.2, 0.5);
    b.half = dvec3(2.0, 1.2, 3.1);
    const dvec3 a = random_unit(rng);
    dvec3 t = glm::cross(a, dvec3(0.0, 1.0, 0.0));
    if (glm::length(t) < 1e-3) t = glm::cross(a, dvec3(1.0, 0.0, 0.0));
    t = glm::normalize(t);
    b.axis[0] = a;
    b.axis[1] = t;
    b.axis[2] = glm::cross(a, t);
    return b;
}

bool inside(const ibl::probe_box<double>& b, const dvec3& p) {
    const dvec3 o = b.to_local(p);
    return std::fabs(o.x) <= b.half.x && std::fabs(o.y) <= b.half.y && std::fabs(o.z) <= b.half.z;
}

} // namespace

TEST_CASE("local probe: box exit distance lands on the boundary, the ray stays inside before it") {
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u(-0.99, 0.99);
    for (int k = 0; k < 2000; ++k) {
        const ibl::probe_box<double> b = k % 2 ? rotated_box(rng) : ibl::probe_box<double>::axis_aligned(dvec3(-1, -2, -3), dvec3(4, 1, 2));
        const dvec3 p = b.center + u(rng) * b.half.x * b.axis[0] + u(rng) * b.half.y * b.axis[1] + u(rng) * b.half.z * b.axis[2];
        const dvec3 r = random_unit(rng);
        const double t = ibl::proxy_exit_distance(b, p, r * 3.0); // R need not be unit
        REQUIRE(t > 0.0);
        const dvec3 o = b.to_local(p + t * r);
        const double m = std::max({std::fabs(o.x) / b.half.x, std::fabs(o.y) / b.half.y, std::fabs(o.z) / b.half.z});
        CHECK(m == doctest::Approx(1.0).epsilon(1e-12));
        // brute force: marching finds the last inside point within the step
        double s = 0.0;
        const double step = 1e-3;
        while (inside(b, p + (s + step) * r)) s += step;
        CHECK(std::fabs(s - t) <= step + 1e-9);
    }
}

TEST_CASE("local probe: an oriented box equals the axis-aligned box in its own frame; spheres by the closed form") {
    std::mt19937_64 rng(11);
    for (int k = 0; k < 500; ++k) {
        const ibl::probe_box<double> b = rotated_box(rng);
        const ibl::probe_box<double> local = ibl::probe_box<double>::axis_aligned(-b.half, b.half);
        const dvec3 p = b.center + 0.5 * random_unit(rng), r = random_unit(rng);
        CHECK(ibl::proxy_exit_distance(b, p, r) == doctest::Approx(ibl::proxy_exit_distance(local, b.to_local(p), b.direction_to_local(r))).epsilon(1e-12));
        const ibl::probe_sphere<double> s{dvec3(1.0, 2.0, -1.0), 2.5};
        const dvec3 q = s.center + 2.4 * std::pow(std::uniform_real_distribution<double>(0, 1)(rng), 1.0 / 3.0) * random_unit(rng);
        const double t = ibl::proxy_exit_distance(s, q, r);
        REQUIRE(t > 0.0);
        CHECK(glm::length(q + t * r - s.center) == doctest::Approx(2.5).epsilon(1e-12));
    }
}

TEST_CASE("local probe: no correction outside and behind, for zero and NaN directions") {
    const auto b = ibl::probe_box<double>::axis_aligned(dvec3(-1), dvec3(1));
    const ibl::probe_sphere<double> s{dvec3(0.0), 1.0};
    CHECK(ibl::proxy_exit_distance(b, dvec3(3, 0, 0), dvec3(1, 0, 0)) == -1.0); // box behind
    CHECK(ibl::proxy_exit_distance(b, dvec3(3, 3, 0), dvec3(0, 0, 1)) == -1.0); // missed, parallel
    CHECK(ibl::proxy_exit_distance(s, dvec3(3, 0, 0), dvec3(0, 1, 0)) == -1.0);
    CHECK(ibl::proxy_exit_distance(b, dvec3(3, 0, 0), dvec3(-1, 0, 0)) == doctest::Approx(4.0)); // outside, facing: the far side
    CHECK(ibl::proxy_exit_distance(b, dvec3(0.0), dvec3(0.0)) == -1.0);
    const double nan = std::numeric_limits<double>::quiet_NaN();
    CHECK(ibl::proxy_exit_distance(s, dvec3(0.0), dvec3(nan, 0, 0)) == -1.0);
    const dvec3 r(0.0, 0.0, 2.0);
    const ibl::parallax_lookup<double> l = ibl::parallax_correct(b, dvec3(0.5), dvec3(5, 5, 5), r);
    CHECK_FALSE(l.hit);
    CHECK(l.direction == dvec3(0, 0, 1));
}

TEST_CASE("local probe: the corrected direction sees the proxy where the reflection ray meets it") {
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> u(-0.95, 0.95);
    const auto room = ibl::probe_box<double>::axis_aligned(dvec3(-4, 0, -3), dvec3(4, 3, 5));
    const dvec3 c(0.5, 1.5, 0.2); // the capture point
    for (int k = 0; k < 1000; ++k) {
        const dvec3 p = room.center + dvec3(u(rng) * room.half.x, u(rng) * room.half.y, u(rng) * room.half.z);
        const dvec3 r = random_unit(rng);
        const ibl::parallax_lookup<double> l = ibl::parallax_correct(room, c, p, r);
        REQUIRE(l.hit);
        const dvec3 hit = p + l.d_shading * r;
        const double tc = ibl::proxy_exit_distance(room, c, l.direction);
        CHECK(glm::length(c + tc * l.direction - hit) < 1e-9);
        CHECK(l.d_probe == doctest::Approx(tc).epsilon(1e-12));
        CHECK(glm::length(l.direction) == doctest::Approx(1.0).epsilon(1e-14));
    }
    // from the capture point itself the lookup is the reflection direction
    for (int k = 0; k < 100; ++k) {
        const dvec3 r = random_unit(rng);
        CHECK(glm::length(ibl::parallax_direction(room, c, c, r) - r) < 1e-14);
    }
}

TEST_CASE("local probe: distance-based roughness") {
    CHECK(ibl::corrected_roughness(0.4, 2.0, 2.0) == doctest::Approx(0.4).epsilon(1e-15));
    CHECK(ibl::corrected_roughness(0.4, 1.0, 4.0) == doctest::Approx(0.2).epsilon(1e-15)); // alpha / 4
    CHECK(ibl::corrected_roughness(0.4, 4.0, 1.0) == doctest::Approx(0.8).epsilon(1e-15)); // alpha x 4
    CHECK(ibl::corrected_roughness(0.9, 10.0, 1.0) == 1.0);                                // clamped
    CHECK(ibl::corrected_roughness(0.0, 3.0, 1.0) == 0.0);                                 // a mirror stays one
    CHECK(ibl::corrected_roughness(0.5, 0.0, 1.0) == 0.5);                                 // no hit: unchanged
    CHECK(ibl::corrected_roughness(0.5, 1.0, std::numeric_limits<double>::infinity()) == 0.5);
    CHECK(ibl::corrected_roughness(1.5, 1.0, 1.0) == 1.0);
    double prev = 0.0;
    for (int k = 1; k <= 50; ++k) { // monotone in d_shading / d_probe
        const double r = ibl::corrected_roughness(0.3, 0.1 * k, 2.0);
        CHECK(r >= prev);
        prev = r;
    }
}

TEST_CASE("local probe: roughness on oblique walls, closed form and limits") {
    // alpha' = alpha (d_s / d_p) sqrt(cos_p / cos_s)
    CHECK(ibl::corrected_roughness(0.4, 1.0, 4.0, 0.5, 0.5) == doctest::Approx(0.2).epsilon(1e-15)); // equal slopes: distance only
    CHECK(ibl::corrected_roughness(0.4, 2.0, 2.0, 1.0, 0.25) == doctest::Approx(0.4 * std::sqrt(0.5)).epsilon(1e-15));
    CHECK(ibl::corrected_roughness(0.4, 2.0, 2.0, 0.25, 1.0) == doctest::Approx(0.4 * std::sqrt(2.0)).epsilon(1e-15));
    CHECK(ibl::corrected_roughness(0.5, 1.0, 2.0, 0.0, 0.0) == doctest::Approx(ibl::corrected_roughness(0.5, 1.0, 2.0)).epsilon(1e-15));
    CHECK(ibl::corrected_roughness(0.5, 1.0, 2.0, 0.0, 0.3) == 1.0); // P grazing: the widest lobe
    CHECK(ibl::corrected_roughness(0.5, 1.0, 2.0, 0.3, 0.0) == 0.0); // C grazing: a mirror
    CHECK(ibl::corrected_roughness(0.0, 1.0, 2.0, 0.0, 0.3) == 0.0); // a mirror stays one
    CHECK(ibl::corrected_roughness(0.5, 0.0, 1.0, 0.2, 0.9) == 0.5); // no hit: unchanged
    CHECK(ibl::corrected_roughness(0.9, 10.0, 1.0, 0.5, 1.0) == 1.0); // clamped
    const ibl::parallax_lookup<double> none{};
    CHECK(ibl::corrected_roughness(0.3, none) == 0.3);
}

TEST_CASE("local probe: the cosines make the roughness correction the solid-angle Jacobian of the lookup map") {
    // The map from P's reflection directions to C's lookup directions scales solid angle by
    // (d_s / d_p)^2 cos_p / cos_s; measured here by finite differences of parallax_direction.
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> u(-0.9, 0.9);
    const auto room = ibl::probe_box<double>::axis_aligned(dvec3(-4, 0, -3), dvec3(4, 3, 5));
    const ibl::probe_sphere<double> ball{dvec3(0.2, 1.0, -0.3), 7.0};
    const dvec3 c(0.5, 1.5, 0.2);
    int checked = 0;
    for (int k = 0; k < 400; ++k) {
        const dvec3 p = room.center + dvec3(u(rng) * room.half.x, u(rng) * room.half.y, u(rng) * room.half.z);
        const dvec3 r = random_unit(rng);
        const auto one = [&](const auto& proxy) {
            const ibl::parallax_lookup<double> l = ibl::parallax_correct(proxy, c, p, r);
            REQUIRE(l.hit);
            if (l.cos_shading < 0.2 || l.cos_probe < 0.2) return; // near edges of the box's faces the map folds
            dvec3 t = glm::normalize(glm::cross(r, std::fabs(r.x) < 0.9 ? dvec3(1, 0, 0) : dvec3(0, 1, 0)));
            const dvec3 b = glm::cross(r, t);
            const double e = 1e-6;
            const dvec3 r1 = glm::normalize(r + e * t), r2 = glm::normalize(r + e * b);
            const ibl::parallax_lookup<double> l1 = ibl::parallax_correct(proxy, c, p, r1), l2 = ibl::parallax_correct(proxy, c, p, r2);
            // the same face for the three rays
            if (glm::length(ibl::proxy_normal(proxy, p + l.d_shading * r) - ibl::proxy_normal(proxy, p + l1.d_shading * r1)) > 0.0 ||
                glm::length(ibl::proxy_normal(proxy, p + l.d_shading * r) - ibl::proxy_normal(proxy, p + l2.d_shading * r2)) > 0.0)
                return;
            const double w = glm::length(glm::cross(r1 - r, r2 - r));
            const double wp = glm::length(glm::cross(l1.direction - l.direction, l2.direction - l.direction));
            const double q = l.d_shading / l.d_probe;
            CHECK(wp / w == doctest::Approx(q * q * l.cos_probe / l.cos_shading).epsilon(1e-4));
            const double a = 0.3 * 0.3, expect = std::sqrt(std::min(1.0, a * std::sqrt(wp / w)));
            CHECK(ibl::corrected_roughness(0.3, l) == doctest::Approx(expect).epsilon(1e-4));
            ++checked;
        };
        one(room);
        one(ball);
    }
    CHECK(checked > 300);
}

TEST_CASE("local probe: the lobe split's taps (closed forms, P = C, mirrors)") {
    std::mt19937_64 rng(5);
    const auto room = ibl::probe_box<double>::axis_aligned(dvec3(-4, 0, -3), dvec3(4, 3, 5));
    const dvec3 c(0.5, 1.5, 0.2);
    for (int k = 0; k < 200; ++k) {
        const dvec3 r = random_unit(rng);
        const double rough = 0.1 + 0.9 * double(k) / 199.0, alpha = rough * rough, q = alpha / 2.0;
        double wsum = 0.0;
        dvec3 ring(0.0);
        for (int i = 0; i < ibl::parallax_split_taps; ++i) {
            const dvec3 w = ibl::parallax_split_direction(r, rough, i);
            CHECK(glm::length(w) == doctest::Approx(1.0).epsilon(1e-12));
            // the ring at the reflected angle 2 atan(alpha / 2) around R
            CHECK(std::acos(std::clamp(glm::dot(w, r), -1.0, 1.0)) == doctest::Approx(i == 0 ? 0.0 : 2.0 * std::atan(q)).epsilon(1e-6));
            if (i > 0) ring += w;
            // from the capture point: the tap's own direction at r / sqrt 2
            const ibl::parallax_tap<double> t = ibl::parallax_split_tap(room, c, c, r, rough, i);
            CHECK(glm::length(t.direction - w) < 1e-12);
            CHECK(t.roughness == doctest::Approx(rough / std::sqrt(2.0)).epsilon(1e-12));
            wsum += t.weight;
        }
        CHECK(wsum == doctest::Approx(1.0).epsilon(1e-15));
        // opposite ring taps: the ring's mean lies on R at cos(theta) = (1 - q^2) / (1 + q^2)
        CHECK(glm::length(ring / 4.0 - r * ((1.0 - q * q) / (1.0 + q * q))) < 1e-12);
    }
    // a mirror: five copies of the corrected mirror lookup
    const dvec3 p(-2.0, 0.7, 3.1), r = glm::normalize(dvec3(0.3, -0.4, 0.8));
    const ibl::parallax_lookup<double> l = ibl::parallax_correct(room, c, p, r);
    for (int i = 0; i < ibl::parallax_split_taps; ++i) {
        const ibl::parallax_tap<double> t = ibl::parallax_split_tap(room, c, p, r, 0.0, i);
        CHECK(glm::length(t.direction - l.direction) < 1e-15);
        CHECK(t.roughness == 0.0);
    }
}

TEST_CASE("local probe: influence weights lie in [0, 1], vanish outside and change by at most |dP| / fade") {
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> u(-6.0, 6.0);
    const ibl::probe_box<double> box = rotated_box(rng);
    const ibl::probe_sphere<double> sph{dvec3(1.0, 0.0, 0.0), 3.0};
    const double fade = 0.5;
    for (int k = 0; k < 20000; ++k) {
        const dvec3 p(u(rng), u(rng), u(rng));
        const dvec3 q = p + 0.05 * random_unit(rng);
        const double wb = ibl::influence_weight(box, fade, p), ws = ibl::influence_weight(sph, fade, p);
        CHECK(wb >= 0.0);
        CHECK(wb <= 1.0);
        if (!inside(box, p)) CHECK(wb == 0.0);
        if (glm::length(p - sph.center) >= 3.0) CHECK(ws == 0.0);
        CHECK(std::fabs(ibl::influence_weight(box, fade, q) - wb) <= glm::length(q - p) / fade + 1e-12);
        CHECK(std::fabs(ibl::influence_weight(sph, fade, q) - ws) <= glm::length(q - p) / fade + 1e-12);
    }
    CHECK(ibl::influence_weight(sph, fade, sph.center) == 1.0);
    CHECK(ibl::influence_weight(sph, 0.0, dvec3(1.0, 2.999, 0.0)) == 1.0); // no fade: a hard edge
}

TEST_CASE("local probe: blend contributions and the fallback sum to one; priorities; continuity") {
    std::mt19937_64 rng(9);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (int k = 0; k < 5000; ++k) {
        const std::size_t n = 1 + std::size_t(k % 6);
        double w[6], c[6];
        int pr[6];
        for (std::size_t i = 0; i < n; ++i) w[i] = k % 3 ? u(rng) : std::round(u(rng)), pr[i] = int(u(rng) * 3.0);
        const double fallback = ibl::blend_probe_weights(w, pr, n, c);
        double sum = fallback;
        for (std::size_t i = 0; i < n; ++i) {
            CHECK(c[i] >= 0.0);
            CHECK(c[i] <= w[i] + 1e-15);
            sum += c[i];
        }
        CHECK(sum == doctest::Approx(1.0).epsilon(1e-14));
        CHECK(fallback >= 0.0);
    }
    // a full-weight higher-priority probe takes everything; equal priorities share by weight
    {
        const double w[3] = {1.0, 1.0, 0.5};
        const int pr[3] = {2, 1, 1};
        double c[3];
        CHECK(ibl::blend_probe_weights(w, pr, 3, c) == 0.0);
        CHECK(c[0] == 1.0);
        CHECK(c[1] == 0.0);
        CHECK(c[2] == 0.0);
        const int same[3] = {0, 0, 0};
        CHECK(ibl::blend_probe_weights(w, same, 3, c) == 0.0);
        CHECK(c[0] == doctest::Approx(0.4));
        CHECK(c[2] == doctest::Approx(0.2));
        const double low[2] = {0.3, 0.2};
        CHECK(ibl::blend_probe_weights(low, same, 2, c) == doctest::Approx(0.5)); // the sky fills in
    }
    // two overlapping influence boxes walked across: every contribution moves by at most a bounded
    // multiple of the step (no jumps at the boundaries)
    const auto a = ibl::probe_box<double>::axis_aligned(dvec3(-4, -1, -1), dvec3(1, 1, 1));
    const auto b = ibl::probe_box<double>::axis_aligned(dvec3(-1, -1, -1), dvec3(4, 1, 1));
    const double fade = 0.5, step = 1e-3;
    double prev[2] = {0, 0}, prev_f = 1.0;
    for (int k = 0; k <= 10000; ++k) {
        const dvec3 p(-5.0 + k * step, 0.1, 0.0);
        const double w[2] = {ibl::influence_weight(a, fade, p), ibl::influence_weight(b, fade, p)};
        const int pr[2] = {0, 0};
        double c[2];
        const double f = ibl::blend_probe_weights(w, pr, 2, c);
        if (k > 0) {
            CHECK(std::fabs(c[0] - prev[0]) <= 4.0 * step / fade);
            CHECK(std::fabs(c[1] - prev[1]) <= 4.0 * step / fade);
            CHECK(std::fabs(f - prev_f) <= 4.0 * step / fade);
        }
        prev[0] = c[0], prev[1] = c[1], prev_f = f;
    }
}

#include <ibl/bake/prefilter.hpp>
#include <ibl/core/color.hpp>
#include <ibl/env/convert.hpp>
#include <ibl/reference/analytic_room.hpp>
#include <ibl/reference/ld_irradiance.hpp>
#include <ibl/reference/metrics.hpp>
#include <ibl/runtime/lookup.hpp>

TEST_CASE("analytic room: traces land on the walls, a capture from a point sees the room from there") {
    const ibl::analytic_room<double> room;
    std::mt19937_64 rng(21);
    for (int k = 0; k < 1000; ++k) {
        const dvec3 p(-3.5 + 7.0 * std::uniform_real_distribution<double>(0, 1)(rng), 0.2 + 2.6 * std::uniform_real_distribution<double>(0, 1)(rng),
                      -2.5 + 7.0 * std::uniform_real_distribution<double>(0, 1)(rng));
        const dvec3 d = random_unit(rng);
        int wall = -1;
        const double t = room.exit(p, d, wall);
        REQUIRE(wall >= 0);
        const dvec3 x = p + t * d;
        const int axis = wall / 2;
        CHECK(x[axis] == doctest::Approx(wall % 2 ? room.hi[axis] : room.lo[axis]).epsilon(1e-12));
        const dvec3 l = room.trace(p, d);
        CHECK(l.x > 0.0);
        CHECK(l.y > 0.0);
    }
    int wall = 0;
    CHECK(room.exit(dvec3(10.0, 1.0, 0.0), dvec3(1.0, 0.0, 0.0), wall) == -1.0); // outside
    CHECK(room.trace(dvec3(10.0, 1.0, 0.0), dvec3(1.0, 0.0, 0.0)) == dvec3(0.0));
    // the emitter is brightest straight above its centre
    CHECK(ibl::luminance(room.trace(dvec3(room.emitter_x, 1.0, room.emitter_z), dvec3(0, 1, 0))) > 30.0);
}

TEST_CASE("analytic room, inner-box variant: rays stop at the block, the rest of the room is unchanged") {
    ibl::analytic_room<double> room;
    const ibl::analytic_room<double> plain;
    room.inner = true;
    // straight down from above the block: its top face, at the block's pattern
    const dvec3 above(0.3, 2.5, -0.2);
    const dvec3 top = room.trace(above, dvec3(0, -1, 0));
    const dvec3 on_top(0.3, room.inner_hi.y, -0.2);
    CHECK(top.x == doctest::Approx(room.inner_base.x * room.pattern(on_top, 1)).epsilon(1e-12));
    CHECK(top.y == doctest::Approx(room.inner_base.y * room.pattern(on_top, 1)).epsilon(1e-12));
    CHECK(top != plain.trace(above, dvec3(0, -1, 0))); // without the block: the floor
    // towards -x from beside the block (at x = 3): its +X face
    int face = -1;
    const double t = room.inner_entry(dvec3(3.0, 0.5, 0.0), dvec3(-1, 0, 0), face);
    CHECK(face == 1);
    CHECK(t == doctest::Approx(3.0 - room.inner_hi.x).epsilon(1e-12));
    // the ray through the block's edge region from a random point outside: it stops at the block
    // exactly when the block is nearer than the wall; rays that miss it see what the plain room shows
    std::mt19937_64 rng(5);
    int blocked = 0, missed = 0;
    for (int k = 0; k < 2000; ++k) {
        const dvec3 p(-3.5 + 7.0 * std::uniform_real_distribution<double>(0, 1)(rng), 0.2 + 2.6 * std::uniform_real_distribution<double>(0, 1)(rng),
                      -2.5 + 7.0 * std::uniform_real_distribution<double>(0, 1)(rng));
        const dvec3 d = random_unit(rng);
        if (room.inside_inner(p)) {
            CHECK(room.trace(p, d) == dvec3(0.0));
            continue;
        }
        int w = -1, f = -1;
        const double tw = room.exit(p, d, w), ti = room.inner_entry(p, d, f);
        if (ti > 0.0 && ti < tw) {
            ++blocked;
            const dvec3 x = p + ti * d;
            const int axis = f / 2;
            CHECK(x[axis] == doctest::Approx(f % 2 ? room.inner_hi[axis] : room.inner_lo[axis]).epsilon(1e-9));
            for (int a = 0; a < 3; ++a) { // the entry point lies on the block
                CHECK(x[a] >= room.inner_lo[a] - 1e-9);
                CHECK(x[a] <= room.inner_hi[a] + 1e-9);
            }
        } else {
            ++missed;
            CHECK(room.trace(p, d) == plain.trace(p, d));
        }
    }
    CHECK(blocked > 100);
    CHECK(missed > 100);
}

TEST_CASE("local probes in the analytic room: parallax correction and distance-based roughness cut the error; the slopes and the lobe split cut it further") {
    // Small and fast (64^2 captures, 12 points x 8 directions, 1024-sample references); the full
    // study with its figures is research/local_probe_error (docs/local_probes.md).
    const ibl::analytic_room<double> room;
    const dvec3 c = 0.5 * (room.lo + room.hi);
    ibl::cubemap<float> cube = ibl::bake_cubemap<float>(ibl::room_view<double>{&room, c}, 64, 2, ibl::serial_executor{});
    cube.generate_mips();
    const ibl::specular_chain chain = ibl::prefilter(cube, ibl::prefilter_options{}, ibl::thread_executor{2});
    const auto proxy = ibl::probe_box<double>::axis_aligned(room.lo, room.hi);
    std::vector<dvec3> points, dirs;
    for (int i = 0; i < 12; ++i)
        points.push_back(dvec3(-3.0 + 2.0 * (i % 4), 0.8 + 0.7 * (i % 3), -2.0 + 2.5 * (i % 3) + 0.5 * (i / 4)));
    for (int k = 0; k < 8; ++k) {
        const double z = 1.0 - (2.0 * k + 1.0) / 8.0, ph = 2.399963229728653 * k, s = std::sqrt(1.0 - z * z);
        dirs.push_back(dvec3(s * std::cos(ph), z, s * std::sin(ph)));
    }
    for (double r : {0.0, 0.4, 0.8}) {
        CAPTURE(r);
        double mean = 0.0;
        std::vector<double> truth, none, fixed, oblique, split;
        for (const dvec3& p : points)
            for (const dvec3& R : dirs) {
                const ibl::room_view<double> view{&room, p};
                truth.push_back(ibl::luminance(r == 0.0 ? room.trace(p, R) : ibl::reference_ld(view, R, r, 1024)));
                none.push_back(ibl::luminance(dvec3(ibl::specular_lookup(chain, ibl::vec3<float>(R), float(r)))));
                const ibl::parallax_lookup<double> l = ibl::parallax_correct(proxy, c, p, R);
                const double rc = ibl::corrected_roughness(r, l.d_shading, l.d_probe);
                fixed.push_back(ibl::luminance(dvec3(ibl::specular_lookup(chain, ibl::vec3<float>(l.direction), float(rc)))));
                const double ro = ibl::corrected_roughness(r, l);
                oblique.push_back(ibl::luminance(dvec3(ibl::specular_lookup(chain, ibl::vec3<float>(l.direction), float(ro)))));
                dvec3 sp(0.0);
                for (int i = 0; i < ibl::parallax_split_taps; ++i) {
                    const ibl::parallax_tap<double> t = ibl::parallax_split_tap(proxy, c, p, R, r, i);
                    sp += t.weight * dvec3(ibl::specular_lookup(chain, ibl::vec3<float>(t.direction), float(t.roughness)));
                }
                split.push_back(ibl::luminance(sp));
                mean += truth.back();
            }
        mean /= double(truth.size());
        ibl::error_accumulator a(1e-3 * mean), b(1e-3 * mean), o(1e-3 * mean), q(1e-3 * mean);
        for (std::size_t i = 0; i < truth.size(); ++i)
            a.add(none[i], truth[i]), b.add(fixed[i], truth[i]), o.add(oblique[i], truth[i]), q.add(split[i], truth[i]);
        const double e_none = a.finish().rel_rmse, e_fixed = b.finish().rel_rmse, e_oblique = o.finish().rel_rmse, e_split = q.finish().rel_rmse;
        MESSAGE("r = " << r << ": uncorrected " << e_none << ", corrected " << e_fixed << ", oblique " << e_oblique << ", split " << e_split);
        if (r > 0.0) CHECK(e_split < e_oblique);
        if (r == 0.8) CHECK(e_split < 0.5 * e_none); // the lobe split halves the error where one tap does not
        if (r <= 0.4) CHECK(e_fixed < 0.5 * e_none);
        CHECK(e_oblique < e_fixed * (r == 0.0 ? 1.0 + 1e-12 : 1.0)); // the slopes' factor: no worse for mirrors, better for glossy
        if (r == 0.0) CHECK(e_fixed < 0.06); // mirror at 64^2 faces (0.5% at 256^2: docs/local_probes.md)
    }
}
