#!/usr/bin/env python3
"""How frame time grows with triangles and with resolution, through the real CLI on real files.

    python3 bench/scale.py --toonray build/apps/toonray --work-dir build-bench/scale \
        [--repeats 5] [--quick] [--markdown out.md] [--csv out.csv] [--svg out.svg]

Scenes (written once into the work directory, then reused):
  * sphere_<N>.obj: a displaced sphere of N triangles (10k to 4M), a grid of nu x nv quads
    (nu = 2 nv) between the poles, without normals (the renderer uses face normals), no camera
    block (the CLI frames the scene);
  * the piano: `toonray piano --export-obj` at 6 s into the score (34,476 triangles, with its
    camera block), rendered at 720p, 1080p, 1440p and 4K.
Each point is the median wall time of `toonray render` from process start to exit (parse, BVH
build, trace, shade, lines, PNG encode and the atomic write), for the default line mode (ink) and
classic on 1 thread and on all threads. Runs of one configuration alternate with the others, so load drifts on a shared
machine spread over every row rather than one.

No third-party Python modules: the plot is written as SVG by hand.
"""

import argparse
import math
import os
import statistics
import subprocess
import sys
import time

TRIANGLES = [10_000, 30_000, 100_000, 300_000, 1_000_000, 2_000_000, 4_000_000]
QUICK_TRIANGLES = [10_000, 100_000]
RESOLUTIONS = [(1280, 720), (1920, 1080), (2560, 1440), (3840, 2160)]
QUICK_RESOLUTIONS = [(320, 180), (640, 360)]
# The line modes timed: the default (ink) and the seed's classic pipeline.
MODES = ["ink", "classic"]
LABELS = {"ink": "default (ink)", "classic": "classic", "robust": "robust"}


def write_sphere(path, triangles):
    """A displaced sphere with `triangles` triangles (rounded to the grid), written atomically."""
    nv = max(2, round(math.sqrt(triangles / 4)))
    nu = 2 * nv
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        f.write(f"# toonray scale benchmark: displaced sphere, {nu} x {nv} quads\n")
        out = []
        for j in range(nv + 1):
            theta = math.pi * j / nv
            for i in range(nu):
                phi = 2 * math.pi * i / nu
                r = 1 + 0.05 * math.sin(12 * theta) * math.sin(9 * phi) + 0.01 * math.sin(61 * theta + 3 * phi)
                out.append("v %.6f %.6f %.6f\n" % (r * math.sin(theta) * math.cos(phi), r * math.cos(theta),
                                                   r * math.sin(theta) * math.sin(phi)))
        f.write("".join(out))
        out = []
        for j in range(nv):
            for i in range(nu):
                a = j * nu + i + 1
                b = j * nu + (i + 1) % nu + 1
                c, d = a + nu, b + nu
                out.append(f"f {a} {c} {b}\nf {b} {c} {d}\n")
            if len(out) > 100_000:
                f.write("".join(out))
                out = []
        f.write("".join(out))
    os.replace(tmp, path)
    return 2 * nu * nv


def sphere(work, triangles):
    path = os.path.join(work, f"sphere_{triangles}.obj")
    nv = max(2, round(math.sqrt(triangles / 4)))
    actual = 2 * (2 * nv) * nv
    if not os.path.exists(path):
        print(f"scale: writing {path}", file=sys.stderr)
        write_sphere(path, triangles)
    return path, actual


def piano(toonray, work):
    d = os.path.join(work, "piano")
    path = os.path.join(d, "keys_000001.obj")
    if not os.path.exists(path):
        subprocess.run([toonray, "piano", "--export-obj", d, "--start", "6", "--seconds", "0.04", "--quiet"],
                       check=True)
    return path, 34_476


def render_seconds(toonray, scene, mode, threads, size, out):
    argv = [toonray, "render", scene, "-o", out, "--edges", mode, "--threads", str(threads),
            "--size", f"{size[0]}x{size[1]}"]
    start = time.perf_counter()
    subprocess.run(argv, check=True, stdout=subprocess.DEVNULL)
    return time.perf_counter() - start


