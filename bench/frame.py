#!/usr/bin/env python3
"""One frame, whole process, against a reference program; and the peak memory of frames.

    python3 bench/frame.py frame --toonray CLI --reference REF --work-dir DIR \\
        [--repeats 5] [--size 1280x720] [--no-pin] [--markdown out.md] [--json out.json] SCENE.obj ...
    python3 bench/frame.py memory --toonray CLI --reference REF --work-dir DIR \\
        [--markdown out.md] [--json out.json]
    python3 bench/frame.py check --toonray CLI --reference REF --work-dir DIR \\
        [--size 320x180] [--min-equal 0.99] SCENE.obj ...

frame: on each scene, `toonray render SCENE -o x.png --size 1280x720 --threads 1` in the default
line mode (ink), with `--adaptive off` when the CLI has that option, with `--edges robust` and
with `--edges classic`, and the reference program (bench/reference_classic.cpp: tinyobjloader,
Embree, libpng, the classic pipeline on one thread) with Embree packets (rtcIntersect8, the
ratios' denominator) and single rays (rtcIntersect1), each timed from process start to exit.
The variants run interleaved, one of each per round (the order rotating each round), after one
warm-up round; the tables give medians of --repeats rounds (TOONRAY_BENCH_REPEATS in run.sh).
Every process is pinned to one CPU (sched_setaffinity; --no-pin to let it float), so a program
that starts threads of its own despite `--threads 1` gets no second core; the CPU column (user +
system time of the process) shows what each one used. Targets: the default mode <= 0.35x the
reference, classic <= 0.25x, judged on the first scene (the scan: run.sh passes scan70k.obj
first); the other scenes show the same ratios for scale. Before timing, the reference's PNG is
compared with toonray's classic PNG (fraction of equal pixels) so that it is seen to draw the
same picture.

memory: peak RSS (ru_maxrss of the child, from wait4) of `toonray render` on all threads: the
default mode at 4K and 8K on a 65,536-triangle displaced sphere (bench/scale.py
--write-sphere 65536), and at 720p on a one-triangle OBJ; classic at 720p on both; the reference
at 720p and 4K beside them. Targets: 4K <= 400 MB, 8K works (exit 0 and a PNG of the right
size) and <= 1 GB, one triangle at 720p <= 40 MB. MB are 10^6 bytes. toonray runs with
--max-memory 8G, so that a frame far over its target is refused rather than run on a shared
machine. --quick: the 720p frames only.

check: the agreement of the reference with `toonray render --edges classic` only, small (CTest
frame_quick): exits 1 when fewer than --min-equal of the pixels are equal on some scene.

--json writes {"rows": [...], "targets": [...]} for run.sh's summary (bench/summary.py).
No third-party Python modules.
"""

import argparse
import os
import statistics
import struct
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import scale  # noqa: E402  (the 65,536-triangle sphere)
from publish import publish  # noqa: E402

DEFAULT_TARGET = 0.35
CLASSIC_TARGET = 0.25
MB = 1e6
MEMORY_CAP = "8G"  # toonray's --max-memory in the memory part


class Run:
    def __init__(self, seconds, cpu, max_rss_bytes, status, stderr):
        self.seconds, self.cpu, self.max_rss, self.status, self.stderr = seconds, cpu, max_rss_bytes, status, stderr


def run(argv, pin=None):
    """Runs argv to exit; wall time, CPU time and peak RSS of that process alone (wait4)."""
    with tempfile.TemporaryFile() as err:
        preexec = (lambda: os.sched_setaffinity(0, {pin})) if pin is not None else None
        start = time.perf_counter()
        p = subprocess.Popen(argv, stdout=subprocess.DEVNULL, stderr=err, preexec_fn=preexec)
        _, status, usage = os.wait4(p.pid, 0)
        seconds = time.perf_counter() - start
        p.returncode = os.waitstatus_to_exitcode(status)
        err.seek(0)
        text = err.read().decode(errors="replace")
    return Run(seconds, usage.ru_utime + usage.ru_stime, usage.ru_maxrss * 1024, p.returncode, text)


