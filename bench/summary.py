#!/usr/bin/env python3
"""The targets table at the end of results.md: every target figure, measured or not.

    python3 bench/summary.py RESULTS_DIR --parts stages rays frame memory animation

Reads what the parts that ran this time left in RESULTS_DIR: frame.json, memory.json and
animation.json (bench/frame.py, bench/animation.py), stages.md (toonray_bench: the "Parse
target" line of each scene) and rays.txt (toonray_accel_bench: the "build ms" line of the
1M-triangle sphere). A target whose part did not run is listed as not measured. Prints the
table as Markdown.
"""

import argparse
import json
import os
import re

# The figures of each part, in the order they are listed; used when the part did not run.
PLACEHOLDERS = {
    "frame": [("default frame, scan70k.obj 1280x720, 1 thread", "<= 0.35x reference"),
              ("classic frame, scan70k.obj 1280x720, 1 thread", "<= 0.25x reference")],
    "memory": [("peak RSS, toonray default (ink) frame, sphere, 65,536 triangles, 3840x2160", "<= 400 MB"),
               ("peak RSS, toonray default (ink) frame, sphere, 65,536 triangles, 7680x4320", "works, <= 1 GB"),
               ("peak RSS, toonray default (ink) frame, one triangle, 1280x720", "<= 40 MB")],
    "animation": [("2,229 piano frames 720p, 2 cores, `toonray piano` (default (ink))", "<= 75 s"),
                  ("2,229 piano frames 720p, 2 cores, `toonray batch` (default (ink))", "<= 90 s"),
                  ("2,229 piano frames 720p, 2 cores, `toonray piano --edges classic` (classic)", "<= 35 s")],
    "stages": [("OBJ parse, every stage scene (worst shown)", ">= 5x tinyobjloader")],
    "rays": [("BVH build, 1M triangles, 1 thread", "<= Embree"), ("BVH build, 1M triangles, 2 threads", "<= Embree")],
}


def from_json(path):
    with open(path) as f:
        return json.load(f)["targets"]


def parse_targets(path):
    """The parse ratio of every scene in stages.md (its "Parse target" lines); one target row for
    the worst."""
    scenes = []
    scene = None
    with open(path) as f:
        for line in f:
            if line.startswith("### "):
                scene = line[4:].split(" — ")[0].strip()
            m = re.match(r"Parse target \(ours >= 5x tinyobjloader\): [^(]*\(([\d.]+)x: ([\d.]+) ms against "
                         r"([\d.]+) ms", line)
            if m and scene:
                scenes.append((scene, float(m.group(1)), float(m.group(2)), float(m.group(3))))
    if not scenes:
        return []
    worst = min(scenes, key=lambda s: s[1])
    all_ratios = ", ".join(f"{s[0]} {s[1]:.2f}x" for s in scenes)
    return [{"figure": "OBJ parse, every stage scene (worst shown)", "target": ">= 5x tinyobjloader",
             "measured": f"{worst[0]}: {worst[2]:.3g} ms = {worst[1]:.2f}x (all: {all_ratios})",
             "reference": f"tinyobjloader {worst[3]:.3g} ms", "met": all(s[1] >= 5 for s in scenes)}]


def build_targets(path):
    """BVH build of the 1M-triangle sphere against Embree, on 1 and on all threads."""
    scene = None
    with open(path) as f:
        for line in f:
            m = re.match(r"## (\S+): (\d+) triangles", line)
            if m:
                scene = m.group(1)
            m = re.search(r"build ms: ours 1t ([\d.]+), embree 1t ([\d.]+), ours all ([\d.]+), embree all ([\d.]+)",
                          line)
            if m and scene == "sphere1m":
                o1, e1, oa, ea = (float(v) for v in m.groups())
                threads = os.cpu_count()
                return [{"figure": "BVH build, 1M triangles, 1 thread", "target": "<= Embree",
                         "measured": f"{o1:.0f} ms = {o1 / e1:.2f}x", "reference": f"Embree {e1:.0f} ms",
                         "met": o1 <= e1},
                        {"figure": f"BVH build, 1M triangles, {threads} threads", "target": "<= Embree",
                         "measured": f"{oa:.0f} ms = {oa / ea:.2f}x", "reference": f"Embree {ea:.0f} ms",
                         "met": oa <= ea}]
    return []


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("results")
    ap.add_argument("--parts", nargs="*", default=[])
    args = ap.parse_args()
    readers = {"frame": ("frame.json", from_json), "memory": ("memory.json", from_json),
               "animation": ("animation.json", from_json), "stages": ("stages.md", parse_targets),
               "rays": ("rays.txt", build_targets)}
    rows = []
    for part in ["frame", "memory", "animation", "stages", "rays"]:
        name, read = readers[part]
        path = os.path.join(args.results, name)
        found = read(path) if part in args.parts and os.path.exists(path) else []
        if found:
            rows += [(part, t) for t in found]
        else:
            why = "part not run" if part not in args.parts else "no figure in its results"
            rows += [(part, {"figure": figure, "target": target, "measured": f"not measured ({why})",
                             "reference": "", "met": None}) for figure, target in PLACEHOLDERS[part]]
    lines = ["| part | figure | target | measured | reference | |", "|---|---|---|---|---|---|"]
    for part, t in rows:
        status = "" if t["met"] is None else ("met" if t["met"] else "**missed**")
        lines.append(f"| {part} | {t['figure']} | {t['target']} | {t['measured']} | {t['reference']} | {status} |")
    measured = [t for _, t in rows if t["met"] is not None]
    lines += ["", f"{sum(t['met'] for t in measured)} of {len(measured)} measured targets met; "
              f"{len(rows) - len(measured)} not measured in this run."]
    print("\n".join(lines))


if __name__ == "__main__":
    main()
