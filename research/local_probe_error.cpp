// research/local_probe_error.cpp — the tables of docs/local_probes.md: local reflection probes
// (ibl/runtime/local_probe.hpp) in the analytic room (ibl/reference/analytic_room.hpp: an 8 x 3 x 8 m
// box with smooth wall patterns and a bright emitter on the ceiling), against the truth at shading
// points spread over the room.
//
// Probes: captured by bake_cubemap over room_view (face N, 4 x 4 rays per texel), prefiltered by
// ibl::prefilter (the defaults: filtered importance sampling, n.l weight, linear roughness
// mapping), SH3 projected. Shading points: a 4 x 3 x 4 grid inset 0.6 m from the walls, 16
// reflection directions each (a spherical Fibonacci set), the same normals for the diffuse part.
// Truth: mirror, what the point sees along R (trace); glossy, reference_ld over room_view at the
// point (GGX importance sampling with ray casting, 4096 samples, the n.l weight the chain uses);
// irradiance, reference_irradiance (4096 cosine samples).
// Estimates:
//   none       one probe at the room's centre, looked up at R and r (a distant-environment lookup)
//   box        the same probe, parallax-corrected direction against the room's box
//   box + r    and the distance-based roughness, distance only (alpha' = alpha d_s / d_p)
//   oblique    and the default: the distances and the proxy's slope at the hit (alpha' = alpha
//              (d_s / d_p) sqrt(cos_p / cos_s), corrected_roughness(r, parallax_lookup))
//   split      the lobe split (an option): five sub-lobes, each corrected (parallax_split_tap)
//   two probes two captures at (-2, 1.5, 0) and (2, 1.5, 2), each corrected (oblique), blended by
//              influence boxes that split the room at x = 0 with 1 m fades (blend_probe_weights)
// Error: relative RMSE of luminance over the points x directions (floor 1e-3 x the mean truth).
//
// Then the same study in the inner-box variant of the room (analytic_room::inner: an opaque
// 2.4 x 1.1 x 1.8 m block on the floor near the centre, below the capture points): captures and
// truth both ray cast against it, the proxy is still the room's box (the block is what the proxy
// does not model); shading points inside the block are left out.
//
//   local_probe_error [N]     faces of N^2 (default 256)
// Regenerate the docs' table: build/release/research/local_probe_error > /tmp/local_probes.md

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include <ibl/bake/prefilter.hpp>
#include <ibl/core/color.hpp>
#include <ibl/core/executor.hpp>
#include <ibl/env/convert.hpp>
#include <ibl/reference/analytic_room.hpp>
#include <ibl/reference/ld_irradiance.hpp>
#include <ibl/reference/metrics.hpp>
#include <ibl/runtime/local_probe.hpp>
#include <ibl/runtime/lookup.hpp>
#include <ibl/sh/convolve.hpp>
#include <ibl/sh/project.hpp>

namespace {

using dvec3 = ibl::vec3<double>;
using fvec3 = ibl::vec3<float>;

struct probe {
    dvec3 at;
    ibl::specular_chain chain;
    ibl::sh_coeffs<double, 3> irradiance; // E coefficients
};

probe capture(const ibl::analytic_room<double>& room, const dvec3& at, int n) {
    const ibl::room_view<double> view{&room, at};
    ibl::cubemap<float> cube = ibl::bake_cubemap<float>(view, n, 4, ibl::thread_executor{2});
    cube.generate_mips();
    ibl::specular_chain chain = ibl::prefilter(cube, ibl::prefilter_options{}, ibl::thread_executor{2});
    const auto sh = ibl::project_cube<3>(cube, ibl::thread_executor{2});
    ibl::sh_coeffs<double, 3> rad;
    for (int k = 0; k < 9; ++k) rad[k] = dvec3(sh[k]);
    return {at, std::move(chain), ibl::sh_irradiance(rad)};
}

double lum(const dvec3& v) { return ibl::luminance(v); }

} // namespace

namespace {

void study(const ibl::analytic_room<double>& room, int n) {
    const ibl::probe_box<double> proxy = ibl::probe_box<double>::axis_aligned(room.lo, room.hi);
    const dvec3 centre = 0.5 * (room.lo + room.hi);
    const probe p0 = capture(room, centre, n);
    const probe pa = capture(room, dvec3(-2.0, 1.5, 0.0), n), pb = capture(room, dvec3(2.0, 1.5, 2.0), n);
    const dvec3 grow(1.0);
    const ibl::probe_box<double> infl_a = ibl::probe_box<double>::axis_aligned(room.lo - grow, dvec3(1.0, room.hi.y + 1.0, room.hi.z + 1.0));
    const ibl::probe_box<double> infl_b = ibl::probe_box<double>::axis_aligned(dvec3(-1.0, room.lo.y - 1.0, room.lo.z - 1.0), room.hi + grow);
    const double fade = 1.0;

    std::vector<dvec3> points, dirs;
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 3; ++j)
            for (int k = 0; k < 4; ++k) {
                const dvec3 t((i + 0.5) / 4.0, (j + 0.5) / 3.0, (k + 0.5) / 4.0);
                const dvec3 lo = room.lo + dvec3(0.6), hi = room.hi - dvec3(0.6);
                if (!room.inside_inner(lo + t * (hi - lo))) points.push_back(lo + t * (hi - lo));
            }
    const int nd = 16;
    for (int k = 0; k < nd; ++k) { // spherical Fibonacci
        const double z = 1.0 - (2.0 * k + 1.0) / nd, ph = 2.399963229728653 * k, s = std::sqrt(1.0 - z * z);
        dirs.push_back(dvec3(s * std::cos(ph), z, s * std::sin(ph)));
    }

