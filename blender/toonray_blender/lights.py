"""The scene's lights as a toonray lights file, and the default material for objects without one.

A frame NAME_NNNNNN.obj gets NAME_NNNNNN.lights next to it (toonray's `--lights` format:
``directional dx dy dz intensity`` / ``point x y z intensity``), which ``toonray render`` and
``toonray batch`` read on their own (docs/blender.md, "Lights").

- sun -> directional, along the sun's local -Z (the way its light travels);
- point, spot -> point at the light's position (a spot's cone is not kept);
- area -> point at its centre.

Intensity: toonray's bands are thresholds on the diffuse term l.n summed over the lights,
where a light of intensity 1 gives l.n itself (0..1). Cycles lights a white diffuse surface with
strength * n.l for a sun, whatever its strength, so one light of any strength gets intensity 1:
its bands are the bands of Cycles' n.l. Between several lights the ratios are kept: each light
is weighted by the irradiance it gives a surface facing it at the centre of the exported
objects' bounds, as Cycles computes it (sun: strength; point and spot: power / (4 pi d^2), a
spot's power being that of a point light shining everywhere; area: power / (pi d^2) times the
cosine of the angle off its axis), and the brightest gets 1.
Light colour is not kept: toonray's lights are white.
"""

import math
import os

LIGHTS_SUFFIX = ".lights"
DEFAULT_MATERIAL = "toonray_default"
DEFAULT_KD = 0.8  # toonray's (and Blender's) colour of faces without a material


def _obj_axes(v):
    x, y, z = v
    return (x, z, -y)  # Blender Z-up -> the OBJ exporter's forward -Z, up Y (camera.py)


def _num(x):
    text = "%.9g" % x
    return "0" if text in ("-0", "0") else text


def light_weight(kind, energy, position, axis, centre):
    """The irradiance the light gives a surface facing it at `centre` (Blender world
    coordinates), in Cycles' units (a sun of strength S gives S, W/m^2). `axis`: the light's
    local -Z in world coordinates (unit)."""
    energy = max(0.0, energy)
    if kind == "SUN":
        return energy
    d = [c - p for c, p in zip(centre, position)]
    d2 = sum(c * c for c in d)
    if d2 <= 1e-12:
        d2 = 1e-12
    if kind == "AREA":
        cos = sum(a * c for a, c in zip(axis, d)) / math.sqrt(d2)
        return energy * max(0.0, cos) / (math.pi * d2)  # radiance power / (pi area)
    return energy / (4.0 * math.pi * d2)  # POINT, SPOT: intensity power / (4 pi)


def scene_lights(objects, centre, global_scale=1.0):
    """[(kind, vector, intensity, name)] in OBJ coordinates for the evaluated light objects
    (those that render), with intensities as the module docstring says."""
    return light_entries(((obj.name, obj.data, obj.matrix_world) for obj in objects
                          if obj.type == "LIGHT"), centre, _obj_axes, global_scale)


def light_entries(lights, centre, axes=lambda v: tuple(v), global_scale=1.0):
    """scene_lights for (name, light data, world matrix) triples: the render engine's instanced
    lights in Blender coordinates (axes: identity), the exporter's in OBJ coordinates."""
    found = []
    for name, data, m in lights:
        position = [m[i][3] for i in range(3)]
        axis = [-m[i][2] for i in range(3)]
        n = math.sqrt(sum(c * c for c in axis))
        if not n > 1e-12:
            continue  # zero scale: no direction
        axis = [c / n for c in axis]
        weight = light_weight(data.type, data.energy, position, axis, centre)
        if data.type == "SUN":
            vector = axes(axis)
            kind = "directional"
        else:
            vector = tuple(c * global_scale for c in axes(position))
            kind = "point"
        found.append([kind, vector, weight, name, data.type])
    brightest = max((f[2] for f in found), default=0.0)
    for f in found:
        f[2] = f[2] / brightest if brightest > 0 else 0.0
    return [tuple(f) for f in found]


