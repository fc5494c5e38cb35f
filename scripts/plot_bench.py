#!/usr/bin/env python3
"""Google Benchmark JSON -> log-log plot (PNG and SVG) of an error counter against time.

    /usr/bin/python3 scripts/plot_bench.py -o OUT --y max_abs_err [options] run1.json [run2.json ...]

Every iteration row (aggregates and failed runs are skipped) is one point: x = time per iteration
in ms (real_time by default), y = the chosen counter. Points are grouped into curves, one per
method: with --curve 'LABEL=REGEX[=YSPEC[=dashed]]' the rows whose run name matches REGEX (a row
joins every curve that matches, so it can give a point on an error curve and one on a
standard-error curve); without --curve, one curve per family = the run name minus its knob
argument (BM_fis/env:0/spp:64/real_time -> BM_fis/env:0/real_time). The knob (--knob NAME,
default: the last argument of the name) orders the points along a curve and is what --annotate
prints.

Writes OUT.png and OUT.svg (each through a temporary file, so a failed run leaves no partial
plot). Unless -q, prints the curves and their points. Exit status: 0 written; 1 bad input
(unreadable, not JSON, not benchmark output, counter missing, nothing to plot); 2 bad usage.
Needs matplotlib (Debian: python3-matplotlib, run with /usr/bin/python3).
"""
import argparse
import json
import math
import os
import re
import sys

PROG = "plot_bench.py"
TIME_UNIT_MS = {"ns": 1e-6, "us": 1e-3, "ms": 1.0, "s": 1e3}
OPTION_TOKENS = {"real_time", "manual_time", "process_time", "threads", "min_time",
                 "min_warmup_time", "iterations", "repeats"}
BOOKKEEPING = {"family_index", "per_family_instance_index", "repetitions", "repetition_index", "threads",
               "iterations", "real_time", "cpu_time"}
REDUCTIONS = {"max": max, "min": min, "mean": lambda v: sum(v) / len(v),
              "rms": lambda v: math.sqrt(sum(x * x for x in v) / len(v))}
LEGEND_LOC = {"auto": "best", "tl": "upper left", "tr": "upper right", "bl": "lower left",
              "br": "lower right", "right": "upper left"}
MARKERS = "os^Dvp"


class InputError(Exception):
    """Bad input data: exit status 1."""


def parse_number(text):
    try:
        return float(text)
    except ValueError:
        return None


class Row:
    """One iteration row: run name, its arguments [(name, value, token index)], times, counters."""

    def __init__(self, entry, where):
        self.name = entry.get("run_name") or entry.get("name")
        if not isinstance(self.name, str):
            raise InputError(f'{where} has no "name"')
        unit = entry.get("time_unit", "ns")
        if unit not in TIME_UNIT_MS:
            raise InputError(f'{where}: {self.name}: unknown time_unit "{unit}"')
        # every numeric member (bool is an int in Python: not a number here)
        self.numbers = {k: float(v) for k, v in entry.items()
                        if isinstance(v, (int, float)) and not isinstance(v, bool)}
        if "real_time" not in self.numbers or "cpu_time" not in self.numbers:
            raise InputError(f"{where}: {self.name}: no numeric real_time / cpu_time")
        self.times = {t: self.numbers[t] * TIME_UNIT_MS[unit] for t in ("real_time", "cpu_time")}
        self.tokens = self.name.split("/")
        self.args, unnamed = [], 0
        for k, tok in enumerate(self.tokens[1:], start=1):
            key, colon, value = tok.partition(":")
            if not colon:
                key, value, unnamed = f"arg{unnamed}", tok, unnamed + (parse_number(tok) is not None)
            if key in OPTION_TOKENS or parse_number(value) is None:
                continue
            self.args.append((key, parse_number(value), k))

    def knob(self, name):
        """(name, value, token) of the knob argument, or None."""
        if not name:
            return self.args[-1] if self.args else None
        return next((a for a in self.args if a[0] == name), None)

    def family(self, knob):
        k = self.knob(knob)
        return "/".join(t for i, t in enumerate(self.tokens) if not k or i != k[2])


