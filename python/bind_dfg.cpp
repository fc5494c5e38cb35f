// python/bind_dfg.cpp — the split-sum DFG terms of built-in C++ models and of BRDF models written in
// Python.
//
// A Python model is evaluated once per batch of nodes (at most max_batch_nodes), never per node. The library's own quadrature
// (ibl::dfg_quadrature_lanes, the path of dfg_exact and make_dfg_lut_exact) runs twice per batch:
//   1. with recording_model, whose sample_weight stores its arguments (n.v, n.l, n.h, v.h) in call
//      order and returns 0: the nodes of the rule, exactly as the C++ path forms them;
//   2. the Python functions are called on those arrays (their values checked for finiteness);
//   3. with replay_model, whose sample_weight returns the weight of each node in the same order:
//      brdf/model.hpp's w = 4 (V n.l) sat(v.h) / n.h * (D_M / D_ggx) (0 where n.l <= 0 or
//      n.h <= 0), formed in double from the model's values and the node, or the model's own
//      sample_weight. The sums, their order and the node weights are the library's.
// So a Python model equal to a C++ model gives the C++ result up to the rounding of its own
// arithmetic (tables: the weight rounds through float, as in make_dfg_lut_exact).
#include "common.hpp"

#include <ibl/bake/dfg.hpp>
#include <ibl/bake/dfg_lut.hpp>
#include <ibl/bake/dfg_multiscatter.hpp>
#include <ibl/core/limits.hpp>
#include <ibl/brdf/blinn_phong.hpp>
#include <ibl/core/executor.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <type_traits>
#include <string>
#include <vector>

namespace ibl_py {

namespace {

/// Blinn-Phong NDF (Walter's alpha mapping, alpha = r^2) with the height-correlated Smith GGX
/// visibility at the same alpha: a model with a non-GGX NDF, sampled by the GGX quadrature with the
/// ratio D_bp / D_ggx (brdf/model.hpp). Defined by the binding for comparisons (not in the library).
struct blinn_phong_model {
    static constexpr const char* name = "blinn_phong";
    template <class T> static T alpha(T roughness) noexcept { return ibl::alpha_from_roughness(roughness); }
    template <class T> static T ndf(T n_dot_h, T alpha) noexcept { return ibl::ndf_blinn_phong(n_dot_h, alpha); }
    template <class T> static T visibility(T n_dot_v, T n_dot_l, T roughness) noexcept {
        return ibl::v_smith_ggx_correlated(n_dot_v, n_dot_l, alpha(roughness));
    }
    template <class T> static T sample_weight(T n_dot_v, T n_dot_l, T n_dot_h, T v_dot_h, T roughness) noexcept {
        const T a = alpha(roughness);
        const T dg = ibl::ndf_ggx(n_dot_h, a);
        const T ratio = dg > T(0) ? ndf(n_dot_h, a) / dg : T(0);
        return ibl::weight_ggx_sampled(visibility(n_dot_v, n_dot_l, roughness), n_dot_l, n_dot_h, v_dot_h) * ratio;
    }
};
static_assert(ibl::brdf_model<blinn_phong_model, float> && ibl::brdf_model<blinn_phong_model, double>);

// ---- record / replay models --------------------------------------------------------------------

struct node_buffer {
    double alpha = 0.0;                // the model's alpha of the current texel / row
    double *nv, *nl, *nh, *vh;         // recording: where the next node goes
    // replay: the model's values of the next node: sample_weight (s), or ndf (d) and visibility (v)
    const double *s = nullptr, *d = nullptr, *v = nullptr;
    std::size_t cursor = 0, capacity = 0;
};
thread_local node_buffer* tls_nodes = nullptr;

struct recording_model {
    template <class T> static T alpha(T) noexcept { return T(tls_nodes->alpha); }
    template <class T> static T sample_weight(T n_dot_v, T n_dot_l, T n_dot_h, T v_dot_h, T) noexcept {
        node_buffer& b = *tls_nodes;
        if (b.cursor < b.capacity) {
            b.nv[b.cursor] = double(n_dot_v);
            b.nl[b.cursor] = double(n_dot_l);
            b.nh[b.cursor] = double(n_dot_h);
            b.vh[b.cursor] = double(v_dot_h);
        }
        ++b.cursor;
        return T(0);
    }
};
/// The weight of the node in replay: the model's sample_weight, or brdf/model.hpp's weight from
/// its ndf and visibility, formed in double from the node's values as recorded (the arguments,
/// which are the recorded values before their conversion to double): 4 (V n.l) sat(v.h) / n.h *
/// D_M / D_ggx, 0 where n.l <= 0 or n.h <= 0.
struct replay_model {
    template <class T> static T alpha(T) noexcept { return T(tls_nodes->alpha); }
    template <class T> static T sample_weight(T, T n_dot_l, T n_dot_h, T v_dot_h, T) noexcept {
        node_buffer& b = *tls_nodes;
        const std::size_t i = b.cursor++;
        if (i >= b.capacity) return T(0);
        if (b.s) return T(b.s[i]);
        const double l = double(n_dot_l), h = double(n_dot_h);
        const double dg = ibl::ndf_ggx(h, b.alpha);
        const double ratio = dg > 0.0 ? b.d[i] / dg : 0.0;
        const double w = ibl::weight_ggx_sampled(b.v[i], l, h, double(v_dot_h)) * ratio;
        return T(l > 0.0 && h > 0.0 ? w : 0.0);
    }
};

struct tls_guard {
    explicit tls_guard(node_buffer* b) { tls_nodes = b; }
    ~tls_guard() { tls_nodes = nullptr; }
    tls_guard(const tls_guard&) = delete;
    tls_guard& operator=(const tls_guard&) = delete;
};

/// Nodes per batch: the Python functions see arrays of at most this length (whole texels, whole
/// table rows). Small enough that a NumPy model's arrays and temporaries stay in cache and are reused
/// by the allocator: a 64^2 table in batches of 2^16 nodes took 128 ms against 200 ms in one batch of
/// 1.8 M nodes (docs/python.md, "BRDF models"); 2^14 to 2^16 measured alike, 2^18 and up as one batch.
constexpr std::size_t max_batch_nodes = std::size_t(1) << 16;

// ---- the Python model ----------------------------------------------------------------------------

std::string shape_str(const py::array& a) { return std::string(py::str(py::tuple(a.attr("shape")))); }

/// Why a Python model's finite values can still give a non-finite integral.
constexpr const char* model_overflow =
    "the Python model's finite values are too large (the weights overflow), or its albedo is 0 where the "
    "multiscatter channel divides by it";

/// result of model.<fn>(...) as n float64 values (a scalar or an array broadcastable to (n,)).
py::array_t<double> model_result(py::object r, const char* fn, std::size_t n) {
    refuse_complex("dfg", (std::string("the result of model.") + fn).c_str(), r);
    auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(r);
    if (!a) throw py::type_error(std::string("ibl: model.") + fn + " returned " + std::string(py::str(py::type::of(r))) +
                                 ", not a real array");
    if (a.ndim() == 0 || (a.ndim() == 1 && std::size_t(a.shape(0)) == n)) {
        if (a.ndim() == 1) return a;
        py::array_t<double> full(static_cast<py::ssize_t>(n));
        std::fill(full.mutable_data(), full.mutable_data() + n, *a.data());
        return full;
    }
    throw py::value_error(std::string("ibl: model.") + fn + " returned shape " + shape_str(a) + " for inputs of shape (" +
                          std::to_string(n) + ",)");
}

struct python_model {
    py::object obj;
    bool has_sample_weight = false;

