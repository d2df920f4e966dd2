#!/usr/bin/env bash
# bake.sh BIN [OUTDIR] -- lightmap baking (`radiosity bake`) on generated offices of 2
# and 10 rooms (seed 3), each solved once to a solution file (2,000 elements: the
# charts are the patches, which the element count does not change), then baked from
# it at 10 and 50 texels per metre into 2048-texel atlases.  Prints, per run, the
# patches, the atlases, the fill ratio (chart texels / atlas texels) and the bake's
# seconds (charting, packing, filling, dilating and writing; best of 3) as the
# program reports them.
set -eu
BIN=$(realpath "$1"); OUT=${2:-/tmp/bake}; mkdir -p "$OUT"; cd "$OUT"
printf '%-6s %8s %6s %8s %7s %9s\n' rooms texels/m atlases fill bake_s glb+png_MB
for rooms in 2 10; do
  [ -f "office$rooms.obj" ] || "$BIN" generate office --rooms "$rooms" --seed 3 -o "office$rooms.obj" -q
  [ -f "office$rooms.radsol" ] ||
    "$BIN" solve "office$rooms.obj" --elements 2000 --threads 2 -q -o "office$rooms.radsol"
  for tpm in 10 50; do
    best=""; line=""
    for _ in 1 2 3; do
      line=$("$BIN" bake "office$rooms.radsol" --threads 2 --texels-per-metre "$tpm" -o "o${rooms}_$tpm.glb")
      s=$(echo "$line" | sed -n 's/.*baked in \([0-9.]*\) s.*/\1/p')
      best=$(echo "$s ${best:-1e9}" | awk '{print ($1 < $2 ? $1 : $2)}')
    done
    atlases=$(echo "$line" | sed -n 's/.* and \([0-9]*\) lightmaps\{0,1\} .*/\1/p')
    fill=$(echo "$line" | sed -n 's/.*(fill \([0-9.]*%\).*/\1/p')
    mb=$(du -cb "o${rooms}_$tpm.glb" o${rooms}_${tpm}_lightmap*.png | tail -1 | awk '{printf "%.1f", $1 / 1048576}')
    printf '%-6s %8s %6s %8s %7s %9s\n' "$rooms" "$tpm" "$atlases" "$fill" "$best" "$mb"
  done
done
