"""A Blender scene as a toonray scene, in process (docs/blender.md, "Scene data").

- Geometry: every mesh entry of ``depsgraph.object_instances`` (modifiers evaluated; linked
  duplicates, collection instances and particles included). Text, curves, surfaces and
  metaballs come as mesh entries too: Blender (3.0 and newer) lists such an object once as
  itself and once as the mesh it evaluates to, whose ``original`` is the object; only the mesh
  is read, so nothing is read twice.
- Each unique mesh is uploaded once (``calc_loop_triangles`` and ``foreach_get`` into numpy) and
  placed by its instances' world matrices (``Scene.add_instance``).
- Materials: the Principled BSDF's base colour, else the viewport display colour, else toonray's
  default (Kd 0.8); an Image Texture on the base colour becomes map_Kd with the mesh's UVs.
- Objects hidden for the render are not in the render depsgraph; an object whose toonray usage
  is Exclude is left out; one whose usage is Occlusion Only hides what is behind it but draws
  no lines of its own; a holdout object does the same and the engine makes its pixels
  transparent (Combined RGBA 0, as Blender's holdout).
- The camera with its lens, sensor fit, shift and pixel aspect; clipping drops the objects
  whose bounds lie wholly nearer than clip start or farther than clip end.
- Lights by the exporter's rules (lights.py), in Blender's coordinates.

Coordinates stay Blender's (Z up): toonray's camera is an eye, a gaze point and an up vector.
"""

import math

import numpy as np

from . import lights as lights_rules

DEFAULT_KD = (0.8, 0.8, 0.8)


class SyncError(Exception):
    pass


def _socket_colour(socket):
    value = socket.default_value
    return (float(value[0]), float(value[1]), float(value[2]))


def _surface_node(material):
    """The shader node feeding the active material output's Surface, or None."""
    tree = material.node_tree if material.use_nodes else None
    if tree is None:
        return None
    outputs = [n for n in tree.nodes if n.type == "OUTPUT_MATERIAL"]
    active = [n for n in outputs if n.is_active_output] or outputs
    if not active:
        return None
    surface = active[0].inputs.get("Surface")
    if surface is None or not surface.is_linked:
        return None
    return surface.links[0].from_node


def material_fields(material):
    """toonray material fields of a Blender material: kd (and map_kd, ks, ns)."""
    fields = {"kd": DEFAULT_KD, "map_kd": ""}
    if material is None:
        return fields
    fields["kd"] = tuple(float(c) for c in material.diffuse_color[:3])
    node = _surface_node(material)
    if node is not None:
        colour = node.inputs.get("Base Color") or node.inputs.get("Color")
        if colour is not None:
            fields["kd"] = _socket_colour(colour)
            if colour.is_linked:
                source = colour.links[0].from_node
                if source.type == "TEX_IMAGE" and source.image is not None:
                    import bpy
                    path = bpy.path.abspath(source.image.filepath, library=source.image.library)
                    if path:
                        fields["map_kd"] = path
                        fields["kd"] = (1.0, 1.0, 1.0)
        specular = node.inputs.get("Specular")
        roughness = node.inputs.get("Roughness")
        if specular is not None and not specular.is_linked:
            s = float(specular.default_value)
            fields["ks"] = (s, s, s)
        if roughness is not None and not roughness.is_linked:
            # As Blender's OBJ exporter writes Ns from the roughness.
            fields["ns"] = ((1.0 - float(roughness.default_value)) * 30.0) ** 2
    return fields


def _matrix(m):
    return np.array([[m[r][c] for c in range(4)] for r in range(4)], dtype=np.float64)


