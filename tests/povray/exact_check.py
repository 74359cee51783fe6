#!/usr/bin/python3
"""The exact pixels of a `dcm povray` result against a full render.

  exact_check.py OUT.exr FULL.exr SAMPLE_MAP.png

The exact pixels are those the sample map does not draw as interpolated
(dark gray, tools/common/sample_map.cpp). Prints
"exact N total T maxrel X beyond K": the largest difference relative to the
value, and how many channel values differ by more than two half-float steps.

Why two half-float steps: POV-Ray writes half floats (10 mantissa bits, one
step = 2^-10 of the value's power of two, at most 2^-10 relative). An exact
pixel is POV-Ray's own value for the ray of the mesh camera, whose direction
comes from a float mesh instead of the perspective camera's double: the
shading differs in the last float bits, which moves a value across at most
one half-float rounding boundary (one step); the engine's L = L_i*tau + L_c
adds float rounding (1e-7). 2^-9 relative (+2^-24 absolute for values near
zero, half's smallest step) is two steps: a pixel of another ray or another
pass differs by far more.
"""
import sys

import numpy as np
import OpenImageIO as oiio


def read(path):
    buf = oiio.ImageBuf(path)
    px = buf.get_pixels(oiio.FLOAT)
    if buf.has_error or px is None:
        sys.exit(f"exact_check: cannot read {path}: {buf.geterror()}")
    return px


out, full, smap = read(sys.argv[1])[:, :, :3], read(sys.argv[2])[:, :, :3], read(sys.argv[3])
h, w = out.shape[:2]
if full.shape[:2] != (h, w):
    sys.exit(f"exact_check: {sys.argv[1]} is {w}x{h}, {sys.argv[2]} {full.shape[1]}x{full.shape[0]}")
m = np.round(smap[:h, :w, :3] * 255).astype(int)
exact = ~np.all(m == 40, axis=-1)
a, b = out[exact], full[exact]
rel = np.abs(a - b) / np.maximum(np.maximum(np.abs(a), np.abs(b)), 2.0 ** -14)
beyond = int((np.abs(a - b) > 2.0 ** -9 * np.maximum(np.abs(a), np.abs(b)) + 2.0 ** -24).sum())
print(f"exact {int(exact.sum())} total {w * h} maxrel {float(rel.max()) if rel.size else 0:.3g} beyond {beyond}")
