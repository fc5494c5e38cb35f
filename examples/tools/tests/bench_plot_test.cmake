# ctest driver for bench_plot (cmake -P): BENCH_PLOT = the executable, DATA_DIR = fixtures,
# WORK_DIR = scratch directory.
file(REMOVE_RECURSE "${WORK_DIR}")
file(MAKE_DIRECTORY "${WORK_DIR}")

# Runs bench_plot with ARGN and checks its exit code; returns stderr in `err`.
function(run_plot expected_rc)
    execute_process(COMMAND "${BENCH_PLOT}" ${ARGN}
        RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
    if(NOT rc STREQUAL "${expected_rc}")
        message(FATAL_ERROR "bench_plot ${ARGN}\n  exit ${rc}, expected ${expected_rc}\n  stdout: ${out}\n  stderr: ${err}")
    endif()
    set(err "${err}" PARENT_SCOPE)
endfunction()

function(expect_in haystack needle)
    string(FIND "${haystack}" "${needle}" at)
    if(at EQUAL -1)
        message(FATAL_ERROR "expected '${needle}' in:\n${haystack}")
    endif()
endfunction()

# PNG width and height from the IHDR chunk (bytes 16..23, big-endian).
function(png_size file out_w out_h)
    file(READ "${file}" sig LIMIT 8 HEX)
    if(NOT sig STREQUAL "89504e470d0a1a0a")
        message(FATAL_ERROR "${file}: not a PNG (signature ${sig})")
    endif()
    file(READ "${file}" w LIMIT 4 OFFSET 16 HEX)
    file(READ "${file}" h LIMIT 4 OFFSET 20 HEX)
    math(EXPR w "0x${w}")
    math(EXPR h "0x${h}")
    set(${out_w} ${w} PARENT_SCOPE)
    set(${out_h} ${h} PARENT_SCOPE)
endfunction()

# 1. the good fixture, explicit curves, a reduction and a dashed curve
set(png "${WORK_DIR}/ok.png")
run_plot(0 -q -o "${png}" --size 640x400 --y max_abs_err --title "fixture"
    --curve "MC=^BM_mc/" --curve "quadrature=^BM_exact/" --curve "fit=^BM_fit$=max(max_abs_err,rms_err)=dashed"
    "${DATA_DIR}/fixture.json")
png_size("${png}" w h)
if(NOT w EQUAL 640 OR NOT h EQUAL 400)
    message(FATAL_ERROR "ok.png is ${w}x${h}, expected 640x400")
endif()

# 2. default grouping (one curve per family), default size
set(png2 "${WORK_DIR}/families.png")
run_plot(0 -q -o "${png2}" --y max_abs_err --annotate ends "${DATA_DIR}/fixture.json")
png_size("${png2}" w h)
if(NOT w EQUAL 960 OR NOT h EQUAL 600)
    message(FATAL_ERROR "families.png is ${w}x${h}, expected 960x600")
endif()

# 3. bad input: exit 1, a message, no PNG left behind
set(bad "${WORK_DIR}/bad.png")
run_plot(1 -o "${bad}" --y max_abs_err "${DATA_DIR}/malformed.json")
expect_in("${err}" "malformed JSON")
file(WRITE "${WORK_DIR}/empty.json" "")
run_plot(1 -o "${bad}" --y max_abs_err "${WORK_DIR}/empty.json")
expect_in("${err}" "empty input")
run_plot(1 -o "${bad}" --y no_such_counter "${DATA_DIR}/fixture.json")
expect_in("${err}" "no counter 'no_such_counter'")
file(WRITE "${WORK_DIR}/other.json" "{\"context\": {}, \"items\": [1, 2]}")
run_plot(1 -o "${bad}" --y max_abs_err "${WORK_DIR}/other.json")
expect_in("${err}" "no \"benchmarks\" array")
run_plot(1 -o "${bad}" --y max_abs_err --curve "x=^BM_nothing" "${DATA_DIR}/fixture.json")
expect_in("${err}" "no benchmark name matches")
run_plot(1 -o "${bad}" --y max_abs_err "${WORK_DIR}/does_not_exist.json")
expect_in("${err}" "cannot open")
if(EXISTS "${bad}")
    message(FATAL_ERROR "a failed run left ${bad} behind")
endif()

# 4. usage errors: exit 2
run_plot(2 --y max_abs_err "${DATA_DIR}/fixture.json")
expect_in("${err}" "no output file")
run_plot(2 -o "${bad}" --y max_abs_err --curve "nolabel" "${DATA_DIR}/fixture.json")
run_plot(2 -o "${bad}" --y "median(a,b)" "${DATA_DIR}/fixture.json")
