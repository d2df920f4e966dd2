#!/bin/sh
# bench/povray.sh -- the default `radiosity render` of the built-in Cornell box
# against POV-Ray 3.7's radiosity on the same box (bench/peers/cornell.pov),
# whole process against whole process, at the same size and thread count.
#
#   bench/povray.sh [RADIOSITY_BINARY] [RUNS]
#       RADIOSITY_BINARY  default build/radiosity
#       RUNS              best of this many runs of each program, default 3
#   THREADS=N bench/povray.sh     both programs on N threads (default: nproc)
#   SIZE=W bench/povray.sh        W x W pixels (default 256)
#
# Prints each program's best wall time, the ratio, and the engine's
# per-surface error (area-mean radiosity, RGB) against the converged reference
# tests/data/cornell_converged.json (docs/testing.md says how it was made).
# Without povray on the PATH it says so, skips the comparison and still
# times the engine.  docs/performance.md quotes its output.
set -eu

here=$(cd "$(dirname "$0")" && pwd)
root=$(dirname "$here")
bin=${1:-$root/build/radiosity}
runs=${2:-3}
threads=${THREADS:-$(nproc)}
size=${SIZE:-256}
reference=$root/tests/data/cornell_converged.json

if [ ! -x "$bin" ]; then
    echo "povray.sh: $bin is not an executable (build it: ./scripts/setup.sh)" >&2
    exit 1
fi
work=$(mktemp -d "${TMPDIR:-/tmp}/radiosity-povray-XXXXXX")
trap 'rm -rf "$work"' EXIT INT TERM

# Best wall time of $runs runs of a command, in seconds (whole process:
# start-up, loading, solving, rendering, writing, teardown).
best_of() {
    best=
    i=0
    while [ "$i" -lt "$runs" ]; do
        t0=$(date +%s.%N)
        "$@" > "$work/out.log" 2>&1 || { echo "povray.sh: failed: $*" >&2; cat "$work/out.log" >&2; exit 1; }
        t1=$(date +%s.%N)
        best=$(echo "$t0 $t1 ${best:-inf}" | awk '{ t = $2 - $1; b = $3; if (b == "inf" || t < b) b = t; print b }')
        i=$((i + 1))
    done
    echo "$best"
}

ours=$(best_of "$bin" render --width "$size" --height "$size" --threads "$threads" --quiet \
    -o "$work/radiosity.png" --stats "$work/stats.json")
echo "radiosity render --width $size --height $size --threads $threads: $ours s (best of $runs)"

if command -v povray > /dev/null 2>&1; then
    # +WT: render threads; -D: no display; the user configuration file need
    # not exist (povray warns on stderr and goes on).
    theirs=$(best_of povray +I"$here/peers/cornell.pov" +W"$size" +H"$size" -D +WT"$threads" \
        +O"$work/povray.png")
    echo "povray +I bench/peers/cornell.pov +W$size +H$size -D +WT$threads: $theirs s (best of $runs)"
    echo "$theirs $ours" | awk '{ printf "ratio povray / radiosity: %.1f\n", $1 / $2 }'
else
    echo "povray: not installed (Debian package povray), comparison skipped"
fi

/usr/bin/python3 - "$reference" "$work/stats.json" << 'EOF'
import json, sys
ref = {s["name"]: s for s in json.load(open(sys.argv[1]))["surfaces"]}
got = {s["name"]: s["radiosity"] for s in json.load(open(sys.argv[2]))["surfaces"]}
worst = 0.0
print("per-surface error against the converged reference (R, G, B):")
for name, s in ref.items():
    errs = [g / b - 1.0 for g, b in zip(got[name], s["radiosity"])]
    worst = max(worst, max(abs(e) for e in errs))
    print("  %-12s %s" % (name, "  ".join("%+6.2f%%" % (100 * e) for e in errs)))
print("worst: %.2f%% (target: within 1%%)" % (100 * worst))
EOF
