"""What the Python module's tests share: where the CLI and the test data are (CTest passes them
in the environment, tests/python/CMakeLists.txt), temporary folders and a small scene."""

import os
import subprocess
import tempfile

import numpy as np

CLI = os.environ.get("TOONRAY_CLI", "toonray")
DATA = os.environ.get("TOONRAY_TEST_DATA", os.path.join(os.path.dirname(__file__), "..", "data"))

# Two objects, a cube with per-vertex normals in material "red" and a ground quad in "blue",
# and the camera block: small, quick, with silhouettes, creases, a material border and an
# intersection (the cube sits half into the ground).
SCENE_OBJ = """mtllib two.mtl
o cube
v -1 -1 -1
v 1 -1 -1
v 1 1 -1
v -1 1 -1
v -1 -1 1
v 1 -1 1
v 1 1 1
v -1 1 1
usemtl red
f 1 4 3
f 1 3 2
f 5 6 7
f 5 7 8
f 1 2 6
f 1 6 5
f 2 3 7
f 2 7 6
f 3 4 8
f 3 8 7
f 4 1 5
f 4 5 8
o ground
v -4 -4 0
v 4 -4 0
v 4 4 0
v -4 4 0
usemtl blue
f 9 10 11
f 9 11 12
# Camera start
v 5 -7 4
v 4.4 -6.16 3.52
vn 0 0 1
c -2 -1 -1
# Camera end
"""
SCENE_MTL = """newmtl red
Kd 0.8 0.2 0.1
newmtl blue
Kd 0.2 0.3 0.9
"""


def write_scene(folder):
    """Writes two.obj and two.mtl into `folder`; returns the OBJ's path."""
    with open(os.path.join(folder, "two.mtl"), "w") as f:
        f.write(SCENE_MTL)
    path = os.path.join(folder, "two.obj")
    with open(path, "w") as f:
        f.write(SCENE_OBJ)
    return path


def scene_arrays():
    """The two objects of SCENE_OBJ as arrays: [(name, positions, triangles, material name)]."""
    positions, objects, current = [], [], None
    for line in SCENE_OBJ.splitlines():
        words = line.split()
        if not words or line.startswith("# Camera"):
            if line.startswith("# Camera start"):
                break
            continue
        if words[0] == "o":
            current = [words[1], len(positions), [], None]
            objects.append(current)
        elif words[0] == "v":
            positions.append([float(w) for w in words[1:4]])
        elif words[0] == "usemtl":
            current[3] = words[1]
        elif words[0] == "f":
            current[2].append([int(w) - 1 for w in words[1:4]])
    out = []
    for name, first, triangles, material in objects:
        tri = np.array(triangles, dtype=np.uint32)
        used = sorted(set(tri.ravel().tolist()))
        out.append((name, np.array([positions[i] for i in used], dtype=np.float32),
                    (tri - min(used)).astype(np.uint32), material))
    return out


def run_cli(*args):
    """Runs the CLI; returns (exit code, stderr)."""
    done = subprocess.run([CLI, *args], capture_output=True, text=True)
    return done.returncode, done.stderr


class TempDir:
    def __enter__(self):
        self._dir = tempfile.TemporaryDirectory(prefix="toonray_python_")
        return self._dir.name

    def __exit__(self, *exc):
        self._dir.cleanup()
