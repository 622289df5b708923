#!/usr/bin/env bash
# The render engine's measurements (docs/blender.md, "Speed"): not a test. Builds the scenes
# (suzanne_scene.py), then times, with Blender's start-up and the scene's evaluation included,
#
#   blender -b suzanne_toonray.blend -E TOONRAY -f 1      (toonray's defaults)
#   blender -b suzanne_cycles.blend  -E CYCLES  -f 1      (1 sample, Freestyle)
#
# RUNS times each, alternating, and prints each time and the medians; then the viewport
# preview's frame times (viewport_time.py). The engine must be installed
# (scripts/install-blender-addon.sh; BLENDER_USER_SCRIPTS / BLENDER_USER_CONFIG are honoured).
#
#   bench/blender/measure.sh [OUT_DIR] [RUNS]
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
out=${1:-/tmp/toonray-blender-bench}
runs=${2:-3}
blender=${BLENDER:-blender}
mkdir -p "$out/frames"
cd "$out"
"$blender" -b --python-exit-code 1 --python "$here/suzanne_scene.py" -- "$out" >scene.log 2>&1 ||
  { cat scene.log; exit 1; }

seconds() {  # seconds LOG COMMAND...: wall-clock seconds of the command
  local log=$1; shift
  local t0 t1
  t0=$(date +%s.%N)
  "$@" >"$log" 2>&1 || { tail -n 20 "$log"; echo "measure: failed: $*" >&2; exit 1; }
  t1=$(date +%s.%N)
  python3 -c "print('%.2f' % ($t1 - $t0))"
}
median() { python3 -c "import statistics, sys; print('%.2f' % statistics.median(map(float, sys.argv[1:])))" "$@"; }

toonray=() cycles=()
for i in $(seq "$runs"); do
  toonray+=("$(seconds toonray.log "$blender" -b suzanne_toonray.blend -E TOONRAY -o "$out/frames/toonray_####" -F PNG -f 1)")
  cycles+=("$(seconds cycles.log "$blender" -b suzanne_cycles.blend -E CYCLES -o "$out/frames/cycles_####" -F PNG -f 1)")
  echo "measure: run $i: toonray ${toonray[-1]} s, Cycles + Freestyle ${cycles[-1]} s"
done
t=$(median "${toonray[@]}") c=$(median "${cycles[@]}")
echo "measure: medians over $runs runs: toonray $t s, Cycles + Freestyle $c s, ratio $(python3 -c "print('%.2f' % ($t / $c))")"
grep -E "toonray \| [0-9]+ triangles \| done| Time:" toonray.log | tail -n 2
grep -E " Time:" cycles.log | tail -n 1
# Blender's own share: start-up, reading the file and evaluating the subdivision.
echo "measure: Blender start-up and evaluation alone: $(seconds eval.log "$blender" -b suzanne_toonray.blend --python-expr "import bpy; bpy.context.evaluated_depsgraph_get()") s"

for samples in 1 4; do
  "$blender" -b viewport.blend --python "$here/viewport_time.py" -- "$samples" 2>&1 | grep "^viewport_time"
done
