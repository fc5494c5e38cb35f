# The LD lobe of a Python BRDF model (python/tabulated_lobe.hpp) in ibl.prefilter and
# ibl.reference_ld: a NumPy GGX against the built-in GGX lobe, the white furnace, a Beckmann and a
# Blinn-Phong model against a closed form on a linear environment, bad models.
import numpy as np
import pytest

import ibl
from conftest import GGX_MIN_ALPHA, BlinnPhong, GGXHeightCorrelated
from test_io_lookup import cube_dirs


class Beckmann(GGXHeightCorrelated):
    """Beckmann D with alpha = r^2 (no C++ counterpart in the module)."""

    def ndf(self, n_dot_h, alpha):
        a2 = np.clip(alpha, GGX_MIN_ALPHA, 1.0) ** 2
        c2 = np.clip(n_dot_h, 0.0, 1.0) ** 2
        return np.where(n_dot_h > 0.0, np.exp(-(1.0 - c2) / (c2 * a2)) / (np.pi * a2 * c2 * c2), 0.0)


def make_cube(n=16, seed=3):
    rng = np.random.default_rng(seed)
    cube = (0.5 + rng.random((6, n, n, 3))).astype(np.float32)
    cube[4, 5:7, 5:7] = 50.0  # a small bright source: the sample directions matter
    return cube


def test_python_ggx_lobe_equals_the_builtin_lobe():
    cube = make_cube()
    model = GGXHeightCorrelated()
    for method in ("fis", "importance", "fast"):
        # the built-in fast filter's peak split is GGX-only: compared with it off
        cpp = ibl.prefilter(cube, method=method, samples=64, threads=1, peaks=0)
        py = ibl.prefilter(cube, method=method, samples=64, threads=1, model=model)
        assert len(py) == len(cpp) == 3
        # the tabulated GGX draws the same half vectors as sample_ggx_ndf up to double rounding;
        # stored in float they agree (measured: 0)
        rel = max(float(np.max(np.abs(a.astype(np.float64) - b) / a)) for a, b in zip(cpp, py))
        assert rel < 1e-5, (method, rel)
    rng = np.random.default_rng(1)
    dirs = rng.normal(size=(12, 3))
    r = rng.choice([0.1, 0.35, 0.8, 1.0], 12)
    cpp = ibl.reference_ld(cube, dirs, r, 1024)
    py = ibl.reference_ld(cube, dirs, r, 1024, model=model)
    assert np.max(np.abs(cpp - py) / cpp) < 1e-10  # measured 6e-14
    assert ibl.prefilter(cube, samples=16, model="ggx")[1].shape == (6, 8, 8, 3)


@pytest.mark.parametrize("model", [BlinnPhong(), Beckmann()])
def test_white_furnace(model):
    cube = np.full((6, 16, 16, 3), 0.75, np.float32)
    for method in ("fis", "fast"):
        for level in ibl.prefilter(cube, samples=32, method=method, model=model):
            np.testing.assert_allclose(level, 0.75, rtol=1e-6)
    np.testing.assert_allclose(ibl.reference_ld(cube, [[0.3, -0.2, 0.9]], 0.6, 256, model=model), 0.75, rtol=1e-12)


def mean_cos_l(model, r, nodes=400):
    """E[n.l] of the LD kernel D(h) n.l about R (N = V = R), by Gauss-Legendre in theta_h on
    [0, pi/4]: d(omega_l) = 4 (n.h) d(omega_h), n.l = cos(2 theta_h)."""
    x, w = np.polynomial.legendre.leggauss(nodes)
    t = (x + 1) * np.pi / 8
    w = w * np.pi / 8
    d = model.ndf(np.cos(t), np.full_like(t, model.alpha(r)))
    k = d * np.cos(2 * t) * np.cos(t) * np.sin(t) * w
    return np.sum(k * np.cos(2 * t)) / np.sum(k)


