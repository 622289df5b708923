"""Checks toonray's renders of the exported frames against Blender (tests/blender/run_test.sh).

    blender -b --factory-startup --python check_frames.py -- WORK REPO

For each config (WORK/scene_X.blend, frames WORK/X/keys_NNNNNN.obj, renders WORK/X/aov/):

1. Camera: for every rendered frame and every cube, the cube's corners projected with Blender's
   own camera (bpy_extras.object_utils.world_to_camera_view, evaluated camera at that frame)
   outline a silhouette (their convex hull) that toonray's depth AOV matches to within 1 pixel:
   every pixel whose centre is more than a pixel inside it shows the cube, none more than a
   pixel outside shows anything, and each corner lands on a pixel showing the cube. Cubes that
   Blender projects within 5 pixels of another object, or near the frame's edge, are skipped
   (and counted: each config must check enough of them).
2. Keys (configs A and B): the key objects' exported vertices turn by the angle the note script
   says at each frame: hand-worked states for w24 (down at the onsets, a visible release
   between repeated notes) and, for every animated key and frame, the depth that toonray's own
   piano (toonray piano --export-obj, WORK/piano) gives.

Prints one line per failure and a summary 'N passed, M failed'; exits 1 on any failure.
"""

import json
import math
import os
import struct
import sys
import zlib

import bpy

sys.dont_write_bytecode = True  # leave no __pycache__ in the source tree
from bpy_extras.object_utils import world_to_camera_view
from mathutils import Vector

argv = sys.argv[sys.argv.index("--") + 1:]
WORK, REPO = os.path.abspath(argv[0]), os.path.abspath(argv[1])
CONFIGS = json.loads(argv[2]) if len(argv) > 2 else None
KEY_ANGLE = 0.2          # what build_scene.py and the command line used
PIANO_KEY_ANGLE = 0.042  # kKeyDipAngle of toonray's piano
PIANO_PIVOT = (0.698, 0.10)  # (y, z) of the piano keys' axis in toonray's piano OBJ
CUBES = ("CubeA", "CubeB", "CubeC")

passed = failed = 0
notes = []


def check(ok, what):
    global passed, failed
    if ok:
        passed += 1
    else:
        failed += 1
        print("FAIL:", what, flush=True)
    return ok


# ---- PNG (8-bit grey, grey+alpha, RGB, RGBA or indexed, not interlaced) --------------------

def read_png(path):
    with open(path, "rb") as f:
        data = f.read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise ValueError("%s: not a PNG" % path)
    pos, idat, width, palette = 8, [], None, None
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        pos += 12 + length
        if kind == b"IHDR":
            width, height, depth, ctype, _c, _f, interlace = struct.unpack(">IIBBBBB", body)
            if depth != 8 or interlace != 0 or ctype not in (0, 2, 3, 4, 6):
                raise ValueError("%s: unsupported PNG (depth %d, type %d)" % (path, depth, ctype))
            channels = {0: 1, 2: 3, 3: 1, 4: 2, 6: 4}[ctype]  # indexed: one index a pixel
        elif kind == b"PLTE":
            palette = body  # toonray writes frames of at most 256 colours indexed
        elif kind == b"IDAT":
            idat.append(body)
        elif kind == b"IEND":
            break
    raw = zlib.decompress(b"".join(idat))
    stride = width * channels
    rows, prev = [], bytearray(stride)
    for y in range(height):
        off = y * (stride + 1)
        ftype, line = raw[off], bytearray(raw[off + 1:off + 1 + stride])
        for i in range(stride):
            a = line[i - channels] if i >= channels else 0
            b = prev[i]
            c = prev[i - channels] if i >= channels else 0
            if ftype == 1:
                line[i] = (line[i] + a) & 255
            elif ftype == 2:
                line[i] = (line[i] + b) & 255
            elif ftype == 3:
                line[i] = (line[i] + ((a + b) >> 1)) & 255
            elif ftype == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(line)
        prev = line
    if palette is not None:  # indexed: expand to RGB
        rows = [bytearray(b"".join(palette[3 * i:3 * i + 3] for i in row)) for row in rows]
        channels = 3
    return width, height, channels, rows


