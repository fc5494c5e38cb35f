// python/bind_env.cpp — cube maps in and out: the prefiltered specular chain, the irradiance map,
// SH projection / evaluation / Lambert convolution and the reference LD. A cube is a float32 array
// (6, n, n, 3): faces +X, -X, +Y, -Y, +Z, -Z, [face, y, x] = texel (x, y) of the library's
// convention (env/cube_geometry.hpp: row 0 is t = 0, column 0 is s = 0).
#include "common.hpp"

#include <ibl/bake/irradiance.hpp>
#include <ibl/bake/prefilter.hpp>
#include <ibl/core/executor.hpp>
#include <ibl/core/limits.hpp>
#include <ibl/env/cubemap.hpp>
#include <ibl/reference/ld_irradiance.hpp>
#include <ibl/sh.hpp>

#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <optional>
#include <type_traits>
#include <utility>
#include <vector>

namespace ibl_py {

namespace {

using cube_array = py::array_t<float, py::array::c_style | py::array::forcecast>;

/// The cube argument as a cubemap<float> with its full mip chain (box-filtered on the sphere).
ibl::cubemap<float> to_cubemap(const char* fn, py::object cube, unsigned threads) {
    cube_array a = cube_array::ensure(cube);
    if (!a) throw py::type_error(std::string("ibl.") + fn + ": cube must be a real array of shape (6, n, n, 3)");
    if (a.ndim() != 4 || a.shape(0) != 6 || a.shape(1) != a.shape(2) || a.shape(3) != 3 || a.shape(1) < 1)
        throw py::value_error(std::string("ibl.") + fn + ": cube must have shape (6, n, n, 3) (faces +X, -X, +Y, -Y, +Z, -Z), got " +
                              std::string(py::str(py::tuple(a.attr("shape")))));
    const py::ssize_t n = a.shape(1);
    if (n > py::ssize_t(ibl::limits::max_face_size))
        throw py::value_error(std::string("ibl.") + fn + ": face size above limits::max_face_size");
    const float* p = a.data();
    const std::size_t count = std::size_t(6 * n * n * 3);
    for (std::size_t i = 0; i < count; ++i)
        if (!std::isfinite(p[i]))
            throw py::value_error(std::string("ibl.") + fn + ": cube holds a non-finite value at flat index " + std::to_string(i));
    py::gil_scoped_release release;
    ibl::cubemap<float> c{int(n)};
    c.fill(0, [&](int f, int x, int y) {
        const float* t = p + ((std::size_t(f) * std::size_t(n) + std::size_t(y)) * std::size_t(n) + std::size_t(x)) * 3;
        return ibl::vec3<float>(t[0], t[1], t[2]);
    });
    c.generate_mips(ibl::thread_executor{threads});
    return c;
}

/// Level `level` of a cubemap as a new (6, s, s, 3) float32 array.
py::array_t<float> level_array(const ibl::cubemap<float>& c, int level) {
    const int s = c.size(level);
    py::array_t<float> out({py::ssize_t(6), py::ssize_t(s), py::ssize_t(s), py::ssize_t(3)});
    float* o = out.mutable_data();
    for (int f = 0; f < 6; ++f)
        for (int y = 0; y < s; ++y)
            for (int x = 0; x < s; ++x) {
                const ibl::vec3<float>& t = c.texel(f, x, y, level);
                float* q = o + ((std::size_t(f) * std::size_t(s) + std::size_t(y)) * std::size_t(s) + std::size_t(x)) * 3;
                q[0] = t.x;
                q[1] = t.y;
                q[2] = t.z;
            }
    return out;
}

/// Runs f(std::integral_constant<int, B>) for bands B in [1, 5].
template <class F> decltype(auto) with_bands(const char* fn, int bands, F&& f) {
    switch (bands) {
    case 1: return f(std::integral_constant<int, 1>{});
    case 2: return f(std::integral_constant<int, 2>{});
    case 3: return f(std::integral_constant<int, 3>{});
    case 4: return f(std::integral_constant<int, 4>{});
    case 5: return f(std::integral_constant<int, 5>{});
    default: throw py::value_error(std::string("ibl.") + fn + ": bands must lie in [1, 5], got " + std::to_string(bands));
    }
}

using coeff_array = py::array_t<double, py::array::c_style | py::array::forcecast>;

/// (B^2, 3) coefficients -> bands B.
int coeff_bands(const char* fn, const coeff_array& c) {
    if (c.ndim() == 2 && c.shape(1) == 3)
        for (int b = 1; b <= 5; ++b)
            if (c.shape(0) == b * b) return b;
    throw py::value_error(std::string("ibl.") + fn + ": coeffs must have shape (bands^2, 3), bands in [1, 5], got " +
                          std::string(py::str(py::tuple(c.attr("shape")))));
}

template <int B> ibl::sh_coeffs<double, B> to_coeffs(const coeff_array& c) {
    ibl::sh_coeffs<double, B> k;
    for (int i = 0; i < B * B; ++i) k.c[i] = ibl::vec3<double>(c.data()[3 * i], c.data()[3 * i + 1], c.data()[3 * i + 2]);
    return k;
}
template <int B> py::array_t<double> from_coeffs(const ibl::sh_coeffs<double, B>& k) {
    py::array_t<double> out({py::ssize_t(B * B), py::ssize_t(3)});
    for (int i = 0; i < B * B; ++i) {
        out.mutable_data()[3 * i] = k.c[i].x;
        out.mutable_data()[3 * i + 1] = k.c[i].y;
        out.mutable_data()[3 * i + 2] = k.c[i].z;
    }
    return out;
}

py::list prefilter(py::object cube, int levels, std::uint32_t samples, const std::string& method, const std::string& weight,
                   unsigned threads) {
    ibl::prefilter_options opt;
    if (method == "fis") opt.method = ibl::prefilter_method::filtered_importance;
    else if (method == "fast") opt.method = ibl::prefilter_method::fast;
    else if (method == "importance") opt.method = ibl::prefilter_method::importance;
    else throw py::value_error("ibl.prefilter: method must be 'fis', 'fast' or 'importance', got '" + method + "'");
    if (weight == "n_dot_l") opt.weight = ibl::ld_weight::n_dot_l;
    else if (weight == "g1") opt.weight = ibl::ld_weight::g1;
    else throw py::value_error("ibl.prefilter: weight must be 'n_dot_l' or 'g1', got '" + weight + "'");
    if (levels < -1) throw py::value_error("ibl.prefilter: levels must be -1 (automatic), 0 (full chain) or positive");
    opt.levels = levels;
    opt.samples = samples;
    ibl::cubemap<float> env = to_cubemap("prefilter", cube, threads);
    std::optional<ibl::specular_chain> chain;
    {
        py::gil_scoped_release release;
        chain.emplace(ibl::prefilter(env, opt, ibl::thread_executor{threads}));
    }
    py::list out;
    for (int l = 0; l < chain->levels(); ++l) out.append(level_array(*chain, l));
    return out;
}

py::array_t<float> irradiance(py::object cube, int size, std::uint32_t samples, const std::string& method, unsigned threads) {
    ibl::irradiance_options opt;
    opt.size = size;
    opt.samples = samples;
    if (method == "cosine") opt.method = ibl::irradiance_method::cosine_importance;
    else if (method == "riemann") opt.method = ibl::irradiance_method::riemann;
    else if (method == "texel_moments") opt.method = ibl::irradiance_method::texel_moments;
    else throw py::value_error("ibl.irradiance: method must be 'cosine', 'riemann' or 'texel_moments', got '" + method + "'");
    if (size < 1 || size > int(ibl::limits::max_face_size)) throw py::value_error("ibl.irradiance: size out of range");
    ibl::cubemap<float> env = to_cubemap("irradiance", cube, threads);
    std::optional<ibl::cubemap<float>> e;
    {
        py::gil_scoped_release release;
        e.emplace(ibl::irradiance_cubemap(env, opt, ibl::thread_executor{threads}));
    }
    return level_array(*e, 0);
}

py::array_t<double> sh_project(py::object cube, int bands, unsigned threads) {
    ibl::cubemap<float> env = to_cubemap("sh_project", cube, threads);
    return with_bands("sh_project", bands, [&](auto b) {
        constexpr int B = decltype(b)::value;
        ibl::sh_coeffs<double, B> k;
        {
            py::gil_scoped_release release;
            const auto c = ibl::project_cube<B>(env, ibl::thread_executor{threads});
            for (int i = 0; i < B * B; ++i) k.c[i] = ibl::vec3<double>(c.c[i]);
        }
        return from_coeffs<B>(k);
    });
}

py::object sh_evaluate(py::object coeffs, py::object dirs) {
    coeff_array c = coeff_array::ensure(coeffs);
    if (!c) throw py::type_error("ibl.sh_evaluate: coeffs must be a real array (bands^2, 3)");
    const int bands = coeff_bands("sh_evaluate", c);
    return with_bands("sh_evaluate", bands, [&](auto b) -> py::object {
        constexpr int B = decltype(b)::value;
        const ibl::sh_coeffs<double, B> k = to_coeffs<B>(c);
        return map_typed<double>("sh_evaluate", {{dirs, 3, "dirs"}}, 3, [&k](const double* const* in, double* out) {
            const ibl::vec3<double> v = ibl::sh_evaluate(k, ibl::vec3<double>(in[0][0], in[0][1], in[0][2]));
            out[0] = v.x;
            out[1] = v.y;
            out[2] = v.z;
        });
    });
}

py::array_t<double> sh_irradiance(py::object coeffs) {
    coeff_array c = coeff_array::ensure(coeffs);
    if (!c) throw py::type_error("ibl.sh_irradiance: coeffs must be a real array (bands^2, 3)");
    return with_bands("sh_irradiance", coeff_bands("sh_irradiance", c), [&](auto b) {
        constexpr int B = decltype(b)::value;
        return from_coeffs<B>(ibl::sh_irradiance(to_coeffs<B>(c)));
    });
}

py::object reference_ld(py::object cube, py::object dirs, py::object roughness, std::uint32_t samples, const std::string& weight,
                        unsigned threads) {
    ibl::ld_weight w;
    if (weight == "n_dot_l") w = ibl::ld_weight::n_dot_l;
    else if (weight == "g1") w = ibl::ld_weight::g1;
    else throw py::value_error("ibl.reference_ld: weight must be 'n_dot_l' or 'g1', got '" + weight + "'");
    if (samples > ibl::limits::max_samples) throw py::value_error("ibl.reference_ld: samples above limits::max_samples");
    const ibl::cubemap<float> env = to_cubemap("reference_ld", cube, threads);
    broadcast_args<double> b = broadcast<double>("reference_ld", {{dirs, 3, "dirs"}, {roughness, 1, "roughness", true}});
    py::array_t<double> out = make_output<double>(b.shape, 3);
    double* o = out.mutable_data();
    const double* d = b.data[0];
    const double* r = b.data[1];
    for (std::size_t i = 0; i < b.count; ++i)
        if (!(d[3 * i] * d[3 * i] + d[3 * i + 1] * d[3 * i + 1] + d[3 * i + 2] * d[3 * i + 2] > 0.0))
            throw py::value_error("ibl.reference_ld: dirs must be non-zero finite vectors");
    {
        py::gil_scoped_release release;
        ibl::thread_executor{threads}(b.count, [&](std::size_t begin, std::size_t end) {
            for (std::size_t i = begin; i < end; ++i) {
                const ibl::vec3<double> v =
                    ibl::reference_ld(env, ibl::vec3<double>(d[3 * i], d[3 * i + 1], d[3 * i + 2]), r[i], samples, w);
                o[3 * i] = v.x;
                o[3 * i + 1] = v.y;
                o[3 * i + 2] = v.z;
            }
        });
    }
    return out;
}

} // namespace

void bind_env(py::module_& m) {
    m.def("prefilter", &prefilter, py::arg("cube"), py::kw_only(), py::arg("levels") = -1, py::arg("samples") = 0u,
          py::arg("method") = "fis", py::arg("weight") = "n_dot_l", py::arg("threads") = 0u,
          "The prefiltered specular chain of ibl::prefilter (GGX, N = V = R): a list of float32 arrays\n"
          "(6, s, s, 3), level l of face size max(1, n >> l) for roughness l / (levels - 1).\n"
          "cube: (6, n, n, 3), faces +X, -X, +Y, -Y, +Z, -Z, [face, y, x], row 0 = t = 0. levels: -1\n"
          "automatic (ibl-bake's rule), 0 the full chain. samples: per texel at level 1 (0 = the default\n"
          "doubling schedule). method 'fis' (filtered importance sampling), 'fast' or 'importance'.\n"
          "weight 'n_dot_l' (Karis) or 'g1'. threads: 0 = all cores.");
    m.def("irradiance", &irradiance, py::arg("cube"), py::arg("size") = 32, py::kw_only(), py::arg("samples") = 1024u,
          py::arg("method") = "cosine", py::arg("threads") = 0u,
          "Irradiance cube (6, size, size, 3) float32 of ibl::irradiance_cubemap: E(n) at every texel\n"
          "centre. method 'cosine' (cosine-importance, `samples` per texel), 'riemann' or 'texel_moments'.");
    m.def("sh_project", &sh_project, py::arg("cube"), py::arg("bands") = 3, py::kw_only(), py::arg("threads") = 0u,
          "Radiance SH coefficients (bands^2, 3) float64 of a cube (ibl::project_cube, exact texel solid\n"
          "angles), bands in [1, 5].");
    m.def("sh_evaluate", &sh_evaluate, py::arg("coeffs"), py::arg("dirs"),
          "The SH expansion (bands^2, 3) evaluated at directions (..., 3): array (..., 3) (ibl::sh_evaluate).");
    m.def("sh_irradiance", &sh_irradiance, py::arg("coeffs"),
          "The Lambert convolution of radiance SH: irradiance SH E_lm = A_l L_lm (ibl::sh_irradiance).");
    m.def("reference_ld", &reference_ld, py::arg("cube"), py::arg("dirs"), py::arg("roughness"), py::arg("samples") = 4096u,
          py::kw_only(), py::arg("weight") = "n_dot_l", py::arg("threads") = 0u,
          "Converged LD at directions (..., 3) and roughness (broadcast) by GGX importance sampling of the\n"
          "cube's level 0 (ibl::reference_ld, double): array (..., 3).");
}

} // namespace ibl_py
