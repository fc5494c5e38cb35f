# Image and KTX2 readers, lat-long -> cube, and the runtime lookups (specular chain, DFG table):
# compared with NumPy restatements of the documented conventions (env/latlong.hpp,
# env/cube_geometry.hpp, runtime/lookup.hpp, runtime/dfg_layout.hpp) and with closed forms.
import os
import subprocess

import numpy as np
import pytest

import ibl

DATA = os.environ.get("IBL_TEST_DATA", os.path.join(os.path.dirname(__file__), "..", "..", "tests", "data"))
COURTYARD = os.path.join(DATA, "courtyard.exr")
BAKE = os.environ.get("IBL_BAKE_EXE", "")
FACES = ("px", "nx", "py", "ny", "pz", "nz")

needs_io = pytest.mark.skipif(not ibl.has_image_io, reason="built without ibl_bake_io")


# ---- conventions, restated ----------------------------------------------------------------------

def latlong_dirs(h, w):
    """Unit directions of the texel centres of an (h, w) lat-long map (env/latlong.hpp)."""
    u = (np.arange(w) + 0.5) / w
    v = 1.0 - (np.arange(h) + 0.5) / h
    phi = 2 * np.pi * (u - 0.5)
    lat = np.pi * (v - 0.5)
    phi, lat = np.meshgrid(phi, lat)
    return np.stack([np.cos(lat) * np.cos(phi), np.sin(lat), np.cos(lat) * np.sin(phi)], axis=-1)


def cube_dirs(n):
    """(6, n, n, 3) unit directions of the texel centres (env/cube_geometry.hpp, OpenGL table 8.19),
    and (sc, tc)."""
    c = 2 * (np.arange(n) + 0.5) / n - 1
    sc, tc = np.meshgrid(c, c)  # [y, x]
    one = np.ones_like(sc)
    d = np.stack([
        np.stack([one, -tc, -sc], -1), np.stack([-one, -tc, sc], -1),
        np.stack([sc, one, tc], -1), np.stack([sc, -one, -tc], -1),
        np.stack([sc, -tc, one], -1), np.stack([-sc, -tc, -one], -1)])
    return d / np.linalg.norm(d, axis=-1, keepdims=True), sc, tc


# ---- read_image, cube_from_latlong ----------------------------------------------------------------

@needs_io
def test_read_image_courtyard_and_errors(tmp_path):
    img = ibl.read_image(COURTYARD)
    assert img.shape == (512, 1024, 3) and img.dtype == np.float32
    assert np.isfinite(img).all() and img.min() >= 0.0 and img.max() > 1.0
    np.testing.assert_array_equal(ibl.read_image(COURTYARD, latlong=True), img)
    with pytest.raises(ValueError, match="no such file"):
        ibl.read_image(str(tmp_path / "missing.exr"))
    with pytest.raises(ValueError, match="courtyard"):
        ibl.read_image(COURTYARD, max_pixels=1000)
    with pytest.raises(ValueError, match="max_pixels"):
        ibl.read_image(COURTYARD, max_pixels=0)
    junk = tmp_path / "junk.hdr"
    junk.write_bytes(b"#?RADIANCE\nthis is not an image" + bytes(range(256)))
    with pytest.raises(ValueError, match="junk.hdr"):
        ibl.read_image(str(junk))
    with pytest.raises(ValueError):
        ibl.read_ktx2(str(junk))
    with pytest.raises(ValueError, match="no such file"):
        ibl.read_ktx2(str(tmp_path / "missing.ktx2"))


def test_cube_from_latlong_constant_and_linear():
    flat = np.full((16, 32, 3), 0.25, np.float32)
    cube = ibl.cube_from_latlong(flat, 4)
    assert cube.shape == (6, 4, 4, 3) and cube.dtype == np.float32
    np.testing.assert_allclose(cube, 0.25, rtol=1e-6)
    # L(d) = 2 + d: the baked texel (mean of k x k bilinear reads) is 2 + its direction up to the
    # texel's curvature and the map's resolution.
    img = (2.0 + latlong_dirs(128, 256)).astype(np.float32)
    n = 8
    cube = ibl.cube_from_latlong(img, n, supersample=4, threads=1)
    d, _, _ = cube_dirs(n)
    np.testing.assert_allclose(cube, 2.0 + d, atol=0.03)


