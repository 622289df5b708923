"""The scene the engine reads from complex.blend (engine_test.sh): every instance is an object of
the toonray scene, named as its Blender object, once (text, curves and metaballs too, which
Blender lists both as themselves and as their meshes), and each geometry is uploaded once
however many instances it has (two linked duplicates share a mesh; a collection instanced twice
uploads its cone and curve once). This is the viewport's depsgraph: the cube hidden only for the
render is in it.

    blender -b WORK/complex.blend --python sync_test.py
"""

import sys

import bpy

from toonray_blender import module, sync

tr = module.load()
depsgraph = bpy.context.evaluated_depsgraph_get()
synced = sync.sync_depsgraph(tr, depsgraph)
names = sorted(synced.scene.objects[1:])
expected = sorted(["Subdivided", "Text", "LinkedA", "LinkedB", "Cone", "Cone", "Curve", "Curve",
                   "Meta", "Holdout", "Hidden"])
ok = True
if names != expected:
    print("sync_test: FAILED: objects %s, expected %s" % (names, expected))
    ok = False
# Subdivided, Text, the linked mesh, Cone, Curve, Meta, Holdout, Hidden.
if synced.meshes != 8:
    print("sync_test: FAILED: %d meshes uploaded for %d instances (expected 8)"
          % (synced.meshes, len(names)))
    ok = False
if synced.excluded != 1:
    print("sync_test: FAILED: %d objects excluded (expected 1)" % synced.excluded)
    ok = False
if not ok:
    sys.exit(1)
print("sync_test: ok: %d instances from %d uploaded meshes, %d triangles"
      % (len(names), synced.meshes, synced.triangles))
