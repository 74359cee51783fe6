#!/usr/bin/env bash
# What accuracy costs on the Cycles room (docs/AOV.md, issue 3): `dcm bench`
# on each view with its shadow and highlight guides, dcm against the paper, Guo and the two
# rivals (uniform grid + bilinear, + joint bilateral) at every threshold,
# block size and enhancement switch; CSV, summary and plots.
#
#   examples/blender/bench.sh OUTDIR [VIEW ...]     views a, b, c (default all)
#
# Environment: DCM, BLENDER, THREADS as for run.sh; SAMPLES=1024 (Cycles
# samples per pixel, seed 3: the renders are also the references of
# noise.sh); SS=1 also each view at 512x512 with SAMPLES per sub-pixel (4x
# the cost, 5-8 min per view on 2 cores), benched with --downsample 2 in
# OUTDIR/4x.
# Renders only the EXRs that are missing (examples/blender/out/).
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
# shellcheck source=common.sh
. "$here/common.sh"
SAMPLES="${SAMPLES:-1024}"
SS="${SS:-0}"
[ $# -ge 1 ] || { echo "usage: bench.sh OUTDIR [VIEW ...]" >&2; exit 2; }
dest="$1"
shift
views=("$@")
[ ${#views[@]} -eq 0 ] && views=(a b c)
require_tools bench.sh
command -v oiiotool >/dev/null || { echo "bench.sh: no oiiotool (scripts/install-deps.sh)" >&2; exit 1; }

inputs=()
for v in "${views[@]}"; do inputs+=("$(guided "$out/noise_${v}_${SAMPLES}_s3.exr" "$v" 256)"); done
"$DCM" bench "${inputs[@]}" --preset blender --out "$dest/1x"
if [ "$SS" = 1 ]; then
  inputs=()
  for v in "${views[@]}"; do inputs+=("$(guided "$out/noise_${v}512_${SAMPLES}_s3.exr" "$v" 512)"); done
  "$DCM" bench "${inputs[@]}" --preset blender --downsample 2 --out "$dest/4x"
fi