def load_rows(path):
    """The iteration rows of one Google Benchmark JSON file and the number of failed runs skipped."""
    try:
        with open(path, encoding="utf-8") as f:
            text = f.read()
    except (OSError, UnicodeDecodeError) as e:
        raise InputError(f"{path}: cannot open: {getattr(e, 'strerror', None) or e}") from None
    if not text.strip():
        raise InputError(f"{path}: empty file (malformed JSON)")
    try:
        doc = json.loads(text)  # accepts the NaN / Infinity that Google Benchmark writes
    except json.JSONDecodeError as e:
        raise InputError(f"{path}:{e.lineno}:{e.colno}: {e.msg} (malformed JSON)") from None
    if not isinstance(doc, dict) or not isinstance(doc.get("benchmarks"), list):
        raise InputError(f'{path}: not a Google Benchmark JSON document (no "benchmarks" array)')
    rows, failed = [], 0
    for i, entry in enumerate(doc["benchmarks"]):
        where = f"{path}: benchmarks[{i}]"
        if not isinstance(entry, dict):
            raise InputError(f"{where} is not an object")
        if entry.get("error_occurred") is True:
            failed += 1
        elif entry.get("run_type") != "aggregate":
            rows.append(Row(entry, where))
    return rows, failed


def y_spec(text):
    """'counter' or 'FUNC(a,b,...)' -> (text, reduction or None, [counters])."""
    m = re.fullmatch(r"\s*(\w+)\s*\((.*)\)\s*", text)
    if not m:
        if not text or "(" in text or ")" in text:
            raise argparse.ArgumentTypeError(f"bad counter expression '{text}'")
        return text, None, [text]
    if m.group(1) not in REDUCTIONS:
        raise argparse.ArgumentTypeError(f"unknown reduction '{m.group(1)}' in '{text}' (max, min, mean, rms)")
    counters = [c.strip() for c in m.group(2).split(",")]
    if not all(counters):
        raise argparse.ArgumentTypeError(f"empty counter name in '{text}'")
    return text, m.group(1), counters


def curve_spec(text):
    """'LABEL=REGEX[=YSPEC[=dashed|solid]]' -> dict."""
    f = text.split("=")
    if not 2 <= len(f) <= 4 or not f[0] or not f[1]:
        raise argparse.ArgumentTypeError(f"bad --curve '{text}' (expected LABEL=REGEX[=YSPEC[=dashed]])")
    if len(f) == 4 and f[3] not in ("dashed", "solid"):
        raise argparse.ArgumentTypeError(f"bad line style '{f[3]}' (dashed or solid)")
    return {"label": f[0], "pattern": f[1], "re": regex(f[1]),
            "y": y_spec(f[2]) if len(f) > 2 and f[2] else None, "dashed": len(f) == 4 and f[3] == "dashed"}


def regex(text):
    try:
        return re.compile(text)
    except re.error as e:
        raise argparse.ArgumentTypeError(f"bad regular expression '{text}': {e}")


def size(text):
    m = re.fullmatch(r"(\d+)x(\d+)", text)
    if not m or int(m.group(1)) < 320 or int(m.group(2)) < 240 or max(map(int, m.groups())) > 20000:
        raise argparse.ArgumentTypeError(f"bad --size '{text}' (WxH, at least 320x240)")
    return int(m.group(1)), int(m.group(2))


