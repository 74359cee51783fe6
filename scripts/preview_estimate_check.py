#!/usr/bin/python3
"""How far `dcm blender`'s estimate from its preview (docs/QUALITY.md, "Without a
goal") falls from the truth on the Blender test scene, with and without the
texture split, over a sweep of thresholds.

    /usr/bin/python3 scripts/preview_estimate_check.py DCM OUT [--res 64x48] [--samples 256]
                     [--preview-samples 16] [--thresholds 0.42,0.105,0.0525,0.03] [--blender blender]

The truth is against the converged image: the result's squared display error
against a 1024-sample render (seed 7) less that render's own noise (half the
squared difference of it and a second 1024-sample render, seed 8). Prints a
Markdown table: threshold, split, exact fraction, estimate [90 % interval],
truth, estimate - truth.
"""
import argparse
import json
import math
import os
import subprocess
import sys


SRC = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(SRC, "tests/blender"))
import blender_support as bs  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("dcm")
    ap.add_argument("out")
    ap.add_argument("--res", default="64x48")
    ap.add_argument("--samples", type=int, default=256)
    ap.add_argument("--preview-samples", type=int, default=16)
    ap.add_argument("--thresholds", default="0.42,0.105,0.0525,0.03")
    ap.add_argument("--blender", default="blender")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    blend = bs.make_scene(a.blender, SRC, a.out, res=a.res)
    conv = bs.render_full(a.blender, SRC, blend, a.out, 1024, 7)
    conv2 = bs.render_full(a.blender, SRC, blend, a.out, 1024, 8)
    ref_noise = bs.display_mse(conv, conv2) / 2  # each 1024-sample render's own squared error, on average
    print("| threshold | texture split | exact | estimate [90 % interval] | true | estimate - true |")
    print("|---|---|---:|---|---:|---:|")
    for t in a.thresholds.split(","):
        for split in (True, False):
            name = os.path.join(a.out, "t%s%s" % (t, "" if split else "_nosplit"))
            cmd = [a.dcm, "blender", blend, "-o", name + ".exr", "--stats", name + ".json", "--blender", a.blender,
                   "--samples", str(a.samples), "--preview-samples", str(a.preview_samples),
                   "--schedule", "preview", "--threshold", t, "-q"] + ([] if split else ["--no-texture-split"])
            subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
            j = json.load(open(name + ".json"))
            true = -10 * math.log10(bs.display_mse(bs.read_exr(name + ".exr")[0], conv) - ref_noise)
            est = j.get("estimated_psnr")
            if est is None:
                row = "none (the preview's own %.2f dB)" % j["blender"].get("preview_psnr", float("nan"))
                diff = ""
            else:
                high = j.get("estimated_psnr_high")
                row = "%.2f [%.2f, %s]" % (est, j["estimated_psnr_low"], "%.2f" % high if high is not None else "inf")
                diff = "%+.2f" % (est - true)
            print("| %s | %s | %.1f %% | %s | %.2f | %s |" % (t, "on" if split else "off", 100 * j["exact_fraction"],
                                                            row, true, diff), flush=True)


if __name__ == "__main__":
    main()
