// python/bind_env.cpp — cube maps in and out: the prefiltered specular chain, the irradiance map,
// SH projection / evaluation / Lambert convolution and the reference LD (the prefilter and the
// reference LD with the built-in GGX lobe or the tabulated lobe of a Python model,
// tabulated_lobe.hpp). A cube is a float32 array
// (6, n, n, 3): faces +X, -X, +Y, -Y, +Z, -Z, [face, y, x] = texel (x, y) of the library's
// convention (env/cube_geometry.hpp: row 0 is t = 0, column 0 is s = 0).
#include "common.hpp"
#include "tabulated_lobe.hpp"

#include <ibl/bake/irradiance.hpp>
#include <ibl/bake/prefilter.hpp>
#include <ibl/core/executor.hpp>
#include <ibl/core/limits.hpp>
#include <ibl/env/cubemap.hpp>
#include <ibl/env/sun_extract.hpp>
#include <ibl/reference/env_importance.hpp>
#include <ibl/reference/ld_irradiance.hpp>
#include <ibl/reference/radiance.hpp>
#include <ibl/sh.hpp>

#include <algorithm>
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
    refuse_complex(fn, "cube", cube);
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

/// Why a finite cube can still give a non-finite result.
constexpr const char* cube_overflow = "the cube's finite values are too large for float (the sums overflow); scale it down";

