"""The add-on's operator, panel and preferences. "Render with DCM" runs
`dcm blender` (the headless command) on a copy of the open file as it is in
memory, in its own session so that Esc stops it and its Blender; the result
is loaded as the image "DCM Result". The open file is never modified."""

import json
import os
import shutil
import tempfile

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty, PointerProperty, StringProperty

from . import runner

RESULT_IMAGE = "DCM Result"


def find_dcm(context):
    """The dcm executable: the add-on preference, else `dcm` on PATH."""
    prefs = context.preferences.addons[__package__].preferences if __package__ in context.preferences.addons else None
    path = bpy.path.abspath(prefs.dcm_path) if prefs and prefs.dcm_path else ""
    return path or shutil.which("dcm") or ""


class DCMPreferences(bpy.types.AddonPreferences):
    bl_idname = __package__

    dcm_path: StringProperty(
        name="dcm executable",
        description="Path of the dcm command (empty: dcm on PATH)",
        subtype="FILE_PATH",
        default="",
    )

    def draw(self, context):
        self.layout.prop(self, "dcm_path")
        found = find_dcm(context)
        self.layout.label(text="Using: " + (found or "dcm not found"), icon="CHECKMARK" if found else "ERROR")


class DCMSettings(bpy.types.PropertyGroup):
    method: EnumProperty(name="Method", default="dcm", items=[
        ("dcm", "DCM", "dcm's refinements (the default)"),
        ("paper", "Paper", "Scheel et al. 2001 as written"),
        ("guo", "Guo", "Guo 1998")])
    threshold: FloatProperty(name="Threshold", default=0.0, min=0.0, max=1.0, precision=3,
                             description="Contrast threshold instead of a target (0: dcm's default goal, 40 dB "
                                         "where the preview can judge it, else the method's threshold); lower: "
                                         "more exact pixels, closer to the full render")
    target_psnr: FloatProperty(name="Target PSNR", default=0.0, min=0.0, max=99.0, precision=1, unit="NONE",
                               description="Reach this PSNR (dB) against the converged image instead of a "
                                           "threshold (0: dcm's default, 40 dB where the preview can judge it; "
                                           "docs/QUALITY.md)")
    samples: IntProperty(name="Samples", description="Cycles samples of the exact pixels (0: the scene's)",
                         default=0, min=0, max=1 << 20)
    preview_samples: IntProperty(name="Preview Samples", default=0, min=0, max=1 << 20,
                                 description="Samples of the guides and preview render (0: dcm's default)")
    full: BoolProperty(name="Full Render", default=False,
                       description="Render every pixel exactly through dcm (the baseline)")
    schedule: EnumProperty(
        name="Rounds",
        description="How Cycles is asked for the exact pixels",
        items=[
            ("auto", "Auto", "Plan on a preview where a render call costs much (Cycles: always)"),
            ("preview", "Preview", "Choose the pixels on a cheap preview, then a few render calls"),
            ("levels", "Levels", "A render call per refinement step (many calls)"),
        ],
        default="auto",
    )
    max_rounds: IntProperty(name="Max rounds", description="Render calls for exact pixels at most",
                            default=3, min=1, max=50)
    preview_correction: BoolProperty(
        name="Preview correction",
        description="Move interpolated pixels toward the preview where they differ from it by more than its "
                    "noise explains",
        default=True)
    preview_filter: BoolProperty(
        name="Preview filter",
        description="Take interpolated pixels halfway to the preview averaged over their neighbours on the same "
                    "surface (after the correction)",
        default=True)
    fixed_samples: BoolProperty(
        name="Every sample",
        description="Render the exact pixels at every sample, also where the goal would leave them fewer",
        default=False)
    output: StringProperty(name="Output", description="Keep the EXR here (empty: a temporary file)",
                           subtype="FILE_PATH", default="")
    sample_map: BoolProperty(name="Sample map", description="Also load the sample map as 'DCM Sample Map'",
                             default=False)
    extra: StringProperty(name="Extra flags", description="More dcm blender flags, as on the command line",
                          default="")


