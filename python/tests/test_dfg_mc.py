# Monte Carlo DFG (NDF and VNDF sampling), the directional albedo and Turquin's compensation:
# against the deterministic quadrature, a NumPy hemisphere quadrature of the albedo (the models of
# conftest.py) and closed forms.
import numpy as np
import pytest

import ibl
from conftest import BlinnPhong, GGXHeightCorrelated, GGXSchlickIBL, ndf_ggx, v_ggx_correlated


def albedo_numpy(mu, r, n=600):
    """E(mu, r) = int D(h) V(v, l) n.l dl of ggx_height_correlated by a midpoint rule in (cos theta_l, phi)."""
    alpha = r * r
    c = (np.arange(n) + 0.5) / n
    phi = (np.arange(2 * n) + 0.5) / (2 * n) * 2 * np.pi
    c, phi = np.meshgrid(c, phi)
    s = np.sqrt(1 - c * c)
    l = np.stack([s * np.cos(phi), s * np.sin(phi), c], -1)
    v = np.array([np.sqrt(1 - mu * mu), 0.0, mu])
    h = l + v
    h /= np.linalg.norm(h, axis=-1, keepdims=True)
    f = ndf_ggx(h[..., 2], alpha) * v_ggx_correlated(mu, c, alpha) * c
    return f.sum() * (1.0 / n) * (2 * np.pi / (2 * n))


@pytest.mark.parametrize("sampling", ["ndf", "vndf"])
def test_dfg_mc_converges_to_the_quadrature(sampling):
    nv, r = np.meshgrid(np.linspace(0.1, 1, 5), np.linspace(0.2, 1, 5))
    for model in ("ggx_height_correlated", "ggx_schlick_ibl"):
        mc = ibl.dfg_mc(nv, r, 4096, model, sampling=sampling)
        assert mc.shape == (5, 5, 2) and mc.dtype == np.float64
        np.testing.assert_allclose(mc, ibl.dfg(nv, r, model), atol=6e-3)
    f32 = ibl.dfg_mc(np.float32(0.5), np.float32(0.5), 256, sampling=sampling)
    assert f32.dtype == np.float32 and f32.shape == (2,)


def test_dfg_mc_vndf_has_less_variance_at_grazing():
    # VNDF sampling never wastes samples under the horizon: at n.v = 0.1, 64 samples are closer
    rng_nv, r = 0.1, np.linspace(0.3, 1, 8)
    exact = ibl.dfg(rng_nv, r)
    err_ndf = np.abs(ibl.dfg_mc(rng_nv, r, 64, sampling="ndf") - exact).sum(-1).mean()
    err_vndf = np.abs(ibl.dfg_mc(rng_nv, r, 64, sampling="vndf") - exact).sum(-1).mean()
    assert err_vndf < err_ndf


def test_dfg_albedo_and_energy_compensation():
    for mu, r in ((0.5, 0.5), (0.9, 0.8), (0.3, 1.0)):
        assert ibl.dfg_albedo(mu, r) == pytest.approx(albedo_numpy(mu, r), abs=2e-3)
    nv, r = np.meshgrid(np.linspace(0, 1, 6), np.linspace(0, 1, 6))
    e = ibl.dfg_albedo(nv, r, "ggx_schlick_ibl")
    np.testing.assert_allclose(e, ibl.dfg(nv, r, "ggx_schlick_ibl").sum(-1), rtol=1e-6)
    assert ((e > 0.25) & (e <= 1 + 1e-12)).all()
    np.testing.assert_allclose(ibl.dfg_energy_compensation(e), (1 - e) / e, rtol=1e-12)
    assert ibl.dfg_energy_compensation(1.0) == 0.0
    assert np.isfinite(ibl.dfg_energy_compensation(0.0))
    lut = ibl.dfg_lut(8, multiscatter=True, threads=1)
    np.testing.assert_allclose(lut[..., 2], ibl.dfg_energy_compensation(lut[..., 0] + lut[..., 1]), rtol=1e-4, atol=1e-6)


def test_dfg_mc_of_python_models():
    nv, r = np.meshgrid(np.linspace(0, 1, 9), np.linspace(0, 1, 9))
    for name, model in (("ggx_height_correlated", GGXHeightCorrelated()), ("ggx_schlick_ibl", GGXSchlickIBL()),
                        ("blinn_phong", BlinnPhong())):
        for sampling in ("ndf", "vndf"):
            # the same draws in the same estimator: equal up to the NumPy model's rounding (measured <= 2.2e-16)
            cpp = ibl.dfg_mc(nv, r, 256, name, sampling=sampling)
            np.testing.assert_allclose(ibl.dfg_mc(nv, r, 256, model, sampling=sampling), cpp, rtol=0, atol=1e-14)
            # float32 inputs: the float estimator, the Python weight rounded to float (measured 1 ulp)
            f = ibl.dfg_mc(nv.astype(np.float32), r.astype(np.float32), 256, model, sampling=sampling)
            assert f.dtype == np.float32
            np.testing.assert_allclose(f, ibl.dfg_mc(nv.astype(np.float32), r.astype(np.float32), 256, name,
                                                     sampling=sampling), rtol=0, atol=1e-6)


def test_dfg_albedo_of_python_models():
    nv, r = np.meshgrid(np.linspace(0, 1, 7), np.linspace(0, 1, 7))
    for name, model in (("ggx_height_correlated", GGXHeightCorrelated()), ("ggx_schlick_ibl", GGXSchlickIBL()),
                        ("blinn_phong", BlinnPhong())):
        # the same kernel sums (E is the kernel's own accumulator): equal to the C++ model's E up to
        # the NumPy model's rounding (measured <= 2.2e-16)
        np.testing.assert_allclose(ibl.dfg_albedo(nv, r, model), ibl.dfg_albedo(nv, r, name), rtol=0, atol=1e-14)
    assert isinstance(ibl.dfg_albedo(0.5, 0.5, GGXHeightCorrelated()), float)
    e32 = ibl.dfg_albedo(np.float32([0.5, 0.7]), np.float32(0.4), GGXHeightCorrelated())
    assert e32.dtype == np.float32 and e32.shape == (2,)
    with pytest.raises(ValueError, match="roughness"):
        ibl.dfg_albedo(0.5, 1.5, GGXHeightCorrelated())


def test_dfg_mc_bad_input(ggx_model):
    with pytest.raises(ValueError, match="samples"):
        ibl.dfg_mc(0.5, 0.5, 0)
    with pytest.raises(ValueError, match="sampling"):
        ibl.dfg_mc(0.5, 0.5, 16, sampling="magic")
    with pytest.raises(ValueError, match="roughness"):
        ibl.dfg_mc(0.5, 1.5, 16)
    with pytest.raises(ValueError, match="unknown model"):
        ibl.dfg_mc(0.5, 0.5, 16, "magic")
    with pytest.raises(ValueError, match="albedo"):
        ibl.dfg_energy_compensation(1.5)
