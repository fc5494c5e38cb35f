#pragma once
// tools/ibl-bake/stages/preview_render.hpp — the preview's sphere grid (stage_preview.cpp says what
// it shows): shared by the preview and by the compression check, which renders it from the
// compressed files too.

#include <algorithm>
#include <cmath>

#include "stages/stages.hpp"

namespace ibl_bake::preview {

constexpr int cell = 128;          ///< pixels per sphere cell
constexpr int cols = 5, rows_ = 2;
constexpr double key_value = 0.6;  ///< exposure: key / mean luminance of the environment
constexpr double hfov_deg = 90.0;

struct camera {
    dvec3 fwd, right, up;
};
inline camera make_camera(const dvec3& light) {
    dvec3 f(-light.x, 0.0, -light.z);
    f = glm::dot(f, f) > 1e-12 ? glm::normalize(f) : dvec3(0.0, 0.0, -1.0);
    const dvec3 right = glm::normalize(glm::cross(f, dvec3(0.0, 1.0, 0.0)));
    return {f, right, glm::cross(right, f)};
}

struct preview_material {
    dvec3 base_color;
    double metallic;
};
inline const preview_material k_materials[rows_] = {{dvec3(0.8), 0.0}, {dvec3(0.95, 0.64, 0.54), 1.0}};

class preview_renderer {
public:
    preview_renderer(const product_view& bp, const ibl::cubemap<float>& source, const dvec3& light)
        : bp_(bp), source_(source), cam_(make_camera(light)) {
        for (int j = 0; j < rows_; ++j)
            for (int i = 0; i < cols; ++i) {
                ibl::pbr_material<double> m;
                m.base_color = k_materials[j].base_color;
                m.metallic = k_materials[j].metallic;
                m.roughness = 0.25 * i;
                shaders_[j][i] = ibl::pbr_shader<double>::from(m, true);
            }
    }

    /// Whether (fx, fy) lies on a sphere (not the background).
    static bool on_sphere(double fx, double fy) {
        const double radius = 0.45 * cell;
        const int ci = std::min(int(fx) / cell, cols - 1), cj = std::min(int(fy) / cell, rows_ - 1);
        const double lx = (fx - (ci + 0.5) * cell) / radius, ly = -(fy - (cj + 0.5) * cell) / radius;
        return lx * lx + ly * ly < 1.0;
    }

    /// Radiance at the sub-pixel position (fx, fy) of the w x h image.
    dvec3 at(double fx, double fy) const {
        const double radius = 0.45 * cell;
        const int ci = std::min(int(fx) / cell, cols - 1), cj = std::min(int(fy) / cell, rows_ - 1);
        const double lx = (fx - (ci + 0.5) * cell) / radius, ly = -(fy - (cj + 0.5) * cell) / radius;
        const double d2 = lx * lx + ly * ly;
        if (d2 < 1.0) { // orthographic sphere
            const dvec3 n = lx * cam_.right + ly * cam_.up - std::sqrt(1.0 - d2) * cam_.fwd;
            const dvec3 v = -cam_.fwd;
            return bp_.shade(shaders_[cj][ci], n, v);
        }
        const double tan_h = std::tan(0.5 * hfov_deg * ibl::pi_v<double> / 180.0), tan_v = tan_h * double(h) / double(w);
        const double ndc_x = 2.0 * fx / w - 1.0, ndc_y = 1.0 - 2.0 * fy / h;
        const dvec3 d = glm::normalize(cam_.fwd + ndc_x * tan_h * cam_.right + ndc_y * tan_v * cam_.up);
        // The residual's level 0 (the chain's level 0, what a runtime has) plus the extracted sun's
        // disk drawn analytically: its radiance where d is inside the cap, d.dir >= cos r,
        // 1 - cos r = omega / (2 pi). Without extraction the residual is the whole source.
        dvec3 l = dvec3(source_.radiance(fvec3(d), 0.0f));
        if (bp_.sun && glm::dot(d, bp_.sun->direction) >= 1.0 - ibl::cap_one_minus_cos(bp_.sun->solid_angle))
            l += bp_.sun->radiance;
        return l;
    }

    static constexpr int w = cols * cell, h = rows_ * cell;

private:
    const product_view& bp_;
    const ibl::cubemap<float>& source_;
    camera cam_;
    ibl::pbr_shader<double> shaders_[rows_][cols];
};

} // namespace ibl_bake::preview
