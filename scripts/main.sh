#!/usr/bin/env bash
# The main job, from a fresh Debian machine (as root): installs missing packages, builds the
# release preset and runs the foundation example, which prints a table computed by the library.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/deps.sh
cmake --preset release >/dev/null
cmake --build --preset release --target foundation_table
./build/release/examples/foundation_table
