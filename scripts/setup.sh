#!/usr/bin/env bash
# Installs every Debian package Kiln needs to build, run and test. Idempotent:
# packages already present are left alone, so a second run costs one dpkg query.
set -euo pipefail

packages=(
  build-essential cmake pkg-config ninja-build
  python3-glad                       # glad 2: generates the GL loader at configure time
  libglfw3-dev libimgui-dev          # window + debug view
  libglm-dev nlohmann-json3-dev libstb-dev catch2
  libcli11-dev                       # every program's command line
  help2man                           # the man page, from kiln --help
  libtinyexr-dev                     # OpenEXR read/write for HDR textures (--dump, reference cache)
  libtinygltf-dev                    # glTF 2.0 scenes (host/model)
  libmeshoptimizer-dev               # their meshes ordered for the vertex cache
  libembree-dev                      # a CPU path tracer the reference is checked against (tests/)
  assimp-testmodels                  # glTF files made to break loaders, and valid ones (tests/model)
  openimageio-tools                  # idiff/oiiotool: the error metrics are cross-checked against them
  libegl-dev libgl-dev libegl-mesa0 libgl1-mesa-dri libglx-mesa0   # EGL/GL + llvmpipe
  xvfb xauth mesa-utils              # window tests/screenshots without a display
  inotify-tools                      # used by live-reload test scripts
  xdotool imagemagick                # driving the window in tests (keys, clicks, screenshots)
  python3-matplotlib                 # the benchmark commands' figures (scripts/plot.py)
)
# scripts/fuzz.sh only: clang with libFuzzer (not needed to build, run or test).
[ "${1:-}" = "--fuzz" ] && packages+=(clang-14 libclang-rt-14-dev)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && { echo "setup: all ${#packages[@]} packages present"; exit 0; }

SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
echo "setup: installing ${missing[*]}"
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
