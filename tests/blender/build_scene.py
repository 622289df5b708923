"""Builds the test scene in Blender and runs both add-on operators (tests/blender/run_test.sh).

    blender -b --factory-startup --python build_scene.py -- WORK REPO

Installs the add-on from a zip (built by blender/build_zip.py) into BLENDER_USER_SCRIPTS, enables
it, builds a scene (three cubes, a row of piano keys named w20..w30 / b14..b21, a camera that
moves, tracks a target and zooms from 32 to 40 mm), animates the keys with
bpy.ops.anim.toonray_keys_from_notes, exports frames 1..48 at 320x180 (sensor fit AUTO) with
bpy.ops.export_scene.toonray_obj_sequence into WORK/A, and saves WORK/scene_A.blend plus
scene_B/C/D.blend with other resolutions and sensor fits for the command-line exports.
"""

import math
import os
import sys

import bpy

sys.dont_write_bytecode = True  # leave no __pycache__ in the source tree

argv = sys.argv[sys.argv.index("--") + 1:]
WORK, REPO = os.path.abspath(argv[0]), os.path.abspath(argv[1])

def _load(path, name):
    import importlib.util
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


build_zip = _load(os.path.join(REPO, "blender", "build_zip.py"), "build_zip")

KEY_ANGLE = 0.2  # radians: larger than the piano's 0.042 so the test measures it precisely
NOTES = os.path.join(REPO, "tests", "blender", "keys_test.notes")


def fail(msg):
    print("build_scene: FAIL:", msg, file=sys.stderr, flush=True)
    sys.exit(1)


# ---- the add-on, installed from its zip as a user would ----
zip_path = build_zip.build_zip(os.path.join(WORK, "toonray_blender.zip"))
if "BLENDER_USER_SCRIPTS" not in os.environ:
    fail("run with BLENDER_USER_SCRIPTS set to a scratch folder (the add-on is installed there)")
bpy.ops.preferences.addon_install(filepath=zip_path, overwrite=True)
bpy.ops.preferences.addon_enable(module="toonray_blender")
import toonray_blender  # noqa: E402

if not os.path.abspath(toonray_blender.__file__).startswith(os.path.abspath(os.environ["BLENDER_USER_SCRIPTS"])):
    fail("the add-on was imported from %s, not from the installed zip" % toonray_blender.__file__)
for op in ("export_scene.toonray_obj_sequence", "anim.toonray_keys_from_notes"):
    mod, name = op.split(".")
    if not hasattr(getattr(bpy.ops, mod), name):
        fail("operator %s is not registered" % op)

# ---- the scene ----
for obj in list(bpy.data.objects):
    bpy.data.objects.remove(obj, do_unlink=True)
scene = bpy.context.scene
scene.render.fps, scene.render.fps_base = 24, 1.0
scene.frame_start, scene.frame_end = 1, 48


def material(name, rgb):
    m = bpy.data.materials.new(name)
    m.diffuse_color = (*rgb, 1.0)
    m.use_nodes = True
    bsdf = m.node_tree.nodes.get("Principled BSDF")
    if bsdf is not None:
        bsdf.inputs["Base Color"].default_value = (*rgb, 1.0)
    return m


def box(name, lo, hi, location, rotation=(0.0, 0.0, 0.0), mat=None):
    """A box mesh with its object origin at `location`; lo/hi are local corners."""
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    verts = [(x, y, z) for x in (x0, x1) for y in (y0, y1) for z in (z0, z1)]
    faces = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(verts, [], faces)
    mesh.update()
    if mat is not None:
        mesh.materials.append(mat)
    obj = bpy.data.objects.new(name, mesh)
    obj.location = location
    obj.rotation_euler = rotation
    scene.collection.objects.link(obj)
    return obj


red = material("red", (0.8, 0.25, 0.2))
blue = material("blue", (0.25, 0.4, 0.8))
green = material("green", (0.3, 0.7, 0.35))
ivory = material("ivory", (0.97, 0.94, 0.84))
ebony = material("ebony", (0.13, 0.12, 0.12))
wood = material("wood", (0.56, 0.28, 0.14))

box("CubeA", (-0.11, -0.11, -0.11), (0.11, 0.11, 0.11), (-0.55, 1.0, 0.75), (0.0, 0.0, 0.4), red)
box("CubeB", (-0.14, -0.14, -0.14), (0.14, 0.14, 0.14), (0.55, 1.6, 0.85), (0.3, 0.2, 0.5), blue)
box("CubeC", (-0.08, -0.08, -0.08), (0.08, 0.08, 0.08), (-0.05, 0.5, 1.3), (0.0, 0.5, 0.7), green)