/// Level `level` of a cubemap as a new (6, s, s, 3) float32 array; ValueError naming `fn` when a
/// texel is not finite (`fn` null: no check).
py::array_t<float> level_array(const ibl::cubemap<float>& c, int level, const char* fn = nullptr) {
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
    if (fn) check_finite_result(fn, out.data(), std::size_t(out.size()), cube_overflow);
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

// ---- the LD lobe of a Python model (tabulated_lobe.hpp) ---------------------------------------------

/// At most this many distinct roughness values per call with a Python model (a table each).
constexpr std::size_t max_lobe_tables = 1024;

/// A model argument: None or "ggx" is the built-in GGX lobe (false), else a Python model (true).
bool is_python_lobe(const char* fn, const py::object& model) {
    if (model.is_none()) return false;
    if (py::isinstance<py::str>(model)) {
        if (model.cast<std::string>() == "ggx" || model.cast<std::string>() == "ggx_height_correlated") return false;
        throw py::value_error(std::string("ibl.") + fn + ": model must be 'ggx' (the built-in lobe) or a Python model "
                              "object with alpha(roughness) and ndf(n_dot_h, alpha), got '" + model.cast<std::string>() + "'");
    }
    for (const char* f : {"alpha", "ndf"})
        if (!py::hasattr(model, f) || !PyCallable_Check(model.attr(f).ptr()))
            throw py::type_error(std::string("ibl.") + fn + ": the model object has no callable '" + f +
                                 "' (the LD lobe of a Python model needs alpha(roughness) and ndf(n_dot_h, alpha))");
    return true;
}

/// `count` float64 values from a model method's result (a scalar or shape (count,)).
std::vector<double> model_values(const char* fn, const char* method, py::object r, std::size_t count) {
    refuse_complex(fn, (std::string("the result of model.") + method).c_str(), r);
    auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(r);
    if (!a) throw py::type_error(std::string("ibl.") + fn + ": model." + method + " returned " +
                                 std::string(py::str(py::type::of(r))) + ", not a real array");
    if (a.ndim() == 0) return std::vector<double>(count, *a.data());
    if (a.ndim() == 1 && std::size_t(a.shape(0)) == count) return std::vector<double>(a.data(), a.data() + count);
    throw py::value_error(std::string("ibl.") + fn + ": model." + method + " returned shape " +
                          std::string(py::str(py::tuple(a.attr("shape")))) + " for inputs of shape (" +
                          std::to_string(count) + ",)");
}

/// The lobe tables of a Python model for the given roughness values: alpha once for all of them,
/// ndf once per batch of tables (at most 2^16 nodes a call, like the DFG's batches).
lobe_tables tabulate_lobe(const char* fn, const py::object& model, std::vector<double> rs) {
    std::sort(rs.begin(), rs.end());
    rs.erase(std::unique(rs.begin(), rs.end()), rs.end());
    if (rs.size() > max_lobe_tables)
        throw py::value_error(std::string("ibl.") + fn + ": a Python model is tabulated once per distinct roughness; " +
                              std::to_string(rs.size()) + " distinct values given, at most " +
                              std::to_string(max_lobe_tables));
    lobe_tables lt;
    lt.tables.resize(rs.size());
    if (rs.empty()) return lt;
    py::array_t<double> ra(py::ssize_t(rs.size()));
    std::copy(rs.begin(), rs.end(), ra.mutable_data());
    const std::vector<double> alpha = model_values(fn, "alpha", model.attr("alpha")(ra), rs.size());
    for (std::size_t i = 0; i < rs.size(); ++i) {
        if (!std::isfinite(alpha[i]) || alpha[i] < 0.0)
            throw py::value_error(std::string("ibl.") + fn + ": model.alpha returned " + std::to_string(alpha[i]) +
                                  " for roughness " + std::to_string(rs[i]) + " (must be finite and >= 0)");
        lt.tables[i].set_grid(rs[i], alpha[i]);
    }
    constexpr std::size_t nodes = lobe_table::cells + 1;
    const std::size_t per_batch = std::max<std::size_t>(1, (std::size_t(1) << 16) / nodes);
    for (std::size_t b0 = 0; b0 < rs.size(); b0 += per_batch) {
        const std::size_t b1 = std::min(rs.size(), b0 + per_batch), n = (b1 - b0) * nodes;
        py::array_t<double> nh(static_cast<py::ssize_t>(n)), al(static_cast<py::ssize_t>(n));
        for (std::size_t i = b0; i < b1; ++i)
            for (std::size_t k = 0; k < nodes; ++k) {
                nh.mutable_data()[(i - b0) * nodes + k] = lt.tables[i].node_n_dot_h(k);
                al.mutable_data()[(i - b0) * nodes + k] = alpha[i];
            }
        const std::vector<double> d = model_values(fn, "ndf", model.attr("ndf")(nh, al), n);
        for (std::size_t i = b0; i < b1; ++i) {
            const double* di = d.data() + (i - b0) * nodes;
            for (std::size_t k = 0; k < nodes; ++k)
                if (!std::isfinite(di[k]) || di[k] < 0.0)
                    throw py::value_error(std::string("ibl.") + fn + ": model.ndf returned " + std::to_string(di[k]) +
                                          " at n_dot_h=" + std::to_string(nh.data()[(i - b0) * nodes + k]) +
                                          ", roughness=" + std::to_string(rs[i]) + " (must be finite and >= 0)");
            lt.tables[i].set_values(di);
            const double m = lt.tables[i].mass();
            if (!(m > 0.0) || !std::isfinite(m))
                throw py::value_error(std::string("ibl.") + fn + ": model.ndf at roughness " + std::to_string(rs[i]) +
                                      " integrates to " + std::to_string(m) +
                                      " over the hemisphere (D cos(theta_h)): must be positive and finite");
        }
    }
    return lt;
}

py::list prefilter(py::object cube, int levels, std::uint32_t samples, const std::string& method, const std::string& weight,
                   unsigned threads, py::object model, py::object peaks, bool coarse_tail, int sh_bands, bool mid_tail) {
    const bool py_lobe = is_python_lobe("prefilter", model);
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
    opt.coarse_tail = coarse_tail;
    opt.mid_tail.enabled = mid_tail;
    if (sh_bands < 0 || sh_bands > ibl::detail::sh_rough_band_limit)
        throw py::value_error("ibl.prefilter: sh_bands must be in [0, " + std::to_string(ibl::detail::sh_rough_band_limit) + "], got " +
                              std::to_string(sh_bands));
    opt.sh_rough.enabled = sh_bands > 0;
    opt.sh_rough.max_bands = sh_bands;
    // The fast filter's peak split (bake/prefilter_peaks.hpp) needs the closed-form GGX kernel: on
    // by default for the built-in lobe, off for a Python model (asking for it there is an error).
    if (!peaks.is_none()) {
        const long long p = peaks.cast<long long>();
        if (p < 0 || p > (1ll << 30)) throw py::value_error("ibl.prefilter: peaks must be in [0, 2^30], got " + std::to_string(p));
        if (p > 0 && py_lobe)
            throw py::value_error("ibl.prefilter: peaks > 0 is the fast filter's peak split through the closed-form GGX "
                                  "kernel, for the built-in lobe only; a Python model takes peaks=0 (or None)");
        opt.peaks.enabled = p > 0;
        opt.peaks.max_peaks = std::uint32_t(p);
    } else if (py_lobe) {
        opt.peaks.enabled = false;
    }
    if (py_lobe && opt.weight == ibl::ld_weight::g1)
        throw py::value_error("ibl.prefilter: weight='g1' is the GGX G1 weight, for the built-in lobe only; a Python "
                              "model's lobe takes weight='n_dot_l'");
    ibl::cubemap<float> env = to_cubemap("prefilter", cube, threads);
    std::optional<ibl::specular_chain> chain;
    if (py_lobe) {
        // the roughness of every level the plan convolves (level 0 is the mirror copy)
        std::vector<double> rs;
        for (const ibl::prefilter_level& lp : ibl::prefilter_plan<python_lobe>(opt, env.size(0)))
            if (lp.level > 0) rs.push_back(lp.roughness);
        const lobe_tables lt = tabulate_lobe("prefilter", model, rs);
        py::gil_scoped_release release;
        lobe_tables_scope scope(lt);
        chain.emplace(ibl::prefilter<python_lobe>(env, opt, ibl::thread_executor{threads}));
    } else {
        py::gil_scoped_release release;
        chain.emplace(ibl::prefilter(env, opt, ibl::thread_executor{threads}));
    }
    py::list out;
    for (int l = 0; l < chain->levels(); ++l) out.append(level_array(*chain, l, "prefilter"));
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
    return level_array(*e, 0, "irradiance");
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
        py::array_t<double> out = from_coeffs<B>(k);
        check_finite_result("sh_project", out.data(), std::size_t(out.size()), cube_overflow);
        return out;
    });
}

