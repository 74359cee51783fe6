#!/usr/bin/env bash
# Renders every bundled scene with DCM and in full (dcm render --with-reference)
# and prints a Markdown table of exact fraction, times, speed-up and error
# (docs/RENDER.md). Usage: scripts/render-study.sh [BUILD_DIR] [OUT_DIR]
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$here/build}
out=${2:-$here/out/study}
mkdir -p "$out"
echo "| scene | working image | exact % | illumination s | DCM s | guides s | total s | full s | speed-up (wall) | speed-up (rays) | PSNR dB | relMSE |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|"
for scene in room room-paper parquet mirror cactus/cactus; do
  name=$(basename "$scene")
  "$build/tools/dcm/dcm" render "$here/examples/scenes/$scene.json" -o "$out/$name.exr" \
    --with-reference --stats "$out/$name.json" --sample-map "$out/${name}_samples.png" --quiet >/dev/null
  /usr/bin/python3 - "$out/$name.json" "$scene" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
t = s.get("time_s", s.get("time_dcm_s", 0))
g = s.get("time_guides_s", 0)
tot = s["time_wall_s"]
full = s["full"]["time_wall_s"]
rays = s["rays"]["total"] if "rays" in s else 0
ref = s.get("reference", {})
print(f"| {sys.argv[2]} | {s['resolution'][0]*s['options']['downsample']}x{s['resolution'][1]*s['options']['downsample']} | {100*s['exact_fraction']:.2f} | "
      f"{s['time_illum_s']:.2f} | {s.get('time_dcm_s', t):.2f} | {g:.2f} | {tot:.2f} | {full:.2f} | {full/tot:.1f}x | "
      f"{s['full']['rays']['total']/max(rays,1):.1f}x | {ref.get('psnr', float('nan')):.2f} | {ref.get('relmse', float('nan')):.2e} |")
PY
done
