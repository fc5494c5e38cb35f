// python/bind_brdf.cpp — samplers (Hammersley, GGX NDF and visible normals with their pdfs) and the
// BRDF terms of ibl/brdf/*.hpp as broadcasting NumPy functions. Each calls the library's function
// element by element (float32 inputs in float, anything else in double), GIL released.
#include "common.hpp"

#include <ibl/brdf.hpp>
#include <ibl/core/limits.hpp>
#include <ibl/sampling/ggx.hpp>
#include <ibl/sampling/sequence.hpp>

#include <cstdint>
#include <string>

namespace ibl_py {

namespace {

template <class T> ibl::vec2<T> v2(const T* p) { return ibl::vec2<T>(p[0], p[1]); }
template <class T> ibl::vec3<T> v3(const T* p) { return ibl::vec3<T>(p[0], p[1], p[2]); }
template <class T> void put3(T* o, const ibl::vec3<T>& v) {
    o[0] = v.x;
    o[1] = v.y;
    o[2] = v.z;
}

} // namespace

// A scalar function of N scalar arguments: PYNAME(x0, ...) -> CALL, with in[i] the arguments.
#define IBL_PY_KERNEL(CALL)                                                                                            \
    [](auto tag) {                                                                                                     \
        using T = decltype(tag);                                                                                       \
        return [](const T* const* in, T* out) { CALL; };                                                              \
    }

void bind_brdf(py::module_& m) {
    // ---- samplers ------------------------------------------------------------------------------
    m.def(
        "hammersley",
        [](long long n, bool float32) -> py::object {
            if (n < 0 || std::uint64_t(n) > ibl::limits::max_samples)
                throw py::value_error("ibl.hammersley: n must lie in [0, " + std::to_string(ibl::limits::max_samples) +
                                      "], got " + std::to_string(n));
            auto fill = [n](auto tag) {
                using T = decltype(tag);
                py::array_t<T> out({py::ssize_t(n), py::ssize_t(2)});
                T* o = out.mutable_data();
                py::gil_scoped_release release;
                for (std::uint32_t i = 0; i < std::uint32_t(n); ++i) {
                    const ibl::vec2<T> p = ibl::hammersley<T>(i, std::uint32_t(n));
                    o[2 * i] = p.x;
                    o[2 * i + 1] = p.y;
                }
                return out;
            };
            if (float32) return fill(float{});
            return fill(double{});
        },
        py::arg("n"), py::kw_only(), py::arg("float32") = false,
        "The n-point Hammersley set: array (n, 2), row i = (i / n, radical_inverse(i)) (ibl::hammersley).\n"
        "float32=True computes in float (as the library's float tables do).");

    m.def(
        "sample_ggx_ndf",
        [](py::object u, py::object alpha) {
            return map("sample_ggx_ndf", {{u, 2, "u"}, {alpha, 1, "alpha", true}}, 3,
                       IBL_PY_KERNEL(put3(out, ibl::sample_ggx_ndf(v2(in[0]), *in[1]))));
        },
        py::arg("u"), py::arg("alpha"),
        "Half vectors h (..., 3) with density D(h) n.h from u (..., 2) in [0, 1)^2 and alpha in [0, 1]\n"
        "(tangent space, z = normal; ibl::sample_ggx_ndf). Broadcasts u's leading axes with alpha.");
    m.def(
        "ggx_ndf_pdf",
        [](py::object h, py::object alpha) {
            return map("ggx_ndf_pdf", {{h, 3, "h"}, {alpha, 1, "alpha", true}}, 1,
                       IBL_PY_KERNEL(*out = ibl::ggx_ndf_pdf(v3(in[0]), *in[1])));
        },
        py::arg("h"), py::arg("alpha"), "Density of sample_ggx_ndf per unit solid angle of h: D(h) max(0, n.h).");
    m.def(
        "ggx_ndf_reflected_pdf",
        [](py::object v, py::object h, py::object alpha) {
            return map("ggx_ndf_reflected_pdf", {{v, 3, "v"}, {h, 3, "h"}, {alpha, 1, "alpha", true}}, 1,
                       IBL_PY_KERNEL(*out = ibl::ggx_ndf_reflected_pdf(v3(in[0]), v3(in[1]), *in[2])));
        },
        py::arg("v"), py::arg("h"), py::arg("alpha"),
        "Density per unit solid angle of l = reflect(v, h), h ~ sample_ggx_ndf: D(h) n.h / (4 v.h).");
    m.def(
        "sample_ggx_vndf",
        [](py::object v, py::object u, py::object alpha) {
            return map("sample_ggx_vndf", {{v, 3, "v"}, {u, 2, "u"}, {alpha, 1, "alpha", true}}, 3,
                       IBL_PY_KERNEL(put3(out, ibl::sample_ggx_vndf(v3(in[0]), v2(in[1]), *in[2]))));
        },
        py::arg("v"), py::arg("u"), py::arg("alpha"),
        "Visible normals h (..., 3) of the unit view v (..., 3) (v.z >= 0) from u (..., 2) and alpha\n"
        "(Dupuy & Benyoub 2023; ibl::sample_ggx_vndf).");
    m.def(
        "ggx_vndf_pdf",
        [](py::object v, py::object h, py::object alpha) {
            return map("ggx_vndf_pdf", {{v, 3, "v"}, {h, 3, "h"}, {alpha, 1, "alpha", true}}, 1,
                       IBL_PY_KERNEL(*out = ibl::ggx_vndf_pdf(v3(in[0]), v3(in[1]), *in[2])));
        },
        py::arg("v"), py::arg("h"), py::arg("alpha"),
        "Density of sample_ggx_vndf per unit solid angle of h: G1(v) max(0, v.h) D(h) / n.v.");
    m.def(
        "ggx_vndf_reflected_pdf",
        [](py::object v, py::object h, py::object alpha) {
            return map("ggx_vndf_reflected_pdf", {{v, 3, "v"}, {h, 3, "h"}, {alpha, 1, "alpha", true}}, 1,
                       IBL_PY_KERNEL(*out = ibl::ggx_vndf_reflected_pdf(v3(in[0]), v3(in[1]), *in[2])));
        },
        py::arg("v"), py::arg("h"), py::arg("alpha"),
        "Density per unit solid angle of l = reflect(v, h), h ~ sample_ggx_vndf: G1(v) D(h) / (4 n.v).");

    // ---- BRDF terms ----------------------------------------------------------------------------
#define IBL_PY_DEF1(NAME, A0, U0, DOC)                                                                                  \
    m.def(                                                                                                             \
        #NAME, [](py::object x0) { return map(#NAME, {{x0, 1, A0, U0}}, 1, IBL_PY_KERNEL(*out = ibl::NAME(*in[0]))); }, \
        py::arg(A0), DOC)
#define IBL_PY_DEF2(NAME, A0, U0, A1, U1, DOC)                                                                          \
    m.def(                                                                                                             \
        #NAME,                                                                                                         \
        [](py::object x0, py::object x1) {                                                                             \
            return map(#NAME, {{x0, 1, A0, U0}, {x1, 1, A1, U1}}, 1, IBL_PY_KERNEL(*out = ibl::NAME(*in[0], *in[1]))); \
        },                                                                                                             \
        py::arg(A0), py::arg(A1), DOC)
#define IBL_PY_DEF3(NAME, A0, U0, A1, U1, A2, U2, DOC)                                                                  \
    m.def(                                                                                                             \
        #NAME,                                                                                                         \
        [](py::object x0, py::object x1, py::object x2) {                                                              \
            return map(#NAME, {{x0, 1, A0, U0}, {x1, 1, A1, U1}, {x2, 1, A2, U2}}, 1,                                  \
                       IBL_PY_KERNEL(*out = ibl::NAME(*in[0], *in[1], *in[2])));                                      \
        },                                                                                                             \
        py::arg(A0), py::arg(A1), py::arg(A2), DOC)

    IBL_PY_DEF1(alpha_from_roughness, "roughness", true, "alpha = roughness^2.");
    IBL_PY_DEF2(ndf_ggx, "n_dot_h", false, "alpha", true,
                "GGX D(h) = alpha^2 / (pi ((n.h)^2 (alpha^2 - 1) + 1)^2); 0 for n.h < 0 (alpha clamped to\n"
                "[ggx_min_alpha, 1]).");
    IBL_PY_DEF2(g1_smith_ggx, "n_dot_w", false, "alpha", true, "Smith G1 for GGX: 2 mu / (mu + sqrt(mu^2 + alpha^2 (1 - mu^2))).");
    IBL_PY_DEF2(lambda_ggx, "n_dot_w", false, "alpha", true,
                "Smith Lambda for GGX: (sqrt(1 + alpha^2 tan^2) - 1) / 2 (the largest finite value at mu = 0).");
    IBL_PY_DEF3(v_smith_ggx_correlated, "n_dot_v", false, "n_dot_l", false, "alpha", true,
                "Height-correlated Smith visibility G2 / (4 n.v n.l) for GGX (finite everywhere).");
    IBL_PY_DEF3(g2_smith_ggx_correlated, "n_dot_v", false, "n_dot_l", false, "alpha", true,
                "Height-correlated Smith G2 for GGX = 1 / (1 + Lambda(v) + Lambda(l)).");
    IBL_PY_DEF1(k_ibl, "roughness", true, "Schlick-GGX k for image-based lighting: roughness^2 / 2.");
    IBL_PY_DEF1(k_direct, "roughness", true, "Schlick-GGX k for punctual lights: (roughness + 1)^2 / 8.");
    IBL_PY_DEF2(g1_schlick_ggx, "n_dot_w", false, "k", true, "Schlick-GGX G1 = mu / (mu (1 - k) + k).");
    IBL_PY_DEF3(g_smith_schlick_ggx, "n_dot_v", false, "n_dot_l", false, "k", true,
                "Separable Schlick-GGX G = G1(n.v) G1(n.l); pass k = k_ibl(r) or k_direct(r).");
    IBL_PY_DEF3(v_smith_schlick_ggx, "n_dot_v", false, "n_dot_l", false, "k", true,
                "Schlick-GGX visibility G / (4 n.v n.l) with the cosines cancelled (finite everywhere).");
    IBL_PY_DEF1(schlick_weight, "cos_theta", false, "Schlick's weight (1 - cos)^5, cos clamped to [0, 1].");
    IBL_PY_DEF3(fresnel_schlick_roughness, "cos_theta", false, "f0", false, "roughness", true,
                "Roughness-aware Schlick Fresnel F0 + (max(1 - r, F0) - F0)(1 - cos)^5.");
    IBL_PY_DEF2(ndf_blinn_phong, "n_dot_h", false, "alpha", true,
                "Normalised Blinn-Phong D = (e + 2)/(2 pi) (n.h)^e, e = 2 / alpha^2 - 2 (Walter et al. 2007).");
    IBL_PY_DEF1(blinn_phong_exponent_from_alpha, "alpha", true, "Blinn-Phong exponent e = 2 / alpha^2 - 2.");
    IBL_PY_DEF2(ndf_charlie, "n_dot_h", false, "alpha", true,
                "Charlie sheen D = (2 + 1/alpha) sin^(1/alpha) / (2 pi) (Estevez & Kulla 2017).");
    IBL_PY_DEF2(v_neubelt, "n_dot_v", false, "n_dot_l", false,
                "Neubelt-Pettineo sheen visibility 1 / (4 (n.l + n.v - n.v n.l)).");
#undef IBL_PY_DEF1
#undef IBL_PY_DEF2
#undef IBL_PY_DEF3

    m.def(
        "fresnel_schlick",
        [](py::object c, py::object f0, py::object f90) {
            return map("fresnel_schlick", {{c, 1, "cos_theta"}, {f0, 1, "f0"}, {f90, 1, "f90"}}, 1,
                       IBL_PY_KERNEL(*out = ibl::fresnel_schlick(*in[0], *in[1], *in[2])));
        },
        py::arg("cos_theta"), py::arg("f0"), py::arg("f90") = 1.0,
        "Schlick Fresnel F0 + (F90 - F0)(1 - cos)^5 (per element; pass an RGB F0 as an array (..., 3) and\n"
        "cos_theta[..., None]).");
}

#undef IBL_PY_KERNEL

} // namespace ibl_py