py::object sh_evaluate(py::object coeffs, py::object dirs) {
    refuse_complex("sh", "coeffs", coeffs);
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
    refuse_complex("sh", "coeffs", coeffs);
    coeff_array c = coeff_array::ensure(coeffs);
    if (!c) throw py::type_error("ibl.sh_irradiance: coeffs must be a real array (bands^2, 3)");
    return with_bands("sh_irradiance", coeff_bands("sh_irradiance", c), [&](auto b) {
        constexpr int B = decltype(b)::value;
        return from_coeffs<B>(ibl::sh_irradiance(to_coeffs<B>(c)));
    });
}

py::object reference_ld(py::object cube, py::object dirs, py::object roughness, std::uint32_t samples, const std::string& weight,
                        unsigned threads, py::object model) {
    const bool py_lobe = is_python_lobe("reference_ld", model);
    ibl::ld_weight w;
    if (weight == "n_dot_l") w = ibl::ld_weight::n_dot_l;
    else if (weight == "g1") w = ibl::ld_weight::g1;
    else throw py::value_error("ibl.reference_ld: weight must be 'n_dot_l' or 'g1', got '" + weight + "'");
    if (samples > ibl::limits::max_samples) throw py::value_error("ibl.reference_ld: samples above limits::max_samples");
    if (py_lobe && w == ibl::ld_weight::g1)
        throw py::value_error("ibl.reference_ld: weight='g1' is the GGX G1 weight, for the built-in lobe only; a Python "
                              "model's lobe takes weight='n_dot_l'");
    const ibl::cubemap<float> env = to_cubemap("reference_ld", cube, threads);
    broadcast_args<double> b = broadcast<double>("reference_ld", {{dirs, 3, "dirs"}, {roughness, 1, "roughness", true}});
    py::array_t<double> out = make_output<double>(b.shape, 3);
    double* o = out.mutable_data();
    const double* d = b.data[0];
    const double* r = b.data[1];
    for (std::size_t i = 0; i < b.count; ++i) {
        const double len2 = d[3 * i] * d[3 * i] + d[3 * i + 1] * d[3 * i + 1] + d[3 * i + 2] * d[3 * i + 2];
        if (!(len2 > 0.0 && std::isfinite(len2)))
            throw py::value_error("ibl.reference_ld: dirs must be non-zero finite vectors (squared length within "
                                  "double's range), got one of squared length " + std::to_string(len2) +
                                  " at index " + std::to_string(i));
    }
    auto run = [&](auto lobe_tag) {
        using Lobe = decltype(lobe_tag);
        ibl::thread_executor{threads}(b.count, [&](std::size_t begin, std::size_t end) {
            for (std::size_t i = begin; i < end; ++i) {
                const ibl::vec3<double> v =
                    ibl::reference_ld<Lobe>(env, ibl::vec3<double>(d[3 * i], d[3 * i + 1], d[3 * i + 2]), r[i], samples, w);
                o[3 * i] = v.x;
                o[3 * i + 1] = v.y;
                o[3 * i + 2] = v.z;
            }
        });
    };
    if (py_lobe) {
        const lobe_tables lt = tabulate_lobe("reference_ld", model, std::vector<double>(r, r + b.count));
        py::gil_scoped_release release;
        lobe_tables_scope scope(lt);
        run(python_lobe{});
    } else {
        py::gil_scoped_release release;
        run(ibl::ggx_lobe{});
    }
    check_finite_result("reference_ld", out.data(), std::size_t(out.size()), cube_overflow);
    return out;
}

