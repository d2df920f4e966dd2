#!/bin/sh
# bench/view3d_box.sh -- element view factors of the View3D box (issue #17,
# item 6) against View3D 3.2's figures measured on the same case.
#
#   bench/view3d_box.sh [N ...]        faces N x N (default: 20 30), plus
#                                      SIXTY=1 for 60 x 60 (21,606 elements,
#                                      3.7 GB of F) on 2 threads only
#
# The scene: bench/view3d_box.py N (a closed unit box, each face N x N
# quads, a 0.3 m cube in its middle; every row of F sums to exactly 1, so
# max |row sum - 1| is a true error).  The factors: the default method
# (analytic) through bench_view3d_box (build/bench/), timed without writing
# them, seed 0, no closure correction or other smoothing.  The same case as
# View3D input (.vs3, the cube as obstruction surfaces) is written beside
# the OBJ for `radiosity viewfactors` once it reads .vs3.
#
# View3D 3.2, single-threaded, measured in issue #17 on this case:
#   2,400 facets: 11.6 s; 5,400 facets: 63 s for the factors (152 s in
#   all); rows within about 2e-4 of 1.
set -eu

here=$(cd "$(dirname "$0")" && pwd)
root=$(dirname "$here")
bench=${BENCH:-$root/build/bench/bench_view3d_box}
if [ ! -x "$bench" ]; then
    echo "view3d_box.sh: $bench is not an executable (build with -DRADIOSITY_BENCH=ON)" >&2
    exit 1
fi
sizes=${*:-20 30}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

view3d_seconds() {
    case $1 in
        20) echo 11.6 ;;
        30) echo 63 ;;
        *) echo - ;;
    esac
}

printf '%9s %7s %9s %9s %12s %12s %12s %12s %10s\n' elements threads wall_s cpu_s rays pairs \
    'max|row-1|' reciprocity view3d_s
run() { # N THREADS
    python3 "$here/view3d_box.py" "$1" "$work/box$1.obj" "$work/box$1.vs3"
    printf '%s %10s\n' "$("$bench" "$work/box$1.obj" --threads "$2")" "$(view3d_seconds "$1")"
}
for n in $sizes; do
    run "$n" 1
    run "$n" 2
done
if [ "${SIXTY:-0}" = 1 ]; then
    run 60 2
fi