class MeshCache:
    """Evaluated meshes uploaded once per sync, keyed by the geometry they come from."""

    def __init__(self, tr, scene, materials):
        self.tr = tr
        self.scene = scene
        self.materials = materials
        self.meshes = {}

    def mesh_for(self, obj):
        """The toonray mesh of an evaluated mesh object and the corners of its bounds in its own
        coordinates, (8, 3); None when it has no triangles."""
        # The evaluated mesh (modifiers applied) is shared by the object's instances and by
        # objects sharing both the mesh and no modifiers.
        key = (obj.data.as_pointer(), self._slots_key(obj))
        if key not in self.meshes:
            self.meshes[key] = self._upload(obj, obj.data)
        return self.meshes[key]

    @staticmethod
    def _slots_key(obj):
        return tuple(slot.material.as_pointer() if slot.material else 0
                     for slot in obj.material_slots)

    def _upload(self, obj, mesh):
        mesh.calc_loop_triangles()
        tris = mesh.loop_triangles
        t = len(tris)
        if t == 0:
            return None
        n = len(mesh.vertices)
        positions = np.empty(n * 3, dtype=np.float32)
        mesh.vertices.foreach_get("co", positions)
        triangles = np.empty(t * 3, dtype=np.int32)
        tris.foreach_get("vertices", triangles)
        # Normals: none for a flat mesh (toonray shades faces flat), one per vertex when every
        # face is smooth and nothing splits them, else one per triangle corner.
        normals = None
        smooth = np.empty(len(mesh.polygons), dtype=bool)
        mesh.polygons.foreach_get("use_smooth", smooth)
        split = mesh.use_auto_smooth or mesh.has_custom_normals
        if smooth.any():
            if smooth.all() and not split:
                normals = np.empty(n * 3, dtype=np.float32)
                mesh.vertices.foreach_get("normal", normals)
                normals = normals.reshape(-1, 3)
            else:
                if split:
                    mesh.calc_normals_split()
                normals = np.empty(t * 9, dtype=np.float32)
                tris.foreach_get("split_normals", normals)
                normals = normals.reshape(-1, 3)
        # Materials: the object's slots as the scene's toonray materials.
        slot_ids = np.array([self.materials.index_of(slot.material) for slot in obj.material_slots]
                            or [0], dtype=np.uint32)
        index = np.empty(t, dtype=np.int32)
        tris.foreach_get("material_index", index)
        material_ids = slot_ids[np.clip(index, 0, len(slot_ids) - 1)]
        uvs = None
        if self.materials.textured(obj.material_slots) and mesh.uv_layers.active is not None:
            loop_uvs = np.empty(len(mesh.loops) * 2, dtype=np.float32)
            mesh.uv_layers.active.data.foreach_get("uv", loop_uvs)
            loops = np.empty(t * 3, dtype=np.int32)
            tris.foreach_get("loops", loops)
            uvs = loop_uvs.reshape(-1, 2)[loops]
        positions = positions.reshape(-1, 3)
        mesh = self.scene.add_mesh(positions, triangles.reshape(-1, 3), normals=normals, uvs=uvs,
                                   materials=material_ids, name=obj.name)
        # The bounds from the vertices: Object.bound_box of an evaluated curve or text object
        # leaks a little of Blender's memory (3.4) each time it is read.
        lo, hi = positions.min(axis=0), positions.max(axis=0)
        corners = np.array([[(lo, hi)[i >> k & 1][k] for k in range(3)] for i in range(8)],
                           dtype=np.float64)
        return mesh, corners


class Materials:
    """Blender materials as the toonray scene's, each added once."""

    def __init__(self, tr, scene):
        self.tr = tr
        self.scene = scene
        self.ids = {}
        self.pass_index = [0]  # by toonray material index: Blender's pass index (IndexMA)
        self.names = ["(default)"]
        self._textured = {}

    def index_of(self, material):
        if material is None:
            return 0
        key = material.as_pointer()
        if key not in self.ids:
            fields = material_fields(material)
            self._textured[key] = bool(fields["map_kd"])
            self.ids[key] = self.scene.add_material(self.tr.Material(material.name, **fields))
            self.pass_index.append(material.pass_index)
            self.names.append(material.name)
        return self.ids[key]

    def textured(self, slots):
        return any(self._textured.get(s.material.as_pointer(), False)
                   for s in slots if s.material is not None)


def camera_of(tr, scene, camera_object, width, height):
    """The toonray camera of a Blender camera object (evaluated) for a width x height frame."""
    data = camera_object.data
    if data.type != "PERSP":
        raise SyncError("camera '%s' is %s: toonray renders perspective cameras only"
                        % (camera_object.name, data.type.lower()))
    m = camera_object.matrix_world
    eye = tuple(m.translation)
    forward = -m.col[2].xyz
    up = m.col[1].xyz
    if forward.length < 1e-12 or up.length < 1e-12:
        raise SyncError("camera '%s' has a zero scale" % camera_object.name)
    target = tuple(m.translation + forward.normalized())
    render = scene.render
    return tr.Camera(eye, target, up=tuple(up.normalized()), lens=data.lens,
                     sensor_width=data.sensor_width, sensor_height=data.sensor_height,
                     sensor_fit=data.sensor_fit, shift=(data.shift_x, data.shift_y),
                     pixel_aspect=render.pixel_aspect_y / render.pixel_aspect_x)


