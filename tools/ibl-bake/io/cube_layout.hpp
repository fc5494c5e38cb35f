#pragma once
// tools/ibl-bake/io/cube_layout.hpp — cubemap inputs and outputs as images: crosses, strips, six face
// files, the project's KTX2 cubemaps; lat-long and octahedral images of a cubemap level.
//
// Faces are the library's (env/cube_geometry.hpp): index 0..5 = +X, -X, +Y, -Y, +Z, -Z, OpenGL
// orientation, texel (x, y) of an n x n face centred on s = (x + 0.5)/n, t = (y + 0.5)/n, row
// y = 0 is t = 0. Face images here are stored exactly that way (image row y = face row y).
//
// Layouts of one image holding six n x n faces. A cell (column, row) of the layout is the square
// [column n, (column + 1) n) x [row n, (row + 1) n) of the image; image row 0 is the top.
//
//   horizontal cross, 4n x 3n (4:3)        vertical cross, 3n x 4n (3:4)
//          +----+                                 +----+
//          | +Y |                                 | +Y |
//     +----+----+----+----+                  +----+----+----+
//     | -X | +Z | +X | -Z |                  | -X | +Z | +X |
//     +----+----+----+----+                  +----+----+----+
//          | -Y |                                 | -Y |
//          +----+                                 +----+
//                                                 | -Z |  rotated 180 degrees
//                                                 +----+
//
// Horizontal cross: every face is placed as stored (face texel (x, y) at image (c n + x, r n + y)).
// Derivation from the table of cube_geometry.hpp: on +Z, direction = (sc, -tc, 1), so image right
// (+s) is +x and image down (+t) is -y; the edge s = 1 of +Z is x = 1, which is the edge s = 0 of
// +X (direction (1, -tc, -sc): s = 0 is z = 1), with t = t on both sides (-y). Likewise +X's s = 1
// edge (z = -1) meets -Z's s = 0 edge ((-sc, -tc, -1): s = 0 is x = 1); -X's s = 1 edge
// ((-1, -tc, sc): z = 1) meets +Z's s = 0 edge; +Y's t = 1 row ((sc, 1, tc): z = 1, x = sc) sits
// on +Z's t = 0 row (y = 1, x = sc); -Y's t = 0 row ((sc, -1, -tc): z = 1) under +Z's t = 1 row.
// So the cross is the unfolded cube: every fold of the image is seamless (the tests walk every
// texel pair across every fold and find them neighbours on the sphere). Seen from inside the cube
// with +Y up the cross is mirrored (the GL cube convention is left-handed): that is the layout
// cmft, AMD CubeMapGen and most viewers use for GL-oriented faces.
//
// Vertical cross: +Y, -X, +Z, +X, -Y in the same orientation as in the horizontal cross (the
// column +Y/+Z/-Y and the row -X/+Z/+X), and -Z below -Y rotated by 180 degrees (face texel (x, y)
// at image (n + n-1-x, 3n + n-1-y)): -Y's t = 1 row is z = -1 with x = sc, and -Z rotated has its
// t = 1 row (y = -1) on top, running x = -sc' = sc. This is the vertical cross of cmft (its
// "vcross" input and output: -Z flipped in both axes) and of the usual HDR cross files.
//
// Strips (only when their aspect is exact): horizontal 6n x n and vertical n x 6n, faces in the
// order +X, -X, +Y, -Y, +Z, -Z left to right / top to bottom, each as stored (cmft's "hstrip" /
// "vstrip"; not seamless, just the face list).
//
// Layout detection from the aspect ratio (detect_layout): w = 2h lat-long, 3w = 4h horizontal
// cross, 4w = 3h vertical cross, w = 6h horizontal strip, h = 6w vertical strip; anything else is
// an error naming the size. An explicit layout skips detection but still checks the size.
//
// Outputs of a cubemap level (ibl::cubemap<float> with valid borders):
//   latlong_from_cube     W x W/2 lat-long (the library's convention, env/latlong.hpp) with the
//                         value of cube.bilinear(direction of the texel centre, level): seamless
//                         bilinear across face edges and corners. Default W = 4 n (the equator
//                         then has about one lat-long texel per cube texel).
//   octahedral_from_cube  S x S plain octahedral map (Cigolle et al. 2014, "A Survey of Efficient
//                         Representations for Independent Unit Vectors"), +Y at the centre: the
//                         texel centre (i + 0.5, j + 0.5) gives p = (2 (i + 0.5)/S - 1,
//                         2 (j + 0.5)/S - 1) in [-1, 1]^2; with a = p.x, b = p.y,
//                         y = 1 - |a| - |b|, if y >= 0 the direction is (a, y, b), otherwise the
//                         outer triangles fold over: (sign(a) (1 - |b|), y, sign(b) (1 - |a|)),
//                         normalised (sign(0) = +1). Image right is +x, image down is +z; the four
//                         corners are -Y. Not equal-area (texel solid angles vary by about 3x).
//                         Default S = 2 n.

#include <array>
#include <optional>
#include <string>
#include <string_view>

#include "io/image_io.hpp"
#include "io/ktx2.hpp"

#include <ibl/env/cubemap.hpp>

