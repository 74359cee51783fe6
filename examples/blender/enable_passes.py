# Prepares an existing .blend for `dcm reconstruct --preset blender` and
# renders the current frame into one multilayer EXR.
#
#   blender -b my_scene.blend --python enable_passes.py -- --out my_scene.exr \
#       [--samples 256] [--res 256] [--keep-filter] [--no-render] [--save fixed.blend]
#
# What it changes (in memory; your .blend is untouched unless --save):
#  - Cycles, every view layer: Combined, IndexOB, IndexMA, UV, Diffuse/Glossy/
#    Transmission Color+Direct+Indirect, Emit, Env, Cryptomatte object+material,
#    Denoising Data (the Denoising Albedo: textures seen in mirrors);
#  - object and material pass indices that are 0 get distinct numbers (dcm
#    prefers the Cryptomatte layers, but IndexOB/IndexMA then mean something too);
#  - adaptive sampling and denoising off (dcm compares against a plain estimate);
#  - pixel filter: Gaussian, 0.01 px, unless --keep-filter (not Box: Cycles
#    ignores the Box width and always spreads samples over the pixel). The index and UV
#    passes are not anti-aliased; a beauty filtered over 1.5 px mixes
#    neighbours that the guides do not see, so dcm needs more exact pixels;
#  - output: OpenEXR multilayer, 32-bit float, ZIP.
# Only one view layer should render (dcm picks it, or use --layer NAME).
import argparse
import os
import sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from cycles_common import enable_dcm_passes  # noqa: E402


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    ap = argparse.ArgumentParser(prog="enable_passes.py")
    ap.add_argument("--out", required=True, help="multilayer EXR to write")
    ap.add_argument("--samples", type=int, default=0, help="Cycles samples (0: keep the file's)")
    ap.add_argument("--res", type=int, default=0, help="resolution of the longer side (0: keep)")
    ap.add_argument("--keep-filter", action="store_true", help="keep the file's pixel filter")
    ap.add_argument("--no-render", action="store_true", help="only set up (with --save)")
    ap.add_argument("--save", default="", help="save the prepared scene as this .blend")
    args = ap.parse_args(argv)

    sc = bpy.context.scene
    sc.render.engine = "CYCLES"
    if args.samples > 0:
        sc.cycles.samples = args.samples
    sc.cycles.use_adaptive_sampling = False
    sc.cycles.use_denoising = False
    if not args.keep_filter:
        sc.cycles.pixel_filter_type = "GAUSSIAN"
        sc.cycles.filter_width = 0.01
    if args.res > 0:
        w, h = sc.render.resolution_x, sc.render.resolution_y
        k = args.res / max(w, h)
        sc.render.resolution_x, sc.render.resolution_y = round(w * k), round(h * k)
        sc.render.resolution_percentage = 100
    sc.render.use_compositing = False    # the EXR gets the render passes as they are

    # Pass indices: keep the ones set by hand, number the rest.
    used = {o.pass_index for o in bpy.data.objects if o.pass_index}
    n = max(used, default=0)
    for o in bpy.data.objects:
        if o.type in {"MESH", "CURVE", "SURFACE", "META", "FONT", "CURVES", "POINTCLOUD", "VOLUME"} \
                and o.pass_index == 0:
            n += 1
            o.pass_index = n
    used = {m.pass_index for m in bpy.data.materials if m.pass_index}
    n = max(used, default=0)
    for m in bpy.data.materials:
        if m.pass_index == 0:
            n += 1
            m.pass_index = n

    rendering = [vl for vl in sc.view_layers if vl.use]
    for vl in sc.view_layers:
        enable_dcm_passes(vl)
    if len(rendering) > 1:
        print("enable_passes.py: %d view layers render; pass --layer NAME to dcm (%s)"
              % (len(rendering), ", ".join(vl.name for vl in rendering)))

    im = sc.render.image_settings
    im.file_format = "OPEN_EXR_MULTILAYER"
    im.color_depth = "32"
    im.exr_codec = "ZIP"
    sc.render.use_file_extension = False
    sc.render.filepath = os.path.abspath(args.out)

    if args.save:
        bpy.ops.wm.save_as_mainfile(filepath=os.path.abspath(args.save), copy=True)
    if not args.no_render:
        bpy.ops.render.render(write_still=True)
        print("wrote", os.path.abspath(args.out))


main()
