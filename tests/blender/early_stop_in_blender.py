"""Inside Blender: Session._stopped_early, the rule that picks the exact pixels
of a round that Cycles' adaptive sampling stopped early and that must be
rendered again with every sample; where they are rendered again
(_render_all_samples through _again); and when a round switches the
keep-alive on instead (_keep_alive_pays, _keep_alive)
(plugins/blender/dcm_blender/scene.py).

    blender -b --factory-startup --python-exit-code 1 --python early_stop_in_blender.py -- SRC"""
import os
import sys
import types

import numpy as np

src = sys.argv[sys.argv.index("--") + 1]
sys.path.insert(0, os.path.join(src, "plugins", "blender"))
from dcm_blender import child, scene  # noqa: E402

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

# Where _render_all_samples renders again:
# a Session without a Blender scene, its cost model's inputs set by hand.
sess = S.__new__(S)
defaults = child.parse_args([])  # the child's call_seconds (0.03 s) and max_calls
sess.args = types.SimpleNamespace(call_seconds=defaults.call_seconds, max_calls=defaults.max_calls,
                                  masked_min_samples=0, border_tile=0)
sess.width = sess.height = 256
sess.samples = 64
sess.pixel_seconds = lambda: 1e-4  # a pixel at every sample; a masked one a seventh of it per sample
failures = []
# 41 stopped pixels scattered over the frame: a border per 16-px tile costs
# 41 calls (1.3 s by the model), the whole frame one call and 32 masked
# samples per pixel (0.51 s).
ys_far = np.arange(41) * 6
xs_far = (np.arange(41) * 37) % 256
borders = []
switched = []
sess._masked_pixels_stop = lambda n: None
sess._keep_alive = switched.append
sess._set_border = borders.append
sess._render = lambda n, label, seed: {}
list(S._render_all_samples(sess, 32, "again", 0, xs_far, ys_far))
if borders != [None]:
    failures.append("41 scattered pixels rendered again in %d borders, not the whole frame" % len(borders))
if switched != [False]:
    failures.append("a render again with every sample switched the keep-alive %s" % switched)
# Two pixels in one 16-px tile: one border over that tile.
borders.clear()
list(S._render_all_samples(sess, 32, "again", 0, np.array([3, 5]), np.array([4, 9])))
if borders != [(0, 0, 16, 16)]:
    failures.append("two pixels of one tile rendered again in %s" % borders)