py::object extract_sun(py::object cube, double threshold_over_median, double threshold_over_peak, double max_solid_angle,
                       double min_share, unsigned threads) {
    auto check = [](double v, const char* name, bool positive) {
        if (!std::isfinite(v) || v < 0.0 || (positive && v <= 0.0))
            throw py::value_error(std::string("ibl.extract_sun: ") + name + " must be finite and " +
                                  (positive ? "> 0" : ">= 0") + ", got " + std::to_string(v));
    };
    check(threshold_over_median, "threshold_over_median", false);
    check(threshold_over_peak, "threshold_over_peak", false);
    check(max_solid_angle, "max_solid_angle", true);
    check(min_share, "min_share", false);
    ibl::sun_extract_options opt;
    opt.threshold_over_median = threshold_over_median;
    opt.threshold_over_peak = threshold_over_peak;
    opt.max_solid_angle = max_solid_angle;
    opt.min_share = min_share;
    ibl::cubemap<float> env = to_cubemap("extract_sun", cube, threads);
    ibl::sun_extraction<float> sun;
    {
        py::gil_scoped_release release;
        sun = ibl::extract_sun_in_place(env, opt, ibl::thread_executor{threads});
    }
    if (sun.status != ibl::sun_status::found) return py::none();
    auto v3 = [](const ibl::vec3<float>& v) {
        py::array_t<double> a(py::ssize_t(3));
        a.mutable_data()[0] = double(v.x);
        a.mutable_data()[1] = double(v.y);
        a.mutable_data()[2] = double(v.z);
        return a;
    };
    py::dict light;
    light["direction"] = v3(sun.direction);
    light["solid_angle"] = double(sun.solid_angle);
    light["angular_radius"] = double(sun.angular_radius);
    light["radiance"] = v3(sun.radiance);
    light["irradiance"] = v3(sun.irradiance);
    light["region_solid_angle"] = double(sun.region_solid_angle);
    light["region_texels"] = sun.region_texels;
    light["share"] = sun.share;
    return py::make_tuple(light, level_array(env, 0, "extract_sun"));
}

// ---- reference_radiance of a Python model: record / replay ------------------------------------------
//
// reference_radiance<Model> evaluates the model through brdf_lobe<Model>::eval: one Model::ndf and
// then one Model::visibility call per lobe evaluation, whose number and order depend only on the
// draws and their densities (GGX VNDF sampling with Model::alpha, the cosine lobe, the environment
// distribution), never on the values returned. So, as the DFG of a Python model does, each point
// runs twice: with rr_record_model, which stores the arguments of every call (returning 1), then,
// after the Python ndf and visibility ran on those arrays (once per batch of points), with
// rr_replay_model, which returns the model's values in the same order. The estimate, its batches,
// MIS weights and error are the library's code; nothing of the estimator is restated.

struct rr_buffer {
    double alpha = 0.0;                  // the model's alpha for the point's roughness
    double *nh = nullptr, *nv = nullptr, *nl = nullptr; // record: the point's slots
    const double *d = nullptr, *v = nullptr;            // replay: the model's values
    std::size_t n_ndf = 0, n_vis = 0, capacity = 0;
};
thread_local rr_buffer* tls_rr = nullptr;

struct rr_record_model {
    static constexpr const char* name = "python";
    template <class T> static T alpha(T) noexcept { return T(tls_rr->alpha); }
    template <class T> static T ndf(T n_dot_h, T) noexcept {
        rr_buffer& b = *tls_rr;
        if (b.n_ndf < b.capacity) b.nh[b.n_ndf] = double(n_dot_h);
        ++b.n_ndf;
        return T(1);
    }
    template <class T> static T visibility(T n_dot_v, T n_dot_l, T) noexcept {
        rr_buffer& b = *tls_rr;
        if (b.n_vis < b.capacity) {
            b.nv[b.n_vis] = double(n_dot_v);
            b.nl[b.n_vis] = double(n_dot_l);
        }
        ++b.n_vis;
        return T(1);
    }
    template <class T> static T sample_weight(T, T, T, T, T) noexcept { return T(0); } // not used by brdf_lobe
};
struct rr_replay_model {
    static constexpr const char* name = "python";
    template <class T> static T alpha(T) noexcept { return T(tls_rr->alpha); }
    template <class T> static T ndf(T, T) noexcept {
        rr_buffer& b = *tls_rr;
        const std::size_t i = b.n_ndf++;
        return i < b.capacity ? T(b.d[i]) : T(0);
    }
    template <class T> static T visibility(T, T, T) noexcept {
        rr_buffer& b = *tls_rr;
        const std::size_t i = b.n_vis++;
        return i < b.capacity ? T(b.v[i]) : T(0);
    }
    template <class T> static T sample_weight(T, T, T, T, T) noexcept { return T(0); }
};
static_assert(ibl::brdf_model<rr_record_model, double> && ibl::brdf_model<rr_replay_model, double>);

