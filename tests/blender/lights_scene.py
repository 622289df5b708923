"""A lit scene exported with the add-on and rendered by Cycles (tests/blender/lights_test.sh).

    blender -b --factory-startup --python lights_scene.py -- WORK REPO

Builds a scene with a sun (strength 3, turning between frames 1 and 10, no shadows), a
smooth-shaded white sphere, a flat red box and an icosphere without a material (written after
the box), seen by a camera that moves; exports frames 1 and 10 with the add-on (the operator)
into WORK/frames; then for both frames renders with Cycles, at pixel centres (a box filter of
0.01 pixel) into float EXR files:

- WORK/cycles/nl_NNNNNN.exr: every object white diffuse (a material override), no bounces, a
  black world: the red channel is strength x n.l of the sun;
- WORK/cycles/id_NNNNNN.exr: an emission of pass_index / 10: which object a pixel shows.

Also writes WORK/objects.json: each object's pass index, its toonray colour (Kd) and where the
material-less object's centre lands in each frame.
"""

import json
import math
import os
import sys

import bpy
from bpy_extras.object_utils import world_to_camera_view
from mathutils import Vector

sys.dont_write_bytecode = True
argv = sys.argv[sys.argv.index("--") + 1:]
WORK, REPO = os.path.abspath(argv[0]), os.path.abspath(argv[1])
sys.path.insert(0, os.path.join(REPO, "blender"))
import toonray_blender  # noqa: E402

toonray_blender.register()

W, H = 200, 150
FRAMES = (1, 10)
SUN_STRENGTH = 3.0


def fail(msg):
    print("lights_scene: FAIL:", msg, file=sys.stderr, flush=True)
    sys.exit(1)


for obj in list(bpy.data.objects):
    bpy.data.objects.remove(obj, do_unlink=True)
scene = bpy.context.scene
scene.frame_start, scene.frame_end = 1, 10


def material(name, rgb):
    m = bpy.data.materials.new(name)
    m.diffuse_color = (*rgb, 1.0)
    m.use_nodes = True
    bsdf = m.node_tree.nodes.get("Principled BSDF")
    bsdf.inputs["Base Color"].default_value = (*rgb, 1.0)
    return m


def link_new(obj, index):
    obj.pass_index = index
    return obj


bpy.ops.mesh.primitive_uv_sphere_add(segments=48, ring_count=24, radius=1.0, location=(-1.2, 0, 1))
sphere = link_new(bpy.context.object, 1)
sphere.name = "A_sphere"
bpy.ops.object.shade_smooth()
sphere.data.materials.append(material("white", (1.0, 1.0, 1.0)))

bpy.ops.mesh.primitive_cube_add(size=1.4, location=(1.1, 0.3, 0.7), rotation=(0.3, 0.2, 0.6))
box = link_new(bpy.context.object, 2)
box.name = "B_box"
box.data.materials.append(material("red", (0.8, 0.3, 0.2)))

# No material: OBJ would carry the box's red over to it; the add-on gives it the default.
bpy.ops.mesh.primitive_ico_sphere_add(subdivisions=3, radius=0.6, location=(0.2, -1.2, 0.6))
plain = link_new(bpy.context.object, 3)
plain.name = "C_plain"
bpy.ops.object.shade_smooth()

sun_data = bpy.data.lights.new("Sun", "SUN")
sun_data.energy = SUN_STRENGTH
sun_data.angle = 0.0
if hasattr(sun_data, "use_shadow"):
    sun_data.use_shadow = False
if hasattr(sun_data, "cycles") and hasattr(sun_data.cycles, "cast_shadow"):
    sun_data.cycles.cast_shadow = False
sun = bpy.data.objects.new("Sun", sun_data)
scene.collection.objects.link(sun)
for frame, rot in ((1, (0.7, 0.2, 0.5)), (10, (0.9, -0.5, 1.6))):
    sun.rotation_euler = rot
    sun.keyframe_insert("rotation_euler", frame=frame)

cam_data = bpy.data.cameras.new("Camera")
cam = bpy.data.objects.new("Camera", cam_data)
scene.collection.objects.link(cam)
scene.camera = cam
target = bpy.data.objects.new("target", None)
target.location = (0.0, 0.0, 0.8)
scene.collection.objects.link(target)
track = cam.constraints.new("TRACK_TO")
track.target = target
track.track_axis, track.up_axis = "TRACK_NEGATIVE_Z", "UP_Y"
for frame, loc in ((1, (1.5, -6.5, 3.5)), (10, (-3.0, -5.5, 2.5))):
    cam.location = loc
    cam.keyframe_insert("location", frame=frame)
