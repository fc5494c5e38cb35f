#!/usr/bin/python3
"""scripts/compression_report.py: the shaded-error table of docs/ibl-bake.md, "Compressed HDR
outputs". Bakes the built-in sky and tests/data/{courtyard,studio}.exr (256^2, the default preset,
2 threads) with each block format and reads the compression check of each report.json: encode
time, bits per texel, the worst level's RMSLE, the seam step before and after, the chain lookup's
relative RMSE at r >= 0.25 and the preview grid's, from the compressed files against the float
products.

    python3 scripts/compression_report.py --tool build/release/tools/ibl-bake/ibl-bake
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--tool", required=True)
    ap.add_argument("--data", default=os.path.join(os.path.dirname(__file__), "..", "tests", "data"))
    ap.add_argument("--formats", default="bc6h:fast,bc6h:normal,astc4x4:normal,astc6x6:normal")
    a = ap.parse_args()
    inputs = [("built-in sky", None)] + [(f, os.path.join(a.data, f)) for f in ("courtyard.exr", "studio.exr")]
    print("| input | format, effort | encode ms | bits/texel | worst level RMSLE | seam step (float -> compressed, worst level) "
          "| lookup rel RMSE r >= 0.25 | preview rel RMSE |")
    print("|---|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        for name, path in inputs:
            for spec in a.formats.split(","):
                fmt, quality = spec.split(":")
                out = os.path.join(tmp, "bake")
                cmd = [a.tool, "--quiet", "--threads", "2", "--out", out, "--ktx2-format", fmt, "--ktx2-quality", quality]
                if path:
                    cmd += ["--input", path]
                subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
                c = json.load(open(os.path.join(out, "report.json")))["compression"]
                worst = max(c["levels"], key=lambda l: l["rmsle"])
                seam = max(c["levels"], key=lambda l: l["seam_step_compressed"] - l["seam_step_float"])
                print(f"| {name} | {fmt} {quality} | {c['encode_ms']:.0f} | {c['bits_per_texel']:.2f} | "
                      f"{worst['rmsle']:.4f} (l{worst['level']}) | {seam['seam_step_float']:.3f} -> {seam['seam_step_compressed']:.3f} "
                      f"(l{seam['level']}) | {c['lookup']['rel_rmse_r_ge_0_25']:.4f} | {c['preview_rel_rmse']:.4f} |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
