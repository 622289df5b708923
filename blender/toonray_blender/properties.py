"""The render engine's properties: the settings document, line sets, object usage and material
line colours (docs/blender.md, "Settings").

The Render properties are made from the module's table of settings keys
(``toonray.setting_keys()``) when the add-on registers: one Blender property per key with the
table's default and help, so the engine has no copy of the option set and a key added to the
library shows up here. Blender gives the image size, camera and lights itself, and writes the
image files, so those keys are left out. ``settings_document`` turns the properties back into
the document's dict, with the line sets, Occlusion Only objects and material line colours as
its line rules.
"""

import bpy
from bpy.props import (BoolProperty, CollectionProperty, EnumProperty, FloatProperty,
                       FloatVectorProperty, IntProperty, PointerProperty, StringProperty)
from bpy.types import PropertyGroup

from . import sync

# Keys whose values Blender gives: the frame size (Output properties), the camera and lights
# (the scene's objects) and the PNG encoding (Blender writes the files).
BLENDER_GIVES = {"image.size", "scene.camera", "scene.lights", "output.png_level"}
# How a key's text is shown when a plain text field would not do.
COLOUR_KEYS = {"image.background", "lines.colour"}
# Keys unset by default (None): a checkbox turns them on, with this value to start from.
OPTIONAL_DEFAULTS = {"scene.auto_smooth": 30.0}

SECTIONS = (("shading", "Shading"), ("tone", "Tone"), ("lines", "Lines"),
            ("sampling", "Sampling"), ("image", "Image"), ("render", "Performance"),
            ("output", "SVG"), ("scene", "Scene"), ("limits", "Limits"))

_settings_keys = []  # [(key, kind)], in the table's order, filled by register()


def prop_name(key):
    return key.replace(".", "__")


def label(key):
    return key.rsplit(".", 1)[1].replace("_", " ").title()


def parse_colour(text):
    text = text.strip()
    if text.startswith("#") and len(text) == 7:
        return tuple(int(text[i:i + 2], 16) / 255.0 for i in (1, 3, 5))
    return tuple(float(c) for c in text.split(","))


def _types_default(text, names):
    if text == "all":
        return set(names)
    if text == "none":
        return set()
    return set(text.split(","))


def _annotations(tr):
    """The settings group's properties, one per key of the table."""
    annotations = {}
    keys = []
    for row in tr.setting_keys():
        key, default, help_text = row["key"], row["default"], row["help"]
        if key in BLENDER_GIVES:
            continue
        name = prop_name(key)
        if key == "lines.mode":
            items = [(m, m.title(), "") for m in tr.LINE_MODES]
            annotations[name] = EnumProperty(name=label(key), description=help_text, items=items,
                                             default=default)
            kind = "enum"
        elif key == "lines.types":
            items = [(t, t.title(), "") for t in tr.LINE_TYPES]
            annotations[name] = EnumProperty(name=label(key), description=help_text, items=items,
                                             options={"ENUM_FLAG"},
                                             default=_types_default(default, tr.LINE_TYPES))
            kind = "flags"
        elif key in COLOUR_KEYS:
            annotations[name] = FloatVectorProperty(name=label(key), description=help_text,
                                                    subtype="COLOR_GAMMA", size=3, min=0.0,
                                                    max=1.0, default=parse_colour(default))
            kind = "colour"
        elif default is None:
            annotations["use_" + name] = BoolProperty(name=label(key), description=help_text)
            start = OPTIONAL_DEFAULTS.get(key)
            if isinstance(start, float):
                annotations[name] = FloatProperty(name=label(key), description=help_text,
                                                  default=start)
            else:
                annotations[name] = StringProperty(name=label(key), description=help_text)
            kind = "optional"
        elif isinstance(default, bool):
            annotations[name] = BoolProperty(name=label(key), description=help_text,
                                             default=default)
            kind = "value"
        elif isinstance(default, int):
            annotations[name] = IntProperty(name=label(key), description=help_text,
                                            default=default)
            kind = "value"
        elif isinstance(default, float):
            annotations[name] = FloatProperty(name=label(key), description=help_text,
                                              default=default)
            kind = "value"
        else:
            annotations[name] = StringProperty(name=label(key), description=help_text,
                                               default=str(default))
            kind = "value"
        keys.append((key, kind))
    annotations["use_svg"] = BoolProperty(
        name="SVG", description="Also write each frame's lines as SVG beside the frame's output "
                                "file (NAME.svg), with the visible and hidden layers")
    return annotations, keys


def setting_keys():
    return _settings_keys


