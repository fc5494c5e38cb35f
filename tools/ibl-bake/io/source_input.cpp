// tools/ibl-bake/io/source_input.cpp — see source_input.hpp.

#include "io/source_input.hpp"

#include <algorithm>
#include <span>

#include <ibl/env/cube_geometry.hpp>

#include "io/cube_layout.hpp"
#include "io/input_guard.hpp"
#include "io/ktx2.hpp"

namespace ibl_bake {

namespace {

using dvec3 = ibl::vec3<double>;
using fvec3 = ibl::vec3<float>;

/// The layout of an image input (a face set or a KTX2 file is read before: automatic).
layout_choice image_layout(input_form f) {
    switch (f) {
    case input_form::latlong: return layout_choice::latlong;
    case input_form::hcross: return layout_choice::cross_horizontal;
    case input_form::vcross: return layout_choice::cross_vertical;
    case input_form::hstrip: return layout_choice::strip_horizontal;
    case input_form::vstrip: return layout_choice::strip_vertical;
    default: return layout_choice::automatic;
    }
}

bool ends_with(const std::string& s, const std::string& suffix) {
    if (s.size() < suffix.size()) return false;
    std::string tail = s.substr(s.size() - suffix.size());
    for (char& c : tail) c = char(std::tolower(static_cast<unsigned char>(c)));
    return tail == suffix;
}

void set_cube(source_env& src, cube_faces faces, const std::string& format) {
    for (image_rgb32f& f : faces.face) src.values_clamped += clamp_radiance(f, src.rr);
    src.analytic = false;
    src.cube = std::make_unique<ibl::cubemap<float>>(cubemap_from_faces(faces));
    src.width = src.height = faces.size;
    src.layout = format;
}

read_options input_read_options(const bake_options& opt) {
    read_options ro;
    ro.max_pixels = opt.max_input_pixels;
    ro.part = opt.part;
    return ro;
}

} // namespace

void read_source(const bake_options& opt, source_env& src) {
    src.name = opt.input;
    const read_options ro = input_read_options(opt);
    const bool automatic = opt.input_layout == input_form::automatic;
    const bool faces = opt.input_layout == input_form::faces || (automatic && opt.input.find("{face}") != std::string::npos);
    const bool ktx2 = opt.input_layout == input_form::ktx2 || (automatic && ends_with(opt.input, ".ktx2"));
    const std::uint64_t max_bytes = input_byte_limit(opt.max_input_pixels);
    if (faces) {
        for (const std::string& p : face_paths(opt.input)) check_input_file(p, max_bytes);
        std::array<read_report, 6> reports;
        set_cube(src, read_face_files(opt.input, ro, &reports), "faces");
        src.rr = reports[0];
        for (int f = 1; f < 6; ++f) {
            src.rr.negative_values += reports[std::size_t(f)].negative_values;
            src.rr.max_value = std::max(src.rr.max_value, reports[std::size_t(f)].max_value);
        }
        return;
    }
    check_input_file(opt.input, max_bytes);
    if (ktx2) {
        const std::vector<unsigned char> bytes = read_file(opt.input);
        set_cube(src, faces_from_ktx2(decode_ktx2_cubemap(bytes, opt.input), 0, opt.input), "ktx2");
        src.rr.format = "KTX2";
        return;
    }
    image_rgb32f img = read_image(opt.input, ro, &src.rr);
    src.values_clamped += clamp_radiance(img, src.rr); // the cube path below finds nothing left to clamp
    const input_layout layout = resolve_layout(img.width, img.height, image_layout(opt.input_layout), opt.input);
    src.analytic = false;
    if (layout != input_layout::latlong) {
        set_cube(src, faces_from_layout(img, layout, opt.input), layout_name(layout));
        src.width = img.width, src.height = img.height;
        return;
    }
    src.layout = "latlong";
    src.width = img.width;
    src.height = img.height;
    src.map = std::make_unique<ibl::latlong<float>>(img.width, img.height, std::span<const float>(img.rgb), 1);
    src.map->update_borders();
}

void mirror_source(source_env& src) {
    src.mirrored = true;
    if (src.analytic) {
        src.sky.set_sun(dvec3(-src.sky.sun_dir.x, src.sky.sun_dir.y, src.sky.sun_dir.z), src.sky.sun_radiance, src.sky.sun_angular_radius);
        return;
    }
    if (src.cube) {
        const ibl::cubemap<float>& c = *src.cube;
        const int n = c.size(0);
        cube_faces f;
        f.size = n;
        for (int face = 0; face < 6; ++face) {
            f.face[std::size_t(face)] = image_rgb32f(n, n);
            for (int y = 0; y < n; ++y)
                for (int x = 0; x < n; ++x) {
                    const dvec3 d = ibl::cube_texel_direction<double>(face, x, y, n);
                    const ibl::cube_coord<double> m = ibl::cube_lookup(dvec3(-d.x, d.y, d.z));
                    const int mx = std::clamp(int(m.s * n), 0, n - 1), my = std::clamp(int(m.t * n), 0, n - 1);
                    const fvec3& v = c.texel(m.face, mx, my, 0);
                    float* t = f.face[std::size_t(face)].texel(x, y);
                    t[0] = v.x, t[1] = v.y, t[2] = v.z;
                }
        }
        src.cube = std::make_unique<ibl::cubemap<float>>(cubemap_from_faces(f));
        return;
    }
    // lat-long: u = 0.5 + atan2(z, x) / (2 pi); x -> -x gives u' = 1.5 - u (mod 1): column i -> (W/2 - 1 - i) mod W
    const ibl::latlong<float>& m = *src.map;
    const int w = m.width(0), h = m.height(0);
    image_rgb32f img(w, h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const int sx = ((w / 2 - 1 - x) % w + w) % w;
            const fvec3 v = m.texel(sx, y, 0);
            float* t = img.texel(x, y);
            t[0] = v.x, t[1] = v.y, t[2] = v.z;
        }
    src.map = std::make_unique<ibl::latlong<float>>(w, h, std::span<const float>(img.rgb), 1);
    src.map->update_borders();
}

} // namespace ibl_bake