def _render_source(context, workdir):
    """The .blend dcm renders: a copy of the open file as it is in memory
    (is_dirty misses changes made by scripts, so the saved file may be stale)."""
    copy = os.path.join(workdir, "scene.blend")
    # copy=True writes the file without making it the open one; relative
    # paths are remapped to the copy's folder.
    bpy.ops.wm.save_as_mainfile(filepath=copy, copy=True, check_existing=False, relative_remap=True)
    return copy


def _build(context, workdir):
    s = context.scene.dcm
    dcm = find_dcm(context)
    if not dcm:
        raise RuntimeError("dcm not found: set its path in the add-on's preferences or put it on PATH")
    if not (os.path.isfile(dcm) and os.access(dcm, os.X_OK)):
        raise RuntimeError("dcm not found at '%s' (the add-on's preferences)" % dcm)
    # Without an output named, the EXR goes to Blender's session folder, which
    # Blender removes at exit: the image reads from it until then.
    out = bpy.path.abspath(s.output) if s.output else os.path.join(
        bpy.app.tempdir or tempfile.gettempdir(), "dcm_result_%s.exr" % os.path.basename(workdir))
    if os.path.isdir(out):
        raise RuntimeError("Output '%s' is a folder; name a file" % out)
    cmd = runner.command_line(
        dcm, _render_source(context, workdir), out,
        blender=bpy.app.binary_path or None,
        stats=os.path.join(workdir, "stats.json"),
        sample_map=os.path.join(workdir, "sample_map.png") if s.sample_map else None,
        samples=s.samples, preview_samples=s.preview_samples, method=s.method, full=s.full,
        threshold=s.threshold if s.threshold > 0 and s.target_psnr <= 0 and not s.full else None,
        target_psnr=s.target_psnr if s.target_psnr > 0 and not s.full else None,
        schedule=s.schedule, max_rounds=s.max_rounds, preview_correction=s.preview_correction,
        preview_filter=s.preview_filter, fixed_samples=s.fixed_samples, view_layer=context.view_layer.name,
        frame=context.scene.frame_current, extra=s.extra)
    return cmd, out


def _show(path, name, pack):
    """Loads `path` as the image `name`, replacing an older one; `pack`: into
    the .blend's memory, for a file about to be removed."""
    old = bpy.data.images.get(name)
    if old:
        bpy.data.images.remove(old)
    img = bpy.data.images.load(path, check_existing=False)
    img.name = name
    if pack:
        img.pack()
    return img


def _finish(operator, context, run, out, workdir):
    code = run.wait()
    if code != 0:
        operator.report({"ERROR"}, "dcm blender failed (exit %d): %s" % (code, run.error_text() or "no message"))
        return {"CANCELLED"}
    img = _show(out, RESULT_IMAGE, False)
    if context.scene.dcm.sample_map and os.path.exists(os.path.join(workdir, "sample_map.png")):
        _show(os.path.join(workdir, "sample_map.png"), "DCM Sample Map", True)
    summary = "DCM: done"
    try:
        with open(os.path.join(workdir, "stats.json")) as f:
            st = json.load(f)
        wall = st.get("blender", {}).get("wall_s")
        summary = "DCM: %.1f %% of the pixels rendered%s" % (
            100.0 * st["exact_fraction"], " in %.1f s" % wall if wall is not None else "")
        if st.get("estimated_psnr") is not None:
            summary += ", estimated PSNR %.1f dB" % st["estimated_psnr"]
        if st.get("quality", {}).get("target_reached") is False:
            summary += " (target not reached)"
    except (OSError, ValueError, KeyError):
        pass
    operator.report({"INFO"}, summary)
    for window in context.window_manager.windows if context.window_manager else []:
        for area in window.screen.areas:
            if area.type == "IMAGE_EDITOR":
                area.spaces.active.image = img
                break
    return {"FINISHED"}


