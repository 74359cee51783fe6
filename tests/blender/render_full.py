# Renders a .blend as it is (the reference of the Blender tests) into a
# multilayer EXR; only the output format is set, in memory, and the samples
# and seed when given.
#   blender -b SCENE.blend --python render_full.py -- OUT.exr [SAMPLES SEED]
import os
import sys

import bpy

args = sys.argv[sys.argv.index("--") + 1:]
out = args[0]
sc = bpy.context.scene
if len(args) == 3:
    sc.cycles.samples, sc.cycles.seed = int(args[1]), int(args[2])
im = sc.render.image_settings
im.file_format = "OPEN_EXR_MULTILAYER"
im.color_depth = "32"
sc.render.use_file_extension = False
sc.render.filepath = os.path.abspath(out)
bpy.ops.render.render(write_still=True)