def coverage(depth_png, normal_png):
    """Pixels where toonray hit something: depth < 255 (misses are 255). The farthest hit is 255
    too, so a pixel whose normal AOV is not (0,0,0) (the misses' value) also counts."""
    w, h, dc, drows = read_png(depth_png)
    w2, h2, nc, nrows = read_png(normal_png)
    assert (w, h) == (w2, h2)
    mask = []
    for y in range(h):
        d, n = drows[y], nrows[y]
        mask.append([d[x * dc] < 255 or any(n[x * nc:x * nc + 3]) for x in range(w)])
    return w, h, mask


# ---- OBJ --------------------------------------------------------------------------------------

def obj_objects(path):
    """{object name: [(x, y, z)]} for Blender's OBJ files (vertices follow their 'o' line), and the
    camera block's (eye, gaze, up)."""
    objects, current, camera, in_cam = {}, None, [], False
    with open(path) as f:
        for line in f:
            if line.startswith("o "):
                current = objects.setdefault(line[2:].strip(), [])
            elif line.startswith("# Camera start"):
                in_cam = True
            elif line.startswith("v ") or line.startswith("vn "):
                vals = tuple(float(t) for t in line.split()[1:4])
                if in_cam:
                    camera.append(vals)
                elif line.startswith("v ") and current is not None:
                    current.append(vals)
    return objects, camera


def piano_key_vertices(path, names):
    """{key name: [(x, y, z)]} from toonray's piano OBJ (all v first; 'o' lines among the faces)."""
    verts, current, members = [], None, {n: set() for n in names}
    with open(path) as f:
        for line in f:
            c = line[:2]
            if c == "v ":
                parts = line.split()
                verts.append((float(parts[1]), float(parts[2]), float(parts[3])))
            elif c == "o ":
                current = line[2:].split()[0]
            elif c == "f " and current in members:
                for corner in line.split()[1:]:
                    members[current].add(int(corner.split("/")[0]))
            elif line.startswith("# Camera start"):
                break
    return {n: [verts[i - 1] for i in sorted(idx)] for n, idx in members.items()}


def key_angle(rest, posed, pivot_yz):
    """Rotation about +x (radians, + = front down) taking rest to posed, from the vertices
    farthest from the pivot axis."""
    py, pz = pivot_yz
    rel = [((r[1] - py, r[2] - pz), (p[1] - py, p[2] - pz)) for r, p in zip(rest, posed)]
    far = max(math.hypot(*r) for r, _ in rel)
    angles = []
    for (ry, rz), (qy, qz) in rel:
        if math.hypot(ry, rz) < 0.5 * far:
            continue
        a = math.atan2(qz, qy) - math.atan2(rz, ry)
        angles.append((a + math.pi) % (2 * math.pi) - math.pi)
    return sum(angles) / len(angles)


# ---- 2D geometry ------------------------------------------------------------------------------

def convex_hull(points):
    """Counter-clockwise hull (in a y-down frame: clockwise on screen) by the monotone chain."""
    pts = sorted(set(points))

    def cross(o, a, b):
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    lower, upper = [], []
    for p in pts:
        while len(lower) >= 2 and cross(lower[-2], lower[-1], p) <= 0:
            lower.pop()
        lower.append(p)
    for p in reversed(pts):
        while len(upper) >= 2 and cross(upper[-2], upper[-1], p) <= 0:
            upper.pop()
        upper.append(p)
    return lower[:-1] + upper[:-1]


def signed_distance(hull, p):
    """Distance from p to the convex polygon's outline: negative inside."""
    inside = True
    best = float("inf")
    n = len(hull)
    for i in range(n):
        a, b = hull[i], hull[(i + 1) % n]
        ex, ey = b[0] - a[0], b[1] - a[1]
        if ex * (p[1] - a[1]) - ey * (p[0] - a[0]) < 0:
            inside = False
        length2 = ex * ex + ey * ey
        t = 0.0 if length2 == 0 else max(0.0, min(1.0, ((p[0] - a[0]) * ex + (p[1] - a[1]) * ey) / length2))
        best = min(best, math.hypot(p[0] - a[0] - t * ex, p[1] - a[1] - t * ey))
    return -best if inside else best


# ---- camera check ------------------------------------------------------------------------------

