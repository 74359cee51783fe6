#!/usr/bin/python3
"""How concentrated an image's error is: the share of its display-referred
squared error (sRGB of R, G, B clipped to [0, 1], as dcm's PSNR) against a
reference that its N worst pixels hold, and where they are.

usage: scripts/error_share.py IMAGE.exr REFERENCE.exr [N ...]   (N: 100 1000 by default)

Reads Blender's `<layer>.Combined.R/G/B` or plain R, G, B."""
import sys

import numpy as np
import OpenImageIO as oiio


def rgb(path):
    inp = oiio.ImageInput.open(path)
    if inp is None:
        sys.exit("%s: %s" % (path, oiio.geterror()))
    names = list(inp.spec().channelnames)
    pixels = np.array(inp.read_image("float"))
    inp.close()
    for c in names:
        if c.endswith(".Combined.R") or c == "R":
            prefix = c[:-1]
            return pixels[..., [names.index(prefix + k) for k in "RGB"]]
    sys.exit("%s: no R, G, B channels" % path)


def srgb(x):
    x = np.clip(x, 0.0, 1.0)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * x ** (1 / 2.4) - 0.055)


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    image, ref = rgb(sys.argv[1]), rgb(sys.argv[2])
    if image.shape != ref.shape:
        sys.exit("%s is %s, %s is %s" % (sys.argv[1], image.shape, sys.argv[2], ref.shape))
    err = ((srgb(image) - srgb(ref)) ** 2).mean(axis=-1)
    order = np.argsort(err.ravel())[::-1]
    total = float(err.sum())
    print("%s: PSNR %.2f dB against %s" % (sys.argv[1], -10 * np.log10(err.mean()), sys.argv[2]))
    for n in [int(a) for a in sys.argv[3:]] or [100, 1000]:
        share = float(err.ravel()[order[:n]].sum()) / total if total > 0 else 0.0
        print("  the %d worst pixels hold %.1f %% of the squared error" % (n, 100 * share))
    w = err.shape[1]
    print("  the worst (x, y): " + ", ".join("(%d, %d)" % (i % w, i // w) for i in order[:8]))


if __name__ == "__main__":
    main()
