#!/usr/bin/env python3
"""Packs the add-on for Preferences > Add-ons > Install (docs/blender.md).

    python3 blender/build_zip.py [OUT.zip] [--module build/python/toonray.cpython-311-...so]

The zip holds the folder toonray_blender/ (``__init__.py`` with bl_info for Blender 3.4-4.1,
``blender_manifest.toml`` for 4.2+ "Install from Disk") and, with --module, the toonray Python
module for the render engine (built for the Python that Blender runs). Runs in any Python 3,
including Blender's (``blender -b --python blender/build_zip.py -- OUT.zip``).
"""

import os
import sys
import zipfile

HERE = os.path.dirname(os.path.abspath(__file__))
PACKAGE = "toonray_blender"


def build_zip(out_path, module=None):
    src = os.path.join(HERE, PACKAGE)
    names = []
    for root, dirs, files in os.walk(src):
        dirs[:] = sorted(d for d in dirs if d != "__pycache__")
        for f in sorted(files):
            if f.endswith((".py", ".toml")):
                names.append(os.path.join(root, f))
    out_path = os.path.abspath(out_path)
    tmp = out_path + ".tmp"
    with zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as z:
        for path in names:
            arc = os.path.join(PACKAGE, os.path.relpath(path, src)).replace(os.sep, "/")
            info = zipfile.ZipInfo(arc, date_time=(2024, 1, 1, 0, 0, 0))  # reproducible
            info.compress_type = zipfile.ZIP_DEFLATED
            info.external_attr = 0o644 << 16
            with open(path, "rb") as f:
                z.writestr(info, f.read())
        if module:
            info = zipfile.ZipInfo(PACKAGE + "/" + os.path.basename(module),
                                   date_time=(2024, 1, 1, 0, 0, 0))
            info.compress_type = zipfile.ZIP_DEFLATED
            info.external_attr = 0o755 << 16
            with open(module, "rb") as f:
                z.writestr(info, f.read())
    os.replace(tmp, out_path)
    return out_path


if __name__ == "__main__":
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else sys.argv[1:]
    module = None
    if "--module" in argv:
        i = argv.index("--module")
        module = argv[i + 1]
        del argv[i:i + 2]
    out = argv[0] if argv else os.path.join(os.getcwd(), PACKAGE + ".zip")
    print("wrote", build_zip(out, module))
