#!/usr/bin/env bash
# layers.sh -- the source follows the pipeline: a file includes only headers
# of its own folder and of folders upstream of it.
#
#   layers.sh [SOURCE_DIR]      (default: the tree this script is in)
#
# The chain is read from docs/architecture.md: the first line of its first
# code block that reads `room -> room -> ... -> room`.  Every
# `#include "folder/file.h"` in src/, cli/ and viewer/ whose folder comes
# LATER in that chain than the including file's folder is reported as
# file:line, and the script exits 1.  cli/ and viewer/ are the last rooms
# (they may include anything); "radiosity.h" is always allowed; includes
# without a folder ("options.h") are the file's own folder.  A folder that
# is neither in the chain nor cli/viewer is reported too: a new room goes
# into the document before its code does.
set -euo pipefail
root=${1:-$(cd "$(dirname "$0")/.." && pwd)}
doc="$root/docs/architecture.md"
[ -r "$doc" ] || { echo "layers.sh: cannot read $doc" >&2; exit 2; }

# The first code block (indented by four spaces or fenced by ```), and in it
# the first line made only of names joined by "->".
chain=$(awk '
  /^```/ { if (fenced) exit; fenced = 1; next }
  fenced || /^    / {
    # (split by hand: mawk 1.3.4 mismatches a repeated group here)
    line = $0; gsub(/[ \t]+/, "", line)
    n = split(line, name, "->"); ok = n >= 3
    for (i = 1; i <= n && ok; i++) ok = name[i] ~ /^[A-Za-z0-9_]+$/
    if (ok) { print line; exit }
    inblock = 1; next
  }
  inblock && !/^[ \t]*$/ { exit }
' "$doc")
[ -n "$chain" ] || {
  echo "layers.sh: no chain \`a -> b -> ...\` in the first code block of $doc" >&2; exit 2; }

# Each room's rank (0 = core); cli and viewer share the last one unless the
# chain names them.
cd "$root"
files=$(find src cli viewer -type f \( -name '*.c' -o -name '*.h' \) 2>/dev/null | LC_ALL=C sort)
[ -n "$files" ] || { echo "layers.sh: no source files found under $root" >&2; exit 2; }

# One pass over every include line ("file:line:text"); awk knows the ranks.
# shellcheck disable=SC2086
report=$( { grep -nH -E '^[[:space:]]*#[[:space:]]*include[[:space:]]*"[^"]+"' $files || true; } |
  awk -v chain="$chain" -v files="$(printf '%s ' $files)" '
  BEGIN {
    n = split(chain, room, "->")
    for (i = 1; i <= n; i++) rank[room[i]] = i
    last = ("cli" in rank) ? rank["cli"] : n + 1
    if (!("cli" in rank)) rank["cli"] = last
    if (!("viewer" in rank)) rank["viewer"] = last
    # Every file belongs to a known room, includes or not.
    m = split(files, list, " ")
    for (i = 1; i <= m; i++) {
      r = room_of(list[i])
      if (!(r in rank)) { printf "%s: folder '\''%s'\'' is not in the chain of docs/architecture.md (%s)\n", list[i], r, chain; bad++ }
    }
  }
  function room_of(f,   p) {
    if (f ~ /^cli\//) return "cli"
    if (f ~ /^viewer\//) return "viewer"
    split(f, p, "/"); return p[2]
  }
  {
    file = $0; sub(/:.*/, "", file)
    rest = substr($0, length(file) + 2); line = rest; sub(/:.*/, "", line)
    target = rest; sub(/^[^"]*"/, "", target); sub(/".*/, "", target)
    if (target == "radiosity.h" || index(target, "/") == 0) next
    to = target; sub(/\/.*/, "", to)
    from = room_of(file)
    if (!(from in rank)) next
    if (!(to in rank)) {
      printf "%s:%s: #include \"%s\": folder '\''%s'\'' is not in the chain of docs/architecture.md\n", file, line, target, to; bad++
    } else if (rank[to] > rank[from]) {
      printf "%s:%s: #include \"%s\" runs up the pipeline (%s includes %s, which comes after it)\n", file, line, target, from, to; bad++
    }
  }
  END { exit bad > 0 }') && status=0 || status=1

checked=$(printf '%s\n' $files | wc -l)
if [ "$status" -ne 0 ]; then
  printf '%s\n' "$report" >&2
  echo "layers.sh: the pipeline is $chain (docs/architecture.md); a file includes only its own and upstream folders" >&2
else
  echo "layers.sh: $checked files follow the pipeline $chain"
fi
exit "$status"
