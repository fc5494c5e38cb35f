// tools/ibl-bake/io/cube_layout.cpp — cube layouts as images (conventions: cube_layout.hpp).

#include "io/cube_layout.hpp"

#include <cmath>
#include <cstddef>
#include <cstring>
#include <utility>

#include <ibl/env/latlong.hpp>

namespace ibl_bake {
namespace {

/// Where a face sits in a layout: cell column, cell row, rotated by 180 degrees.
struct cell {
    int column, row;
    bool rotated;
};

// Face order +X, -X, +Y, -Y, +Z, -Z.
constexpr cell hcross_cells[6] = {{2, 1, false}, {0, 1, false}, {1, 0, false}, {1, 2, false}, {1, 1, false}, {3, 1, false}};
constexpr cell vcross_cells[6] = {{2, 1, false}, {0, 1, false}, {1, 0, false}, {1, 2, false}, {1, 1, false}, {1, 3, true}};

cell face_cell(input_layout layout, int face) noexcept {
    switch (layout) {
    case input_layout::cross_horizontal: return hcross_cells[face];
    case input_layout::cross_vertical: return vcross_cells[face];
    case input_layout::strip_horizontal: return {face, 0, false};
    case input_layout::strip_vertical: return {0, face, false};
    case input_layout::latlong: break;
    }
    return {0, 0, false};
}

/// Layout size in cells (columns, rows).
std::pair<int, int> layout_cells(input_layout layout) noexcept {
    switch (layout) {
    case input_layout::cross_horizontal: return {4, 3};
    case input_layout::cross_vertical: return {3, 4};
    case input_layout::strip_horizontal: return {6, 1};
    case input_layout::strip_vertical: return {1, 6};
    case input_layout::latlong: break;
    }
    return {2, 1};
}

const char* layout_title(input_layout layout) noexcept {
    switch (layout) {
    case input_layout::latlong: return "lat-long";
    case input_layout::cross_horizontal: return "horizontal cross";
    case input_layout::cross_vertical: return "vertical cross";
    case input_layout::strip_horizontal: return "horizontal strip";
    case input_layout::strip_vertical: return "vertical strip";
    }
    return "?";
}

std::string size_text(int w, int h) { return std::to_string(w) + " x " + std::to_string(h); }

void check_faces(const cube_faces& faces, const std::string& name) {
    if (faces.size < 1) throw image_error(name, "cube faces of size " + std::to_string(faces.size));
    for (int f = 0; f < 6; ++f) {
        const image_rgb32f& im = faces.face[std::size_t(f)];
        if (im.width != faces.size || im.height != faces.size ||
            im.rgb.size() != std::size_t(faces.size) * std::size_t(faces.size) * 3)
            throw image_error(name, "face " + std::to_string(f) + " is " + size_text(im.width, im.height) +
                                        ", expected " + size_text(faces.size, faces.size));
    }
}

constexpr const char* face_suffix[6] = {"px", "nx", "py", "ny", "pz", "nz"};

} // namespace

const char* layout_name(input_layout layout) noexcept {
    switch (layout) {
    case input_layout::latlong: return "latlong";
    case input_layout::cross_horizontal: return "hcross";
    case input_layout::cross_vertical: return "vcross";
    case input_layout::strip_horizontal: return "hstrip";
    case input_layout::strip_vertical: return "vstrip";
    }
    return "?";
}

std::optional<layout_choice> parse_layout_choice(std::string_view t) noexcept {
    if (t == "auto") return layout_choice::automatic;
    if (t == "latlong") return layout_choice::latlong;
    if (t == "hcross") return layout_choice::cross_horizontal;
    if (t == "vcross") return layout_choice::cross_vertical;
    if (t == "hstrip") return layout_choice::strip_horizontal;
    if (t == "vstrip") return layout_choice::strip_vertical;
    return std::nullopt;
}

input_layout detect_layout(int w, int h, const std::string& name) {
    if (w < 1 || h < 1) throw image_error(name, "image of size " + size_text(w, h));
    const long long W = w, H = h;
    if (W == 2 * H) return input_layout::latlong;
    if (3 * W == 4 * H) return input_layout::cross_horizontal;
    if (4 * W == 3 * H) return input_layout::cross_vertical;
    if (W == 6 * H) return input_layout::strip_horizontal;
    if (H == 6 * W) return input_layout::strip_vertical;
    throw image_error(name, "cannot tell the layout of a " + size_text(w, h) +
                                " image: expected 2:1 (lat-long), 4:3 (horizontal cross), 3:4 (vertical cross), "
                                "6:1 or 1:6 (strip of six faces)");
}

input_layout resolve_layout(int w, int h, layout_choice choice, const std::string& name) {
    switch (choice) {
    case layout_choice::automatic: return detect_layout(w, h, name);
    case layout_choice::latlong: return input_layout::latlong;
    case layout_choice::cross_horizontal: return input_layout::cross_horizontal;
    case layout_choice::cross_vertical: return input_layout::cross_vertical;
    case layout_choice::strip_horizontal: return input_layout::strip_horizontal;
    case layout_choice::strip_vertical: return input_layout::strip_vertical;
    }
    return detect_layout(w, h, name);
}

int layout_face_size(input_layout layout, int w, int h, const std::string& name) {
    if (layout == input_layout::latlong) throw image_error(name, "a lat-long image has no cube faces");
    const auto [cols, rows] = layout_cells(layout);
    const std::string shape = std::string(layout_title(layout)) + " (" + std::to_string(cols) + ":" +
                              std::to_string(rows) + ", " + std::to_string(cols) + " x " + std::to_string(rows) +
                              " square faces)";
    if (w < cols || h < rows || w % cols != 0 || h % rows != 0 || w / cols != h / rows) {
        std::string why;
        if (w % cols != 0) why = "width " + std::to_string(w) + " is not a multiple of " + std::to_string(cols);
        else if (h % rows != 0) why = "height " + std::to_string(h) + " is not a multiple of " + std::to_string(rows);
        else if (w < cols || h < rows) why = "too small";
        else
            why = "faces would be " + size_text(w / cols, h / rows) + ", not square";
        throw image_error(name, "a " + size_text(w, h) + " image is not a " + shape + ": " + why);
    }
    return w / cols;
}

std::optional<face_texel> layout_texel(input_layout layout, int n, int px, int py) noexcept {
    if (layout == input_layout::latlong || n < 1 || px < 0 || py < 0) return std::nullopt;
    const int c = px / n, r = py / n;
    for (int f = 0; f < 6; ++f) {
        const cell k = face_cell(layout, f);
        if (k.column != c || k.row != r) continue;
        const int x = px - c * n, y = py - r * n;
        return k.rotated ? face_texel{f, n - 1 - x, n - 1 - y} : face_texel{f, x, y};
    }
    return std::nullopt;
}

cube_faces faces_from_layout(const image_rgb32f& image, input_layout layout, const std::string& name) {
    if (image.rgb.size() != std::size_t(image.width > 0 ? image.width : 0) * std::size_t(image.height > 0 ? image.height : 0) * 3)
        throw image_error(name, "inconsistent image of " + size_text(image.width, image.height));
    const int n = layout_face_size(layout, image.width, image.height, name);
    cube_faces out;
    out.size = n;
    for (int f = 0; f < 6; ++f) {
        const cell k = face_cell(layout, f);
        image_rgb32f face(n, n);
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
                const int ix = k.rotated ? n - 1 - x : x, iy = k.rotated ? n - 1 - y : y;
                std::memcpy(face.texel(x, y), image.texel(k.column * n + ix, k.row * n + iy), 3 * sizeof(float));
            }
        out.face[std::size_t(f)] = std::move(face);
    }
    return out;
}

