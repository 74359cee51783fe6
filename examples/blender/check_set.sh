#!/usr/bin/env bash
# Renders the Cycles check set (check_scenes.py; docs/TUNING.md, key CC) into
# OUT_DIR: only the files that are missing, one render at a time.
#
#   examples/blender/check_set.sh OUT_DIR
#
# Per scene NAME (glossy, spines, mirror, outdoor; with SCENES="stage shelf
# street" the held-out set CC2 of docs/TUNING.md), 256x256:
#   NAME_64_s1.exr, NAME_64_s2.exr   64 spp, seeds 1 and 2
#   NAME_512_s1.exr                  512 spp, seed 1
#   NAME_ref.exr                     the converged reference: 2048 spp, seed 1000
#                                    (its noise independent of the others')
#   NAME_ref_rgb.exr                 the reference's Combined as R, G, B
#                                    (for dcm reconstruct --reference)
#   NAME.blend                       the scene as rendered at 64 spp, seed 1
#                                    (for dcm blender NAME.blend)
# and times.tsv: per render, Blender's wall clock (start-up included) and
# Cycles' own render time from the EXR's metadata.
#
# Environment: BLENDER (default blender), THREADS (Cycles threads, default 2),
# SCENES (default "glossy spines mirror outdoor"), RES (default 256),
# FILTER (the pixel filter, TYPE:WIDTH; default GAUSSIAN:0.01, near point
# sampling; Blender's own default is BLACKMAN_HARRIS:1.5).
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
[ $# -eq 1 ] || { echo "usage: $0 OUT_DIR" >&2; exit 2; }
dir="$1"
BLENDER="${BLENDER:-blender}"
THREADS="${THREADS:-2}"
SCENES="${SCENES:-glossy spines mirror outdoor}"
RES="${RES:-256}"
FILTER="${FILTER:-GAUSSIAN:0.01}"
command -v "$BLENDER" >/dev/null ||
  { echo "check_set.sh: no '$BLENDER' (sudo apt-get install --no-install-recommends blender)" >&2; exit 1; }
command -v oiiotool >/dev/null || { echo "check_set.sh: no oiiotool (scripts/install-deps.sh)" >&2; exit 1; }
mkdir -p "$dir"
times="$dir/times.tsv"
[ -f "$times" ] || printf 'file\tspp\tseed\twall_s\tcycles_render_time\n' > "$times"

render() {  # SCENE EXR SAMPLES SEED [ARGS...]: renders EXR unless it exists
  local scene="$1" exr="$2" spp="$3" seed="$4"
  shift 4
  [ -f "$exr" ] && return 0
  echo "rendering $(basename "$exr") (${RES}x${RES}, $spp spp, seed $seed)" >&2
  local t0 log="$dir/blender.log" tmp="${exr%.exr}.part.exr"
  t0=$(date +%s.%N)
  # Written under a temporary name: an interrupted render leaves no EXR that
  # the next run would take as done.
  "$BLENDER" -b --factory-startup --python "$here/check_scenes.py" -- --scene "$scene" --out "$tmp" \
    --res "$RES" --samples "$spp" --seed "$seed" --threads "$THREADS" --pixel-filter "$FILTER" "$@" > "$log" 2>&1 ||
    { tail -20 "$log" >&2; rm -f "$tmp"; exit 1; }
  mv "$tmp" "$exr"
  local wall cycles
  wall=$(awk -v a="$t0" -v b="$(date +%s.%N)" 'BEGIN { printf "%.3f", b - a }')
  cycles=$(oiiotool --info -v "$exr" | sed -n 's/.*cycles\.ViewLayer\.render_time: "\(.*\)"/\1/p')
  printf '%s\t%s\t%s\t%.1f\t%s\n' "$(basename "$exr")" "$spp" "$seed" "$wall" "$cycles" >> "$times"
  echo "$(basename "$exr"): ${wall%.*} s (Cycles $cycles)" >&2
}

for s in $SCENES; do
  blend=()
  [ -f "$dir/$s.blend" ] || blend=(--save-blend "$dir/$s.blend")
  # the .blend is saved by the 64-spp seed-1 render; without it that render is redone
  [ -f "$dir/$s.blend" ] || rm -f "$dir/${s}_64_s1.exr"
  render "$s" "$dir/${s}_64_s1.exr" 64 1 "${blend[@]}"
  render "$s" "$dir/${s}_64_s2.exr" 64 2
  render "$s" "$dir/${s}_512_s1.exr" 512 1
  render "$s" "$dir/${s}_ref.exr" 2048 1000
  if [ ! -f "$dir/${s}_ref_rgb.exr" ]; then
    oiiotool "$dir/${s}_ref.exr" --ch ViewLayer.Combined.R,ViewLayer.Combined.G,ViewLayer.Combined.B \
      --chnames R,G,B -o "$dir/${s}_ref_rgb.part.exr"
    mv "$dir/${s}_ref_rgb.part.exr" "$dir/${s}_ref_rgb.exr"
  fi
done
echo "check set in $dir" >&2
