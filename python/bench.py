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


if __name__ == "__main__":
    what = sys.argv[1] if len(sys.argv) > 1 else "dfg"
    {"dfg": bench_dfg}[what]()
