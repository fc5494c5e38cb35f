#!/usr/bin/env python3
"""Regenerates (or checks) the ibl-bake reports quoted in the docs.

A quoted report sits in a Markdown file between two markers:

    <!-- generated: ibl-bake ARGS -->
    ```
    ...the tool's stdout...
    ```
    <!-- end generated -->

ARGS are the tool's arguments as a user types them (relative paths from the repository root;
"--out DIR" is replaced by a scratch directory, whose name the output shows as DIR). The figures
in these blocks are therefore those of the program that produced them, never typed by hand.

    docs_reports.py --tool PATH --write FILE...   run each command and replace its block
    docs_reports.py --tool PATH --check FILE...   run each command and compare (exit 1 on drift)

--check ignores times (the ms column, "N ms", "N% of the run") and compares every other number
with a relative tolerance (--rtol, default 2%: the last printed digit moves between compilers
and -march settings); words must be equal. The tool's results do not depend on the thread count.
"""
import argparse
import os
import re
import shlex
import subprocess
import sys
import tempfile

BEGIN = re.compile(r"^<!-- generated: ibl-bake (.*) -->$")
END = "<!-- end generated -->"
NUM = re.compile(r"[-+]?(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?")


def run_tool(tool, args, root):
    argv = shlex.split(args)
    with tempfile.TemporaryDirectory() as tmp:
        shown = None
        for i, a in enumerate(argv):
            if a == "--out" and i + 1 < len(argv):
                shown = argv[i + 1]
                argv[i + 1] = os.path.join(tmp, "out")
        proc = subprocess.run([tool] + argv, cwd=root, capture_output=True, text=True)
        if proc.returncode != 0:
            raise RuntimeError(f"ibl-bake {args}: exit {proc.returncode}\n{proc.stderr}")
        out = proc.stdout
        if shown is not None:
            out = out.replace(os.path.join(tmp, "out"), shown)
        return out.rstrip("\n")


def blocks(lines):
    """(begin index, end index, args) of each generated block."""
    i = 0
    while i < len(lines):
        m = BEGIN.match(lines[i])
        if m:
            j = i + 1
            while j < len(lines) and lines[j] != END:
                j += 1
            if j == len(lines):
                raise RuntimeError(f"line {i + 1}: no '{END}'")
            yield i, j, m.group(1)
            i = j
        i += 1


def masked(text):
    """The text with times masked: the ms column (found from the table header), 'N ms', 'N% of'."""
    out = []
    ms_end = None
    for line in text.split("\n"):
        h = line.find("  ms  error")
        if h >= 0:
            ms_end = h + 4  # just after the header's "ms": the column is right-aligned there
        elif ms_end is not None and len(line) >= ms_end and (len(line) == ms_end or line[ms_end] == " "):
            m = re.search(r"\d+\.\d+$", line[:ms_end])
            if m:
                line = line[: m.start()] + "T" + line[ms_end:]
        line = re.sub(r"\d+(?:\.\d+)?( ms)", r"T\1", line)
        line = re.sub(r"\d+(?:\.\d+)?% of the", "T% of the", line)
        line = re.sub(r"\b(source|specular|diffuse|dfg|lobe lut) \d+(?:\.\d+)?", r"\1 T", line)
        out.append(line)
    return "\n".join(out)


def differs(want, got, rtol):
    a, b = masked(want).split("\n"), masked(got).split("\n")
    if len(a) != len(b):
        return f"{len(a)} lines in the docs, {len(b)} from the tool"
    for k, (x, y) in enumerate(zip(a, b)):
        if NUM.sub("#", x).split() != NUM.sub("#", y).split():
            return f"line {k + 1}:\n  docs: {x}\n  tool: {y}"
        for p, q in zip(NUM.findall(x), NUM.findall(y)):
            u, v = float(p), float(q)
            if abs(u - v) > rtol * max(abs(u), abs(v)) and abs(u - v) > 1e-12:
                return f"line {k + 1}: {p} vs {q}\n  docs: {x}\n  tool: {y}"
    return None


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--tool", required=True)
    ap.add_argument("--rtol", type=float, default=0.02)
    mode = ap.add_mutually_exclusive_group(required=True)
    mode.add_argument("--write", action="store_true")
    mode.add_argument("--check", action="store_true")
    ap.add_argument("files", nargs="+")
    a = ap.parse_args()
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    tool = os.path.abspath(a.tool)
    failed = 0
    outputs = {}  # the same command in several files runs once
    for path in a.files:
        full = os.path.join(root, path) if not os.path.isabs(path) else path
        lines = open(full, encoding="utf-8").read().split("\n")
        found = list(blocks(lines))
        if not found:
            print(f"{path}: no generated block", file=sys.stderr)
            failed += 1
        for i, j, args in reversed(found):
            if args not in outputs:
                outputs[args] = run_tool(tool, args, root)
            got = outputs[args]
            body = lines[i + 1 : j]
            if a.write:
                lines[i + 1 : j] = ["```"] + got.split("\n") + ["```"]
                print(f"{path}:{i + 1}: ibl-bake {args}: {len(got.splitlines())} lines")
            else:
                want = "\n".join(l for l in body if l != "```")
                why = differs(want, got, a.rtol)
                if why:
                    failed += 1
                    print(f"{path}:{i + 1}: ibl-bake {args}: the docs differ from the tool's output ({why})\n"
                          f"regenerate: python3 scripts/docs_reports.py --tool {a.tool} --write {path}", file=sys.stderr)
                else:
                    print(f"{path}:{i + 1}: ibl-bake {args}: up to date")
        if a.write:
            open(full, "w", encoding="utf-8").write("\n".join(lines))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
