# Sun extraction (a synthetic sun on a constant sky, against restated texel solid angles and the
# disk-light closed forms of env/sun_extract.hpp) and the MIS outgoing-radiance reference (white
# furnace closed forms: the directional albedo A + B, Lambert, the kD weighting; a small bright
# source's irradiance).
import numpy as np
import pytest

import ibl


def texel_solid_angles(n):
    """Exact solid angle of each texel of a face (n, n): the area integral of (1 + s^2 + t^2)^-3/2."""
    e = 2 * np.arange(n + 1) / n - 1

    def f(x, y):
        return np.arctan2(x * y, np.sqrt(x * x + y * y + 1))

    x0, y0 = np.meshgrid(e[:-1], e[:-1])
    x1, y1 = np.meshgrid(e[1:], e[1:])
    return f(x1, y1) - f(x0, y1) - f(x1, y0) + f(x0, y0)


def test_extract_sun_of_a_synthetic_sun():
    n = 64
    cube = np.full((6, n, n, 3), 0.1, np.float32)
    sun = np.array([2000.0, 1800.0, 1500.0], np.float32)
    cube[4, 31:33, 31:33] = sun  # 2 x 2 texels at the centre of +Z (3.9e-3 sr)
    res = ibl.extract_sun(cube, threads=1)
    assert res is not None
    light, residual = res
    assert residual.shape == cube.shape and residual.dtype == np.float32
    # the residual: the region filled from a constant ring is the constant; nothing else changes
    np.testing.assert_allclose(residual, 0.1, rtol=1e-4)
    np.testing.assert_allclose(light["direction"], [0, 0, 1], atol=1e-6)
    omega = texel_solid_angles(n)[31:33, 31:33]
    assert light["region_texels"] == 4
    assert light["region_solid_angle"] == pytest.approx(omega.sum(), rel=1e-5)
    # uniform excess: the disk's solid angle is the region's
    assert light["solid_angle"] == pytest.approx(omega.sum(), rel=1e-5)
    # irradiance facing the light: sum e Omega (d . z), d.z = 1 / sqrt(1 + s^2 + t^2) at the centres
    c = 2 * (np.arange(n) + 0.5) / n - 1
    s, t = np.meshgrid(c[31:33], c[31:33])
    cos = 1 / np.sqrt(1 + s * s + t * t)
    e_sun = (sun - 0.1)[None, None, :] * (omega * cos)[..., None]
    np.testing.assert_allclose(light["irradiance"], e_sun.sum(axis=(0, 1)), rtol=1e-5)
    # the disk's closed forms: cos r = 1 - Omega / (2 pi), E = L pi sin^2 r
    r = light["angular_radius"]
    assert np.cos(r) == pytest.approx(1 - light["solid_angle"] / (2 * np.pi), rel=1e-6)
    np.testing.assert_allclose(light["radiance"] * np.pi * np.sin(r) ** 2, light["irradiance"], rtol=1e-5)
    assert 0.2 < light["share"] <= 1.0


def test_extract_sun_none_and_bad_input():
    cube = np.full((6, 8, 8, 3), 0.5, np.float32)
    assert ibl.extract_sun(cube) is None  # no texel above the threshold
    big = cube.copy()
    big[2] = 1e4  # a whole face: 2 pi / 3 sr, far above max_solid_angle
    assert ibl.extract_sun(big) is None
    weak = np.full((6, 64, 64, 3), 0.5, np.float32)
    weak[4, 3, 3] = 30.0  # bright, but a small share of the irradiance facing it
    assert ibl.extract_sun(weak, threshold_over_median=10.0) is None
    assert ibl.extract_sun(weak, threshold_over_median=10.0, min_share=0.0) is not None
    with pytest.raises(ValueError, match="shape"):
        ibl.extract_sun(np.zeros((6, 8, 7, 3), np.float32))
    with pytest.raises(ValueError, match="max_solid_angle"):
        ibl.extract_sun(cube, max_solid_angle=0.0)
    with pytest.raises(ValueError, match="min_share"):
        ibl.extract_sun(cube, min_share=np.nan)
    bad = cube.copy()
    bad[1, 2, 3, 1] = np.inf
    with pytest.raises(ValueError, match="non-finite"):
        ibl.extract_sun(bad)