def checked(argv, pin=None):
    r = run(argv, pin)
    if r.status != 0:
        sys.exit(f"frame: {' '.join(argv)} exited with {r.status}:\n{r.stderr}")
    return r


def png_size(path):
    with open(path, "rb") as f:
        head = f.read(24)
    if len(head) < 24 or head[:8] != b"\x89PNG\r\n\x1a\n":
        return None
    return struct.unpack(">II", head[16:24])


def has_option(toonray, option):
    out = subprocess.run([toonray, "render", "--help"], capture_output=True, text=True)
    return option in out.stdout


def agreement(reference, a, b, min_equal=0.0):
    """(fraction equal, fraction within 16, ok) from the reference program's --compare."""
    out = subprocess.run([reference, "--compare", a, b, "--min-equal", str(min_equal)], capture_output=True,
                         text=True)
    words = out.stdout.split()
    if "agreement:" not in words:
        sys.exit(f"frame: cannot compare {a} and {b}: {out.stdout}{out.stderr}")
    i = words.index("equal,")
    return float(words[i - 1]), float(words[i + 1]), out.returncode == 0


def ms(seconds):
    return f"{seconds * 1000:.0f}" if seconds >= 0.1 else f"{seconds * 1000:.1f}"


def met(ok):
    return "met" if ok else "**missed**"


def pin_cpu(args):
    return None if args.no_pin else max(os.sched_getaffinity(0))


def variants(args, scene, out):
    w_h = args.size
    base = [args.toonray, "render", scene, "--size", w_h, "--threads", "1", "-o"]
    v = [("default (ink)", base + [f"{out}/default.png"], DEFAULT_TARGET)]
    if has_option(args.toonray, "--adaptive"):
        v.append(("default, --adaptive off", base + [f"{out}/adaptive_off.png", "--adaptive", "off"], None))
    v += [("robust", base + [f"{out}/robust.png", "--edges", "robust"], None),
          ("classic", base + [f"{out}/classic.png", "--edges", "classic"], CLASSIC_TARGET),
          ("reference: Embree rtcIntersect8", [args.reference, scene, "--size", w_h, "-o", f"{out}/reference.png"],
           None),
          ("reference: Embree rtcIntersect1",
           [args.reference, scene, "--size", w_h, "-o", f"{out}/reference1.png", "--rays", "single"], None)]
    return v


REFERENCE = "reference: Embree rtcIntersect8"


