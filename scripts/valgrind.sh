#!/usr/bin/env bash
# Valgrind memcheck over the unit-label tests (docs/testing.md): every
# suite's executable runs under
#   valgrind --error-exitcode=1 --leak-check=full
# with the narrow suppressions in scripts/valgrind.supp, and so does the
# radiosity program itself on one small render and one bad input (the
# suites that drive it run it as a child, which valgrind does not follow:
# their timing-based checks, the interruption tests, would not survive the
# slowdown).  Exit status 1 if any run reports an error or a leak.
#
#   scripts/valgrind.sh [BUILD_DIR]      (default: build; a Release build is fine)
set -uo pipefail
cd "$(dirname "$0")/.."
build="${1:-build}"
command -v valgrind >/dev/null || { echo "valgrind.sh: valgrind is not installed (apt-get install valgrind)" >&2; exit 2; }
test -x "$build/radiosity" || { echo "valgrind.sh: no $build/radiosity: build first" >&2; exit 2; }

vg=(valgrind --error-exitcode=1 --leak-check=full --errors-for-leak-kinds=definite,possible
    --show-leak-kinds=definite,possible --suppressions=scripts/valgrind.supp --quiet)
# Two threads: the parallel paths run, and valgrind (which serialises
# threads) is not slowed further by more.
export OMP_NUM_THREADS=2

failed=0
run() { # NAME CMD...
  local name=$1; shift
  local t0=$SECONDS
  if "${vg[@]}" --log-file="$log/$name.log" "$@" >"$log/$name.out" 2>&1; then
    echo "valgrind: $name ok ($((SECONDS - t0)) s)"
  else
    echo "valgrind: $name FAILED ($((SECONDS - t0)) s): see $log/$name.log"
    failed=1
  fi
}
log="$build/valgrind"
mkdir -p "$log"

# The unit suites, as CTest knows them: "Test command: EXE ARGS".
while read -r name; do
  cmd=$(ctest --test-dir "$build" -N -V -R "^${name}\$" | sed -n 's/^.*Test command: //p' | head -1)
  [ -n "$cmd" ] || continue
  eval "args=($cmd)" # CTest quotes the arguments
  run "$name" "${args[@]}"
done < <(ctest --test-dir "$build" -N -L unit | sed -n 's/^ *Test *#[0-9]*: *\([^ ]*\).*/\1/p')

# The program itself: a small render (every stage, with stats) and a bad scene.
tmp=$(mktemp -d)
run radiosity_render "$build/radiosity" render --elements 150 --width 24 --height 24 --threads 2 \
  -o "$tmp/v.png" --stats "$tmp/v.json" -q
printf 'o bad\nv 0 0 0\nv 1 0 0\nf 1 2 3\n' >"$tmp/bad.obj"
# valgrind's own errors exit 99 here: the program's failure is exit 1.
"${vg[@]}" --error-exitcode=99 --log-file="$log/radiosity_bad_input.log" "$build/radiosity" \
  render "$tmp/bad.obj" -o "$tmp/bad.png" >/dev/null 2>&1
if [ $? -eq 1 ]; then
  echo "valgrind: radiosity_bad_input ok"
else
  echo "valgrind: radiosity_bad_input FAILED: see $log/radiosity_bad_input.log"; failed=1
fi
rm -rf "$tmp"
exit $failed
