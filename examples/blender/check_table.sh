#!/usr/bin/env bash
# Measures dcm on the Cycles check set (check_set.sh; docs/TUNING.md, key CC)
# and prints a Markdown table, one row per scene: the PSNR against the
# scene's 2048-spp reference of the 64-spp render itself (--full) and of
# `dcm reconstruct --preset blender [FLAGS]` on it, and the same at 512 spp.
#
#   examples/blender/check_table.sh OUT_DIR [-- DCM FLAGS...]
#
# PSNR is dcm's own (the stats' reference.psnr: sRGB-encoded, clipped to
# [0, 1]). "est." is the stats' estimated_psnr (only with --target-psnr or
# --budget); "noise" is what the AOV provider's detector said of the samples
# (the PSNR their noise alone would cost, and whether dcm took them as noisy;
# with --no-detect-noise, --estimate-variance or a second render it says
# nothing). Nothing is rendered: run check_set.sh OUT_DIR first.
#
# Environment: DCM (default build/tools/dcm/dcm of this repository),
# SCENES (default "glossy spines mirror outdoor").
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../.." && pwd)"
DCM="${DCM:-$root/build/tools/dcm/dcm}"
SCENES="${SCENES:-glossy spines mirror outdoor}"
[ $# -ge 1 ] || { echo "usage: $0 OUT_DIR [-- DCM FLAGS...]" >&2; exit 2; }
dir="$1"
shift
if [ $# -gt 0 ]; then
  [ "$1" = "--" ] || { echo "usage: $0 OUT_DIR [-- DCM FLAGS...]" >&2; exit 2; }
  shift
fi
flags=("$@")
[ -x "$DCM" ] || { echo "check_table.sh: no dcm binary at $DCM (build it, or set DCM=...)" >&2; exit 1; }
for s in $SCENES; do
  for f in "${s}_64_s1.exr" "${s}_512_s1.exr" "${s}_ref_rgb.exr"; do
    [ -f "$dir/$f" ] || { echo "check_table.sh: no $dir/$f (examples/blender/check_set.sh $dir)" >&2; exit 1; }
  done
done
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT

# run LABEL EXR REF [FLAGS...]: one dcm reconstruct; writes $tmp/LABEL.json
# and $tmp/LABEL.log (its -v lines).
run() {
  local label="$1" exr="$2" ref="$3"
  shift 3
  "$DCM" reconstruct "$exr" --preset blender -v --reference "$ref" "$@" \
    -o "$tmp/$label.exr" --stats "$tmp/$label.json" > "$tmp/$label.log" 2>&1 ||
    { echo "check_table.sh: failed: $DCM reconstruct $exr --preset blender --reference $ref $*" >&2;
      tail -5 "$tmp/$label.log" >&2; exit 1; }
}

echo "| scene | 64 spp: full | dcm exact % | dcm PSNR | est. | noise | 512 spp: full | dcm exact % | dcm PSNR | est. | noise |"
echo "|---|---:|---:|---:|---:|---|---:|---:|---:|---:|---|"
for s in $SCENES; do
  ref="$dir/${s}_ref_rgb.exr"
  for spp in 64 512; do
    run "${s}_${spp}_full" "$dir/${s}_${spp}_s1.exr" "$ref" --full
    run "${s}_${spp}_dcm" "$dir/${s}_${spp}_s1.exr" "$ref" "${flags[@]}"
  done
  /usr/bin/python3 - "$tmp" "$s" <<'PY'
import json, os, re, sys
tmp, scene = sys.argv[1], sys.argv[2]
cells = [scene]


def db(v):  # the stats write an infinite PSNR (identical images) as null
    return "inf" if v is None else "%.2f" % v


for spp in (64, 512):
    full = json.load(open(os.path.join(tmp, "%s_%d_full.json" % (scene, spp))))
    dcm = json.load(open(os.path.join(tmp, "%s_%d_dcm.json" % (scene, spp))))
    est = dcm.get("estimated_psnr")
    noise = "—"
    for line in open(os.path.join(tmp, "%s_%d_dcm.log" % (scene, spp))):
        m = re.search(r"samples: (noisy|taken as noise-free) \(.* about (-?[0-9.]+|inf) dB", line)
        if m:
            noise = "%s dB, %s" % (m.group(2), "noisy" if m.group(1) == "noisy" else "clean")
    cells += [db(full["reference"]["psnr"]), "%.2f" % (100 * dcm["exact_fraction"]), db(dcm["reference"]["psnr"]),
              db(est) if est is not None else "—", noise]
print("| " + " | ".join(cells) + " |")
PY
done
