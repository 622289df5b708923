"""Finds the toonray Python module (docs/python.md) for the render engine.

scripts/install-blender-addon.sh copies it into this package (toonray.cpython-311-...so next to
this file); otherwise a `toonray` on Blender's sys.path is used. The module must be built for
the Python Blender runs (Debian's Blender 3.4: the system's Python 3.11). Without it the add-on
still registers its exporter and piano tools, and says why the engine is missing.
"""

import importlib
import sys

toonray = None
import_error = None


def load():
    """Imports the module once; returns it, or None (import_error says why)."""
    global toonray, import_error
    if toonray is not None:
        return toonray
    try:
        toonray = importlib.import_module(__package__ + ".toonray")
    except ImportError as bundled:
        try:
            toonray = importlib.import_module("toonray")
        except ImportError as e:
            import_error = ("the toonray Python module is not installed for Blender's Python "
                            "%d.%d (%s; %s): run scripts/install-blender-addon.sh"
                            % (sys.version_info[0], sys.version_info[1], bundled, e))
            return None
    import_error = None
    return toonray
