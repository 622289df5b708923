"""Parses an SVG written by toonray's ink lines with xml.etree and checks its structure.

Usage: check_svg.py FILE WIDTH HEIGHT HIDDEN(0|1) MIN_PATHS
Exits 0 when the file is well-formed XML with the expected groups and enough paths.
"""
import re
import sys
import xml.etree.ElementTree as ET

SVG = "{http://www.w3.org/2000/svg}"
TYPES = ["silhouette", "border", "crease", "material", "intersection", "polyline"]


def fail(message):
    print(f"check_svg: {message}")
    sys.exit(1)


def main():
    path, width, height, hidden, min_paths = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), sys.argv[4] == "1", int(sys.argv[5])
    root = ET.parse(path).getroot()
    if root.tag != SVG + "svg":
        fail(f"root is {root.tag}")
    if root.get("viewBox") != f"0 0 {width} {height}":
        fail(f"viewBox {root.get('viewBox')}")
    layers = [g.get("id") for g in root.findall(SVG + "g")]
    expected = ["visible", "hidden"] if hidden else ["visible"]
    if layers != expected:
        fail(f"layers {layers}")
    paths = 0
    for layer in root.findall(SVG + "g"):
        if layer.get("stroke-linecap") != "round" or float(layer.get("stroke-width")) <= 0:
            fail(f"layer {layer.get('id')} lacks round caps or a width")
        ids = [g.get("id") for g in layer.findall(SVG + "g")]
        if ids != [f"{layer.get('id')}-{t}" for t in TYPES]:
            fail(f"subgroups {ids}")
        for path_element in layer.iter(SVG + "path"):
            d = path_element.get("d")
            if not re.fullmatch(r"M -?\d+\.\d{3} -?\d+\.\d{3}( L -?\d+\.\d{3} -?\d+\.\d{3}( -?\d+\.\d{3} -?\d+\.\d{3})*)?( Z)?", d):
                fail(f"path data {d[:80]}")
            paths += 1
    if paths < min_paths:
        fail(f"{paths} paths, expected at least {min_paths}")


if __name__ == "__main__":
    main()
