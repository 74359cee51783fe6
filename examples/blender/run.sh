#!/usr/bin/env bash
# Renders the example room with Blender Cycles (only the EXRs that are missing)
# and its guides (the sun's shadow guide: 1 sample of the sun's direct light;
# the highlight guide: 16 samples of direct glossy light) and runs
# `dcm reconstruct --preset blender` on each render with its guides.
#
#   examples/blender/run.sh [VIEW ...]        views a, b, c (default: all three)
#
# Environment:
#   DCM=path       the dcm binary (default: build/tools/dcm/dcm of this repository)
#   BLENDER=path   blender (default: blender; Debian 12: apt-get install blender)
#   SAMPLES=256    Cycles samples per pixel of the 256x256 renders
#   SS=1           also render 512x512 at SAMPLES/4 (same cost, 4 samples per
#                  final pixel) and reconstruct it with --downsample 2
#   THREADS=2      Cycles render threads (0: all cores)
#   DCM_ARGS="..." extra flags for dcm reconstruct (e.g. "--method paper")
#   GUIDE=1        pass the guides (0: the render alone)
#
# Outputs in examples/blender/out/: room_<view>_<res>.exr (the render),
# shadow_guide_<view>_<res>.exr, highlight_guide_<view>_<res>.exr, and
# room_<view>_<res>/ with dcm.exr, stats.json, sample_map.png, preview.png,
# error_map.png.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
# shellcheck source=common.sh
. "$here/common.sh"
SAMPLES="${SAMPLES:-256}"
SS="${SS:-0}"
DCM_ARGS="${DCM_ARGS:-}"
GUIDE="${GUIDE:-1}"
views=("$@")
[ ${#views[@]} -eq 0 ] && views=(a b c)

require_tools run.sh

reconstruct() {  # exr dir [flags...]
  local exr="$1" dir="$2"
  shift 2
  mkdir -p "$dir"
  # shellcheck disable=SC2086
  "$DCM" reconstruct "$exr" --preset blender --quiet "$@" $DCM_ARGS \
    -o "$dir/dcm.exr" --stats "$dir/stats.json" --sample-map "$dir/sample_map.png" \
    --preview "$dir/preview.png" --error-map "$dir/error_map.png" > /dev/null
  /usr/bin/python3 - "$dir/stats.json" "$(basename "$dir")" <<'EOF'
import json, sys
s = json.load(open(sys.argv[1]))
r = s["reference"]
print("%-14s %4dx%-4d exact %6.2f %% (%6d of %7d)  PSNR %6.2f dB  relMSE %.6f  SSIM %.4f" % (
    sys.argv[2], s["width"], s["height"], 100 * s["exact_fraction"], s["exact_pixels"],
    s["total_pixels"], r["psnr"], r["relmse"], r["ssim"]))
EOF
}

guide() {  # view res: the guide inputs, or nothing with GUIDE=0
  [ "$GUIDE" = 1 ] || return 0
  render_shadow_guide "$out/shadow_guide_${1}_$2.exr" "$1" "$2"
  render_highlight_guide "$out/highlight_guide_${1}_$2.exr" "$1" "$2"
  echo "$out/shadow_guide_${1}_$2.exr $out/highlight_guide_${1}_$2.exr"
}

for v in "${views[@]}"; do
  exr="$out/room_${v}_256.exr"
  render_room "$exr" "$v" 256 "$SAMPLES" 1
  # shellcheck disable=SC2046
  reconstruct "$exr" "$out/room_${v}_256" $(guide "$v" 256)
  if [ "$SS" = 1 ]; then
    exr="$out/room_${v}_512.exr"
    render_room "$exr" "$v" 512 $(( (SAMPLES + 3) / 4 )) 1
    # shellcheck disable=SC2046
    reconstruct "$exr" "$out/room_${v}_512" --downsample 2 $(guide "$v" 512)
  fi
done
echo "(exact = pixels DCM asked Cycles for; PSNR on sRGB-encoded values clipped to [0,1], against the full render)"
