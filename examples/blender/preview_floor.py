#!/usr/bin/python3
"""What the preview's error estimate (DisplayError in lib/src/preview_correction.cpp,
without a correction: k = 0) says of images whose true error is known: the
converged render itself (true error 0: what it says is its floor) and any other
render, each beside its true display-referred MSE as a PSNR.

  preview_floor.py KEEP_DIR REF.exr [IMAGE.exr ...]

KEEP_DIR holds the renders of a `dcm blender` child run with --keep-renders; its
first two (01_guides.npz, 02_guides.npz) are the preview's halves. To keep them:

  KEEP_DIR=KEEP DCM_BLENDER_CHILD=$PWD/examples/blender/keep_renders_child.py dcm blender SCENE.blend -o OUT.exr --samples 64

Reads Blender's multilayer EXRs (…Combined.R/G/B) and plain R, G, B files."""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from compare_crops import encode, load  # noqa: E402


def halves(keep):
    out = []
    for name in ("01_guides.npz", "02_guides.npz"):
        d = np.load(os.path.join(keep, name))
        out.append(np.stack([d["Combined." + c] for c in "RGB"], -1).astype(np.float64))
    return out


def psnr(mse):
    return 10 * np.log10(1 / mse) if mse > 0 else float("inf")


def main():
    if len(sys.argv) < 3:
        raise SystemExit(__doc__)
    a, b = halves(sys.argv[1])
    ref = load(sys.argv[2])
    if ref.shape != a.shape:
        raise SystemExit("preview_floor.py: '%s' is %s, the preview %s" % (sys.argv[2], ref.shape[:2], a.shape[:2]))
    ea, eb = encode(a), encode(b)
    print("%-40s %12s %12s" % ("image", "true PSNR", "estimated"))
    for path in sys.argv[2:]:
        x = encode(load(path))
        # The estimator's unbiased-looking cross term at k = 0, as DisplayError computes it.
        estimate = (((x - ea) ** 2 + (x - eb) ** 2) / 2 - (ea - eb) ** 2 / 2).mean()
        true = ((x - encode(ref)) ** 2).mean()
        print("%-40s %9.2f dB %9.2f dB" % (os.path.basename(path), psnr(true), psnr(estimate)))


if __name__ == "__main__":
    main()
