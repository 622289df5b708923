"""Compares toonray's bands with Cycles' n.l of the sun (tests/blender/lights_test.sh).

    blender -b --factory-startup --python check_lights.py -- WORK

For each frame: Cycles' n.l (WORK/cycles/nl_*.exr times pi over the sun's strength) quantised with
toonray's default thresholds 0.25 and 0.5 gives a band per pixel; toonray's cel image
(WORK/png/aov/lit_NNNNNN_cel.png, classic lines, one ray per pixel centre) must show, on at
least 97% of the object pixels away from silhouettes (the pixel and its 8 neighbours show the
same object in Cycles' id image), exactly that object's colour times that band's level
(0.5, 0.75, 1.0). The object without a material must have the default colour (Kd 0.8) there.
The same holds for the frames toonray renders from Blender's glTF export of the scene
(WORK/png/gltf/aov), lit by its KHR_lights_punctual sun, and the two routes' bands agree with
each other on at least 99% of those pixels.
Writes WORK/side_by_side_NNNNNN.png: Cycles' n.l, its bands in the objects' colours, toonray's
frame.
"""

import json
import math
import os
import sys

import bpy
import numpy as np

argv = sys.argv[sys.argv.index("--") + 1:]
WORK = os.path.abspath(argv[0])
LEVELS = np.array([0.5, 0.75, 1.0])
MIN_AGREEMENT = 0.97
MIN_ROUTE_AGREEMENT = 0.99  # OBJ + lights file against glTF + KHR_lights_punctual
ROUTES = (("OBJ", os.path.join("png", "aov")), ("glTF", os.path.join("png", "gltf", "aov")))

meta = json.load(open(os.path.join(WORK, "objects.json")))
W, H = meta["size"]
failures = []


def load(path, channels=4):
    img = bpy.data.images.load(path)
    img.colorspace_settings.name = "Non-Color"
    a = np.array(img.pixels[:], dtype=np.float64).reshape(img.size[1], img.size[0], 4)
    bpy.data.images.remove(img)
    return a[::-1]  # top row first, as toonray writes


def save(path, rgb):
    h, w = rgb.shape[:2]
    img = bpy.data.images.new("out", w, h, alpha=False)
    rgba = np.ones((h, w, 4))
    rgba[..., :3] = np.clip(rgb, 0, 1)
    img.pixels[:] = rgba[::-1].ravel()
    img.filepath_raw = path
    img.file_format = "PNG"
    img.save()
    bpy.data.images.remove(img)


def check_route(route, frame, nl, ids, band, interior, kd, cel):
    """Checks one route's frame against Cycles' bands; returns its bands (-1 off the objects)."""
    expected = kd * LEVELS[band][..., None]
    agree = np.all(np.abs(cel - expected) <= 1.5 / 255, axis=2)
    for key in meta["objects"]:
        mask = interior & (ids == int(key))
        n = int(mask.sum())
        rate = float(agree[mask].mean()) if n else 0.0
        print("frame %d %s object %s: %d interior pixels, bands agree on %.2f%%"
              % (frame, route, key, n, 100 * rate), flush=True)
        if n < 300:
            failures.append("frame %d object %s: only %d interior pixels" % (frame, key, n))
        elif rate < MIN_AGREEMENT:
            failures.append("frame %d %s object %s: bands agree on %.2f%% < %.0f%%"
                            % (frame, route, key, 100 * rate, 100 * MIN_AGREEMENT))
    all_rate = float(agree[interior].mean())
    print("frame %d %s: bands agree on %.2f%% of %d object pixels (Cycles bands: %s)"
          % (frame, route, 100 * all_rate, int(interior.sum()),
             np.bincount(band[interior], minlength=3).tolist()), flush=True)
    if all_rate < MIN_AGREEMENT:
        failures.append("frame %d %s: bands agree on %.2f%%" % (frame, route, 100 * all_rate))
    # The material-less object: the default colour (one of 0.8 x the levels), not the box's red,
    # around its centre as Blender projects it.
    cx, cy = meta["plain_centre"][str(frame)]
    px, py = int(cx), H - 1 - int(cy)
    patch = cel[py - 3:py + 4, px - 3:px + 4]
    grey = np.abs(patch[..., 0] - patch[..., 1]) + np.abs(patch[..., 1] - patch[..., 2]) < 2 / 255
    levels = np.min(np.abs(patch[..., :1] - 0.8 * LEVELS), axis=2) <= 1.5 / 255
    print("frame %d %s: material-less object at (%d, %d): %s"
          % (frame, route, px, py, patch[3, 3].round(3).tolist()))
    if ids[py, px] != 3 or not (grey & levels).all():
        failures.append("frame %d %s: the object without a material is not the default colour "
                        "at its centre (%d, %d): %s" % (frame, route, px, py, patch[3, 3].tolist()))
    # toonray's band at each object pixel: the level its colour is nearest to.
    error = np.abs(cel[..., None, :] - kd[..., None, :] * LEVELS[None, None, :, None]).max(axis=3)
    return np.where(ids > 0, np.argmin(error, axis=2), -1), expected


for frame in meta["frames"]:
    nl = load(os.path.join(WORK, "cycles", "nl_%06d.exr" % frame))[..., 0]
    nl = nl * math.pi / meta["sun_strength"]  # white diffuse under a sun: strength x n.l / pi
    ids = np.rint(load(os.path.join(WORK, "cycles", "id_%06d.exr" % frame))[..., 0] * 10)
    band = np.digitize(nl, [0.25, 0.5])  # 0, 1, 2
    interior = ids > 0
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            shifted = np.roll(np.roll(ids, dy, axis=0), dx, axis=1)
            interior &= shifted == ids
    interior[0, :] = interior[-1, :] = interior[:, 0] = interior[:, -1] = False
    kd = np.zeros((H, W, 3))
    for key, colour in meta["objects"].items():
        kd[ids == int(key)] = colour
    bands, cels = [], []
    for route, folder in ROUTES:
        cel = load(os.path.join(WORK, folder, "lit_%06d_cel.png" % frame))[..., :3]
        if cel.shape[:2] != (H, W) or nl.shape != (H, W):
            failures.append("frame %d %s: image sizes %s %s, expected %dx%d"
                            % (frame, route, cel.shape, nl.shape, W, H))
            break
        route_bands, expected = check_route(route, frame, nl, ids, band, interior, kd, cel)
        bands.append(route_bands)
        cels.append(cel)
    if len(bands) != len(ROUTES):
        continue
    same = float((bands[0] == bands[1])[interior].mean())
    print("frame %d: the OBJ and glTF routes give the same band on %.2f%% of %d object pixels"
          % (frame, 100 * same, int(interior.sum())), flush=True)
    if same < MIN_ROUTE_AGREEMENT:
        failures.append("frame %d: the OBJ and glTF routes agree on %.2f%% < %.0f%%"
                        % (frame, 100 * same, 100 * MIN_ROUTE_AGREEMENT))
    side = np.concatenate([np.repeat(np.clip(nl, 0, 1)[..., None], 3, axis=2),
                           np.where((ids > 0)[..., None], expected, 1.0), cels[0]], axis=1)
    save(os.path.join(WORK, "side_by_side_%06d.png" % frame), side)

if failures:
    for f in failures:
        print("check_lights: FAIL:", f, file=sys.stderr, flush=True)
    sys.exit(1)
print("check_lights: OK", flush=True)
