"""The render engine's panels and operators (docs/blender.md, "Panels"): Render (the settings
document, its import and export), View Layer (passes and line sets), Object (line usage) and
Material (line colour); Blender's own panels that apply (output, dimensions, colour management,
camera, light, material surface) are shown for the engine too."""

import bpy
from bpy.props import IntProperty, StringProperty
from bpy.types import Operator, Panel, UIList
from bpy_extras.io_utils import ExportHelper, ImportHelper

from . import module, properties, sync

ENGINE = "TOONRAY"


class ToonrayPanel:
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    COMPAT_ENGINES = {ENGINE}

    @classmethod
    def poll(cls, context):
        return context.engine in cls.COMPAT_ENGINES


# ---- Render ----------------------------------------------------------------------------------

class TOONRAY_PT_render(ToonrayPanel, Panel):
    bl_label = "toonray"
    bl_context = "render"

    def draw(self, context):
        layout = self.layout
        if module.load() is None:
            layout.label(text=module.import_error, icon="ERROR")
            return
        row = layout.row(align=True)
        row.operator("toonray.settings_import", icon="IMPORT")
        row.operator("toonray.settings_export", icon="EXPORT")


def _toggled(layout, data, use, name, heading):
    """A row whose checkbox (`use`) says whether the value (`name`) applies."""
    row = layout.row(heading=heading)
    row.prop(data, use, text="")
    sub = row.row()
    sub.active = getattr(data, use)
    sub.prop(data, name, text="")


def _draw_keys(layout, props, section):
    layout.use_property_split = True
    layout.use_property_decorate = False
    for key, kind in properties.setting_keys():
        if key.split(".", 1)[0] != section:
            continue
        name = properties.prop_name(key)
        if kind == "optional":
            _toggled(layout, props, "use_" + name, name, properties.label(key))
        elif kind == "flags":
            layout.prop(props, name, expand=True)
        else:
            layout.prop(props, name)


def _section_panel(section, title, order):
    def draw(self, context):
        props = context.scene.toonray
        if section == "output":
            self.layout.use_property_split = True
            self.layout.prop(props, "use_svg")
        _draw_keys(self.layout, props, section)

    return type("TOONRAY_PT_render_" + section, (ToonrayPanel, Panel), {
        "bl_label": title, "bl_context": "render", "bl_parent_id": "TOONRAY_PT_render",
        "bl_order": order, "bl_options": {"DEFAULT_CLOSED"} if section == "limits" else set(),
        "poll": classmethod(lambda cls, context: ToonrayPanel.poll.__func__(cls, context)
                            and hasattr(context.scene, "toonray")),
        "draw": draw})


class TOONRAY_OT_settings_export(Operator, ExportHelper):
    """Write the render settings and line sets as a toonray settings document (TOML), as
    `toonray render --settings FILE` reads it"""
    bl_idname = "toonray.settings_export"
    bl_label = "Export Settings"
    filename_ext = ".toml"
    filter_glob: StringProperty(default="*.toml", options={"HIDDEN"})

    def execute(self, context):
        tr = module.load()
        try:
            document = properties.settings_document(context.scene, context.view_layer, tr)
            # The frame size from the Output properties, so that `toonray render --settings`
            # renders the same frame without --size.
            document["image.size"] = "%dx%d" % sync.frame_size(context.scene)
            text = tr.settings_toml(document)
            with open(self.filepath, "w", encoding="utf-8", newline="\n") as f:
                f.write(text)
        except (tr.Error, OSError) as e:
            self.report({"ERROR"}, "toonray: %s" % e)
            return {"CANCELLED"}
        return {"FINISHED"}


class TOONRAY_OT_settings_import(Operator, ImportHelper):
    """Read a toonray settings document (TOML) into the render settings; its line rules become
    the view layer's line sets"""
    bl_idname = "toonray.settings_import"
    bl_label = "Import Settings"
    filename_ext = ".toml"
    filter_glob: StringProperty(default="*.toml", options={"HIDDEN"})

    def execute(self, context):
        tr = module.load()
        try:
            values = tr.settings(self.filepath)
        except (tr.Error, OSError) as e:
            self.report({"ERROR"}, "toonray: %s" % e)
            return {"CANCELLED"}
        properties.apply_values(context.scene.toonray, values, tr)
        line_sets = context.view_layer.toonray.line_sets
        line_sets.clear()
        for i, rule in enumerate(values["lines.rule"]):
            line_set = line_sets.add()
            line_set.name = "Rule %d" % (i + 1)
            properties.line_set_from_rule(line_set, rule)
        return {"FINISHED"}


# ---- View Layer ------------------------------------------------------------------------------

class TOONRAY_PT_view_layer_passes(ToonrayPanel, Panel):
    bl_label = "Passes"
    bl_context = "view_layer"

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        layout.use_property_decorate = False
        view_layer = context.view_layer
        col = layout.column(heading="Data", align=True)
        col.prop(view_layer, "use_pass_combined")
        col.prop(view_layer, "use_pass_z")
        col.prop(view_layer, "use_pass_normal")
        col.prop(view_layer, "use_pass_object_index")
        col.prop(view_layer, "use_pass_material_index")
        col = layout.column(heading="Lines", align=True)
        col.prop(view_layer.toonray, "use_pass_lines")
        col.prop(view_layer.toonray, "use_pass_line_types")


class TOONRAY_UL_line_sets(UIList):
    def draw_item(self, context, layout, data, item, icon, active_data, active_propname, index):
        row = layout.row(align=True)
        row.prop(item, "show", text="")
        row.prop(item, "name", text="", emboss=False)