    explicit python_model(py::object o) : obj(std::move(o)) {
        has_sample_weight = py::hasattr(obj, "sample_weight");
        std::vector<const char*> need{"alpha"};
        if (!has_sample_weight) {
            need.push_back("ndf");
            need.push_back("visibility");
        }
        for (const char* f : need)
            if (!py::hasattr(obj, f) || !PyCallable_Check(obj.attr(f).ptr()))
                throw py::type_error(std::string("ibl: the model object has no callable '") + f +
                                     "' (a Python BRDF model needs alpha(roughness), ndf(n_dot_h, alpha) and "
                                     "visibility(n_dot_v, n_dot_l, roughness), or alpha and sample_weight)");
    }

    /// alpha for n roughness values (finite, >= 0).
    std::vector<double> alpha(const std::vector<double>& r) const {
        py::array_t<double> ra(static_cast<py::ssize_t>(r.size()));
        std::copy(r.begin(), r.end(), ra.mutable_data());
        py::array_t<double> a = model_result(obj.attr("alpha")(ra), "alpha", r.size());
        std::vector<double> out(a.data(), a.data() + r.size());
        for (std::size_t i = 0; i < out.size(); ++i)
            if (!std::isfinite(out[i]) || out[i] < 0.0)
                throw py::value_error("ibl: model.alpha returned " + std::to_string(out[i]) + " for roughness " +
                                      std::to_string(r[i]) + " (must be finite and >= 0)");
        return out;
    }

