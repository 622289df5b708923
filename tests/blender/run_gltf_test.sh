#!/usr/bin/env bash
# Blender's own glTF exporter against toonray (tests/blender/CMakeLists.txt):
#   run_gltf_test.sh TOONRAY REPO WORK [BLENDER]
# 1. gltf_scene.py builds an animated scene (moving and turning objects, a moving and turning
#    camera with a 35 mm lens), exports it as GLB and renders Cycles silhouettes of some frames.
# 2. toonray batch renders the same frames straight from the .glb.
# 3. gltf_compare.py checks the silhouettes' intersection over union on each frame.
# Exits 77 (skipped) only when Blender is not installed.
set -euo pipefail
toonray=$1 repo=$2 work=$3 blender=${4:-blender}

if ! command -v "$blender" >/dev/null 2>&1; then
  echo "blender is not installed (apt-get install --no-install-recommends blender): skipped"
  exit 77
fi
start=$(date +%s)
rm -rf "$work"
mkdir -p "$work"
here=$repo/tests/blender
frames=1,7,13,24
size=(160 120)

run_blender() {  # run_blender LOG ARGS...: quiet unless it fails
  local log=$1; shift
  if ! "$blender" --python-exit-code 1 "$@" >"$log" 2>&1; then
    cat "$log"; echo "run_gltf_test: blender failed: $*"; exit 1
  fi
}

run_blender "$work/scene.log" -b --factory-startup --python "$here/gltf_scene.py" -- \
  "$work" "$frames" "${size[0]}" "${size[1]}"
for f in ${frames//,/ }; do
  "$toonray" batch "$work/scene.glb" "$f" "$f" --fps 24 --output "$work/png" --aov "$work/aov" \
    --size "${size[0]}x${size[1]}" --edges classic --quiet
done
status=0
"$blender" --python-exit-code 1 -b --factory-startup --python "$here/gltf_compare.py" -- \
  "$work" "$frames" 0.99 >"$work/compare.log" 2>&1 || status=$?
grep -E "^(frame|gltf_compare)" "$work/compare.log" || cat "$work/compare.log"
echo "run_gltf_test: $(( $(date +%s) - start )) s"
exit $status
