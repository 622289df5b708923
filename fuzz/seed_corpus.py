#!/usr/bin/env python3
"""Writes the seed corpora in fuzz/corpus/NAME from the test data and a few hand-written inputs.

Run once after changing the test data (the seeds are committed); fuzzing adds its own finds in a
separate working corpus (scripts/fuzz.sh), so the committed seeds stay small.
"""
import os, struct, sys, zlib

root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
out = os.path.join(root, "fuzz", "corpus")


def put(target, name, data):
    d = os.path.join(out, target)
    os.makedirs(d, exist_ok=True)
    if isinstance(data, str):
        data = data.encode("latin-1")
    with open(os.path.join(d, name), "wb") as f:
        f.write(data)


def read(*parts):
    with open(os.path.join(root, *parts), "rb") as f:
        return f.read()


def head_lines(data, limit):
    """The first lines of data, at most `limit` bytes, cut at a line end."""
    if len(data) <= limit:
        return data
    cut = data.rfind(b"\n", 0, limit)
    return data[: cut + 1]


# --- OBJ, camera blocks, render ---
quad = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
camera_block = ("# Camera start\nv 16.270052 26.948549 25.997269\nv 15.863070 26.491430 25.206442\n"
                "vn -0.419904 0.862497 -0.282451\nc -3 -2 -1\n# Camera end\n")
objs = {
    "teapot_head.obj": head_lines(read("tests", "data", "teapot.obj"), 3000),
    "spot_head.obj": head_lines(read("tests", "data", "spot.obj"), 3000),
    "mixed.obj": read("tests", "data", "scene", "mixed.obj"),
    "forms.obj": quad + "vt 0 0\nvt 1 0\nvt 1 1\nvn 0 0 1\nvn 0 0 -1\n"
                 "f 1 2 3\nf 1/1 2/2 3/3\nf 1//1 2//1 3//2\nf 1/1/1 2/2/1 3/3/1\n",
    "relative.obj": "v 0 0 0\nv 1 0 0\nv 1 1 0\nf -3 -2 -1\nv 5 5 5\nf -4 -1 -2\n",
    "polygon.obj": "v 0 0 0\nv 1 0 0\nv 2 1 0\nv 1 2 0\nv 0 1 0\nf 1 2 3 4 5\n",
    "crlf_bom.obj": "\xEF\xBB\xBF# comment\r\nv 0 0 0 1\r\nv 1 0 0 1.0 # trailing\r\nv 0 1 0\r\nf 1 2 3\r\n",
    "continuation.obj": "v 0 0 \\\n0\nv 1 0 0\nv 0 1 0\nf 1 2 \\\n 3\n",
    "objects.obj": quad + "o first\nf 1 2 3\ng second\nf 1 3 4\no first\nf 2 3 4\nusemtl red\ns 1\nf 1 2 4\n",
    "numbers.obj": "v 1e-50 -1e-400 2.5e-39\nv +1 -0 .5\nv 1e38 -3.4e38 0\nf 1 2 3\n",
    "camera.obj": quad + "f 1 2 3 4\n" + camera_block,
    "camera_relative.obj": quad + "v 0 0 5\nv 0 0 4\nvn 0 1 0\nc -2 -1 -1\nf 1 2 3\n",
    "degenerate.obj": "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 0 0\nf 1 2 3\nf 1 1 1\nf 1 4 2\n",
    "statements.obj": quad + "mtllib a.mtl b.mtl\nl 1 2\np 1\nvp 0.5\ncurv 0 1 1 2\nfoo 1\nf 1 2 3\n",
}
for name, data in objs.items():
    put("obj", name, data)
    put("render", name, data)
for name in ("camera.obj", "camera_relative.obj", "objects.obj"):
    put("camera", name, objs[name])
put("camera", "bad_up.obj", "v 0 0 5\nv 0 0 4\nvn 0 0 1\nc 1 2 1\n")
put("camera", "same_point.obj", "v 0 0 5\nv 0 0 5\nvn 0 1 0\nc 1 2 1\n")
put("camera", "spec.txt", "1,2,3,0,0,0,0,1,0")

# --- MTL ---
mtls = {
    "mixed_a.mtl": read("tests", "data", "scene", "mixed_a.mtl"),
    "mixed_b.mtl": read("tests", "data", "scene", "mixed_b.mtl"),
    "full.mtl": "# all statements\nnewmtl red\nKa 0.1 0.1 0.1\nKd 1 0 0\nKs 0.5\nNs 10\nd 0.5\n"
                "Tr 0.2\nillum 2\nmap_Kd -s 1 1 1 -clamp on textures/red.png\n"
                "newmtl grey\nKd spectral file.rfl\nd -halo 0.5\nnewmtl red\nKd 0 1 0\n",
}
for name, data in mtls.items():
    put("mtl", name, data)

