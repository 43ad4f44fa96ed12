#!/bin/sh
# The benchmark figures for a machine with a GPU (README, "On a GPU"): per-pass cost at
# 720², 1080p and 4K, the skip table at 1080p, the fireball growth at 720², and run time
# against error at 720² — the size this machine's CPU rasterizer cannot judge (its
# path-traced reference takes seconds on a GPU, hours here). Headless (EGL); run from
# the build tree or an install.
#   bench/gpu_figures.sh [BIN_DIR] [OUT_DIR]     defaults: build/bin, bench-out/gpu
set -eu
bin=${1:-build/bin}
out=${2:-bench-out/gpu}
# The path-traced references (EXR, megabytes each at 720²) beside the results, not in
# them, so OUT_DIR stays CSVs and plots and a rerun reuses them.
cache=$out.reference-cache
mkdir -p "$out" "$cache"
before=bench/pipelines/default_before_22.json
"$bin/kiln-bench-render" --size 720x720 --frames 30 --repeats 7 --pipeline "$before" --pipeline pipelines/default.json \
    --pipeline pipelines/course.json --out "$out/render_720"
"$bin/kiln-bench-render" --size 1920x1080 --frames 30 --repeats 7 --pipeline "$before" --pipeline pipelines/default.json \
    --out "$out/render_1080p"
"$bin/kiln-bench-render" --size 3840x2160 --frames 20 --repeats 5 --pipeline "$before" --pipeline pipelines/default.json \
    --out "$out/render_4k"
"$bin/kiln-bench-skip" --size 1920x1080 --frames 30 --repeats 5 --out "$out/skip_1080p"
# A GPU this fast leaves the host's CPU work on the critical path: 50 fireballs' 4 000
# particles show it (README, "On a GPU").
"$bin/kiln-bench-render" --size 720x720 --frames 30 --repeats 5 --pipeline pipelines/default.json \
    --grow fireballs=2,50 --out "$out/growth_720"
knobs="--sweep cone_trace.trace_samples=32,48,64,96,128 --sweep composite.pcf=1,3,5 --sweep shadow.size=256,512,1024
       --sweep composite.lamp_samples=8,16 --sweep voxelize.resolution=32,64"
for t in 0 0.5; do
    # shellcheck disable=SC2086
    "$bin/kiln-bench-quality" --size 720x720 --spp 1024 --time "$t" --repeats 3 --out "$out/quality_720_t$t" \
        --cache "$cache" --also "$before" $knobs
done