# ---- reference_radiance ----------------------------------------------------------------------------

def test_reference_radiance_white_furnace_closed_forms():
    cube = np.ones((6, 8, 8, 3), np.float32)
    rng = np.random.default_rng(2)
    n = rng.normal(size=(4, 3))
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    mu = np.array([0.9, 0.6, 0.3, 0.75])
    t = np.cross(n, rng.normal(size=(4, 3)))
    t /= np.linalg.norm(t, axis=-1, keepdims=True)
    v = mu[:, None] * n + np.sqrt(1 - mu * mu)[:, None] * t
    r = np.array([0.3, 0.5, 0.8, 1.0])
    ab = ibl.dfg(mu, r)
    # white metal: F0 = 1, no diffuse: Lo = A + B (the directional albedo)
    metal = ibl.reference_radiance(cube, n, v, np.ones(3), 1.0, r, samples=16384, threads=1)
    assert set(metal) == {"value", "diffuse", "specular", "std_error"}
    assert metal["value"].shape == (4, 3)
    np.testing.assert_allclose(metal["diffuse"], 0.0, atol=1e-12)
    np.testing.assert_allclose(metal["value"], np.repeat(ab.sum(-1)[:, None], 3, 1), atol=5e-3)
    # white dielectric, Lambert + GGX with F0 = 0.04: Lo = 1 + 0.04 A + B
    base = np.array([1.0, 0.5, 0.25])
    diel = ibl.reference_radiance(cube, n, v, base, 0.0, r, samples=16384, threads=1)
    np.testing.assert_allclose(diel["diffuse"], np.broadcast_to(base, (4, 3)), atol=5e-3)
    np.testing.assert_allclose(diel["specular"], np.repeat((0.04 * ab[:, 0] + ab[:, 1])[:, None], 3, 1), atol=5e-3)
    np.testing.assert_allclose(diel["value"], diel["diffuse"] + diel["specular"], rtol=1e-12)
    assert (diel["std_error"] < 3e-3).all()
    assert (np.abs(diel["value"] - (base + (0.04 * ab[:, 0] + ab[:, 1])[:, None])) <= 5 * diel["std_error"] + 1e-4).all()
    # kD = 1 - F_r(n.v) on the diffuse lobe (runtime/shade.hpp's single-scattering weighting)
    kd = ibl.reference_radiance(cube, n, v, np.ones(3), 0.0, r, samples=16384, diffuse="one_minus_fresnel_roughness")
    f0 = 0.04
    fr = f0 + (np.maximum(1 - r, f0) - f0) * (1 - mu) ** 5
    np.testing.assert_allclose(kd["diffuse"], np.repeat((1 - fr)[:, None], 3, 1), atol=5e-3)
    # deterministic; brdf and env strategies agree on a constant environment
    again = ibl.reference_radiance(cube, n, v, base, 0.0, r, samples=16384, threads=1)
    np.testing.assert_array_equal(again["value"], diel["value"])
    for strategy in ("brdf", "env"):
        other = ibl.reference_radiance(cube, n, v, base, 0.0, r, samples=16384, strategy=strategy)
        np.testing.assert_allclose(other["value"], diel["value"], atol=1e-2)


def test_reference_radiance_sun_against_the_disk_closed_form():
    # a lone bright texel seen by a rough diffuse surface facing it: Lo = albedo / pi * E,
    # E = sum L Omega cos (the texel is small: cos ~ 1 at its centre)
    n_face = 16
    cube = np.zeros((6, n_face, n_face, 3), np.float32)
    cube[4, 7:9, 7:9] = 100.0
    omega = texel_solid_angles(n_face)[7:9, 7:9]
    c = 2 * (np.arange(n_face) + 0.5) / n_face - 1
    s, t = np.meshgrid(c[7:9], c[7:9])
    e = 100.0 * (omega / np.sqrt(1 + s * s + t * t)).sum()
    got = ibl.reference_radiance(cube, [0, 0, 1.0], [0, 0, 1.0], np.ones(3), 0.0, 1.0, samples=4096)
    np.testing.assert_allclose(got["diffuse"], e / np.pi, rtol=2e-2)


