#!/bin/sh
# --target-psnr and --budget on the POV-Ray room in dense mode (docs/QUALITY.md):
# a threshold sweep, targets 40 and 45 dB, budgets at the sweep's fractions.
#
#   scripts/quality_check_povray.sh DCM FULL.exr OUTDIR
#
# FULL.exr: every pass merged, as scripts/povray_passes.sh OUT writes OUT/full.exr.
set -eu
D=$1 F=$2 O=$3
mkdir -p "$O"
py=/usr/bin/python3
# Steps of about x0.87 (scripts/quality_check.py): a budget is judged by the
# best single threshold within its fraction, which needs the sweep's cliffs.
for t in 0.6 0.52 0.45 0.391 0.34 0.297 0.26 0.228 0.2 0.173 0.15 0.14 0.128 0.11 0.0938 0.08 0.0693 0.06 0.052 0.045 0.0391 0.034; do
  "$D" reconstruct "$F" -o "$O/s_$t.exr" --stats "$O/s_$t.json" --threshold "$t" --quiet
  "$py" -c "import json, sys; s = json.load(open(sys.argv[1]))
print('sweep %s: %.2f dB at %.2f %%' % (sys.argv[2], s['reference']['psnr'], 100 * s['exact_fraction']))" "$O/s_$t.json" "$t"
done
for T in 40 45; do
  "$D" reconstruct "$F" -o "$O/q$T.exr" --stats "$O/q$T.json" --target-psnr "$T" --quiet
  "$py" -c "import json, sys; s = json.load(open(sys.argv[1]))
print('target %s: estimate %.2f [%s, %s], true %.2f dB, exact %.2f %%, %d runs' % (sys.argv[2], s['estimated_psnr'],
      s['estimated_psnr_low'], s['estimated_psnr_high'], s['reference']['psnr'], 100 * s['exact_fraction'], s['quality']['runs']))" \
    "$O/q$T.json" "$T"
done
for B in 0.0382 0.0515 0.0687; do
  "$D" reconstruct "$F" -o "$O/b$B.exr" --stats "$O/b$B.json" --budget "$B" --quiet
  "$py" -c "import json, sys; s = json.load(open(sys.argv[1]))
import glob
f = s['exact_fraction']
within = [w['reference']['psnr'] for w in map(lambda n: json.load(open(n)), glob.glob(sys.argv[3] + '/s_*.json'))
          if w['exact_fraction'] <= f]
print('budget %s: true %.2f dB at %.2f %%, estimate %.2f; the best single threshold within %.2f %%: %.2f dB' % (
    sys.argv[2], s['reference']['psnr'], 100 * f, s['estimated_psnr'], 100 * f, max(within) if within else float('nan')))" \
    "$O/b$B.json" "$B" "$O"
done
