# Where the samples of dcm blender's rounds go (docs/BLENDER.md, "Masked pixels
# stop early"): in each round render kept by keep_renders_child.py, the pixels
# Cycles rendered (a value other than 0: the exact pixels and the world) and
# the masked pixels (0) that took every sample because a neighbour had not
# converged (Cycles' convergence filter), against the masked pixels that
# stopped at the first check.
#
#   DCM_BLENDER_CHILD=examples/blender/keep_renders_child.py KEEP_DIR=DIR \
#     dcm blender SCENE.blend -o OUT.exr --samples 512
#   /usr/bin/python3 examples/blender/round_samples.py DIR
import glob
import os
import sys

import numpy as np

if len(sys.argv) != 2:
    sys.exit("usage: round_samples.py KEEP_DIR")
renders = sorted(glob.glob(os.path.join(sys.argv[1], "*_eval*.npz")))
if not renders:
    sys.exit("no round renders (NN_evalK.npz) in %s" % sys.argv[1])
print("%-22s %9s %9s %22s %12s" % ("render", "rendered", "masked", "masked, every sample", "per rendered"))
for path in renders:
    planes = np.load(path)
    value = np.stack([planes["Combined." + c] for c in "RGB"], axis=-1)
    took_all = planes["Debug Sample Count.X"] > 0.999  # the share of the samples it took
    rendered = (value != 0).any(axis=-1)
    masked = ~rendered
    full = masked & took_all
    print("%-22s %9d %9d %14d (%4.1f %%) %12.2f" % (os.path.basename(path), rendered.sum(), masked.sum(), full.sum(),
                                                   100.0 * full.sum() / max(masked.sum(), 1),
                                                   full.sum() / max(rendered.sum(), 1)))
