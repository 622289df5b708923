"""toonray add-on for Blender 3.4 and newer (docs/blender.md).

The toonray render engine (``bl_idname`` "TOONRAY", engine.py): F12, animations and the viewport
render in process through the toonray Python module (module.py finds it), with Blender's passes,
line sets and an SVG per frame. Registered when the module loads; the tools below work without
it.

Two operators:

- File > Export > toonray OBJ sequence: ``bpy.ops.export_scene.toonray_obj_sequence`` writes
  NAME_NNNNNN.obj + .mtl per frame with Blender's own OBJ exporter and appends toonray's camera
  block (eye, gaze, up of the scene's active camera; the gaze distance sets the horizontal
  field of view).
- Object > Animation > Animate Piano Keys from Note Script:
  ``bpy.ops.anim.toonray_keys_from_notes`` keys the rotation of objects named w1..w52 /
  b1..b36 (with an optional prefix) from a toonray note script, timed as ``toonray piano``.

Blender 3.4 to 4.1 read ``bl_info``; 4.2 and newer read blender_manifest.toml (and can still
install this folder or zip as a legacy add-on).
"""

bl_info = {
    "name": "toonray",
    "author": "toonray",
    "version": (1, 0, 0),
    "blender": (3, 4, 0),
    "location": "Render Engine > toonray; File > Export > toonray OBJ sequence; "
                "Object > Animation > Animate Piano Keys",
    "description": "The toonray render engine (toon shading, ink lines, SVG); OBJ sequences "
                   "with toonray's camera block; piano keys from a toonray note script",
    "category": "Render",
}

if "bpy" in locals():  # reload (F3 > Reload Scripts)
    import importlib

    for _m in (note_script, camera, lights, exporter, keys, module, sync,  # noqa: F821
               properties, engine, preview, ui):  # noqa: F821
        importlib.reload(_m)

import bpy
from bpy.props import (BoolProperty, EnumProperty, FloatProperty, IntProperty, StringProperty)
from bpy.types import Operator

from . import camera, exporter, keys, lights, module, note_script  # noqa: F401


class TOONRAY_OT_export_obj_sequence(Operator):
    """Export frames as NAME_NNNNNN.obj + .mtl with toonray's camera block"""

    bl_idname = "export_scene.toonray_obj_sequence"
    bl_label = "Export toonray OBJ Sequence"
    bl_options = {"REGISTER", "PRESET"}

    directory: StringProperty(name="Output Folder", subtype="DIR_PATH",
                              description="Folder for the OBJ and MTL files")
    filter_folder: BoolProperty(default=True, options={"HIDDEN"})
    filter_glob: StringProperty(default="*.obj;*.mtl", options={"HIDDEN"})
    name: StringProperty(name="Name", default="keys",
                         description="File name prefix: NAME_NNNNNN.obj (as toonray batch NAME reads)")
    use_scene_range: BoolProperty(name="Scene Frame Range", default=False,
                                  description="Export the scene's frame range instead of Start/End")
    frame_start: IntProperty(name="Start", default=1, min=0, description="First frame")
    frame_end: IntProperty(name="End", default=250, min=0, description="Last frame")
    frame_step: IntProperty(name="Step", default=1, min=1, description="Export every Nth frame")
    use_selection: BoolProperty(name="Selection Only", default=False,
                                description="Export the selected objects only")
    apply_modifiers: BoolProperty(name="Apply Modifiers", default=True)
    eval_mode: EnumProperty(name="Properties", default="DAG_EVAL_VIEWPORT",
                            items=(("DAG_EVAL_VIEWPORT", "Viewport", "Objects as in the viewport"),
                                   ("DAG_EVAL_RENDER", "Render", "Objects as in the render")))
    triangulate: BoolProperty(name="Triangulate", default=True,
                              description="Triangulate faces in Blender (toonray fans polygons, "
                                          "which is wrong for concave n-gons)")
    export_normals: BoolProperty(name="Normals", default=True)
    export_uv: BoolProperty(name="UVs", default=True)
    export_materials: BoolProperty(name="Materials", default=True)
    global_scale: FloatProperty(name="Scale", default=1.0, min=0.0001, max=10000.0)

    def invoke(self, context, event):
        scene = context.scene
        if not self.properties.is_property_set("frame_start"):
            self.frame_start = max(0, scene.frame_start)
        if not self.properties.is_property_set("frame_end"):
            self.frame_end = max(0, scene.frame_end)
        context.window_manager.fileselect_add(self)
        return {"RUNNING_MODAL"}

    def execute(self, context):
        scene = context.scene
        start, end = (scene.frame_start, scene.frame_end) if self.use_scene_range else (
            self.frame_start, self.frame_end)
        # self.properties.name: bpy.types.Operator itself has a read-only "name" (its label).
        try:
            files = exporter.export_sequence(
                context, self.directory, name=self.properties.name, frame_start=start,
                frame_end=end,
                frame_step=self.frame_step, use_selection=self.use_selection,
                global_scale=self.global_scale, apply_modifiers=self.apply_modifiers,
                eval_mode=self.eval_mode, triangulate=self.triangulate,
                export_normals=self.export_normals, export_uv=self.export_uv,
                export_materials=self.export_materials)
        except (exporter.ExportError, camera.CameraError, OSError) as e:
            self.report({"ERROR"}, str(e))
            return {"CANCELLED"}
        self.report({"INFO"}, "toonray: wrote %d frames to %s" % (len(files), self.directory))
        return {"FINISHED"}

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        layout.prop(self.properties, "name")
        layout.prop(self, "use_scene_range")
        col = layout.column(align=True)
        col.enabled = not self.use_scene_range
        col.prop(self, "frame_start")
        col.prop(self, "frame_end")
        layout.prop(self, "frame_step")
        layout.prop(self, "use_selection")
        layout.prop(self, "apply_modifiers")
        layout.prop(self, "eval_mode")
        layout.prop(self, "triangulate")
        layout.prop(self, "export_normals")
        layout.prop(self, "export_uv")
        layout.prop(self, "export_materials")
        layout.prop(self, "global_scale")


