"""Animate piano key objects from a note script, with toonray's key timing.

Key objects are found by name: PREFIX + w1..w52 (white keys) and b1..b36 (black keys), counted
from A0 as in docs/scores.md. Each key turns about one local axis of its own (its origin is the
pivot): rest angle + depth * angle, where depth is toonray's PianoPlayback key depth (0 at rest,
1 fully down) at the frame's score time, t = (frame - start_frame) / fps.

Two ways to key it:

- 'PRESS' (default): the depth curve is piecewise linear, so four keyframes per press (begins
  down, bottoms out at the onset, starts up, back up; fewer when presses crowd each other) with
  linear interpolation reproduce it exactly at every frame and subframe. Keyframes may fall
  between frames.
- 'FRAME': one keyframe per frame on every frame where the key moves (plus one either side),
  for pipelines that resample or that want keys on whole frames only.
"""

import math

import bpy

from . import note_script as ns

REST_PROPERTY = "toonray_key_rest"
AXES = {"X": 0, "Y": 1, "Z": 2}


class KeyAnimationError(Exception):
    pass


def _fcurves_of(obj):
    """The F-curve collection animating obj: Action.fcurves up to 4.x, the slot's channelbag in
    4.4+ (slotted actions; Action.fcurves is gone in 5.0)."""
    ad = obj.animation_data
    if ad is None or ad.action is None:
        return None
    action = ad.action
    slot = getattr(ad, "action_slot", None)
    if slot is not None:
        try:
            from bpy_extras.anim_utils import action_get_channelbag_for_slot
        except ImportError:
            action_get_channelbag_for_slot = None
        if action_get_channelbag_for_slot is not None:
            bag = action_get_channelbag_for_slot(action, slot)
            return bag.fcurves if bag is not None else None
    return getattr(action, "fcurves", None)


def _find_fcurve(obj, data_path, index):
    fcurves = _fcurves_of(obj)
    if fcurves is None:
        return None
    for fc in fcurves:
        if fc.data_path == data_path and fc.array_index == index:
            return fc
    return None


def _remove_fcurve(obj, data_path, index):
    fc = _find_fcurve(obj, data_path, index)
    if fc is not None:
        _fcurves_of(obj).remove(fc)


def find_key_objects(scene, prefix=""):
    """{midi: object} for the key objects in the scene named PREFIX + w1..w52 / b1..b36."""
    found = {}
    objects = scene.objects
    for midi in range(ns.LOWEST_KEY, ns.HIGHEST_KEY + 1):
        obj = objects.get(prefix + ns.key_name(midi))
        if obj is not None:
            found[midi] = obj
    return found


def animate_keys(scene, notes_path=None, score=None, prefix="", start_frame=1.0, tempo_bpm=0.0,
                 axis="X", angle=0.042, mode="PRESS", replace=True, report=None):
    """Keys the rotation of the key objects from a note script (path or parsed Score).

    start_frame: the frame at which score time 0 falls (may be fractional).
    tempo_bpm: if > 0, the default tempo instead of 72 (until the script's first 'tempo').
    angle: radians at full depth (toonray's piano dips 0.042 rad); negative turns the other way.
    replace: remove the keys' existing keyframes on that rotation channel first.
    Returns a summary dict."""
    if score is None:
        if not notes_path:
            raise KeyAnimationError("no note script given")
        try:
            score = ns.load_note_script(bpy.path.abspath(notes_path), tempo_bpm or None)
        except ns.NoteScriptError as e:
            raise KeyAnimationError(str(e))
        except OSError as e:
            raise KeyAnimationError("cannot read note script %s: %s"
                                    % (notes_path, e.strerror or e))
    if axis not in AXES:
        raise KeyAnimationError("axis must be X, Y or Z (got %r)" % (axis,))
    if mode not in ("PRESS", "FRAME"):
        raise KeyAnimationError("mode must be PRESS or FRAME (got %r)" % (mode,))
    index = AXES[axis]
    fps = scene.render.fps / scene.render.fps_base
    playback = ns.KeyPlayback(score.notes_in_seconds())
    keys = find_key_objects(scene, prefix)
    if not keys:
        raise KeyAnimationError("no key objects named %sw1..%sw52 or %sb1..%sb36 in scene '%s'"
                                % (prefix, prefix, prefix, prefix, scene.name))
    for midi, obj in keys.items():
        if obj.rotation_mode in ("QUATERNION", "AXIS_ANGLE"):
            raise KeyAnimationError("key object '%s' uses %s rotation; set it to an Euler mode "
                                    "(Object properties > Transform > Mode)"
                                    % (obj.name, obj.rotation_mode))

    def frame_of(t):
        return start_frame + t * fps

    played = set(playback.presses)
    missing = sorted(played - set(keys))
    keyframes = 0
    for midi, obj in sorted(keys.items()):
        if REST_PROPERTY in obj.keys():
            rest = float(obj[REST_PROPERTY])
        else:
            rest = float(obj.rotation_euler[index])
            obj[REST_PROPERTY] = rest
        if replace:
            _remove_fcurve(obj, "rotation_euler", index)
        if midi not in played:
            if replace:
                obj.rotation_euler[index] = rest
            continue
        if mode == "PRESS":
            points = [(frame_of(t), d) for t, d in playback.breakpoints(midi)]
        else:
            points = []
            for begin, end in _spans(playback, midi):
                f0 = int(math.floor(frame_of(begin))) - 1
                f1 = int(math.ceil(frame_of(end))) + 1
                for f in range(max(f0, points[-1][0] + 1 if points else f0), f1 + 1):
                    points.append((f, playback.depth(midi, (f - start_frame) / fps)))
        keyframes += _insert(obj, index, [(f, rest + angle * d) for f, d in points])
    summary = {"keys_animated": len(played & set(keys)), "keyframes": keyframes,
               "notes": len(score.notes), "ignored_notes": playback.ignored,
               "missing_keys": [prefix + ns.key_name(m) for m in missing],
               "end_frame": frame_of(score.end_time()), "warnings": list(score.warnings)}
    if report:
        report("%d keys animated with %d keyframes from %d notes"
               % (summary["keys_animated"], keyframes, summary["notes"]))
        if missing:
            report("warning: no object for %d played key(s): %s"
                   % (len(missing), ", ".join(summary["missing_keys"])))
        for w in score.warnings:
            report("warning: " + w)
    return summary


def _spans(playback, midi):
    """Runs of overlapping activity of a key (first move, last back up)."""
    s = playback.settings
    spans = []
    for p in playback.presses[midi]:
        b, e = p.on - s.attack, p.off + s.release
        if spans and b <= spans[-1][1]:
            spans[-1] = (spans[-1][0], max(spans[-1][1], e))
        else:
            spans.append((b, e))
    return spans


def _insert(obj, index, points):
    """Inserts keyframes (frame, value) on rotation_euler[index], linear interpolation."""
    if not points:
        return 0
    first_frame, first_value = points[0]
    obj.rotation_euler[index] = first_value
    obj.keyframe_insert(data_path="rotation_euler", index=index, frame=first_frame)
    fc = _find_fcurve(obj, "rotation_euler", index)
    if fc is None:
        raise KeyAnimationError("could not find the F-curve just keyed on '%s'" % obj.name)
    kps = fc.keyframe_points
    for frame, value in points[1:]:
        kps.insert(frame, value, options={"FAST"})
    for kp in kps:
        kp.interpolation = "LINEAR"
    fc.update()
    return len(points)
