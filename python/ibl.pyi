# Type stubs of the extension module `ibl` (python/*.cpp). ArrayLike: anything NumPy converts to a
# real array. Element-wise functions broadcast their arguments (a trailing axis of 2 or 3 where a
# vector is expected), compute in float32 when every NumPy input is float32 and in float64
# otherwise, and return a new array (a Python float when every input is a scalar). Roughness and
# alpha arguments must lie in [0, 1] (ValueError otherwise, also for NaN). Complex input: TypeError.
# A non-finite result of finite input that overflows (a cube near float's range, a Python model
# returning huge values): ValueError (docs/python.md, "Bad input and fuzzing").
from typing import Any, Optional, Protocol, Sequence, Union

import numpy as np
import numpy.typing as npt

ArrayLike = npt.ArrayLike
Real = Union[float, np.ndarray]

__version__: str
builtin_models: tuple[str, ...]
model_batch_nodes: int  # the most nodes a Python model's methods see in one call (2^16)

class BRDFModel(Protocol):
    """A Python BRDF model (brdf/model.hpp's contract). Every method receives float64 arrays of
    equal shape (one batch of quadrature nodes, at most model_batch_nodes long) and returns an
    array of that shape (or a scalar).
    Either ndf + visibility (the weight 4 V n.l (v.h) / n.h * D / D_ggx is formed by the binding) or
    sample_weight must be present."""
    def alpha(self, roughness: np.ndarray) -> np.ndarray: ...
    def ndf(self, n_dot_h: np.ndarray, alpha: np.ndarray) -> np.ndarray: ...
    def visibility(self, n_dot_v: np.ndarray, n_dot_l: np.ndarray, roughness: np.ndarray) -> np.ndarray: ...
    # optional: def sample_weight(self, n_dot_v, n_dot_l, n_dot_h, v_dot_h, roughness) -> np.ndarray

Model = Union[str, BRDFModel]

# ---- samplers ----
def hammersley(n: int, *, float32: bool = False) -> np.ndarray: ...  # (n, 2)
def sample_ggx_ndf(u: ArrayLike, alpha: ArrayLike) -> np.ndarray: ...  # u (..., 2) -> h (..., 3)
def ggx_ndf_pdf(h: ArrayLike, alpha: ArrayLike) -> Real: ...
def ggx_ndf_reflected_pdf(v: ArrayLike, h: ArrayLike, alpha: ArrayLike) -> Real: ...
def sample_ggx_vndf(v: ArrayLike, u: ArrayLike, alpha: ArrayLike) -> np.ndarray: ...  # (..., 3)
def ggx_vndf_pdf(v: ArrayLike, h: ArrayLike, alpha: ArrayLike) -> Real: ...
def ggx_vndf_reflected_pdf(v: ArrayLike, h: ArrayLike, alpha: ArrayLike) -> Real: ...

# ---- BRDF terms ----
def alpha_from_roughness(roughness: ArrayLike) -> Real: ...
def ndf_ggx(n_dot_h: ArrayLike, alpha: ArrayLike) -> Real: ...
def g1_smith_ggx(n_dot_w: ArrayLike, alpha: ArrayLike) -> Real: ...
def lambda_ggx(n_dot_w: ArrayLike, alpha: ArrayLike) -> Real: ...
def v_smith_ggx_correlated(n_dot_v: ArrayLike, n_dot_l: ArrayLike, alpha: ArrayLike) -> Real: ...
def g2_smith_ggx_correlated(n_dot_v: ArrayLike, n_dot_l: ArrayLike, alpha: ArrayLike) -> Real: ...
def k_ibl(roughness: ArrayLike) -> Real: ...
def k_direct(roughness: ArrayLike) -> Real: ...
def g1_schlick_ggx(n_dot_w: ArrayLike, k: ArrayLike) -> Real: ...
def g_smith_schlick_ggx(n_dot_v: ArrayLike, n_dot_l: ArrayLike, k: ArrayLike) -> Real: ...
def v_smith_schlick_ggx(n_dot_v: ArrayLike, n_dot_l: ArrayLike, k: ArrayLike) -> Real: ...
def schlick_weight(cos_theta: ArrayLike) -> Real: ...
def fresnel_schlick(cos_theta: ArrayLike, f0: ArrayLike, f90: ArrayLike = 1.0) -> Real: ...
def fresnel_schlick_roughness(cos_theta: ArrayLike, f0: ArrayLike, roughness: ArrayLike) -> Real: ...
def ndf_blinn_phong(n_dot_h: ArrayLike, alpha: ArrayLike) -> Real: ...
def blinn_phong_exponent_from_alpha(alpha: ArrayLike) -> Real: ...
def ndf_charlie(n_dot_h: ArrayLike, alpha: ArrayLike) -> Real: ...
def v_neubelt(n_dot_v: ArrayLike, n_dot_l: ArrayLike) -> Real: ...

# ---- DFG ----
def dfg(n_dot_v: ArrayLike, roughness: ArrayLike, model: Model = "ggx_height_correlated", *,
        threads: int = 0) -> np.ndarray: ...  # (..., 2): A, B
def dfg_lut(size: int, model: Model = "ggx_height_correlated", *, layout: str = "uniform",
            multiscatter: bool = False, threads: int = 0) -> np.ndarray: ...  # float32 (size, size, 2 or 3)
