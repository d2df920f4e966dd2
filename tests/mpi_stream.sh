#!/bin/sh
# mpi_stream.sh RADIOSITY MPIEXEC WORKDIR -- `mpirun -np 2 radiosity
# viewfactors` writes the bytes of the single process, in every streamed
# format (test_stream_mpi; registered only when the program links MPI).
# The single-process files take the dense route (they fit in memory) or
# blocks of their own size: the identity holds across both.
set -eu
radiosity=$1 mpiexec=$2 work=$3
rm -rf "$work" && mkdir -p "$work" && cd "$work"
# As root Open MPI wants --allow-run-as-root; on fewer cores than ranks,
# --oversubscribe.  One thread per rank: two ranks on a two-core machine.
run2() { "$mpiexec" --allow-run-as-root --oversubscribe -np 2 "$radiosity" viewfactors -q --threads 1 "$@"; }
run1() { "$radiosity" viewfactors -q --threads 1 "$@"; }
status=0
for case in "element mtx" "element csv" "surface json" "surface mtx"; do
  set -- $case
  run1 --elements 250 --level "$1" -o "one.$1.$2"
  run2 --elements 250 --level "$1" -o "two.$1.$2"
  run2 --elements 250 --level "$1" -o "two7.$1.$2" --block-rows 7
  for f in "two.$1.$2" "two7.$1.$2"; do
    if cmp "one.$1.$2" "$f"; then echo "same: $f"; else status=1; fi
  done
done
# A sampled method kept raw streams too, and is the same over two ranks.
run1 --elements 120 --form-factors hemicube --raw-form-factors --level element -o one.raw.mtx
run2 --elements 120 --form-factors hemicube --raw-form-factors --level element -o two.raw.mtx
cmp one.raw.mtx two.raw.mtx && echo "same: two.raw.mtx" || status=1
# Under mpirun only viewfactors is spread: render is refused, non-zero.
if "$mpiexec" --allow-run-as-root --oversubscribe -np 2 "$radiosity" render -q -o never.png >/dev/null 2>&1; then
  echo "render under mpirun was not refused"; status=1
fi
[ ! -e never.png ] || { echo "render under mpirun wrote an image"; status=1; }
exit $status