struct rr_tls_guard {
    explicit rr_tls_guard(rr_buffer* b) { tls_rr = b; }
    ~rr_tls_guard() { tls_rr = nullptr; }
    rr_tls_guard(const rr_tls_guard&) = delete;
    rr_tls_guard& operator=(const rr_tls_guard&) = delete;
};

py::dict reference_radiance(py::object cube, py::object n, py::object v, py::object base_color, py::object metallic,
                            py::object roughness, long long samples, long long batches, std::uint32_t seed,
                            const std::string& strategy, const std::string& diffuse, double dielectric_f0, unsigned threads,
                            py::object model) {
    const char* fn = "reference_radiance";
    bool py_model = false;
    if (!model.is_none()) {
        if (py::isinstance<py::str>(model)) {
            const std::string name = model.cast<std::string>();
            if (name != "ggx" && name != "ggx_height_correlated")
                throw py::value_error("ibl.reference_radiance: model must be 'ggx_height_correlated' (alias 'ggx') or a "
                                      "Python model object with alpha, ndf and visibility, got '" + name + "'");
        } else {
            py_model = true;
            for (const char* f : {"alpha", "ndf", "visibility"})
                if (!py::hasattr(model, f) || !PyCallable_Check(model.attr(f).ptr()))
                    throw py::type_error(std::string("ibl.reference_radiance: the model object has no callable '") + f +
                                         "' (needs alpha(roughness), ndf(n_dot_h, alpha), visibility(n_dot_v, n_dot_l, "
                                         "roughness))");
        }
    }
    ibl::radiance_reference_options opt;
    if (samples < 1 || samples > (long long)ibl::limits::max_samples)
        throw py::value_error("ibl.reference_radiance: samples must lie in [1, " + std::to_string(ibl::limits::max_samples) +
                              "], got " + std::to_string(samples));
    if (batches < 2 || batches > (long long)ibl::limits::max_batches)
        throw py::value_error("ibl.reference_radiance: batches must lie in [2, " + std::to_string(ibl::limits::max_batches) +
                              "], got " + std::to_string(batches));
    opt.samples = std::uint32_t(samples);
    opt.batches = std::uint32_t(batches);
    opt.seed = seed;
    if (strategy == "mis") opt.strategy = ibl::radiance_strategy::mis;
    else if (strategy == "brdf") opt.strategy = ibl::radiance_strategy::brdf;
    else if (strategy == "env") opt.strategy = ibl::radiance_strategy::env;
    else throw py::value_error("ibl.reference_radiance: strategy must be 'mis', 'brdf' or 'env', got '" + strategy + "'");
    ibl::diffuse_weighting dw;
    if (diffuse == "lambert") dw = ibl::diffuse_weighting::lambert;
    else if (diffuse == "one_minus_fresnel_roughness") dw = ibl::diffuse_weighting::one_minus_fresnel_roughness;
    else throw py::value_error("ibl.reference_radiance: diffuse must be 'lambert' or 'one_minus_fresnel_roughness', got '" +
                               diffuse + "'");
    if (!(dielectric_f0 >= 0.0 && dielectric_f0 <= 1.0))
        throw py::value_error("ibl.reference_radiance: dielectric_f0 must lie in [0, 1], got " + std::to_string(dielectric_f0));
    broadcast_args<double> b = broadcast<double>(fn, {{n, 3, "n"},
                                                      {v, 3, "v"},
                                                      {base_color, 3, "base_color", true},
                                                      {metallic, 1, "metallic", true},
                                                      {roughness, 1, "roughness", true}});
    for (int k = 0; k < 2; ++k)
        for (std::size_t i = 0; i < b.count; ++i) {
            const double* d = b.data[std::size_t(k)] + 3 * i;
            const double q = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
            if (!(q > 0.0) || !std::isfinite(q))
                throw py::value_error(std::string("ibl.reference_radiance: ") + (k == 0 ? "n" : "v") +
                                      " must be non-zero finite vectors (flat element " + std::to_string(i) + ")");
        }
    const ibl::cubemap<float> env = to_cubemap(fn, cube, threads);
    std::optional<ibl::cube_env_distribution> dist;
    std::vector<double> out(b.count * 12);
    auto material = [&](std::size_t i) {
        const double* c = b.data[2] + 3 * i;
        return ibl::make_reference_material(ibl::vec3<double>(c[0], c[1], c[2]), b.data[3][i], b.data[4][i], dw, dielectric_f0);
    };
    auto store = [&](std::size_t i, const ibl::radiance_estimate& e) {
        const ibl::vec3<double>* parts[4] = {&e.value, &e.diffuse, &e.specular, &e.std_error};
        for (int p = 0; p < 4; ++p)
            for (int c = 0; c < 3; ++c) out[(std::size_t(p) * b.count + i) * 3 + std::size_t(c)] = (*parts[p])[c];
    };
    auto point = [&](auto model_tag, std::size_t i) {
        using M = decltype(model_tag);
        auto vec = [&](int k) {
            const double* d = b.data[std::size_t(k)] + 3 * i;
            return ibl::vec3<double>(d[0], d[1], d[2]);
        };
        return ibl::reference_radiance<M>(env, dist ? &*dist : nullptr, glm::normalize(vec(0)), glm::normalize(vec(1)),
                                          material(i), opt);
    };
    {
        py::gil_scoped_release release;
        if (opt.strategy != ibl::radiance_strategy::brdf) dist.emplace(env);
    }
    if (!py_model) {
        py::gil_scoped_release release;
        ibl::thread_executor{threads}(b.count, [&](std::size_t begin, std::size_t end) {
            for (std::size_t i = begin; i < end; ++i) store(i, point(ibl::ggx_height_correlated{}, i));
        });
    } else {
        // at most samples lobe evaluations per point (one per draw); points in batches of <= 2^16 slots
        const std::size_t cap = std::size_t(opt.samples);
        const std::size_t per_batch = std::max<std::size_t>(1, (std::size_t(1) << 16) / cap);
        for (std::size_t p0 = 0; p0 < b.count; p0 += per_batch) {
            const std::size_t p1 = std::min(b.count, p0 + per_batch), m = p1 - p0;
            py::array_t<double> rough(static_cast<py::ssize_t>(m));
            for (std::size_t i = 0; i < m; ++i) rough.mutable_data()[i] = material(p0 + i).roughness;
            py::object alpha_obj = model.attr("alpha")(rough);
            refuse_complex("reference_radiance", "the result of model.alpha", alpha_obj);
            py::array_t<double> alpha_arr = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(alpha_obj);
            if (!alpha_arr || !(alpha_arr.ndim() == 0 || (alpha_arr.ndim() == 1 && std::size_t(alpha_arr.shape(0)) == m)))
                throw py::value_error("ibl.reference_radiance: model.alpha must return a real scalar or an array of shape (" +
                                      std::to_string(m) + ",)");
            std::vector<rr_buffer> bufs(m);
            std::vector<double> nh(m * cap), nv(m * cap), nl(m * cap);
            for (std::size_t i = 0; i < m; ++i) {
                const double a = alpha_arr.ndim() == 0 ? *alpha_arr.data() : alpha_arr.data()[i];
                if (!std::isfinite(a) || a < 0.0)
                    throw py::value_error("ibl.reference_radiance: model.alpha returned " + std::to_string(a) +
                                          " for roughness " + std::to_string(rough.data()[i]) + " (must be finite and >= 0)");
                bufs[i].alpha = a;
                bufs[i].nh = nh.data() + i * cap;
                bufs[i].nv = nv.data() + i * cap;
                bufs[i].nl = nl.data() + i * cap;
                bufs[i].capacity = cap;
            }
            {
                py::gil_scoped_release release;
                ibl::thread_executor{threads}(m, [&](std::size_t begin, std::size_t end) {
                    for (std::size_t i = begin; i < end; ++i) {
                        rr_tls_guard g(&bufs[i]);
                        point(rr_record_model{}, p0 + i);
                    }
                });
            }
            // the recorded calls of the batch, packed: point i's first count_i slots
            std::size_t total = 0;
            for (const rr_buffer& rb : bufs) {
                if (rb.n_ndf != rb.n_vis || rb.n_ndf > cap)
                    throw std::logic_error("ibl.reference_radiance: unexpected model call pattern");
                total += rb.n_ndf;
            }
            py::array_t<double> a_nh(static_cast<py::ssize_t>(total)), a_al(static_cast<py::ssize_t>(total)),
                a_nv(static_cast<py::ssize_t>(total)), a_nl(static_cast<py::ssize_t>(total)), a_r(static_cast<py::ssize_t>(total));
            std::vector<std::size_t> offset(m);
            for (std::size_t i = 0, at = 0; i < m; ++i) {
                offset[i] = at;
                for (std::size_t k = 0; k < bufs[i].n_ndf; ++k, ++at) {
                    a_nh.mutable_data()[at] = bufs[i].nh[k];
                    a_al.mutable_data()[at] = bufs[i].alpha;
                    a_nv.mutable_data()[at] = bufs[i].nv[k];
                    a_nl.mutable_data()[at] = bufs[i].nl[k];
                    a_r.mutable_data()[at] = rough.data()[i];
                }
            }
            auto values = [&](py::object r, const char* fn_name) {
                refuse_complex("reference_radiance", (std::string("the result of model.") + fn_name).c_str(), r);
                auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(r);
                if (!a || !(a.ndim() == 0 || (a.ndim() == 1 && std::size_t(a.shape(0)) == total)))
                    throw py::value_error(std::string("ibl.reference_radiance: model.") + fn_name +
                                          " must return a real scalar or an array of shape (" + std::to_string(total) + ",)");
                std::vector<double> vals(total);
                for (std::size_t k = 0; k < total; ++k) {
                    vals[k] = a.ndim() == 0 ? *a.data() : a.data()[k];
                    if (!std::isfinite(vals[k]))
                        throw py::value_error(std::string("ibl.reference_radiance: model.") + fn_name + " returned " +
                                              std::to_string(vals[k]) + " at n_dot_v=" + std::to_string(a_nv.data()[k]) +
                                              ", n_dot_l=" + std::to_string(a_nl.data()[k]) + ", n_dot_h=" +
                                              std::to_string(a_nh.data()[k]) + ", roughness=" + std::to_string(a_r.data()[k]) +
                                              " (must be finite)");
                }
                return vals;
            };
            const std::vector<double> dv = values(model.attr("ndf")(a_nh, a_al), "ndf");
            const std::vector<double> vv = values(model.attr("visibility")(a_nv, a_nl, a_r), "visibility");
            py::gil_scoped_release release;
            ibl::thread_executor{threads}(m, [&](std::size_t begin, std::size_t end) {
                for (std::size_t i = begin; i < end; ++i) {
                    rr_buffer rep{};
                    rep.alpha = bufs[i].alpha;
                    rep.d = dv.data() + offset[i];
                    rep.v = vv.data() + offset[i];
                    rep.capacity = bufs[i].n_ndf;
                    rr_tls_guard g(&rep);
                    store(p0 + i, point(rr_replay_model{}, p0 + i));
                }
            });
        }
    }
    py::dict result;
    const char* names[4] = {"value", "diffuse", "specular", "std_error"};
    for (std::size_t p = 0; p < 4; ++p) {
        py::array_t<double> a = make_output<double>(b.shape, 3);
        std::copy(out.begin() + std::ptrdiff_t(p * b.count * 3), out.begin() + std::ptrdiff_t((p + 1) * b.count * 3),
                  a.mutable_data());
        check_finite_result("reference_radiance", a.data(), std::size_t(a.size()),
                            "the cube's, the material's or the model's finite values are too large (the sums overflow)");
        result[names[p]] = a;
    }
    return result;
}

} // namespace