def frame_part(args):
    pin = pin_cpu(args)
    md = [f"#### One frame at {args.size}, whole process, one thread",
          "",
          f"Median of {args.repeats} interleaved rounds after a warm-up round; "
          + (f"every process pinned to CPU {pin}. " if pin is not None else "processes not pinned. ")
          + "ms: wall time from process start to exit; CPU: user + system time of the process. "
          + f"Targets: default <= {DEFAULT_TARGET}x the reference, classic <= {CLASSIC_TARGET}x, "
          + "judged on the first scene."
          + ("" if has_option(args.toonray, "--adaptive") else
             " (No `--adaptive off` row: this CLI has no --adaptive option.)"),
          ""]
    rows, targets = [], []
    for index, scene in enumerate(args.scenes):
        name = os.path.basename(scene)
        out = os.path.join(args.work_dir, os.path.splitext(name)[0])
        os.makedirs(out, exist_ok=True)
        vs = variants(args, scene, out)
        for label, argv, _ in vs:  # warm-up: page cache, the binaries; the PNGs for the check
            checked(argv, pin)
        equal, close, _ = agreement(args.reference, f"{out}/reference.png", f"{out}/classic.png")
        times = {label: [] for label, _, _ in vs}
        cpu = {label: [] for label, _, _ in vs}
        for r in range(args.repeats):
            for k in range(len(vs)):
                label, argv, _ = vs[(k + r) % len(vs)]
                result = checked(argv, pin)
                times[label].append(result.seconds)
                cpu[label].append(result.cpu)
        med = {label: statistics.median(t) for label, t in times.items()}
        med_cpu = {label: statistics.median(t) for label, t in cpu.items()}
        ref, ref_cpu = med[REFERENCE], med_cpu[REFERENCE]
        md += [f"##### {name}", "",
               f"Reference PNG against toonray's classic PNG: {100 * equal:.2f}% of pixels equal, "
               f"{100 * close:.2f}% within 16 per channel.", "",
               "| program | ms | x reference | CPU ms | CPU x reference | target | |",
               "|---|--:|--:|--:|--:|--:|---|"]
        for label, _, target in vs:
            ratio, cpu_ratio = med[label] / ref, med_cpu[label] / ref_cpu
            judged = target is not None and index == 0
            status = met(ratio <= target) if judged else ""
            md.append(f"| {label} | {ms(med[label])} | {ratio:.2f}x | {ms(med_cpu[label])} | {cpu_ratio:.2f}x | "
                      + (f"<= {target}x" if target is not None else "") + f" | {status} |")
            rows.append({"scene": name, "program": label, "ms": 1000 * med[label], "cpu_ms": 1000 * med_cpu[label],
                         "ratio": ratio, "cpu_ratio": cpu_ratio})
            if judged:
                targets.append({"figure": f"{label.split(' ')[0]} frame, {name} {args.size}, 1 thread",
                                "target": f"<= {target}x reference",
                                "measured": f"{ms(med[label])} ms = {ratio:.2f}x (CPU time {cpu_ratio:.2f}x)",
                                "reference": f"{ms(ref)} ms", "met": ratio <= target})
        md.append("")
        rows.append({"scene": name, "agreement_equal": equal, "agreement_within_16": close})
        print(f"frame: {name} done", file=sys.stderr)
    return md, rows, targets


def write_one_triangle(work):
    path = os.path.join(work, "one_triangle.obj")
    with open(path, "w") as f:
        f.write("# one triangle (bench/frame.py)\nv -1 -1 0\nv 1 -1 0\nv 0 1 0\nf 1 2 3\n")
    return path


def memory_part(args):
    # The sphere is written once (a second) and only when a case needs it.
    sphere, tris = (None, 65_536) if args.quick else scale.sphere(args.work_dir, 65_536)
    tiny = write_one_triangle(args.work_dir)
    out = os.path.join(args.work_dir, "memory")
    os.makedirs(out, exist_ok=True)
    cases = [  # label, scene text, program, size, extra args, target bytes, target text
        ("toonray default (ink)", f"sphere, {tris:,} triangles", args.toonray, sphere, "3840x2160", [], 400 * MB,
         "<= 400 MB"),
        ("toonray default (ink)", f"sphere, {tris:,} triangles", args.toonray, sphere, "7680x4320", [], 1000 * MB,
         "works, <= 1 GB"),
        ("toonray classic", f"sphere, {tris:,} triangles", args.toonray, sphere, "3840x2160", ["--edges", "classic"],
         None, ""),
        ("reference (classic)", f"sphere, {tris:,} triangles", args.reference, sphere, "3840x2160", [], None, ""),
        ("reference (classic)", f"sphere, {tris:,} triangles", args.reference, sphere, "7680x4320", [], None, ""),
        ("toonray default (ink)", "one triangle", args.toonray, tiny, "1280x720", [], 40 * MB, "<= 40 MB"),
        ("toonray classic", "one triangle", args.toonray, tiny, "1280x720", ["--edges", "classic"], None, ""),
        ("reference (classic)", "one triangle", args.reference, tiny, "1280x720", [], None, ""),
    ]
    if args.quick:  # the small frames only: a second, not the 8K frame's minute
        cases = [c for c in cases if c[4] == "1280x720"]
    md = ["#### Peak memory of one frame",
          "",
          "Peak RSS (ru_maxrss of the process, from wait4), one run each; toonray on all threads "
          "(its default), the reference on one. MB = 10^6 bytes.",
          "",
          "| program | scene | image | peak RSS MB | wall s | target | |",
          "|---|---|---|--:|--:|--:|---|"]
    rows, targets = [], []
    ref_rss = {}
    for label, scene_text, program, scene, size, extra, target, target_text in cases:
        png = os.path.join(out, f"{len(rows)}.png")
        if program == args.reference:
            argv = [program, scene, "--size", size, "-o", png]
        else:
            # The cap only keeps a frame far over its target from filling the shared machine: one
            # that would need more is refused (and reported) rather than run.
            argv = [program, "render", scene, "--size", size, "-o", png, "--max-memory", MEMORY_CAP] + extra
        if os.path.exists(png):
            os.remove(png)
        r = run(argv)
        w, h = (int(v) for v in size.split("x"))
        works = r.status == 0 and png_size(png) == (w, h)
        ok = works and (target is None or r.max_rss <= target)
        rss = f"{r.max_rss / MB:.0f}" if works else f"failed (exit {r.status}): {r.stderr.strip()[:120]}"
        md.append(f"| {label} | {scene_text} | {size} | {rss} | {r.seconds:.2f} | {target_text} | "
                  + (met(ok) if target_text else "") + " |")
        rows.append({"program": label, "scene": scene_text, "size": size, "max_rss_bytes": r.max_rss,
                     "seconds": r.seconds, "works": works})
        if label.startswith("reference"):
            ref_rss[(scene_text, size)] = r.max_rss
        if target_text:
            targets.append({"figure": f"peak RSS, {label} frame, {scene_text}, {size}",
                            "target": target_text,
                            "measured": f"{r.max_rss / MB:.0f} MB" if works else f"failed (exit {r.status})",
                            "reference": "", "met": ok, "key": (scene_text, size)})
        if os.path.exists(png):
            os.remove(png)  # 8K PNGs are large
    for t in targets:  # the reference beside each target, where it ran the same scene
        key = t.pop("key")
        near = [v for (s, z), v in ref_rss.items() if s == key[0] and z == key[1]]
        t["reference"] = f"{near[0] / MB:.0f} MB (classic)" if near else ""
    md.append("")
    return md, rows, targets