def settings_values(props, tr):
    """The render settings' keys and values from the scene's properties."""
    out = {}
    for key, kind in _settings_keys:
        name = prop_name(key)
        value = getattr(props, name)
        if kind == "flags":
            chosen = [t for t in tr.LINE_TYPES if t in value]
            out[key] = ",".join(chosen) if chosen else "none"
        elif kind == "colour":
            out[key] = tuple(float(c) for c in value)
        elif kind == "optional":
            if getattr(props, "use_" + name):
                out[key] = value
        else:
            out[key] = value
    return out


def apply_values(props, values, tr):
    """Sets the properties from a settings dict (toonray.settings()), for import."""
    for key, kind in _settings_keys:
        if key not in values:
            continue
        name = prop_name(key)
        value = values[key]
        if kind == "flags":
            setattr(props, name, _types_default(value, tr.LINE_TYPES))
        elif kind == "colour":
            setattr(props, name, parse_colour(value))
        elif kind == "optional":
            setattr(props, "use_" + name, value is not None)
            if value is not None:
                setattr(props, name, type(getattr(props, name))(value))
        else:
            setattr(props, name, value)


# ---- Line sets (View Layer) -------------------------------------------------------------------

VISIBILITY = (("VISIBLE", "Visible", "Lines that are seen"),
              ("HIDDEN", "Hidden", "Lines behind surfaces"),
              ("ALL", "All", "Both"))
PEN = ("draw", "color", "width", "opacity", "dash", "taper", "width_by_depth")


def _edge_items(self, context):
    from . import module
    tr = module.load()
    names = tr.EDGE_TYPES if tr else ["silhouette", "border", "crease", "material",
                                      "intersection", "polyline"]
    return [(n, n.title(), "") for n in names]


class ToonrayLineSet(PropertyGroup):
    """A line set: which lines (objects, collection, materials, types, visibility) and the pen
    they are drawn with; one line rule of the settings document."""

    show: BoolProperty(name="Enabled", default=True)
    collection: PointerProperty(name="Collection", type=bpy.types.Collection,
                                description="Lines of the objects in this collection")
    objects: StringProperty(name="Objects", description="Object names, comma-separated, with * "
                                                        "and ? (empty: every object)")
    materials: StringProperty(name="Materials", description="Material names, comma-separated, "
                                                            "with * and ? (empty: every one)")
    edge_types: EnumProperty(name="Edge Types", items=_edge_items, options={"ENUM_FLAG"},
                             description="Line types it selects (none: all)")
    visibility: EnumProperty(name="Visibility", items=VISIBILITY, default="VISIBLE")
    use_draw: BoolProperty(name="Draw", default=True)
    draw: BoolProperty(name="Draw", default=True, description="Whether the lines are drawn")
    use_color: BoolProperty(name="Colour", default=True)
    color: FloatVectorProperty(name="Colour", subtype="COLOR_GAMMA", size=3, min=0.0, max=1.0,
                               default=(0.0, 0.0, 0.0))
    use_width: BoolProperty(name="Width", default=True)
    width: FloatProperty(name="Width", default=2.0, min=0.0, max=100.0,
                         description="Pixels at 720 lines; scales with the image height")
    use_opacity: BoolProperty(name="Opacity", default=False)
    opacity: FloatProperty(name="Opacity", default=1.0, min=0.0, max=1.0, subtype="FACTOR")
    use_dash: BoolProperty(name="Dash", default=False)
    dash: StringProperty(name="Dash", default="4,2",
                         description="On, off, ... lengths in pixels at 720 lines")
    use_taper: BoolProperty(name="Taper", default=False)
    taper: FloatProperty(name="Taper", default=6.0, min=0.0, max=1000.0)
    use_width_by_depth: BoolProperty(name="Width by Depth", default=False)
    width_by_depth: BoolProperty(name="Width by Depth", default=True)

    def rule(self):
        """The line rule (a dict of the rule's keys) of this line set, or None when it selects
        no object."""
        rule = {}
        objects = [n.strip() for n in self.objects.split(",") if n.strip()]
        if self.collection is not None:
            objects += [o.name for o in self.collection.all_objects]
        if self.collection is not None and not objects:
            return None  # an empty collection: no lines to style
        if objects:
            rule["object"] = sync.glob_list(objects)
        materials = [n.strip() for n in self.materials.split(",") if n.strip()]
        if materials:
            rule["material"] = ",".join(materials)
        if self.edge_types:
            rule["type"] = ",".join(sorted(self.edge_types))
        rule["lines"] = self.visibility.lower()
        for attribute in PEN:
            if getattr(self, "use_" + attribute):
                value = getattr(self, attribute)
                rule[attribute] = tuple(value) if attribute == "color" else value
        return rule