class TOONRAY_OT_keys_from_notes(Operator):
    """Key the rotation of piano key objects (w1..w52, b1..b36) from a toonray note script"""

    bl_idname = "anim.toonray_keys_from_notes"
    bl_label = "Animate Piano Keys from Note Script"
    bl_options = {"REGISTER", "UNDO"}

    filepath: StringProperty(name="Note Script", subtype="FILE_PATH",
                             description="A toonray note script (.notes)")
    filter_glob: StringProperty(default="*.notes;*.txt", options={"HIDDEN"})
    prefix: StringProperty(name="Name Prefix", default="",
                           description="Key objects are PREFIX + w1..w52 and PREFIX + b1..b36")
    start_frame: FloatProperty(name="Start Frame", default=1.0,
                               description="Frame at which the score's time 0 falls")
    tempo: FloatProperty(name="Tempo", default=0.0, min=0.0, max=60000.0,
                         description="Quarter notes per minute until the script's first 'tempo' "
                                     "line; 0 = the script's default, 72")
    axis: EnumProperty(name="Axis", default="X",
                       items=(("X", "X", "Local X"), ("Y", "Y", "Local Y"), ("Z", "Z", "Local Z")),
                       description="Euler rotation channel the keys turn on")
    angle: FloatProperty(name="Angle", default=0.042, subtype="ANGLE",
                         description="Rotation of a fully pressed key (toonray's piano: 0.042 rad); "
                                     "negative turns the other way")
    mode: EnumProperty(name="Keyframes", default="PRESS",
                       items=(("PRESS", "Per Press", "Four linear keyframes per press: exact at "
                                                     "every frame"),
                              ("FRAME", "Per Frame", "One keyframe per frame while a key moves")))
    replace: BoolProperty(name="Replace", default=True,
                          description="Remove the keys' existing keyframes on that channel first")

    def invoke(self, context, event):
        context.window_manager.fileselect_add(self)
        return {"RUNNING_MODAL"}

    def execute(self, context):
        messages = []
        try:
            summary = keys.animate_keys(
                context.scene, notes_path=self.filepath, prefix=self.prefix,
                start_frame=self.start_frame, tempo_bpm=self.tempo, axis=self.axis,
                angle=self.angle, mode=self.mode, replace=self.replace, report=messages.append)
        except keys.KeyAnimationError as e:
            self.report({"ERROR"}, str(e))
            return {"CANCELLED"}
        for m in messages:
            self.report({"WARNING"} if m.startswith("warning") else {"INFO"}, m)
        if summary["keys_animated"] == 0:
            self.report({"WARNING"}, "no key object is played by the script")
        return {"FINISHED"}


def _menu_export(self, context):
    self.layout.operator(TOONRAY_OT_export_obj_sequence.bl_idname,
                         text="toonray OBJ sequence (.obj + camera)")


def _menu_animation(self, context):
    self.layout.operator(TOONRAY_OT_keys_from_notes.bl_idname,
                         text="Animate Piano Keys from Note Script")


_classes = (TOONRAY_OT_export_obj_sequence, TOONRAY_OT_keys_from_notes)


_engine_registered = False


def register():
    global _engine_registered
    for c in _classes:
        bpy.utils.register_class(c)
    bpy.types.TOPBAR_MT_file_export.append(_menu_export)
    bpy.types.VIEW3D_MT_object_animation.append(_menu_animation)
    tr = module.load()
    if tr is None:
        print("toonray: the render engine is not available: %s" % module.import_error)
        return
    from . import engine, properties, ui
    properties.register(tr)
    bpy.utils.register_class(engine.ToonrayRenderEngine)
    ui.register()
    _engine_registered = True


def unregister():
    global _engine_registered
    if _engine_registered:
        from . import engine, properties, ui
        ui.unregister()
        bpy.utils.unregister_class(engine.ToonrayRenderEngine)
        properties.unregister()
        _engine_registered = False
    bpy.types.VIEW3D_MT_object_animation.remove(_menu_animation)
    bpy.types.TOPBAR_MT_file_export.remove(_menu_export)
    for c in reversed(_classes):
        bpy.utils.unregister_class(c)
