"""The scenes of the render engine's measurements (bench/blender/measure.sh, docs/blender.md):

- suzanne_toonray.blend / suzanne_cycles.blend: a smooth-shaded Suzanne subdivided 5 times
  (1,007,616 triangles) on a ground plane, a sun and a camera, 1920x1080; the first renders with toonray
  (its defaults: ink lines, one sample per pixel), the second with Cycles at 1 sample (CPU, no
  denoising, no adaptive sampling) and Freestyle lines.
- viewport.blend: about 100k triangles (a Suzanne subdivided 3 times: 62,976; icospheres of
  20,480, 5,120 and 5,120; a UV sphere of 9,024; the ground: 102,722 triangles) for the viewport
  preview at 960x540.

    blender -b --python suzanne_scene.py -- OUT_DIR          (with the add-on enabled)
"""

import os
import sys

import bpy

out = sys.argv[sys.argv.index("--") + 1]


def base(levels):
    bpy.ops.wm.read_homefile(use_empty=True)
    scene = bpy.context.scene
    bpy.ops.mesh.primitive_monkey_add(location=(0, 0, 1))
    bpy.ops.object.shade_smooth()
    monkey = bpy.context.object
    mod = monkey.modifiers.new("subdivide", "SUBSURF")
    mod.levels = mod.render_levels = levels
    mat = bpy.data.materials.new("skin")
    mat.use_nodes = True
    mat.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (0.8, 0.4, 0.2, 1)
    monkey.data.materials.append(mat)
    bpy.ops.mesh.primitive_plane_add(size=10)
    bpy.ops.object.light_add(type="SUN", rotation=(0.6, 0.2, 0.5))
    bpy.ops.object.camera_add(location=(3.5, -5.5, 2.6), rotation=(1.22, 0.0, 0.56))
    scene.camera = bpy.context.object
    scene.render.resolution_x, scene.render.resolution_y = 1920, 1080
    scene.render.resolution_percentage = 100
    return scene


scene = base(5)
scene.render.engine = "TOONRAY"
bpy.ops.wm.save_as_mainfile(filepath=os.path.join(out, "suzanne_toonray.blend"))
scene.render.engine = "CYCLES"
scene.cycles.device = "CPU"
scene.cycles.samples = 1
scene.cycles.use_adaptive_sampling = False
scene.cycles.use_denoising = False
scene.render.use_freestyle = True
# Freestyle's default line set, with a line style (an empty file has none, and Freestyle then
# fails): silhouettes, borders and creases, visible only, as toonray's default lines.
freestyle = scene.view_layers[0].freestyle_settings
lineset = freestyle.linesets.active or freestyle.linesets.new("LineSet")
if lineset.linestyle is None:
    lineset.linestyle = bpy.data.linestyles.new("LineStyle")
bpy.ops.wm.save_as_mainfile(filepath=os.path.join(out, "suzanne_cycles.blend"))

scene = base(3)
scene.render.engine = "TOONRAY"
for x, subdivisions in ((-2.2, 6), (2.2, 5), (4.4, 5)):
    bpy.ops.mesh.primitive_ico_sphere_add(subdivisions=subdivisions, radius=0.8,
                                          location=(x, 0.5, 0.8))
    bpy.ops.object.shade_smooth()
bpy.ops.mesh.primitive_uv_sphere_add(segments=96, ring_count=48, radius=0.6, location=(-4.4, 0.5, 0.6))
scene.render.resolution_x, scene.render.resolution_y = 960, 540
bpy.ops.wm.save_as_mainfile(filepath=os.path.join(out, "viewport.blend"))
print("suzanne_scene: wrote", out)
