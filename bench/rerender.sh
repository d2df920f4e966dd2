#!/usr/bin/env bash
# rerender.sh BIN [OUTDIR] -- drawing a view again from the solution file against
# solving again: a 2-room office (seed 3) at 6,000 elements, default solver, solved
# once to office2.radsol; then the same 512 x 512 view drawn both ways, best of 3,
# and the two PNGs compared byte for byte.  Prints the seconds of each.
set -eu
BIN=$(realpath "$1"); OUT=${2:-/tmp/rerender}; mkdir -p "$OUT"; cd "$OUT"
[ -f office2.obj ] || "$BIN" generate office --rooms 2 --seed 3 -o office2.obj -q
OPTS="--elements 6000 --threads 2"
best() { # best wall seconds of 3 runs of the command
  local b=""
  for _ in 1 2 3; do
    local t0 t1; t0=$(date +%s.%N); "$@" > /dev/null; t1=$(date +%s.%N)
    b=$(echo "$t0 $t1 ${b:-1e9}" | awk '{d = $2 - $1; print (d < $3 ? d : $3)}')
  done
  echo "$b"
}
solve=$(best "$BIN" solve office2.obj $OPTS -q -o office2.radsol)
again=$(best "$BIN" render office2.obj $OPTS -q -o solved.png)
file=$(best "$BIN" render office2.radsol --threads 2 -q -o from_file.png)
size=$(stat -c %s office2.radsol)
cmp -s solved.png from_file.png && same=yes || same=NO
printf 'solve once (writes %.1f MB):      %6.2f s\n' "$(echo "$size / 1048576" | bc -l)" "$solve"
printf 'render, solving again:            %6.2f s\n' "$again"
printf 'render from the solution file:    %6.2f s\n' "$file"
printf 'same PNG, byte for byte:          %s\n' "$same"
