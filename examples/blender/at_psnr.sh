#!/usr/bin/env bash
# The exact fraction dcm needs for a given PSNR on each Cycles view of the
# example room (issue 3's targets, docs/AOV.md): `dcm reconstruct` at several
# thresholds, and the fraction at the target interpolated linearly between
# the two thresholds whose PSNRs bracket it.
#
#   examples/blender/at_psnr.sh [VIEW ...] [-- DCM_FLAGS ...]    views a, b, c (default all)
#
# Environment: DCM, BLENDER, THREADS as for run.sh; SAMPLES=1024 (as
# bench.sh); SS=1 for the 4x renders (512x512, --downsample 2; default the
# 256x256 ones); TARGET in dB (default 40, with SS=1 45); THRESHOLDS (default
# "0.06 0.08 0.1 0.12 0.14 0.16"). Renders only the EXRs that are missing.
# Prints one line per view: the fraction at TARGET, then each threshold's
# exact % / PSNR dB.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
# shellcheck source=common.sh
. "$here/common.sh"
SAMPLES="${SAMPLES:-1024}"
SS="${SS:-0}"
views=()
while [ $# -gt 0 ] && [ "$1" != "--" ]; do views+=("$1"); shift; done
[ $# -gt 0 ] && shift  # the flags after --
[ ${#views[@]} -eq 0 ] && views=(a b c)
if [ "$SS" = 1 ]; then res=512 target="${TARGET:-45}" scale=(--downsample 2); else res=256 target="${TARGET:-40}" scale=(); fi
THRESHOLDS="${THRESHOLDS:-0.06 0.08 0.1 0.12 0.14 0.16}"
require_tools at_psnr.sh
command -v oiiotool >/dev/null || { echo "at_psnr.sh: no oiiotool (scripts/install-deps.sh)" >&2; exit 1; }
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT

for v in "${views[@]}"; do
  if [ "$SS" = 1 ]; then render="$out/noise_${v}512_${SAMPLES}_s3.exr"; else render="$out/noise_${v}_${SAMPLES}_s3.exr"; fi
  input="$(guided "$render" "$v" "$res")"
  points=()
  for t in $THRESHOLDS; do
    "$DCM" reconstruct "$input" --preset blender "${scale[@]}" --threshold "$t" "$@" \
      -o "$tmp/out.exr" --stats "$tmp/stats.json" --quiet
    points+=("$(/usr/bin/python3 -c 'import json, sys
s = json.load(open(sys.argv[1]))
print("%.4f,%.4f" % (100 * s["exact_fraction"], s["reference"]["psnr"]))' "$tmp/stats.json")")
  done
  /usr/bin/python3 - "$v" "$target" "${points[@]}" <<'EOF'
import sys
view, target = sys.argv[1], float(sys.argv[2])
points = sorted(tuple(map(float, p.split(","))) for p in sys.argv[3:])  # by exact %
at = None
for (f0, d0), (f1, d1) in zip(points, points[1:]):
    if min(d0, d1) <= target <= max(d0, d1) and d0 != d1:
        at = f0 + (f1 - f0) * (target - d0) / (d1 - d0)
        break
cells = " ".join("%.2f/%.2f" % p for p in points)
print("%s: %s at %g dB; exact %% / PSNR dB: %s" % (view, "%.2f %%" % at if at is not None else "not bracketed", target, cells))
EOF
done
