#!/usr/bin/env bash
# The scene's lights and the default material through the add-on, against Cycles
# (tests/blender/CMakeLists.txt):   lights_test.sh TOONRAY REPO WORK [BLENDER]
# 1. lights_scene.py: a sun (turning), a smooth sphere, a flat box, an object without a
#    material, a moving camera; frames 1 and 10 exported with the add-on; Cycles renders the
#    sun's n.l and the object ids at pixel centres.
# 2. toonray renders both frames with no light option: the lights come from the .lights files;
#    and the same frames from the scene exported with Blender's glTF exporter (scene.glb).
# 3. check_lights.py: toonray's bands agree with Cycles' n.l quantised at 0.25 and 0.5 on at
#    least 97% of object pixels away from silhouettes; the material-less object is Kd 0.8; the
#    glTF route's bands agree with Cycles too, and with the OBJ route's on at least 99%.
# Exits 77 (skipped) only when Blender is not installed.
set -euo pipefail
toonray=$1 repo=$2 work=$3 blender=${4:-blender}

if ! command -v "$blender" >/dev/null 2>&1; then
  echo "blender is not installed (apt-get install --no-install-recommends blender): skipped"
  exit 77
fi
start=$(date +%s)
rm -rf "$work"
mkdir -p "$work/config" "$work/png/gltf"
export BLENDER_USER_CONFIG=$work/config
cd "$work"
here=$repo/tests/blender

if ! "$blender" --python-exit-code 1 -b --factory-startup --python "$here/lights_scene.py" -- \
     "$work" "$repo" >scene.log 2>&1; then
  cat scene.log; echo "lights_test: lights_scene.py failed"; exit 1
fi
for f in 1 10; do
  stem=$(printf 'lit_%06d' "$f")
  [ -f "frames/$stem.lights" ] || { echo "lights_test: frames/$stem.lights was not written"; exit 1; }
  "$toonray" render "frames/$stem.obj" -o "png/$stem.png" --size 200x150 --edges classic \
    --background 0,0,1 --aov png/aov --threads 2
  # The glTF route: the same frame straight from Blender's .glb, lit by its KHR_lights_punctual
  # sun (frame N is at N / 24 s, as Blender's exporter writes times).
  "$toonray" render scene.glb --frame "$f" --fps 24 -o "png/gltf/$stem.png" --size 200x150 \
    --edges classic --background 0,0,1 --aov png/gltf/aov --threads 2
done
status=0
"$blender" --python-exit-code 1 -b --factory-startup --python "$here/check_lights.py" -- \
  "$work" >check.log 2>&1 || status=$?
grep -E "^(frame|check_lights)" check.log || cat check.log
echo "lights_test: $(( $(date +%s) - start )) s"
exit $status
