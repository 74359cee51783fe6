#!/usr/bin/env bash
# The cost of the split/merge path: a frame rendered in one process against
# the same frame as N tile processes run one after another plus `dcm merge`,
# with wall time and peak RSS of every process (/usr/bin/time -v), the pixels
# the tiles' halos evaluate twice, and a bit-for-bit check of the result.
#
#   scripts/tiles-benchmark.sh [SCENE] [TILES] [extra dcm render flags...]
#
# Defaults: examples/scenes/room.json, 8 tiles. DCM_BUILD_DIR picks the build
# (default build/). Prints a Markdown table (docs/TILES.md).
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
dcm=${DCM_BUILD_DIR:-$here/build}/tools/dcm/dcm
scene=${1:-$here/examples/scenes/room.json}
tiles=${2:-8}
shift $(($# > 2 ? 2 : $#))
[[ -x $dcm ]] || { echo "tiles-benchmark: no dcm binary at $dcm (build first, or set DCM_BUILD_DIR)" >&2; exit 2; }
[[ -x /usr/bin/time ]] || { echo "tiles-benchmark: needs /usr/bin/time (scripts/install-deps.sh installs it)" >&2; exit 2; }
out=$(mktemp -d /tmp/dcm-tiles-bench.XXXXXX)
trap 'rm -rf "$out"' EXIT

# Runs a command under /usr/bin/time -v; appends "wall_s rss_kib" to $out/times.
measure() {
  local label=$1
  shift
  /usr/bin/time -v -o "$out/time.txt" "$@" >"$out/$label.log" 2>&1 ||
    { cat "$out/$label.log" >&2; echo "tiles-benchmark: $label failed" >&2; exit 1; }
  local wall rss
  wall=$(awk -F': ' '/Elapsed \(wall clock\)/ {n = split($2, t, ":"); s = 0; for (i = 1; i <= n; ++i) s = s * 60 + t[i]; print s}' "$out/time.txt")
  rss=$(awk -F': ' '/Maximum resident set size/ {print $2}' "$out/time.txt")
  echo "$label $wall $rss" >>"$out/times"
}

echo "machine: $(nproc) cores, $(awk '/model name/ {sub(/.*: /, ""); print; exit}' /proc/cpuinfo); load before: $(cut -d' ' -f1-3 /proc/loadavg)"
measure whole "$dcm" render "$scene" -o "$out/whole.exr" --stats "$out/whole.json" --quiet "$@"
for ((i = 0; i < tiles; ++i)); do
  measure "tile$i" "$dcm" render "$scene" --tile "$i/$tiles" -o "$out/part$i.exr" --stats "$out/part$i.json" --quiet "$@"
done
measure merge "$dcm" merge "$out"/part*.exr -o "$out/merged.exr" --stats "$out/merged.json" --quiet
echo "load after: $(cut -d' ' -f1-3 /proc/loadavg)"

/usr/bin/python3 - "$out" "$tiles" <<'EOF'
import json, sys
import numpy as np
import OpenImageIO as oiio
out, tiles = sys.argv[1], int(sys.argv[2])
rows = {}
for line in open(f"{out}/times"):
    label, wall, rss = line.split()
    rows[label] = (float(wall), int(rss))
a = oiio.ImageBuf(f"{out}/whole.exr").get_pixels(oiio.FLOAT)
b = oiio.ImageBuf(f"{out}/merged.exr").get_pixels(oiio.FLOAT)
identical = a.shape == b.shape and not np.any(a.view(np.uint32) != b.view(np.uint32))
whole = json.load(open(f"{out}/whole.json"))
merged = json.load(open(f"{out}/merged.json"))
parts = [json.load(open(f"{out}/part{i}.json")) for i in range(tiles)]
window = sum(p["part"]["window_stats"]["total_pixels"] for p in parts)
window_exact = sum(p["part"]["window_stats"]["exact_pixels"] for p in parts)
frame = whole["total_pixels"]
tile_wall = sum(rows[f"tile{i}"][0] for i in range(tiles))
total = tile_wall + rows["merge"][0]
print(f"\n| run | wall s | peak RSS MiB |\n|---|---|---|")
print(f"| one process | {rows['whole'][0]:.2f} | {rows['whole'][1] / 1024:.0f} |")
for i in range(tiles):
    r = parts[i]["part"]["region"]
    print(f"| tile {i}/{tiles} (region {r[0]},{r[1]} {r[2]}x{r[3]}) | {rows[f'tile{i}'][0]:.2f} | {rows[f'tile{i}'][1] / 1024:.0f} |")
print(f"| merge | {rows['merge'][0]:.2f} | {rows['merge'][1] / 1024:.0f} |")
print(f"| **{tiles} tiles + merge, one after another** | **{total:.2f}** | max {max(rows[k][1] for k in rows if k != 'whole') / 1024:.0f} |")
print(f"\noverhead: {total / rows['whole'][0]:.2f}x the wall time of one process "
      f"({tile_wall / rows['whole'][0]:.2f}x for the tiles alone)")
print(f"working pixels reconstructed: {window} in the tiles' windows for {frame} in the frame ({window / frame:.2f}x, the halos)")
print(f"exact samples: {window_exact} in the windows, {whole['exact_pixels']} in one process ({window_exact / whole['exact_pixels']:.2f}x); "
      f"merged stats count {merged['exact_pixels']} exact pixels in the frame")
print(f"merged frame bit-identical to one process: {'yes' if identical else 'NO'}")
sys.exit(0 if identical else 1)
EOF
