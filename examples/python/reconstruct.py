#!/usr/bin/python3
"""dcm from Python: a renderer written in Python, and a renderer's EXR AOVs.

    reconstruct.py                      an analytic scene through dcm.reconstruct
    reconstruct.py AOVS.exr [PRESET]    dcm.reconstruct_exr (PRESET: blender or generic)

Needs the installed module on PYTHONPATH (<prefix>/lib/python3/dist-packages) and
Debian's /usr/bin/python3 with python3-numpy; docs/PYTHON.md.
"""
import sys

import numpy as np

import dcm


def analytic_scene(width, height):
    """A shaded disc (object 2, textured) on a gradient background (object 1)."""
    y, x = np.mgrid[0:height, 0:width].astype(np.float32)
    disc = (x - 0.45 * width) ** 2 + (y - 0.5 * height) ** 2 < (0.3 * height) ** 2
    ids = np.where(disc, 2, 1).astype(np.uint32)
    checker = ((x // 6 + y // 6) % 2).astype(np.float32)
    tau = np.ones((height, width, 3), np.float32)
    tau[disc] = np.stack([0.3 + 0.5 * checker, 0.3 + 0.3 * checker, 0.6 - 0.2 * checker], axis=-1)[disc]
    li = np.stack([0.2 + 0.6 * x / width, 0.3 + 0.4 * y / height, 0.5 + 0.0 * x], axis=-1).astype(np.float32)
    li[disc] *= (0.6 + 0.4 * np.cos((x[disc] - 0.4 * width) / width * 3.0))[:, None]
    return ids, tau, li


def render_python(width=256, height=192):
    ids, tau, li = analytic_scene(width, height)
    lc = np.zeros_like(li)
    rendered = 0

    def evaluate(xy):
        # A real renderer traces these pixels; xy is (N, 2) int32 of (x, y).
        nonlocal rendered
        rendered += len(xy)
        px = (xy[:, 1], xy[:, 0])
        return {"Li": li[px], "Lc": lc[px]}

    r = dcm.reconstruct(width, height, guides={"id": ids, "tau": tau}, evaluate=evaluate, split=True)
    truth = li * tau + lc
    print(f"{width}x{height}: rendered {rendered} pixels ({100 * r.stats['exact_fraction']:.2f} %) "
          f"in {r.stats['provider_calls']} calls")
    print(f"mean abs error {np.abs(r.image - truth).mean():.6f}, max {np.abs(r.image - truth).max():.4f}")
    return r


def reconstruct_exr(path, preset):
    r = dcm.reconstruct_exr(path, preset=preset)
    line = f"{path}: {r.image.shape[1]}x{r.image.shape[0]}, {100 * r.stats['exact_fraction']:.2f} % exact"
    if "reference" in r.stats:  # dense input: the error against the full render
        line += f", PSNR {r.stats['reference']['psnr']:.2f} dB"
    print(line)
    return r


if __name__ == "__main__":
    if len(sys.argv) > 1:
        reconstruct_exr(sys.argv[1], sys.argv[2] if len(sys.argv) > 2 else "blender")
    else:
        render_python()
