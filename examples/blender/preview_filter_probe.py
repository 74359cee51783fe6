#!/usr/bin/python3
"""How much a guided filter of dcm blender's preview would add (a probe, not
part of dcm): the interpolated pixels of dcm's result replaced by, or averaged
with, the preview filtered over a (2r+1)^2 window, each neighbour weighted by
the same object and material (Cryptomatte rank 0), its normal and albedo, and
its value in dcm's result (the pilot: it carries the edges that the exact
pixels found), each of the preview's light components (diffuse, glossy,
transmission: Blender's light passes, without their colour) filtered apart and
multiplied back by its colour pass.

    DCM_BLENDER_CHILD=examples/blender/keep_renders_child.py KEEP_DIR=KEEP \\
      dcm blender SCENE.blend -o OUT.exr --samples 512 --sample-map MAP.png
    examples/blender/preview_filter_probe.py KEEP OUT.exr MAP.png REF.exr [--radius 3] [--pilot-sd 0.05]

Prints the display-referred PSNR against REF (a converged render) of dcm's
result, of the preview alone, of dcm with the filtered preview in its
interpolated pixels, and of dcm with the mean of the two there."""
import argparse
import os
import sys

import numpy as np
import OpenImageIO as oiio

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from compare_crops import encode, load  # noqa: E402


def psnr(x, ref):
    return -10 * np.log10(np.mean((encode(x) - encode(ref)) ** 2))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("keep")
    ap.add_argument("result")
    ap.add_argument("sample_map")
    ap.add_argument("reference")
    ap.add_argument("--radius", type=int, default=3)
    ap.add_argument("--pilot-sd", type=float, default=0.05, help="of the sRGB-encoded pilot, summed over R, G, B")
    ap.add_argument("--normal-sd", type=float, default=0.2)
    ap.add_argument("--albedo-sd", type=float, default=0.05)
    a = ap.parse_args()
    halves = [np.load(os.path.join(a.keep, f)) for f in sorted(os.listdir(a.keep)) if f.endswith("_guides.npz")]
    if len(halves) != 2:
        sys.exit("preview_filter_probe: %s holds %d guides renders, not the preview's two halves" % (a.keep, len(halves)))

    def mean(name, comps="RGB"):
        return sum(np.stack([h[name + "." + c] for c in comps], -1).astype(np.float64) for h in halves) / 2

    dcm, ref = load(a.result), load(a.reference)
    h, w = dcm.shape[:2]
    m = oiio.ImageInput.open(a.sample_map)
    legend = m.read_image("uint8")[:h, :w, :3]
    m.close()
    interpolated = np.all(legend == 40, -1)  # tools/common/sample_map.cpp: kInterpolated is dark grey
    oid = halves[0]["CryptoObject00.r"].view(np.uint32)
    mid = halves[0]["CryptoMaterial00.r"].view(np.uint32)
    normal = mean("Normal", "XYZ")
    albedo = mean("DiffCol") + mean("GlossCol") + mean("TransCol")
    pilot = encode(dcm)

    def shifted(x, dy, dx):
        return np.roll(np.roll(x, dy, 0), dx, 1)

    weights = []
    for dy in range(-a.radius, a.radius + 1):
        for dx in range(-a.radius, a.radius + 1):
            inside = np.zeros((h, w), bool)  # no neighbour across the frame's edge
            inside[max(dy, 0):h + min(dy, 0), max(dx, 0):w + min(dx, 0)] = True
            wt = (inside & (shifted(oid, dy, dx) == oid) & (shifted(mid, dy, dx) == mid)).astype(np.float64)
            wt *= np.exp(-((shifted(normal, dy, dx) - normal) ** 2).sum(-1) / (2 * a.normal_sd ** 2))
            wt *= np.exp(-((shifted(albedo, dy, dx) - albedo) ** 2).sum(-1) / (2 * a.albedo_sd ** 2))
            wt *= np.exp(-((shifted(pilot, dy, dx) - pilot) ** 2).sum(-1) / (2 * a.pilot_sd ** 2))
            weights.append((dy, dx, wt))
    total = sum(wt for _, _, wt in weights)

    def filtered(x):
        return sum(wt[..., None] * shifted(x, dy, dx) for dy, dx, wt in weights) / total[..., None]

    preview = mean("Combined")
    parts = [(mean(k + "Col"), mean(k + "Dir") + mean(k + "Ind")) for k in ("Diff", "Gloss", "Trans")]
    rest = preview - sum(c * l for c, l in parts)  # emission, the world, volumes
    denoised = sum(c * filtered(l) for c, l in parts) + filtered(rest)
    keep = ~interpolated[..., None]
    print("dcm %.2f dB; the preview %.2f; the filtered preview in the interpolated pixels %.2f; "
          "their mean with dcm's there %.2f (%d %% interpolated)"
          % (psnr(dcm, ref), psnr(preview, ref), psnr(np.where(keep, dcm, denoised), ref),
             psnr(np.where(keep, dcm, 0.5 * (dcm + denoised)), ref), round(100 * interpolated.mean())))


if __name__ == "__main__":
    main()