def test_reference_radiance_bad_input():
    cube = np.ones((6, 4, 4, 3), np.float32)
    args = ([0, 0, 1.0], [0, 0, 1.0], np.ones(3), 0.0, 0.5)
    with pytest.raises(ValueError, match="samples"):
        ibl.reference_radiance(cube, *args, samples=0)
    with pytest.raises(ValueError, match="batches"):
        ibl.reference_radiance(cube, *args, batches=1)
    with pytest.raises(ValueError, match="strategy"):
        ibl.reference_radiance(cube, *args, strategy="magic")
    with pytest.raises(ValueError, match="diffuse"):
        ibl.reference_radiance(cube, *args, diffuse="magic")
    with pytest.raises(ValueError, match="roughness"):
        ibl.reference_radiance(cube, [0, 0, 1.0], [0, 0, 1.0], np.ones(3), 0.0, 1.5)
    with pytest.raises(ValueError, match="n must"):
        ibl.reference_radiance(cube, [0, 0, 0.0], [0, 0, 1.0], np.ones(3), 0.0, 0.5)
    with pytest.raises(ValueError, match="shape"):
        ibl.reference_radiance(np.ones((6, 4, 4, 4), np.float32), *args)


def test_reference_radiance_of_python_models():
    from conftest import BlinnPhong, GGXHeightCorrelated
    rng = np.random.default_rng(2)
    cube = (0.2 + rng.random((6, 16, 16, 3))).astype(np.float32)
    cube[2, 4:6, 4:6] = 40.0
    n = rng.normal(size=(10, 3))
    v = n + 0.8 * rng.normal(size=(10, 3))
    base, metal = rng.random((10, 3)), rng.random(10)
    r = np.array([0.0, 0.05, 0.3, 0.7, 1.0] * 2)  # with the mirror regime (no model calls)
    for strategy in ("mis", "brdf", "env"):
        cpp = ibl.reference_radiance(cube, n, v, base, metal, r, samples=1024, strategy=strategy)
        py = ibl.reference_radiance(cube, n, v, base, metal, r, samples=1024, strategy=strategy,
                                    model=GGXHeightCorrelated())
        for k in cpp:  # the same estimator and draws, the NumPy restatement's values: measured equal
            np.testing.assert_allclose(py[k], cpp[k], rtol=1e-12, atol=0, err_msg=f"{strategy} {k}")
    # white furnace of a white metal: Lo = E = A + B of the model (its own dfg_albedo); Blinn-Phong's
    # E is told apart from GGX's by many standard errors
    white = np.ones((6, 8, 8, 3), np.float32)
    nv = np.array([0.2, 0.5, 0.9])
    views = np.stack([np.sqrt(1 - nv ** 2), 0 * nv, nv], -1)
    for rough in (0.3, 0.7):
        e = ibl.reference_radiance(white, [0, 0, 1], views, [1, 1, 1], 1.0, rough, samples=4096, model=BlinnPhong())
        want = ibl.dfg_albedo(nv, rough, BlinnPhong())
        assert (np.abs(e["value"][:, 0] - want) < 5 * e["std_error"][:, 0]).all(), rough
        assert (np.abs(ibl.dfg_albedo(nv, rough) - want) > 10 * e["std_error"][:, 0]).any(), rough

    class NoVisibility:
        def alpha(self, r):
            return r * r

        def ndf(self, n_dot_h, a):
            return 1.0

    with pytest.raises(TypeError, match="visibility"):
        ibl.reference_radiance(white, [0, 0, 1], [0, 0, 1], [1, 1, 1], 1.0, 0.5, model=NoVisibility())

    class NaNNdf(GGXHeightCorrelated):
        def ndf(self, n_dot_h, a):
            return np.full_like(n_dot_h, np.nan)

    with pytest.raises(ValueError, match="ndf returned nan"):
        ibl.reference_radiance(white, [0, 0, 1], [0, 0, 1], [1, 1, 1], 1.0, 0.5, model=NaNNdf())
    with pytest.raises(ValueError, match="model must be"):
        ibl.reference_radiance(white, [0, 0, 1], [0, 0, 1], [1, 1, 1], 1.0, 0.5, model="beckmann")
