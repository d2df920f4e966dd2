#!/usr/bin/env bash
# stats_runs.sh BIN OUTDIR -- the stats JSON (and view-factor files) of 20 fixed runs:
# every solver and form-factor method on the Cornell box, hierarchical on a 10-room
# office, gathering and shooting on a 2-room office.  Run it with the build before
# and after a change, then compare the two folders with compare_stats.py: a
# refactoring must print "identical".  About 10 s on 2 cores.
set -u
BIN=$1; OUT=$2; mkdir -p "$OUT"; cd "$OUT"
[ -f office10.obj ] || "$BIN" generate office --rooms 10 --seed 7 -o office10.obj -q
[ -f office2.obj ] || "$BIN" generate office --rooms 2 --seed 3 -o office2.obj -q
run() { name=$1; shift; "$BIN" "$@" --threads 2 -q --stats "$name.json" > "$name.log" 2>&1; echo "$name rc=$?"; }
for solver in gauss-seidel jacobi conjugate-gradient direct southwell; do
  run cb_$solver render -o cb_$solver.png --elements 800 --solver $solver --width 64 --height 64
done
run cb_shooting render -o cb_shooting.png --elements 800 --solver shooting --width 64 --height 64
run cb_hier render -o cb_hier.png --solver hierarchical --width 64 --height 64
run cb_hier_classic render -o cb_hier_classic.png --solver hierarchical --oracle classic --epsilon 3e-5 --width 64 --height 64
for ff in analytic contour hybrid hemicube hemisphere montecarlo; do
  run vf_$ff viewfactors -o vf_$ff.F.json --elements 400 --form-factors $ff
done
run vf_closure viewfactors office2.obj -o vf_closure.F.json --elements 400 --closure-correction  # closed: the correction refuses the open Cornell box
run vf_elem viewfactors -o vf_elem.mtx --elements 200 --level element
run office10_hier render office10.obj -o office10.png --solver hierarchical --width 64 --height 64
run office10_hier_cc render office10.obj -o office10cc.png --solver hierarchical --closure-correction --width 64 --height 64
run office2_gs render office2.obj -o office2.png --elements 1500 --width 64 --height 64
run office2_shoot render office2.obj -o office2s.png --elements 1500 --solver shooting --width 64 --height 64
