# Builds a small furnished room procedurally and renders its AOVs with Cycles
# (CPU) into one multilayer EXR that `dcm reconstruct --preset blender` reads.
#
#   blender -b --factory-startup --python make_and_render.py -- \
#       --out out/room_a.exr [--view a|b|c] [--res 256] [--samples 128] \
#       [--threads 2] [--save-blend out/room.blend]
#
# Blender 3.4 (Debian 12's package). Everything is made in this script: the
# geometry, the materials, the floor planks and the rug checker (image
# textures generated here and saved next to the EXR), the lights.
#
# What dcm needs, and what this script sets:
#  - passes: Combined, IndexOB, IndexMA, UV, DiffCol/Dir/Ind, GlossCol/Dir/Ind,
#    TransCol/Dir/Ind, Emit, Env, Cryptomatte object + material;
#  - object.pass_index and material.pass_index (IndexOB/IndexMA are 0 otherwise;
#    dcm prefers the Cryptomatte layers anyway);
#  - a (near) point-sampled beauty: Blender's index and UV passes are not
#    anti-aliased, so the pixel filter is made minimal (box, 0.01 px) and the
#    beauty, the guides and the light passes all describe the pixel centre;
#  - adaptive sampling and denoising off (the reference must be a plain
#    Monte-Carlo estimate at every pixel).
import argparse
import math
import os
import sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from cycles_common import box, cyl, hash01, join, look_at_camera, make_image, principled, scale_uv, setup_render  # noqa: E402


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    ap = argparse.ArgumentParser(prog="make_and_render.py")
    ap.add_argument("--out", required=True, help="multilayer EXR to write")
    ap.add_argument("--view", default="a", choices=["a", "b", "c"], help="camera / variant")
    ap.add_argument("--res", type=int, default=256, help="square resolution")
    ap.add_argument("--samples", type=int, default=128, help="Cycles samples per pixel")
    ap.add_argument("--seed", type=int, default=1, help="Cycles seed")
    ap.add_argument("--threads", type=int, default=2, help="render threads (0: all)")
    ap.add_argument("--save-blend", default="", help="also save the scene as .blend")
    ap.add_argument("--shadow-guide", action="store_true",
                    help="render the sun's shadow guide instead of the AOVs: 1 sample, direct light of the "
                         "sun only on white diffuse materials (view layer 'ShadowGuide', Combined only)")
    ap.add_argument("--highlight-guide", action="store_true",
                    help="render the highlight guide instead of the AOVs: direct light only (no bounces), "
                         "the scene's own materials, --samples samples (view layer 'HighlightGuide', GlossDir)")
    return ap.parse_args(argv)


# ---------------------------------------------------------------- textures --