@needs_io
def test_cube_from_latlong_courtyard_preserves_the_integral():
    img = ibl.read_image(COURTYARD).astype(np.float64)
    h, w = img.shape[:2]
    j = np.arange(h)
    omega_ll = (4 * np.pi / w) * np.sin(np.pi * (j + 0.5) / h) * np.sin(np.pi / (2 * h))
    total_ll = (img * omega_ll[:, None, None]).sum(axis=(0, 1))
    n = 32
    cube = ibl.cube_from_latlong(img.astype(np.float32), n).astype(np.float64)
    _, sc, tc = cube_dirs(n)
    omega = (2.0 / n) ** 2 / (1 + sc * sc + tc * tc) ** 1.5  # texel solid angle at its centre
    total_cube = (cube * omega[None, :, :, None]).sum(axis=(0, 1, 2))
    np.testing.assert_allclose(total_cube, total_ll, rtol=0.02)


def test_cube_from_latlong_bad_input():
    with pytest.raises(ValueError, match="shape"):
        ibl.cube_from_latlong(np.zeros((16, 16, 3), np.float32), 4)
    with pytest.raises(ValueError, match="size"):
        ibl.cube_from_latlong(np.zeros((8, 16, 3), np.float32), 0)
    with pytest.raises(ValueError, match="supersample"):
        ibl.cube_from_latlong(np.zeros((8, 16, 3), np.float32), 4, 0)
    bad = np.zeros((8, 16, 3), np.float32)
    bad[1, 2, 0] = np.inf
    with pytest.raises(ValueError, match="non-finite"):
        ibl.cube_from_latlong(bad, 4)
    with pytest.raises(TypeError):
        ibl.cube_from_latlong("image", 4)


# ---- read_ktx2 -------------------------------------------------------------------------------------

@needs_io
@pytest.mark.skipif(not (BAKE and os.access(BAKE, os.X_OK)), reason="ibl-bake not built (IBL_BAKE_EXE unset)")
def test_read_ktx2_of_ibl_bake(tmp_path):
    chains = {}
    for fmt in ("rgba32f", "bc6h"):
        out = tmp_path / fmt
        subprocess.run([BAKE, "--out", str(out), "--input", COURTYARD, "--size", "8", "--lut-size", "8",
                        "--checks", "none", "--quiet", "--irradiance-size", "0", "--threads", "1",
                        "--ktx2-format", fmt], check=True, stdout=subprocess.DEVNULL)
        chains[fmt] = ibl.read_ktx2(str(out / "specular.ktx2"))
        levels = chains[fmt]
        assert [l.shape for l in levels] == [(6, 8 >> k, 8 >> k, 3) for k in range(len(levels))]
        assert all(l.dtype == np.float32 for l in levels)
    # the float32 KTX2 holds what the per-face EXR files hold
    for k, level in enumerate(chains["rgba32f"]):
        for f, name in enumerate(FACES):
            face = ibl.read_image(str(tmp_path / "rgba32f" / f"specular_l{k}_{name}.exr"))
            np.testing.assert_array_equal(level[f], face)
    # BC6H: the same chain within the format's precision (mean error 7 % and 5 % of the mean on these
    # 8^2 and 4^2 levels of an HDRI with a sun)
    for a, b in zip(chains["bc6h"], chains["rgba32f"]):
        assert np.abs(a - b).mean() <= 0.1 * b.mean()
        assert np.abs(a - b).max() <= 0.2 * b.max()


# ---- specular_lookup -------------------------------------------------------------------------------

def constant_chain(values, n):
    """A chain whose level l is the constant RGB values[l]."""
    return [np.broadcast_to(np.asarray(v, np.float32), (6, max(1, n >> l), max(1, n >> l), 3)).copy()
            for l, v in enumerate(values)]


