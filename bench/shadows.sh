#!/bin/sh
# bench/shadows.sh -- the default picture of the built-in Cornell box against
# the converged one (issue #26 item 3): relative RMS of luminance over the
# interior pixels and the share of them beyond 5% (bench/compare_images.py),
# for the default render and for the same render without the final gather.
#
#   bench/shadows.sh [RADIOSITY_BINARY] [-- EXTRA RENDER FLAGS...]
#       RADIOSITY_BINARY  default build/radiosity
#
# The reference: tests/data/cornell_render_128_seed{1,2}.pfm (path-traced by
# bench/pathtrace.c, tests/data/README.md) and cornell_render_128_ids.pfm; the
# 512 x 512 render is averaged over 4 x 4 blocks.  Needs python3-numpy.
# docs/performance.md quotes its output.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
root=$(dirname "$here")
bin=$root/build/radiosity
if [ $# -gt 0 ] && [ "$1" != "--" ]; then
    bin=$1
    shift
fi
[ "${1:-}" = "--" ] && shift
if [ ! -x "$bin" ]; then
    echo "shadows.sh: $bin is not an executable (build it: ./scripts/setup.sh)" >&2
    exit 1
fi
work=$(mktemp -d "${TMPDIR:-/tmp}/radiosity-shadows-XXXXXX")
trap 'rm -rf "$work"' EXIT INT TERM
data=$root/tests/data
for gather in 1 -1; do
    "$bin" render --quiet --direct-gather "$gather" "$@" -o "$work/render.pfm"
    if [ "$gather" = 1 ]; then
        echo "radiosity render $* (the default: final gather on)"
    else
        echo "radiosity render --direct-gather -1 $* (the elements alone)"
    fi
    /usr/bin/python3 "$here/compare_images.py" "$data/cornell_render_128_seed1.pfm" "$work/render.pfm" \
        --reference2 "$data/cornell_render_128_seed2.pfm" --ids "$data/cornell_render_128_ids.pfm" | sed 's/^/  /'
done