class SyncedScene:
    """A toonray scene of a depsgraph and what the engine needs to map it back to Blender."""

    def __init__(self):
        self.scene = None
        self.object_pass_index = [0]  # by toonray object index (IndexOB)
        self.material_pass_index = [0]
        self.object_names = ["(default)"]
        self.material_names = ["(default)"]
        self.occluders = []  # names of objects that draw no lines (Occlusion Only, holdout)
        self.holdout_ids = []  # toonray object indices of holdout objects
        self.excluded = 0
        self.clipped = 0
        self.triangles = 0
        self.meshes = 0  # meshes uploaded: one per geometry, whatever its instances


def usage_of(obj):
    settings = getattr(obj.original, "toonray", None)
    return settings.usage if settings is not None else "INCLUDE"


def sync_depsgraph(tr, depsgraph, camera=None, clip=None):
    """Builds the toonray scene of `depsgraph`. `camera`: the toonray camera to set; `clip`:
    (camera world matrix, clip_start, clip_end) to drop objects outside the clipping range."""
    out = SyncedScene()
    scene = tr.Scene()
    out.scene = scene
    materials = Materials(tr, scene)
    meshes = MeshCache(tr, scene, materials)
    view_layer = depsgraph.view_layer
    lights = []
    geometry_bounds = []
    if clip is not None:
        cam_matrix, clip_start, clip_end = clip
        cam_inverse = np.linalg.inv(_matrix(cam_matrix))
    for inst in depsgraph.object_instances:
        obj = inst.object
        if not inst.show_self:  # an instancer whose own geometry is hidden
            continue
        if obj.type == "LIGHT":
            lights.append((obj.name, obj.data, inst.matrix_world.copy()))
            continue
        if obj.type != "MESH":
            continue
        usage = usage_of(obj)
        if usage == "EXCLUDE":
            out.excluded += 1
            continue
        uploaded = meshes.mesh_for(obj)
        if uploaded is None:
            continue
        mesh, corners = uploaded
        matrix = _matrix(inst.matrix_world)
        bounds = corners @ matrix[:3, :3].T + matrix[:3, 3]
        if clip is not None:
            depth = -(bounds @ cam_inverse[2, :3] + cam_inverse[2, 3])
            if (depth < clip_start).all() or (depth > clip_end).all():
                out.clipped += 1
                continue
        index = scene.add_instance(mesh, matrix, name=obj.name)
        geometry_bounds.append(bounds)
        out.object_pass_index.append(obj.original.pass_index)
        out.object_names.append(obj.name)
        holdout = obj.original.holdout_get(view_layer=view_layer) \
            if hasattr(obj, "holdout_get") else getattr(obj, "is_holdout", False)
        if holdout:
            out.holdout_ids.append(index)
        if holdout or usage == "OCCLUSION":
            out.occluders.append(obj.name)
    out.material_pass_index = materials.pass_index
    out.material_names = materials.names
    out.triangles = scene.triangle_count + scene.instanced_triangle_count
    out.meshes = sum(1 for m in meshes.meshes.values() if m is not None)
    if geometry_bounds:
        allb = np.concatenate(geometry_bounds)
        centre = tuple(0.5 * (allb.min(axis=0) + allb.max(axis=0)))
    else:
        centre = (0.0, 0.0, 0.0)
    entries = lights_rules.light_entries(lights, centre)
    scene.lights = [tr.Light.directional(v, i) if kind == "directional" else tr.Light.point(v, i)
                    for kind, v, i, _name, _type in entries]
    if camera is not None:
        scene.camera = camera
    return out


def holdout_rules(synced):
    """Line rules for objects that draw no lines of their own."""
    rules = []
    for name in sorted(set(synced.occluders)):
        if _glob_safe(name):
            rules.append({"object": name, "lines": "all", "draw": False})
    return rules


def _glob_safe(name):
    return not any(c in name for c in ",*?")


def glob_list(names):
    """A matcher's list of names: names with glob or list characters cannot be matched."""
    return ",".join(n for n in names if _glob_safe(n))


def frame_size(scene):
    r = scene.render
    return (max(1, int(r.resolution_x * r.resolution_percentage / 100)),
            max(1, int(r.resolution_y * r.resolution_percentage / 100)))
