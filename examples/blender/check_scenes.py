# The Cycles check set: four scenes that differ from the furnished room of
# make_and_render.py (the scene every dcm default was tuned on) in content,
# lights and materials, built procedurally and rendered into one multilayer
# EXR with the room's passes and settings (cycles_common.setup_render), so
# that `dcm reconstruct --preset blender` reads them as it reads the room.
#
#   blender -b --factory-startup --python check_scenes.py -- \
#       --scene glossy|spines|mirror|outdoor|stage|shelf|street --out X.exr [--res 256] \
#       [--samples 64] [--seed 1] [--threads 2] [--save-blend X.blend]
#
#  - glossy:  a large floor of procedural tiles under a clear coat, a monkey,
#             a gold torus, a glass ball and a striped block; an area light
#             and a dim environment.
#  - spines:  a potted cactus with about 400 thin spines and a tuft of
#             grass blades; an area light and a small point light (hard,
#             thin shadows).
#  - mirror:  a mirror ball and a standing mirror in a room of checker,
#             brick and striped walls; a spot light and a faint environment.
#  - outdoor: a sun and a gradient sky over a textured lawn with a paved
#             path, three buildings and five trees casting long shadows.
#
# Three more, held out from 2026-12-06 (key CC2 of docs/TUNING.md):
#  - stage:   white and grey objects on a satin floor before a wall, lit by a
#             red, a green and a blue area light: coloured shadows whose
#             colours change where their luminance barely does.
#  - shelf:   a bookshelf of thin books of many colours (each its own
#             object and material), a vase and a lamp shade in a corner of
#             two walls, lit by a low sun from the open side, a blue sky and
#             a small warm lamp.
#  - street:  a sunlit street: a striped road, a picket fence of thin
#             slats, lamp posts, coloured boxes and a glass-fronted
#             building under a clear sky (direct light: clean at 64 spp).
#
# Every texture is a shader node (no image files), so the saved .blend is
# self-contained. These scenes are the check set of docs/TUNING.md (key CC):
# nothing may be tuned on them.
import argparse
import math
import os
import sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from cycles_common import box, cyl, hash01, join, look_at_camera, principled, setup_render  # noqa: E402

SCENES = ("glossy", "spines", "mirror", "outdoor", "stage", "shelf", "street")


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    ap = argparse.ArgumentParser(prog="check_scenes.py")
    ap.add_argument("--scene", required=True, choices=SCENES, help="which check scene")
    ap.add_argument("--out", required=True, help="multilayer EXR to write")
    ap.add_argument("--res", type=int, default=256, help="square resolution")
    ap.add_argument("--samples", type=int, default=64, help="Cycles samples per pixel")
    ap.add_argument("--seed", type=int, default=1, help="Cycles seed")
    ap.add_argument("--threads", type=int, default=2, help="render threads (0: all)")
    ap.add_argument("--save-blend", default="", help="also save the scene as .blend")
    ap.add_argument("--pixel-filter", default="GAUSSIAN:0.01",
                    help="TYPE:WIDTH (Blender's default: BLACKMAN_HARRIS:1.5)")
    return ap.parse_args(argv)


# ------------------------------------------------------ procedural textures --

def uv_vector(nt, scale):
    """The mesh's UV coordinates scaled by scale (a float or an (x, y, z) triple)."""
    tc = nt.nodes.new("ShaderNodeTexCoord")
    mp = nt.nodes.new("ShaderNodeMapping")
    mp.inputs["Scale"].default_value = scale if isinstance(scale, tuple) else (scale, scale, scale)
    nt.links.new(tc.outputs["UV"], mp.inputs["Vector"])
    return mp.outputs["Vector"]


def textured(name, index, color, rough=0.5, metal=0.0, spec=0.5, clearcoat=0.0, clearcoat_rough=0.03):
    """A Principled material whose base colour is the socket color(node_tree) returns."""
    m = principled(name, index, rough=rough, metal=metal, spec=spec)
    nt = m.node_tree
    bsdf = nt.nodes["Principled BSDF"]
    nt.links.new(color(nt), bsdf.inputs["Base Color"])
    bsdf.inputs["Clearcoat"].default_value = clearcoat
    bsdf.inputs["Clearcoat Roughness"].default_value = clearcoat_rough
    return m


def brick(scale, c1, c2, mortar, mortar_size=0.02, bias=0.0, row_height=0.25, brick_width=0.5):
    def build(nt):
        b = nt.nodes.new("ShaderNodeTexBrick")
        b.inputs["Color1"].default_value = (*c1, 1.0)
        b.inputs["Color2"].default_value = (*c2, 1.0)
        b.inputs["Mortar"].default_value = (*mortar, 1.0)
        b.inputs["Scale"].default_value = 1.0
        b.inputs["Mortar Size"].default_value = mortar_size
        b.inputs["Bias"].default_value = bias
        b.inputs["Brick Width"].default_value = brick_width
        b.inputs["Row Height"].default_value = row_height
        nt.links.new(uv_vector(nt, scale), b.inputs["Vector"])
        return b.outputs["Color"]
    return build


