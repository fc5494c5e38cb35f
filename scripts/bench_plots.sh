#!/usr/bin/env bash
# Error against time: runs the benchmarks that report error counters, keeps their Google Benchmark
# JSON in docs/results/<bench>.json and draws docs/results/*.png and *.svg with scripts/plot_bench.py
# (matplotlib, one curve per method). A few minutes on 2 cores. See docs/results/README.md for the plots.
#
#   bash scripts/bench_plots.sh            # build (release preset), run, plot
#   PLOT_ONLY=1 bash scripts/bench_plots.sh   # re-draw the plots from the JSON already in docs/results
#                                             # (needs only /usr/bin/python3 with python3-matplotlib)
#   BENCH_MIN_TIME=0.2 bash scripts/bench_plots.sh   # steadier timings (default 0.2 s per benchmark)
set -euo pipefail
cd "$(dirname "$0")/.."

out=docs/results
min_time=${BENCH_MIN_TIME:-0.2}
bin=build/release/bench
mkdir -p "$out"

plot() { MPLBACKEND=Agg /usr/bin/python3 scripts/plot_bench.py "$@"; }

# run <bench> <filter>: console table on stdout, JSON to docs/results/<bench>.json
run() {
    local name=$1 filter=$2
    echo "== $name ($filter)"
    "$bin/$name" --benchmark_filter="$filter" --benchmark_min_time="$min_time" \
        --benchmark_out="$out/$name.json.tmp" --benchmark_out_format=json
    mv "$out/$name.json.tmp" "$out/$name.json"
}

if [[ -z "${PLOT_ONLY:-}" ]]; then
    # Only the targets needed here (not the whole tree).
    cmake --preset release >/dev/null
    cmake --build --preset release --target bench_dfg bench_prefilter bench_radiance_reference bench_sh
    # DFG LUT 128^2: quadrature node sweep, MC sample sweeps (NDF and VNDF), scalar loop vs batch, Karis fit.
    run bench_dfg '^BM_(exact_table|mc_table|mc_table_batch_1thread|mc_table_scalar_loop|mc_vndf_table|karis_fit_table)<'
    # Prefiltered mip chain 256^2 -> 5 levels: plain GGX IS and filtered IS, smooth sky (env 0) and sky + sun (env 1).
    run bench_prefilter '^BM_prefilter_(is|fis)/'
    # Outgoing-radiance reference on the sun case: MIS against BRDF sampling alone.
    run bench_radiance_reference '^BM_radiance_(mis|brdf)/'
    # SH projection of a band-limited (3-band) input: cube and lat-long resolution sweeps.
    run bench_sh '^BM_sh_project_'
fi

echo "== plots"
plot -q -o "$out/dfg_error_vs_time" --y max_abs_err --annotate all \
    --title "DFG LUT 128x128, GGX height-correlated: error against time" \
    --ylabel "max abs error of (A, B)" \
    --curve 'MC, GGX NDF sampling (spp)=^BM_mc_table<ibl::ggx_height_correlated>/' \
    --curve 'MC, visible normals, scalar (spp)=^BM_mc_vndf_table<ibl::ggx_height_correlated>/' \
    --curve 'quadrature (level)=^BM_exact_table<ibl::ggx_height_correlated>/' \
    --curve 'Karis analytic fit=^BM_karis_fit_table<ibl::ggx_height_correlated>' \
    "$out/bench_dfg.json"

plot -q -o "$out/dfg_schlick_error_vs_time" --y max_abs_err --annotate all --legend bl \
    --title "DFG LUT 128x128, Schlick-GGX k = a/2: error against time" \
    --ylabel "max abs error of (A, B)" \
    --curve 'MC batch kernel, all threads (spp)=^BM_mc_table<ibl::ggx_schlick_ibl>/' \
    --curve 'MC batch kernel, 1 thread (spp)=^BM_mc_table_batch_1thread<ibl::ggx_schlick_ibl>/' \
    --curve 'MC literature scalar loop, 1 thread (spp)=^BM_mc_table_scalar_loop<ibl::ggx_schlick_ibl>/' \
    --curve 'quadrature (level)=^BM_exact_table<ibl::ggx_schlick_ibl>/' \
    --curve 'Karis analytic fit=^BM_karis_fit_table<ibl::ggx_schlick_ibl>' \
    "$out/bench_dfg.json"

plot -q -o "$out/prefilter_error_vs_time" --y 'mean(rel_1,rel_2,rel_3,rel_4)' --knob spp --annotate all \
    --title "Prefiltered LD mip chain 256^2, 5 levels: error against time" \
    --ylabel "relative RMSE, mean of mips 1-4" \
    --curve 'filtered IS, smooth sky (spp)=^BM_prefilter_fis/env:0/' \
    --curve 'plain IS, smooth sky (spp)=^BM_prefilter_is/env:0/' \
    --curve 'filtered IS, sky + sun (spp)=^BM_prefilter_fis/env:1/==dashed' \
    --curve 'plain IS, sky + sun (spp)=^BM_prefilter_is/env:1/==dashed' \
    "$out/bench_prefilter.json"

plot -q -o "$out/reference_error_vs_samples" --x knob --y rel_err --annotate none \
    --title "Radiance reference, sun reflected by a dielectric (r = 0.3)" \
    --xlabel "samples" --ylabel "relative error" \
    --curve 'MIS, |estimate / converged - 1|=^BM_radiance_mis/' \
    --curve 'BRDF sampling, |estimate / converged - 1|=^BM_radiance_brdf/' \
    --curve 'MIS, own standard error=^BM_radiance_mis/=rel_se=dashed' \
    --curve 'BRDF sampling, own standard error=^BM_radiance_brdf/=rel_se=dashed' \
    "$out/bench_radiance_reference.json"

plot -q -o "$out/reference_error_vs_time" --y rel_err \
    --title "Radiance reference, sun reflected by a dielectric (r = 0.3)" \
    --ylabel "relative error" \
    --curve 'MIS=^BM_radiance_mis/' \
    --curve 'BRDF sampling=^BM_radiance_brdf/' \
    "$out/bench_radiance_reference.json"

plot -q -o "$out/sh_projection_error_vs_time" --y max_err --annotate all \
    --title "SH projection, 3-band signal: error against time" \
    --ylabel "max abs coefficient error" \
    --curve 'cube, serial (face size n)=^BM_sh_project_cube_serial_B3/' \
    --curve 'cube, 2 threads (face size n)=^BM_sh_project_cube_threads2_B3/' \
    --curve 'lat-long, serial (height H)=^BM_sh_project_latlong_B3/' \
    "$out/bench_sh.json"

ls -l "$out"/*.png "$out"/*.svg
