#!/usr/bin/env bash
# scripts/fuzz.sh [RUNS] — build the libFuzzer harness of the ibl-bake image readers
# (tools/ibl-bake/fuzz) with clang++ -fsanitize=fuzzer,address,undefined and run it for RUNS
# executions (default 100000), one job, on a seed corpus made from the real test EXRs and small
# valid HDR/EXR/KTX2/PNG files (EXR in every compression, tiled, multi-part, Y/RY/BY; KTX2 in
# RGBA16F and the block formats BC6H / ASTC 4x4 / 6x6, plain and Zstandard-supercompressed).
# Not part of the default test run. Crash reproducers land in
# build/fuzz/artifacts/; copy them to tools/ibl-bake/tests/data/fuzz-<name> as regression
# inputs once fixed. OpenEXR is Debian's prebuilt library, not instrumented: libFuzzer's coverage
# and the sanitizers see our code (header pre-scan, stream, conversions) and stb; run valgrind on
# the inputs of interest to check OpenEXR's own memory accesses.
set -euo pipefail
RUNS=${1:-100000}
ROOT=$(cd "$(dirname "$0")/.." && pwd)
SRC=$ROOT/tools/ibl-bake
OUT=$ROOT/build/fuzz
CXX=${CXX_FUZZ:-clang++}
mkdir -p "$OUT/corpus" "$OUT/artifacts" "$OUT/seeds"
COMMON=(-std=c++20 -g -O1 -fno-omit-frame-pointer -DASTCENC_DYNAMIC_LIBRARY -I"$SRC" -I"$ROOT/include" -isystem /usr/include/stb -isystem /usr/include/OpenEXR -isystem /usr/include/Imath)
LIBS=(-lOpenEXR -lIex -lImath -lastcenc -lzstd)
IO=("$SRC/io/image_common.cpp" "$SRC/io/image_hdr.cpp" "$SRC/io/image_exr.cpp" "$SRC/io/image_png.cpp" "$SRC/io/ktx2.cpp" "$SRC/io/block_codec.cpp")
SAN=(-fsanitize=address,undefined -fno-sanitize-recover=undefined)

echo "== building (clang: $($CXX --version | head -1))"
"$CXX" "${COMMON[@]}" "${SAN[@]}" -fsanitize=fuzzer \
    "$SRC/fuzz/fuzz_image_readers.cpp" "${IO[@]}" "${LIBS[@]}" -o "$OUT/fuzz_image_readers"
"$CXX" "${COMMON[@]}" "$SRC/fuzz/make_seeds.cpp" "${IO[@]}" "${LIBS[@]}" -o "$OUT/make_seeds"

echo "== seed corpus"
"$OUT/make_seeds" "$OUT/seeds"
cp "$ROOT"/tests/data/*.exr "$OUT/seeds/"
find "$SRC/tests/data" -name 'fuzz-*' -exec cp {} "$OUT/seeds/" \; 2>/dev/null || true
ls -l "$OUT/seeds"

echo "== fuzzing: $RUNS executions, one process"
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:allocator_may_return_null=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
START=$(date +%s)
"$OUT/fuzz_image_readers" "$OUT/corpus" "$OUT/seeds" \
    -runs="$RUNS" -max_len=65536 -timeout=10 -rss_limit_mb=2048 \
    -artifact_prefix="$OUT/artifacts/" -print_final_stats=1 2>&1 | tee "$OUT/fuzz.log" | grep -E '^#|INFO|ERROR|SUMMARY|stat::|Done' | tail -40
STATUS=${PIPESTATUS[0]}
END=$(date +%s)
echo "== fuzz exit status $STATUS, $((END - START)) s wall; artifacts:"
ls -l "$OUT/artifacts"
exit "$STATUS"