def checker(scale, c1, c2):
    def build(nt):
        c = nt.nodes.new("ShaderNodeTexChecker")
        c.inputs["Color1"].default_value = (*c1, 1.0)
        c.inputs["Color2"].default_value = (*c2, 1.0)
        c.inputs["Scale"].default_value = 1.0
        nt.links.new(uv_vector(nt, scale), c.inputs["Vector"])
        return c.outputs["Color"]
    return build


def ramp(nt, fac, stops):
    """A colour ramp on the socket fac with stops [(position, (r, g, b)), ...]."""
    r = nt.nodes.new("ShaderNodeValToRGB")
    els = r.color_ramp.elements
    while len(els) < len(stops):
        els.new(0.5)
    for e, (pos, col) in zip(els, stops):
        e.position = pos
        e.color = (*col, 1.0)
    nt.links.new(fac, r.inputs["Fac"])
    return r.outputs["Color"]


def noise_ramp(scale, stops, detail=4.0):
    """Fractal noise through a colour ramp: sand, grass, mottled stone."""
    def build(nt):
        n = nt.nodes.new("ShaderNodeTexNoise")
        n.inputs["Scale"].default_value = 1.0
        n.inputs["Detail"].default_value = detail
        nt.links.new(uv_vector(nt, scale), n.inputs["Vector"])
        return ramp(nt, n.outputs["Fac"], stops)
    return build


def stripes(scale, stops):
    """Wave bands along the texture's x through a colour ramp (20 / 2 pi bands per unit of scaled x)."""
    def build(nt):
        w = nt.nodes.new("ShaderNodeTexWave")
        w.bands_direction = "X"
        w.inputs["Scale"].default_value = 1.0
        w.inputs["Distortion"].default_value = 0.0
        nt.links.new(uv_vector(nt, scale), w.inputs["Vector"])
        return ramp(nt, w.outputs["Fac"], stops)
    return build


def tiles_with_veins(scale):
    """Cream and grey floor tiles, each mottled by noise (the glossy floor)."""
    def build(nt):
        tiles = brick(scale, (0.50, 0.46, 0.40), (0.26, 0.28, 0.30), (0.06, 0.05, 0.05),
                      mortar_size=0.015, row_height=0.5, brick_width=0.5)(nt)
        veins = noise_ramp(scale * 3.0, [(0.35, (0.55, 0.55, 0.55)), (0.65, (1.0, 1.0, 1.0))])(nt)
        mix = nt.nodes.new("ShaderNodeMixRGB")
        mix.blend_type = "MULTIPLY"
        mix.inputs["Fac"].default_value = 1.0
        nt.links.new(tiles, mix.inputs["Color1"])
        nt.links.new(veins, mix.inputs["Color2"])
        return mix.outputs["Color"]
    return build


# ---------------------------------------------------------------- geometry --

def clear_scene():
    for o in list(bpy.data.objects):
        bpy.data.objects.remove(o, do_unlink=True)


def plane(name, loc, size, mat, index, uv_scale=1.0, rot=(0, 0, 0)):
    """A rectangle size = (sx, sy) with UVs 0..uv_scale across it."""
    bpy.ops.mesh.primitive_plane_add(size=1.0, location=loc, rotation=rot)
    o = bpy.context.active_object
    o.name = name
    o.scale = (size[0], size[1], 1.0)
    bpy.ops.object.transform_apply(scale=True)
    for loop in o.data.uv_layers.active.data:
        loop.uv = (loop.uv[0] * uv_scale * size[0] / max(size), loop.uv[1] * uv_scale * size[1] / max(size))
    o.data.materials.append(mat)
    o.pass_index = index
    return o


def smooth_object(o, mat, index, name):
    o.name = name
    bpy.ops.object.shade_smooth()
    o.data.materials.append(mat)
    o.pass_index = index
    return o


def mesh_object(name, verts, faces, mat, index):
    """One object from raw vertices and faces (thousands of spines or blades in one ID)."""
    me = bpy.data.meshes.new(name)
    me.from_pydata(verts, [], faces)
    me.update()
    o = bpy.data.objects.new(name, me)
    bpy.context.scene.collection.objects.link(o)
    me.materials.append(mat)
    o.pass_index = index
    return o


