#!/usr/bin/env bash
# cycles.sh -- no two files of the library need each other, directly or
# through others: the graph "file A uses a symbol that file B defines" has
# no cycle.
#
#   cycles.sh OBJECT...        (CMake: $<TARGET_OBJECTS:radiosity_objects>)
#
# The graph comes from nm: each object's undefined symbols (U) against the
# global symbols the other objects define.  tsort orders it, and reports
# each loop it has to break; every loop is printed with the symbols that
# tie its files together, and the script exits 1.
set -euo pipefail
# CTest passes $<TARGET_OBJECTS:...> as one argument, a ;-list: split it.
objects=()
for a in "$@"; do IFS=';' read -r -a part <<< "$a"; objects+=("${part[@]}"); done
set -- "${objects[@]}"
[ $# -gt 0 ] || { echo "usage: cycles.sh OBJECT..." >&2; exit 2; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# An object's name as its source file: .../radiosity_objects.dir/src/core/core.c.o -> src/core/core.c
name_of() {
  local n=$1
  case $n in */CMakeFiles/*.dir/*) n=${n#*/CMakeFiles/*.dir/} ;; *) n=${n##*/} ;; esac
  printf '%s\n' "${n%.o}"
}

for obj in "$@"; do
  [ -r "$obj" ] || { echo "cycles.sh: cannot read $obj" >&2; exit 2; }
  printf '%s %s\n' "$obj" "$(name_of "$obj")"
done > "$work/names"
# POSIX format with the object first ("OBJECT: name type [value size]");
# defined globals are upper case (U is undefined; lower case is local).
nm -A -P "$@" | awk 'NR == FNR { name[$1 ":"] = $2; next }
  { f = name[$1] } f == "" { next }
  $3 == "U" { print "U", f, $2; next }
  $3 ~ /^[A-Z]$/ { print "D", f, $2 }' "$work/names" - > "$work/symbols"

# Edges "user definer symbol", one line per symbol; then file pairs for tsort.
awk '$1 == "D" && !($3 in def) { def[$3] = $2 }
     $1 == "U" { use[++n] = $2 " " $3 }
     END { for (i = 1; i <= n; i++) {
             split(use[i], u, " ")
             if ((u[2] in def) && def[u[2]] != u[1]) print u[1], def[u[2]], u[2] } }' \
  "$work/symbols" "$work/symbols" | LC_ALL=C sort -u > "$work/edges"
awk '{ print $1, $2 }' "$work/edges" | LC_ALL=C sort -u > "$work/pairs"
# Every file a node, even one with no edge.
awk '{ print $2, $2 }' "$work/symbols" | LC_ALL=C sort -u >> "$work/pairs"

files=$#
if tsort "$work/pairs" > /dev/null 2> "$work/tsort"; then
  echo "cycles.sh: $files files, no cycle ($(wc -l < "$work/edges") symbol uses between files)"
  exit 0
fi

# GNU tsort: "tsort: FILE: input contains a loop:" then "tsort: NODE" per member.
awk '/input contains a loop/ { if (n) print line; line = ""; n = 0; next }
     /^tsort: / { sub(/^tsort: /, ""); line = line (n++ ? " " : "") $0 }
     END { if (n) print line }' "$work/tsort" > "$work/loops"
[ -s "$work/loops" ] || { cat "$work/tsort" >&2; echo "cycles.sh: tsort failed" >&2; exit 2; }

count=$(wc -l < "$work/loops")
echo "cycles.sh: $count cycle(s) between the library's files (each loop tsort had to break; one file may be in several):" >&2
while read -r -a loop; do
  echo "cycle: ${loop[*]} (back to ${loop[0]})" >&2
  # Each file of the loop uses the next (tsort lists them so); the symbols.
  for i in "${!loop[@]}"; do
    a=${loop[$i]} b=${loop[$(((i + 1) % ${#loop[@]}))]}
    syms=$(awk -v x="$a" -v y="$b" '$1 == x && $2 == y { printf "%s%s", (n++ ? ", " : ""), $3 }' "$work/edges")
    echo "    $a uses $b: ${syms:-(none directly)}" >&2
  done
done < "$work/loops"
exit 1
