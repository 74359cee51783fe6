"""Inside Blender: a round rendered within render borders cropped to them
(Session._set_border, Session._render; plugins/blender/dcm_blender/scene.py)
gives every pixel of its crop the whole frame's value, bit for bit (the
pixels asked for, the masked ones and the world's), and nothing outside it, at frame sizes whose borders fall between Blender's whole pixels
(odd sizes, a resolution percentage).

    blender -b --factory-startup --python-exit-code 1 --python render_border_in_blender.py -- SRC"""
import os
import sys
import tempfile

import bpy
import numpy as np

src = sys.argv[sys.argv.index("--") + 1]
sys.path.insert(0, os.path.join(src, "plugins", "blender"))
from dcm_blender import child, scene  # noqa: E402

failures = []
sc = bpy.context.scene
sc.render.engine = "CYCLES"
sc.cycles.device = "CPU"
for rx, ry, pct in ((250, 190, 100), (301, 97, 100), (256, 256, 50)):
    sc.render.resolution_x, sc.render.resolution_y, sc.render.resolution_percentage = rx, ry, pct
    args = child.parse_args(["--samples", "4", "--workdir", tempfile.mkdtemp()])
    s = scene.Session(args, args.workdir)
    try:
        s.setup()
        s.guides()
        W, H = s.width, s.height
        pick = np.random.default_rng(2).choice(W * H, 200, replace=False)
        xs, ys = pick % W, pick // W
        s._write_mask(s.mask_of(xs, ys))
        s._masked_pixels_stop(0)
        s._keep_alive(False)
        s._set_border(None)
        whole = s._rgb(s._render(4, "whole", s.seeds[0]), "Combined")
        # Tiles of 16 px over the picked pixels, and slivers at the frame's corners.
        rects = s._runs(xs, ys, 16)[:12] + [(W - 7, H - 5, W, H), (0, 0, 3, 2)]
        for rect in rects:
            s._set_border(rect)
            got = s._rgb(s._render(4, "border", s.seeds[0]), "Combined")
            x0, y0, x1, y1 = s._crop
            if not (x0 <= rect[0] and y0 <= rect[1] and x1 >= rect[2] and y1 >= rect[3]):
                failures.append("%dx%d: the crop %s does not hold the border %s" % (W, H, s._crop, rect))
            # Every pixel of the crop: the picked ones, the masked (0) and the world's.
            if not np.array_equal(got[y0:y1, x0:x1], whole[y0:y1, x0:x1]):
                failures.append("%dx%d: the pixels of the crop %s differ from the whole frame's" % (W, H, s._crop))
            outside = np.ones((H, W), bool)
            outside[y0:y1, x0:x1] = False
            if got[outside].any():
                failures.append("%dx%d: the border %s has values outside its crop %s" % (W, H, rect, s._crop))
        s._set_border(None)
    finally:
        s.restore()

if failures:
    print("\n".join(failures), file=sys.stderr)
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(1)
print("render borders: cropped renders equal the whole frame's pixels")
sys.stdout.flush()
os._exit(0)
