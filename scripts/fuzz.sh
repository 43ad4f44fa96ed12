#!/usr/bin/env bash
# Builds the libFuzzer targets (fuzz/) with clang into build-fuzz/ and runs each one for
# SECONDS_PER_TARGET (default 60) from its seed corpus (the shipped pipelines, scenes
# and shaders, plus tests/fuzz_corpus/<target>/). Prints executions, seconds and crashes
# per target; every crash/timeout/oom input is copied to tests/fuzz_corpus/<target>/,
# where ctest replays it in every build ("fuzz: replay <target>"). Exit 1 on a crash.
#   scripts/fuzz.sh [SECONDS_PER_TARGET] [TARGET...]     (targets: pipeline scene shader gltf)
# JOBS=N sets the build's parallelism (default: all cores); nice it on a shared machine.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
seconds="${1:-60}"
shift || true
targets=("$@")
[ ${#targets[@]} -eq 0 ] && targets=(pipeline scene shader gltf)
build="$root/build-fuzz"
cc="$(command -v clang-14 || command -v clang)"
cxx="$(command -v clang++-14 || command -v clang++)"
if [ ! -f "$build/CMakeCache.txt" ]; then
  CC="$cc" CXX="$cxx" cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DKILN_FUZZ=ON -DKILN_TESTS=OFF -DKILN_BENCH=OFF >/dev/null
fi
cmake --build "$build" --parallel "${JOBS:-$(nproc)}" --target "${targets[@]/#/fuzz_}"

declare -A seeds=([pipeline]="$root/pipelines" [gltf]="$root/scenes /usr/share/assimp/models/glTF2" [scene]="$root/scenes $root/tests/sim/data" [shader]="$root/shaders")
status=0
rows=()
for t in "${targets[@]}"; do
  work="$build/fuzz-run/$t"
  mkdir -p "$work/corpus" "$work/artifacts"
  rm -f "$work/artifacts"/*
  # Seeds: every file of the seed directories (and the regression corpus).
  find ${seeds[$t]} "$root/tests/fuzz_corpus/$t" -type f ! -name README.md -exec cp -t "$work/corpus" {} + 2>/dev/null || true
  log="$work/log.txt"
  start=$(date +%s)
  # -fork with -ignore_*: keep going after a crash, so one run finds several.
  (cd "$work" && "$build/bin/fuzz_$t" corpus -max_total_time="$seconds" -fork=1 -ignore_crashes=1 \
     -ignore_timeouts=1 -ignore_ooms=1 -timeout=20 -rss_limit_mb=4096 -max_len=65536 \
     -artifact_prefix="$work/artifacts/" -print_final_stats=1 >"$log" 2>&1) || true
  elapsed=$(( $(date +%s) - start ))
  execs=$(grep -oE '^#[0-9]+' "$log" | tail -1 | tr -d '#')
  crashes=$(find "$work/artifacts" -type f | wc -l)
  if [ "$crashes" -gt 0 ]; then
    status=1
    mkdir -p "$root/tests/fuzz_corpus/$t"
    cp "$work/artifacts"/* "$root/tests/fuzz_corpus/$t/"
  fi
  rows+=("$(printf '%-10s %12s %8s %8s' "$t" "${execs:-0}" "$elapsed" "$crashes")")
done
printf '%-10s %12s %8s %8s\n' target executions seconds crashes
printf '%s\n' "${rows[@]}"
[ "$status" -eq 0 ] || echo "crash inputs copied to tests/fuzz_corpus/<target>/: fix, then commit them (ctest replays them)"
exit "$status"