image_rgb32f layout_from_faces(const cube_faces& faces, input_layout layout, const std::string& name) {
    if (layout == input_layout::latlong) throw image_error(name, "layout_from_faces: use latlong_from_cube for lat-long");
    check_faces(faces, name);
    const int n = faces.size;
    const auto [cols, rows] = layout_cells(layout);
    image_rgb32f image(cols * n, rows * n);
    for (int f = 0; f < 6; ++f) {
        const cell k = face_cell(layout, f);
        const image_rgb32f& face = faces.face[std::size_t(f)];
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
                const int ix = k.rotated ? n - 1 - x : x, iy = k.rotated ? n - 1 - y : y;
                std::memcpy(image.texel(k.column * n + ix, k.row * n + iy), face.texel(x, y), 3 * sizeof(float));
            }
    }
    return image;
}

cube_faces faces_from_images(std::array<image_rgb32f, 6> images, const std::array<std::string, 6>& names) {
    for (int f = 0; f < 6; ++f) {
        const image_rgb32f& im = images[std::size_t(f)];
        if (im.width != im.height)
            throw image_error(names[std::size_t(f)], "cube face is " + size_text(im.width, im.height) + ", not square");
        if (im.width < 1) throw image_error(names[std::size_t(f)], "empty cube face");
        if (im.width != images[0].width)
            throw image_error(names[std::size_t(f)], "cube face is " + size_text(im.width, im.height) + " but " +
                                                         names[0] + " is " + size_text(images[0].width, images[0].height) +
                                                         ": all six faces must have one size");
    }
    cube_faces out;
    out.size = images[0].width;
    out.face = std::move(images);
    check_faces(out, names[0]);
    return out;
}