def lights_text(lights, comment=None):
    lines = []
    if comment:
        lines.append("# " + comment)
    for kind, vector, intensity, name, blender_type in lights:
        lines.append("%s %s %s %s %s    # %s '%s'" % (
            kind, _num(vector[0]), _num(vector[1]), _num(vector[2]), _num(intensity),
            blender_type.lower(), name.replace("\n", " ")))
    return "\n".join(lines) + "\n"


def lights_path(obj_path):
    return os.path.splitext(obj_path)[0] + LIGHTS_SUFFIX


def write_lights(obj_path, lights, comment=None):
    """Writes the lights file next to obj_path, or removes a stale one when there are none."""
    path = lights_path(obj_path)
    if not lights:
        if os.path.exists(path):
            os.remove(path)
        return None
    tmp = path + ".tmp"
    with open(tmp, "w", encoding="utf-8", newline="\n") as f:
        f.write(lights_text(lights, comment))
    os.replace(tmp, path)
    return path


def exported_centre(objects):
    """Centre of the world bounds of the geometry objects (Blender coordinates), or the
    origin when there is none."""
    lo = [math.inf] * 3
    hi = [-math.inf] * 3
    for obj in objects:
        if obj.type not in ("MESH", "CURVE", "SURFACE", "FONT", "META"):
            continue
        m = obj.matrix_world
        for corner in obj.bound_box:
            p = [sum(m[i][j] * (corner[j] if j < 3 else 1.0) for j in range(4)) for i in range(3)]
            lo = [min(a, b) for a, b in zip(lo, p)]
            hi = [max(a, b) for a, b in zip(hi, p)]
    if lo[0] > hi[0]:
        return (0.0, 0.0, 0.0)
    return tuple(0.5 * (a + b) for a, b in zip(lo, hi))


def add_default_material(obj_path):
    """Gives the faces of every object that the exporter wrote without a material an explicit
    ``usemtl toonray_default`` (Kd 0.8, added to the frame's MTL file). OBJ carries the last
    material over to faces with none, so without it such an object would take the colour of
    the object written before it; in Blender it has the default surface. Does nothing when the
    file has no ``mtllib`` (materials not exported: every face has the default then).
    Returns the number of objects given the default material."""
    mtllib = None
    with open(obj_path, "r", encoding="utf-8", errors="surrogateescape") as f:
        for line in f:
            if line.startswith("mtllib "):
                mtllib = line[len("mtllib "):].strip()
                break
            if line.startswith(("o ", "f ")):
                break
    if not mtllib:
        return 0
    mtl_path = os.path.join(os.path.dirname(obj_path), mtllib)
    existing = set()
    if os.path.exists(mtl_path):
        with open(mtl_path, "r", encoding="utf-8", errors="surrogateescape") as f:
            existing = {l.split(None, 1)[1].strip() for l in f if l.startswith("newmtl ")}
    name = DEFAULT_MATERIAL
    suffix = 1
    while name in existing:
        name = "%s_%d" % (DEFAULT_MATERIAL, suffix)
        suffix += 1
    # Blender's exporter writes "o NAME" per object (object groups are off), then its faces,
    # each run of them after "usemtl" when the object has materials ("usemtl " with no name
    # for an empty slot, which toonray reads as the default material).
    has_material = False
    count = 0
    tmp = obj_path + ".tmp"
    with open(obj_path, "r", encoding="utf-8", errors="surrogateescape", newline="") as src, \
            open(tmp, "w", encoding="utf-8", errors="surrogateescape", newline="") as out:
        for line in src:
            if line.startswith("o "):
                has_material = False
            elif line.startswith("usemtl"):
                has_material = True
            elif line.startswith("f ") and not has_material:
                out.write("usemtl %s\n" % name)
                has_material = True
                count += 1
            out.write(line)
    if count == 0:
        os.remove(tmp)
        return 0
    os.replace(tmp, obj_path)
    with open(mtl_path, "a", encoding="utf-8", newline="\n") as f:
        f.write("\n# toonray's default material, for objects without one\nnewmtl %s\n"
                "Kd %s %s %s\n" % (name, DEFAULT_KD, DEFAULT_KD, DEFAULT_KD))
    return count
