# Runs inside Blender (tests/blender/addon_test.py): installs and enables the
# add-on zip in a private user folder, checks what it registers, and runs the
# command its operator runs on the open file's saved copy.
#   blender -b SCENE.blend --python addon_check.py -- ZIP DCM OUT_DIR
import os
import subprocess
import sys

import bpy

zip_path, dcm, out_dir = sys.argv[sys.argv.index("--") + 1:]
bpy.ops.preferences.addon_install(filepath=zip_path)
bpy.ops.preferences.addon_enable(module="dcm_blender")
assert "dcm_blender" in bpy.context.preferences.addons, "the add-on did not enable"
assert hasattr(bpy.ops.render, "dcm_render") and bpy.ops.render.dcm_render.get_rna_type().name == "Render with DCM"
assert hasattr(bpy.types, "RENDER_PT_dcm"), "no DCM panel"
draw_funcs = getattr(bpy.types.TOPBAR_MT_render, "_dyn_ui_initialize")()
assert any(getattr(f, "__module__", "").startswith("dcm_blender") for f in draw_funcs), "not in the Render menu"
from dcm_blender import addon  # noqa: E402

settings = bpy.context.scene.dcm
settings.samples = 8
settings.max_rounds = 2
prefs = bpy.context.preferences.addons["dcm_blender"].preferences
prefs.dcm_path = dcm
blend = os.path.join(out_dir, "copy.blend")
bpy.ops.wm.save_as_mainfile(filepath=blend, copy=True)
assert bpy.data.filepath != blend, "the open file's path changed"
out, stats = os.path.join(out_dir, "addon.exr"), os.path.join(out_dir, "addon.json")
cmd = addon.command(prefs, settings, blend, out, stats)
print("addon command:", cmd)
rc = subprocess.run(cmd).returncode
assert rc == 0 and os.path.exists(out), rc
bpy.data.images.load(out)  # as the operator shows it (the outer test checks the file)
bpy.ops.preferences.addon_disable(module="dcm_blender")
assert not hasattr(bpy.types.Scene, "dcm")
print("addon ok")
sys.stdout.flush()
os._exit(0)