def measure(toonray, cases, repeats, out):
    """cases: list of (key, scene, size). Returns {(key, mode, threads): median seconds}."""
    configs = [(mode, threads) for mode in MODES for threads in (1, 0)]
    times = {}
    for key, scene, size in cases:
        for mode, threads in configs:  # warm-up: page cache and the binary
            render_seconds(toonray, scene, mode, threads, size, out)
        for _ in range(repeats):
            for mode, threads in configs:
                times.setdefault((key, mode, threads), []).append(
                    render_seconds(toonray, scene, mode, threads, size, out))
        print(f"scale: {key} done", file=sys.stderr)
    return {k: statistics.median(v) for k, v in times.items()}


def ms(s):
    return f"{s * 1000:.0f}" if s >= 0.1 else f"{s * 1000:.1f}"


def table(title, rows, medians, label):
    lines = [f"#### {title}", "",
             f"| {label} | " + " | ".join(f"{LABELS[m]}, {'1 thread' if t == 1 else 'all threads'}"
                                         for m in MODES for t in (1, 0)) + " |",
             "|---|" + "--:|" * (2 * len(MODES))]
    for key, text in rows:
        cells = [ms(medians[(key, m, t)]) for m in MODES for t in (1, 0)]
        lines.append(f"| {text} | " + " | ".join(cells) + " |")
    lines.append("")
    lines.append("Milliseconds, median wall time of `toonray render` (process start to exit, PNG written).")
    return "\n".join(lines) + "\n"


