#!/usr/bin/env bash
# The main job, from a fresh Debian machine (as root): installs missing packages, builds the
# release preset, prints the foundation table, then runs the ibl-bake tool on its built-in sky
# (size 256, default quality) into build/bake, which prints the report table (product, method,
# cost knob, time, error) and writes the baked products, preview.png and report.json.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/deps.sh
cmake --preset release >/dev/null
cmake --build --preset release --target foundation_table ibl_bake
./build/release/examples/foundation_table
echo
./build/release/examples/ibl_bake/ibl-bake --out build/bake
