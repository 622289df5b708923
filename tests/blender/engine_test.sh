#!/usr/bin/env bash
# The toonray render engine in the real Blender, headless (tests/blender/CMakeLists.txt):
#   engine_test.sh TOONRAY BUILD REPO WORK [BLENDER]
# 1. scripts/install-blender-addon.sh installs the add-on with the module (from BUILD/python)
#    into WORK's own Blender folders and enables it.
# 2. engine_scene.py builds parity.blend (and exports its settings as look.toml) and
#    complex.blend.
# 3. blender -b parity.blend -E TOONRAY -f 1 (PNG); the same scene through the OBJ exporter and
#    `toonray render --settings look.toml`; the multilayer EXR with every pass; -a over three
#    frames with SVGs; complex.blend's IndexOB pass.
# 4. A frame over the triangle limit from the command line is reported, and Blender quits
#    normally; engine_check.py compares and checks the frames; engine_cancel.py breaks a render
#    and fails one; sync_test.py checks that each mesh is uploaded once; preview_test.py checks
#    the cameras and the viewport preview's renderer.
# 5. viewport_test.py: the viewport in a real Blender window under Xvfb (skipped, with a note,
#    without xvfb-run).
# Exits 77 (skipped) only when Blender is not installed.
set -euo pipefail
toonray=$1 build=$2 repo=$3 work=$4 blender=${5:-blender}

if ! command -v "$blender" >/dev/null 2>&1; then
  echo "blender is not installed (apt-get install --no-install-recommends blender): skipped"
  exit 77
fi
start=$(date +%s)
rm -rf "$work"
mkdir -p "$work/user/scripts" "$work/config"
export BLENDER_USER_SCRIPTS=$work/user/scripts BLENDER_USER_CONFIG=$work/config BLENDER=$blender
cd "$work"
here=$repo/tests/blender

run_blender() {  # run_blender LOG ARGS...: quiet unless it fails
  local log=$1; shift
  if ! "$blender" --python-exit-code 1 "$@" >"$log" 2>&1; then
    cat "$log"; echo "engine_test: blender failed: $*"; exit 1
  fi
}

TOONRAY_BUILD_DIR=$build bash "$repo/scripts/install-blender-addon.sh" >install.log 2>&1 ||
  { cat install.log; echo "engine_test: install-blender-addon.sh failed"; exit 1; }
run_blender scene.log -b --python "$here/engine_scene.py" -- "$work"

# Parity with the command line through the existing OBJ route, same settings document.
run_blender parity.log -b parity.blend -E TOONRAY -o "$work/engine/parity_####" -F PNG -f 1
run_blender export.log -b parity.blend --python "$repo/blender/export_frames.py" -- \
  --out obj --name parity --start 1 --end 1
"$toonray" render obj/parity_000001.obj -o cli.png --settings look.toml  # its size is the scene's

# Every pass in the multilayer EXR.
run_blender exr.log -b parity.blend -E TOONRAY --python-expr "
import bpy
for vl in bpy.context.scene.view_layers:
    vl.use_pass_z = vl.use_pass_normal = True
    vl.use_pass_object_index = vl.use_pass_material_index = True
    vl.toonray.use_pass_lines = vl.toonray.use_pass_line_types = True
" -o "$work/engine/passes_####" -F OPEN_EXR_MULTILAYER -f 1
oiiotool --info -v engine/passes_0001.exr >exr_info.txt
for channel in Combined.R Combined.A Depth.Z Normal.X IndexOB.X IndexMA.X Lines.X \
               "Lines Silhouette.X" "Lines Crease.X" "Lines Intersection.X"; do
  grep -q "ViewLayer.$channel" exr_info.txt ||
    { cat exr_info.txt; echo "engine_test: no channel ViewLayer.$channel in the EXR"; exit 1; }
done
lines_max=$(oiiotool engine/passes_0001.exr --ch "ViewLayer.Lines.X" --printstats 2>&1 |
            sed -n 's/.*Max: *\([0-9.e+-]*\).*/\1/p' | head -n 1)
