#!/usr/bin/env bash
# PSNR against wall time for Cycles: the full render, `dcm blender` and Cycles'
# own adaptive sampling, each timed end to end (Blender start-up included) in
# the same run, each against one converged render of its own seed. The noise
# axis of docs/NOISE.md and the rival of docs/BLENDER.md in one plot.
#
#   examples/blender/tradeoff.sh OUT_DIR [RES=256] [REF_SPP=2048]
#
# Environment: SPPS="16 64 256 512" (samples per pixel of the full renders and
# of dcm blender), ADAPTIVE="0.1 0.03 0.01" (noise thresholds of adaptive
# sampling, at the largest of SPPS), BLEND=FILE (a scene of your own; default
# the room of make_and_render.py, view VIEW=a), DCM_FLAGS (more dcm flags).
# Renders what is missing; writes OUT_DIR/tradeoff.csv and OUT_DIR/tradeoff.png.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
out=${1:?usage: tradeoff.sh OUT_DIR [RES] [REF_SPP]}
res=${2:-256} ref_spp=${3:-2048}
spps=${SPPS:-16 64 256 512}
mkdir -p "$out"
out=$(cd "$out" && pwd)
if [ -n "${BLEND:-}" ]; then
  # The scene and the files beside it (its textures), once.
  src=$(cd "$(dirname "$BLEND")" && pwd)
  for f in "$src"/*; do [ -e "$out/$(basename "$f")" ] || ln -s "$f" "$out/"; done
  [ -e "$out/room.blend" ] || ln -s "$src/$(basename "$BLEND")" "$out/room.blend"
elif [ ! -e "$out/room.blend" ]; then  # the room, made once, in OUT_DIR
  (cd "$out" && blender -b --factory-startup --python "$here/make_and_render.py" -- \
    --out room_1spp.exr --view "${VIEW:-a}" --res "$res" --samples 1 --save-blend room.blend >/dev/null)
fi
top=${spps##* }
for spp in $spps; do
  d="$out/spp$spp"
  mkdir -p "$d"
  # dcm_vs_cycles.sh renders in its folder: the scene, its files and the reference are shared.
  for f in "$out"/*; do
    case "$(basename "$f")" in spp*|tradeoff.*) continue ;; esac
    [ -e "$d/$(basename "$f")" ] || ln -s "$f" "$d/"
  done
  [ -f "$d/done" ] && continue
  adaptive=""
  [ "$spp" = "$top" ] && adaptive=${ADAPTIVE:-0.1 0.03 0.01}
  ADAPTIVE="$adaptive" DCM_VARIANTS="${DCM_FLAGS:- }" "$here/dcm_vs_cycles.sh" "$d" "$res" "$spp" "$ref_spp" "${VIEW:-a}" \
    | tee "$d/summary.txt"
  # The reference is rendered once, by the first run, and shared by the next.
  [ -e "$out/ref.exr" ] || mv "$d/ref.exr" "$out/ref.exr"
  ln -sf "$out/ref.exr" "$d/ref.exr"
  touch "$d/done"
done
/usr/bin/python3 - "$out" $spps <<'PY'
import csv, json, os, re, sys
import numpy as np
import OpenImageIO as oiio
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

out, spps = sys.argv[1], sys.argv[2:]

def load(path):
    inp = oiio.ImageInput.open(path)
    spec, px = inp.spec(), inp.read_image("float")
    names = list(spec.channelnames)
    return px[:, :, [next(i for i, n in enumerate(names) if n.endswith("Combined." + c)) for c in "RGB"]]

def psnr(a, b):  # display-referred: sRGB encodings clipped to [0, 1], as dcm's stats
    enc = lambda x: np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(np.maximum(x, 0), 1 / 2.4) - 0.055)
    return 10 * np.log10(1 / np.mean((np.clip(enc(a), 0, 1) - np.clip(enc(b), 0, 1)) ** 2))

ref = load(os.path.join(out, "ref.exr"))
rows = []
for spp in spps:
    d = os.path.join(out, "spp" + spp)
    times = dict(re.match(r"(.*?) *:? ([0-9.]+) s$", l.strip()).groups() for l in open(os.path.join(d, "times.txt")))
    rows.append(dict(kind="full", spp=spp, setting="", seconds=float(times["full"]),
                     psnr=psnr(load(os.path.join(d, "full.exr")), ref), exact_fraction=1.0))
    stats = json.load(open(os.path.join(d, "dcm0.json")))
    dcm_s = float(next(v for k, v in times.items() if k.startswith("dcm")))
    rows.append(dict(kind="dcm blender", spp=spp, setting="", seconds=dcm_s,
                     psnr=psnr(load(os.path.join(d, "dcm0.exr")), ref), exact_fraction=stats["exact_fraction"]))
    for f in sorted(os.listdir(d)):
        m = re.match(r"adaptive_(.*)\.exr$", f)
        if m:
            rows.append(dict(kind="adaptive", spp=spp, setting=m.group(1), seconds=float(times["adaptive " + m.group(1)]),
                             psnr=psnr(load(os.path.join(d, f)), ref), exact_fraction=""))
with open(os.path.join(out, "tradeoff.csv"), "w", newline="") as f:
    w = csv.DictWriter(f, fieldnames=list(rows[0]))
    w.writeheader()
    w.writerows(rows)
fig, ax = plt.subplots(figsize=(6.4, 4.2), dpi=120)
style = {"full": ("o-", "tab:gray", "Cycles, full render (spp)"),
         "dcm blender": ("s-", "tab:blue", "dcm blender (spp)"),
         "adaptive": ("^--", "tab:orange", "Cycles adaptive sampling (noise threshold)")}
for kind, (marker, colour, label) in style.items():
    pts = [r for r in rows if r["kind"] == kind]
    if not pts:
        continue
    ax.plot([r["seconds"] for r in pts], [r["psnr"] for r in pts], marker, color=colour, label=label)
    for r in pts:
        ax.annotate(r["setting"] or r["spp"], (r["seconds"], r["psnr"]), textcoords="offset points",
                    xytext=(4, -10 if kind == "full" else 4), fontsize=7, color=colour)
ax.set_xscale("log")
ax.set_xlabel("wall time, end to end (s, log scale; Blender start-up included)")
ax.set_ylabel("PSNR against a converged render (dB)")
ax.set_title("Cycles, %s: what accuracy costs in time" % os.path.basename(os.path.realpath(os.path.join(out, "room.blend"))),
             fontsize=10)
ax.grid(alpha=0.3, which="both")
ax.legend(fontsize=8)
fig.tight_layout()
fig.savefig(os.path.join(out, "tradeoff.png"))
for r in rows:
    print("%-12s %5s %-6s %8.2f s  %6.2f dB  %s" % (r["kind"], r["spp"], r["setting"], r["seconds"],
                                                   r["psnr"], r["exact_fraction"]))
print("wrote", os.path.join(out, "tradeoff.csv"), os.path.join(out, "tradeoff.png"))
PY