def add_cone(verts, faces, base, direction, length, radius):
    """A three-sided open cone from base along the unit vector direction."""
    d = direction
    a = (1.0, 0.0, 0.0) if abs(d[0]) < 0.9 else (0.0, 1.0, 0.0)
    u = (d[1] * a[2] - d[2] * a[1], d[2] * a[0] - d[0] * a[2], d[0] * a[1] - d[1] * a[0])
    n = math.sqrt(sum(c * c for c in u))
    u = tuple(c / n for c in u)
    v = (d[1] * u[2] - d[2] * u[1], d[2] * u[0] - d[0] * u[2], d[0] * u[1] - d[1] * u[0])
    i0 = len(verts)
    for k in range(3):
        t = 2.0 * math.pi * k / 3.0
        verts.append(tuple(base[j] + radius * (math.cos(t) * u[j] + math.sin(t) * v[j]) for j in range(3)))
    verts.append(tuple(base[j] + length * d[j] for j in range(3)))
    for k in range(3):
        faces.append((i0 + k, i0 + (k + 1) % 3, i0 + 3))


def world(color, strength):
    w = bpy.data.worlds.new("World")
    w.use_nodes = True
    bg = w.node_tree.nodes["Background"]
    bg.inputs["Color"].default_value = (*color, 1.0)
    bg.inputs["Strength"].default_value = strength
    bpy.context.scene.world = w
    return w


def gradient_sky(stops, strength):
    """A sky graded on the view direction's z (the world's Generated coordinate) through stops."""
    w = world((0.0, 0.0, 0.0), 1.0)
    nt = w.node_tree
    tc = nt.nodes.new("ShaderNodeTexCoord")
    sep = nt.nodes.new("ShaderNodeSeparateXYZ")
    nt.links.new(tc.outputs["Generated"], sep.inputs["Vector"])
    nt.links.new(ramp(nt, sep.outputs["Z"], stops), nt.nodes["Background"].inputs["Color"])
    nt.nodes["Background"].inputs["Strength"].default_value = strength


def light(kind, name, loc, energy, rot=(0, 0, 0), **data):
    bpy.ops.object.light_add(type=kind, location=loc, rotation=rot)
    o = bpy.context.active_object
    o.name = name
    o.data.energy = energy
    for k, val in data.items():
        setattr(o.data, k, val)
    return o


def aim(obj, target):
    """Points a light's -Z axis at target."""
    d = [target[i] - obj.location[i] for i in range(3)]
    yaw = math.atan2(d[1], d[0]) - math.pi / 2
    pitch = math.atan2(math.hypot(d[0], d[1]), -d[2])
    obj.rotation_euler = (pitch, 0.0, yaw)


# ------------------------------------------------------------------ scenes --

def build_glossy():
    m_floor = textured("GlossyTiles", 1, tiles_with_veins(8.0), rough=0.4, spec=0.5,
                       clearcoat=1.0, clearcoat_rough=0.02)
    m_orange = principled("OrangePlastic", 2, color=(0.80, 0.25, 0.04), rough=0.35, spec=0.5)
    m_gold = principled("Gold", 3, color=(0.95, 0.70, 0.30), rough=0.2, metal=1.0)
    m_glass = principled("Glass", 4, color=(0.95, 0.97, 1.0), rough=0.0)
    m_glass.node_tree.nodes["Principled BSDF"].inputs["Transmission"].default_value = 1.0
    m_glass.node_tree.nodes["Principled BSDF"].inputs["IOR"].default_value = 1.45
    m_stripes = textured("BlueStripes", 5, stripes(3.0, [(0.45, (0.05, 0.10, 0.40)), (0.55, (0.85, 0.85, 0.80))]),
                         rough=0.5)

    # a 16 m square floor of 1 m tiles
    plane("Floor", (0, 2.0, 0), (16.0, 16.0), m_floor, 1)

    bpy.ops.mesh.primitive_monkey_add(size=0.9, location=(-0.9, 0.4, 0.42), rotation=(math.radians(-20), 0, math.radians(-25)))
    monkey = bpy.context.active_object
    mod = monkey.modifiers.new("subsurf", "SUBSURF")
    mod.levels = mod.render_levels = 2
    smooth_object(monkey, m_orange, 2, "Monkey")

    bpy.ops.mesh.primitive_torus_add(major_radius=0.38, minor_radius=0.09, location=(0.55, 1.0, 0.36),
                                     rotation=(math.radians(70), 0, math.radians(30)))
    smooth_object(bpy.context.active_object, m_gold, 3, "GoldTorus")

    bpy.ops.mesh.primitive_uv_sphere_add(segments=48, ring_count=24, radius=0.3, location=(0.35, -0.35, 0.3))
    smooth_object(bpy.context.active_object, m_glass, 4, "GlassBall")

    blk = box("StripedBlock", (1.6, 2.2, 0.6), (0.5, 0.5, 1.2), m_stripes)
    blk.rotation_euler[2] = math.radians(25)
    blk.pass_index = 5

    a = light("AREA", "AreaLight", (2.2, -1.4, 3.0), 250.0, shape="SQUARE", size=1.2)
    aim(a, (0.0, 0.8, 0.0))
    world((0.030, 0.035, 0.050), 1.0)
    look_at_camera((-0.3, -3.0, 1.25), (0.25, 0.9, 0.3), 34.0)


