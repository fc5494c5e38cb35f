#!/usr/bin/env bash
# The project's whole test run, from a fresh Debian machine (as root):
#   1. installs missing packages (scripts/deps.sh);
#   2. configures, builds (warnings are errors) and runs ctest with g++ (preset dev) and clang++
#      (preset dev-clang); the dev build includes one translation unit per public header (each
#      header compiles alone) and its ctest includes the nvcc device-compile check when nvcc exists;
#   3. runs the suite once under AddressSanitizer + UndefinedBehaviorSanitizer (preset sanitize);
#   4. installs the package into a temporary prefix and builds and runs a consumer project that
#      uses find_package(ibl CONFIG REQUIRED).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/deps.sh

for preset in dev dev-clang sanitize; do
    echo "== preset $preset"
    cmake --preset "$preset" >/dev/null
    cmake --build --preset "$preset"
    ctest --preset "$preset"
done

echo "== install + find_package(ibl) consumer"
prefix=$(mktemp -d)
trap 'rm -rf "$prefix"' EXIT
cmake --install build/dev --prefix "$prefix/install" >/dev/null
cmake -S tests/consumer -B "$prefix/consumer" -G Ninja -DCMAKE_PREFIX_PATH="$prefix/install" \
    -DCMAKE_CXX_FLAGS="-Wall -Wextra -Wpedantic -Werror" >/dev/null
cmake --build "$prefix/consumer"
"$prefix/consumer/consumer"
echo "== all tests passed"
