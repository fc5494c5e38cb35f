// python/bind_lookup.cpp — the runtime lookups of the baked products (ibl/runtime/lookup.hpp): the
// specular chain at any (direction, roughness) and the DFG table at any (n.v, roughness), as a
// renderer reads them. The C++ lookups are float only: every value is computed in float; the result
// is float32 when every NumPy input is float32 and float64 otherwise (the float values widened).
#include "common.hpp"

#include <ibl/core/limits.hpp>
#include <ibl/env/cubemap.hpp>
#include <ibl/runtime/lookup.hpp>
#include <ibl/runtime/tables.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

namespace ibl_py {

namespace {

using f32_array = py::array_t<float, py::array::c_style | py::array::forcecast>;

/// A chain given as prefilter's list of (6, n >> l, n >> l, 3) levels, as a cubemap<float> with
/// those levels (borders rebuilt).
ibl::cubemap<float> chain_from_list(const char* fn, py::sequence levels) {
    const std::size_t count = py::len(levels);
    if (count < 1) throw py::value_error(std::string("ibl.") + fn + ": chain_levels must hold at least one level");
    std::vector<f32_array> arrays;
    py::ssize_t n = 0;
    for (std::size_t l = 0; l < count; ++l) {
        refuse_complex(fn, "chain_levels", levels[l]);
        f32_array a = f32_array::ensure(levels[l]);
        if (!a) throw py::type_error(std::string("ibl.") + fn + ": chain level " + std::to_string(l) + " is not a real array");
        const py::ssize_t want = l == 0 ? (a.ndim() == 4 ? a.shape(1) : 0) : std::max<py::ssize_t>(1, n >> l);
        if (l == 0) n = want;
        if (a.ndim() != 4 || a.shape(0) != 6 || a.shape(3) != 3 || want < 1 || a.shape(1) != want || a.shape(2) != want)
            throw py::value_error(std::string("ibl.") + fn + ": chain level " + std::to_string(l) + " must have shape (6, " +
                                  (l == 0 ? std::string("n, n") : std::to_string(want) + ", " + std::to_string(want)) +
                                  ", 3), got " + std::string(py::str(py::tuple(a.attr("shape")))));
        if (n > py::ssize_t(ibl::limits::max_face_size))
            throw py::value_error(std::string("ibl.") + fn + ": face size above limits::max_face_size");
        const std::size_t size = std::size_t(a.size());
        for (std::size_t i = 0; i < size; ++i)
            if (!std::isfinite(a.data()[i]))
                throw py::value_error(std::string("ibl.") + fn + ": chain level " + std::to_string(l) +
                                      " holds a non-finite value at flat index " + std::to_string(i));
        arrays.push_back(a);
    }
    int full = 1;
    while ((n >> full) > 0) ++full;
    if (int(count) > full)
        throw py::value_error(std::string("ibl.") + fn + ": " + std::to_string(count) + " levels for face size " +
                              std::to_string(n) + " (at most " + std::to_string(full) + ")");
    py::gil_scoped_release release;
    ibl::cubemap<float> c{int(n), int(count)};
    for (int l = 0; l < int(count); ++l) {
        const float* p = arrays[std::size_t(l)].data();
        const std::size_t s = std::size_t(c.size(l));
        c.fill(l, [&](int f, int x, int y) {
            const float* t = p + ((std::size_t(f) * s + std::size_t(y)) * s + std::size_t(x)) * 3;
            return ibl::vec3<float>(t[0], t[1], t[2]);
        });
    }
    c.update_borders();
    return c;
}

ibl::specular_lookup_desc parse_lookup(const char* fn, const std::string& lookup, const std::string& mapping) {
    ibl::roughness_mapping m;
    if (mapping == "linear") m = ibl::roughness_mapping::linear;
    else if (mapping == "filament") m = ibl::roughness_mapping::filament;
    else throw py::value_error(std::string("ibl.") + fn + ": mapping must be 'linear' or 'filament', got '" + mapping + "'");
    if (lookup == "textbook") return ibl::specular_lookup_desc::textbook(m);
    if (lookup == "accurate") return ibl::specular_lookup_desc::accurate(m);
    throw py::value_error(std::string("ibl.") + fn + ": lookup must be 'textbook' or 'accurate', got '" + lookup + "'");
}

py::object specular_lookup(py::sequence chain_levels, py::object dirs, py::object roughness, const std::string& lookup,
                           const std::string& mapping) {
    const ibl::specular_lookup_desc d = parse_lookup("specular_lookup", lookup, mapping);
    const ibl::cubemap<float> chain = chain_from_list("specular_lookup", chain_levels);
    const std::vector<arg> args{{dirs, 3, "dirs"}, {roughness, 1, "roughness", true}};
    {
        broadcast_args<double> b = broadcast<double>("specular_lookup", args);
        for (std::size_t i = 0; i < b.count; ++i) {
            const double* v = b.data[0] + 3 * i;
            const double q = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
            if (!(q > 0.0) || !std::isfinite(q))
                throw py::value_error("ibl.specular_lookup: dirs must be non-zero finite vectors (flat element " +
                                      std::to_string(i) + ")");
        }
    }
    return map("specular_lookup", args, 3, [&](auto tag) {
        using T = decltype(tag);
        return [&](const T* const* in, T* out) {
            ibl::vec3<float> dir{float(in[0][0]), float(in[0][1]), float(in[0][2])};
            dir = dir / std::sqrt(glm::dot(dir, dir));
            const ibl::vec3<float> v = ibl::specular_lookup(chain, dir, float(in[1][0]), d);
            out[0] = T(v.x);
            out[1] = T(v.y);
            out[2] = T(v.z);
        };
    });
}

py::object dfg_lookup(py::object lut_obj, py::object n_dot_v, py::object roughness, const std::string& layout) {
    refuse_complex("dfg_lookup", "lut", lut_obj);
    f32_array a = f32_array::ensure(lut_obj);
    if (!a) throw py::type_error("ibl.dfg_lookup: lut must be a real array (size, size, 2 or 3)");
    if (a.ndim() != 3 || a.shape(0) < 1 || a.shape(0) != a.shape(1) || (a.shape(2) != 2 && a.shape(2) != 3))
        throw py::value_error("ibl.dfg_lookup: lut must have shape (size, size, 2 or 3) (as ibl.dfg_lut returns), got " +
                              std::string(py::str(py::tuple(a.attr("shape")))));
    if (a.shape(0) > py::ssize_t(ibl::limits::max_dfg_lut_size))
        throw py::value_error("ibl.dfg_lookup: table size above limits::max_dfg_lut_size");
    ibl::dfg_lut lut;
    lut.size = std::uint32_t(a.shape(0));
    lut.channels = std::uint32_t(a.shape(2));
    if (layout == "uniform") lut.layout = ibl::dfg_lut_layout::uniform();
    else if (layout == "remapped") lut.layout = ibl::dfg_lut_layout::remapped();
    else throw py::value_error("ibl.dfg_lookup: layout must be 'uniform' or 'remapped', got '" + layout + "'");
    lut.data.assign(a.data(), a.data() + a.size());
    for (std::size_t i = 0; i < lut.data.size(); ++i)
        if (!std::isfinite(lut.data[i]))
            throw py::value_error("ibl.dfg_lookup: lut holds a non-finite value at flat index " + std::to_string(i));
    const std::size_t ch = lut.channels;
    return map("dfg_lookup", {{n_dot_v, 1, "n_dot_v", true}, {roughness, 1, "roughness", true}}, ch, [&](auto tag) {
        using T = decltype(tag);
        return [&lut, ch](const T* const* in, T* out) {
            const ibl::vec3<float> v = ibl::dfg_lookup(lut, float(in[0][0]), float(in[1][0]));
            for (std::size_t c = 0; c < ch; ++c) out[c] = T(v[int(c)]);
        };
    });
}

py::object shade_ambient(py::object n_dot_v, py::object ld, py::object dfg, py::object irradiance_over_pi,
                         py::object base_color, py::object metallic, py::object roughness, py::object ao,
                         double dielectric_f0, bool multiscatter) {
    if (!(dielectric_f0 >= 0.0 && dielectric_f0 <= 1.0))
        throw py::value_error("ibl.shade_ambient: dielectric_f0 must lie in [0, 1], got " + std::to_string(dielectric_f0));
    const std::vector<arg> args{{n_dot_v, 1, "n_dot_v", true},     {ld, 3, "ld"},
                                {dfg, 2, "dfg"},                    {irradiance_over_pi, 3, "irradiance_over_pi"},
                                {base_color, 3, "base_color", true}, {metallic, 1, "metallic", true},
                                {roughness, 1, "roughness", true},   {ao, 1, "ao", true}};
    return map("shade_ambient", args, 3, [&](auto tag) {
        using T = decltype(tag);
        return [dielectric_f0, multiscatter](const T* const* in, T* out) {
            ibl::pbr_material<T> mat;
            mat.base_color = ibl::vec3<T>(in[4][0], in[4][1], in[4][2]);
            mat.metallic = in[5][0];
            mat.roughness = in[6][0];
            mat.ambient_occlusion = in[7][0];
            mat.dielectric_f0 = T(dielectric_f0);
            ibl::ibl_sample<T> s;
            s.ld = ibl::vec3<T>(in[1][0], in[1][1], in[1][2]);
            s.dfg = ibl::vec2<T>(in[2][0], in[2][1]);
            s.irradiance_over_pi = ibl::vec3<T>(in[3][0], in[3][1], in[3][2]);
            const ibl::vec3<T> v = ibl::pbr_shader<T>::from(mat, multiscatter).ambient(in[0][0], s);
            out[0] = v.x;
            out[1] = v.y;
            out[2] = v.z;
        };
    });
}

} // namespace

void bind_lookup(py::module_& m) {
    m.def("specular_lookup", &specular_lookup, py::arg("chain_levels"), py::arg("dirs"), py::arg("roughness"), py::kw_only(),
          py::arg("lookup") = "textbook", py::arg("mapping") = "linear",
          "The prefiltered chain read as a renderer reads it (ibl::specular_lookup, float): array (..., 3)\n"
          "over the broadcast shape of dirs (..., 3) (normalised here) and roughness (in [0, 1]).\n"
          "chain_levels: the list ibl.prefilter returns (level l of face size max(1, n >> l)).\n"
          "lookup 'textbook' (textureLod at lod(r): linear blend of the bracketing levels) or 'accurate'\n"
          "(t linear in log r, geometric blend). mapping: the bake's roughness per level, 'linear'\n"
          "(r = lod / m, ibl.prefilter's) or 'filament' (lod = r (2 - r) m).");
    m.def("dfg_lookup", &dfg_lookup, py::arg("lut"), py::arg("n_dot_v"), py::arg("roughness"), py::kw_only(),
          py::arg("layout") = "uniform",
          "The DFG table read as a renderer reads it (ibl::dfg_lookup: one bilinear clamp-to-edge tap at\n"
          "dfg_lut_coord, float): array (..., channels) over the broadcast shape of n_dot_v and roughness\n"
          "(both in [0, 1]). lut: (size, size, 2 or 3) as ibl.dfg_lut returns, [j, i] = texel (i, j); layout:\n"
          "the table's own, 'uniform' or 'remapped'.");
    m.def("shade_ambient", &shade_ambient, py::arg("n_dot_v"), py::arg("ld"), py::arg("dfg"), py::arg("irradiance_over_pi"),
          py::arg("base_color"), py::arg("metallic"), py::arg("roughness"), py::kw_only(), py::arg("ao") = 1.0,
          py::arg("dielectric_f0") = 0.04, py::arg("multiscatter") = true,
          "Ambient (image-based) outgoing radiance of a metallic-roughness material (ibl::pbr_shader::ambient,\n"
          "runtime/shade.hpp): array (..., 3) over the broadcast shape of n_dot_v, ld (..., 3: LD at R and r),\n"
          "dfg (..., 2: A, B), irradiance_over_pi (..., 3: E/pi), base_color (..., 3), metallic, roughness and\n"
          "ao (all in [0, 1] but ld, dfg, irradiance_over_pi). multiscatter=True: Fdez-Aguera 2019's energy\n"
          "balance (FssEss LD + (FmsEms + albedo Edss) E/pi) ao; False: the single-scattering textbook\n"
          "ambient with kD = (1 - F)(1 - metallic). F90 = 1.");
}

} // namespace ibl_py