def restated_lookup(values, r, lookup, mapping):
    """runtime/lookup.hpp's specular lookup of a chain of constant levels, in NumPy."""
    values = np.asarray(values, np.float64)
    m = len(values) - 1
    r = np.clip(np.asarray(r, np.float64), 0, 1)
    lod = r * m if mapping == "linear" else r * (2 - r) * m
    l = np.minimum(np.floor(lod).astype(int), m - 1)
    t = np.clip(lod - l, 0, 1)

    def rough(x):
        return x / m if mapping == "linear" else 1 - np.sqrt(np.maximum(1 - x / m, 0))

    if lookup == "accurate":
        r0, r1 = rough(l.astype(float)), rough(l + 1.0)
        with np.errstate(divide="ignore", invalid="ignore"):
            tl = np.clip(np.log(r / r0) / np.log(r1 / r0), 0, 1)
        t = np.where(l > 0, np.where(r > 0, tl, 0.0), t)
    a, b = values[l], values[l + 1]
    lin = a + t[..., None] * (b - a)
    if lookup == "textbook":
        return lin
    return a * np.exp(t[..., None] * np.log(b / a))


@pytest.mark.parametrize("lookup", ["textbook", "accurate"])
@pytest.mark.parametrize("mapping", ["linear", "filament"])
def test_specular_lookup_constant_levels(lookup, mapping):
    values = [[1.0, 2.0, 4.0], [0.5, 1.5, 3.0], [0.25, 1.0, 2.5], [0.2, 0.9, 2.0], [0.1, 0.8, 1.0]]
    chain = constant_chain(values, 16)
    rng = np.random.default_rng(3)
    dirs = rng.normal(size=(200, 3))
    r = np.concatenate([np.linspace(0, 1, 100), rng.uniform(size=100)])
    got = ibl.specular_lookup(chain, dirs, r, lookup=lookup, mapping=mapping)
    assert got.shape == (200, 3) and got.dtype == np.float64
    np.testing.assert_allclose(got, restated_lookup(values, r, lookup, mapping), rtol=2e-5)
    f32 = ibl.specular_lookup(chain, dirs.astype(np.float32), r.astype(np.float32), lookup=lookup, mapping=mapping)
    assert f32.dtype == np.float32


def test_specular_lookup_reads_texel_centres_and_prefilter_chain():
    rng = np.random.default_rng(5)
    n = 8
    chain = [rng.uniform(0.1, 2.0, size=(6, n >> l, n >> l, 3)).astype(np.float32) for l in range(4)]
    for l in range(4):
        d, _, _ = cube_dirs(n >> l)
        got = ibl.specular_lookup(chain, d, l / 3.0)  # exactly level l: its bilinear read at a texel centre
        np.testing.assert_allclose(got, chain[l], rtol=1e-5)
    # a white furnace chain from prefilter reads back as the constant
    levels = ibl.prefilter(np.full((6, 8, 8, 3), 0.6, np.float32), samples=16, threads=1)
    np.testing.assert_allclose(ibl.specular_lookup(levels, rng.normal(size=(50, 3)), rng.uniform(size=50)), 0.6,
                               rtol=1e-5)
    # broadcasting: (4, 1, 3) dirs with (5,) roughness -> (4, 5, 3)
    assert ibl.specular_lookup(levels, rng.normal(size=(4, 1, 3)), np.linspace(0, 1, 5)).shape == (4, 5, 3)


def test_specular_lookup_bad_input():
    chain = constant_chain([[1, 1, 1], [2, 2, 2]], 4)
    with pytest.raises(ValueError, match="roughness"):
        ibl.specular_lookup(chain, [0, 0, 1.0], 1.5)
    with pytest.raises(ValueError, match="dirs"):
        ibl.specular_lookup(chain, [0, 0, 0.0], 0.5)
    with pytest.raises(ValueError, match="shape"):
        ibl.specular_lookup(chain, [0, 1.0], 0.5)
    with pytest.raises(ValueError, match="lookup"):
        ibl.specular_lookup(chain, [0, 0, 1.0], 0.5, lookup="magic")
    with pytest.raises(ValueError, match="mapping"):
        ibl.specular_lookup(chain, [0, 0, 1.0], 0.5, mapping="magic")
    with pytest.raises(ValueError, match="level 1"):
        ibl.specular_lookup([chain[0], chain[0]], [0, 0, 1.0], 0.5)
    with pytest.raises(ValueError, match="at least one"):
        ibl.specular_lookup([], [0, 0, 1.0], 0.5)
    with pytest.raises(ValueError, match="at most"):
        ibl.specular_lookup(constant_chain([[1, 1, 1]] * 4, 4), [0, 0, 1.0], 0.5)
    bad = [c.copy() for c in chain]
    bad[1][0, 0, 0, 0] = np.nan
    with pytest.raises(ValueError, match="non-finite"):
        ibl.specular_lookup(bad, [0, 0, 1.0], 0.5)
    with pytest.raises(TypeError):
        ibl.specular_lookup(["x"], [0, 0, 1.0], 0.5)


