#!/usr/bin/python3
"""Side by side, the same crop of several renders, each labelled with its PSNR
against a reference (display-referred, over the whole image, as the stats').

  compare_crops.py REF.exr OUT.png X Y W H "LABEL=FILE.exr" ... [--scale 2]

The reference is shown last. Reads Blender's multilayer EXRs (…Combined.R/G/B)
and plain R, G, B files."""
import argparse

import numpy as np
import OpenImageIO as oiio
from PIL import Image, ImageDraw


def load(path):
    inp = oiio.ImageInput.open(path)
    if inp is None:
        raise SystemExit("compare_crops.py: cannot read '%s': %s" % (path, oiio.geterror()))
    names, px = list(inp.spec().channelnames), inp.read_image("float")
    inp.close()
    pick = [next((i for i, n in enumerate(names) if n.endswith("Combined." + c) or n == c), None) for c in "RGB"]
    if None in pick:
        raise SystemExit("compare_crops.py: '%s' has no R, G, B or Combined.R/G/B channels" % path)
    return px[:, :, pick].astype(np.float64)


def encode(x):  # sRGB of values clipped to [0, 1]
    x = np.clip(x, 0, 1)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("ref")
    ap.add_argument("out")
    ap.add_argument("box", nargs=4, type=int, metavar="X Y W H")
    ap.add_argument("images", nargs="+", metavar="LABEL=FILE")
    ap.add_argument("--scale", type=int, default=2, help="pixel replication of the crops")
    a = ap.parse_args()
    x, y, w, h = a.box
    ref = load(a.ref)
    panels = []
    for item in a.images + ["converged=" + a.ref]:
        label, _, path = item.partition("=")
        img = load(path)
        if img.shape != ref.shape:
            raise SystemExit("compare_crops.py: '%s' is %s, the reference %s" % (path, img.shape, ref.shape))
        crop = encode(img[y:y + h, x:x + w])
        crop = np.repeat(np.repeat(crop, a.scale, 0), a.scale, 1)
        tile = Image.new("RGB", (crop.shape[1], crop.shape[0] + 34), "white")
        tile.paste(Image.fromarray((crop * 255 + 0.5).astype(np.uint8)), (0, 34))
        draw = ImageDraw.Draw(tile)
        draw.text((4, 2), label, fill="black")
        if path != a.ref:
            mse = np.mean((encode(img) - encode(ref)) ** 2)
            draw.text((4, 17), "%.2f dB (whole image)" % (10 * np.log10(1 / mse)), fill="black")
        panels.append(tile)
    out = Image.new("RGB", (sum(p.width for p in panels) + 6 * (len(panels) - 1), panels[0].height), "white")
    left = 0
    for p in panels:
        out.paste(p, (left, 0))
        left += p.width + 6
    out.save(a.out)


if __name__ == "__main__":
    main()
