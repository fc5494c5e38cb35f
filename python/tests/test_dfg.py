# DFG: built-in models against limits and each other; Python models against the built-in C++ ones.
import time

import numpy as np
import pytest

import ibl
from conftest import BlinnPhong, GGXHeightCorrelated, GGXSchlickIBL, v_ggx_correlated


def test_shapes_and_smooth_limit():
    assert ibl.dfg(0.5, 0.5).shape == (2,)
    nv = np.linspace(0.0, 1.0, 11)
    assert ibl.dfg(nv[:, None], np.array([0.2, 0.4])).shape == (11, 2, 2)
    assert ibl.dfg(np.float32(0.5), np.float32(0.5)).dtype == np.float32
    # r = 0 is the mirror: A = 1 - (1 - mu)^5, B = (1 - mu)^5 (the quadrature reaches it by itself)
    np.testing.assert_allclose(ibl.dfg(nv, 0.0), ibl.dfg_smooth_limit(nv), atol=1e-6)
    np.testing.assert_allclose(ibl.dfg_smooth_limit(nv), np.stack([1 - (1 - nv) ** 5, (1 - nv) ** 5], -1), atol=1e-15)
    # a near-mirror lobe is close to the limit
    np.testing.assert_allclose(ibl.dfg(nv[1:], 0.02), ibl.dfg_smooth_limit(nv[1:]), atol=2e-3)


def test_energy_bounds():
    nv, r = np.meshgrid(np.linspace(0.02, 1, 12), np.linspace(0.0, 1, 12))
    for m in ("ggx_height_correlated", "ggx_schlick_ibl"):  # blinn_phong's GGX masking is not its own
        e = ibl.dfg(nv, r, m).sum(-1)
        assert (e <= 1 + 1e-6).all(), m
        assert (e > 0.3).all(), m
    # white furnace at n.v = 1, r -> 0: A + B -> 1
    assert abs(ibl.dfg(1.0, 1e-3).sum() - 1.0) < 1e-6


def test_lut_equals_pointwise_dfg():
    size = 16
    for layout in ("uniform", "remapped"):
        lut = ibl.dfg_lut(size, layout=layout, multiscatter=True)
        assert lut.shape == (size, size, 3) and lut.dtype == np.float32
        nv, r = ibl.dfg_lut_coords(size, layout)
        ref = ibl.dfg(nv[None, :], r[:, None])  # [j, i]
        # the table's nodes (dfg_lut_default_nodes, weights in float) against the converged double rule
        np.testing.assert_allclose(lut[..., :2], ref, atol=1e-4)
        e = lut[..., 0].astype(np.float64) + lut[..., 1]
        np.testing.assert_allclose(lut[..., 2], (1 - e) / e, atol=1e-4)
    nv, r = ibl.dfg_lut_coords(size, "remapped")
    assert r[0] == 0.0 and nv[0] == 0.0
    np.testing.assert_allclose(ibl.dfg_lut(size, layout="remapped")[0], ibl.dfg_smooth_limit(nv), atol=1e-7)


@pytest.mark.parametrize("name,model", [("ggx_height_correlated", GGXHeightCorrelated()),
                                        ("ggx_schlick_ibl", GGXSchlickIBL()),
                                        ("blinn_phong", BlinnPhong())])
def test_python_model_equals_cpp_model(name, model):
    nv, r = np.meshgrid(np.linspace(0.0, 1.0, 9), np.linspace(0.0, 1.0, 9))
    cpp = ibl.dfg(nv, r, name)
    py = ibl.dfg(nv, r, model)
    diff = np.abs(cpp - py).max()
    print(f"{name}: dfg max |python - C++| = {diff:.3g}")
    assert diff < 1e-12
    lut_cpp = ibl.dfg_lut(32, name, layout="remapped", multiscatter=True)
    lut_py = ibl.dfg_lut(32, model, layout="remapped", multiscatter=True)
    diff = np.abs(lut_cpp.astype(np.float64) - lut_py).max()
    print(f"{name}: 32^2 table max |python - C++| = {diff:.3g}")
    assert diff < 1e-6


def test_python_sample_weight_model():
    class Weighted(GGXHeightCorrelated):
        calls = 0

        def sample_weight(self, n_dot_v, n_dot_l, n_dot_h, v_dot_h, r):
            Weighted.calls += 1
            v = self.visibility(n_dot_v, n_dot_l, r)
            ok = (n_dot_l > 0) & (n_dot_h > 0)
            return np.where(ok, 4 * (v * n_dot_l) * np.clip(v_dot_h, 0, 1) / np.where(ok, n_dot_h, 1), 0.0)

    nv = np.linspace(0.05, 1, 7)
    np.testing.assert_allclose(ibl.dfg(nv, 0.4, Weighted()), ibl.dfg(nv, 0.4), atol=1e-13)
    assert Weighted.calls == 1  # one batch, not one call per node