namespace ibl_bake {

enum class input_layout { latlong, cross_horizontal, cross_vertical, strip_horizontal, strip_vertical };

/// What the command line may ask for: automatic detection or one layout.
enum class layout_choice { automatic, latlong, cross_horizontal, cross_vertical, strip_horizontal, strip_vertical };

/// "latlong", "hcross", "vcross", "hstrip", "vstrip" (the names parse_layout_choice accepts, with "auto").
const char* layout_name(input_layout layout) noexcept;
std::optional<layout_choice> parse_layout_choice(std::string_view text) noexcept;

/// The layout whose aspect ratio w x h has exactly (header comment). Throws image_error naming
/// `name` and the size for any other aspect ratio or a non-positive size.
input_layout detect_layout(int width, int height, const std::string& name);
/// detect_layout for automatic, else the chosen layout (its size is checked by faces_from_layout).
input_layout resolve_layout(int width, int height, layout_choice choice, const std::string& name);

/// Six square faces of one size, in the order +X, -X, +Y, -Y, +Z, -Z, stored as the library's faces.
struct cube_faces {
    int size = 0;
    std::array<image_rgb32f, 6> face;
};

/// A face texel of a layout image: face index and texel (x, y).
struct face_texel {
    int face, x, y;
};

/// The face texel that image pixel (px, py) of a layout of face size n shows; nullopt for the
/// empty cells of a cross and for pixels outside the image. (Not for latlong.)
std::optional<face_texel> layout_texel(input_layout layout, int n, int px, int py) noexcept;

/// Face size of a layout image: throws image_error naming `name`, the layout and the size when the
/// image is not exactly the layout's shape with square faces (e.g. a horizontal cross whose width
/// is not a multiple of 4 or that is not exactly 4:3). Not for latlong.
int layout_face_size(input_layout layout, int width, int height, const std::string& name);

/// Cuts the six faces out of a cross or strip image (bit-exact copies). Throws image_error.
cube_faces faces_from_layout(const image_rgb32f& image, input_layout layout, const std::string& name);
/// The inverse: the layout image of six faces; empty cross cells are 0. Throws image_error for
/// inconsistent faces or input_layout::latlong.
image_rgb32f layout_from_faces(const cube_faces& faces, input_layout layout, const std::string& name = "<faces>");
/// Shorthands for the horizontal cross.
inline cube_faces faces_from_cross(const image_rgb32f& image, const std::string& name) {
    return faces_from_layout(image, input_layout::cross_horizontal, name);
}
inline image_rgb32f cross_from_faces(const cube_faces& faces) {
    return layout_from_faces(faces, input_layout::cross_horizontal);
}

/// Checks six images as faces: each square, all of one size (messages name the offending
/// image by names[i] and give both sizes). Moves them into the result.
cube_faces faces_from_images(std::array<image_rgb32f, 6> images, const std::array<std::string, 6>& names);

/// Face file names: `pattern` with every "{face}" replaced by px, nx, py, ny, pz, nz. Throws
/// image_error if the pattern has no "{face}".
std::array<std::string, 6> face_paths(const std::string& pattern);
/// Reads the six files of face_paths(pattern) with read_image (HDR or EXR) and checks them with
/// faces_from_images. `reports` (optional) receives each file's read_report.
cube_faces read_face_files(const std::string& pattern, const read_options& options = {},
                           std::array<read_report, 6>* reports = nullptr);

/// One level of a cubemap_rgb32f (e.g. decode_ktx2_cubemap's level 0) as faces (copies).
cube_faces faces_from_ktx2(const cubemap_rgb32f& cube, int level = 0, const std::string& name = "<ktx2>");
/// One level of an ibl::cubemap as faces.
cube_faces faces_from_cubemap(const ibl::cubemap<float>& cube, int level);
/// An ibl::cubemap of the faces' size with `levels` levels (0 = the full chain): level 0 = the
/// faces, the others by generate_mips (exact box filter); borders valid, ready for lookups.
ibl::cubemap<float> cubemap_from_faces(const cube_faces& faces, int levels = 0);

/// Every level of a KTX2-layout cubemap (decode_ktx2_cubemap) as an ibl::cubemap<float> with its
/// stored levels (not regenerated mips) and valid borders: what a renderer samples.
ibl::cubemap<float> cubemap_from_rgb32f(const cubemap_rgb32f& cube);
/// The inverse: every level of an ibl::cubemap<float> in the KTX2 writer's layout.
cubemap_rgb32f cubemap_to_rgb32f(const ibl::cubemap<float>& cube);

/// Lat-long image of a level (header comment). width 0 = 4 x face size of the level; otherwise
/// width must be even and >= 2 (height = width / 2). Throws image_error for a bad width or level.
image_rgb32f latlong_from_cube(const ibl::cubemap<float>& cube, int level, int width = 0);

/// Octahedral direction of a point p in [-1, 1]^2 (header comment), unit length.
ibl::vec3<float> octahedral_direction(float a, float b) noexcept;
/// Octahedral image of a level; size 0 = 2 x face size of the level. Throws image_error.
image_rgb32f octahedral_from_cube(const ibl::cubemap<float>& cube, int level, int size = 0);

} // namespace ibl_bake
