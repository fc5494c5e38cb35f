// tests/browser/room_reference.cpp — the C++ side of the room example (tools/viewer/room.html,
// tests/browser/run_browser_test.py --mode room): the analytic room (ibl/reference/analytic_room.hpp)
// lit by a set of two local probes, every visible surface a mirror or glossy reflector, drawn twice
// side by side: the left half looks the probes up as distant environments (R and the material's
// roughness), the right half parallax-corrected against the room's box with the distance-based
// roughness (ibl/runtime/local_probe.hpp).
//
// Prints one JSON document: the scene (camera, room, roughness per wall), the probes (capture
// point, influence box, fade, priority, and the prefiltered chain, every texel rounded to half
// float: the page uploads them as RGBA16F, so both sides filter the same values), and the expected
// linear RGB of every pixel, shaded here in float by the same steps as room.frag.glsl with the
// library's functions (influence_weight, blend_probe_weights, parallax_correct,
// corrected_roughness, specular_lookup). It also marks the pixels whose camera ray meets the room
// within 1e-3 relative of an edge between two walls (float and double may pick different walls
// there) and gives the true radiance (room.trace) of the mirror pixels.
//
//   room_reference [face size 8..128 (default 32)]

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include <ibl/bake/prefilter.hpp>
#include <ibl/env/convert.hpp>
#include <ibl/reference/analytic_room.hpp>
#include <ibl/runtime/local_probe.hpp>
#include <ibl/runtime/lookup.hpp>

namespace {

using v3 = ibl::vec3<float>;
using v3d = ibl::vec3<double>;

// The view: each half is half_w x h pixels; pixel (x, y) counts from the bottom left (gl_FragCoord).
constexpr int half_w = 128, h = 96;
const v3 cam_pos(0.0f, 2.2f, 4.6f);
const v3 cam_target(0.6f, -0.5f, 0.5f);
constexpr float tan_x = 1.0f; // 90 degrees horizontal
// Roughness per wall (0 -X, 1 +X, 2 floor, 3 ceiling, 4 -Z, 5 +Z): the floor a mirror.
constexpr float roughness[6] = {0.2f, 0.25f, 0.0f, 0.5f, 0.1f, 0.3f};

struct probe {
    v3d at;
    v3d infl_lo, infl_hi;
    float fade = 1.0f;
    int priority = 0;
    ibl::specular_chain chain;
};

/// v rounded to the nearest half float (ties to even; the room's radiance is far inside half's range).
float round_half(float v) {
    const double a = std::fabs(double(v));
    if (!(a > 0.0)) return 0.0f;
    const int e = std::ilogb(a);
    const double q = std::ldexp(1.0, (e < -14 ? -14 : e) - 10);
    return float(std::copysign(std::nearbyint(a / q) * q, double(v)));
}

ibl::specular_chain capture(const ibl::analytic_room<double>& room, const v3d& at, int n) {
    const ibl::room_view<double> view{&room, at};
    ibl::cubemap<float> cube = ibl::bake_cubemap<float>(view, n, 2);
    cube.generate_mips();
    ibl::specular_chain chain = ibl::prefilter(cube, ibl::prefilter_options{});
    for (int l = 0; l < chain.levels(); ++l)
        for (int f = 0; f < 6; ++f)
            for (int y = 0; y < chain.size(l); ++y)
                for (int x = 0; x < chain.size(l); ++x) {
                    v3& t = chain.texel_ref(f, x, y, l);
                    t = v3(round_half(t.x), round_half(t.y), round_half(t.z));
                }
    chain.update_borders();
    return chain;
}

struct camera {
    v3 fwd, right, up;
    float tan_y;
};

camera make_camera() {
    camera c;
    c.fwd = glm::normalize(cam_target - cam_pos);
    c.right = glm::normalize(glm::cross(c.fwd, v3(0.0f, 1.0f, 0.0f)));
    c.up = glm::cross(c.right, c.fwd);
    c.tan_y = tan_x * float(h) / float(half_w);
    return c;
}

/// The camera ray through the centre of pixel (x, y) of a half (room.frag.glsl's steps).
v3 pixel_ray(const camera& c, int x, int y) {
    const float nx = 2.0f * (float(x) + 0.5f) / float(half_w) - 1.0f, ny = 2.0f * (float(y) + 0.5f) / float(h) - 1.0f;
    return glm::normalize(c.fwd + (nx * tan_x) * c.right + (ny * c.tan_y) * c.up);
}

/// Where the ray from p (inside) along d leaves the room, and the wall (analytic_room::exit in float,
/// room.frag.glsl's room_exit).
float room_exit(const v3& lo, const v3& hi, const v3& p, const v3& d, int& wall) {
    wall = -1;
    float best = 3.0e38f;
    for (int k = 0; k < 3; ++k) {
        float t = 3.0e38f;
        int w = -1;
        if (d[k] > 0.0f) t = (hi[k] - p[k]) / d[k], w = 2 * k + 1;
        else if (d[k] < 0.0f) t = (lo[k] - p[k]) / d[k], w = 2 * k;
        if (w >= 0 && t < best) best = t, wall = w;
    }
    return best;
}

/// The second-nearest wall's distance minus the nearest's, relative, in double: the margin of the
/// wall choice.
double wall_margin(const v3d& lo, const v3d& hi, const v3d& p, const v3d& d) {
    double t[3];
    for (int k = 0; k < 3; ++k)
        t[k] = d[k] > 0.0 ? (hi[k] - p[k]) / d[k] : d[k] < 0.0 ? (lo[k] - p[k]) / d[k] : 1e300;
    double a = std::fmin(t[0], std::fmin(t[1], t[2]));
    double b = 1e300;
    for (int k = 0; k < 3; ++k)
        if (t[k] != a) b = std::fmin(b, t[k]);
    int ties = 0;
    for (int k = 0; k < 3; ++k) ties += t[k] == a;
    return ties > 1 ? 0.0 : (b - a) / a;
}

void print_v3(const v3d& v) { std::printf("[%.9g, %.9g, %.9g]", v.x, v.y, v.z); }

} // namespace