# --- note scripts ---
score = os.path.join("tests", "data", "score")
for name in sorted(os.listdir(os.path.join(root, score))):
    put("note_script", name, read(score, name))
put("note_script", "directives.notes",
    "ppq 480\ntempo 72\ntime 2/4\nvelocity 90\nstep S\npedal down\nE:w26,w28@100|Q.:m60\nEmpty\n"
    "wait Q+S\ntrack 2\nchannel 10\ntempo 833333us\nX:b3\n100:w52\npedal 64\npedal up\n")

# --- MIDI ---
# The whole Entertainer (22 KB) makes every run ~7 ms (it is read, written and read back twice);
# fuzz/corpus/midi/entertainer_excerpt.mid (1.7 KB, two tracks and the pedal) stands in for it.
# It was made with `toonray score convert`: data/entertainer.midi to a note script, lines 1-120
# and 1104-1190 of it plus "pedal down / E:w20 / pedal up", back to MIDI.


def chunk(kind, body):
    return kind + struct.pack(">I", len(body)) + body


small = chunk(b"MThd", struct.pack(">HHH", 1, 2, 96)) + \
    chunk(b"MTrk", bytes([0, 0xFF, 0x51, 3, 0x07, 0xA1, 0x20, 0, 0xFF, 0x58, 4, 2, 1, 24, 8,
                          0, 0xFF, 0x2F, 0])) + \
    chunk(b"MTrk", bytes([0, 0x90, 60, 80, 0, 64, 70, 0x60, 60, 0, 0, 0x80, 64, 0, 0, 0xB0, 64, 127,
                          0x81, 0x00, 0xC0, 5, 0, 0xF0, 2, 1, 0xF7, 0, 0xB0, 64, 0, 0, 0xFF, 0x2F, 0]))
put("midi", "small.mid", small)
smpte = chunk(b"MThd", struct.pack(">HHH", 0, 1, 0xE728)) + \
    chunk(b"MTrk", bytes([0, 0x90, 60, 80, 10, 0x90, 60, 0, 0, 0xFF, 0x2F, 0]))
put("midi", "smpte.mid", smpte)
put("midi", "unknown_chunk.mid", chunk(b"MThd", struct.pack(">HHH", 0, 1, 384)) + chunk(b"XFIH", b"abc") +
    chunk(b"MTrk", bytes([0, 0x99, 36, 100, 0x83, 0x60, 0x89, 36, 0, 0, 0xFF, 0x2F, 0])))

# --- camera paths ---
put("camera_path", "entertainer.campath", read("data", "entertainer.campath"))
put("camera_path", "simple.campath",
    "key 0 eye 0 1 5 target 0 0 0\nkey 2.5 eye 5 1 0 target 0 0 0 up 0 2 0 fov 60\nkey 4 eye 0 3 -5 target 0 0.5 0\n")
put("camera_path", "loop.campath", "loop 10\nkey 0 eye 1 1 1 target 0 0 0\nkey 5 eye -1 1 1 target 0 0 0 fov 30\n")

# --- command-line values (first byte picks the parser) ---
values = ["\x001920x1080", "\x01+4,6,-10.5e1", "\x021,0.5,0", "\x02#ff8000",
          "\x0316.3,26.9,26.0,15.9,26.5,25.2,-0.42,0.86,-0.28", "\x04keys_%06d.png", "\x04100%%_%d",
          "\x052/7", "\x06keys", "\x06a%b"]
for i, v in enumerate(values):
    put("options", "value%d" % i, v)


# --- shading options and the lights file (first byte: 0 ramp, 1 light, 2 lights file) ---
shading = {"ramp0": "\x000.5,0.75,1.0@0.25,0.5", "ramp1": "\x001", "light0": "\x014,6,10",
           "light1": "\x01dir:0,-1,0@0.5", "light2": "\x01point:1,2,3@2",
           "file0": "\x02# key and fill\npoint 4 6 10 1\ndirectional 0 -1 -0.5 0.4\n", "file1": "\x02point 0 0 0\n"}
for name, v in shading.items():
    put("shading", name, v)


# --- line style files ---
put("line_style", "piano_keys.style", read("docs", "examples", "piano_keys.style"))
put("line_style", "all_keys.style",
    "# every key\nmatch object=* material=* type=all lines=all draw=no\n"
    "match type=crease,silhouette,border,material,intersection lines=visible draw=yes colour=0.5,0.25,1 "
    "width=0 opacity=1 dash=none taper=0\nmatch object=a?c*,d lines=hidden dash=1,2,3 color=#ff00ff\n")
