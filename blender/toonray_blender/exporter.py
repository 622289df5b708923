"""Export an OBJ sequence with toonray's camera block, one frame at a time.

For each frame: set the scene to it, run Blender's own OBJ exporter (``bpy.ops.wm.obj_export``,
the C++ exporter of Blender 3.2+, forward -Z, up Y) on ``NAME_NNNNNN.obj`` (+ ``.mtl``), then
append the camera block of the scene's active camera at that frame (docs/blender.md).

One frame per exporter call, rather than the exporter's own animation mode, because the
animation mode names files after its own pattern and does not say which file is which frame in
a way that is stable across Blender versions; setting the frame ourselves keeps the names
toonray batch expects and evaluates the camera at exactly the frame the geometry was taken at.
"""

import os

import bpy

from . import camera as cam
from . import lights as lights_io

# The parameters we pass to bpy.ops.wm.obj_export. Their names are the same from Blender 3.2
# (the C++ exporter) through 4.x; any that a version lacks is left out, and the required ones
# are checked (see _obj_export_kwargs).
_REQUIRED = ("filepath", "forward_axis", "up_axis", "export_selected_objects")


class ExportError(Exception):
    pass


def frame_file_stem(name, frame):
    return "%s_%06d" % (name, frame)


def _obj_export_kwargs(filepath, use_selection, global_scale, apply_modifiers, eval_mode,
                       triangulate, export_normals, export_uv, export_materials):
    op = bpy.ops.wm.obj_export
    try:
        props = op.get_rna_type().properties
    except (AttributeError, KeyError):
        raise ExportError("this Blender has no bpy.ops.wm.obj_export (the C++ OBJ exporter of "
                          "Blender 3.2 and newer)")
    names = {p.identifier for p in props}
    missing = [n for n in _REQUIRED if n not in names]
    if missing:
        raise ExportError("bpy.ops.wm.obj_export lacks %s on Blender %s"
                          % (", ".join(missing), bpy.app.version_string))
    for axis_prop, value in (("forward_axis", "NEGATIVE_Z"), ("up_axis", "Y")):
        items = {i.identifier for i in props[axis_prop].enum_items}
        if value not in items:
            raise ExportError("bpy.ops.wm.obj_export.%s has no %r on Blender %s (has %s)"
                              % (axis_prop, value, bpy.app.version_string, sorted(items)))
    wanted = dict(
        filepath=filepath,
        check_existing=False,
        export_animation=False,
        forward_axis="NEGATIVE_Z",
        up_axis="Y",
        global_scale=global_scale,
        apply_modifiers=apply_modifiers,
        apply_transform=True,  # newer versions only: world coordinates, as 3.4 always writes
        export_eval_mode=eval_mode,
        export_selected_objects=use_selection,
        export_uv=export_uv,
        export_normals=export_normals,
        export_colors=False,
        export_materials=export_materials,
        export_triangulated_mesh=triangulate,
        export_curves_as_nurbs=False,
        export_object_groups=False,
        export_material_groups=False,
        export_vertex_groups=False,
        export_smooth_groups=False,
        path_mode="AUTO",
    )
    return {k: v for k, v in wanted.items() if k in names}


def active_camera_block(scene, depsgraph, global_scale=1.0):
    """(eye, gaze, up, info) of the scene's active camera as the depsgraph has it now."""
    obj = scene.camera
    if obj is None:
        raise ExportError("scene '%s' has no active camera (Scene properties > Camera)" % scene.name)
    if obj.type != "CAMERA":
        raise ExportError("the active camera '%s' is a %s object, not a camera" % (obj.name, obj.type))
    ev = obj.evaluated_get(depsgraph)
    data = ev.data
    if data.type != "PERSP":
        raise ExportError("camera '%s' is %s; toonray renders perspective cameras only"
                          % (obj.name, data.type.lower()))
    if abs(data.shift_x) > 1e-9 or abs(data.shift_y) > 1e-9:
        raise ExportError("camera '%s' has a lens shift (%g, %g), which toonray's camera block "
                          "cannot express: set Shift X and Y to 0"
                          % (obj.name, data.shift_x, data.shift_y))
    r = scene.render
    t = cam.tan_half_fov_x(data.lens, data.sensor_width, data.sensor_height, data.sensor_fit,
                           r.resolution_x, r.resolution_y, r.pixel_aspect_x, r.pixel_aspect_y)
    m = ev.matrix_world
    eye, gaze, up = cam.camera_block_vectors([[m[i][j] for j in range(4)] for i in range(4)], t,
                                             global_scale)
    size = cam.square_pixel_size(r.resolution_x, r.resolution_y, r.pixel_aspect_x, r.pixel_aspect_y)
    import math
    info = {
        "camera": obj.name,
        "fov_x_degrees": math.degrees(2.0 * math.atan(t)),
        "sensor_fit": data.sensor_fit,
        "size": size,
    }
    return eye, gaze, up, info


