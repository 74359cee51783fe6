# Builds the tiny procedural scene of the Blender tests and saves it as a .blend:
#
#   blender -b --factory-startup --python make_scene.py -- --out scene.blend \
#       [--res 64x48] [--samples 16] [--filter GAUSSIAN:1.5]
#
# What real files contain, in small: a floor whose checker texture sits in a
# node group, a cube whose material has no nodes, a sphere without any
# material, a glossy sphere, a lamp shade that emits, a sun and an area
# light, a sky colour. Cycles on the CPU; Blender's default pixel filter
# (Blackman-Harris, 1.5 px); adaptive sampling and denoising off, so that a
# render is a plain Monte-Carlo estimate per pixel.
import argparse
import os
import sys

import bpy


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    ap = argparse.ArgumentParser(prog="make_scene.py")
    ap.add_argument("--out", required=True, help=".blend to write")
    ap.add_argument("--res", default="64x48", help="WxH")
    ap.add_argument("--samples", type=int, default=16)
    ap.add_argument("--filter", default="BLACKMAN_HARRIS:1.5", help="pixel filter TYPE:WIDTH")
    return ap.parse_args(argv)


def checker_group():
    """A node group: checker texture of two browns, output Color."""
    g = bpy.data.node_groups.new("Checker", "ShaderNodeTree")
    g.outputs.new("NodeSocketColor", "Color")
    gin = g.nodes.new("NodeGroupInput")
    gout = g.nodes.new("NodeGroupOutput")
    chk = g.nodes.new("ShaderNodeTexChecker")
    chk.inputs["Scale"].default_value = 6.0
    chk.inputs["Color1"].default_value = (0.6, 0.45, 0.3, 1)
    chk.inputs["Color2"].default_value = (0.15, 0.1, 0.08, 1)
    g.links.new(chk.outputs["Color"], gout.inputs["Color"])
    del gin
    return g


def node_material(name, color, roughness=0.5, metallic=0.0, emission=0.0, group=None):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    bsdf = m.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (*color, 1)
    bsdf.inputs["Roughness"].default_value = roughness
    bsdf.inputs["Metallic"].default_value = metallic
    if emission:
        bsdf.inputs["Emission"].default_value = (*color, 1)
        bsdf.inputs["Emission Strength"].default_value = emission
    if group:
        node = m.node_tree.nodes.new("ShaderNodeGroup")
        node.node_tree = group
        m.node_tree.links.new(node.outputs["Color"], bsdf.inputs["Base Color"])
    return m


def main():
    args = parse_args()
    w, h = (int(v) for v in args.res.split("x"))
    bpy.ops.wm.read_factory_settings(use_empty=True)
    sc = bpy.context.scene
    sc.render.engine = "CYCLES"
    sc.cycles.device = "CPU"
    sc.cycles.samples = args.samples
    sc.cycles.use_adaptive_sampling = False
    sc.cycles.use_denoising = False
    sc.render.resolution_x, sc.render.resolution_y = w, h
    sc.render.resolution_percentage = 100
    sc.cycles.pixel_filter_type, width = args.filter.split(":")
    sc.cycles.filter_width = float(width)

    world = bpy.data.worlds.new("Sky")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.4, 0.5, 0.7, 1)
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.5
    sc.world = world

    bpy.ops.mesh.primitive_plane_add(size=8, location=(0, 0, 0))
    bpy.context.object.data.materials.append(node_material("Floor", (1, 1, 1), group=checker_group()))
    bpy.ops.mesh.primitive_cube_add(size=1.2, location=(-1.2, 0.4, 0.6), rotation=(0, 0, 0.5))
    plain = bpy.data.materials.new("NoNodes")  # use_nodes stays False
    plain.diffuse_color = (0.2, 0.5, 0.25, 1)
    bpy.context.object.data.materials.append(plain)
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.5, location=(0.9, 1.2, 0.5), segments=24, ring_count=12)
    bpy.ops.object.shade_smooth()  # no material at all
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.6, location=(0.7, -0.5, 0.6), segments=32, ring_count=16)
    bpy.ops.object.shade_smooth()
    bpy.context.object.data.materials.append(node_material("Glossy", (0.8, 0.1, 0.1), roughness=0.15))
    bpy.ops.mesh.primitive_cylinder_add(radius=0.25, depth=0.4, location=(-0.3, 1.6, 1.4))
    bpy.context.object.data.materials.append(node_material("Shade", (1.0, 0.8, 0.5), emission=4.0))

    bpy.ops.object.light_add(type="SUN", location=(0, 0, 5), rotation=(0.6, 0.2, 0.8))
    bpy.context.object.data.energy = 3.0
    bpy.ops.object.light_add(type="AREA", location=(0, -1, 4))
    bpy.context.object.data.energy = 200.0
    bpy.context.object.data.size = 1.5

    bpy.ops.object.camera_add(location=(0, -6, 3.2), rotation=(1.13, 0, 0))
    sc.camera = bpy.context.object
    bpy.ops.wm.save_as_mainfile(filepath=os.path.abspath(args.out))


main()