# A late round at 512 samples, a pixel's cost the room's (6e-4 s): Cycles
# visits every pixel of a frame or border each sample (VISIT_SECONDS), so the
# whole frame costs 0.55 s by the model however few pixels it has. 132
# pixels in 12 clusters of 11 (12 16-px tiles, 0.44 s): borders; as many
# scattered over 132 tiles: the whole frame.
sess.samples = 512
sess.pixel_seconds = lambda: 6e-4
cx, cy = np.arange(12) * 21 + 5, (np.arange(12) * 77) % 240 + 5
clustered = (np.repeat(cx, 11) + np.tile(np.arange(11) % 4, 12), np.repeat(cy, 11) + np.tile(np.arange(11) // 4, 12))
rects = S.rectangles(sess, *clustered)
if rects == [None] or not all(S._inside(r, *clustered).any() for r in rects):
    failures.append("132 pixels in 12 clusters at 512 samples rendered in %s, not in their borders" % rects)
scattered = (np.arange(132) * 37 % 256, np.arange(132) * 2 % 256 // 16 * 16 + np.arange(132) // 16)
if S.rectangles(sess, *scattered) != [None]:
    failures.append("132 scattered pixels at 512 samples rendered within borders, not the whole frame")

# A border is cropped to its rectangle and a pixel more on each side, by
# fractions a quarter pixel inside Blender's whole pixels (y from the bottom).
fake_render = types.SimpleNamespace()
sess.scene = types.SimpleNamespace(render=fake_render)
S._set_border(sess, (16, 32, 48, 40))
r = fake_render
got = [int(r.border_min_x * 256), int(r.border_max_x * 256), int(r.border_min_y * 256), int(r.border_max_y * 256)]
got_rounded = [round(r.border_min_x * 256), round(r.border_max_x * 256), round(r.border_min_y * 256),
               round(r.border_max_y * 256)]
if not (r.use_border and r.use_crop_to_border) or sess._crop != (15, 31, 49, 41) \
        or got != [15, 49, 256 - 41, 256 - 31] or got_rounded != got:
    failures.append("a render border (16, 32, 48, 40) cropped to %s, Blender's pixels %s / %s"
                    % (sess._crop, got, got_rounded))
S._set_border(sess, (0, 0, 256, 256))
if sess._crop != (0, 0, 256, 256) or r.border_max_x > 1 or r.border_max_y > 1:
    failures.append("a border over the frame: %s, maxima %s %s" % (sess._crop, r.border_max_x, r.border_max_y))
S._set_border(sess, None)
if r.use_border or sess._crop is not None:
    failures.append("no border: use_border %s, crop %s" % (r.use_border, sess._crop))
sess.samples = 64
sess.pixel_seconds = lambda: 1e-4

# The keep-alive: on where pixels that might stop early (one preview half 0,
# the other not) would cost more to render again than it costs the round
# (KEEP_ALIVE_COST of its pixels' time). 4000 exact pixels at 64 samples cost
# 0.4 s, the keep-alive 0.048 s; rendering the 41 scattered ones again costs
# the whole frame (1.0 s by the model): on. Two such pixels in one 16-px tile
# among 30000 exact pixels: one border (0.034 s) against 0.36 s: off.
sess._keep_alive_scales = [types.SimpleNamespace(default_value=0.0) for _ in range(3)]
sess._keep_alive_on = False
half_a = np.full((256, 256, 3), 0.2, np.float32)
half_b = half_a.copy()
sess.guides = lambda: {"L": (half_a + half_b) / 2, "L_of_half": [half_a, half_b]}
exact = np.random.default_rng(1).choice(256 * 256, 30000, replace=False)
ex, ey = exact % 256, exact // 256
if S._keep_alive_pays(sess, ex[:4000], ey[:4000], 64):
    failures.append("the keep-alive on without a pixel that might stop early")
half_a[ys_far, xs_far] = 0.0
few = np.concatenate([exact[:4000 - 41], ys_far * 256 + xs_far])
if not S._keep_alive_pays(sess, few % 256, few // 256, 64):
    failures.append("the keep-alive off with 41 scattered pixels that might stop early among 4000")
scales, sess._keep_alive_scales = sess._keep_alive_scales, []
if S._keep_alive_pays(sess, few % 256, few // 256, 64):
    failures.append("the keep-alive on where no surface carries it")
sess._keep_alive_scales = scales
half_a[ys_far, xs_far] = 0.2
half_a[[4, 9], [3, 5]] = 0.0
two = np.concatenate([exact[np.isin(exact, [4 * 256 + 3, 9 * 256 + 5], invert=True)], [4 * 256 + 3, 9 * 256 + 5]])
if S._keep_alive_pays(sess, two % 256, two // 256, 64):
    failures.append("the keep-alive on for two pixels of one tile among 30000")
# Switched by the scale of its emission, only where it changes.
for on, want in ((True, S.KEEP_ALIVE), (True, S.KEEP_ALIVE), (False, 0.0)):
    S._keep_alive(sess, on)
    values = [k.default_value for k in sess._keep_alive_scales]
    if values != [want] * 3:
        failures.append("the keep-alive switched %s: scales %s" % (on, values))
# Which materials may carry it: those Cycles cannot take for a light.
import bpy  # noqa: E402


def material(kind, **inputs):
    m = bpy.data.materials.new(kind)
    m.use_nodes = True
    nt = m.node_tree
    if kind != "ShaderNodeBsdfPrincipled":
        node = nt.nodes.new(kind)
        if kind == "ShaderNodeGroup":  # an Emission inside a group
            node.node_tree = bpy.data.node_groups.new("glow", "ShaderNodeTree")
            node.node_tree.nodes.new("ShaderNodeEmission")
    for name, value in inputs.items():
        nt.nodes["Principled BSDF"].inputs[name].default_value = value
    return m


emits = {
    "a Principled BSDF as Blender makes it": (material("ShaderNodeBsdfPrincipled"), False),
    "a Principled BSDF with an emission strength and black colour": (
        material("ShaderNodeBsdfPrincipled", **{"Emission Strength": 5.0}), False),
    "a Principled BSDF with an emission colour": (
        material("ShaderNodeBsdfPrincipled", Emission=(1, 0.5, 0.2, 1)), True),
    "an Emission node": (material("ShaderNodeEmission"), True),
    "an Emission node in a node group": (material("ShaderNodeGroup"), True),
    "a script node": (material("ShaderNodeScript"), True),
}
for what, (m, want) in emits.items():
    if scene._may_emit(m.node_tree) != want:
        failures.append("%s: may emit %s" % (what, not want))
if failures:
    print("\n".join(failures), file=sys.stderr)
    sys.exit(1)
print("ok")
