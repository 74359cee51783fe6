#!/bin/sh
# Speed-up against PSNR for `dcm povray`: one full render of the scene, then
# dcm at several contrast thresholds, each timed end to end (every start-up
# and POV-Ray process included) in the same run; the PSNR is against that
# run's full render. Writes OUTDIR/tradeoff.csv and the plot PNG.
#
#   examples/povray/tradeoff.sh [PATH/TO/dcm] [OUTDIR] [SIZE] [SCENE] [PNG] [THRESHOLDS]
set -eu
here=$(cd "$(dirname "$0")" && pwd)
dcm=${1:-$here/../../build/tools/dcm/dcm}
out=${2:-$here/out}
size=${3:-512}
scene=${4:-$here/scene.pov}
png=${5:-$out/povray_tradeoff.png}
thresholds=${6:-0.3 0.2 0.14 0.1 0.07}
[ -x "$dcm" ] || { echo "tradeoff.sh: no dcm binary at $dcm" >&2; exit 1; }
mkdir -p "$out"
now() { date +%s.%N; }
t=$(now)
"$dcm" povray "$scene" -o "$out/full.exr" --size "${size}x$size" --full -q
full=$(awk -v a="$t" -v b="$(now)" 'BEGIN { printf "%.3f", b - a }')
csv=$out/tradeoff.csv
echo "threshold,full_s,dcm_s,speedup,psnr_db,exact_fraction,load" >"$csv"
for th in $thresholds; do
    t=$(now)
    "$dcm" povray "$scene" -o "$out/dcm.exr" --size "${size}x$size" --reference "$out/full.exr" \
        --threshold "$th" --stats "$out/dcm.json" -q
    d=$(awk -v a="$t" -v b="$(now)" 'BEGIN { printf "%.3f", b - a }')
    /usr/bin/python3 - "$out/dcm.json" "$th" "$full" "$d" "$(cut -d' ' -f1 /proc/loadavg)" >>"$csv" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
th, full, d, load = sys.argv[2], float(sys.argv[3]), float(sys.argv[4]), sys.argv[5]
print(f"{th},{full:.2f},{d:.2f},{full / d:.3f},{s['reference']['psnr']:.3f},{s['exact_fraction']:.5f},{load}")
PY
    tail -1 "$csv"
done
/usr/bin/python3 - "$csv" "$png" "$scene" "$size" <<'PY'
import csv, os, sys
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
rows = list(csv.DictReader(open(sys.argv[1])))
x = [float(r["psnr_db"]) for r in rows]
y = [float(r["speedup"]) for r in rows]
fig, ax = plt.subplots(figsize=(6, 4), dpi=120)
ax.plot(x, y, "o-", color="tab:blue", label="dcm povray (contrast threshold at each point)")
for r, a, b in zip(rows, x, y):
    ax.annotate(r["threshold"], (a, b), textcoords="offset points", xytext=(4, 4), fontsize=8)
ax.axhline(1.0, color="gray", lw=1, ls="--", label="POV-Ray's full render (1x)")
ax.set_xlabel("PSNR against the full render (dB, display-referred)")
ax.set_ylabel("speed-up, end to end (full render time / dcm time)")
ax.set_title(f"{os.path.basename(sys.argv[3])}, {sys.argv[4]}x{sys.argv[4]}: what accuracy costs in time", fontsize=10)
ax.grid(alpha=0.3)
ax.legend(fontsize=8)
fig.tight_layout()
fig.savefig(sys.argv[2])
print("wrote", sys.argv[2])
PY
