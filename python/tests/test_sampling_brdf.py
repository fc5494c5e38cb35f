# Samplers and BRDF terms against closed forms and independent NumPy restatements.
import numpy as np
import pytest

import ibl
from conftest import ndf_ggx, v_ggx_correlated


def radical_inverse(i):
    i = np.asarray(i, dtype=np.uint64)
    r = np.zeros(i.shape, dtype=np.float64)
    for bit in range(32):
        r += ((i >> np.uint64(bit)) & np.uint64(1)) * 2.0 ** -(bit + 1)
    return r


def test_hammersley_matches_radical_inverse():
    n = 1000
    h = ibl.hammersley(n)
    assert h.shape == (n, 2) and h.dtype == np.float64
    np.testing.assert_array_equal(h[:, 0], np.arange(n) / n)
    np.testing.assert_array_equal(h[:, 1], radical_inverse(np.arange(n)))
    f = ibl.hammersley(64, float32=True)
    assert f.dtype == np.float32
    np.testing.assert_allclose(f, ibl.hammersley(64), atol=2e-7)
    assert ibl.hammersley(0).shape == (0, 2)


def test_sample_ggx_ndf_closed_form_and_pdf():
    u = ibl.hammersley(256)
    alpha = np.array([[0.05], [0.3], [1.0]])  # broadcast (3, 1) with (256,) -> (3, 256)
    h = ibl.sample_ggx_ndf(u, alpha)
    assert h.shape == (3, 256, 3)
    den = 1.0 - u[:, 0] + alpha ** 2 * u[:, 0]
    cos_t = np.sqrt((1.0 - u[:, 0]) / den)
    sin_t = alpha * np.sqrt(u[:, 0] / den)
    phi = 2.0 * np.pi * u[:, 1]
    ref = np.stack([sin_t * np.cos(phi), sin_t * np.sin(phi), cos_t], axis=-1)
    np.testing.assert_allclose(h, ref, atol=1e-14)
    pdf = ibl.ggx_ndf_pdf(h, alpha)
    np.testing.assert_allclose(pdf, ndf_ggx(h[..., 2], alpha) * h[..., 2], rtol=1e-12)


def test_vndf_samples_and_pdf():
    v = np.array([np.sqrt(1 - 0.3 ** 2), 0.0, 0.3])
    u = ibl.hammersley(4096)
    alpha = 0.4
    h = ibl.sample_ggx_vndf(v, u, alpha)
    assert h.shape == (4096, 3)
    np.testing.assert_allclose(np.linalg.norm(h, axis=-1), 1.0, atol=1e-14)
    assert (h[:, 2] > 0).all() and (h @ v > -1e-12).all()
    g1_over_mu = 2.0 / (v[2] + np.sqrt(v[2] ** 2 + alpha ** 2 * (1 - v[2] ** 2)))
    pdf = ibl.ggx_vndf_pdf(v, h, alpha)
    np.testing.assert_allclose(pdf, g1_over_mu * np.clip(h @ v, 0, 1) * ndf_ggx(h[:, 2], alpha), rtol=1e-12, atol=1e-300)
    # the VNDF density integrates to 1: its mean ratio to the NDF density over NDF samples is 1
    hn = ibl.sample_ggx_ndf(u, alpha)
    assert abs((ibl.ggx_vndf_pdf(v, hn, alpha) / ibl.ggx_ndf_pdf(hn, alpha)).mean() - 1.0) < 0.01
    refl = ibl.ggx_vndf_reflected_pdf(v, h, alpha)
    np.testing.assert_allclose(refl, 0.25 * g1_over_mu * ndf_ggx(h[:, 2], alpha), rtol=1e-12)


