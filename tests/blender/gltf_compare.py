"""Compares toonray's renders of the exported glTF with Cycles' silhouettes
(tests/blender/run_gltf_test.sh).

    blender -b --factory-startup --python gltf_compare.py -- WORK FRAMES MIN_IOU

For each frame: Cycles' silhouette is where WORK/cycles/frame_NNNNNN.png has alpha > 0.5;
toonray's is where its depth AOV (WORK/aov/scene_NNNNNN_depth.png) is below 255 or its normal
AOV is not black (the farthest hit has depth 255 too). Prints the intersection over union of
each frame and fails below MIN_IOU, or when a silhouette is nearly empty (a test that compares
nothing must not pass).
"""

import os
import sys

import bpy

argv = sys.argv[sys.argv.index("--") + 1:]
WORK = os.path.abspath(argv[0])
FRAMES = [int(f) for f in argv[1].split(",")]
MIN_IOU = float(argv[2])


def pixels(path):
    image = bpy.data.images.load(path)
    w, h = image.size
    values = list(image.pixels)
    bpy.data.images.remove(image)
    return w, h, values  # RGBA floats, rows bottom to top


failed = 0
for frame in FRAMES:
    w, h, cycles = pixels(os.path.join(WORK, "cycles", "frame_%06d.png" % frame))
    w2, h2, depth = pixels(os.path.join(WORK, "aov", "scene_%06d_depth.png" % frame))
    w3, h3, normal = pixels(os.path.join(WORK, "aov", "scene_%06d_normal.png" % frame))
    assert (w, h) == (w2, h2) == (w3, h3), (w, h, w2, h2)
    both = either = blender_count = toonray_count = 0
    for i in range(w * h):
        a = cycles[4 * i + 3] > 0.5
        b = depth[4 * i] < 0.999 or any(normal[4 * i + c] > 0.001 for c in range(3))
        blender_count += a
        toonray_count += b
        both += a and b
        either += a or b
    iou = both / either if either else 0.0
    ok = iou >= MIN_IOU and blender_count > 0.02 * w * h
    failed += not ok
    print("frame %d: IoU %.4f (Cycles %d pixels, toonray %d)%s"
          % (frame, iou, blender_count, toonray_count, "" if ok else "  FAIL"), flush=True)
print("gltf_compare: %d of %d frames below IoU %.2f" % (failed, len(FRAMES), MIN_IOU), flush=True)
sys.exit(1 if failed else 0)
