"""The viewport preview's frame time, measured in Blender without a window (measure.sh): the
preview of viewport.blend at 960x540 seen from its camera, as the viewport's worker renders it:
the scene's sync (view_update), the first frame (one sample per pixel) and the refined frame
after a view change, over 10 view changes (the camera turning about the scene), with the
renderer's BVH refitted between them as in the viewport.

    blender -b viewport.blend --python viewport_time.py [-- SAMPLES]
"""

import math
import statistics
import sys
import time

import bpy
from mathutils import Matrix

from toonray_blender import module, preview

tr = module.load()
samples = int(sys.argv[sys.argv.index("--") + 1]) if "--" in sys.argv else 4
scene = bpy.context.scene
scene.toonray.sampling__samples = samples
depsgraph = bpy.context.evaluated_depsgraph_get()


class Engine:
    def tag_redraw(self):
        pass


p = preview.Preview(tr, Engine())
start = time.monotonic()
p.update_scene(depsgraph)
sync_seconds = time.monotonic() - start
cam = scene.camera
w, h = 960, 540
window = cam.calc_matrix_camera(depsgraph, x=w, y=h)
first, refined = [], []
for i in range(11):
    view = Matrix.Rotation(math.radians(3 * i), 4, "Z") @ cam.matrix_world
    before = len(p.timings)
    p.set_view(preview.view_camera(tr, view.inverted(), window, w, h), i, w, h)
    generation = p.generation
    while True:
        with p.lock:
            frame = p.frame
        if frame is not None and frame[3] == generation and frame[4] == (2 if samples > 1 else 1):
            break
        time.sleep(0.002)
    new = p.timings[before:]
    if i > 0:  # the first frame also builds the BVH
        first.append(new[0][1])
        refined.append(new[-1][1])
p.stop()
print("viewport_time: %d triangles, %dx%d, %d samples" % (p.synced.triangles, w, h, samples))
print("viewport_time: sync (view_update) %.3f s" % sync_seconds)
print("viewport_time: first frame (1 sample/pixel) median %.3f s, refined frame median %.3f s "
      "over %d view changes" % (statistics.median(first), statistics.median(refined), len(first)))
