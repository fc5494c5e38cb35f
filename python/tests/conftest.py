# Shared fixtures of the Python module's tests: NumPy restatements of the library's models, written
# from the formulas of ibl/brdf/*.hpp (not from the binding), used as Python BRDF models.
import numpy as np
import pytest

import ibl  # noqa: F401  (fails loudly when the module is not on PYTHONPATH)

GGX_MIN_ALPHA = 2.0 ** -255  # ggx_min_alpha_v<double>
TINY = np.finfo(np.float64).tiny  # min_normal_v<double>


def ndf_ggx(n_dot_h, alpha):
    a2 = np.clip(alpha, GGX_MIN_ALPHA, 1.0) ** 2
    c = np.clip(n_dot_h, 0.0, 1.0)
    d = (1.0 - c) * (1.0 + c) + a2 * c * c
    return np.where(n_dot_h >= 0.0, a2 / (np.pi * d * d), 0.0)


def smith_root(mu, a2):
    return np.sqrt(np.maximum(mu * mu + a2 * (1.0 - mu) * (1.0 + mu), 0.0))


def v_ggx_correlated(n_dot_v, n_dot_l, alpha):
    a2 = np.clip(alpha, GGX_MIN_ALPHA, 1.0) ** 2
    v = np.clip(n_dot_v, 0.0, 1.0)
    l = np.clip(n_dot_l, 0.0, 1.0)
    return 0.5 / np.maximum(l * smith_root(v, a2) + v * smith_root(l, a2), TINY)


class GGXHeightCorrelated:
    """ggx_height_correlated (brdf/model.hpp) in NumPy."""

    def alpha(self, r):
        return np.clip(r, 0.0, 1.0) ** 2

    def ndf(self, n_dot_h, alpha):
        return ndf_ggx(n_dot_h, alpha)

    def visibility(self, n_dot_v, n_dot_l, r):
        return v_ggx_correlated(n_dot_v, n_dot_l, self.alpha(r))


class GGXSchlickIBL(GGXHeightCorrelated):
    """ggx_schlick_ibl: V = 1 / (4 (v + k(1 - v)) (l + k(1 - l))), k = r^2 / 2."""

    def visibility(self, n_dot_v, n_dot_l, r):
        k = np.clip(np.clip(r, 0.0, 1.0) ** 2 / 2.0, GGX_MIN_ALPHA / 2.0, 1.0)
        v = np.clip(n_dot_v, 0.0, 1.0)
        l = np.clip(n_dot_l, 0.0, 1.0)
        return 1.0 / (4.0 * (v + k * (1.0 - v)) * (l + k * (1.0 - l)))


class BlinnPhong(GGXHeightCorrelated):
    """Normalised Blinn-Phong D, e = 2 / alpha^2 - 2 (Walter 2007), with the height-correlated GGX V:
    the binding's built-in 'blinn_phong' model, restated."""

    def ndf(self, n_dot_h, alpha):
        a = np.clip(alpha, GGX_MIN_ALPHA, 1.0)
        e = -2.0 * (a - 1.0) * (a + 1.0) / (a * a)
        c = np.clip(n_dot_h, 0.0, 1.0)
        return np.where(n_dot_h >= 0.0, (e + 2.0) / (2.0 * np.pi) * c ** e, 0.0)


@pytest.fixture
def ggx_model():
    return GGXHeightCorrelated()
