#!/usr/bin/env bash
# scripts/fuzz_tool.sh [SECONDS] — build the libFuzzer harnesses of the ibl-bake scene reader
# (tools/ibl-bake/fuzz/fuzz_scene.cpp: parse_scene + make_bake_plan), probe-set reader
# (fuzz_probes.cpp: parse_probes of --probes) and option parser
# (fuzz_options.cpp: parse_options on argv split from the input) with clang++
# -fsanitize=fuzzer,address,undefined, and run each for SECONDS seconds (default 120), one job.
# Seeds: examples/scenes/*.json, small probe sets and typical command lines (one argument per
# line), plus any regression inputs tools/ibl-bake/tests/data/fuzz-scene-* / fuzz-probes-* /
# fuzz-options-*. Not part of the
# default test run. Crash reproducers land in build/fuzz-tool/artifacts/.
set -euo pipefail
SECONDS_EACH=${1:-120}
ROOT=$(cd "$(dirname "$0")/.." && pwd)
SRC=$ROOT/tools/ibl-bake
OUT=$ROOT/build/fuzz-tool
CXX=${CXX_FUZZ:-clang++}
mkdir -p "$OUT/artifacts" "$OUT/seeds-scene" "$OUT/seeds-options" "$OUT/corpus-scene" "$OUT/corpus-options" \
    "$OUT/seeds-probes" "$OUT/corpus-probes"
FLAGS=(-std=c++20 -g -O1 -fno-omit-frame-pointer -I"$SRC" -I"$ROOT/include"
       -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=undefined)

echo "== building (clang: $($CXX --version | head -1))"
"$CXX" "${FLAGS[@]}" "$SRC/fuzz/fuzz_scene.cpp" "$SRC/io/scene_reader.cpp" "$SRC/io/input_guard.cpp" -o "$OUT/fuzz_scene"
"$CXX" "${FLAGS[@]}" "$SRC/fuzz/fuzz_probes.cpp" "$SRC/io/probes_reader.cpp" "$SRC/io/input_guard.cpp" -o "$OUT/fuzz_probes"
"$CXX" "${FLAGS[@]}" "$SRC/fuzz/fuzz_options.cpp" "$SRC/options/bake_options.cpp" -o "$OUT/fuzz_options"

echo "== seeds"
cp "$ROOT"/examples/scenes/*.json "$OUT/seeds-scene/"
printf '{}' >"$OUT/seeds-scene/empty-object.json"
printf '{"name":"x","materials":[{"name":"m","metallic":0.5,"roughness_range":[0,1]}]}' >"$OUT/seeds-scene/minimal.json"
printf '{"probes":[{"input":"a.exr","position":[0,1,0],"proxy":{"box":{"min":[-2,0,-2],"max":[2,3,2]}},"influence":{"box":{"min":[-2,0,-2],"max":[2,3,2]},"fade":0.5}}]}' >"$OUT/seeds-probes/box.json"
printf '{"probes":[{"input":"a.hdr","position":[0,0,0],"priority":2,"proxy":{"sphere":{"center":[0,0,0],"radius":4}},"influence":{"sphere":{"center":[1,0,0],"radius":3},"fade":1}},{"input":"/abs/b.exr","position":[5,0,0],"proxy":{"box":{"min":[3,-1,-1],"max":[7,1,1]}},"influence":{"sphere":{"center":[5,0,0],"radius":2},"fade":0.25}}]}' >"$OUT/seeds-probes/two.json"
printf '{"probes":[{"input":"a.exr","position":[0,1,0],"proxy":{"box":{"center":[0,1.5,0],"half_extents":[4,1.5,3],"axes":[[0.8660254037844386,0,-0.5],[0,1,0],[0.5,0,0.8660254037844386]]}},"influence":{"box":{"center":[0,1.5,0],"half_extents":[5,2,4]},"fade":0.5}}]}' >"$OUT/seeds-probes/oriented.json"
i=0
while IFS= read -r line; do
    i=$((i + 1))
    printf '%s' "$line" | tr ' ' '\n' >"$OUT/seeds-options/cmd-$i"
done <<'CMDS'
--out build/bake
--input tests/data/courtyard.exr --out build/courtyard --size 512 --quality high
--size=32 --lut-size=16 --levels 3 --threads 2 --quality low --quiet --out o
--scene examples/scenes/mobile.json --compare-full --out o
--input sky_{face}.exr --input-layout faces --layout faces,latlong,cross,octahedral --out o
--input cube.ktx2 --input-layout ktx2 --ktx2-format e5b9g9r9 --max-input-pixels 1048576 --out o
--input x.exr --part beauty --ktx2-format b10g11r11 --out o
--help
--version
CMDS
for f in "$SRC"/tests/data/fuzz-scene-*; do [ -e "$f" ] && cp "$f" "$OUT/seeds-scene/"; done
for f in "$SRC"/tests/data/fuzz-probes-*; do [ -e "$f" ] && cp "$f" "$OUT/seeds-probes/"; done
for f in "$SRC"/tests/data/fuzz-options-*; do [ -e "$f" ] && cp "$f" "$OUT/seeds-options/"; done

export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:allocator_may_return_null=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
STATUS=0
for h in scene probes options; do
    echo "== fuzzing $h: $SECONDS_EACH s, one job"
    set +e
    "$OUT/fuzz_$h" "$OUT/corpus-$h" "$OUT/seeds-$h" -max_total_time="$SECONDS_EACH" -max_len=4096 -timeout=5 \
        -rss_limit_mb=2048 -artifact_prefix="$OUT/artifacts/$h-" -print_final_stats=1 >"$OUT/fuzz-$h.log" 2>&1
    s=$?
    set -e
    grep -E '(INITED|DONE) +cov|ERROR|SUMMARY|stat::number_of_executed_units|stat::average_exec_per_sec|Done' "$OUT/fuzz-$h.log" | tail -12
    echo "== $h: exit status $s"
    [ "$s" -ne 0 ] && STATUS=$s
done
ls -l "$OUT/artifacts"
exit "$STATUS"
