#!/usr/bin/env python3
"""The piano animation end to end, through the real CLI: 2,229 frames at 720p on both cores.

    python3 bench/animation.py --toonray build/apps/toonray --work-dir build-bench/animation \
        [--frames 2229] [--repeats 1] [--markdown out.md]

1. `toonray piano --export-obj` writes the first N frames of the Entertainer (24 fps) as one OBJ
   + MTL per frame, each with its camera block (done once; 2,229 frames are 4.7 GB).
2. `toonray batch keys 1 N` renders them to 1280x720 PNGs with both cores, in each line mode:
   every frame is read, parsed, built, traced, shaded, outlined, encoded and written.
3. `toonray piano` renders the same frames from memory (posed in place, BVH refit, no OBJ files).
The line modes: the default (ink lines, no --edges option) and classic; --robust adds robust.
Before timing, the page cache is warmed by reading every OBJ once, so the figure is the
renderer's and not the disk's (a cold read of 4.7 GB would time the storage). Each output
directory is emptied before each run. Reports wall time, frames per second and ms per frame,
and, for the full 2,229 frames, the targets: `toonray piano` default <= 75 s, `toonray batch`
default <= 90 s, `toonray piano --edges classic` <= 35 s. --json writes the rows and targets
for run.sh's summary (bench/summary.py).
"""

import argparse
import os
import shutil
import statistics
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from publish import publish  # noqa: E402

# (label, options): the default line mode is whatever `toonray` draws without --edges.
MODES = [("default (ink)", []), ("classic", ["--edges", "classic"])]
ROBUST = ("robust", ["--edges", "robust"])
FULL = 2229
# Seconds for the full animation, by (mode label, path).
TARGETS = {("default (ink)", "piano"): 75, ("default (ink)", "batch"): 90, ("classic", "piano"): 35}


def run(argv):
    start = time.perf_counter()
    subprocess.run(argv, check=True, stdout=subprocess.DEVNULL)
    return time.perf_counter() - start


def export(toonray, work, frames):
    d = os.path.join(work, f"frames{frames}")
    last = os.path.join(d, f"keys_{frames:06d}.obj")
    if not os.path.exists(last):
        print(f"animation: exporting {frames} frames to {d}", file=sys.stderr)
        subprocess.run([toonray, "piano", "--export-obj", d, "--seconds", str(frames / 24), "--quiet"], check=True)
    if not os.path.exists(last):
        sys.exit(f"animation: {last} was not written")
    return d


def warm(directory):
    total = 0
    for name in sorted(os.listdir(directory)):
        with open(os.path.join(directory, name), "rb") as f:
            while chunk := f.read(1 << 24):
                total += len(chunk)
    return total


def fresh(path):
    shutil.rmtree(path, ignore_errors=True)
    os.makedirs(path)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--toonray", required=True)
    ap.add_argument("--work-dir", required=True)
    ap.add_argument("--frames", type=int, default=2229)
    ap.add_argument("--repeats", type=int, default=1)
    ap.add_argument("--markdown")
    ap.add_argument("--json")
    ap.add_argument("--robust", action="store_true", help="also time --edges robust")
    args = ap.parse_args()
    os.makedirs(args.work_dir, exist_ok=True)
    n = args.frames
    objs = export(args.toonray, args.work_dir, n)
    out = os.path.join(args.work_dir, "out")

    rows, json_rows, targets = [], [], []
    for mode, options in MODES + ([ROBUST] if args.robust else []):
        batch, memory = [], []
        for _ in range(args.repeats):
            size = warm(objs)
            fresh(out)
            batch.append(run([args.toonray, "batch", "keys", "1", str(n), "-i", objs, "-o", out, *options,
                              "--quiet"]))
            pngs = len([f for f in os.listdir(out) if f.endswith(".png")])
            if pngs != n:
                sys.exit(f"animation: batch wrote {pngs} PNGs, expected {n}")
            fresh(out)
            memory.append(run([args.toonray, "piano", "-o", out, "--seconds", str(n / 24), *options, "--quiet"]))
            pngs = len([f for f in os.listdir(out) if f.endswith(".png")])
            if pngs != n:
                sys.exit(f"animation: piano wrote {pngs} PNGs, expected {n}")
        for path, what, times in (("batch", f"`toonray batch` ({size / 1e9:.1f} GB of OBJ)", batch),
                                  ("piano", "`toonray piano` (in memory)", memory)):
            s = statistics.median(times)
            target = TARGETS.get((mode, path)) if n == FULL else None
            cells = f"<= {target} s | {'met' if s <= target else '**missed**'}" if target else " | "
            rows.append(f"| {mode} | {what} | {s:.1f} | {n / s:.1f} | {1000 * s / n:.1f} | {cells} |")
            json_rows.append({"mode": mode, "path": path, "frames": n, "seconds": s})
            if target:
                options_text = " ".join(options)
                targets.append({"figure": f"{n:,} piano frames 720p, 2 cores, `toonray {path}"
                                          + (f" {options_text}" if options_text else "") + f"` ({mode})",
                                "target": f"<= {target} s", "measured": f"{s:.1f} s", "reference": "",
                                "met": s <= target})
        print(f"animation: {mode} done", file=sys.stderr)
    shutil.rmtree(out, ignore_errors=True)

    md = "\n".join([
        f"#### {n} frames of the piano at 1280x720, both cores",
        "",
        "| lines | path | wall s | frames/s | ms per frame | target | |",
        "|---|---|--:|--:|--:|--:|---|",
        *rows,
        "",
        f"Median of {args.repeats} run(s); every PNG written. Page cache warm (see bench/animation.py)."
        + ("" if n == FULL else f" Targets apply to the full {FULL:,} frames."),
    ]) + "\n"
    publish(md, args.markdown, args.json, {"rows": json_rows, "targets": targets})


if __name__ == "__main__":
    main()
