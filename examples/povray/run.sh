#!/bin/sh
# scene.pov rendered with dcm, and in full for comparison.
#
#   examples/povray/run.sh [PATH/TO/dcm] [OUTDIR] [SIZE]
#
# `dcm povray --full` renders the beauty pass in full (OUTDIR/full.exr); `dcm
# povray` renders the guide passes, a preview and the pixels DCM asks for
# (OUTDIR/dcm.exr, sample_map.png, stats.json) and prints its PSNR against the
# full render. docs/POVRAY.md explains the passes; bench.sh times both.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
dcm=${1:-$here/../../build/tools/dcm/dcm}
out=${2:-$here/out}
size=${3:-512}
[ -x "$dcm" ] || { echo "run.sh: no dcm binary at $dcm (build it, or pass its path)" >&2; exit 1; }
mkdir -p "$out"
"$dcm" povray "$here/scene.pov" -o "$out/full.exr" --size "${size}x$size" --full
"$dcm" povray "$here/scene.pov" -o "$out/dcm.exr" --size "${size}x$size" --reference "$out/full.exr" \
    --sample-map "$out/sample_map.png" --stats "$out/stats.json"
