# The full Cycles render of a .blend as its user would run it, for `dcm bench`:
# the file's own settings but the samples, the seed offset, adaptive sampling
# and denoising, written as a multilayer EXR. The file is not saved.
#
#   blender -b SCENE.blend --python-exit-code 1 --python render_main.py -- \
#       --out OUT.exr --samples N [--seed-offset K] [--adaptive-threshold T] [--threads N]
#
# Adaptive sampling and denoising are off unless --adaptive-threshold is given
# (then adaptive sampling is on at that noise threshold, with N samples at most):
# the render `dcm blender` compares itself with takes every sample.
import argparse
import os
import sys

import bpy


def parse(argv):
    ap = argparse.ArgumentParser(prog="render_main.py")
    ap.add_argument("--out", required=True, help="the multilayer EXR to write")
    ap.add_argument("--samples", type=int, required=True, help="Cycles samples per pixel")
    ap.add_argument("--seed-offset", type=int, default=0, help="added to the file's seed (another seed: its noise)")
    ap.add_argument("--adaptive-threshold", type=float, default=0.0,
                    help="Cycles' adaptive sampling at this noise threshold (0: off)")
    ap.add_argument("--threads", type=int, default=0, help="render threads (0: Blender's choice)")
    return ap.parse_args(argv)


def main():
    args = parse(sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else [])
    sc = bpy.context.scene
    if sc.render.engine != "CYCLES":
        raise SystemExit("render_main.py: the scene renders with %s, not Cycles" % sc.render.engine)
    if args.samples < 1:
        raise SystemExit("render_main.py: --samples %d is below 1" % args.samples)
    cy = sc.cycles
    cy.samples = args.samples
    cy.seed = (cy.seed + args.seed_offset) % 2 ** 31
    cy.use_adaptive_sampling = args.adaptive_threshold > 0
    if args.adaptive_threshold > 0:
        cy.adaptive_threshold = args.adaptive_threshold
    cy.use_denoising = False
    if args.threads > 0:
        sc.render.threads_mode, sc.render.threads = "FIXED", args.threads
    im = sc.render.image_settings
    im.file_format, im.color_depth = "OPEN_EXR_MULTILAYER", "32"
    sc.render.use_file_extension = False
    sc.render.filepath = os.path.abspath(args.out)
    if "FINISHED" not in bpy.ops.render.render(write_still=True):
        raise SystemExit("render_main.py: Cycles did not render")
    if not os.path.exists(args.out):
        raise SystemExit("render_main.py: Blender wrote no %s" % args.out)


main()
