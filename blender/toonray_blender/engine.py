"""The toonray render engine (docs/blender.md, "Render engine"): F12 and animations render in
process through the toonray module (no files, no other process), with Blender's passes, an SVG
per frame, progress and cancel; the viewport preview renders on a worker thread (preview.py).
"""

import os

import bpy
import numpy as np

from . import module, properties, sync

# sRGB byte -> linear float: Blender's passes hold scene-linear colour, which its Standard view
# transform turns back into toonray's bytes.
_SRGB_TO_LINEAR = np.array([(c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4)
                            for c in (i / 255.0 for i in range(256))], dtype=np.float32)


def srgb_to_linear(image):
    return _SRGB_TO_LINEAR[image]


def line_pass_name(line_type):
    return "Lines " + line_type.title()


def passes_of(scene, view_layer, tr):
    """[(name, channels, chan_id, type)] of the passes a view layer gets, Blender's names for
    Blender's passes, Combined first."""
    out = [("Combined", 4, "RGBA", "COLOR")]
    if view_layer.use_pass_z:
        out.append(("Depth", 1, "Z", "VALUE"))
    if view_layer.use_pass_normal:
        out.append(("Normal", 3, "XYZ", "VECTOR"))
    if view_layer.use_pass_object_index:
        out.append(("IndexOB", 1, "X", "VALUE"))
    if view_layer.use_pass_material_index:
        out.append(("IndexMA", 1, "X", "VALUE"))
    settings = getattr(view_layer, "toonray", None)
    if settings is not None and settings.use_pass_lines:
        out.append(("Lines", 1, "X", "VALUE"))
    if settings is not None and settings.use_pass_line_types and hasattr(scene, "toonray"):
        for line_type in tr.line_layers(scene.toonray.lines__mode):
            out.append((line_pass_name(line_type), 1, "X", "VALUE"))
    return out


def _ids_to(ids, lut):
    lut = np.asarray(lut, dtype=np.float32)
    seen = ids != np.uint32(0xFFFFFFFF)
    out = np.zeros(ids.shape, dtype=np.float32)
    out[seen] = lut[np.minimum(ids[seen], len(lut) - 1)]
    return out


def needs_layers(wanted, transparent, synced):
    """Whether the frame must keep its layers: passes beyond Combined, a transparent film (alpha
    from the coverage), holdouts (their pixels)."""
    return transparent or bool(synced.holdout_ids) or any(p[0] != "Combined" for p in wanted)


def pass_pixels(frame, synced, transparent, name):
    """One pass's pixels, (height, width, channels) float32 with rows from the top; None for a
    pass toonray does not fill."""
    if name == "Combined":
        rgba = np.empty((frame.height, frame.width, 4), dtype=np.float32)
        rgba[..., :3] = srgb_to_linear(frame.image[..., :3])
        if transparent:
            # The background was rendered black, so colours over it are premultiplied already.
            rgba[..., 3] = np.maximum(frame.layer("A"), frame.layer("lines.all"))
        else:
            rgba[..., 3] = 1.0
        if synced.holdout_ids:
            rgba[np.isin(frame.object_ids, synced.holdout_ids)] = 0.0
        return rgba
    if name == "Depth":
        return frame.layer("view_depth.Z")[..., None]
    if name == "Normal":
        return np.stack([frame.layer("N.X"), frame.layer("N.Y"), frame.layer("N.Z")], axis=-1)
    if name == "IndexOB":
        return _ids_to(frame.object_ids, synced.object_pass_index)[..., None]
    if name == "IndexMA":
        return _ids_to(frame.material_ids, synced.material_pass_index)[..., None]
    if name == "Lines":
        return frame.layer("lines.all")[..., None]
    for layer in frame.layer_names:
        if layer.startswith("lines.") and name == line_pass_name(layer[len("lines."):]):
            return frame.layer(layer)[..., None]
    return None


def fill_passes(passes, frame, synced, transparent):
    """Fills a result layer's passes in one foreach_set, rows from the bottom as Blender keeps
    them (setting each pass's rect from Python is a hundred times slower)."""
    sizes = [frame.width * frame.height * p.channels for p in passes]
    flat = np.zeros(sum(sizes), dtype=np.float32)
    start = 0
    for render_pass, size in zip(passes, sizes):
        values = pass_pixels(frame, synced, transparent, render_pass.name)
        if values is not None and values.shape[-1] == render_pass.channels:
            flat[start:start + size].reshape(values.shape)[:] = values[::-1]
        start += size
    passes.foreach_set("rect", flat)


