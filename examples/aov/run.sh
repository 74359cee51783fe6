#!/bin/sh
# Makes a synthetic multilayer EXR and reconstructs it with DCM in dense mode:
# how many pixels would DCM have evaluated, and at what error?
#   examples/aov/run.sh [PATH/TO/dcm] [OUTDIR]
set -eu
here=$(cd "$(dirname "$0")" && pwd)
dcm=${1:-$here/../../build/tools/dcm/dcm}
out=${2:-$here/out}
mkdir -p "$out"
/usr/bin/python3 "$here/make_aovs.py" "$out/aovs.exr" 256
"$dcm" reconstruct "$out/aovs.exr" -o "$out/dcm.exr" \
    --stats "$out/stats.json" --sample-map "$out/sample_map.png" \
    --preview "$out/preview.png" --error-map "$out/error_map.png" -v
echo "outputs in $out: dcm.exr, stats.json, sample_map.png, preview.png, error_map.png"
