#!/bin/sh
# bench/cornell_reference.sh -- the converged per-surface radiosity of the
# built-in Cornell box, tests/data/cornell_converged.json (test_defaults).
#
#   bench/cornell_reference.sh [RADIOSITY_BINARY] [OUT.json]
#
# Solves the box with its floor split along the blocks' footprints
# (bench/cornell_conforming.py: the same surfaces and areas, but no element
# straddles a contact line) on uniform meshes of falling element size,
# --mesh-size 0.04, 0.04/sqrt(2), 0.02, 0.02/sqrt(2) m (about 1,300 to
# 10,000 elements: gauss-seidel on analytic form factors, seed 0), and
# extrapolates each surface's mean to zero element size with
# bench/richardson.py (B(h) = B0 + c h^p, p fitted).  About 5 minutes on
# 2 cores, most of it the finest mesh's form factors.  MESH_SIZES="..."
# overrides the sequence.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
root=$(dirname "$here")
bin=${1:-$root/build/radiosity}
out=${2:-$root/tests/data/cornell_converged.json}
sizes=${MESH_SIZES:-0.04 0.028284271 0.02 0.014142136}
work=$(mktemp -d "${TMPDIR:-/tmp}/radiosity-reference-XXXXXX")
trap 'rm -rf "$work"' EXIT INT TERM

/usr/bin/python3 "$here/cornell_conforming.py" "$root/tests/data/cornell_box.obj" "$work/cornell.obj"
stats=
for h in $sizes; do
    "$bin" render "$work/cornell.obj" --solver gauss-seidel --form-factors analytic --seed 0 \
        --mesh-size "$h" --width 16 --height 16 --quiet -o "$work/h$h.png" --stats "$work/h$h.json"
    echo "mesh size $h m: done"
    stats="$stats $work/h$h.json"
done
# shellcheck disable=SC2086 # one argument per stats file
/usr/bin/python3 "$here/richardson.py" "$out" $stats