def build_spines():
    m_sand = textured("Sand", 1, noise_ramp(12.0, [(0.3, (0.55, 0.45, 0.32)), (0.7, (0.78, 0.68, 0.50))]), rough=0.95,
                      spec=0.3)
    m_pot = textured("Terracotta", 2, stripes(2.0, [(0.4, (0.55, 0.22, 0.10)), (0.6, (0.65, 0.30, 0.15))]),
                     rough=0.8, spec=0.3)
    m_cactus = textured("CactusSkin", 3, stripes((2.0 * math.pi * 12 / 20.0, 1.0, 1.0), [(0.3, (0.08, 0.25, 0.08)), (0.7, (0.16, 0.42, 0.14))]),
                        rough=0.6, spec=0.4)
    m_spine = principled("Spine", 4, color=(0.92, 0.86, 0.62), rough=0.4, spec=0.5)
    m_grass = principled("Grass", 5, color=(0.35, 0.55, 0.12), rough=0.7, spec=0.4)

    plane("Ground", (0, 0, 0), (6.0, 6.0), m_sand, 1)
    cyl("Pot", (0, 0, 0.175), 0.26, 0.35, m_pot, verts=48).pass_index = 2

    # the body: an ellipsoid on the pot, 12 ribs from the stripes across its UVs
    c, ra, rb = (0.0, 0.0, 0.35 + 0.40), 0.2, 0.48
    bpy.ops.mesh.primitive_uv_sphere_add(segments=48, ring_count=32, radius=1.0, location=c)
    body = bpy.context.active_object
    body.scale = (ra, ra, rb)
    bpy.ops.object.transform_apply(scale=True)
    smooth_object(body, m_cactus, 3, "Cactus")

    # areoles on 12 ribs x 11 rows, three spines each, jittered
    verts, faces = [], []
    for i in range(12):
        for j in range(11):
            lon = 2.0 * math.pi * (i + 0.5 * (j % 2)) / 12.0
            lat = math.radians(-55.0 + 125.0 * j / 10.0)
            p = (c[0] + ra * math.cos(lat) * math.cos(lon), c[1] + ra * math.cos(lat) * math.sin(lon),
                 c[2] + rb * math.sin(lat))
            nrm = (math.cos(lat) * math.cos(lon) / ra, math.cos(lat) * math.sin(lon) / ra, math.sin(lat) / rb)
            for k in range(3):
                d = [nrm[q] + 2.0 * (hash01(i, j, 3 * k + q) - 0.5) * 3.0 for q in range(3)]
                n = math.sqrt(sum(x * x for x in d))
                d = [x / n for x in d]
                add_cone(verts, faces, p, d, 0.05 + 0.05 * hash01(i, j, 10 + k), 0.0025)
    mesh_object("Spines", verts, faces, m_spine, 4)

    # a tuft of grass blades beside the pot
    verts, faces = [], []
    for k in range(160):
        r = 0.35 + 0.35 * hash01(k, 1)
        t = math.radians(-150 + 80 * hash01(k, 2))
        x, y = 0.2 + r * math.cos(t), -0.1 + r * math.sin(t)
        h = 0.12 + 0.22 * hash01(k, 3)
        yaw = 2.0 * math.pi * hash01(k, 4)
        lean = 0.4 * hash01(k, 5)
        wx, wy = 0.006 * math.cos(yaw), 0.006 * math.sin(yaw)
        lx, ly = lean * h * math.cos(yaw + 1.3), lean * h * math.sin(yaw + 1.3)
        i0 = len(verts)
        verts += [(x - wx, y - wy, 0.0), (x + wx, y + wy, 0.0),
                  (x + 0.6 * wx + 0.4 * lx, y + 0.6 * wy + 0.4 * ly, 0.55 * h),
                  (x - 0.6 * wx + 0.4 * lx, y - 0.6 * wy + 0.4 * ly, 0.55 * h),
                  (x + lx, y + ly, h)]
        faces += [(i0, i0 + 1, i0 + 2, i0 + 3), (i0 + 3, i0 + 2, i0 + 4)]
    mesh_object("GrassTuft", verts, faces, m_grass, 5)

    a = light("AREA", "AreaLight", (-1.6, -1.4, 2.2), 160.0, shape="SQUARE", size=1.0)
    aim(a, (0.0, 0.0, 0.6))
    light("POINT", "PointLight", (1.4, 0.6, 1.6), 90.0, shadow_soft_size=0.02, color=(1.0, 0.88, 0.7))
    world((0.025, 0.022, 0.020), 1.0)
    look_at_camera((0.35, -2.3, 1.05), (0.05, 0.0, 0.6), 40.0)


