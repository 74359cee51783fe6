# What every Cycles scene of examples/blender shares, so that
# `dcm reconstruct --preset blender` reads all their renders alike: the render
# settings and passes (setup_render, enable_dcm_passes), materials with a pass
# index, and the small geometry helpers. Imported by make_and_render.py (the
# room, the tuning scene), check_scenes.py (the check set) and enable_passes.py
# (a user's file); Blender 3.4.
import math
import os

import bpy


# ---------------------------------------------------------------- textures --

def hash01(i, j=0, k=0):
    """Deterministic pseudo-random number in [0, 1)."""
    h = (i * 374761393 + j * 668265263 + k * 2147483647) & 0xFFFFFFFF
    h = ((h ^ (h >> 13)) * 1274126177) & 0xFFFFFFFF
    return ((h ^ (h >> 16)) & 0xFFFFFF) / float(1 << 24)


def make_image(name, size, texel, path):
    """An sRGB image texture from texel(x, y) -> (r, g, b) in [0,1], saved as PNG."""
    img = bpy.data.images.new(name, width=size, height=size, alpha=False)
    px = [0.0] * (size * size * 4)
    for y in range(size):
        for x in range(size):
            r, g, b = texel(x, y)
            o = (y * size + x) * 4
            px[o], px[o + 1], px[o + 2], px[o + 3] = r, g, b, 1.0
    img.pixels.foreach_set(px)
    img.filepath_raw = path
    img.file_format = "PNG"
    img.save()
    return img



# --------------------------------------------------------------- materials --

def principled(name, index, color=(0.8, 0.8, 0.8), rough=0.5, metal=0.0, spec=0.5,
               image=None, emission=None, strength=0.0):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    m.pass_index = index
    nt = m.node_tree
    bsdf = nt.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (*color, 1.0)
    bsdf.inputs["Roughness"].default_value = rough
    bsdf.inputs["Metallic"].default_value = metal
    bsdf.inputs["Specular"].default_value = spec
    if image is not None:
        tex = nt.nodes.new("ShaderNodeTexImage")
        tex.image = image
        tex.extension = "REPEAT"
        nt.links.new(tex.outputs["Color"], bsdf.inputs["Base Color"])
    if emission is not None:
        bsdf.inputs["Emission"].default_value = (*emission, 1.0)
        bsdf.inputs["Emission Strength"].default_value = strength
    return m



# ---------------------------------------------------------------- geometry --

def box(name, loc, dims, mat):
    bpy.ops.mesh.primitive_cube_add(size=1.0, location=loc)
    o = bpy.context.active_object
    o.name = name
    o.scale = dims
    bpy.ops.object.transform_apply(scale=True)
    o.data.materials.append(mat)
    return o


def cyl(name, loc, radius, depth, mat, verts=16, rot=(0, 0, 0)):
    bpy.ops.mesh.primitive_cylinder_add(vertices=verts, radius=radius, depth=depth,
                                        location=loc, rotation=rot)
    o = bpy.context.active_object
    o.name = name
    o.data.materials.append(mat)
    return o


def join(name, parts, index):
    """Joins parts into one object (one Cryptomatte / IndexOB entry) with pass_index."""
    bpy.ops.object.select_all(action="DESELECT")
    for p in parts:
        p.select_set(True)
    bpy.context.view_layer.objects.active = parts[0]
    if len(parts) > 1:
        bpy.ops.object.join()
    o = bpy.context.view_layer.objects.active
    o.name = name
    o.pass_index = index
    return o


def scale_uv(obj, k):
    for loop in obj.data.uv_layers.active.data:
        loop.uv = (loop.uv[0] * k, loop.uv[1] * k)



def look_at_camera(loc, target, lens):
    """The scene's camera at loc, looking at target, no roll; focal length lens mm."""
    bpy.ops.object.camera_add(location=loc)
    cam = bpy.context.active_object
    cam.data.lens = lens
    cam.data.clip_start = 0.05
    d = [target[i] - loc[i] for i in range(3)]
    yaw = math.atan2(d[1], d[0]) - math.pi / 2
    pitch = math.atan2(d[2], math.hypot(d[0], d[1]))
    cam.rotation_euler = (math.pi / 2 + pitch, 0.0, yaw)
    bpy.context.scene.camera = cam
    return cam


# ------------------------------------------------------------------ render --

def enable_dcm_passes(vl):
    """The passes `dcm reconstruct --preset blender` reads, on view layer vl:
    Combined, Normal (creases inside one object, --crease-angle), IndexOB,
    IndexMA, UV, Diffuse/Glossy/Transmission Color+Direct+Indirect, Emit, Env,
    Cryptomatte object and material, and Denoising Data (its Denoising Albedo:
    the texture seen in mirrors and through glass, docs/NOISE.md)."""
    vl.use_pass_combined = True
    vl.use_pass_normal = True
    vl.use_pass_object_index = True
    vl.use_pass_material_index = True
    vl.use_pass_uv = True
    for kind in ("diffuse", "glossy", "transmission"):
        for part in ("color", "direct", "indirect"):
            setattr(vl, "use_pass_%s_%s" % (kind, part), True)
    vl.use_pass_emit = True
    vl.use_pass_environment = True
    vl.use_pass_cryptomatte_object = True
    vl.use_pass_cryptomatte_material = True
    vl.cycles.denoising_store_passes = True


def setup_render(args):
    sc = bpy.context.scene
    sc.render.engine = "CYCLES"
    sc.cycles.device = "CPU"
    sc.cycles.samples = args.samples
    sc.cycles.use_adaptive_sampling = False
    sc.cycles.use_denoising = False
    sc.cycles.max_bounces = 4
    sc.cycles.diffuse_bounces = 2
    sc.cycles.glossy_bounces = 2
    sc.cycles.transmission_bounces = 4
    # production noise controls: no caustics, blurred glossy after diffuse
    # bounces, indirect clamping (the reference is this same estimator)
    sc.cycles.sample_clamp_indirect = 1.0
    sc.cycles.sample_clamp_direct = 8.0
    sc.cycles.caustics_reflective = False
    sc.cycles.caustics_refractive = False
    sc.cycles.blur_glossy = 1.0
    sc.cycles.seed = args.seed
    # (near) point sampling: the index and UV passes are not anti-aliased.
    # Gaussian, not Box: Cycles ignores the width of the Box filter (it always
    # spreads the samples over the whole pixel). --pixel-filter TYPE:WIDTH
    # where the script has it (Blender's default: BLACKMAN_HARRIS:1.5).
    kind, width = (getattr(args, "pixel_filter", "") or "GAUSSIAN:0.01").split(":")
    sc.cycles.pixel_filter_type = kind
    sc.cycles.filter_width = float(width)
    sc.render.resolution_x = sc.render.resolution_y = args.res
    sc.render.resolution_percentage = 100
    sc.render.film_transparent = False
    sc.render.use_compositing = False       # write the passes as rendered
    sc.render.use_sequencer = False
    sc.view_settings.view_transform = "Standard"
    if args.threads > 0:
        sc.render.threads_mode = "FIXED"
        sc.render.threads = args.threads

    vl = sc.view_layers[0]
    vl.name = "ViewLayer"
    enable_dcm_passes(vl)
    vl.use_pass_z = True
    vl.pass_cryptomatte_depth = 2

    im = sc.render.image_settings
    im.file_format = "OPEN_EXR_MULTILAYER"
    im.color_depth = "32"                   # float: IDs and UVs exact
    im.exr_codec = "ZIP"
    sc.render.use_file_extension = False
    sc.render.filepath = os.path.abspath(args.out)