put("line_style", "bad.style", "match width=-1\n")
put("line_style", "brush_keys.style",
    "match type=band,shadow,tone pressure=0.2,1,0.4 calligraphy=0.3 nib_angle=30 brush=b.png "
    "brush_stretch=yes sketch=3 sketch_offset=2 sketch_period=40 sketch_seed=5 boil=2\n"
    "match pressure=none brush=none sketch=0\n")

# --- settings documents ---
put("settings", "every_key.toml",
    "[image]\nsize = \"320x180\"\nbackground = \"#ffffff\"\n[scene]\n"
    "camera = \"1,2,3,0,0,0,0,1,0\"\nlights = [\"dir:0,-1,0@0.5\", \"point:1,2,3\"]\n"
    "auto_smooth = 30.0\n[shading]\nramp = \"0.5,0.75,1@0.25,0.5\"\nshadows = true\n"
    "specular = false\nrim = 0.2\nrim_strength = 0.35\ntextures = true\n[lines]\n"
    "mode = \"robust\"\ntypes = \"silhouette,depth\"\ncrease_angle = 40.0\nwidth = 2.0\n"
    "colour = \"#000000\"\n[lines.classic]\ndepth_threshold = 8.0\nnormal_threshold = 4.0\n"
    "[lines.robust]\ndepth_step = 0.02\nsilhouette_ratio = 0.1\n[lines.ink]\ntaper = 2.0\n"
    "width_by_depth = true\n[sampling]\nsamples = 9\nadaptive = false\ntile_size = 64\n"
    "[render]\nthreads = 1\nbvh_leaf_size = 4\n[output]\npng_level = 3\nsvg_hidden = true\n"
    "svg_fill = false\n[limits]\nmemory = \"4G\"\ntriangles = \"5M\"\n")
put("settings", "rules.toml",
    "[[lines.rule]]\ntype = \"crease\"\ncolor = \"#3050a0\"\nwidth = 1.0\n"
    "[[lines.rule]]\nobject = \"box*\"\nlines = \"hidden\"\ndraw = true\ndash = [4, 3]\n")
put("settings", "bad_key.toml", "[lines]\nwidht = 2\n")
put("settings", "tone.toml",
    "[tone]\nmode = \"hatch\"\nanchor = \"screen\"\nhatch_direction = \"1,0,0\"\nspacing = 5.0\n"
    "angle = 30.0\n[lines]\ntypes = \"all,band\"\n[output]\nsvg_plotter = true\n")

# --- tone looks and line types (fuzz_tone) ---
for name, text in [("mode_hatch", "hatch"), ("mode_screentone", "screentone"),
                   ("anchor_screen", "screen"), ("direction_curvature", "curvature"),
                   ("direction_light", "light"), ("direction_vector", "0.5,1,-2"),
                   ("direction_y", "y"), ("direction_tiny", "1e-30,0,0"),
                   ("lines_all_band", "all,band,shadow"), ("lines_shadow", "silhouette,shadow")]:
    put("tone", name, text)


# --- PNG ---
def png(width, height, colour_type, rows):
    raw = b"".join(b"\0" + r for r in rows)
    ihdr = struct.pack(">IIBBBBB", width, height, 8, colour_type, 0, 0, 0)
    def c(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))
    return b"\x89PNG\r\n\x1a\n" + c(b"IHDR", ihdr) + c(b"IDAT", zlib.compress(raw)) + c(b"IEND", b"")


put("png", "rgb.png", png(3, 2, 2, [bytes([255, 0, 0, 0, 255, 0, 0, 0, 255])] * 2))
put("png", "gray.png", png(4, 1, 0, [bytes([0, 64, 128, 255])]))
put("png", "rgba.png", png(1, 1, 6, [bytes([1, 2, 3, 4])]))


# --- glTF: the Khronos samples as .gltf text; for fuzz_glb as "JSON\nBIN\nbinary" (the target
# wraps that in a GLB header) and one real GLB ---
import base64, json as json_module

for name in ("Box", "BoxAnimated", "RiggedSimple", "SimpleMorph", "SimpleSkin", "instances"):
    text = read("tests", "data", "gltf", name + ".gltf")
    put("gltf", name + ".gltf", text)
    doc = json_module.loads(text)
    if len(doc["buffers"]) != 1:
        continue
    uri = doc["buffers"][0].pop("uri")
    binary = base64.b64decode(uri.split(",", 1)[1])
    compact = json_module.dumps(doc, separators=(",", ":")).encode()
    put("glb", name + ".txt", compact + b"\nBIN\n" + binary)
    if name == "Box":
        j = compact + b" " * (-len(compact) % 4)
        b = binary + b"\0" * (-len(binary) % 4)
        put("glb", "Box.glb", b"glTF" + struct.pack("<II", 2, 28 + len(j) + len(b)) +
            struct.pack("<I", len(j)) + b"JSON" + j + struct.pack("<I", len(b)) + b"BIN\0" + b)
