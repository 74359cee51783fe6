"""The loaded scene as dcm's sample provider: renders the guides and preview
once, and any set of pixels at full quality in one Cycles render call.

How Cycles renders only some pixels: before every Material Output the surface
is mixed with a zero-strength Emission, Fac = 1 - IsCameraRay * (1 - mask),
where mask is an Image Texture in Window coordinates (Closest, Extend) that is
1 on the pixels asked for. Only camera rays see the mask, so indirect light is
the full render's. Masked pixels' samples are all 0, and a round's adaptive
sampling stops them after a few. A pixel asked for whose samples all agree so
far (all 0: a dark pixel that rare paths light) would stop too: where the
preview says that may happen, the round switches on an emission of white
noise in the sample's window position times 1e-20 (KEEP_ALIVE) on the pixels
asked for, so that their samples never all agree: it adds at most 1e-20 to
a pixel, which a float sum with any value above 1e-13 loses. The mask has
`mask_scale` texels per pixel and side and covers, around each pixel asked
for, the footprint of the pixel filter (where the pixel's camera rays
leave). With persistent data a mask changed in memory,
or saved and reloaded under the same name, does not reach the next render; a
new file per render does.

With `--variance-halves` every exact pixel is rendered as two halves of its
samples with different seeds (the file's and the next), which cost what one
render costs but for a render call: the pixel is their mean, and (A - B)^2/4
per pixel, the variance of that mean from this pixel alone, goes to dcm,
which pools it over the exact pixels on the same surface (docs/NOISE.md).

Every change to the scene (settings, nodes, materials) is recorded and undone
by restore(), also after an error; the .blend on disk is never written."""
import os

import bpy
import numpy as np

from . import exr

# Below this in every channel DiffCol says no diffuse colour (a mirror, glass,
# metal; also the sky and black surfaces), and the texture guide there is the
# Denoising Albedo, at least this: dcm's kAlbedoFloor (the AOV provider's
# albedo role, docs/AOV.md).
ALBEDO_FLOOR = 0.02


class SceneError(Exception):
    """A scene dcm cannot render, with the reason for the user."""


class Changes:
    """Attribute changes and created data, undone in reverse order."""

    def __init__(self):
        self._undo = []

    def set(self, obj, attr, value):
        old = getattr(obj, attr)
        if old != value:
            self._undo.append(lambda: setattr(obj, attr, old))
            setattr(obj, attr, value)

    def on_restore(self, fn):
        self._undo.append(fn)

    def restore_later(self, obj, attrs):
        """Restores `attrs` of `obj` to their present values, in this order."""
        saved = [(a, getattr(obj, a)) for a in attrs]
        self._undo.append(lambda: [setattr(obj, a, v) for a, v in saved])

    def restore(self):
        errors = []
        while self._undo:
            fn = self._undo.pop()
            try:
                fn()
            except Exception as e:  # keep undoing the rest
                errors.append(str(e))
        return errors


def _write_png(path, grey):
    """An 8-bit greyscale PNG of `grey` [rows top-down, columns]."""
    import struct
    import zlib

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))
    h, w = grey.shape
    rows = np.zeros((h, w + 1), np.uint8)  # filter byte 0 per row
    rows[:, 1:] = grey
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 0, 0, 0, 0))
                + chunk(b"IDAT", zlib.compress(rows.tobytes(), 1)) + chunk(b"IEND", b""))


def _srgb(x):
    """The sRGB encoding of linear x, clipped to [0, 1] (dcm::SrgbEncode)."""
    x = np.clip(x, 0.0, 1.0)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)


def _noise_psnr(var, L):
    """The display-referred PSNR that noise of variance `var` [h, w, 3] (from one
    pixel's halves) costs on the image L: the mean over pixels and channels of
    ((enc(L + s) - enc(L - s)) / 2)^2, s = sqrt(var), as dcm's estimate counts an
    exact pixel's noise (DisplayNoise in lib/src/preview_correction.cpp). A mean,
    not a typical pixel: a path tracer's noise sits in few pixels (the
    highlights, the indirect corners), and the PSNR is their mean; the display's
    clip bounds what one firefly adds."""
    s = np.sqrt(np.maximum(var.astype(np.float64), 0.0))
    L = L.astype(np.float64)
    mse = float(np.mean(((_srgb(L + s) - _srgb(L - s)) / 2) ** 2))
    return 99.0 if not mse > 0 else min(99.0, -10 * np.log10(mse))


def _clock_seconds(text):
    """Seconds of a time as Blender's metadata writes it ("[HH:]MM:SS.ss"); NaN if not one."""
    try:
        return sum(float(part) * 60 ** i for i, part in enumerate(reversed(text.split(":"))))
    except ValueError:
        return float("nan")


def _value(socket):
    """A socket's constant as a tuple of floats, or None where it is linked."""
    if socket.is_linked:
        return None
    v = socket.default_value
    return tuple(v) if hasattr(v, "__len__") else (v,)


def _may_emit(tree, seen=None):
    """Whether Cycles may take a surface of this node tree (node groups
    included) for a light: an Emission or Background node, a Principled BSDF
    with an emission colour and strength that are not constant 0 (Cycles adds
    its emission node only then), or a node Cycles cannot see into (a script)."""
    seen = set() if seen is None else seen
    if tree is None or tree.name in seen:
        return False
    seen.add(tree.name)
    for n in tree.nodes:
        kind = n.bl_idname
        if kind in {"ShaderNodeEmission", "ShaderNodeBackground", "ShaderNodeScript"}:
            return True
        if kind == "ShaderNodeBsdfPrincipled":
            colour = _value(n.inputs.get("Emission Color") or n.inputs["Emission"])  # the name since Blender 4.0
            strength = _value(n.inputs["Emission Strength"])
            if (colour is None or any(colour[:3])) and (strength is None or any(strength)):
                return True
        if kind == "ShaderNodeGroup" and _may_emit(n.node_tree, seen):
            return True
    return False


def _log(msg):
    print("dcm-blender: " + msg, file=os.sys.stderr, flush=True)