std::array<std::string, 6> face_paths(const std::string& pattern) {
    static constexpr std::string_view key = "{face}";
    if (pattern.find(key) == std::string::npos)
        throw image_error(pattern, "a face file pattern must contain {face} (replaced by px, nx, py, ny, pz, nz)");
    std::array<std::string, 6> out;
    for (int f = 0; f < 6; ++f) {
        std::string s;
        std::size_t at = 0;
        for (std::size_t k; (k = pattern.find(key, at)) != std::string::npos; at = k + key.size())
            s += pattern.substr(at, k - at) + face_suffix[f];
        s += pattern.substr(at);
        out[std::size_t(f)] = s;
    }
    return out;
}

cube_faces read_face_files(const std::string& pattern, const read_options& options, std::array<read_report, 6>* reports) {
    const std::array<std::string, 6> paths = face_paths(pattern);
    std::array<image_rgb32f, 6> images;
    for (std::size_t f = 0; f < 6; ++f) images[f] = read_image(paths[f], options, reports ? &(*reports)[f] : nullptr);
    return faces_from_images(std::move(images), paths);
}

cube_faces faces_from_ktx2(const cubemap_rgb32f& cube, int level, const std::string& name) {
    if (level < 0 || level >= int(cube.levels.size()))
        throw image_error(name, "no level " + std::to_string(level) + " in a cubemap of " +
                                    std::to_string(cube.levels.size()) + " levels");
    const int n = cube.face_size(level);
    cube_faces out;
    out.size = n;
    for (std::size_t f = 0; f < 6; ++f) {
        const std::vector<float>& src = cube.levels[std::size_t(level)][f];
        if (src.size() != std::size_t(n) * std::size_t(n) * 3)
            throw image_error(name, "level " + std::to_string(level) + " face " + std::to_string(f) + " has " +
                                        std::to_string(src.size()) + " values, expected " +
                                        std::to_string(std::size_t(n) * std::size_t(n) * 3));
        out.face[f].width = n;
        out.face[f].height = n;
        out.face[f].rgb = src;
    }
    return out;
}

cube_faces faces_from_cubemap(const ibl::cubemap<float>& cube, int level) {
    if (level < 0 || level >= cube.levels())
        throw image_error("<cubemap>", "no level " + std::to_string(level) + " in a cubemap of " +
                                           std::to_string(cube.levels()) + " levels");
    const int n = cube.size(level);
    cube_faces out;
    out.size = n;
    for (int f = 0; f < 6; ++f) {
        image_rgb32f im(n, n);
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
                const ibl::vec3<float>& v = cube.texel(f, x, y, level);
                float* p = im.texel(x, y);
                p[0] = v.x;
                p[1] = v.y;
                p[2] = v.z;
            }
        out.face[std::size_t(f)] = std::move(im);
    }
    return out;
}

ibl::cubemap<float> cubemap_from_faces(const cube_faces& faces, int levels) {
    check_faces(faces, "<faces>");
    ibl::cubemap<float> cube(faces.size, levels);
    cube.fill(0, [&](int f, int x, int y) {
        const float* p = faces.face[std::size_t(f)].texel(x, y);
        return ibl::vec3<float>(p[0], p[1], p[2]);
    });
    cube.generate_mips();
    return cube;
}

