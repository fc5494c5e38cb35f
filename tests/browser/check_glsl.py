#!/usr/bin/python3
"""tests/browser/check_glsl.py: include/ibl/glsl/*.glsl compile as GLSL ES 3.00 and as GLSL 4.50
(glslangValidator, OpenGL semantics), with glsl_check_main.glsl calling every function; the
viewer's fragment shaders compile as GLSL ES 3.00 after the same files."""

import os
import subprocess
import sys

here = os.path.dirname(os.path.abspath(__file__))
repo = os.path.join(here, "..", "..")
glslang = sys.argv[1] if len(sys.argv) > 1 else "glslangValidator"
lib = "".join(open(os.path.join(repo, "include", "ibl", "glsl", f)).read() + "\n"
              for f in ("ibl_common.glsl", "ibl_lookup.glsl", "ibl_sh.glsl", "ibl_shade.glsl", "ibl_runtime.glsl",
                        "ibl_prefilter.glsl", "ibl_local_probe.glsl"))
es = "#version 300 es\nprecision highp float;\nprecision highp int;\nprecision highp samplerCube;\nprecision highp sampler2D;\n"
cases = [("ES 3.00, every function", es, "tests/browser/glsl_check_main.glsl"),
         ("4.50, every function", "#version 450\n", "tests/browser/glsl_check_main.glsl"),
         ("ES 3.00, viewer", es, "tools/viewer/viewer.frag.glsl"),
         ("ES 3.00, numeric grid", es, "tools/viewer/numeric.frag.glsl"),
         ("ES 3.00, prefilter", es, "tools/viewer/prefilter.frag.glsl"),
         ("ES 3.00, room example", es, "tools/viewer/room.frag.glsl")]
ok = True
for name, header, main in cases:
    src = header + lib + open(os.path.join(repo, main)).read()
    p = subprocess.run([glslang, "--stdin", "-S", "frag"], input=src, capture_output=True, text=True)
    print(f"{name}: {'ok' if p.returncode == 0 else 'FAILED'}")
    if p.returncode != 0:
        print(p.stdout + p.stderr)
        ok = False
# The include guards: a second concatenation of every file compiles too.
p = subprocess.run([glslang, "--stdin", "-S", "frag"], input=es + lib + lib + open(os.path.join(repo, cases[0][2])).read(),
                   capture_output=True, text=True)
print(f"ES 3.00, files concatenated twice: {'ok' if p.returncode == 0 else 'FAILED'}")
ok = ok and p.returncode == 0
sys.exit(0 if ok else 1)