class Session:
    def __init__(self, args, workdir):
        self.args = args
        self.workdir = workdir
        self.changes = Changes()
        self.scene = bpy.context.scene
        self.notes = []
        self._guides = None   # planes of the guides/preview render
        self._through_mirror = None  # [height, width]: texture from the Denoising Albedo
        self._mask_image = None
        self._round = 0
        self.noise_psnr = None  # of the exact pixels' samples, from the preview's halves
        self.render_seconds = []
        self.rendered_again = 0  # exact pixels that stopped early (_stopped_early)
        self.extra_pixels = 0  # pixels rendered exactly without being asked for (evaluate)
        self._known = None  # [height, width]: pixels asked for or given as extra so far
        self.kept_alive = []  # materials that carry the keep-alive emission (_insert_masks)
        self.kept_alive_renders = 0  # renders of exact pixels with the keep-alive on (evaluate)
        self._keep_alive_scales = []  # the sockets that switch it (_keep_alive)
        self._keep_alive_on = False
        self._crop = None  # the render border's rectangle, cropped to (_set_border)
        self.masked_materials = 0  # materials whose surface the mask decides

    # ------------------------------------------------------------- setup --
    def setup(self):
        sc, c, a = self.scene, self.changes, self.args
        if a.frame is not None:
            old = sc.frame_current
            self.changes.on_restore(lambda: sc.frame_set(old))
            sc.frame_set(a.frame)
        if sc.render.engine != "CYCLES":
            raise SceneError("the scene renders with %s; dcm blender renders with Cycles only "
                             "(Render Properties > Render Engine)" % sc.render.engine)
        if sc.camera is None:
            raise SceneError("the scene has no camera")
        cam = sc.camera.data
        if getattr(cam, "type", "PERSP") == "PANO":
            raise SceneError("panoramic cameras are not supported (the pixel mask follows a flat image)")
        if cam.dof.use_dof:
            raise SceneError("depth of field is on (Camera > Depth of Field): a pixel's rays then "
                             "leave from the whole lens and the pixel mask cannot follow them")
        if sc.render.use_motion_blur:
            raise SceneError("motion blur is on (Render Properties > Motion Blur): a pixel's rays "
                             "then see moving surfaces the pixel mask cannot follow")
        r = sc.render
        self.width = r.resolution_x * r.resolution_percentage // 100
        self.height = r.resolution_y * r.resolution_percentage // 100
        if self.width < 1 or self.height < 1:
            raise SceneError("empty resolution %dx%d" % (self.width, self.height))
        if r.use_border:
            self.notes.append("the render region (border) is ignored: dcm renders the whole frame")
        # Rounds render within borders of their own (rectangles()): the user's come back.
        c.restore_later(r, ("use_border", "use_crop_to_border", "border_min_x", "border_max_x", "border_min_y",
                            "border_max_y"))
        r.use_border, r.use_crop_to_border = False, False

        # The view layer: the named one, else the first that renders; the others are off.
        layers = [vl for vl in sc.view_layers if vl.use]
        if a.view_layer:
            layers = [vl for vl in sc.view_layers if vl.name == a.view_layer]
            if not layers:
                raise SceneError("no view layer '%s' (the scene has: %s)"
                                 % (a.view_layer, ", ".join(vl.name for vl in sc.view_layers)))
        if not layers:
            raise SceneError("no view layer renders (View Layer > Use for Rendering)")
        self.layer = layers[0]
        if len([vl for vl in sc.view_layers if vl.use]) > 1 and not a.view_layer:
            self.notes.append("several view layers render; dcm renders '%s' (--view-layer NAME)"
                              % self.layer.name)
        for vl in sc.view_layers:
            c.set(vl, "use", vl == self.layer)
        vl = self.layer
        for attr in ("use_pass_combined", "use_pass_diffuse_color", "use_pass_diffuse_direct",
                     "use_pass_diffuse_indirect"):
            c.set(vl, attr, True)
        c.set(vl, "pass_cryptomatte_depth", 2)
        self._guides_only_passes(True)
        # What a mirror reflects, GlossCol * GlossInd (_reflected).
        for attr in ("use_pass_glossy_color", "use_pass_glossy_indirect"):
            c.set(vl, attr, True)
        # How many samples each pixel took: an exact pixel that stopped early is rendered again.
        c.set(vl.cycles, "pass_debug_sample_count", True)

        cy = sc.cycles
        self.samples = a.samples if a.samples > 0 else cy.samples
        self.file_samples = self.samples  # the run's: exact_samples may lower self.samples
        # At least 16: below it the preview's noise costs what the correction draws from
        # it (and its error estimate squares differences through the sRGB curve, whose
        # bias grows as the halves' variance squared; docs/BLENDER.md).
        self.preview_samples = min(self.samples, a.preview_samples or max(16, self.samples // 16))
        if cy.use_adaptive_sampling:
            self.notes.append("adaptive sampling off: every pixel gets %d samples" % self.samples)
            c.set(cy, "use_adaptive_sampling", False)
        if cy.use_denoising:
            self.notes.append("denoising off (it would see a frame of black, unrendered pixels)")
            c.set(cy, "use_denoising", False)
        c.set(cy, "samples", self.samples)
        # Rounds of exact pixels switch adaptive sampling on (_masked_pixels_stop); a round
        # that fails leaves it so, and the restore undoes it.
        c.restore_later(cy, ("use_adaptive_sampling", "adaptive_threshold", "adaptive_min_samples"))
        # Two halves of the samples with two seeds: the second seed is the next one.
        self.halves = a.variance_halves and self.samples >= 2
        self.seeds = (cy.seed, (cy.seed + 1) % 2 ** 31) if self.halves else (cy.seed,)
        # The preview's halves take the two seeds after those: with the exact
        # pixels' own seeds its samples would be the first of theirs (Cycles'
        # sequences are progressive), and a result drawn toward the preview
        # would share their noise, which the validation's estimate then misses.
        self.preview_seeds = tuple((cy.seed + 2 + k) % 2 ** 31 for k in range(2 if self.halves else 1))
        c.restore_later(cy, ("seed",))
        if a.threads > 0:
            c.set(r, "threads_mode", "FIXED")
            c.set(r, "threads", a.threads)
        c.set(r, "use_persistent_data", True)  # the BVH and shaders are built once
        c.set(r, "use_compositing", False)     # the passes as Cycles renders them
        c.set(r, "use_sequencer", False)
        c.set(r, "use_file_extension", False)
        c.set(r, "filepath", os.path.join(self.workdir, "render.exr"))
        # The depth a format allows depends on the format: restore all three at once, format first.
        im = r.image_settings
        c.restore_later(im, ("file_format", "color_depth", "exr_codec"))
        im.file_format, im.color_depth, im.exr_codec = "OPEN_EXR_MULTILAYER", "32", "NONE"
        # How far from its centre a pixel's camera rays leave: Cycles samples a filter over
        # [-W/2, W/2], W = 3 widths for a Gaussian, 2 for Blackman-Harris; a Box keeps to the
        # pixel whatever its width (docs/BLENDER.md, "The pixel filter").
        self.filter_radius = max(0.5, {"BOX": 0.0, "GAUSSIAN": 1.5}.get(cy.pixel_filter_type, 1.0) * cy.filter_width)
        if self.filter_radius > 0.5:
            lo, hi = self._footprint()
            self.notes.append("pixel filter %s %.2f px: a pixel's rays leave up to %.2f px from its centre, so the "
                              "mask around each exact pixel spans %.2f x %.2f px, and every camera ray in it is "
                              "traced in full (a Gaussian of 0.01 px: the pixel's own rays alone; docs/BLENDER.md, "
                              "\"The pixel filter's cost\")"
                              % (cy.pixel_filter_type.replace("_", "-").title(), cy.filter_width,
                                 self.filter_radius, (hi - lo) / self.args.mask_scale, (hi - lo) / self.args.mask_scale))
        self._insert_masks()

    # -------------------------------------------------------- the masks --
    def _insert_masks(self):
        k = self.args.mask_scale
        self._write_mask(np.ones((self.height * k, self.width * k), np.float32))
        img = bpy.data.images.load(self.mask_path)
        self.changes.on_restore(lambda: bpy.data.images.remove(img))
        img.colorspace_settings.name = "Non-Color"
        self._mask_image = img

        # Objects that render without a material of nodes get a stand-in that
        # renders the same: Cycles' default surface, or the material's colour.
        default = None
        for m in list(bpy.data.materials):
            if m.use_nodes or m.users == 0:
                continue
            self._nodes_for_plain(m)
        for ob in self.scene.objects:
            if ob.type not in {"MESH", "CURVE", "SURFACE", "META", "FONT"} or ob.hide_render:
                continue
            if any(s.material for s in ob.material_slots):
                continue
            if default is None:
                default = bpy.data.materials.new("dcm_default_surface")
                self.changes.on_restore(lambda m=default: bpy.data.materials.remove(m))
                self._nodes_for_plain(default, colour=(0.8, 0.8, 0.8, 1.0), created=True)
            self._give_material(ob, default)
        for m in bpy.data.materials:
            if m.use_nodes and m.node_tree and m.users:
                # The keep-alive emission would make a surface that emits nothing a
                # light Cycles samples (other paths, other values): only on those
                # that cannot emit, with their light sampling off.
                keep_alive = not _may_emit(m.node_tree)
                if keep_alive:
                    self.kept_alive.append(m.name)
                    if hasattr(m.cycles, "emission_sampling"):  # Blender 3.5 and later
                        self.changes.set(m.cycles, "emission_sampling", "NONE")
                    else:
                        self.changes.set(m.cycles, "sample_as_light", False)
                self._mask_tree(m.node_tree, keep_alive)
                self.masked_materials += 1

    def _nodes_for_plain(self, m, colour=None, created=False):
        """Cycles renders a material without nodes as a Diffuse BSDF of its colour."""
        colour = tuple(m.diffuse_color) if colour is None else colour
        had_tree = m.node_tree is not None
        if not created:
            self.changes.set(m, "use_nodes", True)
        else:
            m.use_nodes = True
        nt = m.node_tree
        if not had_tree and not created:
            # use_nodes made a default tree; Blender keeps it, so empty it again on restore.
            self.changes.on_restore(lambda: [nt.nodes.remove(n) for n in list(nt.nodes)])
        saved = [n for n in nt.nodes]
        for n in saved:  # outputs of the user's (unused) tree must not win
            if n.bl_idname == "ShaderNodeOutputMaterial":
                self.changes.set(n, "is_active_output", False)
        diffuse = nt.nodes.new("ShaderNodeBsdfDiffuse")
        diffuse.inputs["Color"].default_value = colour
        out = nt.nodes.new("ShaderNodeOutputMaterial")
        out.target = "ALL"
        nt.links.new(diffuse.outputs["BSDF"], out.inputs["Surface"])
        out.is_active_output = True
        self.changes.on_restore(lambda: (nt.nodes.remove(out), nt.nodes.remove(diffuse)))

    def _give_material(self, ob, mat):
        if ob.material_slots:
            slot = ob.material_slots[0]
            old_mat = slot.material
            self.changes.on_restore(lambda: setattr(slot, "material", old_mat))
            slot.material = mat
        else:
            data = ob.data
            data.materials.append(mat)
            self.changes.on_restore(lambda: data.materials.clear())  # it had none

    def _mask_tree(self, nt, keep_alive):
        for out in [n for n in nt.nodes if n.bl_idname == "ShaderNodeOutputMaterial"]:
            if out.target not in {"ALL", "CYCLES"}:
                continue
            surf = out.inputs["Surface"]
            if not surf.is_linked:
                continue  # renders black in any case
            src = surf.links[0].from_socket
            made = []

            def new(kind):
                n = nt.nodes.new(kind)
                made.append(n)
                return n
            coord = new("ShaderNodeTexCoord")
            tex = new("ShaderNodeTexImage")
            tex.image = self._mask_image
            tex.interpolation = "Closest"
            tex.extension = "EXTEND"  # rays of border pixels leave the frame: the edge texel
            nt.links.new(coord.outputs["Window"], tex.inputs["Vector"])
            path = new("ShaderNodeLightPath")
            inv = new("ShaderNodeMath")
            inv.operation = "SUBTRACT"
            inv.inputs[0].default_value = 1.0
            nt.links.new(tex.outputs["Color"], inv.inputs[1])
            mul = new("ShaderNodeMath")
            mul.operation = "MULTIPLY"
            nt.links.new(path.outputs["Is Camera Ray"], mul.inputs[0])
            nt.links.new(inv.outputs[0], mul.inputs[1])
            fac = new("ShaderNodeMath")
            fac.operation = "SUBTRACT"
            fac.inputs[0].default_value = 1.0
            nt.links.new(mul.outputs[0], fac.inputs[1])
            emit = new("ShaderNodeEmission")
            emit.inputs["Strength"].default_value = 0.0
            mix = new("ShaderNodeMixShader")
            nt.links.new(fac.outputs[0], mix.inputs["Fac"])
            nt.links.new(emit.outputs["Emission"], mix.inputs[1])
            shader = src
            if keep_alive:
                strength = self._keep_alive_strength(new, nt, coord, path, tex)
                keep = new("ShaderNodeEmission")
                nt.links.new(strength, keep.inputs["Strength"])
                add = new("ShaderNodeAddShader")
                nt.links.new(src, add.inputs[0])
                nt.links.new(keep.outputs["Emission"], add.inputs[1])
                shader = add.outputs["Shader"]
            nt.links.new(shader, mix.inputs[2])
            nt.links.new(mix.outputs["Shader"], surf)

            def undo(nt=nt, made=made, src=src, surf=surf):
                for n in made:
                    nt.nodes.remove(n)
                nt.links.new(src, surf)
            self.changes.on_restore(undo)

    # The keep-alive's scale: far below any value a render holds (a float sum of
    # 1 and 1e-20 is 1), far above the float minimum.
    KEEP_ALIVE = 1e-20

    def _keep_alive_strength(self, new, nt, coord, path, tex):
        """The keep-alive's strength, KEEP_ALIVE * white noise of the Window
        position * IsCameraRay * mask: a camera sample's position is jittered
        over the pixel filter, so each sample of a pixel draws another value."""
        noise = new("ShaderNodeTexWhiteNoise")
        noise.noise_dimensions = "3D"
        nt.links.new(coord.outputs["Window"], noise.inputs["Vector"])
        seen = new("ShaderNodeMath")
        seen.operation = "MULTIPLY"
        nt.links.new(path.outputs["Is Camera Ray"], seen.inputs[0])
        nt.links.new(tex.outputs["Color"], seen.inputs[1])
        scaled = new("ShaderNodeMath")
        scaled.operation = "MULTIPLY"
        nt.links.new(noise.outputs["Value"], scaled.inputs[0])
        scaled.inputs[1].default_value = 0.0  # off: Cycles folds it away (_keep_alive)
        self._keep_alive_scales.append(scaled.inputs[1])
        strength = new("ShaderNodeMath")
        strength.operation = "MULTIPLY"
        nt.links.new(seen.outputs[0], strength.inputs[0])
        nt.links.new(scaled.outputs[0], strength.inputs[1])
        return strength.outputs[0]

    def _keep_alive(self, on):
        """Switches the keep-alive emission on or off for the next renders. On,
        Cycles takes every surface that carries it for an emitter and shades the
        last hit of paths it would end: more time for the pixels rendered
        (KEEP_ALIVE_COST); off, its nodes fold to nothing."""
        if on != self._keep_alive_on:
            for socket in self._keep_alive_scales:
                socket.default_value = self.KEEP_ALIVE if on else 0.0
            self._keep_alive_on = on

    def _write_mask(self, texels):
        """texels: [rows top-down, columns] of 0/1. Written to its file and reloaded:
        with persistent data Cycles sees a mask changed in memory only that way."""
        self._mask_count = getattr(self, "_mask_count", 0) + 1
        self.mask_path = os.path.join(self.workdir, "mask%d.png" % self._mask_count)
        _write_png(self.mask_path, (texels > 0).astype(np.uint8) * 255)
        if self._mask_image is not None:
            self._mask_image.filepath = self.mask_path
            self._mask_image.reload()

    def _footprint(self):
        """Texel offsets (lo, hi) from a pixel's first texel that its camera rays may reach."""
        k = self.args.mask_scale
        r = self.filter_radius + 1e-3
        return int(np.floor((0.5 - r) * k)), int(np.ceil((0.5 + r) * k))

    def mask_of(self, xs, ys):
        """The mask texels for pixels (xs, ys): the filter footprint of each."""
        k = self.args.mask_scale
        lo, hi = self._footprint()
        texels = np.zeros((self.height * k, self.width * k), np.float32)
        for dy in range(lo, hi):
            ty = np.clip(ys * k + dy, 0, self.height * k - 1)
            for dx in range(lo, hi):
                tx = np.clip(xs * k + dx, 0, self.width * k - 1)
                texels[ty, tx] = 1.0
        return texels

    def reached(self, texels):
        """Two [height, width] masks: whether any camera ray of the pixel can meet
        a mask texel of 1, and whether all of them do. One pass: the texels of 1
        in each pixel's footprint, counted on a summed-area table (a texel off
        the image reads the edge texel, as the texture's Extend does)."""
        k = self.args.mask_scale
        lo, hi = self._footprint()
        pad = max(-lo, hi - k, 0)
        s = np.zeros((self.height * k + 2 * pad + 1, self.width * k + 2 * pad + 1), np.int64)
        s[1:, 1:] = np.pad(texels > 0, pad, mode="edge").cumsum(0).cumsum(1)
        y0, x0 = np.arange(self.height) * k + lo + pad, np.arange(self.width) * k + lo + pad
        y1, x1 = y0 + hi - lo, x0 + hi - lo
        count = s[y1][:, x1] - s[y0][:, x1] - s[y1][:, x0] + s[y0][:, x0]
        return count > 0, count == (hi - lo) ** 2

    # ----------------------------------------------------------- renders --
    def _render(self, samples, label, seed=None):
        import time
        sc = self.scene
        self._round += 1
        path = sc.render.filepath
        sc.cycles.samples = samples
        if seed is not None:
            sc.cycles.seed = seed
        # A changed sample count alone does not reach a persistent Cycles session;
        # a change to the render settings (the same path) makes it look again.
        sc.render.filepath = path
        t0 = time.monotonic()
        result = bpy.ops.render.render(write_still=True, scene=sc.name, layer=self.layer.name)
        if "FINISHED" not in result or not os.path.exists(path):
            raise SceneError("Cycles did not render (%s)" % label)
        w, h, planes, meta = exr.read(path)
        os.remove(path)
        # The call's wall clock, then Cycles' own synchronisation and render time.
        cycles = [_clock_seconds(meta.get("cycles.%s.%s" % (self.layer.name, k), "")) for k in
                  ("synchronization_time", "render_time")]
        self.render_seconds.append((label, time.monotonic() - t0, *cycles))
        crop = self._crop
        if crop is not None:
            # A cropped render: its planes in the frame, 0 outside as an uncropped border's.
            x0, y0, x1, y1 = crop
            if (w, h) != (x1 - x0, y1 - y0):
                raise SceneError("Cycles rendered %dx%d for the render border %s, expected %dx%d" %
                                 (w, h, crop, x1 - x0, y1 - y0))
            for k, v in planes.items():
                frame = np.zeros((self.height, self.width), v.dtype)
                frame[y0:y1, x0:x1] = v
                planes[k] = frame
        elif (w, h) != (self.width, self.height):
            raise SceneError("Cycles rendered %dx%d, expected %dx%d" % (w, h, self.width, self.height))
        if self.args.keep_renders:
            os.makedirs(self.args.keep_renders, exist_ok=True)
            dst = os.path.join(self.args.keep_renders, "%02d_%s.npz" % (self._round, label))
            np.savez(dst, **{k.split(".", 1)[-1]: v for k, v in planes.items()})
        done = meta.get("cycles.%s.samples" % self.layer.name)
        if done is not None and done != str(samples):
            raise SceneError("Cycles rendered %s samples per pixel, asked for %d (%s)" % (done, samples, label))
        p = self.layer.name + "."
        return {k[len(p):]: v for k, v in planes.items() if k.startswith(p)}

    def _guides_only_passes(self, on):
        """The passes only the guides read: the IDs (Cryptomatte), the normal and
        the Denoising Albedo (the texture seen in mirrors). Off in the rounds:
        Cycles writes them for every sample of every pixel, masked ones too
        (docs/BLENDER.md)."""
        vl = self.layer
        for attr in ("use_pass_normal", "use_pass_cryptomatte_object", "use_pass_cryptomatte_material"):
            self.changes.set(vl, attr, on)
        self.changes.set(vl.cycles, "denoising_store_passes", on)

    def _rgb(self, planes, name, comps="RGB"):
        return np.stack([planes[name + "." + c] for c in comps], axis=-1)

    def guides(self):
        """The guides and the preview: one unmasked render at the preview's samples;
        with halves two, one per seed, whose difference gives noise_psnr."""
        if self._guides is None:
            self._write_mask(np.ones((self.height * self.args.mask_scale,
                                      self.width * self.args.mask_scale), np.float32))
            ps = self.preview_samples
            counts = [ps - ps // 2, ps // 2] if self.halves and ps >= 2 else [ps]
            pls = [self._render(n, "guides", seed) for n, seed in zip(counts, self.preview_seeds)]
            if len(pls) == 2:  # one entry: round_cost() reads the guides render's time
                self.render_seconds[-2:] = [("guides", *(a + b for a, b in zip(self.render_seconds[-2][1:],
                                                                                 self.render_seconds[-1][1:])))]
                self.scene.cycles.seed = self.seeds[0]

            def mean(name, comps="RGB"):
                return sum(n * self._rgb(p, name, comps) for n, p in zip(counts, pls)) / float(ps)
            pl = pls[0]
            self._guides_only_passes(False)
            g = {}
            g["texture"] = mean("DiffCol")
            g["object_id"] = pl["CryptoObject00.r"].view(np.uint32).copy()
            g["shader_id"] = pl["CryptoMaterial00.r"].view(np.uint32).copy()
            # The texture split through mirrors (the AOV provider's albedo role): on a
            # surface whose DiffCol is below ALBEDO_FLOOR at most pixels, the texture is
            # the Denoising Albedo and L_i the light it modulates over it (_reflected),
            # so that what a mirror shows is re-applied per pixel.
            mirror = np.zeros((self.height, self.width), bool)
            if "Denoising Albedo.R" in pl:
                dark = (g["texture"] < ALBEDO_FLOOR).all(axis=-1)
                surface = g["object_id"].astype(np.uint64) << np.uint64(32) | g["shader_id"].astype(np.uint64)
                _, inverse = np.unique(surface, return_inverse=True)
                share = np.bincount(inverse.ravel(), dark.ravel()) / np.bincount(inverse.ravel())
                mirror = (share > 0.5)[inverse].reshape(dark.shape)
                g["texture"][mirror] = np.maximum(mean("Denoising Albedo")[mirror], ALBEDO_FLOOR)
            self._through_mirror = mirror
            g["normal"] = self._rgb(pl, "Normal", "XYZ")
            g["L"] = mean("Combined")
            # Each half's render alone (_may_stop_early, _stopped_early).
            g["L_of_half"] = [self._rgb(p, "Combined") for p in pls]
            g["Li"] = mean("DiffDir") + mean("DiffInd")
            reflected = sum(n * self._reflected(p) for n, p in zip(counts, pls)) / float(ps)
            g["Li"][mirror] = reflected[mirror] / g["texture"][mirror]
            g["Lc"] = g["L"] - g["Li"] * g["texture"]
            if len(pls) == 2:
                # The preview's variance (dcm::HalvesVariance), at the exact pixels' samples.
                # g["var"]: the preview's own, which dcm weighs while it plans on the preview.
                a, b = self._rgb(pls[0], "Combined"), self._rgb(pls[1], "Combined")
                g["var"] = ((a - b) ** 2 * (counts[0] * counts[1] / float(ps) ** 2)).astype(np.float32)
                # The texture guide is these renders' DiffCol: the covariance of its
                # estimate and the preview's, which dcm's estimate of its error takes out.
                ta, tb = self._rgb(pls[0], "DiffCol"), self._rgb(pls[1], "DiffCol")
                if mirror.any():
                    ta[mirror] = np.maximum(self._rgb(pls[0], "Denoising Albedo")[mirror], ALBEDO_FLOOR)
                    tb[mirror] = np.maximum(self._rgb(pls[1], "Denoising Albedo")[mirror], ALBEDO_FLOOR)
                g["texcov"] = ((ta - tb) * (a - b) * (counts[0] * counts[1] / float(ps) ** 2)).astype(np.float32)
                self.noise_psnr = _noise_psnr(g["var"] * (ps / float(self.samples)), g["L"])
            self._guides = g
        return self._guides

    def _runs(self, xs, ys, t):
        """Rectangles over the tiles of side t that hold a pixel: each tile row's runs."""
        tw, th = -(-self.width // t), -(-self.height // t)
        occ = np.zeros((th, tw), bool)
        occ[ys // t, xs // t] = True
        rects = []
        for ty in range(th):
            tx = 0
            while tx < tw:
                if not occ[ty, tx]:
                    tx += 1
                    continue
                start = tx
                while tx < tw and occ[ty, tx]:
                    tx += 1
                rects.append((start * t, ty * t, min(tx * t, self.width), min((ty + 1) * t, self.height)))
        return rects

    def rectangles(self, xs, ys, calls=1):
        """Where to render pixels (xs, ys) in a round: a list of (x0, y0, x1, y1), or
        [None] for the whole frame. A masked pixel costs Cycles a camera ray and a
        shader per sample (about a seventh of a rendered one) until it stops
        (_masked_pixels_stop), and a visit per sample after that:
        _cheapest() with `calls` renders per rectangle."""
        if self.args.border_tile > 0:
            return self._runs(xs, ys, self.args.border_tile)
        n = self.samples // calls
        return self._cheapest(xs, ys, calls, self._border_pixel_seconds(n, self._masked_stop(n)))[0]

    def _cheapest(self, xs, ys, calls, per_pixel, tiles=(16, 32, 64)):
        """Of the `tiles` (sides in px) that hold the pixels (xs, ys) (each tile
        row's runs one render border, at most max_calls of them) and the whole
        frame ([None]), the cheapest to render: `calls` renders per rectangle,
        each its fixed time (call_seconds) and `per_pixel` seconds for every
        pixel inside its border (_border_pixel_seconds). Returns the rectangles
        and their cost in seconds."""
        best, best_cost = [None], calls * (self.args.call_seconds + self.width * self.height * per_pixel)
        for t in tiles:
            rects = self._runs(xs, ys, t)
            area = sum((x1 - x0) * (y1 - y0) for x0, y0, x1, y1 in rects)
            cost = calls * (len(rects) * self.args.call_seconds + area * per_pixel)
            if len(rects) <= self.args.max_calls and cost < best_cost:
                best, best_cost = rects, cost
        return best, best_cost

    # Cycles judges a pixel's convergence every this many samples past the minimum.
    CHECK = 16

    # What Cycles spends on a pixel of the render (border) per sample after the
    # pixel stopped: it visits every pixel each sample. A round of no pixel at
    # 256² took 0.58 s at 512 samples, 0.29 s at 64, on this project's machine
    # (examples/blender/round_call_cost.py; docs/BLENDER.md, *Render borders*).
    VISIT_SECONDS = 1e-8

    def _border_pixel_seconds(self, n, masked_samples):
        """What a masked pixel inside a render border costs a call of n samples: the
        masked_samples it takes before it stops, and Cycles' visit each sample."""
        return self._masked_seconds(masked_samples) + n * self.VISIT_SECONDS

    def _masked_seconds(self, samples):
        """What a masked pixel costs for `samples` samples: about a seventh of a
        rendered pixel's per sample (docs/BLENDER.md)."""
        return 0.14 * self.pixel_seconds() * samples / self.samples

    def _masked_stop(self, n):
        """Samples a masked pixel of a render of n samples takes: it stops at Cycles'
        first check past the minimum."""
        return min(n, self.CHECK * (self._masked_min_samples(n) // self.CHECK + 1))

    def _masked_min_samples(self, n):
        """Samples after which a masked pixel of a render of n samples may stop: 8
        (it stops at the first check, 16)."""
        return max(4, min(n, self.args.masked_min_samples or 8))

    def _may_stop_early(self, xs, ys):
        """Which pixels (xs, ys) might stop early: where a few samples can all be
        0, where one half of the preview is 0 and the other is not (a dark pixel
        that rare paths light); without halves a black preview counts too. (The
        preview has seeds of its own: it tells the odds, not a seed's first
        samples.)"""
        g = self.guides()
        halves = [(p[ys, xs] == 0).all(axis=1) for p in g["L_of_half"]]
        zero = np.logical_or.reduce(halves)
        if len(halves) > 1:
            zero &= ~(g["L"][ys, xs] == 0).all(axis=1)
        return zero

    # What the keep-alive adds to the time of the pixels a render renders.
    KEEP_ALIVE_COST = 0.12

    def _keep_alive_pays(self, xs, ys, n):
        """Whether a render of exact pixels (xs, ys) at n samples should switch
        the keep-alive on (_keep_alive): where pixels might stop early
        (_may_stop_early) and rendering them again (_again) would cost more."""
        zero = self._may_stop_early(xs, ys)
        if not zero.any() or not self._keep_alive_scales:  # no surface carries it
            return False
        again = self._again(xs[zero], ys[zero], n)[1]
        return again > self.KEEP_ALIVE_COST * len(xs) * self.pixel_seconds() * n / self.samples

    # Cycles' noise threshold with the keep-alive on: below the error it gives a
    # pixel whose other samples are all 0 (about 1e-16).
    KEEP_ALIVE_THRESHOLD = 1e-30

    def _masked_pixels_stop(self, n, keep_alive=False):
        """Lets a masked pixel stop after a few of the n samples (n = 0: off). A
        masked camera ray costs Cycles about a seventh of a rendered one per sample;
        with adaptive sampling a pixel whose samples agree stops, and a masked
        pixel's are all 0. The threshold is so low that a rendered pixel stops only
        when its samples (nearly) agree; _stopped_early() finds those that did.
        With the keep-alive on (_keep_alive_pays) none of its pixels' samples
        agree, and the threshold is lower still: only samples that agree
        exactly stop a pixel, so no exact pixel stops (the world's pixels,
        whose samples may differ only a little, then take longer)."""
        cy = self.scene.cycles
        cy.use_adaptive_sampling = n > 0
        if n > 0:
            cy.adaptive_threshold = self.KEEP_ALIVE_THRESHOLD if keep_alive else self.args.adaptive_threshold
            cy.adaptive_min_samples = self._masked_min_samples(n)

    # Values that differ by less than this, relative, are equal but for the
    # order of float additions (a few float ulps; the tests' exactness bound).
    SAME = 1e-5

    def _stopped_early(self, pl, n, xs, ys, inside):
        """Which pixels (xs, ys) in `inside` took fewer than the n samples and are
        not constant: their value differs from the preview's, or the preview's
        halves differ from each other, by more than SAME. A pixel whose samples
        were all 0 so far stops, and a dark pixel that rare paths light is not
        0; a pixel whose samples agree to float precision so far stops
        too, and its value is the full render's but for float rounding
        (docs/BLENDER.md, "Masked pixels stop early")."""
        took = pl["Debug Sample Count.X"][ys, xs] * n  # Cycles writes the share of the samples
        short = inside & (took < n - 0.5)
        if not short.any():
            return short
        g = self.guides()
        L = self._rgb(pl, "Combined")[ys, xs]

        def same(a, b):
            return (np.abs(a - b) <= self.SAME * np.maximum(np.abs(a), np.abs(b))).all(axis=1)
        constant = same(L, g["L"][ys, xs])
        halves = g["L_of_half"]
        for other in halves[1:]:
            constant &= same(halves[0][ys, xs], other[ys, xs])
        return short & ~constant

    @staticmethod
    def _inside(rect, xs, ys):
        """Which pixels (xs, ys) a render border (x0, y0, x1, y1) holds; None: the frame."""
        if rect is None:
            return np.ones(len(xs), bool)
        return (xs >= rect[0]) & (xs < rect[2]) & (ys >= rect[1]) & (ys < rect[3])

    def _reflected(self, planes):
        """What a mirror reflects of the surfaces it shows, which their albedo
        modulates: GlossCol * GlossInd (the AOV preset's Lr; light through glass
        stays in L_c)."""
        return self._rgb(planes, "GlossCol") * self._rgb(planes, "GlossInd")

    def _exact_values(self, pl, xs, ys):
        """L and L_i = DiffDir + DiffInd of pixels (xs, ys) in a render's planes;
        through a mirror (guides()) L_i = _reflected() / the texture guide."""
        texture = self.guides()["texture"]
        L = self._rgb(pl, "Combined")[ys, xs]
        Li = (self._rgb(pl, "DiffDir") + self._rgb(pl, "DiffInd"))[ys, xs]
        mirror = self._through_mirror[ys, xs]
        Li[mirror] = self._reflected(pl)[ys, xs][mirror] / texture[ys, xs][mirror]
        return L, Li

    def _again(self, xs, ys, n):
        """Where pixels (xs, ys) are rendered again with every one of n samples
        (adaptive sampling off: every pixel inside a border takes them all), and
        what that costs: borders over their 16-px tiles or the whole frame,
        whichever _cheapest() finds cheaper. (Larger tiles save calls for area
        that, with adaptive sampling off, costs more than the model's masked
        pixel: docs/BLENDER.md.)"""
        return self._cheapest(xs, ys, 1, self._border_pixel_seconds(n, n), (16,))

    def _render_all_samples(self, n, label, seed, xs, ys):
        """Renders pixels (xs, ys) with every one of the n samples, where _again()
        says: the planes of each render and where it holds."""
        self._masked_pixels_stop(0)
        self._keep_alive(False)  # every pixel takes every sample
        for rect in self._again(xs, ys, n)[0]:
            self._set_border(rect)
            yield self._render(n, label, seed), self._inside(rect, xs, ys)

    def _set_border(self, rect):
        """Renders from now on within rect (x0, y0, x1, y1) and a pixel more on each
        side, cropped to it (_render() places it in the frame); None: the frame."""
        r = self.scene.render
        if rect is None:
            r.use_border = False
            self._crop = None
            return
        x0, y0 = max(rect[0] - 1, 0), max(rect[1] - 1, 0)
        x1, y1 = min(rect[2] + 1, self.width), min(rect[3] + 1, self.height)
        # A quarter pixel in: Blender takes the border to whole pixels, by
        # truncation or rounding alike; y counts from the bottom.
        W, H = self.width, self.height
        r.use_border = r.use_crop_to_border = True
        r.border_min_x, r.border_max_x = (x0 + 0.25) / W, min((x1 + 0.25) / W, 1.0)
        r.border_min_y, r.border_max_y = (H - y1 + 0.25) / H, min((H - y0 + 0.25) / H, 1.0)
        self._crop = (x0, y0, x1, y1)

    def evaluate(self, xs, ys, variance=True):
        """L, L_i, L_c, var [n, 3] of pixels (xs, ys) at full samples: one mask, and one
        render call per rectangle of rectangles(), two with halves where the variance
        is asked for (var: the variance of L from the two halves at this pixel alone;
        None without halves). A round whose variance dcm does not weigh costs one
        render call per rectangle, with the file's seed. Then `extra`: (x, y, L, L_i,
        L_c, var) of the pixels not asked for that the round rendered as a full
        render does: every ray of theirs met the mask (a pixel filter wider than a
        pixel), and they took every sample or are constant (_stopped_early)."""
        g = self.guides()
        if os.environ.get("DCM_BLENDER_TEST_FAULT") == "crash-on-eval":  # tests: Blender dies mid-round
            os.kill(os.getpid(), 9)
        texels = self.mask_of(xs, ys)
        self._write_mask(texels)
        reached, covered = self.reached(texels)
        if self._known is None:
            self._known = np.zeros((self.height, self.width), bool)
        self._known[ys, xs] = True
        free = covered & ~self._known  # dcm has the others already
        fy, fx = (a.astype(np.int64) for a in np.nonzero(free))
        # Samples per render: all of them, or two halves (the first takes the odd one).
        halves = self.halves and variance
        counts = [self.samples] if not halves else [self.samples - self.samples // 2, self.samples // 2]
        L = np.zeros((len(counts), len(xs), 3), np.float32)
        Li = np.zeros((len(counts), len(xs), 3), np.float32)
        done = np.zeros(len(xs), bool)
        FL = np.zeros((len(counts), len(fx), 3), np.float32)
        FLi = np.zeros((len(counts), len(fx), 3), np.float32)
        fdone = np.zeros(len(fx), bool)
        fshort = np.zeros(len(fx), bool)
        self._evals = getattr(self, "_evals", 0) + 1
        for rect in self.rectangles(xs, ys, len(counts)):
            self._set_border(rect)
            inside = self._inside(rect, xs, ys)
            finside = self._inside(rect, fx, fy)
            for h, (n, seed) in enumerate(zip(counts, self.seeds)):
                keep_alive = (self.args.keep_alive == "on" or self.args.keep_alive == "auto"
                              and self._keep_alive_pays(xs[inside], ys[inside], n))
                self._masked_pixels_stop(n, keep_alive)
                self._keep_alive(keep_alive)
                self.kept_alive_renders += keep_alive
                pl = self._render(n, "eval%d" % self._evals, seed)
                diffcol = self._rgb(pl, "DiffCol")
                # The mask rendered must be the mask asked for: outside it no surface
                # keeps its own shader (a stale mask would show diffuse colour there).
                stray = (diffcol.max(axis=-1) > 0) & ~reached
                if stray.any():
                    raise SceneError("%d pixels outside the mask were rendered: the mask of this round did not "
                                     "reach Cycles" % int(stray.sum()))
                L[h, inside], Li[h, inside] = self._exact_values(pl, xs[inside], ys[inside])
                FL[h, finside], FLi[h, finside] = self._exact_values(pl, fx[finside], fy[finside])
                fshort |= self._stopped_early(pl, n, fx, fy, finside)
                early = np.flatnonzero(self._stopped_early(pl, n, xs, ys, inside))
                if len(early):
                    self.rendered_again += len(early)
                    ex, ey = xs[early], ys[early]
                    for pl2, in2 in self._render_all_samples(n, "eval%d_again" % self._evals, seed, ex, ey):
                        L[h, early[in2]], Li[h, early[in2]] = self._exact_values(pl2, ex[in2], ey[in2])
                    self._set_border(rect)
            done |= inside
            fdone |= finside
        self._set_border(None)
        self._masked_pixels_stop(0)
        self.scene.cycles.seed = self.seeds[0]
        if not done.all():
            raise SceneError("%d pixels fell outside every render border" % int((~done).sum()))
        keep = fdone & ~fshort
        fx, fy, FL, FLi = fx[keep], fy[keep], FL[:, keep], FLi[:, keep]
        self._known[fy, fx] = True

        def combine(L, Li, x, y):
            var = None
            if halves:
                # The mean weighted by samples; its variance (A - B)^2 nA nB / N^2 (dcm::HalvesVariance).
                nA, nB = counts
                N = float(self.samples)
                var = ((L[0] - L[1]) ** 2 * (nA * nB / N ** 2)).astype(np.float32)
                L = ((nA * L[0] + nB * L[1]) / N).astype(np.float32)
                Li = ((nA * Li[0] + nB * Li[1]) / N).astype(np.float32)
            else:
                L, Li = L[0], Li[0]
            return L, Li, L - Li * g["texture"][y, x], var
        self.extra_pixels += len(fx)
        return (*combine(L, Li, xs, ys), (fx, fy, *combine(FL, FLi, fx, fy)))

    def set_exact_samples(self, n):
        """Later rounds render their exact pixels at n samples, at most the run's
        (a goal that does not need them all; with halves, at least 2)."""
        if not (2 if self.halves else 1) <= n <= self.file_samples:
            raise ValueError("exact_samples %d: outside 1 to %d" % (n, self.file_samples))
        self.samples = n

    def pixel_seconds(self):
        """What one pixel at full samples costs, from the guides render (its samples
        are preview_samples; its time includes the scene's first sync: an upper bound)."""
        return self.render_seconds[0][1] * self.samples / self.preview_samples / (self.width * self.height)

    def round_cost(self):
        """(seconds per round, seconds per exact pixel), from the guides render: a
        pixel at full samples costs samples / preview_samples times a preview pixel
        (pixel_seconds); a round is a render call per seed, each its fixed time
        (call_seconds) and the masked pixels of the whole frame until they stop
        (_masked_stop) and after (VISIT_SECONDS; docs/BLENDER.md)."""
        n = self.samples // len(self.seeds)
        per_pixel = self._border_pixel_seconds(n, self._masked_stop(n))
        return len(self.seeds) * (self.args.call_seconds + self.width * self.height * per_pixel), self.pixel_seconds()

    def fingerprint(self):
        """What setup() may change, as text: restore() must bring it back."""
        sc = self.scene
        lines = []
        for m in bpy.data.materials:
            lines.append("material %s nodes=%s" % (m.name, m.use_nodes))
            if m.node_tree:
                lines += sorted("  node %s %s" % (n.name, getattr(n, "is_active_output", "")) for n in m.node_tree.nodes)
                lines += sorted("  link %s.%s>%s.%s" % (l.from_node.name, l.from_socket.identifier, l.to_node.name,
                                                         l.to_socket.identifier) for l in m.node_tree.links)
        lines += ["image " + i.name for i in bpy.data.images if i.type != "RENDER_RESULT"]
        lines += ["material %s light sampling %s" % (m.name, getattr(m.cycles, "emission_sampling", None)
                                                     or m.cycles.sample_as_light) for m in bpy.data.materials]
        for ob in sc.objects:
            lines.append("object %s %s" % (ob.name, [s.material and s.material.name for s in ob.material_slots]))
        for vl in sc.view_layers:
            lines.append("layer %s %s" % (vl.name, [getattr(vl, a) for a in dir(vl) if a.startswith("use_pass")]
                                          + [vl.use, vl.pass_cryptomatte_depth]))
        r, cy = sc.render, sc.cycles
        lines.append("render %s" % ([getattr(r, a) for a in ("use_border", "use_crop_to_border", "border_min_x",
                                                             "border_max_y", "use_persistent_data", "use_compositing",
                                                             "use_sequencer", "use_file_extension", "filepath",
                                                             "threads_mode", "threads")]
                                    + [r.image_settings.file_format, r.image_settings.color_depth,
                                       r.image_settings.exr_codec]))
        lines.append("cycles %s" % [cy.samples, cy.seed, cy.use_adaptive_sampling, cy.use_denoising, sc.frame_current])
        return "\n".join(lines)

    def restore(self):
        for e in self.changes.restore():
            _log("while restoring the scene: " + e)
