#!/usr/bin/env bash
# Configures (once) and builds Kiln into build/. Extra arguments go to cmake --build.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
generator=()
command -v ninja >/dev/null && generator=(-G Ninja)
# Configured once; again when an earlier configure failed before writing its build files.
if [ ! -f "$root/build/CMakeCache.txt" ] || { [ ! -f "$root/build/build.ninja" ] && [ ! -f "$root/build/Makefile" ]; }; then
  cmake -S "$root" -B "$root/build" "${generator[@]}" -DCMAKE_BUILD_TYPE=RelWithDebInfo
fi
cmake --build "$root/build" --parallel "$(nproc)" "$@"