def export_frame(context, filepath, use_selection=False, global_scale=1.0, apply_modifiers=True,
                 eval_mode="DAG_EVAL_VIEWPORT", triangulate=True, export_normals=True,
                 export_uv=True, export_materials=True):
    """Exports the scene at its current frame to filepath and appends the camera block."""
    scene = context.scene
    depsgraph = context.evaluated_depsgraph_get()
    eye, gaze, up, info = active_camera_block(scene, depsgraph, global_scale)
    kwargs = _obj_export_kwargs(filepath, use_selection, global_scale, apply_modifiers, eval_mode,
                                triangulate, export_normals, export_uv, export_materials)
    result = bpy.ops.wm.obj_export(**kwargs)
    if "FINISHED" not in result or not os.path.isfile(filepath):
        raise ExportError("Blender's OBJ exporter did not write %s" % filepath)
    comment = ("toonray camera: Blender camera '%s' at frame %d, horizontal fov %.6f degrees "
               "(sensor fit %s); render with --size %dx%d"
               % (info["camera"], scene.frame_current, info["fov_x_degrees"], info["sensor_fit"],
                  info["size"][0], info["size"][1]))
    if export_materials:
        info["default_material_objects"] = lights_io.add_default_material(filepath)
    with open(filepath, "a", encoding="utf-8", newline="\n") as f:
        f.write(cam.camera_block_text(eye, gaze, up, comment))
    lights = frame_lights(context, depsgraph, use_selection, eval_mode, global_scale)
    info["lights"] = len(lights)
    lights_io.write_lights(filepath, lights,
                           "toonray lights: Blender scene '%s' at frame %d (docs/blender.md)"
                           % (scene.name, scene.frame_current))
    return info


def frame_lights(context, depsgraph, use_selection, eval_mode, global_scale):
    """The scene's lights that render at the current frame (every light, with or without
    use_selection), evaluated, as lights.scene_lights gives them."""
    scene = context.scene
    render = eval_mode == "DAG_EVAL_RENDER"

    def shown(obj):
        return not obj.hide_render if render else obj.visible_get()

    lights = [o.evaluated_get(depsgraph) for o in scene.objects
              if o.type == "LIGHT" and shown(o)]
    geometry = [o.evaluated_get(depsgraph) for o in scene.objects
                if o.type != "LIGHT" and shown(o) and (not use_selection or o.select_get())]
    return lights_io.scene_lights(lights, lights_io.exported_centre(geometry), global_scale)


def export_sequence(context, directory, name="keys", frame_start=1, frame_end=250, frame_step=1,
                    use_selection=False, report=None, **options):
    """Writes directory/NAME_NNNNNN.obj + .mtl for frame_start, frame_start + step, ... up to
    frame_end, each with its camera block. Returns the list of OBJ paths. The scene's current
    frame is restored afterwards."""
    if not name or os.sep in name or (os.altsep and os.altsep in name):
        raise ExportError("bad sequence name %r: give a plain file name prefix such as 'keys'" % name)
    if frame_step < 1:
        raise ExportError("the frame step must be at least 1 (got %d)" % frame_step)
    if frame_end < frame_start:
        raise ExportError("the last frame %d is before the first %d" % (frame_end, frame_start))
    if frame_start < 0:
        raise ExportError("frame numbers must not be negative (got %d)" % frame_start)
    directory = bpy.path.abspath(directory) if directory else ""
    if not directory:
        raise ExportError("no output folder given")
    os.makedirs(directory, exist_ok=True)
    scene = context.scene
    if scene.camera is None:
        raise ExportError("scene '%s' has no active camera (Scene properties > Camera)" % scene.name)
    saved_frame, saved_subframe = scene.frame_current, scene.frame_subframe
    written = []
    try:
        for frame in range(frame_start, frame_end + 1, frame_step):
            scene.frame_set(frame)
            path = os.path.join(directory, frame_file_stem(name, frame) + ".obj")
            info = export_frame(context, path, use_selection=use_selection, **options)
            written.append(path)
            if report:
                report("frame %d -> %s (camera '%s', fov_x %.3f deg)"
                       % (frame, path, info["camera"], info["fov_x_degrees"]))
    finally:
        scene.frame_set(saved_frame, subframe=saved_subframe)
    return written