def test_brdf_terms_closed_forms():
    c = np.linspace(0.0, 1.0, 101)
    a = np.linspace(0.01, 1.0, 7)[:, None]
    np.testing.assert_allclose(ibl.ndf_ggx(c, a), ndf_ggx(c, a), rtol=1e-13)
    np.testing.assert_allclose(ibl.v_smith_ggx_correlated(c, c[::-1], a), v_ggx_correlated(c, c[::-1], a), rtol=1e-13)
    mu = np.linspace(0.01, 1.0, 50)
    g1 = 2 * mu / (mu + np.sqrt(mu ** 2 + a ** 2 * (1 - mu ** 2)))
    np.testing.assert_allclose(ibl.g1_smith_ggx(mu, a), g1, rtol=1e-13)
    lam = (np.sqrt(1 + a ** 2 * (1 - mu ** 2) / mu ** 2) - 1) / 2
    np.testing.assert_allclose(ibl.lambda_ggx(mu, a), lam, rtol=1e-10)  # the NumPy form cancels
    np.testing.assert_allclose(ibl.g2_smith_ggx_correlated(mu, mu[::-1], a),
                               1 / (1 + ibl.lambda_ggx(mu, a) + ibl.lambda_ggx(mu[::-1], a)), rtol=1e-12)
    r = np.linspace(0, 1, 11)
    np.testing.assert_allclose(ibl.k_ibl(r), r * r / 2, rtol=1e-15)
    np.testing.assert_allclose(ibl.k_direct(r), (r + 1) ** 2 / 8, rtol=1e-15)
    k = ibl.k_ibl(0.5)
    np.testing.assert_allclose(ibl.g1_schlick_ggx(mu, k), mu / (mu * (1 - k) + k), rtol=1e-14)
    np.testing.assert_allclose(ibl.g_smith_schlick_ggx(mu, mu, k), (mu / (mu * (1 - k) + k)) ** 2, rtol=1e-14)
    np.testing.assert_allclose(ibl.v_smith_schlick_ggx(mu, mu, k), 1 / (4 * (mu + k * (1 - mu)) ** 2), rtol=1e-14)
    np.testing.assert_allclose(ibl.schlick_weight(c), (1 - c) ** 5, rtol=1e-13, atol=1e-300)
    np.testing.assert_allclose(ibl.fresnel_schlick(c, 0.04), 0.04 + 0.96 * (1 - c) ** 5, rtol=1e-14)
    f0 = np.array([0.04, 0.5, 0.9])
    rgb = ibl.fresnel_schlick(c[:, None], f0)
    assert rgb.shape == (101, 3)
    f90 = np.maximum(1 - 0.3, f0)
    np.testing.assert_allclose(ibl.fresnel_schlick_roughness(c[:, None], f0, 0.3), f0 + (f90 - f0) * (1 - c[:, None]) ** 5,
                               rtol=1e-14)
    e = ibl.blinn_phong_exponent_from_alpha(a)
    np.testing.assert_allclose(e, 2 / a ** 2 - 2, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(ibl.ndf_blinn_phong(c, a), (e + 2) / (2 * np.pi) * c ** e, rtol=1e-12, atol=1e-300)
    s2 = (1 - c) * (1 + c)
    np.testing.assert_allclose(ibl.ndf_charlie(c[1:-1], a), (2 + 1 / a) * s2[1:-1] ** (0.5 / a) / (2 * np.pi), rtol=1e-12)
    np.testing.assert_allclose(ibl.v_neubelt(c, c[::-1]), 1 / (4 * (c[::-1] + c - c * c[::-1])), rtol=1e-14)


def test_dtypes_scalars_and_broadcast():
    assert isinstance(ibl.ndf_ggx(0.9, 0.5), float)
    x = np.linspace(0, 1, 5, dtype=np.float32)
    d32 = ibl.ndf_ggx(x, np.float32(0.5))
    assert d32.dtype == np.float32
    np.testing.assert_allclose(d32, ibl.ndf_ggx(x.astype(np.float64), 0.5), rtol=1e-6)
    assert ibl.ndf_ggx(x, 0.5).dtype == np.float32  # a Python float does not promote
    assert ibl.ndf_ggx(x, np.float64(0.5)).dtype == np.float64
    assert ibl.v_smith_ggx_correlated(np.ones((2, 1, 3)), np.ones((4, 1)), 0.5).shape == (2, 4, 3)
    # strided (non-contiguous) input is accepted
    big = np.linspace(0, 1, 20)
    np.testing.assert_array_equal(ibl.schlick_weight(big[::2]), ibl.schlick_weight(big)[::2])


def test_bad_inputs_raise():
    with pytest.raises(ValueError, match="alpha"):
        ibl.ndf_ggx(0.5, np.nan)
    with pytest.raises(ValueError, match="roughness"):
        ibl.k_ibl(1.5)
    with pytest.raises(ValueError, match="shape"):
        ibl.sample_ggx_ndf(np.zeros((4, 3)), 0.5)
    with pytest.raises(ValueError, match="broadcast"):
        ibl.ndf_ggx(np.zeros(3), np.full(4, 0.5))
    with pytest.raises(ValueError):
        ibl.hammersley(-1)
    with pytest.raises(TypeError):
        ibl.ndf_ggx("a", 0.5)
