#!/usr/bin/env bash
# Sets up, builds and runs the whole test suite through ctest, then the whole suite
# again under AddressSanitizer + UBSan (GL, live-editing and CLI tests included; the
# kiln binary they run is the sanitized one). Leak checking covers the sim and graph
# tests; the GL tests run with it off, because Mesa's llvmpipe keeps allocations of its
# own until exit that no suppression can name (its frames are unsymbolized).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
"$root/scripts/setup.sh"
"$root/scripts/build.sh"
(cd "$root/build" && ctest --output-on-failure --timeout 600 -j "$(nproc)")

generator=()
command -v ninja >/dev/null && generator=(-G Ninja)
asan="$root/build-asan"
if [ ! -f "$asan/CMakeCache.txt" ]; then
  cmake -S "$root" -B "$asan" "${generator[@]}" -DCMAKE_BUILD_TYPE=Debug -DKILN_WITH_GL=ON \
        -DKILN_SANITIZE=ON -DKILN_BENCH=OFF
fi
cmake --build "$asan" --parallel "$(nproc)"
(cd "$asan" && ASAN_OPTIONS=detect_leaks=0 UBSAN_OPTIONS=print_stacktrace=1 \
   ctest --output-on-failure --timeout 900 -j "$(nproc)")
(cd "$asan" && ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
   ctest --output-on-failure --timeout 900 -j "$(nproc)" -R "^(sim|graph):")