class TOONRAY_PT_line_sets(ToonrayPanel, Panel):
    bl_label = "Line Sets"
    bl_context = "view_layer"

    def draw(self, context):
        layout = self.layout
        settings = context.view_layer.toonray
        row = layout.row()
        row.template_list("TOONRAY_UL_line_sets", "", settings, "line_sets", settings,
                          "active_line_set", rows=3)
        col = row.column(align=True)
        col.operator("toonray.line_set_add", icon="ADD", text="")
        col.operator("toonray.line_set_remove", icon="REMOVE", text="")
        col.separator()
        col.operator("toonray.line_set_move", icon="TRIA_UP", text="").direction = -1
        col.operator("toonray.line_set_move", icon="TRIA_DOWN", text="").direction = 1
        if not 0 <= settings.active_line_set < len(settings.line_sets):
            layout.label(text="Line sets style the ink lines, in order; later ones win")
            return
        line_set = settings.line_sets[settings.active_line_set]
        layout.use_property_split = True
        layout.use_property_decorate = False
        box = layout.column(heading="Select")
        box.prop(line_set, "collection")
        box.prop(line_set, "objects")
        box.prop(line_set, "materials")
        box.prop(line_set, "visibility", expand=True)
        layout.prop(line_set, "edge_types", expand=True)
        pen = layout.column(heading="Pen")
        for attribute in properties.PEN:
            _toggled(pen, line_set, "use_" + attribute, attribute,
                     line_set.bl_rna.properties[attribute].name)


class TOONRAY_OT_line_set_add(Operator):
    """Add a line set"""
    bl_idname = "toonray.line_set_add"
    bl_label = "Add Line Set"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        settings = context.view_layer.toonray
        line_set = settings.line_sets.add()
        line_set.name = "LineSet %d" % len(settings.line_sets)
        settings.active_line_set = len(settings.line_sets) - 1
        return {"FINISHED"}


class TOONRAY_OT_line_set_remove(Operator):
    """Remove the active line set"""
    bl_idname = "toonray.line_set_remove"
    bl_label = "Remove Line Set"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        settings = context.view_layer.toonray
        if 0 <= settings.active_line_set < len(settings.line_sets):
            settings.line_sets.remove(settings.active_line_set)
            settings.active_line_set = max(0, settings.active_line_set - 1)
        return {"FINISHED"}


class TOONRAY_OT_line_set_move(Operator):
    """Move the active line set up or down (later line sets win)"""
    bl_idname = "toonray.line_set_move"
    bl_label = "Move Line Set"
    bl_options = {"REGISTER", "UNDO"}
    direction: IntProperty(default=-1)

    def execute(self, context):
        settings = context.view_layer.toonray
        i, j = settings.active_line_set, settings.active_line_set + self.direction
        if 0 <= i < len(settings.line_sets) and 0 <= j < len(settings.line_sets):
            settings.line_sets.move(i, j)
            settings.active_line_set = j
        return {"FINISHED"}


# ---- Object and Material ---------------------------------------------------------------------

class TOONRAY_PT_object(ToonrayPanel, Panel):
    bl_label = "toonray Lines"
    bl_context = "object"

    @classmethod
    def poll(cls, context):
        return super().poll(context) and context.object is not None

    def draw(self, context):
        self.layout.use_property_split = True
        self.layout.prop(context.object.toonray, "usage")


class TOONRAY_PT_material(ToonrayPanel, Panel):
    bl_label = "toonray Lines"
    bl_context = "material"

    @classmethod
    def poll(cls, context):
        return super().poll(context) and context.material is not None

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        _toggled(layout, context.material.toonray, "use_line_color", "line_color", "Line Colour")


# ---- Blender's own panels --------------------------------------------------------------------

# Panels of other engines that describe what toonray reads too: the material's surface nodes
# (the base colour), the light's type and strength.
_ALSO = {"EEVEE_MATERIAL_PT_context_material", "EEVEE_MATERIAL_PT_surface", "DATA_PT_EEVEE_light"}
# Blender's passes panels list passes toonray does not make; it has its own.
_NOT = {"VIEWLAYER_PT_layer_passes", "VIEWLAYER_PT_filter"}


def _blender_panels():
    for panel in bpy.types.Panel.__subclasses__():
        engines = getattr(panel, "COMPAT_ENGINES", None)
        if not isinstance(engines, set) or panel.__name__ in _NOT:
            continue
        if "BLENDER_RENDER" in engines or panel.__name__ in _ALSO:
            yield panel


_classes = [TOONRAY_PT_render, TOONRAY_OT_settings_export, TOONRAY_OT_settings_import,
            TOONRAY_PT_view_layer_passes, TOONRAY_UL_line_sets, TOONRAY_PT_line_sets,
            TOONRAY_OT_line_set_add, TOONRAY_OT_line_set_remove, TOONRAY_OT_line_set_move,
            TOONRAY_PT_object, TOONRAY_PT_material]
_registered = []


def register():
    for cls in _classes:
        bpy.utils.register_class(cls)
        _registered.append(cls)
    for order, (section, title) in enumerate(properties.SECTIONS):
        if any(key.split(".", 1)[0] == section for key, _ in properties.setting_keys()):
            cls = _section_panel(section, title, order)
            bpy.utils.register_class(cls)
            _registered.append(cls)
    for panel in _blender_panels():
        panel.COMPAT_ENGINES.add(ENGINE)


def unregister():
    for panel in _blender_panels():
        panel.COMPAT_ENGINES.discard(ENGINE)
    for cls in reversed(_registered):
        bpy.utils.unregister_class(cls)
    _registered.clear()
