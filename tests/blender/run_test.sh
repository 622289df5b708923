#!/usr/bin/env bash
# The Blender add-on end to end, with the real Blender (tests/blender/CMakeLists.txt):
#   run_test.sh TOONRAY REPO WORK [BLENDER]
# 1. build_scene.py: installs the add-on from its zip, builds a scene (cubes, a row of piano
#    keys, a moving, tracking, zooming camera), runs both operators; config A = 320x180 AUTO.
# 2. blender/export_frames.py (the command line) exports configs B (200x300 VERTICAL, with
#    --notes and per-frame keys), C (180x320 AUTO, --step 5) and D (240x150 HORIZONTAL with
#    pixel aspect 1.5, frames 3..45 step 6).
# 3. toonray renders every exported frame with AOVs; toonray piano exports the same score.
# 4. check_frames.py compares the renders with Blender's own camera projection and the keys
#    with the note script and with toonray piano.
# Exits 77 (skipped) only when Blender is not installed.
set -euo pipefail
toonray=$1 repo=$2 work=$3 blender=${4:-blender}

if ! command -v "$blender" >/dev/null 2>&1; then
  echo "blender is not installed (apt-get install --no-install-recommends blender): skipped"
  exit 77
fi
start=$(date +%s)
rm -rf "$work"
mkdir -p "$work/user/scripts" "$work/config"
# Keep the add-on install and preferences out of the user's own Blender folders.
export BLENDER_USER_SCRIPTS=$work/user/scripts BLENDER_USER_CONFIG=$work/config
cd "$work"
here=$repo/tests/blender
notes=$here/keys_test.notes

run_blender() {  # run_blender LOG ARGS...: quiet unless it fails
  local log=$1; shift
  if ! "$blender" --python-exit-code 1 "$@" >"$log" 2>&1; then
    cat "$log"; echo "run_test: blender failed: $*"; exit 1
  fi
}

echo "== $("$blender" -b --factory-startup --version 2>/dev/null | head -n 1)"
run_blender build.log -b --factory-startup --python "$here/build_scene.py" -- "$work" "$repo"
grep -E "^(Info: [0-9]+ keys|build_scene)" build.log || true

run_blender export_B.log -b scene_B.blend --python "$repo/blender/export_frames.py" -- \
  --out B --name keys --start 1 --end 48 --notes "$notes" --angle 0.2 --key-mode FRAME
run_blender export_C.log -b scene_C.blend --python "$repo/blender/export_frames.py" -- \
  --out C --name keys --start 1 --end 48 --step 5
run_blender export_D.log -b scene_D.blend --python "$repo/blender/export_frames.py" -- \
  --out D --name keys --start 3 --end 45 --step 6
grep -h "^toonray:" export_*.log

# The command line must fail cleanly on bad input (exit 1, a message, no traceback).
if "$blender" --python-exit-code 3 -b scene_B.blend --python "$repo/blender/export_frames.py" -- \
     --out bad --notes "$repo/data/entertainer.midi" >bad.log 2>&1; then
  echo "run_test: export_frames.py accepted a MIDI file as a note script"; exit 1
fi
grep -q "toonray: error: .*toonray score convert" bad.log || { cat bad.log; echo "run_test: no clear error for a MIDI file"; exit 1; }

render_each() {  # render_each DIR WxH: toonray render on every exported frame
  local dir=$1 size=$2 f
  for f in "$dir"/keys_*.obj; do
    "$toonray" render "$f" -o "$dir/png/$(basename "${f%.obj}").png" --size "$size" --aov "$dir/aov" --threads 2
  done
}
"$toonray" batch keys 1 48 --input A --output A/png --size 320x180 --aov A/aov --quiet
"$toonray" batch keys 1 48 --input B --output B/png --size 200x300 --aov B/aov --quiet
mkdir -p C/png D/png
render_each C 180x320
render_each D 240x100
"$toonray" piano --score "$notes" --export-obj piano --seconds 2 --fps 24 --quiet
"$toonray" score convert "$repo/data/entertainer.midi" entertainer.notes

configs='{"A": {"size": [320, 180], "min_checks": 130, "keys": true},
          "B": {"size": [200, 300], "min_checks": 125, "keys": true},
          "C": {"size": [180, 320], "min_checks": 25},
          "D": {"size": [240, 100], "min_checks": 15}}'
status=0
"$blender" --python-exit-code 1 -b --factory-startup --python "$here/check_frames.py" -- \
  "$work" "$repo" "$configs" >check.log 2>&1 || status=$?
grep -v -E "^(note:|Read |Blender quit|Blender [0-9])" check.log || true
[ "$status" -ne 0 ] || rm -rf piano   # 100 MB of piano frames; everything else stays for a look
echo "run_test: $(( $(date +%s) - start )) s"
exit $status
