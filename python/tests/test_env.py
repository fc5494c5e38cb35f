# Prefilter, irradiance, SH and the reference LD: white furnace, symmetry, closed forms.
import numpy as np
import pytest

import ibl


def test_white_furnace_prefilter_and_irradiance():
    cube = np.full((6, 16, 16, 3), 0.75, np.float32)
    levels = ibl.prefilter(cube, samples=64, threads=1)
    assert [l.shape for l in levels] == [(6, 16 >> k, 16 >> k, 3) for k in range(len(levels))]
    for l in levels:
        assert l.dtype == np.float32
        np.testing.assert_allclose(l, 0.75, rtol=1e-5)
    for method in ("fast", "importance"):
        for l in ibl.prefilter(cube, levels=3, samples=32, method=method, weight="g1"):
            np.testing.assert_allclose(l, 0.75, rtol=1e-5)
    e = ibl.irradiance(cube, 8, samples=256)
    assert e.shape == (6, 8, 8, 3)
    np.testing.assert_allclose(e, 0.75 * np.pi, rtol=1e-5)


def test_prefilter_symmetry():
    # light only on face +Y: the environment is symmetric under x -> -x, which maps face +X onto -X
    # with columns reversed (and +Z, -Z onto themselves, columns reversed). The chain is symmetric up
    # to the sample pattern (Hammersley points in each texel's frame are not mirror symmetric).
    cube = np.zeros((6, 16, 16, 3), np.float32)
    cube[2] = 1.0
    levels = ibl.prefilter(cube, levels=4, samples=256)
    for l in levels[1:]:
        np.testing.assert_allclose(l[0], l[1][:, ::-1], atol=2e-2)
        np.testing.assert_allclose(l[4], l[4][:, ::-1], atol=2e-2)
        assert abs(l[0].mean() - l[1].mean()) < 2e-3
    assert levels[-1][3].max() < levels[-1][2].min()  # -Y sees less than +Y


def test_sh_project_evaluate_and_lambert():
    cube = np.full((6, 8, 8, 3), 2.0, np.float32)
    c = ibl.sh_project(cube, 3)
    assert c.shape == (9, 3)
    np.testing.assert_allclose(c[0], 2.0 * np.sqrt(4 * np.pi), rtol=1e-6)
    np.testing.assert_allclose(c[1:], 0.0, atol=1e-6)
    dirs = np.random.default_rng(1).normal(size=(5, 7, 3))
    dirs /= np.linalg.norm(dirs, axis=-1, keepdims=True)
    np.testing.assert_allclose(ibl.sh_evaluate(c, dirs), 2.0, rtol=1e-6)
    e = ibl.sh_irradiance(c)
    factors = np.array([np.pi] + [2 * np.pi / 3] * 3 + [np.pi / 4] * 5)
    np.testing.assert_allclose(e, c * factors[:, None], rtol=1e-14)
    np.testing.assert_allclose(ibl.sh_evaluate(e, dirs), 2.0 * np.pi, rtol=1e-6)
    # a linear radiance L = d.z (+Z face bright...) is band 1: projection and evaluation recover it
    for bands in range(1, 6):
        assert ibl.sh_project(cube, bands).shape == (bands * bands, 3)


def test_reference_ld_constant_and_bad_cubes():
    cube = np.full((6, 8, 8, 3), 0.5, np.float32)
    ld = ibl.reference_ld(cube, np.array([[0, 0, 1.0], [1.0, 1.0, 0]]), np.array([0.2, 0.9]), 256)
    assert ld.shape == (2, 3)
    np.testing.assert_allclose(ld, 0.5, rtol=1e-6)
    with pytest.raises(ValueError, match="shape"):
        ibl.prefilter(np.zeros((5, 8, 8, 3), np.float32))
    with pytest.raises(ValueError, match="shape"):
        ibl.irradiance(np.zeros((6, 8, 4, 3), np.float32))
    bad = cube.copy()
    bad[0, 0, 0, 0] = np.nan
    with pytest.raises(ValueError, match="non-finite"):
        ibl.sh_project(bad)
    with pytest.raises(ValueError, match="bands"):
        ibl.sh_project(cube, 6)
    with pytest.raises(ValueError, match="coeffs"):
        ibl.sh_evaluate(np.zeros((5, 3)), [0, 0, 1.0])
    with pytest.raises(ValueError, match="method"):
        ibl.prefilter(cube, method="magic")
    with pytest.raises(ValueError, match="roughness"):
        ibl.reference_ld(cube, [0, 0, 1.0], 2.0)