python3 -c "import sys; sys.exit(0 if float('$lines_max') > 0.5 else 1)" ||
  { echo "engine_test: the Lines pass is empty (max $lines_max)"; exit 1; }
echo "engine_test: the EXR has every pass; Lines reaches $lines_max"

# -a over three frames, with an SVG beside each.
run_blender anim.log -b parity.blend -E TOONRAY --python-expr "
import bpy
s = bpy.context.scene
s.frame_start, s.frame_end = 1, 3
s.render.resolution_percentage = 50
s.toonray.use_svg = True
s.toonray.output__svg_hidden = True
" -o "$work/anim/frame_####" -F PNG -a

# Every object of the complex scene in the IndexOB pass.
run_blender complex.log -b complex.blend -E TOONRAY -o "$work/engine/complex_####" -f 1
oiiotool engine/complex_0001.exr --ch "ViewLayer.IndexOB.X" --chnames Y -d float -o complex_index.exr
oiiotool engine/complex_0001.exr --ch "ViewLayer.Combined.A" --chnames Y -d float -o complex_alpha.exr

# A frame that fails from the command line: reported with the library's message, and Blender
# ends normally with exit status 1 (a failed render; no crash, which would be a signal).
status=0
"$blender" -b parity.blend -E TOONRAY --python-expr "
import bpy
s = bpy.context.scene
s.toonray.use_limits__triangles = True
s.toonray.limits__triangles = '1k'
" -o "$work/engine/limited_####" -F PNG -f 1 >limited.log 2>&1 || status=$?
grep -q "toonray: the scene has 3374 triangles, more than the limit of 1000 (limits.triangles raises it)" limited.log &&
  [ "$status" -eq 1 ] && grep -q "Blender quit" limited.log ||
  { cat limited.log; echo "engine_test: a failing frame was not reported cleanly (exit $status)"; exit 1; }
echo "engine_test: a frame over the triangle limit is reported and Blender quits (exit 1)"

run_blender check.log -b --factory-startup --python "$here/engine_check.py" -- "$work"
grep "^engine_check" check.log
run_blender cancel.log -b parity.blend --python "$here/engine_cancel.py"
grep "^engine_cancel" cancel.log
run_blender sync.log -b complex.blend --python "$here/sync_test.py"
grep "^sync_test" sync.log
run_blender preview.log -b parity.blend --python "$here/preview_test.py"
grep "^preview_test" preview.log

# The viewport in a real window: Xvfb and Mesa's software OpenGL (scripts/install-deps.sh all).
if command -v xvfb-run >/dev/null 2>&1; then
  timeout 240 xvfb-run -a -s "-screen 0 1280x800x24" "$blender" parity.blend \
    --python "$here/viewport_test.py" -- "$work" >viewport.log 2>&1 || true
  if grep -q -E "Traceback|Error: Python|property not found" viewport.log; then
    cat viewport.log; echo "engine_test: Python errors in the window's session (panels, viewport)"; exit 1
  fi
  python3 - "$work/viewport.json" <<'PY' || { cat viewport.log; exit 1; }
import json, sys
try:
    r = json.load(open(sys.argv[1]))
except OSError:
    sys.exit("engine_test: the viewport test wrote no result")
draws = r["draws"]
print("engine_test: viewport drew %d refined frames, %s s after each view change; errors %s"
      % (len(draws), [round(d["seconds"], 2) for d in draws], r["errors"]))
ok = (r.get("ok") and not r["errors"] and len(draws) == 5
      and len({d["generation"] for d in draws}) == 5
      and all(d["non_background"] > 0.05 for d in draws))
sys.exit(0 if ok else "engine_test: the viewport did not draw toonray's frames of each view")
PY
else
  echo "engine_test: xvfb-run is not installed: the viewport in a window is not tested" \
       "(preview_test.py tested the preview's renderer)"
fi
echo "engine_test: $(( $(date +%s) - start )) s"
