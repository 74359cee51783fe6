#!/bin/sh
# Reproduces docs/RESULTS.md: `dcm bench` on every bundled scene at the paper's
# sizes, one output folder per scene, then copies the plots and error maps
# into docs/img/ (error maps side by side, reduced: tools/bench/error_strip.py). Usage: tools/bench/run_results.sh [BUILD_DIR] [OUT_DIR]
# (defaults: build, build/bench-results). Takes about half an hour on 2 cores.
set -eu
root=$(cd "$(dirname "$0")/../.." && pwd)
build=${1:-$root/build}
out=${2:-$build/bench-results}
dcm=$build/tools/dcm/dcm
mkdir -p "$out" "$root/docs/img"
for scene in room room-paper cactus/cactus parquet mirror; do
  name=$(basename "$scene")
  "$dcm" bench "$root/examples/scenes/$scene.json" --threads 2 --out "$out/$name" > "$out/$name.log"
  cp "$out/$name/${name}_psnr_vs_time.png" "$out/$name/${name}_psnr_vs_exact.png" "$root/docs/img/"
done
# The error maps, reduced for the repository (full size in $out/SCENE/).
for name in room cactus parquet mirror; do
  /usr/bin/python3 "$root/tools/bench/error_strip.py" "$out/$name" "$name" "$root/docs/img/${name}_error_maps.png"
done
echo "results in $out; plots in $root/docs/img"
