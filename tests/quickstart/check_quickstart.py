#!/usr/bin/python3
"""tests/quickstart/check_quickstart.py: README.md's code blocks are the tested sources.

  readme  every ```cpp and ```glsl block of README.md follows a marker line
          `<!-- snippet: FILE NAME -->` and equals, line for line, the lines of FILE between its
          two `// [readme:NAME]` lines (examples/quickstart.cpp, examples/quickstart_*.glsl);
          every marker names an existing region and is followed by a block.
  glsl    glslangValidator compiles examples/quickstart_library.glsl after the library's GLSL
          includes and examples/quickstart_textbook.glsl alone, each as GLSL ES 3.00 and 4.50.

The example program itself (examples/quickstart.cpp, ctest `quickstart`) checks its results.
Exit status 0 = pass.
"""

import os
import re
import subprocess
import sys

here = os.path.dirname(os.path.abspath(__file__))
repo = os.path.normpath(os.path.join(here, "..", ".."))


def region(path, name):
    """The lines strictly between the two `// [readme:NAME]` lines of path."""
    lines = open(os.path.join(repo, path)).read().split("\n")
    marks = [i for i, l in enumerate(lines) if l.strip() == f"// [readme:{name}]"]
    if len(marks) != 2:
        raise SystemExit(f"{path}: expected two '// [readme:{name}]' lines, found {len(marks)}")
    return lines[marks[0] + 1:marks[1]]


def check_readme():
    lines = open(os.path.join(repo, "README.md")).read().split("\n")
    ok, blocks, marker = True, 0, None
    i = 0
    while i < len(lines):
        m = re.fullmatch(r"<!-- snippet: (\S+) (\S+) -->", lines[i].strip())
        if m:
            marker = (m.group(1), m.group(2), i + 1)
            i += 1
            continue
        fence = re.fullmatch(r"```(\w*)", lines[i])
        if fence:
            end = next(j for j in range(i + 1, len(lines)) if lines[j] == "```")
            body = lines[i + 1:end]
            if fence.group(1) in ("cpp", "glsl"):
                blocks += 1
                if marker is None:
                    print(f"README.md:{i + 1}: a ```{fence.group(1)} block without a '<!-- snippet: FILE NAME -->' line")
                    ok = False
                else:
                    path, name, at = marker
                    want = region(path, name)
                    if body != want:
                        ok = False
                        print(f"README.md:{i + 1}: block differs from {path} [readme:{name}] (marker line {at})")
                        for k in range(max(len(body), len(want))):
                            a = body[k] if k < len(body) else "<missing>"
                            b = want[k] if k < len(want) else "<missing>"
                            if a != b:
                                print(f"  first difference, line {k + 1}:\n    README: {a}\n    source: {b}")
                                break
                    else:
                        print(f"README.md:{i + 1}: = {path} [readme:{name}] ({len(body)} lines)")
            elif marker is not None:
                print(f"README.md:{marker[2]}: a snippet marker before a ```{fence.group(1)} block")
                ok = False
            marker = None
            i = end + 1
            continue
        if marker is not None and lines[i].strip():
            print(f"README.md:{marker[2]}: a snippet marker not followed by a code block")
            ok = False
            marker = None
        i += 1
    if blocks == 0:
        print("README.md: no ```cpp or ```glsl block found")
        ok = False
    return ok


def check_glsl(glslang):
    glsl_dir = os.path.join(repo, "include", "ibl", "glsl")
    lib = "".join(open(os.path.join(glsl_dir, f)).read() + "\n"
                  for f in ("ibl_common.glsl", "ibl_lookup.glsl", "ibl_sh.glsl", "ibl_shade.glsl"))
    es = "#version 300 es\nprecision highp float;\nprecision highp int;\nprecision highp samplerCube;\n"
    ok = True
    for name, prefix in (("quickstart_library.glsl", lib), ("quickstart_textbook.glsl", "")):
        src = open(os.path.join(repo, "examples", name)).read()
        for version, header in (("ES 3.00", es), ("4.50", "#version 450\n")):
            p = subprocess.run([glslang, "--stdin", "-S", "frag"], input=header + prefix + src,
                               capture_output=True, text=True)
            print(f"{name}, {version}: {'ok' if p.returncode == 0 else 'FAILED'}")
            if p.returncode != 0:
                print(p.stdout + p.stderr)
                ok = False
    return ok


if __name__ == "__main__":
    mode = sys.argv[1] if len(sys.argv) > 1 else ""
    if mode == "readme":
        sys.exit(0 if check_readme() else 1)
    if mode == "glsl":
        sys.exit(0 if check_glsl(sys.argv[2] if len(sys.argv) > 2 else "glslangValidator") else 1)
    raise SystemExit("usage: check_quickstart.py readme | glsl [glslangValidator]")
