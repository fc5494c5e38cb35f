# ibl.prefilter texel by texel against the library's C++ prefilter on the same cube and options:
# tests/prefilter_ref.cpp (target ibl_python_prefilter_ref, a program written against the C++ API,
# not the binding) reads the cube from a raw file, runs cubemap + generate_mips + prefilter and
# writes every level. Its path comes from IBL_PREFILTER_REF_EXE (set by the python_module ctest).
import os
import subprocess

import numpy as np
import pytest

import ibl
from conftest import GGXHeightCorrelated

REF = os.environ.get("IBL_PREFILTER_REF_EXE")
needs_ref = pytest.mark.skipif(not REF or not os.path.exists(REF),
                               reason="IBL_PREFILTER_REF_EXE (the ibl_python_prefilter_ref program) not given")


def cpp_prefilter(tmp_path, cube, levels, samples, method, weight, threads=1):
    n = cube.shape[1]
    src, dst = tmp_path / "cube.f32", tmp_path / "chain.f32"
    np.ascontiguousarray(cube, np.float32).tofile(src)
    subprocess.run([REF, str(src), str(n), str(dst), str(levels), str(samples), method, weight, str(threads)],
                   check=True, timeout=60)
    flat = np.fromfile(dst, np.float32)
    out, at, s = [], 0, n
    while at < flat.size:
        k = 6 * s * s * 3
        out.append(flat[at:at + k].reshape(6, s, s, 3))
        at, s = at + k, max(1, s // 2)
    assert at == flat.size
    return out


def make_cube(n, seed):
    rng = np.random.default_rng(seed)
    cube = rng.random((6, n, n, 3)).astype(np.float32) ** 4 * 4  # high dynamic range
    cube[2, 3:5, n - 6:n - 4] = 200.0  # a sun on +Y, off the face centre
    cube[0, :, 0] = 30.0  # a bright column along a face edge: the seams matter
    return cube


@needs_ref
@pytest.mark.parametrize("levels,samples,method,weight", [
    (-1, 0, "fis", "n_dot_l"),  # the defaults
    (0, 48, "fis", "g1"),  # the full chain down to 1^2
    (3, 32, "importance", "n_dot_l"),
    (4, 0, "fast", "g1"),
])
def test_prefilter_equals_cpp_texel_by_texel(tmp_path, levels, samples, method, weight):
    cube = make_cube(16, 11)
    cpp = cpp_prefilter(tmp_path, cube, levels, samples, method, weight)
    py = ibl.prefilter(cube, levels=levels, samples=samples, method=method, weight=weight, threads=2)
    assert [l.shape for l in py] == [l.shape for l in cpp]
    assert len(py) == {-1: 3, 0: 5, 3: 3, 4: 4}[levels]
    for k, (a, b) in enumerate(zip(py, cpp)):
        np.testing.assert_array_equal(a, b, err_msg=f"level {k}")  # same code, deterministic: equal bits
    np.testing.assert_array_equal(py[0], cube)  # level 0: the mirror copy of the source
    if weight == "n_dot_l":  # the NumPy GGX model's tabulated lobe gives the same texels
        for a, b in zip(ibl.prefilter(cube, levels=levels, samples=samples, method=method, model=GGXHeightCorrelated()),
                        cpp):
            np.testing.assert_allclose(a, b, rtol=1e-6)
