#!/usr/bin/env bash
# `dcm blender --target-psnr T` against a sweep of global thresholds on one
# scene: the exact fraction each needs and its true PSNR against the
# converged image, and the target's exact fraction over that of the best
# single threshold whose truth reaches T (issue #22's bound: at most 1.3).
#
#   examples/blender/threshold_sweep.sh OUT_DIR SCENE.blend REF.exr FULL.exr
#
# REF.exr: the converged render (4x FULL's samples, another seed); FULL.exr:
# the full render at SPP. The truth is MSE(x, REF) less REF's own noise,
# MSE(FULL, REF) / 5. Environment: SPP (512), TARGET (40), THRESHOLDS
# ("1.0 0.8 0.6 0.42 0.3 0.21 0.15 0.105 0.075 0.05"), DCM (build/tools/dcm/dcm),
# BUDGETS (none): `--budget B` for each B, judged by the preview and by
# validation pixels, against the sweep's PSNR at the same exact fraction
# (interpolated in log fraction; issue #22's bound: within 0.5 dB).
set -euo pipefail
here=$(cd "$(dirname "$0")/../.." && pwd)
[ $# -eq 4 ] || { echo "usage: $0 OUT_DIR SCENE.blend REF.exr FULL.exr" >&2; exit 2; }
out=$1 blend=$2 ref=$3 full=$4
dcm=${DCM:-$here/build/tools/dcm/dcm}
spp=${SPP:-512} target=${TARGET:-40}
thresholds=${THRESHOLDS:-1.0 0.8 0.6 0.42 0.3 0.21 0.15 0.105 0.075 0.05}
mkdir -p "$out"
for t in $thresholds; do
  # RESUME=1 keeps the sweep's runs already in OUT_DIR (the same build and scene only).
  [ "${RESUME:-0}" = 1 ] && [ -f "$out/t$t.json" ] && continue
  "$dcm" blender "$blend" -o "$out/t$t.exr" --stats "$out/t$t.json" --samples "$spp" --threshold "$t" -q >/dev/null
done
"$dcm" blender "$blend" -o "$out/target.exr" --stats "$out/target.json" --samples "$spp" --target-psnr "$target" -q \
  >/dev/null
for b in ${BUDGETS:-}; do
  for judge in preview validation; do
    rm -f "$out/b${b}_$judge.json"
    "$dcm" blender "$blend" -o "$out/b${b}_$judge.exr" --stats "$out/b${b}_$judge.json" --samples "$spp" \
      --budget "$b" --estimate-from "$judge" -q >/dev/null || true
  done
done
BUDGETS="${BUDGETS:-}" /usr/bin/python3 - "$out" "$ref" "$full" "$target" $thresholds <<'PY'
import json, os, sys
import numpy as np
import OpenImageIO as oiio

out, ref_path, full_path, target = sys.argv[1], sys.argv[2], sys.argv[3], float(sys.argv[4])

def load(path):
    inp = oiio.ImageInput.open(path)
    spec, px = inp.spec(), inp.read_image("float")
    names = list(spec.channelnames)
    return px[:, :, [next(i for i, n in enumerate(names) if n.endswith("Combined." + c) or n == c) for c in "RGB"]]

enc = lambda x: np.clip(np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(np.maximum(x, 0), 1 / 2.4) - 0.055), 0, 1)
mse = lambda a, b: float(np.mean((enc(a) - enc(b)) ** 2))
ref = load(ref_path)
ref_noise = mse(load(full_path), ref) / 5

def row(name):
    j = json.load(open("%s/%s.json" % (out, name)))
    return 100 * j["exact_fraction"], -10 * np.log10(mse(load("%s/%s.exr" % (out, name)), ref) - ref_noise), j

print("| threshold | exact | true PSNR |")
print("|---|---:|---:|")
best = None
for t in sys.argv[5:]:
    exact, true, _ = row("t" + t)
    print("| %s | %.2f %% | %.2f |" % (t, exact, true))
    if true >= target and (best is None or exact < best[1]):
        best = (t, exact)
exact, true, j = row("target")
q = j.get("quality", {})
print("\n--target-psnr %g: %.2f %% exact, true %.2f dB, estimated %.2f dB (from the %s), thresholds %s"
      % (target, exact, true, j.get("estimated_psnr", float("nan")), j.get("estimated_psnr_from", "?"),
         [round(r["threshold"], 4) for r in q.get("ladder", [])] or q.get("threshold")))
if best:
    print("best single threshold reaching %g dB: %s at %.2f %% exact; ratio %.2f" % (target, best[0], best[1],
                                                                                     exact / best[1]))
else:
    print("no threshold of the sweep reaches %g dB" % target)
sweep = sorted(row("t" + t)[:2] for t in sys.argv[5:])
for b in os.environ["BUDGETS"].split():
    print("\n| --budget %s judged by | exact | true PSNR | estimated | the sweep at that fraction | render calls |" % b)
    print("|---|---:|---:|---:|---:|---:|")
    for judge in ("preview", "validation"):
        if not os.path.exists("%s/b%s_%s.json" % (out, b, judge)):
            print("| %s | refused (stderr above) | | | | |" % judge)
            continue
        exact, true, j = row("b%s_%s" % (b, judge))
        at = next((p0 + (p1 - p0) * np.log(exact / f0) / np.log(f1 / f0)
                   for (f0, p0), (f1, p1) in zip(sweep, sweep[1:]) if f0 <= exact <= f1 and f1 > f0), float("nan"))
        print("| %s | %.2f %% | %.2f | %.2f | %.2f | %d |" % (judge, exact, true, j.get("estimated_psnr", float("nan")),
                                                            at, len(j["blender"]["rounds"])))
PY
