"""Cancel and errors in a real Blender render (engine_test.sh): the engine's render stops within
a second of Blender's break (Esc: RenderEngine.test_break, which the engine asks through
_stop_requested, replaced here), the result is ended and Blender goes on rendering; a render
that fails (a settings limit) is reported and Blender goes on; the settings document exported
and imported gives the same properties and line sets.

    blender -b WORK/parity.blend --python engine_cancel.py
"""

import sys
import time

import bpy

from toonray_blender import engine as toonray_engine

failures = []


def check(ok, message):
    print("engine_cancel: %s: %s" % ("ok" if ok else "FAILED", message))
    if not ok:
        failures.append(message)


class Break:
    """When the engine was first told to stop, and when it first asked. `after` is a third of
    the whole frame, whatever the machine's speed."""
    after = None
    started = None
    broke = None


def stop_requested(self):
    """Blender's test_break once the user pressed Esc `after` seconds into the frame. (Python
    cannot override test_break itself: Blender's function wins over a subclass's.)"""
    now = time.monotonic()
    if Break.started is None:
        Break.started = now
    if now - Break.started >= Break.after:
        Break.broke = Break.broke or now
        return True
    return False


scene = bpy.context.scene
scene.render.resolution_x, scene.render.resolution_y = 1600, 1200
scene.toonray.sampling__samples = 16
scene.toonray.sampling__adaptive = False

# The frame uncancelled, for its length.
start = time.monotonic()
bpy.ops.render.render()
whole = time.monotonic() - start
check(whole > 0.3, "the whole frame takes %.2f s (long enough to cancel)" % whole)
Break.after = whole / 3

real_stop_requested = toonray_engine.ToonrayRenderEngine._stop_requested
toonray_engine.ToonrayRenderEngine._stop_requested = stop_requested
bpy.ops.render.render()
ended = time.monotonic()
toonray_engine.ToonrayRenderEngine._stop_requested = real_stop_requested
check(Break.broke is not None, "the engine asked Blender whether to stop")
if Break.broke is not None:
    after = ended - Break.broke
    check(after < 1.0, "the render stopped %.2f s after the break (within a second)" % after)
    check(ended - Break.started < whole, "and sooner than the whole frame")

# Blender goes on: the next render is whole.
scene.render.resolution_x, scene.render.resolution_y = 160, 120
bpy.ops.render.render()
check(True, "Blender rendered again after the cancelled frame")

# A failing render is reported, with the library's message, and Blender goes on.
scene.toonray.use_limits__triangles = True
scene.toonray.limits__triangles = "10"
reports = []
original_fail = toonray_engine.ToonrayRenderEngine._fail
toonray_engine.ToonrayRenderEngine._fail = lambda self, message: (reports.append(message),
                                                                  original_fail(self, message))
try:
    bpy.ops.render.render()  # the engine's error report makes the operator raise, here
except RuntimeError as e:
    check("more than the limit of 10" in str(e), "the operator reports it: %s" % e)
toonray_engine.ToonrayRenderEngine._fail = original_fail
check(len(reports) == 1 and "more than the limit of 10 (limits.triangles raises it)" in reports[0],
      "the limit is reported: %s" % reports)
scene.toonray.use_limits__triangles = False
bpy.ops.render.render()
check(True, "Blender rendered again after the failed frame")

# The settings document out and back in: the Render properties and the line sets.
import os
import tempfile

with tempfile.TemporaryDirectory() as folder:
    path = os.path.join(folder, "look.toml")
    settings = scene.toonray
    settings.lines__width = 3.5
    settings.lines__mode = "robust"
    line_set = bpy.context.view_layer.toonray.line_sets.add()
    line_set.objects = "Box,Sphere"
    line_set.visibility = "HIDDEN"
    line_set.use_dash = True
    line_set.dash = "4,2"
    bpy.ops.toonray.settings_export(filepath=path)
    with open(path) as f:
        text = f.read()
    check("width = 3.5" in text and 'mode = "robust"' in text and 'dash = "4,2"' in text
          and 'size = "160x120"' in text, "the exported document has the settings and the rule")
    settings.lines__width = 1.0
    settings.lines__mode = "ink"
    bpy.context.view_layer.toonray.line_sets.clear()
    bpy.ops.toonray.settings_import(filepath=path)
    sets = bpy.context.view_layer.toonray.line_sets
    check(settings.lines__width == 3.5 and settings.lines__mode == "robust",
          "importing it sets the properties back")
    check(len(sets) == 1 and sets[0].objects == "Box,Sphere" and sets[0].visibility == "HIDDEN"
          and sets[0].use_dash and sets[0].dash == "4,2" and not sets[0].use_taper,
          "and its rule becomes the line set again")

# Every section of the settings document has its panel in the Render properties.
from toonray_blender import properties  # noqa: E402

sections = {section for section, _ in properties.SECTIONS}
missing = sorted({key.split(".", 1)[0] for key, _ in properties.setting_keys()} - sections)
check(not missing, "every section of the settings has a panel (without one: %s)" % missing)
check(hasattr(bpy.types, "TOONRAY_PT_render_tone"), "the tone look has its panel")

if failures:
    sys.exit(1)
print("engine_cancel: all passed")