def frames_of(folder):
    out = []
    for f in sorted(os.listdir(folder)):
        if f.startswith("keys_") and f.endswith(".obj"):
            out.append(int(f[5:11]))
    return out


def check_camera(tag, folder, size):
    scene = bpy.context.scene
    W, H = size
    checked = 0
    with open(os.path.join(folder, "keys_%06d.obj" % frames_of(folder)[0])) as f:
        said = [line for line in f if line.startswith("# toonray camera:")]
    check(said and said[0].rstrip().endswith("--size %dx%d" % (W, H)),
          "%s: the camera comment should recommend --size %dx%d: %s" % (tag, W, H, said))
    for frame in frames_of(folder):
        depth_png = os.path.join(folder, "aov", "keys_%06d_depth.png" % frame)
        if not os.path.exists(depth_png):
            continue
        w, h, mask = coverage(depth_png, depth_png.replace("_depth.png", "_normal.png"))
        if not check((w, h) == (W, H), "%s frame %d: AOV is %dx%d, expected %dx%d" % (tag, frame, w, h, W, H)):
            continue
        scene.frame_set(frame)
        dg = bpy.context.evaluated_depsgraph_get()
        cam = scene.camera.evaluated_get(dg)
        projected, boxes = {}, {}
        for obj in scene.objects:
            if obj.type != "MESH":
                continue
            ev = obj.evaluated_get(dg)
            pts = []
            for v in ev.data.vertices:
                ndc = world_to_camera_view(scene, cam, ev.matrix_world @ v.co)
                pts.append((ndc.x * W, (1.0 - ndc.y) * H))
            projected[obj.name] = pts
            boxes[obj.name] = (int(math.floor(min(p[0] for p in pts))), int(math.floor(max(p[0] for p in pts))),
                               int(math.floor(min(p[1] for p in pts))), int(math.floor(max(p[1] for p in pts))))
        for name in CUBES:
            px = projected[name]
            x0, x1, y0, y1 = boxes[name]
            where = "%s frame %d %s" % (tag, frame, name)
            if x0 < 5 or y0 < 5 or x1 > W - 6 or y1 > H - 6:
                notes.append("%s: partly outside the frame, not checked" % where)
                continue
            # Isolation, from Blender's own projections: no other object's box within 5 pixels,
            # so every covered pixel near the cube must be the cube.
            if any(b[0] <= x1 + 5 and b[1] >= x0 - 5 and b[2] <= y1 + 5 and b[3] >= y0 - 5
                   for other, b in boxes.items() if other != name):
                notes.append("%s: another object within 5 pixels, not checked" % where)
                continue
            # toonray samples pixel centres: a pixel well inside Blender's silhouette (the hull of
            # the projected corners) must be covered, one well outside must not, within 1 pixel.
            hull = convex_hull(px)
            wrong = []
            for y in range(y0 - 4, y1 + 5):
                for x in range(x0 - 4, x1 + 5):
                    sd = signed_distance(hull, (x + 0.5, y + 0.5))
                    if (mask[y][x] and sd > 1.0) or (not mask[y][x] and sd < -1.0):
                        wrong.append((x, y, round(sd, 2)))
            check(not wrong, "%s: %d pixel(s) more than 1 pixel off Blender's silhouette, e.g. %s"
                  % (where, len(wrong), wrong[:3]))
            # Each corner lands on the object: inside the silhouette, its pixel is covered; on the
            # outline, a covered pixel centre lies within 1 pixel of the outline next to it.
            for (fx, fy) in px:
                ix, iy = int(math.floor(fx)), int(math.floor(fy))
                if signed_distance(hull, (fx, fy)) < -0.75:
                    check(mask[iy][ix], "%s: corner at (%.2f, %.2f) is inside Blender's silhouette "
                          "but toonray shows no object at pixel (%d, %d)" % (where, fx, fy, ix, iy))
                else:
                    near = any(mask[iy + dy][ix + dx] for dx in range(-2, 3) for dy in range(-2, 3)
                               if signed_distance(hull, (ix + dx + 0.5, iy + dy + 0.5)) < 0.0)
                    ok = near or all(signed_distance(hull, (ix + dx + 0.5, iy + dy + 0.5)) > -0.5
                                     for dx in range(-2, 3) for dy in range(-2, 3))
                    check(ok, "%s: corner at (%.2f, %.2f): no covered pixel near it" % (where, fx, fy))
            checked += 1
    return checked


