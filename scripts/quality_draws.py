#!/usr/bin/python3
"""How a single validation draw estimates a result's PSNR (docs/QUALITY.md).

Simulates many independent draws on a result and its reference, as
ReconstructToQuality's last draw makes them: uniform, and by importance after
the error proxy (kProxyShare of the draw follows the squared display
difference between the result and the bilinear interpolation of its
elementary lattice, spread by a max filter of a quarter block each side; the
rest uniform), each with the Hansen-Hurwitz estimate and its 90 % interval.
Prints, per kind, the median error of the estimate (estimate - truth, dB),
the share of draws within 1.5 dB of the truth, the share whose interval
covers it, and the 10th and 90th percentiles of the error. The library also
leaves out of the proxy the pixels it evaluated itself (no error), which the
result alone does not show: the simulation draws them too.

usage: scripts/quality_draws.py RESULT.exr REFERENCE.exr [--block 16] [--draws 656]
                                [--trials 1000] [--share 0.8]
REFERENCE at the working resolution is box-filtered to the result's.
"""
import argparse

import numpy as np
import OpenImageIO as oiio
from scipy.ndimage import maximum_filter


def read(path):
    i = oiio.ImageInput.open(path)
    if not i:
        raise SystemExit(f"{path}: {oiio.geterror()}")
    a = np.array(i.read_image("float"))[..., :3]
    i.close()
    return a


def srgb(x):
    x = np.clip(x, 0, 1)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * x ** (1 / 2.4) - 0.055)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("result")
    ap.add_argument("reference")
    ap.add_argument("--block", type=int, default=16, help="elementary block, output pixels (16 at 1x, 8 at 4x)")
    ap.add_argument("--draws", type=int, default=656, help="pixels per draw (1 %% of the output, at least 512)")
    ap.add_argument("--trials", type=int, default=1000)
    ap.add_argument("--share", type=float, default=0.8)
    a = ap.parse_args()
    r, f = read(a.result), read(a.reference)
    if f.shape != r.shape:
        k = f.shape[0] // r.shape[0]
        f = f.reshape(r.shape[0], k, r.shape[1], k, 3).mean((1, 3))
    D = srgb(r)
    d = ((D - srgb(f)) ** 2).mean(-1).ravel()
    H, W = r.shape[:2]
    L = a.block
    ys, xs = np.mgrid[0:H, 0:W]
    x0, y0 = xs // L * L, ys // L * L
    u, v = ((xs - x0) / L)[..., None], ((ys - y0) / L)[..., None]
    P = lambda x, y: D[np.minimum(y, H - 1), np.minimum(x, W - 1)]
    lerp = P(x0, y0) * (1 - u) * (1 - v) + P(x0 + L, y0) * u * (1 - v) + P(x0, y0 + L) * (1 - u) * v + P(x0 + L, y0 + L) * u * v
    proxy = maximum_filter(((D - lerp) ** 2).sum(-1), size=2 * round(L / 4) + 1).ravel()
    N = H * W
    truth = d.mean()
    db = lambda m: 10 * np.log10(1 / np.maximum(m, 1e-12))
    print(f"true {db(truth):.2f} dB; {a.trials} draws of {a.draws} pixels")
    for name, share in (("uniform", 0.0), (f"importance {a.share:g}", a.share)):
        q = (1 - share) / N + share * proxy / proxy.sum()
        rng = np.random.default_rng(1)
        err, cover = [], 0
        for _ in range(a.trials):
            i = rng.choice(N, a.draws, p=q / q.sum())
            y = d[i] / (N * q[i])
            m, se = y.mean(), y.std(ddof=1) / np.sqrt(a.draws)
            err.append(db(m) - db(truth))
            cover += m - 1.645 * se <= truth <= m + 1.645 * se
        e = np.array(err)
        p10, p90 = np.percentile(e, [10, 90])
        print(f"{name:16s} median error {np.median(e):+.2f} dB, within 1.5 dB {np.mean(abs(e) <= 1.5):.2f}, "
              f"interval covers {cover / a.trials:.2f}, 10th-90th percentile {p10:+.2f} to {p90:+.2f} dB")


if __name__ == "__main__":
    main()
