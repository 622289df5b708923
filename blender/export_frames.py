"""Command-line entry point: export a .blend file's frames for toonray (docs/blender.md).

    blender -b scene.blend --python blender/export_frames.py -- \\
        --out frames/ --name keys --start 1 --end 250 [--step 2] [--selection] \\
        [--notes song.notes [--prefix piano_] [--notes-start-frame 1] [--tempo 72] \\
         [--axis X] [--angle 0.042] [--key-mode PRESS|FRAME]] [--save animated.blend]

Writes frames/keys_000001.obj + .mtl, ... each with toonray's camera block, ready for
``toonray batch keys 1 250 --input frames/ --output png/``. With --notes the piano keys are
animated from the note script first (as Object > Animation > Animate Piano Keys does).
Exits 0 on success, 1 on an error (message on stderr), 2 on bad arguments. Uses the add-on
next to this file (blender/toonray_blender); it need not be installed.
"""

import argparse
import os
import sys

import bpy

HERE = os.path.dirname(os.path.abspath(__file__))
sys.dont_write_bytecode = True  # leave no __pycache__ in the source tree
if HERE not in sys.path:
    sys.path.insert(0, HERE)

import toonray_blender  # noqa: E402
from toonray_blender import camera, exporter, keys  # noqa: E402


def parse_args(argv):
    argv = argv[argv.index("--") + 1:] if "--" in argv else []
    scene = bpy.context.scene
    p = argparse.ArgumentParser(
        prog="blender -b FILE.blend --python blender/export_frames.py --",
        description="Export OBJ frames with toonray's camera block (and optionally animate "
                    "piano keys from a note script first).")
    p.add_argument("--out", required=True, help="output folder")
    p.add_argument("--name", default="keys", help="file prefix: NAME_NNNNNN.obj (default keys)")
    p.add_argument("--start", type=int, default=scene.frame_start,
                   help="first frame (default: the scene's, %d)" % scene.frame_start)
    p.add_argument("--end", type=int, default=scene.frame_end,
                   help="last frame (default: the scene's, %d)" % scene.frame_end)
    p.add_argument("--step", type=int, default=1, help="export every Nth frame (default 1)")
    p.add_argument("--selection", action="store_true", help="export the selected objects only")
    p.add_argument("--no-triangulate", action="store_true",
                   help="leave polygons to toonray's fan triangulation")
    p.add_argument("--render-properties", action="store_true",
                   help="export objects as in the render (modifiers, visibility), not the viewport")
    p.add_argument("--notes", help="animate the piano keys from this note script first")
    p.add_argument("--prefix", default="", help="key object name prefix (keys are PREFIXw1..)")
    p.add_argument("--notes-start-frame", type=float, default=1.0,
                   help="frame at which the score's time 0 falls (default 1)")
    p.add_argument("--tempo", type=float, default=0.0,
                   help="default tempo in quarter notes per minute (default: 72, the script's)")
    p.add_argument("--axis", choices=("X", "Y", "Z"), default="X", help="key rotation axis")
    p.add_argument("--angle", type=float, default=0.042,
                   help="rotation of a fully pressed key in radians (default 0.042)")
    p.add_argument("--key-mode", choices=("PRESS", "FRAME"), default="PRESS",
                   help="keyframes per press (exact, default) or per frame")
    p.add_argument("--save", help="save the (animated) scene to this .blend file")
    return p.parse_args(argv)


def main():
    args = parse_args(sys.argv)
    context = bpy.context
    log = lambda m: print("toonray:", m, flush=True)  # noqa: E731
    if args.notes:
        keys.animate_keys(context.scene, notes_path=args.notes, prefix=args.prefix,
                          start_frame=args.notes_start_frame, tempo_bpm=args.tempo,
                          axis=args.axis, angle=args.angle, mode=args.key_mode, report=log)
    files = exporter.export_sequence(
        context, os.path.abspath(args.out), name=args.name, frame_start=args.start,
        frame_end=args.end, frame_step=args.step, use_selection=args.selection,
        triangulate=not args.no_triangulate,
        eval_mode="DAG_EVAL_RENDER" if args.render_properties else "DAG_EVAL_VIEWPORT")
    log("wrote %d frames (%s_%06d.obj .. %s) to %s"
        % (len(files), args.name, args.start, os.path.basename(files[-1]) if files else "-",
           os.path.abspath(args.out)))
    if args.save:
        bpy.ops.wm.save_as_mainfile(filepath=os.path.abspath(args.save), copy=True)
        log("saved %s" % os.path.abspath(args.save))


if __name__ == "__main__":
    try:
        main()
    except SystemExit:
        raise
    except (exporter.ExportError, camera.CameraError, keys.KeyAnimationError, OSError) as e:
        print("toonray: error: %s" % e, file=sys.stderr, flush=True)
        sys.exit(1)
