#!/usr/bin/env bash
# End to end, as a user runs it: `dcm blender ROOM.blend` against the full
# Cycles render of the same file at the same samples, in the same run, both
# from the command to the EXR (Blender start-up included); PSNR of both
# against a converged render (REF_SPP samples).
#
#   examples/blender/dcm_vs_cycles.sh OUT_DIR [RES=256] [SPP=512] [REF_SPP=2048] [VIEW=a]
#
# DCM_VARIANTS="FLAGS|FLAGS|..." runs dcm blender once per set of flags after
# the one full render; ADAPTIVE="0.01 0.03" renders with Cycles' adaptive
# sampling at those noise thresholds (same samples at most) for comparison. Prints one line per render and leaves in OUT_DIR:
# room.blend, full.exr, dcmN.exr, dcmN.json, ref.exr, times.txt.
set -euo pipefail
here=$(cd "$(dirname "$0")/../.." && pwd)
out=${1:?usage: dcm_vs_cycles.sh OUT_DIR [RES] [SPP] [REF_SPP] [VIEW]}
res=${2:-256} spp=${3:-512} ref_spp=${4:-2048} view=${5:-a}
dcm=${DCM:-$here/build/tools/dcm/dcm}
mkdir -p "$out"
cd "$out"
# The scene (examples/blender/make_and_render.py), saved after a 1-spp render.
[ -f room.blend ] || blender -b --factory-startup --python "$here/examples/blender/make_and_render.py" -- \
    --out room_1spp.exr --view "$view" --res "$res" --samples 1 --save-blend room.blend >/dev/null
render() {  # render SAMPLES OUT [NOISE_THRESHOLD [SEED_OFFSET]]: the file at SAMPLES (adaptive sampling at the threshold)
  blender -b room.blend --python-expr "
import bpy
sc = bpy.context.scene
sc.cycles.samples = $1
sc.cycles.seed += ${4:-0}
sc.cycles.use_adaptive_sampling = $([ -n "${3:-}" ] && echo True || echo False)
sc.cycles.adaptive_threshold = ${3:-0.01}
im = sc.render.image_settings
im.file_format = 'OPEN_EXR_MULTILAYER'; im.color_depth = '32'
sc.render.use_file_extension = False
sc.render.filepath = '$PWD/$2'
bpy.ops.render.render(write_still=True)" >/dev/null
}
now() { /usr/bin/python3 -c 'import time; print(time.monotonic())'; }  # the clock dcm's --stats use
since() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.3f", b - a }'; }  # seconds from $1 to $2
# DCM_VARIANTS: extra dcm flags per run, separated by '|' (default: one run, no flags).
IFS='|' read -r -a variants <<< "${DCM_VARIANTS:- }"
t0=$(now); render "$spp" full.exr; t1=$(now)
full_s=$(since "$t0" "$t1")
printf "full %.2f s\n" "$full_s" > times.txt
dcm_s=()
for i in "${!variants[@]}"; do
  t1=$(now)
  "$dcm" blender room.blend -o "dcm$i.exr" --stats "dcm$i.json" --samples "$spp" -q ${variants[$i]} >/dev/null
  t2=$(now)
  dcm_s+=("$(since "$t1" "$t2")")
  printf "dcm %s: %.2f s\n" "${variants[$i]}" "${dcm_s[$i]}" >> times.txt
done
# ADAPTIVE="T1 T2 ...": Cycles' adaptive sampling at these noise thresholds, the rival at equal time.
adaptive_s=()
for t in ${ADAPTIVE:-}; do
  t1=$(now); render "$spp" "adaptive_$t.exr" "$t"; t2=$(now)
  adaptive_s+=("$t:$(since "$t1" "$t2")")
  printf "adaptive %s: %.2f s\n" "$t" "$(since "$t1" "$t2")" >> times.txt
done
# The reference with a seed of its own: with the file's, its first samples
# would be the full render's and dcm's, and their errors against it smaller.
[ -f ref.exr ] || render "$ref_spp" ref.exr "" 1000
/usr/bin/python3 - "$full_s" "${DCM_VARIANTS:- }" "${adaptive_s[*]:-}" "${dcm_s[@]}" <<'PY'
import json, sys
import numpy as np
import OpenImageIO as oiio

def load(path):
    inp = oiio.ImageInput.open(path)
    spec, px = inp.spec(), inp.read_image("float")
    names = list(spec.channelnames)
    return px[:, :, [next(i for i, n in enumerate(names) if n.endswith("Combined." + c)) for c in "RGB"]]

def psnr(a, b):  # on sRGB-encoded values clipped to [0, 1], as docs/AOV.md
    enc = lambda x: np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(np.maximum(x, 0), 1 / 2.4) - 0.055)
    mse = np.mean((np.clip(enc(a), 0, 1) - np.clip(enc(b), 0, 1)) ** 2)
    return 10 * np.log10(1 / mse)

ref, full = load("ref.exr"), load("full.exr")
full_s = float(sys.argv[1])
print("full Cycles          %7.2f s           PSNR %.2f dB vs the converged render" % (full_s, psnr(full, ref)))
for item in sys.argv[3].split():
    t, s = item.split(":")
    print("adaptive %-6s       %7.2f s (%.2fx)  PSNR %.2f dB vs the converged render"
          % (t, float(s), full_s / float(s), psnr(load("adaptive_%s.exr" % t), ref)))
for i, (flags, s) in enumerate(zip(sys.argv[2].split("|"), sys.argv[4:])):
    dcm, j = load("dcm%d.exr" % i), json.load(open("dcm%d.json" % i))
    b, s = j["blender"], float(s)
    print("dcm blender %-20s %7.2f s (%.2fx)  PSNR %.2f dB (%.2f dB vs full); %.2f %% exact, %d calls %s; "
          "start %.2f s, guides+preview %.2f s, rounds %.2f s, engine %.2f s"
          % (flags.strip() or "(defaults)", s, full_s / s, psnr(dcm, ref), psnr(dcm, full), 100 * j["exact_fraction"],
             len(b["rounds"]), [r["pixels"] for r in b["rounds"]], b["startup_s"], b["guides_s"] + b["preview_s"],
             b["rounds_s"], b["engine_s"]))
PY
