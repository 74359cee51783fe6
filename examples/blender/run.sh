#!/usr/bin/env bash
# Renders the example room with Blender Cycles (only the EXRs that are missing)
# and runs `dcm reconstruct --preset blender` on each render.
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
#
# Outputs in examples/blender/out/: room_<view>_<res>.exr (the render) and
# room_<view>_<res>/ with dcm.exr, stats.json, sample_map.png, preview.png,
# error_map.png.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../.." && pwd)"
DCM="${DCM:-$root/build/tools/dcm/dcm}"
BLENDER="${BLENDER:-blender}"
SAMPLES="${SAMPLES:-256}"
SS="${SS:-0}"
THREADS="${THREADS:-2}"
DCM_ARGS="${DCM_ARGS:-}"
views=("$@")
[ ${#views[@]} -eq 0 ] && views=(a b c)

command -v "$BLENDER" >/dev/null || { echo "run.sh: no '$BLENDER' (sudo apt-get install --no-install-recommends blender)" >&2; exit 1; }
[ -x "$DCM" ] || { echo "run.sh: no dcm binary at $DCM (build it, or set DCM=...)" >&2; exit 1; }
out="$here/out"
mkdir -p "$out"

render() {  # view res samples exr
  [ -f "$4" ] && return 0
  echo "rendering $(basename "$4") (${2}x${2}, $3 spp; about 2-3 min on 2 cores)" >&2
  "$BLENDER" -b --factory-startup --python "$here/make_and_render.py" -- \
    --out "$4" --view "$1" --res "$2" --samples "$3" --threads "$THREADS" > "$out/blender.log" 2>&1 ||
    { tail -20 "$out/blender.log" >&2; exit 1; }
}

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

for v in "${views[@]}"; do
  exr="$out/room_${v}_256.exr"
  render "$v" 256 "$SAMPLES" "$exr"
  reconstruct "$exr" "$out/room_${v}_256"
  if [ "$SS" = 1 ]; then
    exr="$out/room_${v}_512.exr"
    render "$v" 512 $(( (SAMPLES + 3) / 4 )) "$exr"
    reconstruct "$exr" "$out/room_${v}_512" --downsample 2
  fi
done
echo "(exact = pixels DCM asked Cycles for; PSNR on sRGB-encoded values clipped to [0,1], against the full render)"
