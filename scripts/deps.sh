#!/usr/bin/env bash
# Installs (as root, with apt-get) the Debian packages that the build, tests, benchmarks and
# tools need, skipping those already present.
set -euo pipefail
pkgs=(cmake ninja-build g++ clang libclang-rt-14-dev libglm-dev doctest-dev libbenchmark-dev libstb-dev libopenexr-dev python3-matplotlib glslang-tools chromium)
missing=()
for p in "${pkgs[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
    echo "== installing: ${missing[*]}"
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq
    apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