def build_mirror():
    m_floor = textured("CheckerFloor", 1, checker(10.0, (0.80, 0.78, 0.72), (0.12, 0.12, 0.14)), rough=0.7, spec=0.4)
    m_brick = textured("BrickWall", 2, brick(6.0, (0.55, 0.18, 0.10), (0.42, 0.15, 0.09), (0.70, 0.68, 0.62),
                                                mortar_size=0.02), rough=0.9, spec=0.3)
    m_stripe = textured("StripedWall", 3, stripes(4.0, [(0.35, (0.15, 0.35, 0.55)), (0.65, (0.85, 0.80, 0.55))]),
                        rough=0.8, spec=0.3)
    m_ceiling = principled("Ceiling", 4, color=(0.75, 0.75, 0.72), rough=0.9, spec=0.3)
    m_mirror = principled("Mirror", 5, color=(0.92, 0.92, 0.92), rough=0.0, metal=1.0)
    m_frame = principled("MirrorFrame", 6, color=(0.06, 0.05, 0.04), rough=0.4, spec=0.5)
    m_green = principled("GreenPaint", 7, color=(0.10, 0.55, 0.15), rough=0.4, spec=0.5)
    m_yellow = principled("YellowPaint", 8, color=(0.85, 0.70, 0.05), rough=0.5, spec=0.5)
    m_purple = principled("PurplePaint", 9, color=(0.40, 0.10, 0.55), rough=0.3, spec=0.5)

    # a closed 6 x 6 x 3 m room (the camera inside), so the mirrors see walls everywhere
    h = 3.0
    plane("Floor", (0, 0, 0), (6.0, 6.0), m_floor, 1)
    plane("Ceiling", (0, 0, h), (6.0, 6.0), m_ceiling, 4, rot=(math.pi, 0, 0))
    plane("BackWall", (0, 3.0, h / 2), (6.0, h), m_stripe, 3, uv_scale=1.0, rot=(math.pi / 2, 0, 0))
    plane("LeftWall", (-3.0, 0, h / 2), (6.0, h), m_brick, 2, rot=(math.pi / 2, 0, math.pi / 2))
    plane("RightWall", (3.0, 0, h / 2), (6.0, h), m_brick, 10, rot=(math.pi / 2, 0, -math.pi / 2))
    plane("FrontWall", (0, -3.0, h / 2), (6.0, h), m_stripe, 12, rot=(-math.pi / 2, 0, 0))

    bpy.ops.mesh.primitive_uv_sphere_add(segments=64, ring_count=32, radius=0.55, location=(0.5, 0.6, 0.55))
    smooth_object(bpy.context.active_object, m_mirror, 5, "MirrorBall")

    # a standing mirror at the back left, turned to reflect the right wall and the objects
    yaw = math.radians(60)
    ctr = (-1.3, 1.6, 1.05)
    glass = plane("StandingMirror", ctr, (1.1, 1.7), m_mirror, 6, rot=(math.pi / 2, 0, yaw))
    behind = (-math.sin(yaw), math.cos(yaw))    # the plane faces (sin, -cos)
    fr = box("MirrorFrame", (ctr[0] + 0.03 * behind[0], ctr[1] + 0.03 * behind[1], ctr[2]),
             (1.2, 0.04, 1.8), m_frame)
    fr.rotation_euler[2] = yaw
    fr.pass_index = 7
    glass.location = (ctr[0] - 0.005 * behind[0], ctr[1] - 0.005 * behind[1], ctr[2])

    bpy.ops.mesh.primitive_cone_add(vertices=32, radius1=0.3, depth=0.8, location=(-0.6, 0.2, 0.4))
    smooth_object(bpy.context.active_object, m_green, 8, "GreenCone")
    box("YellowCube", (1.6, -0.4, 0.25), (0.5, 0.5, 0.5), m_yellow).pass_index = 9
    bpy.data.objects["YellowCube"].rotation_euler[2] = math.radians(20)
    cyl("PurpleColumn", (1.9, 1.9, 0.6), 0.2, 1.2, m_purple, verts=32).pass_index = 11

    s = light("SPOT", "SpotLight", (-1.2, -2.2, 2.8), 1500.0, spot_size=math.radians(55), spot_blend=0.15,
              shadow_soft_size=0.05)
    aim(s, (0.3, 0.8, 0.4))
    world((0.12, 0.12, 0.14), 1.0)
    look_at_camera((1.3, -2.8, 1.4), (-0.1, 1.0, 0.75), 28.0)