def parse_args(argv):
    p = argparse.ArgumentParser(prog=PROG, description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("inputs", nargs="+", metavar="FILE.json", help="Google Benchmark JSON output")
    p.add_argument("-o", "--output", required=True, help="output path without extension (.png/.svg stripped)")
    p.add_argument("--format", default="png,svg", help="comma-separated formats to write (default png,svg)")
    p.add_argument("--y", required=True, type=y_spec, metavar="SPEC",
                   help="y: a counter, or max(a,b,..) / min(..) / mean(..) / rms(..) of counters")
    p.add_argument("--x", default="real_time", help="x: real_time (default) or cpu_time per iteration in ms, "
                   "knob (the knob's value) or a counter")
    p.add_argument("--knob", default="", help="the argument varying along a curve (default: the last one)")
    p.add_argument("--curve", action="append", type=curve_spec, default=[], metavar="LABEL=REGEX[=YSPEC[=dashed]]",
                   help="a curve of the rows whose name matches REGEX (repeatable); YSPEC overrides --y")
    p.add_argument("--filter", type=regex, help="without --curve: keep only rows whose name matches")
    p.add_argument("--title", default="")
    p.add_argument("--xlabel", default="")
    p.add_argument("--ylabel", default="")
    p.add_argument("--size", type=size, default=(960, 600), metavar="WxH", help="pixels (default 960x600)")
    p.add_argument("--legend", choices=LEGEND_LOC, default="auto", help="inside (auto, tl, tr, bl, br) or right")
    p.add_argument("--annotate", choices=("none", "ends", "all"), default="none", help="print knob values at points")
    p.add_argument("-q", "--quiet", action="store_true", help="no table of the plotted points")
    a = p.parse_args(argv)
    if a.curve and a.filter:
        p.error("--filter applies only without --curve")
    a.format = a.format.split(",")
    if not a.format or not set(a.format) <= {"png", "svg"}:
        p.error(f"bad --format '{','.join(a.format)}' (png, svg)")
    a.output = re.sub(r"\.(png|svg)$", "", a.output)
    return a


def build_curves(rows, a):
    """[{label, dashed, points: [(x, y, knob, name)], missing: {counters: [row names]}}], sorted by knob."""
    def add(curve, row, spec):
        if a.x in row.times:
            x = row.times[a.x]
        elif a.x == "knob":
            k = row.knob(a.knob)
            if not k:
                raise InputError(f"{row.name}: no knob argument {a.knob!r} for --x knob")
            x = k[1]
        else:
            x = row.numbers.get(a.x)
        ys = [row.numbers.get(c) for c in spec[2]]
        absent = [c for c, v in zip([a.x] + spec[2], [x] + ys) if v is None]
        if absent:
            curve["missing"].setdefault(", ".join(absent), []).append(row.name)
            return
        y = REDUCTIONS[spec[1]](ys) if spec[1] else ys[0]
        if not (math.isfinite(x) and math.isfinite(y) and x > 0 and y > 0):
            print(f"{PROG}: warning: {row.name}: (x, y) = ({x:g}, {y:g}) cannot be shown on log axes; dropped",
                  file=sys.stderr)
            return
        k = row.knob(a.knob)
        curve["points"].append((x, y, k[1] if k else None, row.name))

    def new_curve(label, dashed=False):
        return {"label": label, "dashed": dashed, "points": [], "missing": {}}

    curves = []
    for c in a.curve:
        curve = new_curve(c["label"], c["dashed"])
        matched = [r for r in rows if c["re"].search(r.name)]
        if not matched:
            raise InputError(f"curve '{c['label']}': no benchmark name matches '{c['pattern']}'")
        for r in matched:
            add(curve, r, c["y"] or a.y)
        curves.append(curve)
    if not a.curve:
        families = {}
        for r in (r for r in rows if a.filter is None or a.filter.search(r.name)):
            add(families.setdefault(r.family(a.knob), new_curve(r.family(a.knob))), r, a.y)
        curves = list(families.values())
    present = ", ".join(sorted({k for r in rows for k in r.numbers} - BOOKKEEPING)) or "none"
    for c in curves:
        for counter, names in c["missing"].items():
            if not c["points"] and (a.curve or not any(d["points"] for d in curves)):
                raise InputError(f"curve '{c['label']}': no row has counter '{counter}' (counters: {present})")
            print(f"{PROG}: warning: curve '{c['label']}': {len(names)} row(s) without counter '{counter}' "
                  f"skipped ({names[0]}{', ...' if len(names) > 1 else ''})", file=sys.stderr)
        by_knob = all(p[2] is not None for p in c["points"])
        c["points"].sort(key=lambda p: (p[2], p[0]) if by_knob else p[0])
    if not any(c["points"] for c in curves):
        raise InputError("nothing to plot: no benchmark row with positive, finite x and y")
    return curves


def label_log_axis(axis, lo, hi):
    """Tick labels of a log axis: plain decimals within [1e-3, 1e4], else m x 10^k; on an axis of
    under two decades also 2 and 5 (under 0.7 decades every digit) between the powers of ten."""
    from matplotlib.ticker import FuncFormatter
    plain = lo >= 0.999e-3 and hi <= 1.001e4
    digits = set(range(2, 10)) if math.log10(hi / lo) < 0.7 else {2, 5} if math.log10(hi / lo) < 2 else set()

    def split(v):
        k = math.floor(math.log10(v) + 1e-9)
        return round(v / 10 ** k), k

    def text(v, _=None):
        m, k = split(v)
        return f"{v:g}" if plain else f"$10^{{{k}}}$" if m == 1 else f"${m}\\times10^{{{k}}}$"
    axis.set_major_formatter(FuncFormatter(text))
    axis.set_minor_formatter(FuncFormatter(lambda v, _: text(v) if split(v)[0] in digits else ""))


def plot(curves, a):
    os.environ.setdefault("MPLBACKEND", "Agg")
    import matplotlib
    matplotlib.rcParams.update({"svg.hashsalt": "plot_bench",  # identical SVG for identical input
                                "font.size": 11, "legend.fontsize": 10, "legend.framealpha": 0.9})
    import matplotlib.pyplot as plt

    dpi = 100
    fig, ax = plt.subplots(figsize=(a.size[0] / dpi, a.size[1] / dpi), dpi=dpi, layout="constrained")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.grid(True, which="major", color="#d0d0d0", linewidth=0.8)
    ax.grid(True, which="minor", color="#ececec", linewidth=0.5)
    ax.set_axisbelow(True)
    ax.margins(0.06)
    for i, c in enumerate(curves):
        if not c["points"]:
            continue
        xs, ys, knobs, _ = zip(*c["points"])
        line, = ax.plot(xs, ys, label=c["label"], marker=MARKERS[i % len(MARKERS)], markersize=5,
                        linewidth=1.6, linestyle="--" if c["dashed"] else "-", color=f"C{i % 10}")
        for j, (x, y, k) in enumerate(zip(xs, ys, knobs)):
            if k is not None and (a.annotate == "all" or (a.annotate == "ends" and j in (0, len(xs) - 1))):
                ax.annotate(f"{k:.6g}", (x, y), xytext=(4, 4), textcoords="offset points", fontsize=8,
                            color=line.get_color())
    xlabel = a.xlabel or {"real_time": "time per iteration (ms, wall clock)", "cpu_time": "CPU time per iteration (ms)",
                          "knob": a.knob or "argument"}.get(a.x, a.x)
    ylabel = a.ylabel or a.y[0]
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(a.title or f"{ylabel} against {xlabel}")
    label_log_axis(ax.xaxis, *ax.get_xlim())
    label_log_axis(ax.yaxis, *ax.get_ylim())
    ax.legend(loc=LEGEND_LOC[a.legend], bbox_to_anchor=(1.02, 1.0) if a.legend == "right" else None)
    written = []
    for fmt in a.format:
        path, tmp = f"{a.output}.{fmt}", f"{a.output}.{fmt}.tmp"
        try:
            fig.savefig(tmp, format=fmt, metadata={"Date": None} if fmt == "svg" else None)
            os.replace(tmp, path)
        except OSError as e:
            if os.path.exists(tmp):
                os.remove(tmp)
            raise InputError(f"{path}: cannot write: {e.strerror or e}") from None
        written.append(path)
    plt.close(fig)
    return written


def main(argv=None):
    a = parse_args(sys.argv[1:] if argv is None else argv)
    try:
        rows, failed = [], 0
        for path in a.inputs:
            r, f = load_rows(path)
            if not r:
                print(f"{PROG}: warning: {path}: no benchmark rows", file=sys.stderr)
            rows, failed = rows + r, failed + f
        if failed:
            print(f"{PROG}: warning: skipped {failed} failed benchmark run(s)", file=sys.stderr)
        curves = build_curves(rows, a)
        written = plot(curves, a)
    except InputError as e:
        print(f"{PROG}: error: {e}", file=sys.stderr)
        return 1
    if not a.quiet:
        for c in curves:
            print(f"curve '{c['label']}': {len(c['points'])} points{' (dashed)' if c['dashed'] else ''}")
            for x, y, k, name in c["points"]:
                print(f"  x {x:<12.5g} y {y:<12.5g} knob {'-' if k is None else f'{k:g}':<8} {name}")
        print(f"wrote {' '.join(written)} ({a.size[0]}x{a.size[1]})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
