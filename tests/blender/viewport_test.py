"""The viewport preview in a real Blender window (engine_test.sh runs it under Xvfb with Mesa's
software OpenGL): a 3D view in Rendered shading with the toonray engine draws toonray's frames
of its view, first with one sample per pixel and then refined, and follows the view when it
turns. Meanwhile the Properties editor shows the engine's Render, Output, View Layer (with a
line set), Object and Material panels, so that their drawing runs too (engine_test.sh fails on
a Python error in the log). Writes WORK/viewport.json with what it saw and the frame times.

    xvfb-run blender WORK/parity.blend --python viewport_test.py -- WORK
"""

import json
import math
import os
import sys
import time

import bpy
from mathutils import Quaternion

from toonray_blender import preview

work = sys.argv[sys.argv.index("--") + 1]
result = {"draws": [], "errors": []}
state = {"step": 0, "started": time.monotonic(), "turns": 0}
TURNS = 4


def view3d():
    return area_of("VIEW_3D")


def area_of(kind):
    for window in bpy.context.window_manager.windows:
        for area in window.screen.areas:
            if area.type == kind:
                return window, area, area.spaces.active
    return None, None, None


PANELS = ["RENDER", "OUTPUT", "VIEW_LAYER", "OBJECT", "MATERIAL"]


def show_panels(turn):
    """The Properties editor on the next tab of PANELS."""
    _w, area, space = area_of("PROPERTIES")
    if space is None:
        return
    space.context = PANELS[turn % len(PANELS)]
    area.tag_redraw()


def finish(ok):
    result["ok"] = ok
    with open(os.path.join(work, "viewport.json"), "w") as f:
        json.dump(result, f, indent=1)
    bpy.ops.wm.quit_blender()


def tick():
    try:
        return step()
    except Exception as e:
        result["errors"].append(repr(e))
        finish(False)
        return None


def step():
    window, area, space = view3d()
    if state["step"] == 0:
        if space is None:
            result["errors"].append("no 3D view")
            finish(False)
            return None
        scene = bpy.context.scene
        scene.render.engine = "TOONRAY"
        line_set = bpy.context.view_layer.toonray.line_sets.add()
        line_set.name = "Boxes"
        line_set.objects = "Box"
        line_set.use_dash = True
        bpy.context.view_layer.objects.active = scene.objects["Box"]
        show_panels(0)
        space.shading.type = "RENDERED"
        space.region_3d.view_perspective = "PERSP"
        space.region_3d.view_distance = 12.0
        area.tag_redraw()
        state["step"] = 1
        state["asked"] = time.monotonic()
        return 0.05
    previews = list(preview.active)
    if time.monotonic() - state["started"] > 120:
        result["errors"].append("timed out at step %d with %d previews" % (state["step"],
                                                                            len(previews)))
        finish(False)
        return None
    if not previews:
        return 0.05
    p = previews[0]
    with p.lock:
        drawn, frame = p.drawn, p.frame
    if p.error:
        result["errors"].append(p.error)
    if drawn is None or frame is None or drawn != (p.generation, 2):
        return 0.05
    rgba = frame[0]
    result["draws"].append({"generation": drawn[0], "size": [frame[1], frame[2]],
                            "seconds": time.monotonic() - state["asked"],
                            "timings": p.timings[-2:], "sync_seconds": p.sync_seconds,
                            "non_background": float((abs(rgba[..., 2] - 1.0) > 0.01).mean())})
    if state["turns"] == TURNS:
        finish(True)
        return None
    # Turn the view about the vertical axis and wait for its refined frame to be drawn.
    rv3d = space.region_3d
    rv3d.view_rotation = Quaternion((0, 0, 1), math.radians(12)) @ rv3d.view_rotation
    area.tag_redraw()
    state["turns"] += 1
    show_panels(state["turns"])
    state["asked"] = time.monotonic()
    return 0.05


bpy.app.timers.register(tick, first_interval=1.0)