def build_outdoor():
    m_lawn = textured("Lawn", 1, noise_ramp(40.0, [(0.35, (0.10, 0.22, 0.04)), (0.5, (0.20, 0.35, 0.08)),
                                                  (0.7, (0.35, 0.32, 0.15))]), rough=0.95, spec=0.2)
    m_path = textured("Paving", 2, brick(2.0, (0.55, 0.52, 0.48), (0.45, 0.43, 0.40), (0.20, 0.19, 0.18),
                                          mortar_size=0.04, row_height=0.5, brick_width=1.0), rough=0.8, spec=0.3)
    m_facade = textured("Facade", 3, brick(8.0, (0.72, 0.62, 0.48), (0.66, 0.56, 0.44), (0.30, 0.28, 0.26),
                                            mortar_size=0.03), rough=0.85, spec=0.3)
    m_white = principled("WhiteRender", 4, color=(0.78, 0.78, 0.75), rough=0.9, spec=0.3)
    m_roof = principled("Roof", 5, color=(0.18, 0.10, 0.08), rough=0.6, spec=0.4)
    m_bark = principled("Bark", 6, color=(0.22, 0.14, 0.08), rough=0.9, spec=0.2)
    m_leaves = textured("Leaves", 7, noise_ramp(6.0, [(0.4, (0.05, 0.20, 0.04)), (0.6, (0.12, 0.35, 0.06))]),
                        rough=0.8, spec=0.3)

    plane("Ground", (0, 10.0, 0), (80.0, 80.0), m_lawn, 1)
    plane("Path", (0.5, 6.0, 0.01), (2.0, 30.0), m_path, 2, uv_scale=30.0)   # UV in metres

    def building(name, loc, dims, facade, idx):
        b = box(name, (loc[0], loc[1], dims[2] / 2), dims, facade)
        r = box(name + "_roof", (loc[0], loc[1], dims[2] + 0.1), (dims[0] + 0.3, dims[1] + 0.3, 0.2), m_roof)
        return join(name, [b, r], idx)

    building("HouseA", (-5.0, 10.0), (4.0, 3.0, 4.5), m_facade, 3)
    building("HouseB", (5.5, 14.0), (5.0, 3.5, 7.0), m_white, 4)
    building("Shed", (3.2, 4.5), (1.6, 1.4, 2.0), m_facade, 5)

    for k, (x, y, s) in enumerate([(-2.0, 3.0, 1.0), (-3.2, 6.5, 1.2), (2.2, 8.0, 0.9), (-1.0, 14.0, 1.3),
                                   (8.0, 7.0, 1.1)]):
        trunk = cyl("trunk", (x, y, 0.8 * s), 0.12 * s, 1.6 * s, m_bark, verts=12)
        bpy.ops.mesh.primitive_ico_sphere_add(subdivisions=2, radius=0.9 * s, location=(x, y, 2.2 * s))
        crown = bpy.context.active_object
        crown.data.materials.append(m_leaves)
        join("Tree%d" % (k + 1), [trunk, crown], 6 + k)

    sun = light("SUN", "Sun", (0, 0, 10), 4.0, angle=math.radians(0.8), color=(1.0, 0.95, 0.86))
    sun.rotation_euler = (math.radians(65), 0.0, math.radians(-100))   # 25 degrees high, from the left

    gradient_sky([(0.0, (0.80, 0.86, 0.95)), (0.35, (0.35, 0.52, 0.88)), (1.0, (0.18, 0.36, 0.80))], 0.8)
    look_at_camera((-4.0, -9.0, 1.7), (1.0, 6.0, 2.0), 30.0)


def build_stage():
    m_floor = principled("SatinFloor", 1, color=(0.60, 0.60, 0.58), rough=0.25, spec=0.5)
    m_wall = textured("Wall", 2, noise_ramp(3.0, [(0.4, (0.70, 0.70, 0.68)), (0.6, (0.80, 0.80, 0.78))]),
                      rough=0.9, spec=0.3)
    m_white = principled("WhitePlaster", 3, color=(0.85, 0.85, 0.85), rough=0.6, spec=0.4)
    m_grey = textured("GreyStripes", 4, stripes(4.0, [(0.45, (0.25, 0.25, 0.25)), (0.55, (0.65, 0.65, 0.65))]),
                      rough=0.5, spec=0.5)
    m_steel = principled("Steel", 5, color=(0.7, 0.7, 0.72), rough=0.15, metal=1.0)

    plane("Floor", (0, 1.0, 0), (10.0, 10.0), m_floor, 1)
    plane("Wall", (0, 3.0, 2.0), (10.0, 4.0), m_wall, 2, rot=(math.pi / 2, 0, 0))
    bpy.ops.mesh.primitive_uv_sphere_add(segments=64, ring_count=32, radius=0.45, location=(-0.7, 1.2, 0.45))
    smooth_object(bpy.context.active_object, m_white, 3, "Sphere")
    c = cyl("StripedColumn", (0.6, 1.6, 0.6), 0.25, 1.2, m_grey, verts=48)
    c.pass_index = 4
    bpy.ops.object.shade_smooth()
    bpy.ops.mesh.primitive_cone_add(vertices=48, radius1=0.35, depth=0.7, location=(0.1, 0.4, 0.35))
    smooth_object(bpy.context.active_object, m_white, 6, "Cone")
    pole = cyl("Pole", (-1.6, 2.0, 0.9), 0.025, 1.8, m_steel, verts=16)
    pole.pass_index = 5
    for name, loc, col in (("RedLight", (-2.5, -0.5, 2.2), (1.0, 0.08, 0.05)),
                           ("GreenLight", (0.2, -1.8, 2.6), (0.08, 1.0, 0.10)),
                           ("BlueLight", (2.6, -0.3, 2.0), (0.08, 0.15, 1.0))):
        a = light("AREA", name, loc, 60.0, shape="SQUARE", size=0.5, color=col)
        aim(a, (0.0, 1.2, 0.4))
    world((0.02, 0.02, 0.02), 1.0)
    look_at_camera((0.2, -3.2, 1.5), (0.0, 1.2, 0.55), 32.0)


