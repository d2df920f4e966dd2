#!/bin/sh
# bench/stream.sh [BUILD] -- memory and time of view factors in row blocks
# (docs/performance.md, "View factors at scale").  A generated office of
# 16 rooms (seed 1), surface level, method hybrid (the fastest reciprocal
# pair method), two threads, blocks of 64 rows:
#   1. 10,000 elements streamed to the end, and the projection from its
#      first 30 s (checks the projection);
#   2. 50,000 and 100,000 elements: peak memory, and the time projected
#      from 120 s of rows (a full 100,000-element run takes hours here);
#   3. the dense route at 10,000 elements for comparison (8 n^2 bytes).
# Peak RSS is the whole process's (getrusage / GNU time): mesh, Embree's
# BVH, one block, the S x S table, the C library.
set -eu
build=${1:-build}
bench=$build/bench/bench_stream
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$bench" 10000 --output "$work/full.json"
"$bench" 10000 --seconds 30 --output "$work/part.json"
"$bench" 50000 --seconds 120 --output "$work/x.json"
"$bench" 100000 --seconds 120 --output "$work/x.json"
"$build/radiosity" generate office --rooms 16 --seed 1 -q -o "$work/office.obj"
/usr/bin/time -f "dense route, 10000 elements: peak RSS %M kB, %e s" \
  "$build/radiosity" viewfactors "$work/office.obj" --elements 10000 --form-factors hybrid --threads 2 -q \
  -o "$work/dense.json"
