"""Builds an animated scene in Blender, exports it with Blender's own glTF exporter and renders
Cycles silhouettes of some frames (tests/blender/run_gltf_test.sh).

    blender -b --factory-startup --python gltf_scene.py -- WORK FRAMES WIDTH HEIGHT

The scene: a cube that moves, a cylinder that turns, a cone that moves and turns (its parent
an empty that turns too), a camera with a 35 mm lens that moves and turns; no lights needed. It
is exported to WORK/scene.glb (io_scene_gltf2, GLB, Y up, animations), and for each frame in
FRAMES (comma-separated) Cycles renders WORK/cycles/frame_NNNNNN.png at WIDTH x HEIGHT with a
transparent film and a pixel filter of almost no width, so a pixel's alpha says whether its
centre sees an object: the silhouette toonray's renders are compared with.
"""

import math
import os
import sys

import bpy

argv = sys.argv[sys.argv.index("--") + 1:]
WORK = os.path.abspath(argv[0])
FRAMES = [int(f) for f in argv[1].split(",")]
WIDTH, HEIGHT = int(argv[2]), int(argv[3])

for obj in list(bpy.data.objects):
    bpy.data.objects.remove(obj, do_unlink=True)
scene = bpy.context.scene
scene.render.fps, scene.render.fps_base = 24, 1.0
scene.frame_start, scene.frame_end = 0, 24


def keys(obj, frames, **channels):
    """Keyframes: for each channel name, one value per frame in `frames`."""
    for i, frame in enumerate(frames):
        for name, values in channels.items():
            setattr(obj, name, values[i])
            obj.keyframe_insert(name, frame=frame)


bpy.ops.mesh.primitive_cube_add(size=0.8, location=(-1.2, 0.0, 0.4))
cube = bpy.context.object
cube.name = "Mover"
keys(cube, (0, 24), location=((-1.2, 0.0, 0.4), (-0.4, 0.6, 0.9)))

bpy.ops.mesh.primitive_cylinder_add(vertices=12, radius=0.35, depth=1.2, location=(0.9, 0.3, 0.6))
cylinder = bpy.context.object
cylinder.name = "Turner"
keys(cylinder, (0, 12, 24), rotation_euler=((0, 0, 0), (0.6, 0.2, 0.9), (1.2, -0.3, 2.0)))

pivot = bpy.data.objects.new("Pivot", None)
scene.collection.objects.link(pivot)
pivot.location = (0.0, -0.8, 0.0)
keys(pivot, (0, 24), rotation_euler=((0, 0, 0), (0, 0, 1.0)))
bpy.ops.mesh.primitive_cone_add(vertices=10, radius1=0.3, depth=0.7, location=(0.5, 0.0, 0.35))
cone = bpy.context.object
cone.name = "Cone"
cone.parent = pivot
keys(cone, (0, 24), location=((0.5, 0.0, 0.35), (0.8, 0.2, 0.8)),
     rotation_euler=((0, 0, 0), (0.7, 0.0, 0.0)))

cam_data = bpy.data.cameras.new("Camera")
cam_data.lens = 35.0  # not Blender's default 50 mm
cam_data.sensor_fit = "AUTO"
cam = bpy.data.objects.new("Camera", cam_data)
scene.collection.objects.link(cam)
scene.camera = cam
keys(cam, (0, 24), location=((2.8, -3.2, 2.0), (1.5, -3.8, 2.5)),
     rotation_euler=((math.radians(65), 0, math.radians(42)), (math.radians(58), 0, math.radians(22))))

for obj in scene.objects:
    if obj.animation_data and obj.animation_data.action:
        for fc in obj.animation_data.action.fcurves:
            for kp in fc.keyframe_points:
                kp.interpolation = "BEZIER"

scene.render.resolution_x, scene.render.resolution_y = WIDTH, HEIGHT
scene.render.resolution_percentage = 100

bpy.ops.export_scene.gltf(filepath=os.path.join(WORK, "scene.glb"), export_format="GLB",
                          export_cameras=True, export_animations=True, export_yup=True)

# Cycles silhouettes: alpha from a transparent film, point-sampled at pixel centres.
scene.render.engine = "CYCLES"
scene.cycles.device = "CPU"
scene.cycles.samples = 1
scene.cycles.use_denoising = False
scene.cycles.pixel_filter_type = "BOX"
scene.cycles.filter_width = 0.01
scene.render.film_transparent = True
scene.render.image_settings.file_format = "PNG"
scene.render.image_settings.color_mode = "RGBA"
world = bpy.data.worlds.new("none")
scene.world = world
os.makedirs(os.path.join(WORK, "cycles"), exist_ok=True)
for frame in FRAMES:
    scene.frame_set(frame)
    scene.render.filepath = os.path.join(WORK, "cycles", "frame_%06d.png" % frame)
    bpy.ops.render.render(write_still=True)
print("gltf_scene: OK", flush=True)