    const auto lookup = [](const probe& pr, const dvec3& d, double r) {
        return dvec3(ibl::specular_lookup(pr.chain, fvec3(d), float(r)));
    };
    // rough: 0 the probe's roughness, 1 distance only, 2 the default (distances and slopes)
    const auto corrected = [&](const probe& pr, const dvec3& p, const dvec3& R, double r, int rough) {
        const ibl::parallax_lookup<double> l = ibl::parallax_correct(proxy, pr.at, p, R);
        return lookup(pr, l.direction,
                      rough == 2 ? ibl::corrected_roughness(r, l) : rough == 1 ? ibl::corrected_roughness(r, l.d_shading, l.d_probe) : r);
    };
    const auto split = [&](const probe& pr, const dvec3& p, const dvec3& R, double r) {
        dvec3 sum(0.0);
        for (int i = 0; i < ibl::parallax_split_taps; ++i) {
            const ibl::parallax_tap<double> t = ibl::parallax_split_tap(proxy, pr.at, p, R, r, i);
            sum += t.weight * lookup(pr, t.direction, t.roughness);
        }
        return sum;
    };
    const auto blended = [&](const dvec3& p, auto&& per_probe) {
        const double w[2] = {ibl::influence_weight(infl_a, fade, p), ibl::influence_weight(infl_b, fade, p)};
        const int pr[2] = {0, 0};
        double c[2];
        (void)ibl::blend_probe_weights(w, pr, 2, c); // the fallback is 0 inside the room (weights sum >= 1)
        return c[0] * per_probe(pa) + c[1] * per_probe(pb);
    };

    std::printf("faces %d^2, %zu points x %d directions\n\n", n, points.size(), nd);
    std::printf("| roughness | none | box | box + r (distance) | box + r (oblique) | split (5 taps) | two probes (oblique, blended) |\n|---|---|---|---|---|---|---|\n");
    const double roughness[] = {0.0, 0.1, 0.2, 0.4, 0.6, 0.8};
    for (double r : roughness) {
        std::vector<double> truth, est[6];
        for (const dvec3& p : points) {
            const ibl::room_view<double> view{&room, p};
            for (const dvec3& R : dirs) {
                const dvec3 t = r == 0.0 ? room.trace(p, R) : ibl::reference_ld(view, R, r, 4096);
                truth.push_back(lum(t));
                est[0].push_back(lum(lookup(p0, R, r)));
                est[1].push_back(lum(corrected(p0, p, R, r, 0)));
                est[2].push_back(lum(corrected(p0, p, R, r, 1)));
                est[3].push_back(lum(corrected(p0, p, R, r, 2)));
                est[4].push_back(lum(split(p0, p, R, r)));
                est[5].push_back(lum(blended(p, [&](const probe& q) { return corrected(q, p, R, r, 2); })));
            }
        }
        double mean = 0.0;
        for (double t : truth) mean += t;
        mean /= double(truth.size());
        std::printf("| %.1f |", r);
        for (const auto& e : est) {
            ibl::error_accumulator acc(1e-3 * mean);
            for (std::size_t i = 0; i < truth.size(); ++i) acc.add(e[i], truth[i]);
            std::printf(" %.4f |", acc.finish().rel_rmse);
        }
        std::printf("\n");
        std::fflush(stdout);
    }
    // Diffuse: the probes' SH irradiance (no parallax for SH) against the true irradiance.
    std::vector<double> truth, one, two;
    for (const dvec3& p : points) {
        const ibl::room_view<double> view{&room, p};
        for (const dvec3& nrm : dirs) {
            truth.push_back(lum(ibl::reference_irradiance(view, nrm, 4096)));
            one.push_back(lum(ibl::sh_evaluate(p0.irradiance, nrm)));
            two.push_back(lum(blended(p, [&](const probe& q) { return ibl::sh_evaluate(q.irradiance, nrm); })));
        }
    }
    double mean = 0.0;
    for (double t : truth) mean += t;
    mean /= double(truth.size());
    ibl::error_accumulator a1(1e-3 * mean), a2(1e-3 * mean);
    for (std::size_t i = 0; i < truth.size(); ++i) a1.add(one[i], truth[i]), a2.add(two[i], truth[i]);
    std::printf("\nirradiance (SH3): one probe at the centre %.4f, two probes blended %.4f (relative RMSE of luminance)\n",
                a1.finish().rel_rmse, a2.finish().rel_rmse);
}

} // namespace

int main(int argc, char** argv) {
    const int n = argc > 1 ? std::atoi(argv[1]) : 256;
    if (n < 8 || n > 2048) {
        std::fprintf(stderr, "usage: local_probe_error [face size 8..2048]\n");
        return 2;
    }
    const ibl::analytic_room<double> room;
    study(room, n);
    ibl::analytic_room<double> blocked = room;
    blocked.inner = true;
    std::printf("\ninner-box variant: a block [%g, %g] x [%g, %g] x [%g, %g] m in the room, not in the proxy\n", blocked.inner_lo.x,
                blocked.inner_hi.x, blocked.inner_lo.y, blocked.inner_hi.y, blocked.inner_lo.z, blocked.inner_hi.z);
    study(blocked, n);
    return 0;
}
