"""Runs scripts/plot_bench.py on the fixtures next to this file (ctest: plot_bench_script).

    /usr/bin/python3 tests/plot/test_plot_bench.py SCRIPT WORK_DIR

Good input: the PNG and SVG exist, are valid and of the requested size, and the printed summary
names the expected curves with the expected points (units converted to ms, aggregates and failed
runs skipped, reductions applied). Bad input: exit 1 with a message and no plot left behind; bad
command lines: exit 2.
"""
import os
import re
import shutil
import struct
import subprocess
import sys
import xml.etree.ElementTree as ET

SCRIPT, WORK = sys.argv[1], sys.argv[2]
DATA = os.path.dirname(os.path.abspath(__file__))
FIXTURE = os.path.join(DATA, "fixture.json")
failures = []


def check(cond, what):
    if not cond:
        failures.append(what)
        print(f"FAIL: {what}")


def run(*args, rc=0):
    p = subprocess.run([sys.executable, SCRIPT, *args], capture_output=True, text=True, timeout=60)
    check(p.returncode == rc, f"{' '.join(args)}: exit {p.returncode}, expected {rc}\n{p.stdout}{p.stderr}")
    return p


def curves(stdout):
    """{label: [(x, y, knob), ...]} from the summary the script prints."""
    out, label = {}, None
    for line in stdout.splitlines():
        if m := re.match(r"curve '(.*)': (\d+) points", line):
            label = m.group(1)
            out[label] = []
        elif m := re.match(r"\s+x (\S+)\s+y (\S+)\s+knob (\S+)", line):
            out[label].append(tuple(None if v == "-" else float(v) for v in m.groups()))
    return out


def check_png(path, size):
    with open(path, "rb") as f:
        head = f.read(24)
    check(head[:8] == b"\x89PNG\r\n\x1a\n" and head[12:16] == b"IHDR", f"{path}: not a PNG")
    check(struct.unpack(">II", head[16:24]) == size, f"{path}: size {struct.unpack('>II', head[16:24])}, expected {size}")


def check_svg(path, labels):
    root = ET.parse(path).getroot()  # raises on malformed XML
    check(root.tag == "{http://www.w3.org/2000/svg}svg", f"{path}: root is {root.tag}")
    text = open(path, encoding="utf-8").read()
    for label in labels:  # matplotlib writes each text as a comment before its glyph paths
        check(f"<!-- {label} -->" in text, f"{path}: no text '{label}'")


def close(a, b):
    return abs(a - b) <= 1e-9 * abs(b)


shutil.rmtree(WORK, ignore_errors=True)
os.makedirs(WORK)
out = os.path.join(WORK, "ok")

# 1. explicit curves, a reduction, a dashed curve; times in ns, us, ms and s
p = run("-o", out + ".png", "--size", "640x400", "--y", "max_abs_err", "--title", "fixture", "--annotate", "all",
        "--curve", "MC=^BM_mc/", "--curve", "quadrature=^BM_exact/",
        "--curve", "fit=^BM_fit$=max(max_abs_err,rms_err)=dashed", FIXTURE)
c = curves(p.stdout)
check(list(c) == ["MC", "quadrature", "fit"], f"curves {list(c)}")
# the aggregate row (mean of spp:256) and the failed row (level:24) are not points
expect = {"MC": [(1.5, 0.2, 16), (6.0, 0.1, 64), (24.0, 0.05, 256)],
          "quadrature": [(3.0, 1e-3, 8), (11.0, 3e-6, 16)],
          "fit": [(0.12, 0.02, None)]}
for label, points in expect.items():
    got = c.get(label, [])
    check(len(got) == len(points) and all(close(g[0], e[0]) and close(g[1], e[1]) and g[2] == e[2]
                                          for g, e in zip(got, points)), f"curve {label}: {got}, expected {points}")
check("fit': 1 points (dashed)" in p.stdout, "fit is not dashed")
check("skipped 1 failed benchmark run" in p.stderr, f"no warning about the failed run: {p.stderr}")
check_png(out + ".png", (640, 400))
check_svg(out + ".svg", ["fixture", "MC", "quadrature", "fit", "256"])

# 2. one curve per family (name minus the knob), x = the knob, PNG only, default size
fam = os.path.join(WORK, "families")
p = run("-o", fam, "--format", "png", "--x", "knob", "--y", "rms_err", "--filter", "^BM_(mc|exact)/", FIXTURE)
c = curves(p.stdout)
check(list(c) == ["BM_mc/real_time", "BM_exact/real_time"], f"families {list(c)}")
check([pt[:2] for pt in c.get("BM_mc/real_time", [])] == [(16, 0.05), (64, 0.025), (256, 0.0125)],
      f"BM_mc against spp: {c.get('BM_mc/real_time')}")
check_png(fam + ".png", (960, 600))
check(not os.path.exists(fam + ".svg"), "--format png also wrote an SVG")

# 3. bad input: exit 1, a message naming the problem, no plot left behind
bad = os.path.join(WORK, "bad")
empty, other, none, agg = (os.path.join(WORK, n) for n in ("empty.json", "other.json", "none.json", "agg.json"))
open(empty, "w").close()
with open(other, "w") as f:
    f.write('{"context": {}, "items": [1, 2]}')
with open(none, "w") as f:
    f.write('{"context": {}, "benchmarks": []}')
with open(agg, "w") as f:  # only an aggregate and a failed run
    f.write('{"benchmarks": [{"name": "BM_a/1_mean", "run_name": "BM_a/1", "run_type": "aggregate",'
            ' "real_time": 1, "cpu_time": 1, "e": 1}, {"name": "BM_a/2", "error_occurred": true}]}')
for args, message in [
    (["--y", "max_abs_err", os.path.join(DATA, "malformed.json")], "malformed JSON"),
    (["--y", "max_abs_err", empty], "empty file"),
    (["--y", "max_abs_err", other], 'no "benchmarks" array'),
    (["--y", "max_abs_err", none], "nothing to plot"),
    (["--y", "e", agg], "nothing to plot"),
    (["--y", "no_such_counter", FIXTURE], "no row has counter 'no_such_counter'"),
    (["--y", "max_abs_err", "--curve", "fit=^BM_fit$=evals_per_texel", FIXTURE], "no row has counter 'evals_per_texel'"),
    (["--y", "max_abs_err", "--curve", "x=^BM_nothing", FIXTURE], "no benchmark name matches"),
    (["--y", "max_abs_err", os.path.join(WORK, "does_not_exist.json")], "cannot open"),
]:
    p = run("-o", bad, *args, rc=1)
    check(message in p.stderr, f"{args}: expected '{message}' in: {p.stderr}")
check(not any(n.startswith("bad") for n in os.listdir(WORK)), f"a failed run left a plot: {os.listdir(WORK)}")

# 4. bad command lines: exit 2
for args in [["--y", "max_abs_err", FIXTURE], ["-o", bad, "--y", "median(a,b)", FIXTURE],
             ["-o", bad, "--y", "max_abs_err", "--curve", "nolabel", FIXTURE],
             ["-o", bad, "--y", "max_abs_err", "--size", "10x10", FIXTURE]]:
    run(*args, rc=2)

print(f"{len(failures)} failure(s)")
sys.exit(1 if failures else 0)