# Piano keys: origin = pivot at the back bottom edge, the key reaching forward to -Y (toward
# the camera); turning +X moves the front down, as toonray's piano keys do.
PITCH = 0.0235
white_x = {}
for n in range(20, 31):
    midi = toonray_blender.note_script.white_key(n)
    x = (n - 25) * PITCH
    white_x[midi] = x
    box("w%d" % n, (-0.0112, -0.15, 0.0), (0.0112, 0.0, 0.022), (x, 0.0, 0.72), mat=ivory)
for n in range(1, 37):
    midi = toonray_blender.note_script.black_key(n)
    if midi - 1 in white_x and midi + 1 in white_x:
        x = 0.5 * (white_x[midi - 1] + white_x[midi + 1])
        box("b%d" % n, (-0.0065, -0.10, 0.0), (0.0065, 0.0, 0.03), (x, 0.0, 0.735), mat=ebony)
box("keybed", (-0.15, -0.17, -0.08), (0.15, 0.03, 0.0), (0.0, 0.0, 0.70), mat=wood)

# The camera: moves, tracks a target (a constraint, so only the evaluated matrix is right) and
# zooms (animated lens).
target = bpy.data.objects.new("target", None)
target.location = (0.0, 0.7, 0.9)
scene.collection.objects.link(target)
cam_data = bpy.data.cameras.new("Camera")
cam_data.sensor_width, cam_data.sensor_height = 36.0, 24.0
cam = bpy.data.objects.new("Camera", cam_data)
scene.collection.objects.link(cam)
scene.camera = cam
track = cam.constraints.new("TRACK_TO")
track.target = target
track.track_axis, track.up_axis = "TRACK_NEGATIVE_Z", "UP_Y"
for frame, loc, lens in ((1, (0.25, -2.9, 1.55), 32.0), (48, (-0.35, -2.5, 2.0), 40.0)):
    cam.location = loc
    cam.keyframe_insert("location", frame=frame)
    cam_data.lens = lens
    cam_data.keyframe_insert("lens", frame=frame)

# ---- operator 1: the keys from the note script ----
result = bpy.ops.anim.toonray_keys_from_notes(filepath=NOTES, start_frame=1.0, axis="X",
                                              angle=KEY_ANGLE, mode="PRESS")
if "FINISHED" not in result:
    fail("anim.toonray_keys_from_notes returned %s" % result)
fc_count = 0
for obj in scene.objects:
    if obj.animation_data and obj.animation_data.action and obj.name[:1] in "wb" and obj.name[1:].isdigit():
        fc_count += 1
if fc_count != 7:  # w22 w24 w26 w27 w28 w30 b17
    fail("expected 7 animated keys, found %d" % fc_count)

# ---- operator 2: export config A (320x180, AUTO) ----
scene.render.resolution_x, scene.render.resolution_y = 320, 180
scene.render.resolution_percentage = 100
cam_data.sensor_fit = "AUTO"
scene.frame_set(7)  # the export must restore this
bpy.ops.wm.save_as_mainfile(filepath=os.path.join(WORK, "scene_A.blend"))
result = bpy.ops.export_scene.toonray_obj_sequence(
    directory=os.path.join(WORK, "A"), name="keys", frame_start=1, frame_end=48, frame_step=1)
if "FINISHED" not in result:
    fail("export_scene.toonray_obj_sequence returned %s" % result)
if scene.frame_current != 7:
    fail("the export left the scene at frame %d, not 7" % scene.frame_current)

# Configs for the command-line exports: resolution, sensor fit, pixel aspect.
CONFIGS = {
    "B": (200, 300, "VERTICAL", 1.0, 1.0),
    "C": (180, 320, "AUTO", 1.0, 1.0),
    "D": (240, 150, "HORIZONTAL", 1.5, 1.0),  # toonray --size 240x100
}
for tag, (w, h, fit, pax, pay) in CONFIGS.items():
    scene.render.resolution_x, scene.render.resolution_y = w, h
    scene.render.pixel_aspect_x, scene.render.pixel_aspect_y = pax, pay
    cam_data.sensor_fit = fit
    bpy.ops.wm.save_as_mainfile(filepath=os.path.join(WORK, "scene_%s.blend" % tag), copy=True)
print("build_scene: OK", flush=True)
