"""The same inputs give the same bytes through the command line and through Python: the PNG, the
SVG and the error messages (docs/python.md, "Same as the command line")."""

import os
import unittest

import numpy as np

import toonray
from support import CLI, DATA, TempDir, run_cli, scene_arrays, write_scene

# Settings as the command line gives them and as a dict gives them.
CASES = [
    ([], {}),
    (["--edges", "robust", "--samples", "4", "--line-width", "3"],
     {"lines.mode": "robust", "sampling.samples": 4, "lines.width": 3.0}),
    (["--edges", "classic", "--ramp", "0.3,0.6,1@0.2,0.6", "--background", "1,1,1"],
     {"lines": {"mode": "classic"}, "shading": {"ramp": "0.3,0.6,1@0.2,0.6"},
      "image.background": (1, 1, 1)}),
    (["--samples", "9", "--line-color", "#203040", "--hidden-lines", "--light", "dir:1,1,-1@0.8"],
     {"sampling.samples": 9, "lines.colour": "#203040", "output.svg_hidden": True,
      "scene.lights": ["dir:1,1,-1@0.8"]}),
]


class CommandLineParity(unittest.TestCase):
    def test_obj_scene_png_and_svg_are_byte_identical(self):
        with TempDir() as d:
            obj = write_scene(d)
            scene = toonray.load(obj)
            built = self.built_scene()
            for i, (flags, settings) in enumerate(CASES):
                png, svg = os.path.join(d, "cli%d.png" % i), os.path.join(d, "cli%d.svg" % i)
                code, err = run_cli("render", obj, "-o", png, "--svg", svg, "--size", "160x120",
                                    *flags)
                self.assertEqual(code, 0, err)
                with open(png, "rb") as f:
                    cli_png = f.read()
                with open(svg) as f:
                    cli_svg = f.read()
                for name, s in (("loaded", scene), ("arrays", built)):
                    frame = toonray.render(s, 160, 120, settings, svg=True)
                    self.assertEqual(frame.png(), cli_png, "case %d, %s scene" % (i, name))
                    self.assertEqual(frame.svg, cli_svg, "case %d, %s scene" % (i, name))

    def test_settings_file_is_the_same_document(self):
        with TempDir() as d:
            obj = write_scene(d)
            toml = os.path.join(d, "look.toml")
            with open(toml, "w") as f:
                f.write("[lines]\nmode = \"robust\"\nwidth = 4.5\n\n[[lines.rule]]\n"
                        "object = \"ground\"\ndraw = false\n")
            png = os.path.join(d, "cli.png")
            code, err = run_cli("render", obj, "-o", png, "--size", "96x64", "--settings", toml)
            self.assertEqual(code, 0, err)
            with open(png, "rb") as f:
                self.assertEqual(toonray.render(toonray.load(obj), 96, 64, toml).png(), f.read())
            # The same document given as a dict (a path-like works too).
            as_dict = {"lines": {"mode": "robust", "width": 4.5,
                                 "rule": [{"object": "ground", "draw": False}]}}
            with open(png, "rb") as f:
                self.assertEqual(toonray.render(toonray.load(obj), 96, 64, as_dict).png(), f.read())

    def test_gltf_posed_at_a_time(self):
        gltf = os.path.join(DATA, "gltf", "BoxAnimated.gltf")
        with TempDir() as d:
            png = os.path.join(d, "box.png")
            code, err = run_cli("render", gltf, "-o", png, "--size", "120x90", "--time", "1.25")
            self.assertEqual(code, 0, err)
            frame = toonray.render(toonray.load(gltf, time=1.25), 120, 90)
            with open(png, "rb") as f:
                self.assertEqual(frame.png(), f.read())

    def test_errors_carry_the_command_lines_message(self):
        with TempDir() as d:
            bad_obj = os.path.join(d, "bad.obj")
            with open(bad_obj, "w") as f:
                f.write("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n")
            code, err = run_cli("render", bad_obj, "-o", os.path.join(d, "x.png"))
            self.assertEqual(code, 1)
            with self.assertRaises(toonray.Error) as caught:
                toonray.load(bad_obj)
            self.assertEqual("toonray: error: %s\n" % caught.exception, err)

            obj = write_scene(d)
            toml = os.path.join(d, "bad.toml")
            with open(toml, "w") as f:
                f.write("[lines]\nwidth = 200\n")
            code, err = run_cli("render", obj, "-o", os.path.join(d, "x.png"), "--settings", toml)
            self.assertEqual(code, 1)
            with self.assertRaises(toonray.Error) as caught:
                toonray.render(toonray.load(obj), 32, 32, toml)
            self.assertEqual("toonray: error: %s\n" % caught.exception, err)
            # A value given directly: the command line names its option, Python the key.
            with self.assertRaises(toonray.Error) as caught:
                toonray.render(toonray.load(obj), 32, 32, {"lines.width": 200})
            self.assertEqual(str(caught.exception), "lines.width: 200 is outside [0, 100]")
            code, err = run_cli("render", obj, "-o", os.path.join(d, "x.png"), "--line-width", "200")
            self.assertEqual(err, "toonray: error: --line-width: '200' is outside [0, 100]\n")

    @staticmethod
    def built_scene():
        """two.obj's scene built from arrays: its materials, objects and camera block."""
        scene = toonray.Scene()
        ids = {"red": scene.add_material(toonray.Material("red", kd=(0.8, 0.2, 0.1))),
               "blue": scene.add_material(toonray.Material("blue", kd=(0.2, 0.3, 0.9)))}
        for name, positions, triangles, material in scene_arrays():
            scene.add_object(positions, triangles, name=name,
                             materials=np.full(len(triangles), ids[material], dtype=np.uint32))
        scene.camera = toonray.Camera.block((5, -7, 4), (4.4, -6.16, 3.52), (0, 0, 1))
        return scene


if __name__ == "__main__":
    unittest.main()
