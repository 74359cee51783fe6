#!/usr/bin/python3
"""Writes a synthetic multilayer EXR like a renderer's AOV output, for `dcm reconstruct`.

Channels (dcm's generic preset): id, shader (object and material IDs), u, v,
tau.R/G/B (texture value), Li.R/G/B (light before texturing), Lc.R/G/B (light
the texture does not modulate) and the beauty R, G, B = Li * tau + Lc.

The scene: a textured floor (checker) with a soft gradient and a shadow, a disc
with a glossy highlight, and a thin pole (one to two pixels wide).

Usage: /usr/bin/python3 make_aovs.py OUT.exr [SIZE]
Needs Debian's python3-numpy and python3-openimageio (hence /usr/bin/python3).
"""
import sys

import numpy as np
import OpenImageIO as oiio


def scene(size):
    h = w = size
    y, x = np.mgrid[0:h, 0:w].astype(np.float32)
    fx, fy = x / w, y / h
    disc = (fx - 0.45) ** 2 + (fy - 0.55) ** 2 < 0.09
    pole = (np.abs(fx - 0.8 - 0.05 * fy) < 0.006) & (fy < 0.9)
    obj = np.where(pole, 3, np.where(disc, 2, 1)).astype(np.float32)
    shader = np.where(pole, 7, np.where(disc, 5, 3)).astype(np.float32)
    u, v = fx, 1.0 - fy

    checker = ((np.floor(u * 16) + np.floor(v * 16)) % 2).astype(np.float32)
    tau = np.stack([0.25 + 0.55 * checker, 0.3 + 0.5 * checker, 0.35 + 0.4 * checker], axis=-1)
    tau[disc] = (0.7, 0.4, 0.3)
    tau[pole] = (0.2, 0.2, 0.2)

    li = np.stack([0.6 + 0.4 * fx, 0.7 + 0.2 * fy, 0.9 - 0.3 * fx], axis=-1)
    # A soft-edged shadow on the floor.
    shadow = np.clip((fx + fy - 0.7) / 0.03, 0.0, 1.0)
    floor = ~disc & ~pole
    li[floor] *= (0.25 + 0.75 * shadow[floor])[:, None]

    highlight = np.exp(-((fx - 0.4) ** 2 + (fy - 0.5) ** 2) / 0.002)
    lc = np.zeros_like(li)
    lc[disc] = (0.8 * highlight[disc])[:, None]
    beauty = li * tau + lc
    return w, h, {
        "id": obj, "shader": shader, "u": u, "v": v,
        "tau.R": tau[..., 0], "tau.G": tau[..., 1], "tau.B": tau[..., 2],
        "Li.R": li[..., 0], "Li.G": li[..., 1], "Li.B": li[..., 2],
        "Lc.R": lc[..., 0], "Lc.G": lc[..., 1], "Lc.B": lc[..., 2],
        "R": beauty[..., 0], "G": beauty[..., 1], "B": beauty[..., 2],
    }


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    out = sys.argv[1]
    size = int(sys.argv[2]) if len(sys.argv) > 2 else 256
    w, h, channels = scene(size)
    names = list(channels)
    spec = oiio.ImageSpec(w, h, len(names), "float")
    spec.channelnames = tuple(names)
    spec.attribute("compression", "zip")
    data = np.ascontiguousarray(np.stack([channels[n] for n in names], axis=-1).astype(np.float32))
    o = oiio.ImageOutput.create(out)
    if not o or not o.open(out, spec) or not o.write_image(data) or not o.close():
        sys.exit("cannot write %s: %s" % (out, oiio.geterror()))
    print("wrote %s: %dx%d, channels %s" % (out, w, h, ", ".join(names)))


if __name__ == "__main__":
    main()