def test_python_model_called_once_per_batch():
    calls = {"alpha": [], "ndf": [], "visibility": []}  # the length of each call's arrays

    class Counting(GGXHeightCorrelated):
        def alpha(self, r):
            calls["alpha"].append(np.size(r))
            return super().alpha(r)

        def ndf(self, n_dot_h, a):
            calls["ndf"].append(n_dot_h.size)
            return super().ndf(n_dot_h, a)

        def visibility(self, n_dot_v, n_dot_l, r):
            calls["visibility"].append(n_dot_v.size)
            return v_ggx_correlated(n_dot_v, n_dot_l, np.clip(r, 0.0, 1.0) ** 2)

    ibl.dfg_lut(64, Counting())
    # whole table rows per batch, at most model_batch_nodes nodes: 64 x 432 nodes a row (the table
    # nodes, dfg_lut_default_nodes), so two rows a batch and 32 batches for the 64 rows
    row = 64 * 432
    per_batch = ibl.model_batch_nodes // row
    assert per_batch >= 1
    assert calls["ndf"] == calls["visibility"]
    assert sum(calls["ndf"]) == 64 * row
    assert all(n <= ibl.model_batch_nodes and n % row == 0 for n in calls["ndf"])
    assert len(calls["ndf"]) == -(-64 // per_batch) == len(calls["alpha"])
    assert calls["alpha"] == [n // row for n in calls["ndf"]]  # alpha once per batch, one value a row


def test_arrays_kept_by_a_model_stay_as_given():
    kept = []

    class Keeping(GGXHeightCorrelated):
        def ndf(self, n_dot_h, a):
            kept.append((n_dot_h, n_dot_h.copy(), a[::2], a[::2].copy()))  # the array and a NumPy view of one
            return super().ndf(n_dot_h, a)

    ref = ibl.dfg_lut(64)
    assert np.abs(ibl.dfg_lut(64, Keeping()).astype(np.float64) - ref).max() < 1e-6
    assert len(kept) > 2
    for arr, copy, view, view_copy in kept:  # later batches did not write into what an earlier one was given
        np.testing.assert_array_equal(arr, copy)
        np.testing.assert_array_equal(view, view_copy)


def test_cost_of_python_model():
    model = GGXHeightCorrelated()
    ibl.dfg_lut(64, model)  # warm up (first-touch of the node arrays)
    t0 = time.perf_counter()
    ibl.dfg_lut(64, threads=1)
    t1 = time.perf_counter()
    ibl.dfg_lut(64, model)
    t2 = time.perf_counter()
    ratio = (t2 - t1) / (t1 - t0)
    print(f"64^2 DFG table: C++ model {1e3 * (t1 - t0):.1f} ms (1 thread), Python model {1e3 * (t2 - t1):.1f} ms, "
          f"ratio {ratio:.1f}")
    assert ratio < 50  # generous: a loaded machine; the measured figure is in docs/python.md


def test_bad_models_and_inputs():
    with pytest.raises(ValueError, match="unknown model"):
        ibl.dfg(0.5, 0.5, "beckmann_nonexistent")

    class NoNdf:
        def alpha(self, r):
            return r * r

        def visibility(self, v, l, r):
            return v * 0 + 0.25

    with pytest.raises(TypeError, match="ndf"):
        ibl.dfg(0.5, 0.5, NoNdf())

    class WrongShape(GGXHeightCorrelated):
        def ndf(self, n_dot_h, a):
            return np.ones(3)

    with pytest.raises(ValueError, match="shape"):
        ibl.dfg(0.5, 0.5, WrongShape())

    class NaNV(GGXHeightCorrelated):
        def visibility(self, v, l, r):
            return np.full_like(v, np.nan)

    with pytest.raises(ValueError, match="visibility"):
        ibl.dfg_lut(8, NaNV())

    class BadAlpha(GGXHeightCorrelated):
        def alpha(self, r):
            return -r

    with pytest.raises(ValueError, match="alpha"):
        ibl.dfg(0.5, 0.5, BadAlpha())

    class Raises(GGXHeightCorrelated):
        def ndf(self, n_dot_h, a):
            raise RuntimeError("model bug")

    with pytest.raises(RuntimeError, match="model bug"):
        ibl.dfg(0.5, 0.5, Raises())
    with pytest.raises(ValueError, match="roughness"):
        ibl.dfg(0.5, np.nan)
    with pytest.raises(ValueError, match="roughness"):
        ibl.dfg(0.5, 1.5)
    with pytest.raises(ValueError, match="n_dot_v"):
        ibl.dfg(-0.1, 0.5)
    with pytest.raises(ValueError, match="layout"):
        ibl.dfg_lut(8, layout="log")
    with pytest.raises(ValueError, match="size"):
        ibl.dfg_lut(0)
