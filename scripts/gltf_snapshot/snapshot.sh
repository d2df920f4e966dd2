#!/usr/bin/env bash
# snapshot.sh LIT.glb OUT.png -- a picture of an exported lit mesh as an ordinary glTF
# viewer shows it: three.js's GLTFLoader in headless Chromium (software WebGL), from
# the Cornell box's camera.  Needs Debian's chromium and npm (three.js is installed
# into a temporary folder); a documentation tool, not part of the build or the tests.
#   ./build/radiosity export --elements 6000 -o /tmp/lit.glb
#   scripts/gltf_snapshot/snapshot.sh /tmp/lit.glb docs/images/cornell_lit_glb_threejs.png
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
glb=$(realpath "$1"); out=$(realpath -m "$2")
work=$(mktemp -d); trap 'kill "$server" 2>/dev/null; rm -rf "$work"' EXIT
cp "$here/index.html" "$work/"; cp "$glb" "$work/lit.glb"
(cd "$work" && npm install --no-audit --no-fund --silent three@0.160.0 >/dev/null)
port=$((20000 + RANDOM % 20000))
(cd "$work" && exec python3 -m http.server "$port" --bind 127.0.0.1 >/dev/null 2>&1) & server=$!
sleep 1
chromium --headless --no-sandbox --use-gl=angle --use-angle=swiftshader --enable-unsafe-swiftshader \
  --disable-background-networking --disable-component-update --disable-sync --no-first-run \
  --user-data-dir="$work/profile" --window-size=512,512 --virtual-time-budget=8000 \
  --screenshot="$out" "http://127.0.0.1:$port/index.html?file=lit.glb" 2>/dev/null
echo "wrote $out"