int main(int argc, char** argv) {
    const int n = argc > 1 ? std::atoi(argv[1]) : 32;
    if (n < 8 || n > 128) {
        std::fprintf(stderr, "usage: room_reference [face size 8..128]\n");
        return 2;
    }
    const ibl::analytic_room<double> room;
    const v3 lo(room.lo), hi(room.hi);
    // The two probes of research/local_probe_error: influence boxes splitting the room at x = 0,
    // 1 m fades, equal priorities (their weights sum to >= 1 everywhere in the room).
    std::vector<probe> probes;
    probes.push_back({v3d(-2.0, 1.5, 0.0), room.lo - v3d(1.0), v3d(1.0, room.hi.y + 1.0, room.hi.z + 1.0), 1.0f, 0,
                      capture(room, v3d(-2.0, 1.5, 0.0), n)});
    probes.push_back({v3d(2.0, 1.5, 2.0), v3d(-1.0, room.lo.y - 1.0, room.lo.z - 1.0), room.hi + v3d(1.0), 1.0f, 0,
                      capture(room, v3d(2.0, 1.5, 2.0), n)});
    const ibl::probe_box<float> proxy = ibl::probe_box<float>::axis_aligned(lo, hi);
    const camera cam = make_camera();

    std::printf("{\"width\": %d, \"height\": %d, \"face\": %d,\n", 2 * half_w, h, n);
    std::printf("\"camera\": {\"position\": ");
    print_v3(v3d(cam_pos));
    std::printf(", \"forward\": ");
    print_v3(v3d(cam.fwd));
    std::printf(", \"right\": ");
    print_v3(v3d(cam.right));
    std::printf(", \"up\": ");
    print_v3(v3d(cam.up));
    std::printf(", \"tan\": [%.9g, %.9g]},\n\"room\": {\"lo\": ", double(tan_x), double(cam.tan_y));
    print_v3(room.lo);
    std::printf(", \"hi\": ");
    print_v3(room.hi);
    std::printf("},\n\"roughness\": [");
    for (int w = 0; w < 6; ++w) std::printf("%s%.9g", w ? ", " : "", double(roughness[w]));
    std::printf("],\n\"probes\": [");
    for (std::size_t i = 0; i < probes.size(); ++i) {
        const probe& p = probes[i];
        std::printf("%s\n{\"at\": ", i ? "," : "");
        print_v3(p.at);
        std::printf(", \"influence\": {\"lo\": ");
        print_v3(p.infl_lo);
        std::printf(", \"hi\": ");
        print_v3(p.infl_hi);
        std::printf("}, \"fade\": %.9g, \"priority\": %d, \"levels\": [", double(p.fade), p.priority);
        for (int l = 0; l < p.chain.levels(); ++l) {
            const int s = p.chain.size(l);
            std::printf("%s{\"size\": %d, \"faces\": [", l ? ", " : "", s);
            for (int f = 0; f < 6; ++f) {
                std::printf("%s[", f ? ", " : "");
                for (int y = 0; y < s; ++y)
                    for (int x = 0; x < s; ++x) {
                        const v3& t = p.chain.texel(f, x, y, l);
                        std::printf("%s%.9g,%.9g,%.9g", x || y ? "," : "", double(t.x), double(t.y), double(t.z));
                    }
                std::printf("]");
            }
            std::printf("]}");
        }
        std::printf("]}");
    }
    std::printf("],\n");

    // The expected pixels: rows from the bottom (readPixels), left half uncorrected, right corrected.
    std::vector<float> expect;
    std::vector<int> excluded, mirror;
    std::vector<v3d> truth;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < 2 * half_w; ++x) {
            const bool corrected = x >= half_w;
            const v3 d = pixel_ray(cam, corrected ? x - half_w : x, y);
            int wall = -1;
            const float t = room_exit(lo, hi, cam_pos, d, wall);
            v3 p = cam_pos + t * d;
            p[wall / 2] = (wall % 2) ? hi[wall / 2] : lo[wall / 2];
            v3 nrm(0.0f);
            nrm[wall / 2] = (wall % 2) ? -1.0f : 1.0f; // facing into the room
            const v3 r = d - 2.0f * glm::dot(nrm, d) * nrm;
            const float rough = roughness[wall];
            float weight[2], contrib[2];
            int priority[2];
            for (int i = 0; i < 2; ++i) {
                const ibl::probe_box<float> infl = ibl::probe_box<float>::axis_aligned(v3(probes[std::size_t(i)].infl_lo),
                                                                                    v3(probes[std::size_t(i)].infl_hi));
                weight[i] = ibl::influence_weight(infl, probes[std::size_t(i)].fade, p);
                priority[i] = probes[std::size_t(i)].priority;
            }
            (void)ibl::blend_probe_weights(weight, priority, 2, contrib); // the fallback (black) takes the rest
            v3 c(0.0f);
            for (int i = 0; i < 2; ++i) {
                const probe& pr = probes[std::size_t(i)];
                v3 dir = r;
                float rr = rough;
                if (corrected) {
                    const ibl::parallax_lookup<float> l = ibl::parallax_correct(proxy, v3(pr.at), p, r);
                    dir = l.direction;
                    rr = ibl::corrected_roughness(rough, l);
                }
                c += contrib[i] * ibl::specular_lookup(pr.chain, dir, rr);
            }
            expect.insert(expect.end(), {c.x, c.y, c.z});
            const int index = y * 2 * half_w + x;
            if (wall_margin(room.lo, room.hi, v3d(cam_pos), v3d(d)) < 1e-3) excluded.push_back(index);
            if (rough == 0.0f) {
                mirror.push_back(index);
                truth.push_back(room.trace(v3d(p), v3d(r)));
            }
        }
    std::printf("\"expect\": [");
    for (std::size_t i = 0; i < expect.size(); ++i) std::printf("%s%.9g", i ? "," : "", double(expect[i]));
    std::printf("],\n\"excluded\": [");
    for (std::size_t i = 0; i < excluded.size(); ++i) std::printf("%s%d", i ? "," : "", excluded[i]);
    std::printf("],\n\"mirror\": [");
    for (std::size_t i = 0; i < mirror.size(); ++i) std::printf("%s%d", i ? "," : "", mirror[i]);
    std::printf("],\n\"mirror_truth\": [");
    for (std::size_t i = 0; i < truth.size(); ++i)
        std::printf("%s%.9g,%.9g,%.9g", i ? "," : "", truth[i].x, truth[i].y, truth[i].z);
    std::printf("]}\n");
    return 0;
}
