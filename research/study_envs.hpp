#pragma once
// research/study_envs.hpp — what the runtime studies (runtime_error, occlusion_error) share: the
// deterministic shading points and the environments (the built-in sky + sun and the HDRIs of
// tests/data), each with the 512^2 source cube the products are baked from and the MIS
// environment distribution of its reference.

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <span>
#include <string>

#include <ibl/core/executor.hpp>
#include <ibl/core/frame.hpp>
#include <ibl/env/analytic.hpp>
#include <ibl/env/convert.hpp>
#include <ibl/env/latlong.hpp>
#include <ibl/reference/env_importance.hpp>
#include <ibl/reference/radiance.hpp>

#if defined(IBL_RESEARCH_DATA_DIR)
#include "io/image_io.hpp"
#endif

namespace study {

/// A uniform number in [0, 1) from two integers (lowbias32 twice, 24 bits).
inline double unit(std::uint32_t a, std::uint32_t b) {
    return double(ibl::detail::rr_hash(ibl::detail::rr_hash(a * 0x9e3779b9u + 17u) ^ b) >> 8) * 0x1p-24;
}

/// Point k at view cosine mu: n uniform on the sphere, v at acos(mu) from n with uniform azimuth.
inline void make_point(std::uint32_t k, double mu, ibl::vec3<double>& n, ibl::vec3<double>& v) {
    const double z = 1.0 - 2.0 * unit(k, 1), ph = 2.0 * M_PI * unit(k, 2), s = std::sqrt(std::max(0.0, 1.0 - z * z));
    n = ibl::vec3<double>(s * std::cos(ph), z, s * std::sin(ph));
    const ibl::frame<double> fr = ibl::make_frame(n);
    const double az = 2.0 * M_PI * unit(k, 3), st = std::sqrt(std::max(0.0, (1.0 - mu) * (1.0 + mu)));
    v = fr.to_world(ibl::vec3<double>(st * std::cos(az), st * std::sin(az), mu));
}

/// Calls run(name, integrand, source cube, distribution) for the sky + sun (integrand analytic,
/// 4x4 supersampled cube, distribution 128^2) and for each of tests/data/{courtyard,studio}.exr
/// that reads (integrand the lat-long map, 2x2 supersampled, distribution 256^2); an unreadable
/// file is reported and skipped.
template <class Run> void for_each_environment(Run&& run) {
    {
        const ibl::sky_environment<double> sky = ibl::make_default_sky<double>();
        const ibl::cubemap<float> src = ibl::bake_cubemap<float>(sky, 512, 4, ibl::thread_executor{2});
        const ibl::cube_env_distribution dist = ibl::make_cube_env_distribution<double>(sky, 128, 4);
        run(std::string("sky + sun"), sky, src, dist);
    }
#if defined(IBL_RESEARCH_DATA_DIR)
    for (const char* file : {"courtyard.exr", "studio.exr"}) {
        const std::string path = std::string(IBL_RESEARCH_DATA_DIR) + "/" + file;
        try {
            const ibl_bake::image_rgb32f img = ibl_bake::read_latlong(path, {});
            ibl::latlong<float> map(img.width, img.height, std::span<const float>(img.rgb), 1);
            map.update_borders();
            const ibl::cubemap<float> src = ibl::bake_cubemap<float>(map, 512, 2, ibl::thread_executor{2});
            const ibl::cube_env_distribution dist = ibl::make_cube_env_distribution<float>(map, 256, 2);
            run(std::string(file), map, src, dist);
        } catch (const std::exception& ex) {
            std::printf("%s skipped: %s\n", file, ex.what());
        }
    }
#endif
}

} // namespace study
