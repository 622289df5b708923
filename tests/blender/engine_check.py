"""Checks the render engine test's outputs (engine_test.sh), in Blender (its PNG reader):

- parity: the engine's frame of parity.blend against `toonray render` of the same scene exported
  through the OBJ exporter with the same settings document: the silhouettes (pixels that are
  not the blue background) have an IoU of at least 0.99, and away from silhouettes and lines
  the colours (each object's Kd times its band's level) agree on at least 99% of the pixels
  both show as surfaces, and every colour either shows is one the other shows too (the same
  bands of the same objects);
- complex: the IndexOB pass of complex.blend (copied to an EXR of its own by oiiotool) shows every
  object's pass index, each instanced object's too, and not those of an object hidden for the
  render or excluded; a holdout object's pixels have alpha 0 in Combined;
- anim: -a wrote three frames and three SVGs with visible and hidden layers.

    blender -b --factory-startup --python engine_check.py -- WORK
"""

import json
import os
import sys

import bpy
import numpy as np

work = sys.argv[sys.argv.index("--") + 1]
failures = []


def check(ok, message):
    print("engine_check: %s: %s" % ("ok" if ok else "FAILED", message))
    if not ok:
        failures.append(message)


def png(path):
    image = bpy.data.images.load(path)
    w, h = image.size
    pixels = np.empty(w * h * 4, dtype=np.float32)
    image.pixels.foreach_get(pixels)
    rgb = np.rint(pixels.reshape(h, w, 4)[::-1, :, :3] * 255).astype(np.int32)
    bpy.data.images.remove(image)
    return rgb


def exr_channel(path):
    """A one-channel float EXR (oiiotool's copy of one pass), rows from the top."""
    image = bpy.data.images.load(path)
    w, h = image.size
    pixels = np.empty(w * h * 4, dtype=np.float32)
    image.pixels.foreach_get(pixels)
    bpy.data.images.remove(image)
    return pixels.reshape(h, w, 4)[::-1, :, 0]


def eroded(mask):
    """Pixels whose 8 neighbours are in the mask too."""
    out = mask.copy()
    out[1:, :] &= mask[:-1, :]
    out[:-1, :] &= mask[1:, :]
    out[:, 1:] &= mask[:, :-1]
    out[:, :-1] &= mask[:, 1:]
    out[1:, 1:] &= mask[:-1, :-1]
    out[:-1, :-1] &= mask[1:, 1:]
    out[1:, :-1] &= mask[:-1, 1:]
    out[:-1, 1:] &= mask[1:, :-1]
    return out


def parity():
    engine = png(os.path.join(work, "engine", "parity_0001.png"))
    cli = png(os.path.join(work, "cli.png"))
    check(engine.shape == cli.shape, "the engine's frame is %s, the command line's %s"
          % (engine.shape[:2], cli.shape[:2]))
    blue = np.array([0, 0, 255])
    a = np.abs(engine - blue).max(axis=-1) > 8
    b = np.abs(cli - blue).max(axis=-1) > 8
    iou = (a & b).sum() / max(1, (a | b).sum())
    check(iou >= 0.99, "silhouette IoU %.4f (at least 0.99)" % iou)
    # Surfaces away from lines: no dark pixel (a line) in the neighbourhood in either frame.
    dark = lambda img: img.max(axis=-1) < 24
    inside = eroded(a & b & ~dark(engine) & ~dark(cli))
    inside = eroded(inside)
    same = (np.abs(engine - cli).max(axis=-1) <= 2) & inside
    agree = same.sum() / max(1, inside.sum())
    check(inside.sum() > 5000, "%d surface pixels compared" % inside.sum())
    check(agree >= 0.99, "colours (object and band) agree on %.2f%% of them (at least 99%%)"
          % (100 * agree))
    colours = lambda img: {tuple(c) for c in img[inside].tolist()}

    def bands(img):
        counts = {}
        for c in img[inside].tolist():
            counts[tuple(c)] = counts.get(tuple(c), 0) + 1
        return {c for c, n in counts.items() if n >= 20}  # each band of each object

    ea, ca = bands(engine), bands(cli)
    near = lambda c, s: any(max(abs(x - y) for x, y in zip(c, d)) <= 2 for d in s)
    check(all(near(c, colours(cli)) for c in ea) and all(near(c, colours(engine)) for c in ca),
          "the same %d object bands in both frames" % len(ea))


def complex_scene():
    scene_file = os.path.join(work, "complex_indices.json")
    with open(scene_file) as f:
        wanted = json.load(f)
    index = np.rint(exr_channel(os.path.join(work, "complex_index.exr"))).astype(int)
    alpha = exr_channel(os.path.join(work, "complex_alpha.exr"))
    seen = set(np.unique(index).tolist())
    for name, value in sorted(wanted["seen"].items(), key=lambda kv: kv[1]):
        check(value in seen, "object %s (pass index %d) is in the IndexOB pass" % (name, value))
    for name, value in sorted(wanted["left_out"].items()):
        check(value not in seen, "object %s (pass index %d) is not rendered" % (name, value))
    holdout = index == wanted["seen"]["Holdout"]
    check(holdout.any() and (alpha[holdout] == 0).all() and (alpha[index == 1] == 1).all(),
          "the holdout's pixels are transparent in Combined, the others opaque")


def anim():
    folder = os.path.join(work, "anim")
    for frame in (1, 2, 3):
        stem = os.path.join(folder, "frame_%04d" % frame)
        check(os.path.exists(stem + ".png"), "frame %d's PNG was written" % frame)
        ok = os.path.exists(stem + ".svg")
        check(ok, "frame %d's SVG was written beside it" % frame)
        if ok:
            with open(stem + ".svg") as f:
                text = f.read()
            check('<g id="visible' in text and '<g id="hidden' in text and
                  text.endswith("</svg>\n"), "frame %d's SVG has visible and hidden layers" % frame)
    check(not os.path.exists(os.path.join(folder, "frame_0004.png")), "no fourth frame")


parity()
complex_scene()
anim()
if failures:
    print("engine_check: %d failed" % len(failures))
    sys.exit(1)
print("engine_check: all passed")
