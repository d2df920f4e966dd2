#!/usr/bin/env bash
# install.sh -- the installed library, used as the README says: install the
# build into a fresh prefix, take the README's example program (its first
# ```c block, verbatim), and build and run it against that prefix four ways:
# pkg-config shared and static (--static), CMake find_package(radiosity) with
# radiosity::radiosity and radiosity::radiosity_static.
#
#   install.sh CMAKE CC BUILD_DIR SOURCE_DIR WORK_DIR [FLAG...]
#
# FLAGs go to every compile and link of the example (the sanitizer flags in
# a sanitizer build: its libraries need the sanitizer runtime).
set -euo pipefail
cmake=$1 cc=$2 build=$3 source=$4 work=$5
shift 5
flags=("$@")

fail() { echo "install.sh: $*" >&2; exit 1; }

rm -rf "$work"
mkdir -p "$work"
prefix=$work/prefix
"$cmake" --install "$build" --prefix "$prefix" > "$work/install.log"

# The README's example, verbatim (the first ```c block).
awk '/^```c$/ { inside = 1; next } inside && /^```$/ { exit } inside' "$source/README.md" \
  > "$work/example.c"
lines=$(wc -l < "$work/example.c")
[ "$lines" -ge 10 ] || fail "README.md: no example program in a \`\`\`c block ($lines lines)"

# The example loads "room.obj": one room of the office generator, written by
# the installed program.
mkdir -p "$work/run"
"$prefix/bin/radiosity" generate office --rooms 1 --seed 1 -o "$work/run/room.obj" -q

# run NAME: run the example built as $work/NAME in $work/run; it must print
# the first surface's radiosity and write room.png.
run() {
  rm -f "$work/run/room.png"
  (cd "$work/run" && "$work/$1") > "$work/$1.out" || fail "$1 failed: $(cat "$work/$1.out")"
  grep -Eq '^[^:]+: B = [0-9.e+-]+ [0-9.e+-]+ [0-9.e+-]+ W/m\^2$' "$work/$1.out" ||
    fail "$1 printed '$(cat "$work/$1.out")'"
  [ -s "$work/run/room.png" ] || fail "$1 wrote no room.png"
  echo "$1: $(cat "$work/$1.out")"
}
# linked NAME yes|no: whether the program needs libradiosity.so at run time.
linked() {
  if readelf -d "$work/$1" | grep -q 'NEEDED.*libradiosity\.so'; then
    [ "$2" = yes ] || fail "$1 needs libradiosity.so; it should hold the static library"
  else
    [ "$2" = no ] || fail "$1 does not need libradiosity.so"
  fi
}

# ---- pkg-config ----
pc=$(find "$prefix" -name radiosity.pc)
[ -n "$pc" ] || fail "no radiosity.pc installed"
export PKG_CONFIG_PATH=${pc%/*}
version=$(sed -n 's/^#define RAD_VERSION_STRING "\(.*\)"$/\1/p' "$source/include/radiosity.h")
[ "$(pkg-config --modversion radiosity)" = "$version" ] ||
  fail "pkg-config says version $(pkg-config --modversion radiosity), the header $version"
libdir=$(pkg-config --variable=libdir radiosity)
case "$(realpath "$libdir")" in "$(realpath "$prefix")"/*) ;; *) fail "libdir $libdir is outside $prefix" ;; esac

# shellcheck disable=SC2046 # pkg-config's output is a list of words
"$cc" -std=c11 -Wall -Wextra -Wpedantic -Werror "${flags[@]}" "$work/example.c" \
  -o "$work/example_pc_shared" $(pkg-config --cflags --libs radiosity) -Wl,-rpath,"$libdir"
linked example_pc_shared yes
run example_pc_shared

# With both libraries installed the linker takes the shared one for
# -lradiosity; -l:libradiosity.a names the archive.
read -ra static_flags <<< "$(pkg-config --static --cflags --libs radiosity)"
archive=no
for i in "${!static_flags[@]}"; do
  if [ "${static_flags[$i]}" = -lradiosity ]; then
    static_flags[i]=-l:libradiosity.a
    archive=yes
  fi
done
[ $archive = yes ] || fail "pkg-config --static --libs gives no -lradiosity: ${static_flags[*]}"
"$cc" -std=c11 -Wall -Wextra -Wpedantic -Werror "${flags[@]}" "$work/example.c" \
  -o "$work/example_pc_static" "${static_flags[@]}"
linked example_pc_static no
run example_pc_static

# ---- CMake: find_package(radiosity) ----
"$cmake" -S "$source/tests/library/consumer" -B "$work/consumer" -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_C_COMPILER="$cc" -DCMAKE_PREFIX_PATH="$prefix" -DEXAMPLE="$work/example.c" \
  -DEXPECTED_DIR="$prefix" -DEXPECTED_VERSION="$version" -DCMAKE_C_FLAGS="${flags[*]}" > "$work/consumer.log" ||
  fail "configuring the CMake consumer failed: $(cat "$work/consumer.log")"
"$cmake" --build "$work/consumer" >> "$work/consumer.log" 2>&1 ||
  fail "building the CMake consumer failed: $(cat "$work/consumer.log")"
cp "$work/consumer/example_shared" "$work/example_cmake_shared"
cp "$work/consumer/example_static" "$work/example_cmake_static"
linked example_cmake_shared yes
run example_cmake_shared
linked example_cmake_static no
run example_cmake_static

rm -rf "$work"