# ---- key check ---------------------------------------------------------------------------------

# Hand-worked from keys_test.notes (tempo 120: a line is 6 frames; frame f is t = (f - 1) / 24;
# a key starts down 15 ms before its onset, rises over 25 ms from its end, and a repeated key is
# fully up 1/24 s before the next press begins).
W24_EXPECTED = {1: 0, 12: 0, 13: 1, 16: 1, 19: 1, 20: 0, 30: 0, 31: 1, 35: 1, 36: 0, 37: 1,
                43: 1, 44: 0}
# w27 (second voice) is caught part way: 15 ms attack from 0.3678 s, 25 ms release from 0.65625 s.
W27_EXPECTED = {9: 0, 10: (0.375 - 0.3678125) / 0.015, 11: 1, 16: 1, 17: 1 - (16 / 24 - 0.65625) / 0.025,
                18: 0}
ANIMATED = ("w22", "w24", "w26", "w27", "w28", "w30", "b17")


def check_keys(tag, folder, piano):
    frames = frames_of(folder)
    if 1 not in frames:
        return check(False, "%s: frame 1 (all keys at rest) was not exported" % tag)
    rest_objs, _ = obj_objects(os.path.join(folder, "keys_000001.obj"))
    scene = bpy.context.scene
    for frame in frames:
        objs, _ = obj_objects(os.path.join(folder, "keys_%06d.obj" % frame))
        for name in ANIMATED:
            loc = scene.objects[name].matrix_world.translation  # the pivot (Blender coordinates)
            pivot = (loc.z, -loc.y)                              # (y, z) in OBJ coordinates
            depth = key_angle(rest_objs[name], objs[name], pivot) / KEY_ANGLE
            where = "%s frame %d %s" % (tag, frame, name)
            expected = {"w24": W24_EXPECTED, "w27": W27_EXPECTED}.get(name, {})
            if frame in expected:
                check(abs(depth - expected[frame]) < 1e-3,
                      "%s: depth %.4f, the script says %.4f" % (where, depth, expected[frame]))
            if piano is not None and frame in piano:
                want = piano[frame][name]
                check(abs(depth - want) < 2e-3,
                      "%s: depth %.4f, toonray piano has %.4f" % (where, depth, want))
        # Keys the script never plays stay at rest.
        for name in ("w20", "w25", "b14"):
            check(max(abs(a - b) for p, q in zip(rest_objs[name], objs[name]) for a, b in zip(p, q)) < 1e-5,
                  "%s frame %d %s: moved, but the script never plays it" % (tag, frame, name))


def piano_depths():
    folder = os.path.join(WORK, "piano")
    frames = frames_of(folder)
    rest = piano_key_vertices(os.path.join(folder, "keys_000001.obj"), ANIMATED)
    out = {}
    for frame in frames:
        posed = piano_key_vertices(os.path.join(folder, "keys_%06d.obj" % frame), ANIMATED)
        out[frame] = {n: key_angle(rest[n], posed[n], PIANO_PIVOT) / PIANO_KEY_ANGLE for n in ANIMATED}
    return out


