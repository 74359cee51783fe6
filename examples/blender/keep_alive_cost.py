# What the keep-alive of `dcm blender`'s rounds costs Cycles (docs/BLENDER.md,
# "Masked pixels stop early"): the scene's render times with it off and on,
# the fastest of three each, for the whole frame at 32 samples and for a
# round of 5 % of the pixels at random at 256 samples (adaptive sampling on,
# as the child renders rounds). Run from the source tree:
#
#   blender -b SCENE.blend --python examples/blender/keep_alive_cost.py
import os
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "plugins", "blender"))
from dcm_blender import child, scene  # noqa: E402

args = child.parse_args(["--samples", "512", "--variance-halves", "--workdir", tempfile.mkdtemp()])
s = scene.Session(args, args.workdir)
try:
    s.setup()
    s.guides()
    w, h, k = s.width, s.height, args.mask_scale
    pick = np.random.default_rng(3).choice(w * h, w * h // 20, replace=False)
    times = {}
    for what, n in (("full frame", 32), ("round", 256)):
        if what == "full frame":
            s._write_mask(np.ones((h * k, w * k), np.float32))
            s._masked_pixels_stop(0)
        else:
            s._write_mask(s.mask_of(pick % w, pick // w))
            s._masked_pixels_stop(n)
        for on in (False, True) * 3:
            s._keep_alive(on)
            s._render(n, what)
            times.setdefault((what, on), []).append(s.render_seconds[-1][3])  # Cycles' own render time
    for what in ("full frame", "round"):
        off, on = min(times[(what, False)]), min(times[(what, True)])
        print("%s: %s, keep-alive off %.2f s, on %.2f s (%+.1f %%)"
              % (os.path.basename(sys.argv[sys.argv.index("-b") + 1]), what, off, on, 100 * (on / off - 1)))
finally:
    s.restore()
sys.stdout.flush()
os._exit(0)
