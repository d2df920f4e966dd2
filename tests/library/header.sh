#!/usr/bin/env bash
# header.sh -- the public header compiles alone, with nothing included
# before it, as C11 and as C++17, warnings as errors.
#
#   header.sh CC CXX INCLUDE_DIR WORK_DIR
set -euo pipefail
cc=$1 cxx=$2 include=$3 work=$4

[ -n "$cxx" ] && command -v "$cxx" > /dev/null ||
  { echo "header.sh: no C++ compiler (scripts/setup.sh installs g++)" >&2; exit 1; }
mkdir -p "$work"
printf '#include <radiosity.h>\n' > "$work/header_alone.c"
"$cc" -std=c11 -Wall -Wextra -Wpedantic -Werror -Wstrict-prototypes -Wundef \
  -I"$include" -fsyntax-only "$work/header_alone.c"
echo "C11: ok"
"$cxx" -std=c++17 -Wall -Wextra -Wpedantic -Werror -Wundef -Wold-style-cast \
  -x c++ -I"$include" -fsyntax-only "$work/header_alone.c"
echo "C++17: ok"
