#!/usr/bin/env bash
# The main job, from a fresh Debian machine (as root): installs missing packages, builds the
# release preset's ibl-bake tool and runs it on its built-in sky + sun (size 256, default
# quality) into build/bake. It prints the report table (product, method, cost knob, time, error)
# and writes the baked products, preview.png and report.json.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/deps.sh
cmake --preset release >/dev/null
cmake --build --preset release --target ibl_bake
./build/release/tools/ibl-bake/ibl-bake --out build/bake