def dfg_smooth_limit(n_dot_v: ArrayLike) -> np.ndarray: ...  # (..., 2)
def dfg_lut_coords(size: int, layout: str = "uniform") -> tuple[np.ndarray, np.ndarray]: ...  # (n_dot_v, roughness)
def dfg_mc(n_dot_v: ArrayLike, roughness: ArrayLike, samples: int = 1024, model: Model = "ggx_height_correlated", *,
           sampling: str = "ndf") -> np.ndarray: ...  # (..., 2); sampling "ndf" | "vndf"
def dfg_albedo(n_dot_v: ArrayLike, roughness: ArrayLike, model: Model = "ggx_height_correlated") -> Real: ...  # E = A + B
def dfg_energy_compensation(albedo: ArrayLike) -> Real: ...  # (1 - E) / E

# ---- cubes: (6, n, n, 3) float32, faces +X, -X, +Y, -Y, +Z, -Z, [face, y, x], row 0 = t = 0 ----
class LobeModel(Protocol):
    """What prefilter and reference_ld use of a Python model: alpha and an isotropic ndf. The LD
    lobe D(h) n.l (N = V = R) is tabulated per roughness from one vectorised ndf call on 4097 n.h
    nodes (python/tabulated_lobe.hpp: y = ln(1 + tan^2(theta_h) / alpha^2) on a uniform grid,
    D cos^4 e^y interpolated exponentially, exact for GGX), sampled by the inverse CDF of the
    table; a model restating GGX gives the built-in GGX results to float rounding."""
    def alpha(self, roughness: np.ndarray) -> np.ndarray: ...
    def ndf(self, n_dot_h: np.ndarray, alpha: np.ndarray) -> np.ndarray: ...

LobeArg = Union[None, str, LobeModel]  # None or "ggx": the built-in GGX lobe

def prefilter(cube: ArrayLike, *, levels: int = -1, samples: int = 0, method: str = "fis",
              weight: str = "n_dot_l", threads: int = 0,
              model: LobeArg = None,
              peaks: int | None = None,
              coarse_tail: bool = True, sh_bands: int = 24, mid_tail: bool = True) -> list[np.ndarray]: ...  # a Python model: weight "n_dot_l", peaks 0 / None
def irradiance(cube: ArrayLike, size: int = 32, *, samples: int = 1024, method: str = "cosine",
               threads: int = 0) -> np.ndarray: ...
def sh_project(cube: ArrayLike, bands: int = 3, *, threads: int = 0) -> np.ndarray: ...  # (bands^2, 3)
def sh_evaluate(coeffs: ArrayLike, dirs: ArrayLike) -> np.ndarray: ...  # (..., 3)
def sh_irradiance(coeffs: ArrayLike) -> np.ndarray: ...  # (bands^2, 3)
def reference_ld(cube: ArrayLike, dirs: ArrayLike, roughness: ArrayLike, samples: int = 4096, *,
                 weight: str = "n_dot_l", threads: int = 0,
                 model: LobeArg = None) -> np.ndarray: ...  # (..., 3); a Python model: <= 1024 distinct roughness
def extract_sun(cube: ArrayLike, *, threshold_over_median: float = 50.0, threshold_over_peak: float = 1e-3,
                max_solid_angle: float = 1e-2, min_share: float = 0.2,
                threads: int = 0) -> Optional[tuple[dict[str, Any], np.ndarray]]: ...  # (light, residual cube) or None
def reference_radiance(cube: ArrayLike, n: ArrayLike, v: ArrayLike, base_color: ArrayLike, metallic: ArrayLike,
                       roughness: ArrayLike, *, samples: int = 4096, batches: int = 16, seed: int = 0,
                       strategy: str = "mis", diffuse: str = "lambert", dielectric_f0: float = 0.04,
                       threads: int = 0, model: Union[None, str, BRDFModel] = None
                       ) -> dict[str, np.ndarray]: ...  # value, diffuse, specular, std_error: (..., 3)
# reference_radiance model: None / "ggx" (GGX height-correlated) or a Python model with alpha, ndf and
# visibility (sample_weight is not used), evaluated once per batch of points on the recorded calls

# ---- files (the bake tool's I/O library; has_image_io False: RuntimeError) ----
has_image_io: bool
def read_image(path: str, *, latlong: bool = False, max_pixels: int = 134217728,
               replace_nonfinite: bool = False) -> np.ndarray: ...  # float32 (h, w, 3), row 0 at the top
def read_ktx2(path: str) -> list[np.ndarray]: ...  # float32 (6, s, s, 3) per level
def cube_from_latlong(img: ArrayLike, size: int, supersample: int = 2, *, threads: int = 0) -> np.ndarray: ...  # (6, size, size, 3)

# ---- runtime lookups (float inside; float32 out when every NumPy input is float32) ----
def specular_lookup(chain_levels: Sequence[ArrayLike], dirs: ArrayLike, roughness: ArrayLike, *,
                    lookup: str = "textbook", mapping: str = "linear") -> np.ndarray: ...  # (..., 3)
def dfg_lookup(lut: ArrayLike, n_dot_v: ArrayLike, roughness: ArrayLike, *,
               layout: str = "uniform") -> np.ndarray: ...  # (..., channels of lut)
def shade_ambient(n_dot_v: ArrayLike, ld: ArrayLike, dfg: ArrayLike, irradiance_over_pi: ArrayLike,
                  base_color: ArrayLike, metallic: ArrayLike, roughness: ArrayLike, *, ao: ArrayLike = 1.0,
                  dielectric_f0: float = 0.04, multiscatter: bool = True) -> np.ndarray: ...  # (..., 3)
