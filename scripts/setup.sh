#!/usr/bin/env bash
# Install what is missing (Debian 12 packages), then configure and build
# into build/.  Safe to run again: it installs nothing that is there and
# rebuilds only what changed.
#
#   RADIOSITY_BUILD_DIR   build folder (default: build)
#   RADIOSITY_CMAKE_ARGS  extra arguments for cmake's configure step
#   RADIOSITY_FUZZ=1      also install clang 14 and build the libFuzzer
#                         targets into build-fuzz/ (docs/testing.md, "Fuzzing")
#
# Where npm is installed, the Khronos glTF validator (npm package
# gltf-validator) goes into $build/npm for test_export; without npm, or
# offline, that test skips the validator and the setup goes on.
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(build-essential g++ cmake pkg-config libembree-dev libassimp-dev libstb-dev
          libopenblas-dev liblapacke-dev libcjson-dev libcmocka-dev
          libcairo2-dev fonts-dejavu-core  # false colour and plots: cairo, and a font for its text
          libopenmpi-dev openmpi-bin
          python3-numpy  # bench/compare_images.py
          libsdl2-dev libepoxy-dev libegl-dev libegl-mesa0 libgl1-mesa-dri)  # the last five: the viewer
if [ "${RADIOSITY_FUZZ:-0}" = 1 ]; then
  packages+=(clang-14 libclang-rt-14-dev libomp-14-dev)
fi
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}"
  sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $sudo apt-get update -qq
  $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

build="${RADIOSITY_BUILD_DIR:-build}"
# shellcheck disable=SC2086
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release ${RADIOSITY_CMAKE_ARGS:-} >/dev/null
# The build's own status, not the filter's: a stale binary from an earlier
# build must not pass for a build that failed.
set +e
cmake --build "$build" -j "$(nproc)" 2>&1 | grep -Ev '^\[ *[0-9]+%\]|^gmake|^make|Consolidate compiler'
built=${PIPESTATUS[0]}
set -e
[ "$built" -eq 0 ] && test -x "$build/radiosity" || { echo "setup: build failed" >&2; exit 1; }
echo "setup: built $build/radiosity"

if [ ! -f "$build/npm/node_modules/gltf-validator/package.json" ]; then
  if ! command -v npm >/dev/null 2>&1; then
    echo "setup: npm not found: test_export will skip the glTF validator"
  elif timeout 300 npm install --prefix "$build/npm" --no-audit --no-fund --silent gltf-validator \
         >/dev/null 2>&1; then
    echo "setup: installed the glTF validator (npm gltf-validator) in $build/npm"
  else
    echo "setup: npm could not install gltf-validator (offline?): test_export will skip the glTF validator"
  fi
fi

if [ "${RADIOSITY_FUZZ:-0}" = 1 ]; then
  CC=clang-14 cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DRADIOSITY_FUZZ=ON \
    -DRADIOSITY_BENCH=OFF >/dev/null
  cmake --build build-fuzz -j "$(nproc)" --target fuzz_obj fuzz_mtl fuzz_gltf fuzz_glb fuzz_camera \
    fuzz_cli_options fuzz_solve fuzz_solution fuzz_thermal_bc 2>&1 | grep -Ev '^\[ *[0-9]+%\]|^gmake|^make' || true
  test -x build-fuzz/fuzz/fuzz_obj || { echo "setup: fuzz build failed" >&2; exit 1; }
  echo "setup: built the fuzzers in build-fuzz/fuzz/"
fi
