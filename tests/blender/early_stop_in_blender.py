"""Inside Blender: Session._stopped_early, the rule that picks the exact pixels
of a round that Cycles' adaptive sampling stopped early and that must be
rendered again with every sample; how long careful renders keep their masked
pixels (_masked_stop); and where those pixels are rendered again
(_render_all_samples through _again) (plugins/blender/dcm_blender/scene.py).

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

# Session._careful's protection, and where _render_all_samples renders again:
# a Session without a Blender scene, its cost model's inputs set by hand.
sess = S.__new__(S)
sess.args = types.SimpleNamespace(call_seconds=0.3, max_calls=64, masked_min_samples=0, border_tile=0)
sess.width = sess.height = 256
sess.samples = 64
sess.pixel_seconds = lambda: 1e-4  # a pixel at every sample; a masked one a seventh of it per sample
failures = []
# Careful must keep every pixel past Cycles' first check (16 samples): in a
# render of 32 samples or fewer none may stop early, in a longer one none
# before 32 (an eighth of 32 or 64 samples is no protection: it stops at 16).
for n in (16, 32, 64, 256, 1024):
    plain, careful = S._masked_stop(sess, n), S._masked_stop(sess, n, careful=True)
    if careful < min(n, 32) or (n > 16 and careful <= plain):
        failures.append("careful at %d samples stops at %d (plain %d)" % (n, careful, plain))
# 41 stopped pixels scattered over the frame: a border per 16-px tile costs
# about 41 calls (12 s by the model), the whole frame one call and 32 masked
# samples per pixel (0.76 s).
ys_far = np.arange(41) * 6
xs_far = (np.arange(41) * 37) % 256
borders = []
sess._masked_pixels_stop = lambda n, careful=False: None
sess._set_border = borders.append
sess._render = lambda n, label, seed: {}
list(S._render_all_samples(sess, 32, "again", 0, xs_far, ys_far))
if borders != [None]:
    failures.append("41 scattered pixels rendered again in %d borders, not the whole frame" % len(borders))
# Two pixels in one 16-px tile: one border over that tile.
borders.clear()
list(S._render_all_samples(sess, 32, "again", 0, np.array([3, 5]), np.array([4, 9])))
if borders != [(0, 0, 16, 16)]:
    failures.append("two pixels of one tile rendered again in %s" % borders)
if failures:
    print("\n".join(failures), file=sys.stderr)
    sys.exit(1)
print("ok")
