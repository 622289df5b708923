"""Parses an SVG written by toonray's ink lines with xml.etree and checks its structure.

Usage: check_svg.py FILE WIDTH HEIGHT HIDDEN(0|1) MIN_PATHS [MIN_DASHED_HIDDEN]
Exits 0 when the file is well-formed XML with the expected groups and enough paths, every
stroked path is a polyline whose own style attributes (stroke, stroke-width, stroke-opacity,
stroke-dasharray) are well-formed, every filled outline (a stroke whose width varies: stroke
none, fill, fill-opacity) is made of closed subpaths of lines and quarter arcs, an embedded
fill image (if any) is a PNG data URI under the lines, and at least MIN_DASHED_HIDDEN paths of
the hidden layer are dashed.
"""
import re
import sys
import xml.etree.ElementTree as ET

SVG = "{http://www.w3.org/2000/svg}"
TYPES = ["silhouette", "border", "crease", "material", "intersection", "polyline", "band", "shadow"]


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
    # A tone look's strokes and dots come first, under the lines.
    if layers and layers[0] == "tone":
        expected = ["tone"] + expected
    if layers != expected:
        fail(f"layers {layers}")
    min_dashed_hidden = int(sys.argv[6]) if len(sys.argv) > 6 else 0
    images = root.findall(SVG + "image")
    for image in images:
        href = image.get("{http://www.w3.org/1999/xlink}href") or ""
        if image.get("id") != "fill" or not href.startswith("data:image/png;base64,iVBORw0KGgo"):
            fail("the fill image is not an embedded PNG")
        if list(root).index(image) != 0:
            fail("the fill image is not under the lines")
    number = r"\d+\.\d{3}"
    dashed_hidden = 0
    paths = 0
    for layer in root.findall(SVG + "g"):
        if layer.get("stroke-linecap") != "round" or float(layer.get("stroke-width")) <= 0:
            fail(f"layer {layer.get('id')} lacks round caps or a width")
        ids = [g.get("id") for g in layer.findall(SVG + "g")]
        if layer.get("id") == "tone":
            if ids:
                fail(f"the tone has subgroups {ids}")
            for circle in layer.iter(SVG + "circle"):
                if not re.fullmatch(r"#[0-9a-f]{6}", circle.get("fill") or "") or float(circle.get("r")) <= 0:
                    fail(f"dot {circle.attrib}")
        elif ids != [f"{layer.get('id')}-{t}" for t in TYPES]:
            fail(f"subgroups {ids}")
        for path_element in layer.iter(SVG + "path"):
            d = path_element.get("d")
            outline = path_element.get("fill") is not None
            if outline:
                point = r"-?\d+\.\d{3} -?\d+\.\d{3}"
                shape = rf"M {point}( L {point}| A {number} {number} 0 0 0 {point})* Z"
                if path_element.get("stroke") != "none" or not re.fullmatch(rf"{shape}( {shape})*", d):
                    fail(f"outline {path_element.get('stroke')} {d[:80]}")
                checks = {"fill": r"#[0-9a-f]{6}", "fill-opacity": number}
            else:
                if not re.fullmatch(r"M -?\d+\.\d{3} -?\d+\.\d{3}( L -?\d+\.\d{3} -?\d+\.\d{3}( -?\d+\.\d{3} -?\d+\.\d{3})*)?( Z)?", d):
                    fail(f"path data {d[:80]}")
                checks = {"stroke": r"#[0-9a-f]{6}", "stroke-width": number, "stroke-opacity": number,
                          "stroke-dasharray": rf"{number}(,{number})*", "stroke-linecap": "butt"}
            for name, pattern in checks.items():
                value = path_element.get(name)
                if value is not None and not re.fullmatch(pattern, value):
                    fail(f"path {name}={value}")
            opacity = path_element.get("fill-opacity" if outline else "stroke-opacity")
            if opacity is not None and not 0.0 <= float(opacity) <= 1.0:
                fail(f"opacity {opacity}")
            if layer.get("id") == "hidden" and path_element.get("stroke-dasharray"):
                dashed_hidden += 1
            paths += 1
    if paths < min_paths:
        fail(f"{paths} paths, expected at least {min_paths}")
    if dashed_hidden < min_dashed_hidden:
        fail(f"{dashed_hidden} dashed hidden paths, expected at least {min_dashed_hidden}")


if __name__ == "__main__":
    main()
