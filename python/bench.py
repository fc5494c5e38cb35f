"""Timings of docs/python.md, "Measured" (not a test). Run from the repository root:

    PYTHONPATH=build/dev/python python3 python/bench.py dfg        # 64^2 DFG table, C++ vs NumPy model
    PYTHONPATH=build/dev/python python3 python/bench.py prefilter  # 256^2 prefilter from Python

Each figure is the median of interleaved runs (C++ and Python alternate), so that a load change on
a shared machine hits both sides alike.
"""
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent / "tests"))
import ibl  # noqa: E402
from conftest import GGXHeightCorrelated  # noqa: E402  (the NumPy restatement used by the tests)


def interleaved(fns, repeats):
    times = [[] for _ in fns]
    for _ in range(repeats):
        for t, f in zip(times, fns):
            t0 = time.perf_counter()
            f()
            t.append(time.perf_counter() - t0)
    return [statistics.median(t) for t in times]


def bench_dfg(repeats=11):
    model = GGXHeightCorrelated()
    ibl.dfg_lut(64, model)  # warm-up
    c, p = interleaved([lambda: ibl.dfg_lut(64, threads=1), lambda: ibl.dfg_lut(64, model)], repeats)
    print(f"64^2 dfg_lut: C++ model (1 thread) {c * 1e3:.1f} ms, NumPy model {p * 1e3:.1f} ms, "
          f"ratio {p / c:.2f} (medians of {repeats})")
    import numpy as np
    nv, r = np.meshgrid(np.linspace(0.0, 1.0, 64), np.linspace(0.0, 1.0, 64))
    c, p = interleaved([lambda: ibl.dfg(nv, r, threads=1), lambda: ibl.dfg(nv, r, model)], max(3, repeats // 2))
    print(f"64^2 points dfg (double): C++ model (1 thread) {c * 1e3:.1f} ms, NumPy model {p * 1e3:.1f} ms, "
          f"ratio {p / c:.2f}")


def bench_prefilter(repeats=5, size=256):
    """ibl.prefilter (default options) against the same chain computed by the C++ program
    ibl_python_prefilter_ref (python/tests/prefilter_ref.cpp; its own timer around cubemap +
    generate_mips + prefilter, so process start and file I/O are not counted), 1 thread and all
    cores, interleaved. The cube: tests/data/courtyard.exr at size^2 when the readers are built."""
    import os
    import subprocess
    import tempfile

    import numpy as np
    root = Path(__file__).resolve().parents[1]
    exe = os.environ.get("IBL_PREFILTER_REF_EXE", str(root / "build/dev/python/ibl_python_prefilter_ref"))
    if ibl.has_image_io:
        cube = ibl.cube_from_latlong(ibl.read_image(str(root / "tests/data/courtyard.exr"), latlong=True), size)
        what = "courtyard"
    else:
        cube = (np.random.default_rng(1).random((6, size, size, 3)) ** 4 * 8).astype(np.float32)
        what = "random"
    with tempfile.TemporaryDirectory() as tmp:
        src, dst = Path(tmp) / "cube.f32", Path(tmp) / "chain.f32"
        cube.tofile(src)
        for threads in (1, 0):
            nthreads = threads if threads else (os.cpu_count() or 1)
            py, cpp = [], []
            for _ in range(repeats):
                t0 = time.perf_counter()
                ibl.prefilter(cube, threads=threads)
                py.append(time.perf_counter() - t0)
                out = subprocess.run([exe, str(src), str(size), str(dst), "-1", "0", "fis", "n_dot_l", str(nthreads),
                                      "--time"], check=True, capture_output=True, text=True).stdout
                cpp.append(float(out.split()[1]))
            p, c = statistics.median(py), statistics.median(cpp)
            print(f"{size}^2 prefilter ({what}, default options), {nthreads} thread(s): Python {p:.3f} s, "
                  f"C++ {c:.3f} s, Python / C++ {p / c:.3f} (medians of {repeats}, interleaved; "
                  f"Python runs {', '.join(f'{x:.2f}' for x in py)}; C++ {', '.join(f'{x:.2f}' for x in cpp)})")


if __name__ == "__main__":
    what = sys.argv[1] if len(sys.argv) > 1 else "dfg"
    {"dfg": bench_dfg, "prefilter": bench_prefilter}[what]()