def check_part(args):
    failed = False
    for scene in args.scenes:
        name = os.path.splitext(os.path.basename(scene))[0]
        out = os.path.join(args.work_dir, name)
        os.makedirs(out, exist_ok=True)
        checked([args.toonray, "render", scene, "--size", args.size, "--threads", "1", "--edges", "classic",
                 "-o", f"{out}/classic.png"])
        checked([args.reference, scene, "--size", args.size, "-o", f"{out}/reference.png"])
        equal, close, ok = agreement(args.reference, f"{out}/reference.png", f"{out}/classic.png", args.min_equal)
        print(f"{name} {args.size}: reference against toonray classic: {100 * equal:.2f}% equal, "
              f"{100 * close:.2f}% within 16 per channel (required: {100 * args.min_equal:.0f}% equal): "
              + ("ok" if ok else "FAILED"))
        failed |= not ok
    return 1 if failed else 0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("part", choices=["frame", "memory", "check"])
    ap.add_argument("scenes", nargs="*")
    ap.add_argument("--toonray", required=True)
    ap.add_argument("--reference", required=True)
    ap.add_argument("--work-dir", required=True)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--size")
    ap.add_argument("--no-pin", action="store_true")
    ap.add_argument("--quick", action="store_true", help="memory: the 720p frames only")
    ap.add_argument("--min-equal", type=float, default=0.99)
    ap.add_argument("--markdown")
    ap.add_argument("--json")
    args = ap.parse_intermixed_args()
    os.makedirs(args.work_dir, exist_ok=True)
    if args.part in ("frame", "check") and not args.scenes:
        ap.error(f"{args.part} needs at least one scene")
    if args.part == "check":
        args.size = args.size or "320x180"
        sys.exit(check_part(args))
    args.size = args.size or "1280x720"
    md, rows, targets = frame_part(args) if args.part == "frame" else memory_part(args)
    publish("\n".join(md) + "\n", args.markdown, args.json, {"rows": rows, "targets": targets})


if __name__ == "__main__":
    main()
