#!/usr/bin/env bash
# Sets up, builds and runs the default pipeline: in a window when there is a display,
# otherwise headless into out/kiln.png. Arguments are passed to kiln.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
"$root/scripts/setup.sh"
"$root/scripts/build.sh"
if [ -n "${DISPLAY:-}${WAYLAND_DISPLAY:-}" ]; then
  exec "$root/build/bin/kiln" "$@"
fi
mkdir -p "$root/out"
"$root/build/bin/kiln" --headless --frames 60 --stats --out "$root/out/kiln.png" "$@"
echo "no display: rendered headless to $root/out/kiln.png"