def svg_path(scene):
    """The SVG beside the frame's output file: its path with the extension .svg."""
    path = bpy.path.abspath(scene.render.frame_path(frame=scene.frame_current))
    return os.path.splitext(path)[0] + ".svg"


def write_atomic(path, text):
    folder = os.path.dirname(path)
    if folder:
        os.makedirs(folder, exist_ok=True)
    tmp = path + ".tmp"
    with open(tmp, "w", encoding="utf-8", newline="") as f:
        f.write(text)
    os.replace(tmp, path)


class ToonrayRenderEngine(bpy.types.RenderEngine):
    bl_idname = "TOONRAY"
    bl_label = "toonray"
    bl_use_preview = False  # material previews would render Blender's preview scenes
    bl_use_shading_nodes_custom = False  # keep Blender's material nodes
    bl_use_postprocess = True

    def __init__(self):
        self.preview = None

    def __del__(self):
        preview = getattr(self, "preview", None)
        if preview is not None:
            preview.stop()

    # ---- Passes ----------------------------------------------------------------------------

    def update_render_passes(self, scene=None, renderlayer=None):
        tr = module.load()
        if tr is None or scene is None or renderlayer is None:
            return
        for name, channels, chan_id, kind in passes_of(scene, renderlayer, tr):
            self.register_pass(scene, renderlayer, name, channels, chan_id, kind)

    # ---- Final render (F12, animations, blender -b -f / -a) --------------------------------

    def render(self, depsgraph):
        tr = module.load()
        if tr is None:
            self.report({"ERROR"}, module.import_error)
            return
        try:
            self._render(tr, depsgraph)
        except tr.Cancelled:
            pass
        except Exception as e:  # reported, never raised into Blender
            self._fail("toonray: %s" % e)

    def _stop_requested(self):
        """Whether the user asked to stop (Esc): Blender's test_break."""
        return self.test_break()

    def _fail(self, message):
        self.report({"ERROR"}, message)
        if hasattr(self, "error_set"):
            self.error_set(message)
        print(message, flush=True)

    def _render(self, tr, depsgraph):
        scene = depsgraph.scene
        view_layer = depsgraph.view_layer
        width, height = sync.frame_size(scene)
        if scene.camera is None:
            raise sync.SyncError("the scene has no camera")
        camera_object = scene.camera.evaluated_get(depsgraph)
        self.update_stats("", "toonray: reading the scene")
        camera = sync.camera_of(tr, scene, camera_object, width, height)
        synced = sync.sync_depsgraph(
            tr, depsgraph, camera=camera,
            clip=(camera_object.matrix_world, camera_object.data.clip_start,
                  camera_object.data.clip_end))
        if self._stop_requested():
            return
        settings = properties.settings_document(scene, view_layer, tr, synced)
        transparent = scene.render.film_transparent
        if transparent:
            settings["image.background"] = (0.0, 0.0, 0.0)
        use_svg = scene.toonray.use_svg
        stats = "toonray | %d triangles" % synced.triangles

        def progress(fraction):
            self.update_progress(fraction)
            self.update_stats("", "%s | rendering %d%%" % (stats, round(100 * fraction)))
            return not self._stop_requested()

        wanted = passes_of(scene, view_layer, tr)
        frame = tr.Renderer().render(synced.scene, width, height, settings,
                                     layers=needs_layers(wanted, transparent, synced),
                                     svg=use_svg, progress=progress)
        for warning in frame.warnings:
            self.report({"WARNING"}, "toonray: %s" % warning)
        if use_svg:
            write_atomic(svg_path(scene), frame.svg)
        for name, channels, chan_id, _kind in wanted[1:]:
            self.add_pass(name, channels, chan_id, layer=view_layer.name)
        # Nothing between begin_result and end_result may raise out of here: an exception there
        # crashes Blender 3.4, so the result is ended in `finally` and errors are reported.
        result = self.begin_result(0, 0, width, height, layer=view_layer.name)
        try:
            fill_passes(result.layers[0].passes, frame, synced, transparent)
        except Exception as e:
            self._fail("toonray: could not fill the passes: %s" % e)
        finally:
            self.end_result(result)
        self.update_stats("", "%s | done" % stats)

    # ---- Viewport preview -------------------------------------------------------------------

    def view_update(self, context, depsgraph):
        tr = module.load()
        if tr is None:
            return
        from . import preview
        if self.preview is None:
            self.preview = preview.Preview(tr, self)
        try:
            self.preview.update_scene(depsgraph)
        except Exception as e:
            self.preview.error = str(e)

    def view_draw(self, context, depsgraph):
        if self.preview is None:
            return
        from . import preview
        preview.draw(self, context, depsgraph)
