"""Inside Blender: Session._stopped_early, the rule that picks the exact pixels
of a round that Cycles' adaptive sampling stopped early and that must be
rendered again with every sample (plugins/blender/dcm_blender/scene.py).

    blender -b --factory-startup --python-exit-code 1 --python early_stop_in_blender.py -- SRC"""
import os
import sys
import types

import numpy as np

src = sys.argv[sys.argv.index("--") + 1]
sys.path.insert(0, os.path.join(src, "plugins", "blender"))
from dcm_blender import scene  # noqa: E402

S = scene.Session
n = 64
# One row of pixels: (samples taken, the round's value, preview half A, preview half B).
v = 0.3
cases = [
    ("every sample", 64, v * 1.1, v, v, False),
    ("all 0 so far, the preview black", 16, 0.0, 0.0, 0.0, False),
    ("all 0 so far, the preview lit", 16, 0.0, 0.0, 2 * v, True),
    ("constant, as the preview but for float rounding", 32, v * (1 + 3e-6), v, v * (1 - 2e-6), False),
    ("constant so far, the preview elsewhere", 32, v * (1 + 1e-3), v, v, True),
    ("as the preview's mean, whose halves differ", 48, v, v * (1 - 1e-3), v * (1 + 1e-3), True),
]
w = len(cases)
row = lambda k: np.array([[c[k] for c in cases]], np.float32)
took, L, A, B = row(1) / n, row(2), row(3), row(4)
rgb = lambda x: np.repeat(x[..., None], 3, axis=-1)
planes = {"Debug Sample Count.X": took, **{"Combined." + c: L for c in "RGB"}}
guides = {"L": rgb((A + B) / 2), "L_of_half": [rgb(A), rgb(B)]}
fake = types.SimpleNamespace(SAME=S.SAME, guides=lambda: guides, _rgb=lambda pl, name, comps="RGB": S._rgb(None, pl, name, comps))
xs, ys = np.arange(w), np.zeros(w, int)
again = S._stopped_early(fake, planes, n, xs, ys, np.ones(w, bool))
wrong = [c[0] for c, a in zip(cases, again) if bool(a) != c[5]]
if wrong:
    print("rendered again or not, wrongly: %s" % wrong, file=sys.stderr)
    sys.exit(1)
print("ok")
