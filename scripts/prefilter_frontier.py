#!/usr/bin/env python3
"""The prefilter's error-against-time frontier, measured by ibl-bake itself.

For each input (the shared HDRIs given with --input, and the built-in sky + sun) and each filter
setting (filtered importance sampling and the fast filter at --quality low / default / high, the
fast filter without its peak split, and without its rough levels by spherical harmonics), runs

    ibl-bake [--input F] --prefilter M [--quality Q] [--fast-peaks 0] --threads 2 --out DIR

`--repeat` times and reads report.json: the specular stage's time (median of the runs) and the
relative RMSE of every level >= 1 as the tool's check reports it (the same texels and reference for
every setting). Writes the Markdown table (stdout, or --table FILE) and, with --plot FILE, one
panel per level of error against time (log-log), a line per input and filter.

    python3 scripts/prefilter_frontier.py --tool build/release/tools/ibl-bake/ibl-bake \\
        --input ../shared/data/courtyard.exr --input ../shared/data/studio.exr \\
        --plot docs/prefilter-frontier.png --table /tmp/frontier.md

(the plot needs matplotlib: Debian's python3-matplotlib, /usr/bin/python3)

docs/ibl-bake.md ("Fast filter") quotes its output.
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile

SETTINGS = [
    ("fis", ["--prefilter", "fis", "--quality", "low"], "fis low"),
    ("fis", ["--prefilter", "fis"], "fis default"),
    ("fis", ["--prefilter", "fis", "--quality", "high"], "fis high"),
    ("fast", ["--prefilter", "fast", "--quality", "low"], "fast low"),
    ("fast", ["--prefilter", "fast"], "fast default"),
    ("fast", ["--prefilter", "fast", "--quality", "high"], "fast high"),
    ("fast0", ["--prefilter", "fast", "--fast-peaks", "0"], "fast default, no peak split"),
    ("fastsh0", ["--prefilter", "fast", "--fast-sh-bands", "0"], "fast default, tap sets on every level (no SH levels)"),
    ("fastmid0", ["--prefilter", "fast", "--fast-mid-tail", "0"], "fast default, no intermediate coarse tail"),
]


def run(tool, inp, args, repeat, threads):
    times, levels, samples = [], None, None
    for _ in range(repeat):
        with tempfile.TemporaryDirectory() as out:
            cmd = [tool] + (["--input", inp] if inp else []) + args + ["--threads", str(threads), "--quiet", "--out", out]
            subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
            with open(os.path.join(out, "report.json")) as f:
                spec = json.load(f)["specular"]
        times.append(spec["time_ms"])
        levels = [lv["rel_rmse"] for lv in spec["levels"][1:]]
        samples = spec["levels"][1]["samples"] if len(spec["levels"]) > 1 else 0
    return statistics.median(times), levels, samples


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--tool", required=True)
    ap.add_argument("--input", action="append", default=[], help="an HDRI (repeatable); the built-in sky is always added")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--plot")
    ap.add_argument("--table")
    ap.add_argument("--json", help="also write the measured rows here")
    ap.add_argument("--from-json", help="table and plot from rows written by --json (no runs)")
    a = ap.parse_args()
    inputs = [(os.path.splitext(os.path.basename(p))[0], p) for p in a.input] + [("sky", None)]
    rows = []
    if a.from_json:
        with open(a.from_json) as f:
            rows = json.load(f)
        inputs = list(dict.fromkeys((r["input"], None) for r in rows))
    for name, path in ([] if a.from_json else inputs):
        for kind, args, label in SETTINGS:
            t, lv, n = run(a.tool, path, args, a.repeat, a.threads)
            rows.append({"input": name, "kind": kind, "setting": label, "time_ms": t, "levels": lv, "samples": n})
            print(f"{name:10s} {label:28s} {t:8.1f} ms  " + " ".join(f"{e:.4f}" for e in lv), file=sys.stderr)
    lines = ["| input | filter | N at level 1 | time | levels 1-5 rel RMSE |", "|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['input']} | {r['setting']} | {r['samples']} | {r['time_ms']:.0f} ms | "
                     + " ".join(f"{e:.3g}" for e in r["levels"]) + " |")
    table = "\n".join(lines) + "\n"
    if a.table:
        with open(a.table, "w") as f:
            f.write(table)
    else:
        sys.stdout.write(table)
    if a.json:
        with open(a.json, "w") as f:
            json.dump(rows, f, indent=1)
    if a.plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        nlev = max(len(r["levels"]) for r in rows)
        fig, axes = plt.subplots(1, nlev, figsize=(3.2 * nlev, 3.4), sharey=True)
        colours = {"courtyard": "tab:green", "studio": "tab:purple", "sky": "tab:blue"}
        for li in range(nlev):
            ax = axes[li] if nlev > 1 else axes
            for name, _ in inputs:
                for kind, style in (("fis", "s--"), ("fast", "o-")):
                    pts = [(r["time_ms"], r["levels"][li]) for r in rows if r["input"] == name and r["kind"] == kind]
                    if pts:
                        ax.plot([p[0] for p in pts], [p[1] for p in pts], style, color=colours.get(name, "k"),
                                label=f"{name} {kind}", ms=4)
                for r in rows:
                    if r["input"] == name and r["kind"] == "fast0":
                        ax.plot(r["time_ms"], r["levels"][li], "x", color=colours.get(name, "k"), ms=6)
                    if r["input"] == name and r["kind"] == "fastsh0":
                        ax.plot(r["time_ms"], r["levels"][li], "+", color=colours.get(name, "k"), ms=7)
                    if r["input"] == name and r["kind"] == "fastmid0":
                        ax.plot(r["time_ms"], r["levels"][li], "1", color=colours.get(name, "k"), ms=8)
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.set_title(f"level {li + 1}")
            ax.set_xlabel("specular time (ms)")
            ax.grid(True, which="both", alpha=0.3)
        (axes[0] if nlev > 1 else axes).set_ylabel("rel RMSE (ibl-bake check)")
        (axes[-1] if nlev > 1 else axes).legend(fontsize=6)
        fig.suptitle("Prefilter error against time: FIS (squares) and the fast filter (circles; x = no peak split, "
                     "+ = tap sets on every level, Y = no intermediate coarse tail)",
                     fontsize=9)
        fig.tight_layout()
        fig.savefig(a.plot, dpi=110)


if __name__ == "__main__":
    main()
