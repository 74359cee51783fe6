"""dcm for Blender: renders with Cycles only the pixels DCM asks for.

Two uses of this package:
 - the add-on (Preferences > Add-ons > Install, the zip the build makes:
   build/plugins/blender/dcm_render.zip): Render > Render with DCM, and a
   "DCM" panel in the Render properties. It saves a copy of the open file and
   runs `dcm blender` on it, the same command as headless; the open file is
   not touched;
 - the dcm-pipe child that `dcm blender` starts inside a background Blender
   (child.py, scene.py; started by ../child_main.py).
"""
bl_info = {
    "name": "DCM Render",
    "author": "dcm",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "Render > Render with DCM; Properties > Render > DCM",
    "description": "Render with Cycles only the pixels Directional Coherence Maps ask for; reconstruct the rest",
    "category": "Render",
}


def register():
    from . import addon
    addon.register()


def unregister():
    from . import addon
    addon.unregister()