# ---- dfg_lookup ------------------------------------------------------------------------------------

def restated_dfg_lookup(lut, nv, r, layout):
    """Bilinear clamp-to-edge read at dfg_lut_coord (runtime/dfg_layout.hpp), in NumPy (float64)."""
    n = lut.shape[0]
    nv = np.clip(nv, 0, 1)
    r = np.clip(r, 0, 1)
    if layout == "remapped":
        s = (np.cbrt(nv) * (n - 1) + 0.5) / n
        t = (np.sqrt(r) * (n - 1) + 0.5) / n
    else:
        s, t = nv, r
    fx = np.clip(s * n - 0.5, 0, n - 1)
    fy = np.clip(t * n - 0.5, 0, n - 1)
    i0, j0 = np.floor(fx).astype(int), np.floor(fy).astype(int)
    i1, j1 = np.minimum(i0 + 1, n - 1), np.minimum(j0 + 1, n - 1)
    tx, ty = (fx - i0)[..., None], (fy - j0)[..., None]
    top = lut[j0, i0] * (1 - tx) + lut[j0, i1] * tx
    bottom = lut[j1, i0] * (1 - tx) + lut[j1, i1] * tx
    return top * (1 - ty) + bottom * ty


@pytest.mark.parametrize("layout", ["uniform", "remapped"])
def test_dfg_lookup_is_the_bilinear_read(layout):
    rng = np.random.default_rng(7)
    for channels in (2, 3):
        lut = rng.uniform(size=(9, 9, channels)).astype(np.float32)
        nv = np.concatenate([[0.0, 1.0, 0.5], rng.uniform(size=300)])
        r = np.concatenate([[0.0, 1.0, 0.001], rng.uniform(size=300)])
        got = ibl.dfg_lookup(lut, nv, r, layout=layout)
        assert got.shape == (303, channels) and got.dtype == np.float64
        np.testing.assert_allclose(got, restated_dfg_lookup(lut.astype(np.float64), nv, r, layout), atol=2e-6)


def test_dfg_lookup_of_a_table_matches_dfg():
    nv, r = np.meshgrid(np.linspace(0.05, 1, 7), np.linspace(0.1, 1, 7))
    exact = ibl.dfg(nv, r)
    for layout in ("uniform", "remapped"):
        lut = ibl.dfg_lut(32, layout=layout, multiscatter=True, threads=1)
        got = ibl.dfg_lookup(lut, nv.astype(np.float32), r.astype(np.float32), layout=layout)
        assert got.shape == (7, 7, 3) and got.dtype == np.float32
        np.testing.assert_allclose(got[..., :2], exact, atol=0.02)
    assert isinstance(ibl.dfg_lookup(lut, 0.5, 0.5, layout="remapped"), np.ndarray)


def test_dfg_lookup_bad_input():
    lut = np.zeros((8, 8, 2), np.float32)
    with pytest.raises(ValueError, match="shape"):
        ibl.dfg_lookup(np.zeros((8, 4, 2), np.float32), 0.5, 0.5)
    with pytest.raises(ValueError, match="shape"):
        ibl.dfg_lookup(np.zeros((8, 8, 4), np.float32), 0.5, 0.5)
    with pytest.raises(ValueError, match="n_dot_v"):
        ibl.dfg_lookup(lut, -0.1, 0.5)
    with pytest.raises(ValueError, match="roughness"):
        ibl.dfg_lookup(lut, 0.5, np.nan)
    with pytest.raises(ValueError, match="layout"):
        ibl.dfg_lookup(lut, 0.5, 0.5, layout="magic")
    bad = lut.copy()
    bad[2, 3, 1] = np.inf
    with pytest.raises(ValueError, match="non-finite"):
        ibl.dfg_lookup(bad, 0.5, 0.5)
    with pytest.raises(ValueError, match="broadcast"):
        ibl.dfg_lookup(lut, np.zeros(3), np.zeros(4))


