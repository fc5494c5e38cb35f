#!/usr/bin/env bash
# The project's whole test run, from a fresh Debian machine (as root):
#   1. installs missing packages (scripts/deps.sh);
#   2. configures, builds (warnings are errors) and runs ctest with g++ (preset dev) and clang++
#      (preset dev-clang); the dev build includes one translation unit per public header (each
#      header compiles alone) and its ctest includes the nvcc device-compile check when nvcc exists;
#   3. runs the suite once under AddressSanitizer + UndefinedBehaviorSanitizer (preset sanitize);
#      the headless-Chromium GLSL tests run in the dev preset only (the shaders and the browser do
#      not depend on the C++ compiler; the tool paths they drive are covered by the tool tests);
#   4. installs the package into a temporary prefix (checking that it holds exactly include/ibl: no
#      research, example or tool file) and builds and runs a consumer project that
#      uses find_package(ibl CONFIG REQUIRED);
#   5. builds and runs a consumer that vendors ibl with add_subdirectory (it checks that ibl then
#      defines nothing but its INTERFACE library);
#   6. configures the repository with plain defaults and installs it without building anything
#      (the headers and package files alone), then builds the find_package consumer against that.
# The consumers check that the version CMake reports equals IBL_VERSION_STRING of the headers.
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
# The install tree is the shipping library: exactly include/ibl, no research, study or tool file.
if find "$prefix/install" | grep -E '/(research|examples|tools)(/|$)'; then
    echo "the install tree holds research, example or tool files" >&2; exit 1
fi
diff <(cd include && find ibl -type f | sort) <(cd "$prefix/install/include" && find ibl -type f | sort) \
    || { echo "the installed headers differ from include/ibl" >&2; exit 1; }
cmake -S tests/consumer -B "$prefix/consumer" -G Ninja -DCMAKE_PREFIX_PATH="$prefix/install" \
    -DCMAKE_CXX_FLAGS="-Wall -Wextra -Wpedantic -Werror" >/dev/null
cmake --build "$prefix/consumer"
"$prefix/consumer/consumer"

echo "== add_subdirectory(ibl) consumer"
cmake -S tests/consumer_subdir -B "$prefix/consumer_subdir" -G Ninja -DIBL_ROOT="$PWD" \
    -DCMAKE_CXX_FLAGS="-Wall -Wextra -Wpedantic -Werror" >/dev/null
cmake --build "$prefix/consumer_subdir"
"$prefix/consumer_subdir/consumer"

echo "== configure-only install (plain defaults, nothing built)"
cmake -S . -B "$prefix/plain" >/dev/null
cmake --install "$prefix/plain" --prefix "$prefix/plain_install" >/dev/null
for f in include/ibl/ibl.hpp include/ibl/core/config.hpp share/cmake/ibl/iblConfig.cmake \
         share/cmake/ibl/iblConfigVersion.cmake share/cmake/ibl/iblTargets.cmake; do
    test -f "$prefix/plain_install/$f" || { echo "configure-only install lacks $f" >&2; exit 1; }
done
cmake -S tests/consumer -B "$prefix/consumer_plain" -G Ninja -DCMAKE_PREFIX_PATH="$prefix/plain_install" \
    -DCMAKE_CXX_FLAGS="-Wall -Wextra -Wpedantic -Werror" >/dev/null
cmake --build "$prefix/consumer_plain"
"$prefix/consumer_plain/consumer"
echo "== all tests passed"
