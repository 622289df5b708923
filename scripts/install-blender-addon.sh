#!/usr/bin/env bash
# Installs the Blender add-on (blender/toonray_blender) with the toonray Python module into the
# user's Blender and enables it (docs/blender.md, "Install"). Afterwards
#
#   blender -b scene.blend -E TOONRAY -f 1        (and -a)
#
# renders with toonray with no other step.
#
#   scripts/install-blender-addon.sh
#
# Environment: TOONRAY_BUILD_DIR (default build): where the module was built (build/python);
# when it is missing there, the module's target is built in that build directory. BLENDER
# (default blender). Blender's own BLENDER_USER_SCRIPTS and BLENDER_USER_CONFIG choose where the
# add-on and the preferences go (the tests install into a folder of their own this way).
#
# The module must be built for the Python Blender runs (Debian's Blender 3.4: the system's
# Python 3.11, which the build uses by default); a module for another Python is refused here
# rather than failing inside Blender.
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir=${TOONRAY_BUILD_DIR:-build}
blender=${BLENDER:-blender}

if ! command -v "$blender" >/dev/null; then
  echo "install-blender-addon: Blender not found ('$blender'; set BLENDER or install it:" \
       "apt-get install blender)" >&2
  exit 1
fi

find_module() { compgen -G "$build_dir/python/toonray.*.so" | head -n 1 || true; }
module=$(find_module)
if [ -z "$module" ] && [ -f "$build_dir/CMakeCache.txt" ]; then
  echo "install-blender-addon: building the module in $build_dir"
  cmake --build "$build_dir" --target toonray_python
  module=$(find_module)
fi
if [ -z "$module" ]; then
  echo "install-blender-addon: no toonray module in $build_dir/python: build toonray first" \
       "(TOONRAY_BUILD_DIR=$build_dir bash scripts/build.sh; it needs python3-dev and" \
       "pybind11-dev)" >&2
  exit 1
fi

# Where Blender keeps the user's add-ons, and the extension suffix of its Python.
info=$("$blender" -b --factory-startup --python-expr \
  "import bpy, sysconfig; print('TOONRAY_BLENDER', bpy.utils.script_path_user(), sysconfig.get_config_var('EXT_SUFFIX'))" \
  2>/dev/null | grep '^TOONRAY_BLENDER ' || true)
if [ -z "$info" ]; then
  echo "install-blender-addon: could not ask $blender where its add-ons go" >&2
  exit 1
fi
read -r _ scripts_dir suffix <<<"$info"
if [[ $(basename "$module") != "toonray$suffix" ]]; then
  echo "install-blender-addon: $module is not built for Blender's Python (it loads" \
       "toonray$suffix); configure the build with -DPython3_EXECUTABLE= the Python Blender runs" >&2
  exit 1
fi

dest="$scripts_dir/addons/toonray_blender"
echo "install-blender-addon: installing into $dest"
mkdir -p "$scripts_dir/addons"
tmp=$(mktemp -d "$scripts_dir/addons/.toonray_blender.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
cp blender/toonray_blender/*.py blender/toonray_blender/*.toml "$tmp/"
cp "$module" "$tmp/"
chmod 755 "$tmp"
rm -rf "$dest"
mv "$tmp" "$dest"

# Enable it in the user's preferences, then check that a new Blender has the engine.
"$blender" -b --python-exit-code 1 --python-expr "
import bpy
bpy.ops.preferences.addon_enable(module='toonray_blender')
bpy.ops.wm.save_userpref()
" >/dev/null
if ! "$blender" -b --python-exit-code 1 --python-expr "
import bpy, sys
if 'TOONRAY' not in {e.bl_idname for e in bpy.types.RenderEngine.__subclasses__()}:
    sys.exit('the TOONRAY engine is not registered')
" >/dev/null; then
  echo "install-blender-addon: the add-on is installed but Blender does not show the toonray" \
       "engine (run blender and see its console)" >&2
  exit 1
fi
echo "install-blender-addon: done: blender -b scene.blend -E TOONRAY -f 1"
