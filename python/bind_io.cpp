// python/bind_io.cpp — images and cubes from files: Radiance HDR / OpenEXR through the bake tool's
// I/O library (ibl_bake_io, tools/ibl-bake/io/image_io.hpp), lat-long -> cube by ibl::latlong +
// ibl::bake_cubemap, and the KTX2 cubemaps ibl-bake writes (io/ktx2.hpp, every format it decodes).
// Without ibl_bake_io (IBL_PY_HAVE_BAKE_IO undefined) the file readers raise RuntimeError.
#include "common.hpp"

#include <ibl/core/executor.hpp>
#include <ibl/core/limits.hpp>
#include <ibl/env/convert.hpp>
#include <ibl/env/cubemap.hpp>
#include <ibl/env/latlong.hpp>

#ifdef IBL_PY_HAVE_BAKE_IO
#include "io/image_io.hpp"
#include "io/ktx2.hpp"
#endif

#include <cmath>
#include <cstdint>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace ibl_py {

namespace {

#ifdef IBL_PY_HAVE_BAKE_IO
/// image_error and the std exceptions of a reader as ValueError / OSError with their message.
template <class F> auto guarded(F&& f) {
    try {
        return f();
    } catch (const ibl_bake::image_error& e) {
        throw py::value_error(std::string("ibl: ") + e.what());
    } catch (const std::bad_alloc&) {
        throw;
    } catch (const std::length_error& e) {
        throw py::value_error(std::string("ibl: ") + e.what());
    } catch (const std::invalid_argument& e) {
        throw py::value_error(std::string("ibl: ") + e.what());
    }
}
#else
[[noreturn]] void no_bake_io(const char* fn) {
    throw std::runtime_error(std::string("ibl.") + fn +
                             ": the module was built without the bake tool's I/O library (ibl_bake_io: "
                             "IBL_BUILD_TOOLS or IBL_BUILD_RESEARCH off, or its dependencies missing)");
}
#endif

py::array_t<float> read_image(const std::string& path, bool latlong, long long max_pixels, bool replace_nonfinite) {
#ifdef IBL_PY_HAVE_BAKE_IO
    if (max_pixels < 1) throw py::value_error("ibl.read_image: max_pixels must be positive, got " + std::to_string(max_pixels));
    ibl_bake::read_options opt;
    opt.max_pixels = std::uint64_t(max_pixels);
    opt.nonfinite = replace_nonfinite ? ibl_bake::nonfinite_policy::replace_with_zero : ibl_bake::nonfinite_policy::reject;
    std::optional<ibl_bake::image_rgb32f> img;
    {
        py::gil_scoped_release release;
        guarded([&] {
            img.emplace(latlong ? ibl_bake::read_latlong(path, opt) : ibl_bake::read_image(path, opt));
            return 0;
        });
    }
    py::array_t<float> out({py::ssize_t(img->height), py::ssize_t(img->width), py::ssize_t(3)});
    std::copy(img->rgb.begin(), img->rgb.end(), out.mutable_data());
    return out;
#else
    (void)path;
    (void)latlong;
    (void)max_pixels;
    (void)replace_nonfinite;
    no_bake_io("read_image");
#endif
}

py::list read_ktx2(const std::string& path) {
#ifdef IBL_PY_HAVE_BAKE_IO
    std::optional<ibl_bake::cubemap_rgb32f> cube;
    {
        py::gil_scoped_release release;
        guarded([&] {
            const std::vector<unsigned char> bytes = ibl_bake::read_file(path);
            cube.emplace(ibl_bake::decode_ktx2_cubemap(std::span<const unsigned char>(bytes), path));
            return 0;
        });
    }
    py::list out;
    for (int l = 0; l < int(cube->levels.size()); ++l) {
        const py::ssize_t s = cube->face_size(l);
        py::array_t<float> a({py::ssize_t(6), s, s, py::ssize_t(3)});
        float* o = a.mutable_data();
        for (int f = 0; f < 6; ++f) {
            const std::vector<float>& face = cube->levels[std::size_t(l)][std::size_t(f)];
            if (face.size() != std::size_t(s * s * 3)) throw std::logic_error("ibl.read_ktx2: inconsistent face size");
            std::copy(face.begin(), face.end(), o + std::size_t(f) * face.size());
        }
        out.append(a);
    }
    return out;
#else
    (void)path;
    no_bake_io("read_ktx2");
#endif
}

py::array_t<float> cube_from_latlong(py::object image, int size, int supersample, unsigned threads) {
    using img_array = py::array_t<float, py::array::c_style | py::array::forcecast>;
    refuse_complex("cube_from_latlong", "img", image);
    img_array a = img_array::ensure(image);
    if (!a) throw py::type_error("ibl.cube_from_latlong: img must be a real array of shape (h, 2h, 3)");
    if (a.ndim() != 3 || a.shape(2) != 3 || a.shape(0) < 1 || a.shape(1) != 2 * a.shape(0))
        throw py::value_error("ibl.cube_from_latlong: img must have shape (h, 2h, 3) (a lat-long map, row 0 = +Y), got " +
                              std::string(py::str(py::tuple(a.attr("shape")))));
    if (a.shape(1) > py::ssize_t(ibl::limits::max_face_size))
        throw py::value_error("ibl.cube_from_latlong: image width above limits::max_face_size");
    if (size < 1 || size > int(ibl::limits::max_face_size))
        throw py::value_error("ibl.cube_from_latlong: size must lie in [1, " + std::to_string(ibl::limits::max_face_size) +
                              "], got " + std::to_string(size));
    if (supersample < 1 || supersample > int(ibl::limits::max_subsamples))
        throw py::value_error("ibl.cube_from_latlong: supersample must lie in [1, " +
                              std::to_string(ibl::limits::max_subsamples) + "], got " + std::to_string(supersample));
    const int h = int(a.shape(0)), w = int(a.shape(1));
    const float* p = a.data();
    const std::size_t count = std::size_t(w) * std::size_t(h) * 3;
    for (std::size_t i = 0; i < count; ++i)
        if (!std::isfinite(p[i]))
            throw py::value_error("ibl.cube_from_latlong: img holds a non-finite value at flat index " + std::to_string(i));
    std::optional<ibl::cubemap<float>> c;
    {
        py::gil_scoped_release release;
        try {
            ibl::latlong<float> map(w, h, std::span<const float>(p, count), 1);
            c.emplace(ibl::bake_cubemap<float>(map, size, supersample, ibl::thread_executor{threads}, 1));
        } catch (const std::length_error& e) {
            throw py::value_error(std::string("ibl.cube_from_latlong: ") + e.what());
        } catch (const std::invalid_argument& e) {
            throw py::value_error(std::string("ibl.cube_from_latlong: ") + e.what());
        }
    }
    py::array_t<float> out({py::ssize_t(6), py::ssize_t(size), py::ssize_t(size), py::ssize_t(3)});
    float* o = out.mutable_data();
    for (int f = 0; f < 6; ++f)
        for (int y = 0; y < size; ++y)
            for (int x = 0; x < size; ++x) {
                const ibl::vec3<float>& t = c->texel(f, x, y, 0);
                float* q = o + ((std::size_t(f) * std::size_t(size) + std::size_t(y)) * std::size_t(size) + std::size_t(x)) * 3;
                q[0] = t.x;
                q[1] = t.y;
                q[2] = t.z;
            }
    check_finite_result("cube_from_latlong", out.data(), std::size_t(out.size()),
                        "the image's finite values are too large for float (the sums overflow); scale it down");
    return out;
}

} // namespace

