#!/usr/bin/env bash
# Noisy Cycles renders (issue #8, docs/NOISE.md): dcm reconstructs from a
# 64-spp render with the noise detected and estimated from the data, or from two 64-spp
# renders of other seeds, and is compared against a converged render.
#
#   examples/blender/noise.sh [VIEW]            view a, b or c (default a)
#
# Environment: DCM, BLENDER, THREADS as for run.sh; SPP=64 (the noisy
# renders), REF_SPP=2048 (the converged reference: 116 s of Cycles for view a on 2 cores).
# Renders only the EXRs that are missing (examples/blender/out/noise_*.exr).
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
# shellcheck source=common.sh
. "$here/common.sh"
SPP="${SPP:-64}"
REF_SPP="${REF_SPP:-2048}"
view="${1:-a}"
require_tools noise.sh
command -v oiiotool >/dev/null || { echo "noise.sh: no oiiotool (scripts/install-deps.sh)" >&2; exit 1; }

a="$out/noise_${view}_${SPP}_s1.exr"
b="$out/noise_${view}_${SPP}_s2.exr"
ref="$out/noise_${view}_${REF_SPP}_s3.exr"
render_room "$a" "$view" 256 "$SPP" 1
render_room "$b" "$view" 256 "$SPP" 2
render_room "$ref" "$view" 256 "$REF_SPP" 3
# The sun's shadow guide (1 sample), a second input of every dcm run.
guide="$out/shadow_guide_${view}_256.exr"
render_shadow_guide "$guide" "$view" 256
# The reference's beauty as plain R, G, B for --reference.
layer=$(oiiotool --info -v "$ref" | sed -n 's/.*channel list: \([^ ,]*\)\.Combined\.R.*/\1/p' | head -1)
layer=${layer:-ViewLayer}
oiiotool "$ref" --ch "$layer.Combined.R,$layer.Combined.G,$layer.Combined.B" --chnames R,G,B -o "$out/noise_ref_rgb.exr"

run() {  # label flags...
  local label="$1"
  shift
  "$DCM" reconstruct --preset blender --quiet --reference "$out/noise_ref_rgb.exr" "$@" \
    -o "$out/noise_out.exr" --stats "$out/noise_stats.json" > /dev/null
  /usr/bin/python3 - "$out/noise_stats.json" "$label" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
r = s["reference"]
print("| %s | %.1f | %.2f | %.3g | %.4f |" % (sys.argv[2], 100 * s["exact_fraction"], r["psnr"], r["relmse"], r["ssim"]))
PY
}

echo "Cycles, view $view, 256x256; noisy renders $SPP spp (seeds 1, 2), reference $REF_SPP spp (seed 3); dcm runs with the shadow guide."
echo
echo "| input and method | exact % | PSNR dB | relMSE | SSIM |"
echo "|---|---|---|---|---|"
run "one render: the render itself" "$a" --full
run "one render: paper (noise taken at face value)" "$a" --method paper
run "one render: dcm, noise ignored (no variance)" "$a" "$guide" --no-detect-noise
run "one render: dcm, defaults (noise detected from the data)" "$a" "$guide"
run "one render: dcm --estimate-variance" "$a" "$guide" --estimate-variance
run "two renders: their mean" "$a" --second-render "$b" --full
run "two renders: dcm --second-render" "$a" "$guide" --second-render "$b"
