# How far from its centre a Cycles pixel's camera rays leave, per pixel filter:
#
#   blender -b --factory-startup --python filter_support.py -- GAUSSIAN 1.5
#
# An orthographic camera sees an emitting half-plane (strength 1e4) whose edge
# lies on a pixel border, over a black world; 32 x 32 px, 4096 spp. A pixel d
# centres from the edge (d = 0.5, 1.5, ...) shows the share of its rays that
# leave further than d from its centre (its value / 1e4). Prints that share per
# distance: the filter's support is where it reaches 0.
import os
import sys
import tempfile

import bpy
import numpy as np

STRENGTH, SIZE, SAMPLES = 1e4, 32, 4096


def main():
    kind, width = sys.argv[-2], float(sys.argv[-1])
    bpy.ops.wm.read_factory_settings(use_empty=True)
    sc = bpy.context.scene
    sc.render.engine = "CYCLES"
    sc.cycles.samples, sc.cycles.use_adaptive_sampling, sc.cycles.use_denoising = SAMPLES, False, False
    sc.render.resolution_x = sc.render.resolution_y = SIZE
    sc.render.resolution_percentage = 100
    sc.cycles.pixel_filter_type, sc.cycles.filter_width = kind, width
    cam = bpy.data.cameras.new("camera")
    cam.type, cam.ortho_scale = "ORTHO", float(SIZE)  # one unit per pixel
    ob = bpy.data.objects.new("camera", cam)
    sc.collection.objects.link(ob)
    sc.camera, ob.location = ob, (0, 0, 10)
    world = bpy.data.worlds.new("black")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0
    sc.world = world
    # The half-plane x >= 0: its edge is the left border of column SIZE / 2.
    bpy.ops.mesh.primitive_plane_add(size=1, location=(50, 0, 0))
    plane = bpy.context.object
    plane.scale = (100, 100, 1)
    mat = bpy.data.materials.new("emitter")
    mat.use_nodes = True
    nt = mat.node_tree
    for n in list(nt.nodes):
        nt.nodes.remove(n)
    em, out = nt.nodes.new("ShaderNodeEmission"), nt.nodes.new("ShaderNodeOutputMaterial")
    em.inputs["Strength"].default_value = STRENGTH
    nt.links.new(em.outputs[0], out.inputs[0])
    plane.data.materials.append(mat)
    path = os.path.join(tempfile.mkdtemp(prefix="filter-support-"), "row.exr")
    sc.render.image_settings.file_format, sc.render.filepath = "OPEN_EXR", path
    bpy.ops.render.render(write_still=True)
    img = bpy.data.images.load(path)
    row = np.array(img.pixels[:]).reshape(SIZE, SIZE, 4)[SIZE // 2, :SIZE // 2, 0][::-1] / STRENGTH
    os.remove(path)
    print("%s %.2f px: share of a pixel's rays beyond distance d from its centre" % (kind, width))
    for i, share in enumerate(row[:6]):
        print("  d = %.1f px: %.6f (%d of %d samples)" % (i + 0.5, share, round(share * SAMPLES), SAMPLES))


main()