void bind_io(py::module_& m) {
#ifdef IBL_PY_HAVE_BAKE_IO
    m.attr("has_image_io") = true;
#else
    m.attr("has_image_io") = false;
#endif
    m.def("read_image", &read_image, py::arg("path"), py::kw_only(), py::arg("latlong") = false,
          py::arg("max_pixels") = 16384ll * 8192ll, py::arg("replace_nonfinite") = false,
          "A Radiance HDR or OpenEXR file (format from its content) as float32 (h, w, 3) linear RGB, row 0 at\n"
          "the top (ibl-bake's reader, tools/ibl-bake/io/image_io.hpp). latlong=True also requires w = 2 h.\n"
          "max_pixels: larger images are refused. replace_nonfinite: NaN / inf become 0 instead of an error.\n"
          "Negative values are clamped to 0 (as ibl-bake does). A missing or malformed file, or one over the\n"
          "limits: ValueError with the reader's message. RuntimeError when built without ibl_bake_io.");
    m.def("read_ktx2", &read_ktx2, py::arg("path"),
          "The cubemap of a KTX2 file written by ibl-bake (any of its formats: RGBA32F, RGBA16F, B10G11R11,\n"
          "E5B9G9R9, BC6H, ASTC 4x4 / 6x6 HDR, optionally Zstandard-supercompressed; blocks decoded as a\n"
          "GPU decodes them): a list of float32 arrays (6, s, s, 3), one per mip level. ValueError with the\n"
          "decoder's message for a bad file; RuntimeError when built without ibl_bake_io.");
    m.def("cube_from_latlong", &cube_from_latlong, py::arg("img"), py::arg("size"), py::arg("supersample") = 2,
          py::kw_only(), py::arg("threads") = 0u,
          "A lat-long map (h, 2h, 3) (row 0 = +Y, column 0 = azimuth -pi) as a cube (6, size, size, 3)\n"
          "float32: each texel the mean of supersample x supersample bilinear reads of the map (ibl::latlong +\n"
          "ibl::bake_cubemap).");
}

} // namespace ibl_py