def planks_texel(size):
    rows = 8                       # planks across the texture
    row_h = size / rows
    def texel(x, y):
        row = int(y // row_h)
        plank_len = size / 2
        off = (hash01(row, 7) * plank_len)
        col = int((x + off) // plank_len)
        base = 0.55 + 0.35 * hash01(row, col)        # per-plank tone
        v = y - row * row_h
        u = (x + off) - col * plank_len
        grain = 0.08 * math.sin(0.35 * x + 3.0 * math.sin(0.05 * x + row) + 6.0 * hash01(row, col, 3))
        seam = 0.35 if (v < 1.5 or u < 1.5) else 1.0   # dark gaps between planks
        s = base * (1.0 + grain) * seam
        return (0.62 * s, 0.40 * s, 0.22 * s)
    return texel


def checker_texel(size, n=8):
    cell = size // n
    def texel(x, y):
        if ((x // cell) + (y // cell)) % 2:
            return (0.75, 0.72, 0.62)
        return (0.20, 0.28, 0.45)
    return texel


# ---------------------------------------------------------------- geometry --

def table(x, y, wood, idx):
    top_h = 0.75
    parts = [box("table_top", (x, y, top_h - 0.02), (1.4, 0.8, 0.04), wood)]
    for sx in (-1, 1):
        for sy in (-1, 1):
            parts.append(cyl("table_leg", (x + sx * 0.62, y + sy * 0.33, (top_h - 0.04) / 2),
                             0.025, top_h - 0.04, wood))
    return join("Table", parts, idx)


def chair(name, x, y, yaw, wood, fabric, idx):
    c, s = math.cos(yaw), math.sin(yaw)
    def at(dx, dy, z):
        return (x + c * dx - s * dy, y + s * dx + c * dy, z)
    seat_h = 0.45
    parts = [box(name + "_seat", at(0, 0, seat_h), (0.44, 0.42, 0.04), fabric)]
    parts[-1].rotation_euler[2] = yaw
    for sx in (-1, 1):
        for sy in (-1, 1):
            parts.append(cyl(name + "_leg", at(sx * 0.19, sy * 0.18, seat_h / 2 - 0.01),
                             0.014, seat_h - 0.02, wood, verts=12))
    # back: two thin posts, a top rail and three spindles (sub-pixel at 256²)
    for sx in (-1, 1):
        parts.append(cyl(name + "_post", at(sx * 0.19, 0.19, seat_h + 0.23), 0.014, 0.46, wood, verts=12))
    rail = box(name + "_rail", at(0, 0.19, seat_h + 0.43), (0.40, 0.025, 0.06), wood)
    rail.rotation_euler[2] = yaw
    parts.append(rail)
    for k in (-1, 0, 1):
        parts.append(cyl(name + "_spindle", at(k * 0.09, 0.19, seat_h + 0.21), 0.006, 0.38, wood, verts=8))
    return join(name, parts, idx)


def floor_lamp(x, y, metal, shade, idx):
    parts = [cyl("lamp_base", (x, y, 0.015), 0.16, 0.03, metal, verts=24),
             cyl("lamp_pole", (x, y, 0.75), 0.011, 1.45, metal, verts=12)]
    bpy.ops.mesh.primitive_cone_add(vertices=32, radius1=0.24, radius2=0.14, depth=0.26,
                                    end_fill_type="NOTHING", location=(x, y, 1.42))
    sh = bpy.context.active_object
    sh.data.materials.append(shade)
    parts.append(sh)
    o = join("FloorLamp", parts, idx)
    # The shade glows but is not sampled as a light, and there is no bulb:
    # Cycles 3.4 picks one light per bounce, so every extra light adds noise
    # wherever several lights contribute.
    shade.cycles.sample_as_light = False
    return o


# ------------------------------------------------------------------- scene --

def build(outdir):
    for o in list(bpy.data.objects):
        bpy.data.objects.remove(o, do_unlink=True)

    planks = make_image("planks", 512, planks_texel(512), os.path.join(outdir, "planks.png"))
    checker = make_image("checker", 256, checker_texel(256), os.path.join(outdir, "checker.png"))

    m_floor = principled("Floor", 1, image=planks, rough=0.35, spec=0.4)
    m_wall = principled("Wall", 2, color=(0.78, 0.76, 0.70), rough=0.9, spec=0.3)
    m_wood = principled("Wood", 3, color=(0.35, 0.20, 0.10), rough=0.45, spec=0.5)
    m_fabric = principled("Fabric", 4, color=(0.15, 0.35, 0.30), rough=1.0, spec=0.2)
    m_metal = principled("BrushedMetal", 5, color=(0.85, 0.85, 0.82), rough=0.25, metal=1.0)
    m_chrome = principled("Chrome", 6, color=(0.95, 0.93, 0.90), rough=0.05, metal=1.0)
    m_ceramic = principled("RedCeramic", 7, color=(0.60, 0.06, 0.04), rough=0.08, spec=0.6)
    m_shade = principled("LampShade", 8, color=(0.9, 0.85, 0.7), rough=0.8,
                         emission=(1.0, 0.85, 0.6), strength=3.0)
    m_rug = principled("Rug", 9, image=checker, rough=1.0, spec=0.2)
    m_frame = principled("Frame", 10, color=(0.05, 0.05, 0.05), rough=0.3, spec=0.5)

    # Room 5 x 4 x 2.7 m: floor z=0, x in [-2.5, 2.5], y in [-2, 2]. The camera
    # side (y = -2) is open; the back wall (y = 2) has a window.
    bpy.ops.mesh.primitive_plane_add(size=1.0, location=(0, 0, 0))
    floor = bpy.context.active_object
    floor.name = "Floor"
    floor.scale = (5.0, 4.0, 1.0)
    bpy.ops.object.transform_apply(scale=True)
    scale_uv(floor, 1.0)
    for loop in floor.data.uv_layers.active.data:        # planks 0.5 m long, UV 1 = 1.25 m
        loop.uv = (loop.uv[0] * 4.0, loop.uv[1] * 3.2)
    floor.data.materials.append(m_floor)
    floor.pass_index = 1

    h, t = 2.7, 0.1
    walls = [box("wall_left", (-2.5 - t / 2, 0, h / 2), (t, 4.0, h), m_wall),
             box("wall_right", (2.5 + t / 2, 0, h / 2), (t, 4.0, h), m_wall),
             box("ceiling", (0, 0, h + t / 2), (5.2, 4.0, t), m_wall)]
    # back wall with a window opening x in [0.2, 1.6], z in [0.9, 2.1]
    wy = 2.0 + t / 2
    walls += [box("wall_back_l", ((-2.6 + 0.2) / 2, wy, h / 2), (2.8, t, h), m_wall),
              box("wall_back_r", ((1.6 + 2.6) / 2, wy, h / 2), (1.0, t, h), m_wall),
              box("wall_back_b", (0.9, wy, 0.45), (1.4, t, 0.9), m_wall),
              box("wall_back_t", (0.9, wy, (2.1 + h) / 2), (1.4, t, h - 2.1), m_wall)]
    join("Walls", walls, 2)
    # window frame: thin mullions (dark) in the opening
    fr = [box("mullion_v", (0.9, wy, 1.5), (0.04, 0.06, 1.2), m_frame),
          box("mullion_h", (0.9, wy, 1.5), (1.4, 0.06, 0.04), m_frame)]
    join("WindowFrame", fr, 3)

    table(0.0, 0.6, m_wood, 4)
    chair("ChairA", -0.35, -0.05, 0.0 + math.pi, m_wood, m_fabric, 5)
    chair("ChairB", 0.45, -0.05, math.pi + 0.15, m_wood, m_fabric, 6)
    chair("ChairC", 0.95, 0.75, math.pi / 2, m_wood, m_fabric, 7)
    floor_lamp(-1.9, 1.5, m_metal, m_shade, 8)

    # rug under the table (checker image texture)
    bpy.ops.mesh.primitive_plane_add(size=1.0, location=(0.1, 0.4, 0.004))
    rug = bpy.context.active_object
    rug.name = "Rug"
    rug.scale = (2.2, 1.6, 1.0)
    bpy.ops.object.transform_apply(scale=True)
    rug.data.materials.append(m_rug)
    rug.pass_index = 9

    # glossy objects on the table: a chrome sphere and a red ceramic vase
    bpy.ops.mesh.primitive_uv_sphere_add(segments=48, ring_count=24, radius=0.14, location=(-0.3, 0.55, 0.87))
    s = bpy.context.active_object
    s.name = "ChromeBall"
    bpy.ops.object.shade_smooth()
    s.data.materials.append(m_chrome)
    s.pass_index = 10
    bpy.ops.mesh.primitive_cylinder_add(vertices=48, radius=0.08, depth=0.30, location=(0.3, 0.7, 0.88))
    v = bpy.context.active_object
    v.name = "Vase"
    bpy.ops.object.shade_smooth()
    v.data.materials.append(m_ceramic)
    v.pass_index = 11

    # a sideboard against the right wall, and a picture (checker) above it
    box("Sideboard", (2.2, 0.0, 0.4), (0.5, 1.6, 0.8), m_wood).pass_index = 12
    pic = box("Picture", (2.44, 0.0, 1.6), (0.02, 0.9, 0.6), m_rug)
    pic.pass_index = 13

    # lights: a ceiling area light, a sun through the window, a sky
    bpy.ops.object.light_add(type="AREA", location=(0.0, 0.2, h - 0.02))
    a = bpy.context.active_object
    a.name = "CeilingLight"
    a.data.shape = "RECTANGLE"
    a.data.size, a.data.size_y = 1.2, 0.6
    a.data.energy = 150.0
    bpy.ops.object.light_add(type="SUN", location=(0, 4, 4),
                             rotation=(math.radians(-55), 0.0, math.radians(200)))
    sun = bpy.context.active_object
    sun.name = "Sun"
    sun.data.energy = 3.0
    sun.data.angle = math.radians(1.5)
    sun.data.color = (1.0, 0.93, 0.82)

    world = bpy.data.worlds.new("Sky")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.45, 0.62, 0.95, 1.0)
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 1.0
    bpy.context.scene.world = world


VIEWS = {
    # name: (location, look-at, focal length mm)
    "a": ((-1.2, -3.4, 1.45), (0.25, 0.9, 0.55), 26.0),   # from the open side, window behind the table
    "b": ((1.9, -1.3, 0.55), (-0.4, 0.6, 0.35), 24.0),   # low, across the chair legs to the lamp
    "c": ((1.0, -1.1, 1.9), (-0.05, 0.6, 0.7), 30.0),    # down onto the table: chrome, ceramic, rug
}


def camera(view):
    look_at_camera(*VIEWS[view])


def setup_shadow_guide():
    """The sun's direct light on white diffuse surfaces, one sample per pixel:
    > 0 where the sun reaches the surface, 0 in its shadow. Every other light
    is off (the ceiling light, the sky, the lamp shade's emission, which the
    material override removes), and no light bounces: what is left is a
    visibility guide, 1/samples of the cost of the render (docs/AOV.md)."""
    sc = bpy.context.scene
    sc.cycles.samples = 1
    sc.cycles.max_bounces = 0
    bpy.data.objects["CeilingLight"].hide_render = True
    # a hard shadow: its edge is the middle of the render's 1.5-degree
    # penumbra, the same in every pixel (one sample of a soft shadow would
    # scatter lit and unlit pixels over the penumbra)
    bpy.data.objects["Sun"].data.angle = 0.0
    sc.world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
    white = bpy.data.materials.new("GuideWhite")
    white.use_nodes = True
    white.node_tree.nodes.clear()
    out = white.node_tree.nodes.new("ShaderNodeOutputMaterial")
    bsdf = white.node_tree.nodes.new("ShaderNodeBsdfDiffuse")
    bsdf.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    white.node_tree.links.new(bsdf.outputs["BSDF"], out.inputs["Surface"])
    vl = sc.view_layers[0]
    vl.name = "ShadowGuide"   # dcm's blender preset takes its Combined as the shadow guide
    vl.material_override = white
    for attr in dir(vl):
        if attr.startswith("use_pass_") and attr != "use_pass_combined":
            try:
                setattr(vl, attr, False)
            except (AttributeError, TypeError):
                pass


def setup_highlight_guide():
    """Where the lights are seen in glossy surfaces: the direct glossy light
    (GlossDir) of the scene's own materials, so their own roughness decides
    how sharp a highlight is; no bounces, so it costs a few samples of direct
    light only (docs/AOV.md)."""
    sc = bpy.context.scene
    sc.cycles.max_bounces = 0
    vl = sc.view_layers[0]
    vl.name = "HighlightGuide"   # dcm's blender preset takes its GlossDir as the highlight guide
    for attr in dir(vl):
        if attr.startswith("use_pass_") and attr not in ("use_pass_combined", "use_pass_glossy_direct"):
            try:
                setattr(vl, attr, False)
            except (AttributeError, TypeError):
                pass
    vl.use_pass_glossy_direct = True


def main():
    args = parse_args()
    outdir = os.path.dirname(os.path.abspath(args.out))
    os.makedirs(outdir, exist_ok=True)
    build(outdir)
    camera(args.view)
    setup_render(args)
    if args.shadow_guide:
        setup_shadow_guide()
    if args.highlight_guide:
        setup_highlight_guide()
    if args.save_blend:
        bpy.ops.wm.save_as_mainfile(filepath=os.path.abspath(args.save_blend))
    bpy.ops.render.render(write_still=True)
    print("wrote", os.path.abspath(args.out))


main()