@pytest.mark.parametrize("model", [Beckmann(), BlinnPhong()])
def test_linear_environment_closed_form(model):
    # L(d) = 1 + g.d: for a kernel symmetric about R, LD(R) = 1 + (g.R) E[n.l]
    n = 64
    g = np.array([0.3, -0.5, 0.6])
    dirs, _, _ = cube_dirs(n)
    cube = np.repeat((1.0 + dirs @ g)[..., None], 3, -1).astype(np.float32)
    rng = np.random.default_rng(7)
    points = rng.normal(size=(8, 3))
    points /= np.linalg.norm(points, axis=-1, keepdims=True)
    for r in (0.3, 0.9):
        e = mean_cos_l(model, r)
        ld = ibl.reference_ld(cube, points, r, 4096, model=model)[:, 0]
        # the bilinear reads of the 64^2 cube and 4096 samples: within 3e-4 (measured 1e-4, also
        # for GGX against its own E); GGX's E would be off by more than 3e-3 at these points
        assert np.max(np.abs(ld - (1.0 + (points @ g) * e))) < 3e-4, r
        assert np.max(np.abs(ld - (1.0 + (points @ g) * mean_cos_l(GGXHeightCorrelated(), r)))) > 3e-3, r


def test_python_lobe_calls_and_bad_models():
    calls = []

    class Counting(GGXHeightCorrelated):
        def ndf(self, n_dot_h, a):
            calls.append(n_dot_h.size)
            return super().ndf(n_dot_h, a)

    cube = np.ones((6, 16, 16, 3), np.float32)
    ibl.prefilter(cube, samples=8, model=Counting())  # 3 levels: 2 tables in one call
    assert calls == [2 * 4097]

    class NoNdf:
        def alpha(self, r):
            return r * r

    with pytest.raises(TypeError, match="ndf"):
        ibl.prefilter(cube, model=NoNdf())
    with pytest.raises(ValueError, match="model must be"):
        ibl.prefilter(cube, model="beckmann")
    with pytest.raises(ValueError, match="g1"):
        ibl.prefilter(cube, weight="g1", model=GGXHeightCorrelated())
    with pytest.raises(ValueError, match="g1"):
        ibl.reference_ld(cube, [0, 0, 1], 0.5, weight="g1", model=GGXHeightCorrelated())

    class NaNNdf(GGXHeightCorrelated):
        def ndf(self, n_dot_h, a):
            return np.where(n_dot_h < 0.5, np.nan, 1.0)

    with pytest.raises(ValueError, match="ndf returned nan at n_dot_h"):
        ibl.prefilter(cube, model=NaNNdf())

    class Negative(GGXHeightCorrelated):
        def ndf(self, n_dot_h, a):
            return n_dot_h - 0.5

    with pytest.raises(ValueError, match="finite and >= 0"):
        ibl.reference_ld(cube, [0, 0, 1], 0.5, model=Negative())

    class Zero(GGXHeightCorrelated):
        def ndf(self, n_dot_h, a):
            return 0.0

    with pytest.raises(ValueError, match="integrates to"):
        ibl.prefilter(cube, model=Zero())

    class WrongShape(GGXHeightCorrelated):
        def ndf(self, n_dot_h, a):
            return np.ones(5)

    with pytest.raises(ValueError, match="shape"):
        ibl.prefilter(cube, model=WrongShape())

    class BadAlpha(GGXHeightCorrelated):
        def alpha(self, r):
            return -np.asarray(r)

    with pytest.raises(ValueError, match="alpha"):
        ibl.prefilter(cube, model=BadAlpha())
    with pytest.raises(ValueError, match="distinct"):
        ibl.reference_ld(cube, np.tile([0, 0, 1.0], (1100, 1)), np.linspace(0.1, 1, 1100), 4,
                         model=GGXHeightCorrelated())

    class Raises(GGXHeightCorrelated):
        def ndf(self, n_dot_h, a):
            raise RuntimeError("model bug")

    with pytest.raises(RuntimeError, match="model bug"):
        ibl.reference_ld(cube, [0, 0, 1], 0.5, model=Raises())


def test_fast_filter_peak_split_builtin_only():
    cube = make_cube()
    on = ibl.prefilter(cube, method="fast", samples=16, threads=1)
    off = ibl.prefilter(cube, method="fast", samples=16, threads=1, peaks=0)
    # the bright block is above 16 times the mean: the split changes the rough levels, not the mirror
    assert np.array_equal(on[0], off[0])
    assert any(not np.array_equal(a, b) for a, b in zip(on[1:], off[1:]))
    # the same light energy either way (a white-furnace-like check on the sum over texels)
    for a, b in zip(on[1:], off[1:]):
        assert abs(float(a.mean()) / float(b.mean()) - 1.0) < 0.05
    with pytest.raises(ValueError, match="peaks"):
        ibl.prefilter(cube, method="fast", model=GGXHeightCorrelated(), peaks=8)
    with pytest.raises(ValueError, match="peaks"):
        ibl.prefilter(cube, method="fast", peaks=-1)


