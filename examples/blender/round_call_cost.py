# What a render call of `dcm blender`'s rounds costs Cycles beyond its exact
# pixels (docs/BLENDER.md, "Render borders"): a round of no pixel over the
# whole frame and over one 16-px tile, at 64 and 512 samples (the difference
# per pixel and sample is the child's VISIT_SECONDS); then a round of about
# 130 pixels in 12 clusters at 512 samples, over the whole frame and within
# the borders of their 16- and 32-px tiles, cropped to the border or not.
# The fastest of three each, the call's wall clock (the render, its EXR and
# the reading of it). Run from the source tree:
#
#   blender -b SCENE.blend --python examples/blender/round_call_cost.py
import os
import sys
import tempfile
import time

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "plugins", "blender"))
from dcm_blender import child, scene  # noqa: E402

args = child.parse_args(["--samples", "512", "--workdir", tempfile.mkdtemp()])
s = scene.Session(args, args.workdir)


def call(xs, ys, n, rects, crop=True):
    """Seconds for one round of pixels (xs, ys) at n samples in `rects`."""
    s._write_mask(s.mask_of(xs, ys))
    s._masked_pixels_stop(n)
    s._keep_alive(False)
    t = time.monotonic()
    for r in rects:
        s._set_border(r)
        if r is not None and not crop:
            s.scene.render.use_crop_to_border = False
            s._crop = (0, 0, s.width, s.height)  # the whole frame comes back, 0 outside the border
        s._render(n, "cost")
    s._set_border(None)
    return time.monotonic() - t


try:
    s.setup()
    s.guides()
    w, h = s.width, s.height
    name = os.path.basename(sys.argv[sys.argv.index("-b") + 1])
    none = (np.zeros(0, np.int64), np.zeros(0, np.int64))
    empty = {}
    for n in (64, 512):
        for what, rects in (("whole frame", [None]), ("one 16-px tile", [(96, 96, 112, 112)])):
            empty[(what, n)] = min(call(*none, n, rects) for _ in range(3))
            print("%s: a round of no pixel, %s, %d samples: %.3f s" % (name, what, n, empty[(what, n)]))
    visit = (empty[("whole frame", 512)] - empty[("whole frame", 64)]) / (448 * w * h)
    print("%s: per pixel and sample beyond the 16 of a masked pixel: %.2g s" % (name, visit))
    rng = np.random.default_rng(1)
    cx, cy = rng.integers(8, w - 8, 12), rng.integers(8, h - 8, 12)
    xs = np.concatenate([c + rng.integers(-3, 4, 12) for c in cx])
    ys = np.concatenate([c + rng.integers(-3, 4, 12) for c in cy])
    k = np.unique(ys * w + xs)
    xs, ys = k % w, k // w
    for what, rects, crop in (("whole frame", [None], True),
                              ("16-px tiles, cropped", s._runs(xs, ys, 16), True),
                              ("16-px tiles, not cropped", s._runs(xs, ys, 16), False),
                              ("32-px tiles, cropped", s._runs(xs, ys, 32), True)):
        t = min(call(xs, ys, 512, rects, crop) for _ in range(3))
        print("%s: a round of %d pixels, 512 samples, %s (%d calls): %.3f s" % (name, len(xs), what, len(rects), t))
finally:
    s.restore()
sys.stdout.flush()
os._exit(0)