def check_parser():
    """The add-on's note-script reader on the demo score as toonray writes it (the whole
    extension: ppq, tracks, step S, ties, waits, @velocity) and on bad input."""
    import importlib.util
    spec = importlib.util.spec_from_file_location(
        "ns", os.path.join(REPO, "blender", "toonray_blender", "note_script.py"))
    ns = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(ns)
    score = ns.load_note_script(os.path.join(WORK, "entertainer.notes"))
    notes = score.notes_in_seconds()
    # docs/scores.md: 2621 notes, keys 29..90, velocities 90 and 127, the last note ends at
    # tick 116544 = 252.917 s, the piece at tick 116736 = 253.333 s.
    check(len(notes) == 2621, "entertainer: %d notes, expected 2621" % len(notes))
    check(min(n[2] for n in notes) == 29 and max(n[2] for n in notes) == 90, "entertainer: key range")
    check(sorted(set(n[3] for n in notes)) == [90, 127], "entertainer: velocities")
    check(score.end_tick == 116736 and max(n.end for n in score.notes) == 116544,
          "entertainer: end ticks %d / %d" % (score.end_tick, max(n.end for n in score.notes)))
    check(abs(score.end_time() - 116736 * 0.833333 / 384) < 1e-9, "entertainer: end time %r" % score.end_time())
    for text, message in (("E:w24\nQ:w53\n", "bad.notes:2: unknown key 'w53': white keys are w1..w52"),
                          ("tempo fast\n", "bad.notes:1: bad tempo 'fast'"),
                          ("E:w24\nppq 96\n", "bad.notes:2: 'ppq' must come before every other line"),
                          ("Z:w1\n", "bad.notes:1: unknown duration 'Z'")):
        try:
            ns.parse_note_script(text, "bad.notes")
            check(False, "no error for %r" % text)
        except ns.NoteScriptError as e:
            check(str(e).startswith(message), "error for %r: %s" % (text, e))
    midi = os.path.join(REPO, "data", "entertainer.midi")
    try:
        ns.load_note_script(midi)
        check(False, "no error for a MIDI file")
    except ns.NoteScriptError as e:
        check("toonray score convert" in str(e), "MIDI file error: %s" % e)


def check_fov_rule():
    """The add-on's field of view against Blender's own camera frame (Camera.view_frame) over
    sensor fits, resolutions, pixel aspects, lenses and sensors, rendered or not."""
    import importlib.util
    spec = importlib.util.spec_from_file_location(
        "cam", os.path.join(REPO, "blender", "toonray_blender", "camera.py"))
    cam = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(cam)
    scene = bpy.context.scene
    data = bpy.data.cameras.new("fov_probe")
    worst = 0.0
    for fit in ("AUTO", "HORIZONTAL", "VERTICAL"):
        for (w, h) in ((320, 180), (200, 300), (180, 320), (100, 100), (1920, 817)):
            for (pax, pay) in ((1, 1), (1.5, 1), (1, 2), (3, 2)):
                for lens, sw, sh in ((32, 36, 24), (85, 23.6, 15.6), (14, 36, 36)):
                    data.sensor_fit, data.lens, data.sensor_width, data.sensor_height = fit, lens, sw, sh
                    scene.render.resolution_x, scene.render.resolution_y = w, h
                    scene.render.pixel_aspect_x, scene.render.pixel_aspect_y = pax, pay
                    frame = data.view_frame(scene=scene)  # corners in camera space, z < 0
                    blender = max(abs(v.x) for v in frame) / abs(frame[0].z)
                    ours = cam.tan_half_fov_x(lens, sw, sh, fit, w, h, pax, pay)
                    worst = max(worst, abs(ours / blender - 1.0))
                    # The vertical extent toonray gives at the recommended size matches too.
                    bw, bh = cam.square_pixel_size(w, h, pax, pay)
                    blender_v = max(abs(v.y) for v in frame) / abs(frame[0].z)
                    if bh * pay / pax == h or pax == pay:
                        worst = max(worst, abs(ours * bh / bw / blender_v - 1.0))
    bpy.data.cameras.remove(data)
    check(worst < 1e-5, "field of view differs from Blender's view_frame by %.2g (relative)" % worst)


def main():
    check_parser()
    check_fov_rule()
    piano = piano_depths()
    check(len(piano) >= 48, "toonray piano exported %d frames, expected 48" % len(piano))
    check(piano[13]["w24"] > 0.99 and piano[36]["w24"] < 0.01, "toonray piano's own w24 timing")
    total_camera = {}
    for tag, cfg in sorted(CONFIGS.items()):
        bpy.ops.wm.open_mainfile(filepath=os.path.join(WORK, "scene_%s.blend" % tag))
        folder = os.path.join(WORK, tag)
        n = check_camera(tag, folder, tuple(cfg["size"]))
        total_camera[tag] = n
        check(n >= cfg["min_checks"], "%s: only %d cube projections checked (want >= %d)"
              % (tag, n, cfg["min_checks"]))
        if cfg.get("keys"):
            check_keys(tag, folder, piano)
    for line in notes:
        print("note:", line)
    print("camera checks per config:", total_camera)
    print("%d passed, %d failed" % (passed, failed), flush=True)
    sys.exit(1 if failed else 0)


main()