class RENDER_OT_dcm_render(bpy.types.Operator):
    """Render the current frame with DCM: Cycles renders only the pixels DCM needs"""

    bl_idname = "render.dcm_render"
    bl_label = "Render with DCM"
    bl_options = {"REGISTER"}

    _timer = None
    _run = None

    @classmethod
    def poll(cls, context):
        return context.scene is not None

    def _start(self, context):
        self._workdir = tempfile.mkdtemp(prefix="dcm-blender-")
        try:
            cmd, self._out = _build(context, self._workdir)
        except (RuntimeError, OSError) as e:
            shutil.rmtree(self._workdir, ignore_errors=True)
            self.report({"ERROR"}, str(e))
            return False
        self._run = runner.Run(cmd)
        return True

    def _cleanup(self):
        shutil.rmtree(self._workdir, ignore_errors=True)

    def execute(self, context):
        # Without an event loop (blender -b, scripts): run to the end.
        if not self._start(context):
            return {"CANCELLED"}
        try:
            return _finish(self, context, self._run, self._out, self._workdir)
        finally:
            self._cleanup()

    def invoke(self, context, event):
        if bpy.app.background:
            return self.execute(context)
        if not self._start(context):
            return {"CANCELLED"}
        wm = context.window_manager
        self._timer = wm.event_timer_add(0.25, window=context.window)
        wm.progress_begin(0, 100)
        wm.modal_handler_add(self)
        return {"RUNNING_MODAL"}

    def modal(self, context, event):
        wm = context.window_manager
        if event.type == "ESC":
            self._run.cancel()
            self._end(context)
            self.report({"WARNING"}, "DCM render cancelled")
            return {"CANCELLED"}
        if event.type != "TIMER":
            return {"PASS_THROUGH"}
        wm.progress_update(int(100 * self._run.fraction))
        context.workspace.status_text_set("DCM: %s %d%% (Esc cancels)" % (self._run.stage, 100 * self._run.fraction))
        if self._run.poll() is None:
            return {"PASS_THROUGH"}
        result = _finish(self, context, self._run, self._out, self._workdir)
        self._end(context)
        return result

    def _end(self, context):
        wm = context.window_manager
        if self._timer:
            wm.event_timer_remove(self._timer)
        wm.progress_end()
        context.workspace.status_text_set(None)
        self._cleanup()


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
        layout = self.layout
        layout.use_property_split = True
        layout.prop(s, "method")
        layout.prop(s, "target_psnr")
        row = layout.row()
        row.active = s.target_psnr <= 0  # a target chooses the threshold
        row.prop(s, "threshold")
        layout.prop(s, "samples")
        layout.prop(s, "preview_samples")
        layout.prop(s, "full")
        col = layout.column(heading="Rounds")
        col.prop(s, "schedule", text="Schedule")
        col.prop(s, "max_rounds")
        col.prop(s, "preview_correction")
        sub = col.row()
        sub.active = s.preview_correction  # the filter acts within the correction
        sub.prop(s, "preview_filter")
        col.prop(s, "fixed_samples")
        layout.prop(s, "output")
        layout.prop(s, "sample_map")
        layout.prop(s, "extra")
        layout.operator(RENDER_OT_dcm_render.bl_idname, icon="RENDER_STILL")


def menu_func(self, context):
    self.layout.separator()
    self.layout.operator(RENDER_OT_dcm_render.bl_idname, icon="RENDER_STILL")


_classes = (DCMPreferences, DCMSettings, RENDER_OT_dcm_render, RENDER_PT_dcm)


def register():
    for c in _classes:
        bpy.utils.register_class(c)
    bpy.types.Scene.dcm = PointerProperty(type=DCMSettings)
    bpy.types.TOPBAR_MT_render.append(menu_func)


def unregister():
    bpy.types.TOPBAR_MT_render.remove(menu_func)
    del bpy.types.Scene.dcm
    for c in reversed(_classes):
        bpy.utils.unregister_class(c)
