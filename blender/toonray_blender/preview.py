"""The viewport preview (Rendered shading with toonray): frames render on a worker thread, one
sample per pixel first and then with the scene's samples, and are drawn when they are done, so
the interface never waits for a frame (docs/blender.md, "Viewport").

- view_update (a depsgraph change) builds the toonray scene again, in Blender's thread;
- view_draw computes the view's camera from the region's matrices and, when it changed, asks for
  a new frame; it draws the newest finished frame;
- a new request cancels the frame in flight (toonray.Renderer.cancel), and the worker starts on
  the newest request; the renderer keeps its BVH, refitted while the triangles stay the same;
- a timer in Blender's thread redraws the viewport when a frame is done (Blender's API may not be
  called from the worker).
"""

import threading
import time
import weakref

import numpy as np

from . import properties, sync


def view_camera(tr, view_matrix, window_matrix, width, height):
    """The toonray camera of a 3D view: its view (world to view) and window (projection)
    matrices, as Blender's RegionView3D gives them; None for an orthographic view.

    The projection maps view-space (x, y, z), looking down -z, to x_ndc = (P00 x + P02 z) / -z
    and likewise for y. The seed's camera has its image plane at |gaze - eye| with half a
    width of 1, so |gaze - eye| = P00; the plane's centre sits where x_ndc = 0, which is
    P02 / 2 image widths to the right (the lens shift), and P12 P00 / (2 P11) up."""
    p = window_matrix
    if abs(p[3][3]) > 1e-9 or abs(p[3][2]) < 1e-9:
        return None  # orthographic
    inverse = view_matrix.inverted()
    eye = inverse.translation
    forward = -inverse.col[2].xyz.normalized()
    up = inverse.col[1].xyz.normalized()
    distance = p[0][0]
    gaze = eye + forward * distance
    shift = (p[0][2] / 2.0, p[1][2] * p[0][0] / (2.0 * p[1][1]))
    return tr.Camera.block(tuple(eye), tuple(gaze), tuple(up), shift=shift)


# The previews of open viewports (for tests and measurements: docs/blender.md, "Viewport").
active = weakref.WeakSet()


class Preview:
    """One viewport's renderer, worker thread and newest frame."""

    def __init__(self, tr, engine):
        active.add(self)
        self.tr = tr
        self.engine = weakref.ref(engine)
        self.renderer = tr.Renderer()
        self.lock = threading.Lock()
        self.synced = None
        self.settings = None
        self.view = None  # (camera key, width, height)
        self.camera = None
        self.generation = 0  # of the newest request
        self.worker = None
        self.frame = None  # (rgba float32 rows from the bottom, width, height, generation, stage)
        self.drawn = None
        self.error = None
        self.stopped = False
        self.timings = []  # (stage, seconds from the request to the frame), newest last
        self.sync_seconds = 0.0  # of the last update_scene
        self._requested_at = 0.0
        self._timer = None

    # ---- Requests (Blender's thread) --------------------------------------------------------

    def update_scene(self, depsgraph):
        started = time.monotonic()
        synced = sync.sync_depsgraph(self.tr, depsgraph)
        settings = properties.settings_document(depsgraph.scene, depsgraph.view_layer, self.tr,
                                                synced)
        with self.lock:
            self.synced = synced
            self.settings = settings
            self.sync_seconds = time.monotonic() - started
        self._request()

    def set_view(self, camera, key, width, height):
        view = (key, width, height)
        if view == self.view:
            return
        with self.lock:
            self.view = view
            self.camera = camera
        self._request()

    def _request(self):
        with self.lock:
            if self.synced is None or self.view is None or self.stopped:
                return
            self.generation += 1
            self._requested_at = time.monotonic()
            self.error = None
            running = self.worker is not None and self.worker.is_alive()
        self.renderer.cancel()
        if not running:
            self.worker = threading.Thread(target=self._work, name="toonray preview",
                                           daemon=True)
            self.worker.start()
        self._start_timer()

    def stop(self):
        with self.lock:
            self.stopped = True
        self.renderer.cancel()
        if self.worker is not None:
            self.worker.join(timeout=5)

    # ---- The worker -------------------------------------------------------------------------

    def _work(self):
        done = 0
        while True:
            with self.lock:
                if self.stopped or self.generation == done:
                    return
                generation = self.generation
                synced, settings, camera = self.synced, dict(self.settings), self.camera
                _key, width, height = self.view
                started = self._requested_at
            stages = [(1, dict(settings, **{"sampling.samples": 1}))]
            if settings.get("sampling.samples", 1) != 1:
                stages.append((2, settings))
            for stage, stage_settings in stages:
                try:
                    frame = self.renderer.render(synced.scene, width, height, stage_settings,
                                                 layers=False, camera=camera)
                except self.tr.Cancelled:
                    break
                except Exception as e:
                    self.error = str(e)
                    break
                rgba = np.empty((height, width, 4), dtype=np.float32)
                from .engine import srgb_to_linear
                rgba[..., :3] = srgb_to_linear(frame.image[::-1, :, :3])
                rgba[..., 3] = 1.0
                with self.lock:
                    if generation != self.generation:
                        break
                    self.frame = (rgba, width, height, generation, stage)
                    self.timings.append((stage, time.monotonic() - started))
                    del self.timings[:-50]
            done = generation

    # ---- Redraws ----------------------------------------------------------------------------

    def _start_timer(self):
        import bpy
        if self._timer is not None and bpy.app.timers.is_registered(self._timer):
            return
        preview = weakref.ref(self)

        def tick():
            p = preview()
            if p is None or p.stopped:
                return None
            engine = p.engine()
            if engine is None:
                return None
            with p.lock:
                new = p.frame is not None and p.frame[3:] != p.drawn
                busy = p.worker is not None and p.worker.is_alive()
            if new:
                try:
                    engine.tag_redraw()
                except ReferenceError:
                    return None
            return 0.02 if busy or new else None

        self._timer = tick
        bpy.app.timers.register(tick, first_interval=0.02)


_textures = weakref.WeakKeyDictionary()


def draw(engine, context, depsgraph):
    """view_draw: asks for a frame of the current view and draws the newest one."""
    import gpu
    from gpu_extras.presets import draw_texture_2d
    preview = engine.preview
    region, rv3d = context.region, context.region_data
    width, height = region.width, region.height
    camera = view_camera(preview.tr, rv3d.view_matrix, rv3d.window_matrix, width, height)
    if camera is None:
        preview.error = "toonray renders perspective views only"
    else:
        key = (tuple(map(tuple, rv3d.view_matrix)), tuple(map(tuple, rv3d.window_matrix)))
        preview.set_view(camera, key, width, height)
    with preview.lock:
        frame = preview.frame
    if frame is None:
        return
    rgba, w, h, generation, stage = frame
    cached = _textures.get(preview)
    if cached is None or cached[0] != (generation, stage):
        buffer = gpu.types.Buffer("FLOAT", w * h * 4, rgba.reshape(-1))
        texture = gpu.types.GPUTexture((w, h), format="RGBA16F", data=buffer)
        cached = ((generation, stage), texture)
        _textures[preview] = cached
    with preview.lock:
        preview.drawn = (generation, stage)
    gpu.state.blend_set("ALPHA_PREMULT")
    engine.bind_display_space_shader(depsgraph.scene)
    draw_texture_2d(cached[1], (0, 0), width, height)
    engine.unbind_display_space_shader()
    gpu.state.blend_set("NONE")
