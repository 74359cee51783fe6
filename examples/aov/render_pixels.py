#!/usr/bin/python3
"""A stand-in renderer for the round trip: renders the pixels of a `dcm plan`
list by looking them up in a full synthetic render, and writes them as a
samples EXR (Li.R/G/B, Lc.R/G/B and mask; the channels the plan names).

Usage: /usr/bin/python3 render_pixels.py FULL.exr LIST.txt SAMPLES.exr
"""
import sys

import numpy as np
import OpenImageIO as oiio

full, listfile, out = sys.argv[1:4]
buf = oiio.ImageBuf(full)
spec = buf.spec()
names = list(spec.channelnames)
pixels = buf.get_pixels(oiio.FLOAT)
wanted = None
xs, ys = [], []
for line in open(listfile):
    if line.startswith("# dcm plan:"):
        wanted = line.rsplit("channels: ", 1)[1].strip().split(",")
        continue
    if line.strip():
        x, y = map(int, line.split())
        xs.append(x)
        ys.append(y)
channels = [c for c in wanted if c != "mask"]
data = np.zeros((spec.height, spec.width, len(channels) + 1), np.float32)
for k, c in enumerate(channels):
    data[ys, xs, k] = pixels[ys, xs, names.index(c)]
data[ys, xs, -1] = 1.0
ospec = oiio.ImageSpec(spec.width, spec.height, len(channels) + 1, "float")
ospec.channelnames = tuple(channels + ["mask"])
o = oiio.ImageOutput.create(out)
o.open(out, ospec)
o.write_image(data)
o.close()