    /// The model's values at n nodes, checked: sample_weight finite at every node, or ndf and
    /// visibility finite wherever n.l > 0 and n.h > 0 (replay_model forms the weight). One pass
    /// sums x - x of the checked values (NaN once one is NaN or infinite); only then a second pass
    /// finds the first offending node for the message.
    struct values {
        py::array_t<double> s, d, v;
    };
    values evaluate(std::size_t n, const py::array_t<double>& nv, const py::array_t<double>& nl, const py::array_t<double>& nh,
                    const py::array_t<double>& vh, const py::array_t<double>& rough, const py::array_t<double>& alpha) const {
        const double *pnv = nv.data(), *pl = nl.data(), *ph = nh.data(), *pr = rough.data();
        auto fail = [&](const double* p, const char* fn, bool only_valid) {
            for (std::size_t i = 0; i < n; ++i) {
                if (only_valid && !(pl[i] > 0.0 && ph[i] > 0.0)) continue;
                if (!std::isfinite(p[i]))
                    throw py::value_error(std::string("ibl: model.") + fn + " returned " + std::to_string(p[i]) +
                                          " at n_dot_v=" + std::to_string(pnv[i]) + ", n_dot_l=" + std::to_string(pl[i]) +
                                          ", n_dot_h=" + std::to_string(ph[i]) + ", roughness=" + std::to_string(pr[i]) +
                                          " (must be finite)");
            }
        };
        values out;
        if (has_sample_weight) {
            out.s = model_result(obj.attr("sample_weight")(nv, nl, nh, vh, rough), "sample_weight", n);
            const double* ps = out.s.data();
            double probe = 0.0;
            {
                py::gil_scoped_release release;
                for (std::size_t i = 0; i < n; ++i) probe += ps[i] - ps[i];
            }
            if (!(probe == 0.0)) fail(ps, "sample_weight", false);
            return out;
        }
        out.d = model_result(obj.attr("ndf")(nh, alpha), "ndf", n);
        out.v = model_result(obj.attr("visibility")(nv, nl, rough), "visibility", n);
        const double *pd = out.d.data(), *pv = out.v.data();
        double probe = 0.0;
        {
            py::gil_scoped_release release;
            for (std::size_t i = 0; i < n; ++i)
                probe += pl[i] > 0.0 && ph[i] > 0.0 ? (pd[i] - pd[i]) + (pv[i] - pv[i]) : 0.0;
        }
        if (!(probe == 0.0)) {
            fail(pd, "ndf", true);
            fail(pv, "visibility", true);
        }
        return out;
    }
};

/// The node arrays of the batches of one call: storage for the largest batch, allocated once, and
/// per batch views of its first n nodes (fresh arrays per batch would be fresh pages per batch).
/// A store is replaced by a new one when anything besides these views still references it (a
/// model that kept an input array keeps what it was given).
struct batch_nodes {
    static constexpr int arrays = 6;
    std::size_t n = 0;
    py::array_t<double> store[arrays];
    py::array_t<double> view[arrays]; // nv, nl, nh, vh, rough, alpha
    double* data[arrays] = {};
    bool used = false;
    explicit batch_nodes(std::size_t capacity) {
        for (auto& a : store) a = py::array_t<double>(py::ssize_t(capacity));
    }
    void use(std::size_t count) {
        n = count;
        for (int k = 0; k < arrays; ++k) {
            // our references: store[k] itself and the view's base (while the view lives)
            if (used && (view[k].ref_count() > 1 || store[k].ref_count() > 2)) store[k] = py::array_t<double>(store[k].size());
            data[k] = store[k].mutable_data();
            view[k] = py::array_t<double>({py::ssize_t(count)}, {py::ssize_t(sizeof(double))}, data[k], store[k]);
        }
        used = true;
    }
};

// ---- built-in models -----------------------------------------------------------------------------

enum class builtin { ggx_height_correlated, ggx_schlick_ibl, blinn_phong };

const char* builtin_names = "'ggx_height_correlated', 'ggx_schlick_ibl' (alias 'ggx_separable'), 'blinn_phong'";

bool parse_builtin(const std::string& s, builtin& b) {
    if (s == "ggx_height_correlated" || s == "ggx") b = builtin::ggx_height_correlated;
    else if (s == "ggx_schlick_ibl" || s == "ggx_separable" || s == "schlick_ibl") b = builtin::ggx_schlick_ibl;
    else if (s == "blinn_phong") b = builtin::blinn_phong;
    else return false;
    return true;
}

template <class F> decltype(auto) with_builtin(builtin b, F&& f) {
    switch (b) {
    case builtin::ggx_schlick_ibl: return f(ibl::ggx_schlick_ibl{});
    case builtin::blinn_phong: return f(blinn_phong_model{});
    default: return f(ibl::ggx_height_correlated{});
    }
}

/// The model argument: a built-in name or a Python object.
struct model_arg {
    bool is_builtin = true;
    builtin b = builtin::ggx_height_correlated;
    py::object obj;
};
model_arg parse_model(const char* fn, py::object model) {
    model_arg m;
    if (py::isinstance<py::str>(model)) {
        if (!parse_builtin(model.cast<std::string>(), m.b))
            throw py::value_error(std::string("ibl.") + fn + ": unknown model '" + model.cast<std::string>() +
                                  "'; built-in models: " + builtin_names + ", or a Python model object");
        return m;
    }
    m.is_builtin = false;
    m.obj = model;
    return m;
}

// ---- ibl.dfg ---------------------------------------------------------------------------------------

/// E = A + B and B of n points for a Python model: the default rule of dfg_exact, the kernel run
/// as the file header describes, per batch of whole points. Output: eb[2 i] = E, eb[2 i + 1] = B.
std::vector<double> python_dfg_eb(const py::object& obj, const double* mu, const double* r, std::size_t n) {
    std::vector<double> eb(2 * n);
    const python_model pm(obj);
    const ibl::dfg_quadrature_rule& rule = ibl::default_dfg_quadrature_rule();
    const ibl::dfg_quadrature_view q = rule.view();
    const std::size_t evals = rule.nodes().evaluations();
    const std::size_t per_batch = std::max<std::size_t>(1, max_batch_nodes / evals);
    batch_nodes nodes(std::min(n, per_batch) * evals);
    for (std::size_t begin = 0; begin < n; begin += per_batch) {
        const std::size_t end = std::min(n, begin + per_batch), m = end - begin;
        const std::vector<double> alpha = pm.alpha(std::vector<double>(r + begin, r + end));
        nodes.use(m * evals);
        node_buffer buf{};
        {
            py::gil_scoped_release release;
            tls_guard g(&buf);
            buf.nv = nodes.data[0];
            buf.nl = nodes.data[1];
            buf.nh = nodes.data[2];
            buf.vh = nodes.data[3];
            buf.capacity = nodes.n;
            double* pr = nodes.data[4];
            double* pa = nodes.data[5];
            for (std::size_t i = 0; i < m; ++i) {
                buf.alpha = alpha[i];
                double e, bb;
                ibl::dfg_quadrature_lanes<recording_model, 1>(q, r[begin + i], &mu[begin + i], &e, &bb);
                std::fill(pr + i * evals, pr + (i + 1) * evals, r[begin + i]);
                std::fill(pa + i * evals, pa + (i + 1) * evals, alpha[i]);
            }
        }
        if (buf.cursor != nodes.n) throw std::logic_error("ibl.dfg: the quadrature's node count changed");
        const python_model::values vals = pm.evaluate(nodes.n, nodes.view[0], nodes.view[1], nodes.view[2], nodes.view[3], nodes.view[4], nodes.view[5]);
        py::gil_scoped_release release;
        node_buffer rep{};
        tls_guard g(&rep);
        rep.s = pm.has_sample_weight ? vals.s.data() : nullptr;
        rep.d = pm.has_sample_weight ? nullptr : vals.d.data();
        rep.v = pm.has_sample_weight ? nullptr : vals.v.data();
        rep.capacity = nodes.n;
        for (std::size_t i = 0; i < m; ++i) {
            rep.alpha = alpha[i];
            double e, bb;
            ibl::dfg_quadrature_lanes<replay_model, 1>(q, r[begin + i], &mu[begin + i], &e, &bb);
            eb[2 * (begin + i)] = e;
            eb[2 * (begin + i) + 1] = bb;
        }
    }
    return eb;
}


py::object dfg(py::object n_dot_v, py::object roughness, py::object model, unsigned threads) {
    const model_arg ma = parse_model("dfg", model);
    const bool f32 = all_float32({{n_dot_v, 1, "n_dot_v"}, {roughness, 1, "roughness"}});
    broadcast_args<double> b = broadcast<double>("dfg", {{n_dot_v, 1, "n_dot_v", true}, {roughness, 1, "roughness", true}});
    const std::size_t n = b.count;
    std::vector<double> ab(2 * n);
    const double* mu = b.data[0];
    const double* r = b.data[1];
    if (ma.is_builtin) {
        py::gil_scoped_release release;
        with_builtin(ma.b, [&](auto m) {
            using M = decltype(m);
            ibl::thread_executor{threads}(n, [&](std::size_t begin, std::size_t end) {
                for (std::size_t i = begin; i < end; ++i) {
                    const ibl::vec2<double> v = ibl::dfg_exact<M>(mu[i], r[i]);
                    ab[2 * i] = v.x;
                    ab[2 * i + 1] = v.y;
                }
            });
        });
    } else {
        const std::vector<double> eb = python_dfg_eb(ma.obj, mu, r, n);
        for (std::size_t i = 0; i < n; ++i) {
            ab[2 * i] = eb[2 * i] - eb[2 * i + 1];
            ab[2 * i + 1] = eb[2 * i + 1];
        }
    }
    auto emit = [&](auto tag) {
        using T = decltype(tag);
        py::array_t<T> out = make_output<T>(b.shape, 2);
        for (std::size_t i = 0; i < 2 * n; ++i) out.mutable_data()[i] = T(ab[i]);
        if (!ma.is_builtin) check_finite_result("dfg", out.data(), 2 * n, model_overflow);
        return out;
    };
    if (f32) return emit(float{});
    return emit(double{});
}

// ---- ibl.dfg_lut -----------------------------------------------------------------------------------

/// make_dfg_lut_exact's row loop for a Python model (same lanes, same nodes, weights in float).
ibl::dfg_lut python_dfg_lut(const python_model& pm, std::uint32_t size, const ibl::dfg_lut_layout& layout,
                            std::uint32_t channels) {
    const ibl::dfg_quadrature_nodes qn = ibl::dfg_lut_default_nodes;
    ibl::detail::check_dfg_lut_args("dfg_lut", size, channels, qn.evaluations(), "evaluations size^2 * nodes");
    constexpr std::size_t W = 16;
    ibl::dfg_lut lut{size, channels, {}, layout, "python"};
    lut.data.assign(std::size_t(size) * size * channels, 0.0f);
    const ibl::dfg_quadrature_rule rule(qn);
    const ibl::dfg_quadrature_view q = rule.view();
    const std::size_t row_nodes = std::size_t(size) * qn.evaluations();
    const std::size_t rows_per_batch = std::max<std::size_t>(1, max_batch_nodes / row_nodes);
    batch_nodes nodes(std::min<std::size_t>(size, rows_per_batch) * row_nodes);
    // The kernel calls of one row, in make_dfg_lut_exact's order: W-lane groups, then single texels.
    auto row_calls = [&](std::uint32_t j, auto model_tag) {
        using M = decltype(model_tag);
        const double r = lut.roughness(j);
        std::uint32_t i = 0;
        for (; i + W <= size; i += W) {
            double mu[W], e[W], b[W];
            for (std::size_t l = 0; l < W; ++l) mu[l] = lut.n_dot_v(i + std::uint32_t(l));
            ibl::dfg_quadrature_lanes<M, W, float>(q, r, mu, e, b);
            if constexpr (std::is_same_v<M, replay_model>)
                for (std::size_t l = 0; l < W; ++l) ibl::detail::dfg_store<double>(lut, i + std::uint32_t(l), j, e[l], b[l]);
        }
        for (; i < size; ++i) {
            const double mu = lut.n_dot_v(i);
            double e, b;
            ibl::dfg_quadrature_lanes<M, 1, float>(q, r, &mu, &e, &b);
            if constexpr (std::is_same_v<M, replay_model>) ibl::detail::dfg_store<double>(lut, i, j, e, b);
        }
    };
    for (std::uint32_t j0 = 0; j0 < size; j0 += std::uint32_t(rows_per_batch)) {
        const std::uint32_t j1 = std::min<std::uint32_t>(size, j0 + std::uint32_t(rows_per_batch));
        std::vector<std::uint32_t> rows; // the integrated rows (r > 0; a mirror row is the closed form)
        std::vector<double> rs;
        for (std::uint32_t j = j0; j < j1; ++j) {
            const double r = lut.roughness(j);
            if (r <= 0.0) {
                for (std::uint32_t i = 0; i < size; ++i)
                    ibl::detail::dfg_store<double>(lut, i, j, 1.0, ibl::pow5(1.0 - lut.n_dot_v(i)));
                continue;
            }
            rows.push_back(j);
            rs.push_back(r);
        }
        if (rows.empty()) continue;
        const std::vector<double> alpha = pm.alpha(rs);
        nodes.use(rows.size() * row_nodes);
        node_buffer buf{};
        {
            py::gil_scoped_release release;
            tls_guard g(&buf);
            buf.nv = nodes.data[0];
            buf.nl = nodes.data[1];
            buf.nh = nodes.data[2];
            buf.vh = nodes.data[3];
            buf.capacity = nodes.n;
            double* pr = nodes.data[4];
            double* pa = nodes.data[5];
            for (std::size_t k = 0; k < rows.size(); ++k) {
                buf.alpha = alpha[k];
                row_calls(rows[k], recording_model{});
                std::fill(pr + k * row_nodes, pr + (k + 1) * row_nodes, rs[k]);
                std::fill(pa + k * row_nodes, pa + (k + 1) * row_nodes, alpha[k]);
            }
        }
        if (buf.cursor != nodes.n) throw std::logic_error("ibl.dfg_lut: the quadrature's node count changed");
        const python_model::values vals = pm.evaluate(nodes.n, nodes.view[0], nodes.view[1], nodes.view[2], nodes.view[3], nodes.view[4], nodes.view[5]);
        py::gil_scoped_release release;
        node_buffer rep{};
        tls_guard g(&rep);
        rep.s = pm.has_sample_weight ? vals.s.data() : nullptr;
        rep.d = pm.has_sample_weight ? nullptr : vals.d.data();
        rep.v = pm.has_sample_weight ? nullptr : vals.v.data();
        rep.capacity = nodes.n;
        for (std::size_t k = 0; k < rows.size(); ++k) {
            rep.alpha = alpha[k];
            row_calls(rows[k], replay_model{});
        }
    }
    return lut;
}

py::array_t<float> dfg_lut(long long size, py::object model, const std::string& layout_name, bool multiscatter,
                           unsigned threads) {
    if (size < 1 || size > (long long)ibl::limits::max_dfg_lut_size)
        throw py::value_error("ibl.dfg_lut: size must lie in [1, " + std::to_string(ibl::limits::max_dfg_lut_size) +
                              "], got " + std::to_string(size));
    ibl::dfg_lut_layout layout;
    if (layout_name == "uniform") layout = ibl::dfg_lut_layout::uniform();
    else if (layout_name == "remapped") layout = ibl::dfg_lut_layout::remapped();
    else throw py::value_error("ibl.dfg_lut: layout must be 'uniform' or 'remapped', got '" + layout_name + "'");
    const model_arg ma = parse_model("dfg_lut", model);
    const std::uint32_t channels = multiscatter ? 3u : 2u;
    ibl::dfg_lut lut;
    if (ma.is_builtin) {
        py::gil_scoped_release release;
        lut = with_builtin(ma.b, [&](auto m) {
            return ibl::make_dfg_lut_exact<decltype(m)>(std::uint32_t(size), layout, channels, ibl::dfg_lut_default_nodes,
                                                        ibl::thread_executor{threads});
        });
    } else {
        lut = python_dfg_lut(python_model(ma.obj), std::uint32_t(size), layout, channels);
        check_finite_result("dfg_lut", lut.data.data(), lut.data.size(), model_overflow);
    }
    py::array_t<float> out({py::ssize_t(size), py::ssize_t(size), py::ssize_t(channels)});
    std::copy(lut.data.begin(), lut.data.end(), out.mutable_data());
    return out;
}

// ---- Monte Carlo DFG and the multiscatter energy terms (built-in models) ----------------------------


/// dfg_mc / dfg_mc_vndf of a Python model in T (the built-in path's precision): both estimators call
/// Model::sample_weight once per draw, in draw order, whatever the values; so the record / replay
/// passes of the file header apply, per batch of whole points (samples nodes each).
template <class T>
std::vector<T> python_dfg_mc(const py::object& obj, const double* mu, const double* r, std::size_t count, std::uint32_t samples,
                             bool vndf) {
    std::vector<T> ab(2 * count);
    const python_model pm(obj);
    const std::size_t evals = samples;
    const std::size_t per_batch = std::max<std::size_t>(1, max_batch_nodes / evals);
    batch_nodes nodes(std::min(count, per_batch) * evals);
    auto run = [&](auto model_tag, std::size_t i) {
        using M = decltype(model_tag);
        return vndf ? ibl::dfg_mc_vndf<M>(T(mu[i]), T(r[i]), samples) : ibl::dfg_mc<M>(T(mu[i]), T(r[i]), samples);
    };
    for (std::size_t begin = 0; begin < count; begin += per_batch) {
        const std::size_t end = std::min(count, begin + per_batch), m = end - begin;
        std::vector<double> rb(m);
        for (std::size_t i = 0; i < m; ++i) rb[i] = double(T(r[begin + i])); // the roughness the estimator sees
        const std::vector<double> alpha = pm.alpha(rb);
        nodes.use(m * evals);
        node_buffer buf{};
        {
            py::gil_scoped_release release;
            tls_guard g(&buf);
            buf.nv = nodes.data[0];
            buf.nl = nodes.data[1];
            buf.nh = nodes.data[2];
            buf.vh = nodes.data[3];
            buf.capacity = nodes.n;
            for (std::size_t i = 0; i < m; ++i) {
                buf.alpha = alpha[i];
                run(recording_model{}, begin + i);
                if (buf.cursor != (i + 1) * evals) throw std::logic_error("ibl.dfg_mc: the estimator's call count changed");
                std::fill(nodes.data[4] + i * evals, nodes.data[4] + (i + 1) * evals, rb[i]);
                std::fill(nodes.data[5] + i * evals, nodes.data[5] + (i + 1) * evals, alpha[i]);
            }
        }
        if (buf.cursor != nodes.n) throw std::logic_error("ibl.dfg_mc: the estimator's call count changed");
        const python_model::values vals =
            pm.evaluate(nodes.n, nodes.view[0], nodes.view[1], nodes.view[2], nodes.view[3], nodes.view[4], nodes.view[5]);
        py::gil_scoped_release release;
        node_buffer rep{};
        tls_guard g(&rep);
        rep.s = pm.has_sample_weight ? vals.s.data() : nullptr;
        rep.d = pm.has_sample_weight ? nullptr : vals.d.data();
        rep.v = pm.has_sample_weight ? nullptr : vals.v.data();
        rep.capacity = nodes.n;
        for (std::size_t i = 0; i < m; ++i) {
            rep.alpha = alpha[i];
            rep.cursor = i * evals;
            const ibl::vec2<T> v = run(replay_model{}, begin + i);
            ab[2 * (begin + i)] = v.x;
            ab[2 * (begin + i) + 1] = v.y;
        }
    }
    return ab;
}

py::object dfg_mc(py::object n_dot_v, py::object roughness, long long samples, py::object model, const std::string& sampling) {
    const model_arg ma = parse_model("dfg_mc", model);
    if (samples < 1 || samples > (long long)ibl::limits::max_samples)
        throw py::value_error("ibl.dfg_mc: samples must lie in [1, " + std::to_string(ibl::limits::max_samples) + "], got " +
                              std::to_string(samples));
    bool vndf;
    if (sampling == "ndf") vndf = false;
    else if (sampling == "vndf") vndf = true;
    else throw py::value_error("ibl.dfg_mc: sampling must be 'ndf' or 'vndf', got '" + sampling + "'");
    const auto n = std::uint32_t(samples);
    if (!ma.is_builtin) {
        const bool f32 = all_float32({{n_dot_v, 1, "n_dot_v"}, {roughness, 1, "roughness"}});
        broadcast_args<double> b = broadcast<double>("dfg_mc", {{n_dot_v, 1, "n_dot_v", true}, {roughness, 1, "roughness", true}});
        auto emit = [&](auto tag) -> py::object {
            using T = decltype(tag);
            const std::vector<T> ab = python_dfg_mc<T>(ma.obj, b.data[0], b.data[1], b.count, n, vndf);
            py::array_t<T> out = make_output<T>(b.shape, 2);
            std::copy(ab.begin(), ab.end(), out.mutable_data());
            check_finite_result("dfg_mc", out.data(), ab.size(), model_overflow);
            return out;
        };
        return f32 ? emit(float{}) : emit(double{});
    }
    const builtin b = ma.b;
    return map("dfg_mc", {{n_dot_v, 1, "n_dot_v", true}, {roughness, 1, "roughness", true}}, 2, [&](auto tag) {
        using T = decltype(tag);
        return [b, n, vndf](const T* const* in, T* out) {
            const ibl::vec2<T> v = with_builtin(b, [&](auto m) {
                using M = decltype(m);
                return vndf ? ibl::dfg_mc_vndf<M>(in[0][0], in[1][0], n) : ibl::dfg_mc<M>(in[0][0], in[1][0], n);
            });
            out[0] = v.x;
            out[1] = v.y;
        };
    });
}

py::object dfg_albedo(py::object n_dot_v, py::object roughness, py::object model) {
    const model_arg ma = parse_model("dfg_albedo", model);
    if (!ma.is_builtin) { // E of the kernel, as ibl::dfg_albedo takes it (dfg_exact_abe's e)
        const bool f32 = all_float32({{n_dot_v, 1, "n_dot_v"}, {roughness, 1, "roughness"}});
        broadcast_args<double> b = broadcast<double>("dfg_albedo", {{n_dot_v, 1, "n_dot_v", true}, {roughness, 1, "roughness", true}});
        const std::vector<double> eb = python_dfg_eb(ma.obj, b.data[0], b.data[1], b.count);
        for (std::size_t i = 0; i < b.count; ++i) {
            const double e = f32 ? double(float(eb[2 * i])) : eb[2 * i];
            check_finite_result("dfg_albedo", &e, 1, model_overflow);
        }
        if (b.scalar) return py::float_(f32 ? double(float(eb[0])) : eb[0]);
        auto emit = [&](auto tag) -> py::object {
            using T = decltype(tag);
            py::array_t<T> out = make_output<T>(b.shape, 1);
            for (std::size_t i = 0; i < b.count; ++i) out.mutable_data()[i] = T(eb[2 * i]);
            return out;
        };
        return f32 ? emit(float{}) : emit(double{});
    }
    const builtin b = ma.b;
    return map("dfg_albedo", {{n_dot_v, 1, "n_dot_v", true}, {roughness, 1, "roughness", true}}, 1, [&](auto tag) {
        using T = decltype(tag);
        return [b](const T* const* in, T* out) {
            *out = with_builtin(b, [&](auto m) { return ibl::dfg_albedo<decltype(m)>(in[0][0], in[1][0]); });
        };
    });
}

} // namespace

void bind_dfg(py::module_& m) {
    m.def("dfg", &dfg, py::arg("n_dot_v"), py::arg("roughness"), py::arg("model") = "ggx_height_correlated",
          py::kw_only(), py::arg("threads") = 0u,
          "Split-sum DFG terms (A, B) by the library's deterministic quadrature (ibl::dfg_exact, default\n"
          "nodes, converged to 1e-6): array (..., 2) over the broadcast shape of n_dot_v and roughness\n"
          "(both in [0, 1]). model: a built-in name ('ggx_height_correlated', 'ggx_schlick_ibl' alias\n"
          "'ggx_separable', 'blinn_phong') or a Python model object with alpha(roughness),\n"
          "ndf(n_dot_h, alpha), visibility(n_dot_v, n_dot_l, roughness) [or sample_weight(n_dot_v,\n"
          "n_dot_l, n_dot_h, v_dot_h, roughness) instead of ndf and visibility], each called once per\n"
          "batch of quadrature nodes with float64 arrays. threads: C++ models only (0 = all cores).");
    m.def("dfg_lut", &dfg_lut, py::arg("size"), py::arg("model") = "ggx_height_correlated", py::kw_only(),
          py::arg("layout") = "uniform", py::arg("multiscatter") = false, py::arg("threads") = 0u,
          "The exact DFG table of ibl::make_dfg_lut_exact (nodes dfg_lut_default_nodes, weights in float):\n"
          "float32 array (size, size, channels), [j, i] = texel (i, j): row j one roughness, column i one\n"
          "n.v. layout 'uniform' (texel centres (i + 0.5) / size) or 'remapped' (cbrt(n.v) x sqrt(r), edge\n"
          "aligned). channels 2 (A, B), or 3 with multiscatter=True (k = (1 - E) / E).\n"
          "model: as ibl.dfg (a Python model is evaluated once per batch of rows).");
    m.def(
        "dfg_smooth_limit",
        [](py::object n_dot_v) {
            return map("dfg_smooth_limit", {{n_dot_v, 1, "n_dot_v"}}, 2, [](auto tag) {
                using T = decltype(tag);
                return [](const T* const* in, T* out) {
                    const ibl::vec2<T> v = ibl::dfg_smooth_limit(*in[0]);
                    out[0] = v.x;
                    out[1] = v.y;
                };
            });
        },
        py::arg("n_dot_v"), "The r = 0 (mirror) limit of (A, B): (1 - (1 - n.v)^5, (1 - n.v)^5), shape (..., 2).");
    m.def(
        "dfg_lut_coords",
        [](long long size, const std::string& layout_name) {
            if (size < 1 || size > (long long)ibl::limits::max_dfg_lut_size)
                throw py::value_error("ibl.dfg_lut_coords: bad size " + std::to_string(size));
            ibl::dfg_lut lut{std::uint32_t(size), 2, {}, ibl::dfg_lut_layout::uniform(), ""};
            if (layout_name == "remapped") lut.layout = ibl::dfg_lut_layout::remapped();
            else if (layout_name != "uniform")
                throw py::value_error("ibl.dfg_lut_coords: layout must be 'uniform' or 'remapped', got '" + layout_name + "'");
            py::array_t<double> nv(static_cast<py::ssize_t>(size)), r(static_cast<py::ssize_t>(size));
            for (std::uint32_t i = 0; i < std::uint32_t(size); ++i) {
                nv.mutable_data()[i] = lut.n_dot_v(i);
                r.mutable_data()[i] = lut.roughness(i);
            }
            return py::make_tuple(nv, r);
        },
        py::arg("size"), py::arg("layout") = "uniform",
        "(n_dot_v, roughness): the texel values of a table's columns and rows in a layout.");
    m.def("dfg_mc", &dfg_mc, py::arg("n_dot_v"), py::arg("roughness"), py::arg("samples") = 1024,
          py::arg("model") = "ggx_height_correlated", py::kw_only(), py::arg("sampling") = "ndf",
          "Split-sum DFG terms (A, B) by Monte Carlo with `samples` Hammersley points: array (..., 2) over the\n"
          "broadcast shape of n_dot_v and roughness (in [0, 1]). sampling 'ndf': GGX NDF importance sampling\n"
          "(ibl::dfg_mc, the estimator of Karis 2013); 'vndf': visible normals (ibl::dfg_mc_vndf, Heitz /\n"
          "Dupuy). Samples below the horizon count as zeros. model: as ibl.dfg.");
    m.def("dfg_albedo", &dfg_albedo, py::arg("n_dot_v"), py::arg("roughness"), py::arg("model") = "ggx_height_correlated",
          "The directional albedo E = A + B by the deterministic quadrature (ibl::dfg_albedo,\n"
          "bake/dfg_multiscatter.hpp): the single-scattering energy; 1 - E is what multiple scattering\n"
          "restores. model: as ibl.dfg (a built-in name or a Python model object).");
    m.def(
        "dfg_energy_compensation",
        [](py::object albedo) {
            return map("dfg_energy_compensation", {{albedo, 1, "albedo", true}}, 1, [](auto tag) {
                using T = decltype(tag);
                return [](const T* const* in, T* out) { *out = ibl::dfg_energy_compensation(in[0][0]); };
            });
        },
        py::arg("albedo"),
        "Turquin's energy compensation k = (1 - E) / E of an albedo E in [0, 1] (E floored at the smallest\n"
        "normal float): the third channel of dfg_lut(multiscatter=True).");
    
    m.attr("model_batch_nodes") = py::int_(max_batch_nodes);
    m.attr("builtin_models") = py::make_tuple("ggx_height_correlated", "ggx_schlick_ibl", "blinn_phong");
}

} // namespace ibl_py
