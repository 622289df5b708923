# Writes tests/data/gltf/instances.gltf (python3 make_instances.py instances.gltf): a small
# instanced scene (a mesh shared by three nodes, one mirrored; EXT_mesh_gpu_instancing; a ground;
# a camera) for the frame comparison across builds and instruction sets.
import base64, json, math, struct, sys

def sphere(rings, segs):
    pos, nor, idx = [], [], []
    for r in range(rings + 1):
        th = math.pi * r / rings
        for k in range(segs):
            ph = 2 * math.pi * k / segs
            n = (math.sin(th) * math.cos(ph), math.cos(th), math.sin(th) * math.sin(ph))
            if r in (0, rings): n = (0.0, 1.0 if r == 0 else -1.0, 0.0)
            pos.append(n); nor.append(n)
    ids = lambda r, k: r * segs + k % segs
    for r in range(rings):
        for k in range(segs):
            a, b, c, d = ids(r, k), ids(r, k + 1), ids(r + 1, k + 1), ids(r + 1, k)
            if r > 0: idx += [a, c, b]
            if r + 1 < rings: idx += [a, d, c]
    return pos, nor, idx

def box():
    p = [(x, y, z) for z in (-0.5, 0.5) for y in (0.0, 1.4) for x in (-0.5, 0.5)]
    q = [(0,2,3,1),(4,5,7,6),(0,1,5,4),(2,6,7,3),(0,4,6,2),(1,3,7,5)]
    idx = []
    for a, b, c, d in q: idx += [a, b, c, a, c, d]
    return p, idx

def look_rotation(eye, target):
    f = [t - e for t, e in zip(target, eye)]
    l = math.sqrt(sum(v * v for v in f)); f = [v / l for v in f]
    r = [-f[2], 0.0, f[0]]; l = math.sqrt(sum(v * v for v in r)); r = [v / l for v in r]
    u = [r[1] * f[2] - r[2] * f[1], r[2] * f[0] - r[0] * f[2], r[0] * f[1] - r[1] * f[0]]
    m = [[r[0], u[0], -f[0]], [r[1], u[1], -f[1]], [r[2], u[2], -f[2]]]
    t = m[0][0] + m[1][1] + m[2][2]
    k = 0.5 / math.sqrt(t + 1.0)
    return [(m[2][1] - m[1][2]) * k, (m[0][2] - m[2][0]) * k, (m[1][0] - m[0][1]) * k, 0.25 / k]

EYE = (5.5, 4.2, 7.0)
bin_ = bytearray(); views = []; accessors = []
def add(data, fmt, count, type_, comp, minmax=None):
    while len(bin_) % 4: bin_.append(0)
    off = len(bin_)
    for v in data: bin_.extend(struct.pack(fmt, *v) if isinstance(v, tuple) else struct.pack(fmt, v))
    views.append({"buffer": 0, "byteOffset": off, "byteLength": len(bin_) - off})
    acc = {"bufferView": len(views) - 1, "componentType": comp, "count": count, "type": type_}
    if minmax:
        acc["min"] = [min(v[i] for v in data) for i in range(3)]
        acc["max"] = [max(v[i] for v in data) for i in range(3)]
    accessors.append(acc)
    return len(accessors) - 1

sp, sn, si = sphere(10, 18)
a_sp = add(sp, "<3f", len(sp), "VEC3", 5126, True)
a_sn = add(sn, "<3f", len(sn), "VEC3", 5126)
a_si = add(si, "<H", len(si), "SCALAR", 5123)
bp, bi = box()
a_bp = add(bp, "<3f", len(bp), "VEC3", 5126, True)
a_bi = add(bi, "<H", len(bi), "SCALAR", 5123)
gp = [(-6.0, 0.0, -6.0), (6.0, 0.0, -6.0), (6.0, 0.0, 6.0), (-6.0, 0.0, 6.0)]
a_gp = add(gp, "<3f", 4, "VEC3", 5126, True)
a_gi = add([0, 2, 1, 0, 3, 2], "<H", 6, "SCALAR", 5123)
trans = [(-2.5, 1.0, -1.0), (-1.0, 0.8, 1.5), (0.8, 1.2, 2.2), (2.4, 0.9, 0.4), (1.5, 1.1, -2.0), (-0.2, 0.7, -2.6)]
rot = [(0.0, math.sin(0.15 * i), 0.0, math.cos(0.15 * i)) for i in range(6)]
scl = [(0.7 + 0.05 * i, 0.6 + 0.08 * i, 0.7) for i in range(6)]
a_t = add(trans, "<3f", 6, "VEC3", 5126)
a_r = add(rot, "<4f", 6, "VEC4", 5126)
a_s = add(scl, "<3f", 6, "VEC3", 5126)
while len(bin_) % 4: bin_.append(0)
doc = {
    "asset": {"version": "2.0", "generator": "tests/data/gltf/README.md (instances.gltf)"},
    "extensionsUsed": ["EXT_mesh_gpu_instancing"],
    "scene": 0, "scenes": [{"nodes": [0, 1, 5, 6, 7]}],
    "nodes": [
        {"name": "ground", "mesh": 2},
        {"name": "stack", "children": [2, 3, 4], "translation": [0.3, 0.0, 0.2]},
        {"name": "box.a", "mesh": 1, "rotation": [0.0, 0.3826834, 0.0, 0.9238795]},
        {"name": "box.b", "mesh": 1, "translation": [0.55, 0.2, 0.1], "scale": [1.2, 0.7, 0.9]},
        {"name": "box.c", "mesh": 1, "translation": [-0.9, 0.0, 0.4], "scale": [-1.0, 1.1, 1.0]},
        {"name": "balls", "mesh": 0, "extensions": {"EXT_mesh_gpu_instancing": {"attributes": {"TRANSLATION": a_t, "ROTATION": a_r, "SCALE": a_s}}}},
        {"name": "ball.lone", "mesh": 0, "translation": [3.5, 0.6, 2.8], "scale": [0.6, 0.6, 0.6]},
        {"name": "camera", "camera": 0, "translation": list(EYE), "rotation": look_rotation(EYE, (0.0, 0.6, 0.0))},
    ],
    "cameras": [{"type": "perspective", "perspective": {"yfov": 0.75, "znear": 0.1, "aspectRatio": 1.7778}}],
    "materials": [
        {"name": "ball", "pbrMetallicRoughness": {"baseColorFactor": [0.45, 0.6, 0.95, 1]}},
        {"name": "box", "pbrMetallicRoughness": {"baseColorFactor": [0.95, 0.7, 0.45, 1]}},
        {"name": "ground", "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.8, 0.75, 1]}},
    ],
    "meshes": [
        {"name": "ball", "primitives": [{"attributes": {"POSITION": a_sp, "NORMAL": a_sn}, "indices": a_si, "material": 0}]},
        {"name": "box", "primitives": [{"attributes": {"POSITION": a_bp}, "indices": a_bi, "material": 1}]},
        {"name": "ground", "primitives": [{"attributes": {"POSITION": a_gp}, "indices": a_gi, "material": 2}]},
    ],
    "accessors": accessors, "bufferViews": views,
    "buffers": [{"byteLength": len(bin_), "uri": "data:application/octet-stream;base64," + base64.b64encode(bytes(bin_)).decode()}],
}
open(sys.argv[1], "w").write(json.dumps(doc, indent=1) + "\n")