def svg_plot(panels, path):
    """panels: [(title, xlabel, [(x, {series: seconds})])]; log-log axes, one panel per entry."""
    colours = {("classic", 1): "#1f77b4", ("classic", 0): "#7fb2dc", ("ink", 1): "#d62728",
               ("ink", 0): "#ee9a9b", ("robust", 1): "#2ca02c", ("robust", 0): "#98df8a"}
    names = {(m, t): f"{LABELS[m]}, {'1 thread' if t == 1 else 'all threads'}"
             for m in LABELS for t in (1, 0)}
    pw, ph, ml, mt, mb = 420, 300, 60, 40, 50
    width = len(panels) * (pw + ml + 20) + 20
    height = ph + mt + mb + 60
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" '
           f'font-family="sans-serif" font-size="12">', f'<rect width="{width}" height="{height}" fill="white"/>']
    for p, (title, xlabel, points) in enumerate(panels):
        x0 = 20 + p * (pw + ml + 20) + ml
        xs = [x for x, _ in points]
        ys = [v for _, series in points for v in series.values()]
        lx0, lx1 = math.log10(min(xs)), math.log10(max(xs))
        ly0, ly1 = math.floor(math.log10(min(ys))), math.ceil(math.log10(max(ys)))
        if lx1 == lx0:
            lx1 = lx0 + 1

        def X(x):
            return x0 + (math.log10(x) - lx0) / (lx1 - lx0) * pw

        def Y(y):
            return mt + ph - (math.log10(y) - ly0) / (ly1 - ly0) * ph

        out.append(f'<text x="{x0 + pw / 2}" y="{mt - 15}" text-anchor="middle" font-weight="bold">{title}</text>')
        out.append(f'<rect x="{x0}" y="{mt}" width="{pw}" height="{ph}" fill="none" stroke="#444"/>')
        for e in range(ly0, ly1 + 1):
            for m in (1, 2, 5):
                v = m * 10 ** e
                if 10 ** ly0 <= v <= 10 ** ly1:
                    y = Y(v)
                    out.append(f'<line x1="{x0}" y1="{y:.1f}" x2="{x0 + pw}" y2="{y:.1f}" stroke="#ddd"/>')
                    out.append(f'<text x="{x0 - 5}" y="{y + 4:.1f}" text-anchor="end">{v * 1000:g}</text>')
        for x in xs:
            out.append(f'<line x1="{X(x):.1f}" y1="{mt}" x2="{X(x):.1f}" y2="{mt + ph}" stroke="#eee"/>')
            lab = f"{x / 1e6:.2g}M" if x >= 1e6 else f"{x / 1e3:.0f}k"
            out.append(f'<text x="{X(x):.1f}" y="{mt + ph + 15}" text-anchor="middle">{lab}</text>')
        out.append(f'<text x="{x0 + pw / 2}" y="{mt + ph + 35}" text-anchor="middle">{xlabel}</text>')
        out.append(f'<text x="{x0 - 45}" y="{mt + ph / 2}" text-anchor="middle" '
                   f'transform="rotate(-90 {x0 - 45} {mt + ph / 2})">ms per frame (log)</text>')
        for key, colour in colours.items():
            if key not in points[0][1]:
                continue  # a mode not timed
            pts = " ".join(f"{X(x):.1f},{Y(series[key]):.1f}" for x, series in points)
            out.append(f'<polyline points="{pts}" fill="none" stroke="{colour}" stroke-width="2"/>')
            for x, series in points:
                out.append(f'<circle cx="{X(x):.1f}" cy="{Y(series[key]):.1f}" r="3" fill="{colour}"/>')
    timed = [(key, colour) for key, colour in colours.items() if key in panels[0][2][0][1]]
    for i, (key, colour) in enumerate(timed):
        lx = 20 + ml + i * 170
        out.append(f'<line x1="{lx}" y1="{height - 20}" x2="{lx + 25}" y2="{height - 20}" stroke="{colour}" '
                   f'stroke-width="3"/><text x="{lx + 30}" y="{height - 16}">{names[key]}</text>')
    out.append("</svg>")
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        f.write("\n".join(out) + "\n")
    os.replace(tmp, path)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--toonray", help="the toonray CLI to time (required unless --write-sphere)")
    ap.add_argument("--write-sphere", type=int, metavar="N",
                    help="only write the N-triangle sphere into the work directory and print its path")
    ap.add_argument("--work-dir", required=True)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--quick", action="store_true", help="small scenes and images, one repeat")
    ap.add_argument("--markdown")
    ap.add_argument("--csv")
    ap.add_argument("--svg")
    args = ap.parse_args()
    os.makedirs(args.work_dir, exist_ok=True)
    if args.write_sphere:
        print(sphere(args.work_dir, args.write_sphere)[0])
        return
    if not args.toonray:
        ap.error("--toonray is required")
    out = os.path.join(args.work_dir, "frame.png")
    repeats = 1 if args.quick else args.repeats
    tri_counts = QUICK_TRIANGLES if args.quick else TRIANGLES
    resolutions = QUICK_RESOLUTIONS if args.quick else RESOLUTIONS

    spheres = [(n,) + sphere(args.work_dir, n) for n in tri_counts]
    med_tris = measure(args.toonray, [(n, path, (1280, 720)) for n, path, _ in spheres], repeats, out)
    piano_path, _ = piano(args.toonray, args.work_dir)
    med_res = measure(args.toonray, [(size, piano_path, size) for size in resolutions], repeats, out)

    md = table("Frame time against triangles (displaced sphere, 1280x720)",
               [(n, f"{actual:,}") for n, _, actual in spheres], med_tris, "triangles")
    md += "\n" + table("Frame time against resolution (the piano, 34,476 triangles)",
                       [(s, f"{s[0]}x{s[1]} ({s[0] * s[1] / 1e6:.2f} Mpixel)") for s in resolutions], med_res,
                       "image")
    print(md)
    if args.markdown:
        with open(args.markdown, "w") as f:
            f.write(md)
    if args.csv:
        with open(args.csv, "w") as f:
            f.write("sweep,x,mode,threads,seconds\n")
            for (n, mode, t), s in sorted(med_tris.items()):
                f.write(f"triangles,{n},{mode},{t or 'all'},{s:.6f}\n")
            for ((w, h), mode, t), s in sorted(med_res.items()):
                f.write(f"pixels,{w * h},{mode},{t or 'all'},{s:.6f}\n")
    if args.svg:
        by_tris = [(actual, {(m, t): med_tris[(n, m, t)] for m in MODES for t in (1, 0)}) for n, _, actual in spheres]
        by_pix = [(w * h, {(m, t): med_res[((w, h), m, t)] for m in MODES for t in (1, 0)}) for w, h in resolutions]
        svg_plot([("Triangles (1280x720)", "triangles", by_tris),
                  ("Pixels (the piano, 34k triangles)", "pixels", by_pix)], args.svg)


if __name__ == "__main__":
    main()