def line_set_from_rule(line_set, rule):
    """Fills a line set from a line rule's entries (toonray.settings()['lines.rule'][i])."""
    line_set.objects = rule.get("object", "") if rule.get("object", "*") != "*" else ""
    line_set.materials = rule.get("material", "") if rule.get("material", "*") != "*" else ""
    types = rule.get("type", "all")
    line_set.edge_types = set() if types == "all" else set(types.split(","))
    line_set.visibility = rule.get("lines", "visible").upper()
    for attribute in PEN:
        text = rule.get(attribute)
        setattr(line_set, "use_" + attribute, text is not None)
        if text is None:
            continue
        if attribute in ("draw", "width_by_depth"):
            setattr(line_set, attribute, text == "yes")
        elif attribute == "color":
            line_set.color = parse_colour(text)
        elif attribute == "dash":
            line_set.dash = text
        else:
            setattr(line_set, attribute, float(text))


class ToonrayViewLayerSettings(PropertyGroup):
    line_sets: CollectionProperty(type=ToonrayLineSet)
    active_line_set: IntProperty(name="Active Line Set")
    use_pass_lines: BoolProperty(name="Lines", default=True,
                                 description="The Lines pass: every line's coverage")
    use_pass_line_types: BoolProperty(name="Line Types", default=False,
                                      description="One pass per line type of the line mode "
                                                  "(Lines Silhouette, ...)")


class ToonrayObjectSettings(PropertyGroup):
    usage: EnumProperty(
        name="Lines", default="INCLUDE",
        items=(("INCLUDE", "Include", "Rendered, draws its lines and hides what is behind it"),
               ("OCCLUSION", "Occlusion Only", "Rendered and hides lines behind it, but draws "
                                               "no lines of its own"),
               ("EXCLUDE", "Exclude", "Left out of toonray's render: no surface, no lines")),
        description="How the object takes part in toonray's lines (as Line Art's usage)")


class ToonrayMaterialSettings(PropertyGroup):
    use_line_color: BoolProperty(name="Line Colour", default=False,
                                 description="Draw this material's lines in their own colour")
    line_color: FloatVectorProperty(name="Line Colour", subtype="COLOR_GAMMA", size=3, min=0.0,
                                    max=1.0, default=(0.0, 0.0, 0.0))


def settings_document(scene, view_layer, tr, synced=None):
    """The settings document (a dict for toonray.render) of a scene and view layer: the Render
    properties, then the line rules: the view layer's line sets in order, the materials' line
    colours, and last the objects that draw no lines (Occlusion Only, holdout)."""
    document = settings_values(scene.toonray, tr)
    rules = []
    layer_settings = getattr(view_layer, "toonray", None)
    if layer_settings is not None:
        rules += [r for r in (ls.rule() for ls in layer_settings.line_sets if ls.show) if r]
    for material in bpy.data.materials:
        settings = getattr(material, "toonray", None)
        if settings is not None and settings.use_line_color and sync.glob_list([material.name]):
            rules.append({"material": material.name, "lines": "all",
                          "color": tuple(settings.line_color)})
    if synced is not None:
        rules += sync.holdout_rules(synced)
    document["lines.rule"] = rules
    return document


_groups = []


def register(tr):
    global _settings_keys
    annotations, _settings_keys = _annotations(tr)
    group = type("ToonraySceneSettings", (PropertyGroup,), {
        "__annotations__": annotations,
        "__doc__": "toonray's render settings (the settings document's keys)"})
    for cls in (group, ToonrayLineSet, ToonrayViewLayerSettings, ToonrayObjectSettings,
                ToonrayMaterialSettings):
        bpy.utils.register_class(cls)
        _groups.append(cls)
    bpy.types.Scene.toonray = PointerProperty(type=group)
    bpy.types.ViewLayer.toonray = PointerProperty(type=ToonrayViewLayerSettings)
    bpy.types.Object.toonray = PointerProperty(type=ToonrayObjectSettings)
    bpy.types.Material.toonray = PointerProperty(type=ToonrayMaterialSettings)


def unregister():
    for owner in (bpy.types.Material, bpy.types.Object, bpy.types.ViewLayer, bpy.types.Scene):
        if hasattr(owner, "toonray"):
            del owner.toonray
    for cls in reversed(_groups):
        bpy.utils.unregister_class(cls)
    _groups.clear()
