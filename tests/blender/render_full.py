# Renders a .blend as it is (the reference of the Blender tests) into a
# multilayer EXR; only the output format is set, in memory.
#   blender -b SCENE.blend --python render_full.py -- OUT.exr
import os
import sys

import bpy

out = sys.argv[sys.argv.index("--") + 1]
sc = bpy.context.scene
im = sc.render.image_settings
im.file_format = "OPEN_EXR_MULTILAYER"
im.color_depth = "32"
sc.render.use_file_extension = False
sc.render.filepath = os.path.abspath(out)
bpy.ops.render.render(write_still=True)
