#!/usr/bin/env bash
# exports.sh -- the shared library exports exactly the functions the public
# header declares: every one of them (each marked RAD_API), nothing else
# (the internals are rad_* too, so the check is against the header's list,
# not a prefix).
#
#   exports.sh SHARED_LIBRARY HEADER WORK_DIR
set -euo pipefail
library=$1 header=$2 work=$3
mkdir -p "$work"

# The header without comments and preprocessor lines: what remains is C.
perl -0777 -pe 's{/\*.*?\*/}{}gs' "$header" | grep -v '^[[:space:]]*#' > "$work/header.c"
# Every function it declares: a name followed by '('.
grep -oE '\brad_[a-z0-9_]+ *\(' "$work/header.c" | sed 's/ *($//' | sort -u > "$work/declared"
# The declarations marked RAD_API: the first name followed by '(' in each.
tr '\n' ' ' < "$work/header.c" | grep -oE 'RAD_API[^;]*;' |
  sed -E 's/^[^(]*\b(rad_[a-z0-9_]+) *\(.*$/\1/' | sort -u > "$work/marked"
# What the library exports.
nm -D --defined-only "$library" | awk '{ print $NF }' | sort -u > "$work/exported"

count=$(wc -l < "$work/declared")
[ "$count" -ge 30 ] || { echo "exports.sh: only $count functions found in $header" >&2; exit 1; }
status=0
if ! diff -u "$work/declared" "$work/marked" > "$work/diff"; then
  echo "exports.sh: functions declared without RAD_API (-) or misread (+):" >&2
  cat "$work/diff" >&2
  status=1
fi
if ! diff -u "$work/declared" "$work/exported" > "$work/diff"; then
  echo "exports.sh: $library exports what the header does not declare (+)," \
       "or misses what it does (-):" >&2
  cat "$work/diff" >&2
  status=1
fi
[ $status = 0 ] && echo "$count functions declared, marked RAD_API and exported; nothing else exported"
exit $status
