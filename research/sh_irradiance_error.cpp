// research/sh_irradiance_error.cpp — how wrong is 3-band SH irradiance (Ramamoorthi & Hanrahan 2001), measured
// against brute-force cosine-weighted integration of the same cubemap?
//
//   reference  E(n) = sum over every texel t of L_t max(0, n . d_t) Omega_t   (exact Omega_t, double)
//   SH         E(n) = sum_k A_l L_k Y_k(n), L_k = projection of the same cubemap (exact Omega_t)
//
// Both read the same texels, so the difference is the truncation of the series (the 3-band
// Lambert kernel's own error plus ringing), not sampling noise. Normals: the texel centres of a
// 16 x 16-per-face cube (1536 directions). Reported per environment: mean and largest relative
// error, and the smallest irradiance (ringing makes it negative around suns), without and with
// the automatic Hanning window.
//
// Produces: no docs table (a study kept for comparison; the plan's SH figures come from
// research/plan_measure.cpp `sh`). Run with
//   cmake --preset release && cmake --build --preset release --target sh_irradiance_error
//   ./build/release/research/sh_irradiance_error [latlong.exr|.hdr ...]    (default: tests/data/courtyard.exr)
#include <ibl/env.hpp>
#include <ibl/sh.hpp>

#include "io/image_io.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace {

using dvec3 = ibl::vec3<double>;

struct errors {
    double mean_rel = 0, max_rel = 0, min_e = 1e300;
};

// Brute-force irradiance at each normal (luminance-free: per channel, then relative error of the
// channel sum so that one colour number summarises the three).
std::vector<dvec3> brute_force(const ibl::cubemap<float>& cube, const std::vector<dvec3>& normals) {
    const int n = cube.size(0);
    std::vector<dvec3> dir, rad;
    std::vector<double> omega;
    for (int f = 0; f < 6; ++f)
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
                dir.push_back(ibl::cube_texel_direction<double>(f, x, y, n));
                omega.push_back(ibl::cube_texel_solid_angle<double>(x, y, n));
                rad.push_back(dvec3(cube.texel(f, x, y, 0)) * omega.back());
            }
    std::vector<dvec3> e(normals.size(), dvec3(0));
    ibl::thread_executor{}(normals.size(), [&](std::size_t b, std::size_t end) {
        for (std::size_t i = b; i < end; ++i) {
            dvec3 s(0);
            for (std::size_t t = 0; t < dir.size(); ++t) {
                const double c = glm::dot(normals[i], dir[t]);
                s += rad[t] * (c > 0 ? c : 0.0);
            }
            e[i] = s;
        }
    });
    return e;
}

template <int B>
errors compare(const ibl::sh_coeffs<double, B>& radiance, const std::vector<dvec3>& normals,
               const std::vector<dvec3>& ref) {
    errors r;
    for (std::size_t i = 0; i < normals.size(); ++i) {
        const dvec3 e = ibl::sh_irradiance_at(radiance, normals[i]);
        const double er = ref[i].x + ref[i].y + ref[i].z, es = e.x + e.y + e.z;
        const double rel = std::fabs(es - er) / er;
        r.mean_rel += rel / double(normals.size());
        r.max_rel = std::max(r.max_rel, rel);
        r.min_e = std::min({r.min_e, e.x, e.y, e.z});
    }
    return r;
}

void report(const char* name, const ibl::cubemap<float>& cube) {
    std::vector<dvec3> normals;
    for (int f = 0; f < 6; ++f)
        for (int y = 0; y < 16; ++y)
            for (int x = 0; x < 16; ++x) normals.push_back(ibl::cube_texel_direction<double>(f, x, y, 16));
    const std::vector<dvec3> ref = brute_force(cube, normals);
    double ref_min = 1e300;
    for (const auto& e : ref) ref_min = std::min({ref_min, e.x, e.y, e.z});
    const auto coeffs = ibl::project_cube<3>(
        cube.size(0), [&](int f, int x, int y) { return dvec3(cube.texel(f, x, y, 0)); }, ibl::thread_executor{});
    const errors raw = compare<3>(coeffs, normals, ref);
    const auto win = ibl::sh_auto_window(coeffs);
    const errors w = compare<3>(win.radiance, normals, ref);
    std::printf("%-28s | %9.2e %9.2e %11.4g | %7.3g %9.2e %9.2e %11.4g | %11.4g\n", name, raw.mean_rel, raw.max_rel,
                raw.min_e, double(win.width), w.mean_rel, w.max_rel, w.min_e, ref_min);
}

} // namespace

int main(int argc, char** argv) {
    std::printf("3-band SH irradiance vs brute-force cosine integration of the same 128^2 cubemap (1536 normals)\n");
    std::printf("%-28s | %9s %9s %11s | %7s %9s %9s %11s | %11s\n", "environment", "mean rel", "max rel", "min E",
                "window", "mean rel", "max rel", "min E", "min E (ref)");
    {
        const auto sky = ibl::make_default_sky<float>();
        // k = 8: a 1-degree sun covers ~ 8 texels of 128^2 faces; 64 sub-samples each keep its
        // power within ~1e-3 (env tests: k = 16 at n = 32 gives 1.3e-4).
        report("default sky + sun", ibl::bake_cubemap<float>(sky, 128, 8, ibl::thread_executor{}, 1));
    }
    std::vector<std::string> files;
    for (int i = 1; i < argc; ++i) files.emplace_back(argv[i]);
    if (files.empty()) files.emplace_back(std::string(IBL_RESEARCH_DATA_DIR) + "/courtyard.exr");
    for (const auto& file : files) {
        try {
            const ibl_bake::image_rgb32f img = ibl_bake::read_latlong(file);
            const ibl::latlong<float> ll(img.width, img.height, std::span<const float>(img.rgb), 1);
            const auto cube = ibl::latlong_to_cubemap(ll, 128, 2, ibl::thread_executor{}, 1);
            report(file.substr(file.find_last_of('/') + 1).c_str(), cube);
        } catch (const std::exception& e) {
            std::fprintf(stderr, "%s\n", e.what());
            return 1;
        }
    }
    return 0;
}
