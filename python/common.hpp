#pragma once
// python/common.hpp — the NumPy plumbing shared by the binding's source files: argument
// conversion (float32 stays float32, anything else real becomes float64), broadcasting over
// leading dimensions with a fixed trailing "core" size per argument (1 = scalar, 2 = u, 3 = a
// direction), range checks that raise ValueError, and the element loop with the GIL released.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

namespace ibl_py {

namespace py = pybind11;

/// One argument of an element-wise function: its Python object, its core size (1: a scalar per
/// element, k > 1: a trailing axis of length k) and its name (for error messages). `unit`: every
/// value must lie in [0, 1] (NaN refused) — roughness and alpha.
struct arg {
    py::handle obj;
    std::size_t core = 1;
    const char* name = "";
    bool unit = false;
};

inline bool is_f32(const py::dtype& d) { return d.kind() == 'f' && d.itemsize() == 4; }

/// TypeError for a complex array or NumPy scalar: NumPy's forced cast to a real dtype would
/// drop the imaginary part silently (with a ComplexWarning at most).
inline void refuse_complex(const char* fn, const char* name, py::handle obj) {
    bool complex = false;
    if (py::isinstance<py::array>(obj)) complex = py::reinterpret_borrow<py::array>(obj).dtype().kind() == 'c';
    else if (PyComplex_Check(obj.ptr())) complex = true;
    else if (py::hasattr(obj, "dtype") && py::hasattr(obj, "shape")) {
        py::object dt = obj.attr("dtype");
        complex = py::isinstance<py::dtype>(dt) && py::reinterpret_borrow<py::dtype>(dt).kind() == 'c';
    }
    if (complex)
        throw py::type_error(std::string("ibl.") + fn + ": argument '" + name + "' is complex; a real array is expected");
}

/// ValueError when a result holds a non-finite value: the inputs were finite, but too large (a
/// cube near float's range, a model returning huge values) for the computation not to overflow.
template <class T> void check_finite_result(const char* fn, const T* p, std::size_t n, const char* cause) {
    for (std::size_t i = 0; i < n; ++i)
        if (!std::isfinite(p[i]))
            throw py::value_error(std::string("ibl.") + fn + ": the result is not finite (" + std::to_string(double(p[i])) +
                                  " at flat index " + std::to_string(i) + "): " + cause);
}

/// True when every NumPy argument is float32 (and at least one is): the computation then runs in
/// float, otherwise in double. Python numbers do not vote (as NumPy 2's promotion rules).
inline bool all_float32(const std::vector<arg>& args) {
    bool any = false;
    for (const arg& a : args) {
        if (py::isinstance<py::array>(a.obj)) {
            if (!is_f32(py::reinterpret_borrow<py::array>(a.obj).dtype())) return false;
            any = true;
        } else if (py::hasattr(a.obj, "dtype")) { // a NumPy scalar
            if (!is_f32(py::dtype::from_args(a.obj.attr("dtype")))) return false;
            any = true;
        }
    }
    return any;
}

/// The inputs, broadcast and C-contiguous in T (a copy only where a conversion or a broadcast
/// needs one), and the leading shape of the result.
template <class T> struct broadcast_args {
    std::vector<py::array_t<T, py::array::c_style | py::array::forcecast>> arrays;
    std::vector<const T*> data;
    std::vector<py::ssize_t> shape; // leading (broadcast) shape
    std::size_t count = 1;          // product of shape
    bool scalar = true;             // every input was a scalar (0-d)
};

template <class T> broadcast_args<T> broadcast(const char* fn, const std::vector<arg>& args) {
    py::module_ np = py::module_::import("numpy");
    broadcast_args<T> out;
    std::vector<py::array> conv;
    py::list leads;
    for (const arg& a : args) {
        if (a.obj.is_none()) // NumPy would make it NaN
            throw py::type_error(std::string("ibl.") + fn + ": argument '" + a.name + "' is None; a real number or array is expected");
        refuse_complex(fn, a.name, a.obj);
        py::array x = py::array_t<T, py::array::c_style | py::array::forcecast>::ensure(a.obj);
        if (!x) throw py::type_error(std::string("ibl.") + fn + ": argument '" + a.name + "' is not a real number array");
        if (a.core > 1) {
            if (x.ndim() < 1 || std::size_t(x.shape(x.ndim() - 1)) != a.core)
                throw py::value_error(std::string("ibl.") + fn + ": argument '" + a.name + "' must have shape (..., " +
                                      std::to_string(a.core) + "), got " + std::string(py::str(py::tuple(x.attr("shape")))));
            out.scalar = false;
        } else if (x.ndim() > 0) {
            out.scalar = false;
        }
        py::tuple shp = x.attr("shape");
        py::ssize_t nlead = x.ndim() - (a.core > 1 ? 1 : 0);
        leads.append(shp[py::slice(0, nlead, 1)]);
        conv.push_back(x);
    }
    py::tuple lead;
    try {
        lead = np.attr("broadcast_shapes")(*leads);
    } catch (py::error_already_set&) {
        throw py::value_error(std::string("ibl.") + fn + ": the arguments' shapes do not broadcast: " + std::string(py::str(leads)));
    }
    for (auto d : lead) out.shape.push_back(d.cast<py::ssize_t>());
    for (py::ssize_t d : out.shape) out.count *= std::size_t(d);
    for (std::size_t i = 0; i < args.size(); ++i) {
        py::tuple full = lead;
        if (args[i].core > 1) {
            full = py::tuple(lead.size() + 1);
            for (std::size_t d = 0; d < lead.size(); ++d) full[d] = lead[d];
            full[lead.size()] = py::int_(args[i].core);
        }
        py::object b = conv[i];
        if (!py::tuple(conv[i].attr("shape")).equal(full)) b = np.attr("broadcast_to")(conv[i], full);
        auto c = py::array_t<T, py::array::c_style | py::array::forcecast>::ensure(b); // copies a broadcast view only
        out.data.push_back(c.data());
        out.arrays.push_back(std::move(c));
    }
    for (std::size_t i = 0; i < args.size(); ++i) {
        if (!args[i].unit) continue;
        const T* p = out.data[i];
        const std::size_t n = out.count * args[i].core;
        for (std::size_t k = 0; k < n; ++k)
            if (!(p[k] >= T(0) && p[k] <= T(1)))
                throw py::value_error(std::string("ibl.") + fn + ": '" + args[i].name + "' must lie in [0, 1] (no NaN), got " +
                                      std::to_string(double(p[k])) + " at flat index " + std::to_string(k));
    }
    return out;
}

/// A new array of shape lead + (core,) (core 1: lead alone).
template <class T> py::array_t<T> make_output(const std::vector<py::ssize_t>& lead, std::size_t core) {
    std::vector<py::ssize_t> shape = lead;
    if (core > 1) shape.push_back(py::ssize_t(core));
    return py::array_t<T>(shape);
}

/// Element-wise map: kernel(const T* const* in, T* out) per element (in[i] points at element's
/// core values of argument i), with the GIL released. Scalars in give a Python float out when the
/// output core is 1.
template <class T, class Kernel>
py::object map_typed(const char* fn, const std::vector<arg>& args, std::size_t out_core, Kernel&& kernel) {
    broadcast_args<T> b = broadcast<T>(fn, args);
    py::array_t<T> out = make_output<T>(b.shape, out_core);
    T* o = out.mutable_data();
    {
        py::gil_scoped_release release;
        std::vector<const T*> in(args.size());
        for (std::size_t e = 0; e < b.count; ++e) {
            for (std::size_t i = 0; i < args.size(); ++i) in[i] = b.data[i] + e * args[i].core;
            kernel(in.data(), o + e * out_core);
        }
    }
    if (b.scalar && out_core == 1) return py::float_(double(o[0]));
    return out;
}

/// map_typed in float when every NumPy input is float32, in double otherwise. `make` is a generic
/// lambda [](auto tag) returning the kernel for T = decltype(tag).
template <class Make> py::object map(const char* fn, const std::vector<arg>& args, std::size_t out_core, Make&& make) {
    if (all_float32(args)) return map_typed<float>(fn, args, out_core, make(float{}));
    return map_typed<double>(fn, args, out_core, make(double{}));
}

} // namespace ibl_py