def build_shelf():
    m_wood = textured("Wood", 1, stripes((1.0, 12.0, 1.0), [(0.4, (0.30, 0.17, 0.08)), (0.6, (0.42, 0.25, 0.12))]),
                      rough=0.6, spec=0.4)
    m_wall = principled("WallPaint", 2, color=(0.75, 0.72, 0.66), rough=0.9, spec=0.3)
    m_floor = textured("FloorBoards", 3, brick(4.0, (0.45, 0.30, 0.18), (0.38, 0.25, 0.15), (0.10, 0.07, 0.05),
                                                mortar_size=0.01, row_height=0.125, brick_width=1.0), rough=0.5, spec=0.4)
    m_vase = principled("Ceramic", 4, color=(0.10, 0.30, 0.60), rough=0.1, spec=0.6)
    m_shade = principled("LampShade", 5, color=(0.90, 0.85, 0.70), rough=0.9, spec=0.2)

    plane("Floor", (0, 0, 0), (8.0, 8.0), m_floor, 3)
    plane("BackWall", (0, 1.0, 1.5), (8.0, 3.0), m_wall, 2, rot=(math.pi / 2, 0, 0))
    plane("SideWall", (-2.2, -1.0, 1.5), (4.0, 3.0), m_wall, 2, rot=(math.pi / 2, 0, math.pi / 2))
    # the shelf: two sides and four boards
    parts = [box("side_l", (-1.0, 0.8, 1.0), (0.04, 0.35, 2.0), m_wood),
             box("side_r", (1.0, 0.8, 1.0), (0.04, 0.35, 2.0), m_wood)]
    for k, z in enumerate((0.05, 0.6, 1.15, 1.7)):
        parts.append(box("board%d" % k, (0.0, 0.8, z), (2.0, 0.35, 0.03), m_wood))
    join("Shelf", parts, 1)
    # books of many colours on three boards, each its own object and material
    idx = 10
    for row, z in enumerate((0.065, 0.615, 1.165)):
        x = -0.96
        k = 0
        while x < 0.9:
            w = 0.02 + 0.03 * hash01(row * 101 + k)
            h = 0.32 + 0.18 * hash01(row * 211 + k + 7)
            hue = hash01(row * 307 + k + 13)
            col = (0.15 + 0.7 * abs(math.sin(6.28 * hue)), 0.15 + 0.6 * abs(math.sin(6.28 * hue + 2.1)),
                   0.15 + 0.6 * abs(math.sin(6.28 * hue + 4.2)))
            m = principled("Book%d" % idx, idx, color=col, rough=0.5, spec=0.4)
            b = box("Book%d" % idx, (x + w / 2, 0.78, z + h / 2), (w, 0.25, h), m)
            b.rotation_euler[1] = math.radians(6.0 * (hash01(idx) - 0.5)) if hash01(idx + 5) > 0.7 else 0.0
            b.pass_index = idx
            x += w + 0.004
            k += 1
            idx += 1
    bpy.ops.mesh.primitive_uv_sphere_add(segments=48, ring_count=24, radius=0.12, location=(0.6, 0.8, 1.85))
    vase = bpy.context.active_object
    vase.scale = (1.0, 1.0, 1.5)
    smooth_object(vase, m_vase, 4, "Vase")
    bpy.ops.mesh.primitive_cone_add(vertices=48, radius1=0.28, radius2=0.16, depth=0.3, location=(1.5, 0.2, 1.3))
    smooth_object(bpy.context.active_object, m_shade, 5, "LampShade")
    cyl("LampStand", (1.5, 0.2, 0.6), 0.02, 1.2, m_wood, verts=12).pass_index = 6
    light("POINT", "Lamp", (1.5, 0.2, 1.28), 25.0, shadow_soft_size=0.05, color=(1.0, 0.8, 0.55))
    sun = light("SUN", "Sun", (0, 0, 5), 3.0, angle=math.radians(1.0), color=(1.0, 0.92, 0.80))
    sun.rotation_euler = (math.radians(70), 0.0, math.radians(-60))
    world((0.35, 0.45, 0.65), 0.6)
    look_at_camera((0.3, -1.3, 1.2), (-0.05, 0.8, 0.95), 30.0)