void bind_env(py::module_& m) {
    m.def("prefilter", &prefilter, py::arg("cube"), py::kw_only(), py::arg("levels") = -1, py::arg("samples") = 0u,
          py::arg("method") = "fis", py::arg("weight") = "n_dot_l", py::arg("threads") = 0u, py::arg("model") = py::none(),
          py::arg("peaks") = py::none(), py::arg("coarse_tail") = true, py::arg("sh_bands") = 24, py::arg("mid_tail") = true,
          "The prefiltered specular chain of ibl::prefilter (N = V = R): a list of float32 arrays\n"
          "(6, s, s, 3), level l of face size max(1, n >> l) for roughness l / (levels - 1).\n"
          "cube: (6, n, n, 3), faces +X, -X, +Y, -Y, +Z, -Z, [face, y, x], row 0 = t = 0. levels: -1\n"
          "automatic (ibl-bake's rule), 0 the full chain. samples: per texel at level 1 (0 = the default\n"
          "doubling schedule). method 'fis' (filtered importance sampling), 'fast' or 'importance'.\n"
          "weight 'n_dot_l' (Karis) or 'g1'. threads: 0 = all cores. model: None or 'ggx' (the built-in\n"
          "GGX lobe) or a Python model with alpha(roughness) and ndf(n_dot_h, alpha): its LD lobe,\n"
          "tabulated from one vectorised ndf call on a fine grid of n.h per level roughness\n"
          "(weight 'n_dot_l' only). peaks: the fast filter's peak split, at most this many source texels\n"
          "taken out of the tap set and added back through the closed-form GGX kernel (None = 1024 for\n"
          "the built-in lobe, off for a Python model; 0 = off). coarse_tail: the fast filter reads each\n"
          "level's kernel tail from the finished next level (prefilter_options::coarse_tail; True by default).\n"
          "sh_bands: the fast filter's rough levels by spherical-harmonic convolution: a level whose kernel\n"
          "needs at most this many bands is reconstructed from the source's projection (prefilter_options::\n"
          "sh_rough.max_bands; 24 by default, at most 32; 0 = tap sets on every level). mid_tail: the fast\n"
          "filter's intermediate coarse tail for the built-in lobe (prefilter_options::mid_tail; True by\n"
          "default: a 256^2 chain's level 1 reads its tail from a half-size level at r = 0.22).");
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
          py::kw_only(), py::arg("weight") = "n_dot_l", py::arg("threads") = 0u, py::arg("model") = py::none(),
          "Converged LD at directions (..., 3) and roughness (broadcast) by importance sampling of the\n"
          "cube's level 0 (ibl::reference_ld, double): array (..., 3). model: None or 'ggx' (the built-in\n"
          "GGX lobe) or a Python model (alpha, ndf): its tabulated LD lobe as in ibl.prefilter, one\n"
          "table per distinct roughness (at most 1024).");
    m.def("extract_sun", &extract_sun, py::arg("cube"), py::kw_only(), py::arg("threshold_over_median") = 50.0,
          py::arg("threshold_over_peak") = 1e-3, py::arg("max_solid_angle") = 1e-2, py::arg("min_share") = 0.2,
          py::arg("threads") = 0u,
          "Finds a sun (a compact, very bright region) in a cube and splits it off as a disk light\n"
          "(ibl::extract_sun_in_place, env/sun_extract.hpp): (light, residual), or None when there is no\n"
          "compact dominant source (no texel above the threshold, region above max_solid_angle, or less than\n"
          "min_share of the irradiance facing it). light: dict with 'direction' (unit, towards the light),\n"
          "'solid_angle' (sr) and 'angular_radius' (rad) of the equivalent uniform disk, its 'radiance' (RGB),\n"
          "the 'irradiance' it delivers facing it (= radiance pi sin^2 angular_radius), 'region_solid_angle',\n"
          "'region_texels' and 'share'. residual: float32 (6, n, n, 3), the region filled harmonically from\n"
          "its ring.");
    m.def("reference_radiance", &reference_radiance, py::arg("cube"), py::arg("n"), py::arg("v"), py::arg("base_color"),
          py::arg("metallic"), py::arg("roughness"), py::kw_only(), py::arg("samples") = 4096, py::arg("batches") = 16,
          py::arg("seed") = 0u, py::arg("strategy") = "mis", py::arg("diffuse") = "lambert", py::arg("dielectric_f0") = 0.04,
          py::arg("threads") = 0u, py::arg("model") = py::none(),
          "Outgoing radiance Lo(n, v) of a metallic-roughness material under the cube WITHOUT the split sum\n"
          "(ibl::reference_radiance, reference/radiance.hpp: GGX height-correlated specular + Lambert, single\n"
          "scattering, F90 = 1), by multiple importance sampling of the BRDF and the environment (randomised\n"
          "QMC in `batches` independent batches, `samples` radiance evaluations per point). n, v (..., 3)\n"
          "(normalised here), base_color (..., 3), metallic, roughness broadcast; all in [0, 1] but n, v.\n"
          "strategy 'mis', 'brdf' or 'env'; diffuse 'lambert' (k_d = 1) or 'one_minus_fresnel_roughness' (the\n"
          "single-scattering shader's kD). Returns a dict of float64 arrays (..., 3): 'value', 'diffuse',\n"
          "'specular' and 'std_error' (of value, from the batch means). Deterministic for given inputs.\n"
          "model: None or 'ggx' (GGX height-correlated), or a Python model with alpha(roughness),\n"
          "ndf(n_dot_h, alpha), visibility(n_dot_v, n_dot_l, roughness): the same estimator run twice per\n"
          "batch of points (record the calls, evaluate the model once per batch, replay its values).");
}

} // namespace ibl_py
