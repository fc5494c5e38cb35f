#!/usr/bin/env bash
# The main job, from a fresh Debian machine (as root): installs only what the bake needs
# (scripts/deps.sh bake: compiler, CMake, Ninja, GLM, stb, OpenEXR), builds ibl-bake alone (preset
# tool: -O3 -march=native, no tests, benchmarks or examples) and runs it on its built-in sky + sun
# (size 256, default quality, the default preset: the textbook products) into build/bake. It
# prints the report (product, method, time, error) and writes the baked products, preview.png
# and report.json.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/deps.sh bake
cmake --preset tool >/dev/null
cmake --build --preset tool --target ibl_bake
./build/tool/tools/ibl-bake/ibl-bake --out build/bake
