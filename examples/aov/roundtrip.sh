#!/bin/sh
# The file-based round trip with a scripted "renderer" (render_pixels.py, which
# looks the requested pixels up in the synthetic scene): `dcm plan` asks for
# pixels, the renderer renders them into a samples EXR, until plan says done;
# then `dcm reconstruct` with the samples gives the same image as dense mode.
#   examples/aov/roundtrip.sh [PATH/TO/dcm] [OUTDIR]
set -eu
here=$(cd "$(dirname "$0")" && pwd)
dcm=${1:-$here/../../build/tools/dcm/dcm}
out=${2:-$here/out/roundtrip}
mkdir -p "$out"
rm -f "$out"/samples_*.exr
/usr/bin/python3 "$here/make_aovs.py" "$out/full.exr" 256
# The guides a renderer produces cheaply (IDs and texture values only).
oiiotool "$out/full.exr" --ch id,shader,tau.R,tau.G,tau.B -o "$out/guides.exr"
samples=""
round=0
while :; do
    # shellcheck disable=SC2086
    state=$("$dcm" plan "$out/guides.exr" $samples --list "$out/next.txt" --mask "$out/next_mask.exr" --quiet)
    echo "round $round: $state"
    [ "$state" = done ] && break
    /usr/bin/python3 "$here/render_pixels.py" "$out/full.exr" "$out/next.txt" "$out/samples_$round.exr"
    samples="$samples --samples $out/samples_$round.exr"
    round=$((round + 1))
done
# shellcheck disable=SC2086
"$dcm" reconstruct "$out/guides.exr" $samples -o "$out/sparse.exr" --stats "$out/sparse.json"
"$dcm" reconstruct "$out/full.exr" -o "$out/dense.exr" --quiet
/usr/bin/python3 - "$out/sparse.exr" "$out/dense.exr" <<'PY'
import sys, numpy as np, OpenImageIO as oiio
a, b = (oiio.ImageBuf(f).get_pixels(oiio.FLOAT) for f in sys.argv[1:3])
print("sparse round trip == dense mode, bit for bit:", np.array_equal(a.view(np.uint32), b.view(np.uint32)))
PY
