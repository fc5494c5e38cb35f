#!/usr/bin/env bash
# Installs (as root, with apt-get) the Debian packages a job needs, skipping those already present.
#   bash scripts/deps.sh bake   what the main job needs: build and run ibl-bake (compiler, CMake,
#                               Ninja, GLM, stb, OpenEXR, astc-encoder, Zstandard)
#   bash scripts/deps.sh        everything the tests, benchmarks and tools need (the test command):
#                               also clang, doctest, Google Benchmark, matplotlib, glslang, chromium,
#                               pybind11, the Python headers, pytest and NumPy (the Python module),
#                               xsimd (the benchmarks' hand-written SIMD comparison, BM_convolve_xsimd)
set -euo pipefail
bake=(cmake ninja-build g++ libglm-dev libstb-dev libopenexr-dev libastcenc-dev libzstd-dev)
all=("${bake[@]}" clang libclang-rt-14-dev doctest-dev libbenchmark-dev python3-matplotlib glslang-tools chromium
     pybind11-dev python3-dev python3-pytest python3-numpy libxsimd-dev)
case "${1:-all}" in
    bake) pkgs=("${bake[@]}") ;;
    all) pkgs=("${all[@]}") ;;
    *) echo "usage: deps.sh [bake|all]" >&2; exit 2 ;;
esac
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
