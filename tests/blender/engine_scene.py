"""Builds the render engine test's scenes (engine_test.sh) and saves them:

- parity.blend: a red box, a smooth green sphere, a blue ground with a viewport colour only (no
  nodes), a torus without a material, a sun, a camera; 320x240, toonray with a blue background,
  Standard view transform and no dither, so that the engine's PNG holds toonray's bytes. Its
  settings are exported as look.toml for the command line.
- complex.blend: a subdivided cube (modifier), a text object, two linked duplicates of one mesh,
  a collection of a cone and a bevelled curve instanced twice by empties, a metaball; a cube
  hidden for the render, one whose toonray usage is Exclude and a holdout cube; each object has
  its own pass index; 200x150.

    blender -b --python engine_scene.py -- WORK
"""

import math
import os
import sys

import bpy

work = sys.argv[sys.argv.index("--") + 1]


def principled(name, colour):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    bsdf = m.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (*colour, 1.0)
    return m


def reset():
    bpy.ops.wm.read_homefile(use_empty=True)
    scene = bpy.context.scene
    scene.render.engine = "TOONRAY"
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.render.dither_intensity = 0.0
    scene.render.image_settings.file_format = "PNG"
    scene.render.image_settings.color_mode = "RGB"
    return scene


def camera(scene, location, target, lens=40.0):
    bpy.ops.object.camera_add(location=location)
    cam = bpy.context.object
    cam.data.lens = lens
    direction = [t - l for t, l in zip(target, location)]
    cam.rotation_euler = _look_rotation(direction)
    scene.camera = cam
    return cam


def _look_rotation(direction):
    from mathutils import Vector
    return Vector(direction).to_track_quat("-Z", "Y").to_euler()


def build_parity():
    scene = reset()
    scene.render.resolution_x, scene.render.resolution_y = 320, 240
    scene.render.resolution_percentage = 100
    scene.frame_start = scene.frame_end = 1
    t = scene.toonray
    t.image__background = (0.0, 0.0, 1.0)
    bpy.ops.mesh.primitive_cube_add(size=1.6, location=(-1.2, 0.0, 0.8))
    box = bpy.context.object
    box.name = "Box"
    box.rotation_euler = (0.0, 0.0, 0.5)
    box.data.materials.append(principled("red", (0.8, 0.1, 0.05)))
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.9, location=(1.2, 0.4, 0.9), segments=48,
                                         ring_count=24)
    sphere = bpy.context.object
    sphere.name = "Sphere"
    bpy.ops.object.shade_smooth()
    sphere.data.materials.append(principled("green", (0.1, 0.7, 0.2)))
    bpy.ops.mesh.primitive_plane_add(size=8.0)
    ground = bpy.context.object
    ground.name = "Ground"
    blue = bpy.data.materials.new("blue")
    blue.use_nodes = False
    blue.diffuse_color = (0.2, 0.3, 0.9, 1.0)
    ground.data.materials.append(blue)
    bpy.ops.mesh.primitive_torus_add(location=(0.2, -1.6, 0.35), major_radius=0.6,
                                     minor_radius=0.2)
    bpy.context.object.name = "Torus"
    bpy.ops.object.light_add(type="SUN", location=(0, 0, 5), rotation=(0.6, 0.3, 0.8))
    bpy.context.object.data.energy = 3.0
    camera(scene, (5.0, -6.0, 4.0), (0.0, 0.0, 0.6))
    bpy.ops.wm.save_as_mainfile(filepath=os.path.join(work, "parity.blend"))
    bpy.ops.toonray.settings_export(filepath=os.path.join(work, "look.toml"))


def build_complex():
    scene = reset()
    scene.render.resolution_x, scene.render.resolution_y = 200, 150
    scene.render.resolution_percentage = 100
    index = {}

    def tag(obj, name):
        obj.name = name
        obj.pass_index = len(index) + 1
        index[name] = obj.pass_index

    bpy.ops.mesh.primitive_cube_add(size=1.0, location=(-2.0, 0.0, 0.5))
    cube = bpy.context.object
    cube.modifiers.new("subdivide", "SUBSURF").levels = 2
    tag(cube, "Subdivided")
    bpy.ops.object.text_add(location=(-0.8, -1.5, 0.0), rotation=(math.pi / 2, 0, 0))
    text = bpy.context.object
    text.data.body = "Toon"
    text.data.extrude = 0.05
    tag(text, "Text")
    bpy.ops.mesh.primitive_ico_sphere_add(radius=0.4, location=(0.0, 0.0, 0.4))
    first = bpy.context.object
    tag(first, "LinkedA")
    second = first.copy()  # a linked duplicate: the same mesh
    second.location = (0.0, 1.2, 0.4)
    scene.collection.objects.link(second)
    tag(second, "LinkedB")
    # A collection instanced twice; its own objects are not in the view layer.
    group = bpy.data.collections.new("Group")
    bpy.ops.mesh.primitive_cone_add(radius1=0.3, depth=0.6, location=(0.0, 0.0, 0.3))
    cone = bpy.context.object
    for c in cone.users_collection:
        c.objects.unlink(cone)
    group.objects.link(cone)
    tag(cone, "Cone")
    bpy.ops.curve.primitive_bezier_circle_add(radius=0.3, location=(0.6, 0.0, 0.3))
    curve = bpy.context.object
    curve.data.bevel_depth = 0.05
    for c in curve.users_collection:
        c.objects.unlink(curve)
    group.objects.link(curve)
    tag(curve, "Curve")
    for i, location in enumerate([(1.5, -0.5, 0.0), (1.5, 1.0, 0.0)]):
        empty = bpy.data.objects.new("Instancer%d" % i, None)
        empty.instance_type = "COLLECTION"
        empty.instance_collection = group
        empty.location = location
        scene.collection.objects.link(empty)
    bpy.ops.object.metaball_add(type="BALL", radius=0.5, location=(-2.0, 1.6, 0.5))
    tag(bpy.context.object, "Meta")
    # Objects the render must leave out, or make transparent.
    left_out = {}
    for name, location in (("Hidden", (0.0, -1.0, 1.5)), ("Excluded", (-1.0, 1.0, 1.5)),
                           ("Holdout", (1.2, 0.2, 1.4))):
        bpy.ops.mesh.primitive_cube_add(size=0.5, location=location)
        obj = bpy.context.object
        obj.name = name
        obj.pass_index = 20 + len(left_out)
        left_out[name] = obj.pass_index
    bpy.data.objects["Hidden"].hide_render = True
    bpy.data.objects["Excluded"].toonray.usage = "EXCLUDE"
    bpy.data.objects["Holdout"].is_holdout = True
    index["Holdout"] = left_out["Holdout"]
    bpy.ops.object.light_add(type="SUN", rotation=(0.5, 0.2, 0.4))
    camera(scene, (6.0, -7.0, 5.0), (0.0, 0.2, 0.3), lens=30.0)
    scene.view_layers[0].use_pass_object_index = True
    scene.render.image_settings.file_format = "OPEN_EXR_MULTILAYER"
    import json
    with open(os.path.join(work, "complex_indices.json"), "w") as f:
        json.dump({"seen": index, "left_out": {k: v for k, v in left_out.items()
                                                if k != "Holdout"}}, f)
    bpy.ops.wm.save_as_mainfile(filepath=os.path.join(work, "complex.blend"))


build_parity()
build_complex()
print("engine_scene: saved parity.blend, look.toml and complex.blend")