image_rgb32f latlong_from_cube(const ibl::cubemap<float>& cube, int level, int width) {
    if (level < 0 || level >= cube.levels())
        throw image_error("<latlong>", "no level " + std::to_string(level) + " in a cubemap of " +
                                           std::to_string(cube.levels()) + " levels");
    if (!cube.borders_valid()) throw image_error("<latlong>", "cubemap borders are stale (call update_borders)");
    if (width == 0) width = 4 * cube.size(level);
    if (width < 2 || width % 2 != 0 || width > 65536)
        throw image_error("<latlong>", "lat-long width must be even, in [2, 65536], got " + std::to_string(width));
    const int height = width / 2;
    image_rgb32f out(width, height);
    for (int j = 0; j < height; ++j) {
        const double v = 1.0 - (double(j) + 0.5) / double(height);
        for (int i = 0; i < width; ++i) {
            const double u = (double(i) + 0.5) / double(width);
            const ibl::vec3<float> d(ibl::latlong_direction<double>(u, v));
            const ibl::vec3<float> c = cube.bilinear(d, level);
            float* p = out.texel(i, j);
            p[0] = c.x;
            p[1] = c.y;
            p[2] = c.z;
        }
    }
    return out;
}

ibl::vec3<float> octahedral_direction(float a, float b) noexcept {
    const double x = a, z = b;
    const double y = 1.0 - std::fabs(x) - std::fabs(z);
    ibl::vec3<double> d;
    if (y >= 0.0) d = {x, y, z};
    else d = {std::copysign(1.0 - std::fabs(z), x), y, std::copysign(1.0 - std::fabs(x), z)};
    return ibl::vec3<float>(d / std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z));
}

image_rgb32f octahedral_from_cube(const ibl::cubemap<float>& cube, int level, int size) {
    if (level < 0 || level >= cube.levels())
        throw image_error("<octahedral>", "no level " + std::to_string(level) + " in a cubemap of " +
                                              std::to_string(cube.levels()) + " levels");
    if (!cube.borders_valid()) throw image_error("<octahedral>", "cubemap borders are stale (call update_borders)");
    if (size == 0) size = 2 * cube.size(level);
    if (size < 1 || size > 65536)
        throw image_error("<octahedral>", "octahedral size must be in [1, 65536], got " + std::to_string(size));
    image_rgb32f out(size, size);
    for (int j = 0; j < size; ++j)
        for (int i = 0; i < size; ++i) {
            const float a = float(2.0 * (double(i) + 0.5) / double(size) - 1.0);
            const float b = float(2.0 * (double(j) + 0.5) / double(size) - 1.0);
            const ibl::vec3<float> c = cube.bilinear(octahedral_direction(a, b), level);
            float* p = out.texel(i, j);
            p[0] = c.x;
            p[1] = c.y;
            p[2] = c.z;
        }
    return out;
}

cubemap_rgb32f cubemap_to_rgb32f(const ibl::cubemap<float>& c) {
    cubemap_rgb32f k = cubemap_rgb32f::zeros(c.size(0), c.levels());
    for (int l = 0; l < c.levels(); ++l) {
        const int s = k.face_size(l);
        for (int f = 0; f < 6; ++f)
            for (int y = 0; y < s; ++y)
                for (int x = 0; x < s; ++x) {
                    const ibl::vec3<float>& v = c.texel(f, x, y, l);
                    float* t = &k.levels[std::size_t(l)][std::size_t(f)][3 * (std::size_t(y) * std::size_t(s) + std::size_t(x))];
                    t[0] = v.x, t[1] = v.y, t[2] = v.z;
                }
    }
    return k;
}

ibl::cubemap<float> cubemap_from_rgb32f(const cubemap_rgb32f& k) {
    ibl::cubemap<float> c(k.size, int(k.levels.size()));
    for (int l = 0; l < c.levels(); ++l) {
        const int s = k.face_size(l);
        c.fill(l, [&](int f, int x, int y) {
            const float* t = &k.levels[std::size_t(l)][std::size_t(f)][3 * (std::size_t(y) * std::size_t(s) + std::size_t(x))];
            return ibl::vec3<float>(t[0], t[1], t[2]);
        });
    }
    c.update_borders();
    return c;
}

} // namespace ibl_bake