def test_fast_filter_coarse_tail():
    # a 64^2 cube (5 levels): level 1 reads its kernel tail from level 2 (16^2), level 2 would read
    # 8^2 (below the 16-texel minimum) and is the tap set alone either way
    n = 64
    cube = np.ones((6, n, n, 3), np.float32)
    cube[2] *= 20.0  # a bright +Y face over dim ones
    on = ibl.prefilter(cube, method="fast", samples=16, threads=1, peaks=0)
    off = ibl.prefilter(cube, method="fast", samples=16, threads=1, peaks=0, coarse_tail=False)
    assert len(on) == 5
    assert not np.array_equal(on[1], off[1])
    for k in (0, 2, 3, 4):
        assert np.array_equal(on[k], off[k])
    # a white furnace stays exactly white with the tail (its share and the rest's add to 1)
    white = ibl.prefilter(np.ones((6, n, n, 3), np.float32), method="fast", samples=16, threads=1)
    assert all(np.allclose(level, 1.0, rtol=0, atol=1e-6) for level in white)
    # the option is read by the fast filter only
    fis_on = ibl.prefilter(cube, method="fis", samples=16, threads=1)
    fis_off = ibl.prefilter(cube, method="fis", samples=16, threads=1, coarse_tail=False)
    assert all(np.array_equal(a, b) for a, b in zip(fis_on, fis_off))


def test_fast_filter_mid_tail():
    # a 256^2 cube (6 levels): level 1 (r = 0.2) reads its kernel tail from an intermediate level
    # at r = 0.22 (64^2); mid_tail=False reads level 2; no other level changes
    n = 256
    rng = np.random.default_rng(3)
    cube = (1.0 + 4.0 * rng.random((6, n, n, 3))).astype(np.float32)
    cube[2] *= 10.0
    on = ibl.prefilter(cube, method="fast", threads=1)
    off = ibl.prefilter(cube, method="fast", threads=1, mid_tail=False)
    assert len(on) == 6
    assert not np.array_equal(on[1], off[1])
    for k in (0, 2, 3, 4, 5):
        assert np.array_equal(on[k], off[k])
    white = ibl.prefilter(np.ones((6, n, n, 3), np.float32), method="fast", threads=1)
    assert all(np.allclose(level, 1.0, rtol=0, atol=1e-5) for level in white)


def test_fast_filter_sh_levels():
    # a 64^2 cube (5 levels, r = l / 4): levels 2-4 are reconstructed from spherical harmonics by
    # default; sh_bands=0 filters them by their tap sets; level 1 (r = 0.25) keeps its tap set
    n = 64
    rng = np.random.default_rng(7)
    cube = (1.0 + rng.random((6, n, n, 3))).astype(np.float32)
    cube[2] *= 20.0
    sh = ibl.prefilter(cube, method="fast", samples=16, threads=1, peaks=0)
    taps = ibl.prefilter(cube, method="fast", samples=16, threads=1, peaks=0, sh_bands=0)
    ref = ibl.prefilter(cube, method="fis", samples=2048, threads=1)  # filtered IS, 2048 samples a texel

    def rel_rmse(a, k):
        return float(np.sqrt(np.mean((a[k][..., 1] / ref[k][..., 1] - 1.0) ** 2)))

    for k in (2, 3, 4):
        assert not np.array_equal(sh[k], taps[k])
        # the same kernel; the spherical harmonics within 0.3 % of the reference (measured 0.08-0.12 %),
        # the 16-sample tap sets 8-10 % off at the bright face's edges
        assert rel_rmse(sh, k) < 3e-3
        assert rel_rmse(sh, k) < 0.1 * rel_rmse(taps, k)
    # a white furnace stays exactly white (each level is divided by its reconstruction of a constant)
    white = ibl.prefilter(np.ones((6, n, n, 3), np.float32), method="fast", samples=16, threads=1)
    assert all(np.array_equal(level, np.ones_like(level)) for level in white)
    # read by the fast filter only; bad values are refused
    fis_a = ibl.prefilter(cube, method="fis", samples=16, threads=1)
    fis_b = ibl.prefilter(cube, method="fis", samples=16, threads=1, sh_bands=0)
    assert all(np.array_equal(a, b) for a, b in zip(fis_a, fis_b))
    for bad in (-1, 33):
        with pytest.raises(ValueError, match="sh_bands"):
            ibl.prefilter(cube, method="fast", sh_bands=bad)