# ---- shade_ambient ---------------------------------------------------------------------------------

def restated_ambient(nv, ld, ab, e_pi, base, metal, r, ao, f0d=0.04, multiscatter=True):
    """runtime/shade.hpp's ambient (F90 = 1), in NumPy."""
    metal = metal[..., None]
    f0 = f0d * (1 - metal) + base * metal
    a, b = np.clip(ab[..., :1], 0, 1), np.clip(ab[..., 1:], 0, 1)
    if multiscatter:
        ess = np.clip(a + b, 0, 1)
        fss = f0 * a + b
        favg = f0 + (1 - f0) / 21
        ems = 1 - ess
        fms = ems * fss * favg / (ess + ems * (1 - favg))
        edss = np.clip(1 - fss - fms, 0, 1)
        return (fss * ld + (fms + base * (1 - metal) * edss) * e_pi) * ao[..., None]
    f90 = np.maximum(1 - r[..., None], f0)
    f = f0 + (f90 - f0) * (1 - nv[..., None]) ** 5
    kd = (1 - f) * (1 - metal)
    return (kd * base * e_pi + ld * (f0 * a + b)) * ao[..., None]


@pytest.mark.parametrize("multiscatter", [True, False])
def test_shade_ambient_restated(multiscatter):
    rng = np.random.default_rng(11)
    m = 64
    nv, metal, r, ao = (rng.uniform(size=m) for _ in range(4))
    ld, e_pi, base = rng.uniform(0, 3, size=(m, 3)), rng.uniform(0, 3, size=(m, 3)), rng.uniform(size=(m, 3))
    ab = ibl.dfg(nv, r)
    got = ibl.shade_ambient(nv, ld, ab, e_pi, base, metal, r, ao=ao, multiscatter=multiscatter)
    assert got.shape == (m, 3) and got.dtype == np.float64
    np.testing.assert_allclose(got, restated_ambient(nv, ld, ab, e_pi, base, metal, r, ao, multiscatter=multiscatter),
                               rtol=1e-12, atol=1e-14)


def test_shade_ambient_white_furnace():
    # L = 1 everywhere (LD = E/pi = 1), white dielectric (diffuse albedo 1) or white metal (F0 = 1):
    # the multiple-scattering ambient is exactly 1
    nv, r = np.meshgrid(np.linspace(0.05, 1, 6), np.linspace(0.05, 1, 6))
    for metal in (0.0, 1.0):
        got = ibl.shade_ambient(nv, np.ones(3), ibl.dfg(nv, r), np.ones(3), np.ones(3), metal, r)
        np.testing.assert_allclose(got, 1.0, rtol=1e-12)
    f32 = ibl.shade_ambient(np.float32(0.5), np.ones(3, np.float32), np.float32([0.5, 0.1]), np.ones(3, np.float32),
                            np.ones(3, np.float32), np.float32(0.0), np.float32(0.5))
    assert f32.dtype == np.float32 and f32.shape == (3,)
    with pytest.raises(ValueError, match="metallic"):
        ibl.shade_ambient(0.5, np.ones(3), [0.5, 0.1], np.ones(3), np.ones(3), 2.0, 0.5)
    with pytest.raises(ValueError, match="base_color"):
        ibl.shade_ambient(0.5, np.ones(3), [0.5, 0.1], np.ones(3), [1, 2, 0.5], 0.0, 0.5)
    with pytest.raises(ValueError, match="dfg"):
        ibl.shade_ambient(0.5, np.ones(3), [0.5, 0.1, 0.0], np.ones(3), np.ones(3), 0.0, 0.5)
    with pytest.raises(ValueError, match="dielectric_f0"):
        ibl.shade_ambient(0.5, np.ones(3), [0.5, 0.1], np.ones(3), np.ones(3), 0.0, 0.5, dielectric_f0=-1)
