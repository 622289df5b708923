"""The cameras and the viewport preview's renderer, without a display (engine_test.sh):

- the final render's camera (lens, sensor fit, shift, pixel aspect) and the viewport's (from a
  view and window matrix, here a camera's own) project points where Blender's projection
  matrix (Object.calc_matrix_camera) puts them, to within a thousandth of a pixel;
- the preview renders on its worker thread: one sample per pixel first, then the scene's
  samples, and the refined frame is exactly what toonray renders for that view; a new view
  while a frame renders cancels it and the newest view's frame follows.

    blender -b WORK/parity.blend --python preview_test.py
"""

import sys
import time

import bpy
import numpy as np
from mathutils import Vector

from toonray_blender import engine as toonray_engine
from toonray_blender import module, preview, sync

tr = module.load()
failures = []


def check(ok, message):
    print("preview_test: %s: %s" % ("ok" if ok else "FAILED", message))
    if not ok:
        failures.append(message)


def toonray_pixel(spec, p, width, height):
    """Where toonray's view plane (the seed's, with the lens shift) puts world point p."""
    eye, gaze, up = (np.array(spec[k], dtype=np.float64) for k in ("eye", "gaze", "up"))
    view = gaze - eye
    right = np.cross(view, up)
    right /= np.linalg.norm(right)
    centre = gaze + right * 2 * spec["shift"][0] + up * 2 * spec["shift"][1]
    up_vec = up * height / width
    ul = centre + up_vec - right
    step_x, step_y = 2 * right / width, -2 * up_vec / height
    normal = np.cross(step_x, step_y)
    d = np.asarray(p, dtype=np.float64) - eye
    hit = eye + d * (np.dot(ul - eye, normal) / np.dot(d, normal)) - ul
    # Solve hit = x step_x + y step_y.
    m = np.stack([step_x, step_y], axis=1)
    x, y = np.linalg.lstsq(m, hit, rcond=None)[0]
    return x, y


def blender_pixel(cam, depsgraph, p, width, height, render):
    projection = cam.calc_matrix_camera(depsgraph, x=width, y=height,
                                        scale_x=render.pixel_aspect_x,
                                        scale_y=render.pixel_aspect_y)
    clip = projection @ cam.matrix_world.inverted() @ Vector((*p, 1.0))
    ndc = clip.xyz / clip.w
    return (ndc.x + 1) / 2 * width, (1 - ndc.y) / 2 * height


def cameras():
    scene = bpy.context.scene
    cam = scene.camera
    render = scene.render
    rng = np.random.default_rng(7)
    points = rng.uniform(-1.5, 1.5, size=(20, 3))
    for fit, shift, size, aspect in (("AUTO", (0.0, 0.0), (320, 240), (1, 1)),
                                     ("AUTO", (0.12, -0.07), (240, 320), (1, 1)),
                                     ("HORIZONTAL", (-0.2, 0.1), (300, 200), (1, 1)),
                                     ("VERTICAL", (0.05, 0.25), (300, 200), (1, 1)),
                                     ("AUTO", (0.1, 0.1), (240, 150), (1.5, 1))):
        cam.data.sensor_fit = fit
        cam.data.shift_x, cam.data.shift_y = shift
        render.resolution_x, render.resolution_y = size
        render.pixel_aspect_x, render.pixel_aspect_y = aspect
        depsgraph = bpy.context.evaluated_depsgraph_get()
        w, h = sync.frame_size(scene)
        final = sync.camera_of(tr, scene, cam.evaluated_get(depsgraph), w, h).spec(w, h)
        window = cam.calc_matrix_camera(depsgraph, x=w, y=h)
        viewport = preview.view_camera(tr, cam.matrix_world.inverted(), window, w, h)
        worst_final = worst_view = 0.0
        for p in points:
            b = blender_pixel(cam, depsgraph, p, w, h, render)
            t = toonray_pixel(final, p, w, h)
            worst_final = max(worst_final, abs(b[0] - t[0]), abs(b[1] - t[1]))
            if aspect == (1, 1):
                v = toonray_pixel(viewport.spec(w, h), p, w, h)
                worst_view = max(worst_view, abs(b[0] - v[0]), abs(b[1] - v[1]))
        check(worst_final < 1e-3 and worst_view < 1e-3,
              "%s fit, shift %s, %dx%d, pixel aspect %s: within %.1e px (render), %.1e px "
              "(viewport)" % (fit, shift, w, h, aspect, worst_final, worst_view))
    cam.data.sensor_fit = "AUTO"
    cam.data.shift_x = cam.data.shift_y = 0.0
    render.resolution_x, render.resolution_y = 320, 240
    render.pixel_aspect_x = render.pixel_aspect_y = 1.0


class FakeEngine:
    """What the preview needs of its RenderEngine."""
    redraws = 0

    def tag_redraw(self):
        self.redraws += 1


def wait_for(preview_, generation, stage, timeout=60.0):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        with preview_.lock:
            frame = preview_.frame
        if frame is not None and frame[3] == generation and frame[4] == stage:
            return frame
        time.sleep(0.01)
    return None


def preview_renders():
    scene = bpy.context.scene
    scene.toonray.sampling__samples = 4
    depsgraph = bpy.context.evaluated_depsgraph_get()
    cam = scene.camera
    w, h = 320, 240
    engine = FakeEngine()
    p = preview.Preview(tr, engine)
    p.update_scene(depsgraph)
    window = cam.calc_matrix_camera(depsgraph, x=w, y=h)
    camera = preview.view_camera(tr, cam.matrix_world.inverted(), window, w, h)
    p.set_view(camera, "view 1", w, h)
    # The one-sample frame may be replaced by the refined one before a poll sees it: the
    # preview's timings tell that both arrived, in order (below).
    refined = wait_for(p, p.generation, 2)
    check(refined is not None, "the refined frame (4 samples) arrives")
    settings = dict(p.settings)
    direct = tr.render(p.synced.scene, w, h, settings, layers=False, camera=camera)
    expected = toonray_engine.srgb_to_linear(direct.image[::-1, :, :3])
    check(refined is not None and np.array_equal(refined[0][..., :3], expected),
          "the refined frame is toonray's frame of the view")
    check([s for s, _ in p.timings[:2]] == [1, 2],
          "the first frame (one sample per pixel) came before it: timings %s" % p.timings)
    # Views requested while frames render: each cancels the one in flight; the last one wins.
    for i in range(5):
        moved = cam.matrix_world.copy()
        moved.translation.x += 0.05 * (i + 1)
        p.set_view(preview.view_camera(tr, moved.inverted(), window, w, h), "view %d" % (i + 2),
                   w, h)
    last = wait_for(p, p.generation, 2)
    check(last is not None and p.generation == 6, "the newest view's frame arrives (request %d)"
          % p.generation)
    p.stop()
    check(not p.worker.is_alive(), "the worker stops")


cameras()
preview_renders()
if failures:
    sys.exit(1)
print("preview_test: all passed")
