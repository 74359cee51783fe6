"""The add-on's operator, panel and preferences. The render itself is
`dcm blender` on a saved copy of the open file, run in the background while
Blender stays responsive; its result is loaded as the image "DCM Result"."""
import os
import shlex
import shutil
import subprocess
import tempfile

import bpy


def command(prefs, settings, blend, out, stats):
    """The `dcm blender` command line for the settings (the headless command)."""
    cmd = [prefs.dcm_path or "dcm", "blender", blend, "-o", out, "--stats", stats, "-q",
           "--blender", bpy.app.binary_path,
           "--method", settings.method, "--max-rounds", str(settings.max_rounds)]
    if settings.samples:
        cmd += ["--samples", str(settings.samples)]
    if settings.preview_samples:
        cmd += ["--preview-samples", str(settings.preview_samples)]
    if settings.threshold > 0:
        cmd += ["--threshold", "%g" % settings.threshold]
    if settings.full:
        cmd += ["--full"]
    return cmd


class DCMPreferences(bpy.types.AddonPreferences):
    bl_idname = __package__

    dcm_path: bpy.props.StringProperty(
        name="dcm executable", subtype="FILE_PATH", default="",
        description="The dcm command (empty: 'dcm' on PATH)")

    def draw(self, context):
        self.layout.prop(self, "dcm_path")


class DCMSettings(bpy.types.PropertyGroup):
    samples: bpy.props.IntProperty(name="Samples", default=0, min=0,
                                   description="Cycles samples of the exact pixels (0: the scene's)")
    preview_samples: bpy.props.IntProperty(name="Preview Samples", default=0, min=0,
                                           description="Samples of the guides and preview render (0: default)")
    method: bpy.props.EnumProperty(name="Method", default="dcm", items=[
        ("dcm", "DCM", "dcm's refinements (the default)"),
        ("paper", "Paper", "the paper's algorithm"),
        ("guo", "Guo", "Guo 1998")])
    threshold: bpy.props.FloatProperty(name="Threshold", default=0.0, min=0.0, max=1.0,
                                       description="Contrast threshold (0: the method's default); lower: more "
                                                   "exact pixels, closer to the full render")
    max_rounds: bpy.props.IntProperty(name="Max Render Calls", default=3, min=1, max=100,
                                      description="Render calls for exact pixels at most")
    full: bpy.props.BoolProperty(name="Full Render", default=False,
                                 description="Render every pixel exactly (the baseline)")


class DCM_OT_render(bpy.types.Operator):
    """Render the scene with Cycles at the pixels DCM asks for (dcm blender)"""
    bl_idname = "render.dcm_render"
    bl_label = "Render with DCM"

    _timer = None
    _proc = None

    def execute(self, context):
        prefs = context.preferences.addons[__package__].preferences
        exe = prefs.dcm_path or shutil.which("dcm")
        if not exe or not os.path.exists(exe):
            self.report({"ERROR"}, "dcm not found: set its path in the add-on's preferences")
            return {"CANCELLED"}
        self._dir = tempfile.mkdtemp(prefix="dcm-render-")
        blend = os.path.join(self._dir, "scene.blend")
        # A copy: the open file, its path and its unsaved state stay as they are.
        bpy.ops.wm.save_as_mainfile(filepath=blend, copy=True)
        self._out = os.path.join(self._dir, "dcm.exr")
        cmd = command(prefs, context.scene.dcm, blend, self._out, os.path.join(self._dir, "dcm.json"))
        cmd[0] = exe
        print("DCM:", " ".join(shlex.quote(c) for c in cmd))
        self._log = open(os.path.join(self._dir, "dcm.log"), "w+")
        self._proc = subprocess.Popen(cmd, stdout=self._log, stderr=subprocess.STDOUT)
        self._timer = context.window_manager.event_timer_add(0.5, window=context.window)
        context.window_manager.modal_handler_add(self)
        self.report({"INFO"}, "DCM render started")
        return {"RUNNING_MODAL"}

    def modal(self, context, event):
        if event.type == "ESC":
            self._proc.terminate()  # dcm ends its Blender child and writes nothing
            self._proc.wait()
            self._finish(context)
            self.report({"WARNING"}, "DCM render cancelled")
            return {"CANCELLED"}
        if event.type != "TIMER" or self._proc.poll() is None:
            return {"PASS_THROUGH"}
        self._finish(context)
        if self._proc.returncode != 0:
            self._log.seek(0)
            lines = [l for l in self._log.read().splitlines() if "error" in l] or ["dcm failed"]
            self.report({"ERROR"}, lines[-1][:500])
            return {"CANCELLED"}
        img = bpy.data.images.get("DCM Result")
        if img is not None:
            bpy.data.images.remove(img)
        img = bpy.data.images.load(self._out)
        img.name = "DCM Result"
        img.pack()
        shutil.rmtree(self._dir, ignore_errors=True)
        for area in context.screen.areas:
            if area.type == "IMAGE_EDITOR":
                area.spaces.active.image = img
                break
        self.report({"INFO"}, "DCM render done: image 'DCM Result'")
        return {"FINISHED"}

    def _finish(self, context):
        context.window_manager.event_timer_remove(self._timer)
        self._log.close()
        keep = self._proc.returncode == 0
        if not keep:
            shutil.rmtree(self._dir, ignore_errors=True)


class RENDER_PT_dcm(bpy.types.Panel):
    bl_label = "DCM"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "render"

    @classmethod
    def poll(cls, context):
        return context.scene.render.engine == "CYCLES"

    def draw(self, context):
        s = context.scene.dcm
        col = self.layout.column()
        for name in ("samples", "preview_samples", "method", "threshold", "max_rounds", "full"):
            col.prop(s, name)
        col.operator(DCM_OT_render.bl_idname, icon="RENDER_STILL")


def menu(self, context):
    self.layout.operator(DCM_OT_render.bl_idname, icon="RENDER_STILL")


classes = (DCMPreferences, DCMSettings, DCM_OT_render, RENDER_PT_dcm)


def register():
    for c in classes:
        bpy.utils.register_class(c)
    bpy.types.Scene.dcm = bpy.props.PointerProperty(type=DCMSettings)
    bpy.types.TOPBAR_MT_render.append(menu)


def unregister():
    bpy.types.TOPBAR_MT_render.remove(menu)
    del bpy.types.Scene.dcm
    for c in reversed(classes):
        bpy.utils.unregister_class(c)
