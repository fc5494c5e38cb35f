// python/ibl_module.cpp — the Python extension module `ibl` (pybind11): NumPy in, NumPy out.
// See docs/python.md for the API and python/ibl.pyi for the signatures.
#include "common.hpp"

#include <ibl/core/config.hpp>

namespace ibl_py {
void bind_brdf(py::module_& m);
void bind_dfg(py::module_& m);
void bind_env(py::module_& m);
void bind_io(py::module_& m);
void bind_lookup(py::module_& m);
} // namespace ibl_py

PYBIND11_MODULE(ibl, m) {
    m.doc() = "ibl: image-based-lighting mathematics (samplers, BRDF terms, split-sum DFG of built-in and "
              "Python BRDF models, prefilter, irradiance, SH, image and KTX2 readers, runtime lookups) over NumPy arrays. float32 inputs are computed in float, others in float64.";
    m.attr("__version__") = IBL_VERSION_STRING;
    ibl_py::bind_brdf(m);
    ibl_py::bind_dfg(m);
    ibl_py::bind_env(m);
    ibl_py::bind_io(m);
    ibl_py::bind_lookup(m);
}