cam_data.lens = 35.0
# Blender's glTF exporter writes an object's own animation channels, not what a constraint adds:
# bake the aim into rotation keys (and drop the constraint) so every route sees the same camera.
aims = {}
for frame in FRAMES:
    scene.frame_set(frame)
    aims[frame] = cam.matrix_world.to_euler("XYZ")
cam.constraints.remove(track)
for frame in FRAMES:
    cam.rotation_euler = aims[frame]
    cam.keyframe_insert("rotation_euler", frame=frame)
for fc in (cam.animation_data.action.fcurves if cam.animation_data else []):
    for k in fc.keyframe_points:
        k.interpolation = "LINEAR"

r = scene.render
r.resolution_x, r.resolution_y, r.resolution_percentage = W, H, 100

# ---- export with the add-on ----
frames_dir = os.path.join(WORK, "frames")
for frame in FRAMES:
    result = bpy.ops.export_scene.toonray_obj_sequence(
        directory=frames_dir, name="lit", frame_start=frame, frame_end=frame, frame_step=1)
    if "FINISHED" not in result:
        fail("export returned %s" % result)

# ---- the same scene through Blender's own glTF exporter, its sun as KHR_lights_punctual ----
result = bpy.ops.export_scene.gltf(filepath=os.path.join(WORK, "scene.glb"), export_format="GLB",
                                   export_cameras=True, export_lights=True,
                                   export_animations=True, export_yup=True)
if "FINISHED" not in result:
    fail("glTF export returned %s" % result)

# ---- Cycles: n.l of the sun at pixel centres, and the object ids ----
r.engine = "CYCLES"
scene.cycles.device = "CPU"
scene.cycles.samples = 4
if hasattr(scene.cycles, "use_adaptive_sampling"):
    scene.cycles.use_adaptive_sampling = False
scene.cycles.use_denoising = False
scene.cycles.max_bounces = 0
scene.cycles.pixel_filter_type = "BOX"
scene.cycles.filter_width = 0.01
r.film_transparent = True
world = bpy.data.worlds.new("black")
world.use_nodes = True
world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
scene.world = world
scene.view_settings.view_transform = "Standard"
scene.view_settings.look = "None"
r.image_settings.file_format = "OPEN_EXR"
r.image_settings.color_depth = "32"
r.image_settings.color_mode = "RGBA"

white = bpy.data.materials.new("nl_white")
white.use_nodes = True
nodes, links = white.node_tree.nodes, white.node_tree.links
nodes.clear()
diffuse = nodes.new("ShaderNodeBsdfDiffuse")
diffuse.inputs["Color"].default_value = (1, 1, 1, 1)
out = nodes.new("ShaderNodeOutputMaterial")
links.new(diffuse.outputs["BSDF"], out.inputs["Surface"])

ids = bpy.data.materials.new("object_ids")
ids.use_nodes = True
nodes, links = ids.node_tree.nodes, ids.node_tree.links
nodes.clear()
info = nodes.new("ShaderNodeObjectInfo")
scale = nodes.new("ShaderNodeMath")
scale.operation = "MULTIPLY"
scale.inputs[1].default_value = 0.1
emission = nodes.new("ShaderNodeEmission")
out = nodes.new("ShaderNodeOutputMaterial")
links.new(info.outputs["Object Index"], scale.inputs[0])
links.new(scale.outputs[0], emission.inputs["Color"])
links.new(emission.outputs["Emission"], out.inputs["Surface"])

layer = scene.view_layers[0]
plain_px = {}
for frame in FRAMES:
    scene.frame_set(frame)
    for tag, mat in (("nl", white), ("id", ids)):
        layer.material_override = mat
        r.filepath = os.path.join(WORK, "cycles", "%s_%06d.exr" % (tag, frame))
        bpy.ops.render.render(write_still=True)
    p = world_to_camera_view(scene, cam, plain.matrix_world.translation)
    plain_px[frame] = [p.x * W, p.y * H]  # from the bottom left, as Blender's pixels

json.dump({"size": [W, H], "frames": list(FRAMES), "sun_strength": SUN_STRENGTH,
           "objects": {"1": [1.0, 1.0, 1.0], "2": [0.8, 0.3, 0.2], "3": [0.8, 0.8, 0.8]},
           "plain_centre": plain_px},
          open(os.path.join(WORK, "objects.json"), "w"))
print("lights_scene: OK", flush=True)