def build_street():
    m_road = textured("Asphalt", 1, noise_ramp(30.0, [(0.4, (0.10, 0.10, 0.11)), (0.6, (0.16, 0.16, 0.17))]),
                      rough=0.85, spec=0.3)
    m_line = principled("RoadLine", 2, color=(0.85, 0.80, 0.30), rough=0.7, spec=0.3)
    m_walk = textured("Sidewalk", 3, checker(12.0, (0.55, 0.53, 0.50), (0.45, 0.44, 0.42)), rough=0.8, spec=0.3)
    m_fence = principled("WhitePaint", 4, color=(0.85, 0.85, 0.82), rough=0.6, spec=0.4)
    m_post = principled("DarkMetal", 5, color=(0.08, 0.08, 0.09), rough=0.35, metal=1.0)
    m_wall = textured("Stucco", 6, noise_ramp(15.0, [(0.4, (0.70, 0.55, 0.40)), (0.6, (0.78, 0.62, 0.46))]),
                      rough=0.9, spec=0.3)
    m_glass = principled("Window", 7, color=(0.10, 0.14, 0.18), rough=0.05, spec=0.9)

    plane("Road", (0, 10.0, 0), (8.0, 60.0), m_road, 1)
    for k in range(12):
        plane("Line%d" % k, (0, 1.0 + 3.0 * k, 0.005), (0.15, 1.5), m_line, 2)
    plane("Sidewalk", (6.0, 10.0, 0.05), (4.0, 60.0), m_walk, 3, uv_scale=15.0)
    plane("Verge", (-10.0, 10.0, 0.0), (12.0, 60.0), m_walk, 3, uv_scale=15.0)
    # a picket fence of thin slats along the far side of the sidewalk
    slats = []
    for k in range(70):
        slats.append(box("slat", (7.8, -2.0 + 0.28 * k, 0.55), (0.04, 0.09, 1.0), m_fence))
    slats.append(box("rail", (7.78, 7.7, 0.8), (0.03, 19.6, 0.06), m_fence))
    join("Fence", slats, 4)
    for k in range(4):
        post = cyl("Post%d" % k, (4.4, 1.0 + 6.0 * k, 2.0), 0.05, 4.0, m_post, verts=12)
        arm = box("Arm%d" % k, (4.0, 1.0 + 6.0 * k, 3.95), (0.8, 0.06, 0.06), m_post)
        join("LampPost%d" % k, [post, arm], 5 + k)
    for k, (x, y, col) in enumerate([(-2.0, 3.0, (0.70, 0.08, 0.06)), (2.0, 7.0, (0.05, 0.25, 0.65)),
                                     (-2.0, 12.0, (0.85, 0.75, 0.10)), (2.0, 16.0, (0.10, 0.45, 0.15))]):
        m = principled("CarPaint%d" % k, 20 + k, color=col, rough=0.25, spec=0.6)
        body = box("CarBody%d" % k, (x, y, 0.55), (1.7, 4.0, 0.8), m)
        top = box("CarTop%d" % k, (x, y - 0.2, 1.2), (1.5, 2.0, 0.5), m_glass)
        join("Car%d" % k, [body, top], 20 + k)
    bldg = box("Building", (-8.0, 14.0, 5.0), (6.0, 16.0, 10.0), m_wall)
    wins = [bldg]
    for fl in range(4):
        for k in range(7):
            wins.append(box("win", (-4.98, 7.5 + 2.0 * k, 1.5 + 2.3 * fl), (0.05, 1.0, 1.4), m_glass))
    join("Building", wins, 30)
    sun = light("SUN", "Sun", (0, 0, 10), 5.0, angle=math.radians(0.6), color=(1.0, 0.96, 0.90))
    sun.rotation_euler = (math.radians(55), 0.0, math.radians(40))
    gradient_sky([(0.0, (0.75, 0.82, 0.92)), (0.4, (0.30, 0.50, 0.90)), (1.0, (0.15, 0.30, 0.75))], 0.9)
    look_at_camera((1.5, -6.0, 1.6), (0.5, 10.0, 1.5), 32.0)


def main():
    args = parse_args()
    outdir = os.path.dirname(os.path.abspath(args.out))
    os.makedirs(outdir, exist_ok=True)
    clear_scene()
    {"glossy": build_glossy, "spines": build_spines, "mirror": build_mirror, "outdoor": build_outdoor,
     "stage": build_stage, "shelf": build_shelf, "street": build_street}[args.scene]()
    setup_render(args)
    if args.save_blend:
        bpy.ops.wm.save_as_mainfile(filepath=os.path.abspath(args.save_blend))
    bpy.ops.render.render(write_still=True)
    print("wrote", os.path.abspath(args.out))


main()
