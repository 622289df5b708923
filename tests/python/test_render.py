"""Frames from Python: the picture, layers, strokes and SVG; scenes from arrays with instances;
progress, cancel and the GIL (docs/python.md)."""

import math
import threading
import time
import unittest

import numpy as np

import toonray
from support import TempDir, write_scene


def cube():
    """A unit cube's positions and triangles (outward winding)."""
    p = np.array([[x, y, z] for z in (-0.5, 0.5) for y in (-0.5, 0.5) for x in (-0.5, 0.5)],
                 dtype=np.float32)
    quads = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    t = []
    for a, b, c, d in quads:
        t += [(a, b, c), (a, c, d)]
    return p, np.array(t, dtype=np.uint32)


def translation(x, y, z, scale=1.0):
    m = np.eye(4) * scale
    m[3, 3] = 1.0
    m[:3, 3] = (x, y, z)
    return m


def two_cubes():
    scene = toonray.Scene()
    red = scene.add_material(toonray.Material("red", kd=(0.9, 0.1, 0.1)))
    positions, triangles = cube()
    mesh = scene.add_mesh(positions, triangles, materials=np.full(12, red, dtype=np.uint32),
                          name="cube")
    left = scene.add_instance(mesh, translation(-1, 0, 0), name="left")
    right = scene.add_instance(mesh, translation(1, 0, 0, scale=0.5))
    scene.camera = toonray.Camera((0, -6, 1), (0, 0, 0), up=(0, 0, 1), lens=35)
    return scene, left, right


class Frames(unittest.TestCase):
    def test_tone_looks_have_their_coverage_layer(self):
        scene, _, _ = two_cubes()
        cel = toonray.render(scene, 120, 80, {})
        self.assertEqual(cel.layers["tone.coverage"].max(), 0.0)
        for mode in ("hatch", "screentone"):
            frame = toonray.render(scene, 120, 80, {"tone.mode": mode})
            coverage = frame.layers["tone.coverage"]
            self.assertGreater(coverage.max(), 0.0, mode)
            self.assertLessEqual(coverage.max(), 1.0, mode)
            self.assertFalse((frame.image == cel.image).all(), mode)

    def test_picture_layers_and_ids(self):
        scene, left, right = two_cubes()
        # Lines 10 pixels wide at 720 lines: over a pixel here.
        frame = toonray.render(scene, 120, 80, {"lines.width": 10})
        self.assertEqual((frame.width, frame.height), (120, 80))
        image = frame.image
        self.assertEqual(image.shape, (80, 120, 4))
        self.assertEqual(image.dtype, np.uint8)
        self.assertTrue((image[..., 3] == 255).all())
        # The EXR's channels, one per line type of the mode among them.
        layers = frame.layers
        for name in ["R", "A", "Z", "view_depth.Z", "N.X", "object_id.id", "band.index",
                     "light.L", "lines.all"]:
            self.assertIn(name, layers)
        for line_type in toonray.line_layers("ink"):
            self.assertIn("lines." + line_type, layers)
        self.assertEqual(layers["Z"].shape, (80, 120))
        self.assertEqual(frame.layer_names, list(layers))
        self.assertTrue((frame.layer("lines.all") == layers["lines.all"]).all())
        with self.assertRaises(KeyError):
            frame.layer("no such layer")
        self.assertEqual(layers["Z"].dtype, np.float32)
        ids = frame.object_ids
        self.assertEqual(ids.dtype, np.uint32)
        seen = set(np.unique(ids).tolist())
        self.assertEqual(seen, {left, right, toonray.NO_ID})
        self.assertEqual(scene.objects, ["(default)", "left", "cube"])
        # Where nothing is seen: Blender's background depth, alpha 0, no id.
        background = ids == toonray.NO_ID
        self.assertTrue((layers["Z"][background] == 1e10).all())
        self.assertTrue((layers["A"][background] == 0).all())
        self.assertGreater(layers["lines.all"].max(), 0.99)
        # The instance placed at half size is smaller in the picture.
        self.assertGreater((ids == left).sum(), 2 * (ids == right).sum())

    def test_instances_store_their_mesh_once(self):
        scene, left, right = two_cubes()
        self.assertEqual(scene.instance_count, 2)
        self.assertEqual(scene.instanced_triangle_count, 24)
        # Nothing of the instances is copied into the scene's own triangles.
        self.assertEqual(scene.triangle_count, 0)
        self.assertEqual(scene.positions.shape, (0, 3))
        # A mesh never placed is not in the scene at all.
        scene.add_mesh(*cube(), name="unused")
        self.assertEqual(scene.instanced_triangle_count, 24)

    def test_instances_draw_as_their_mesh_moved(self):
        # The same cubes placed once each as the scene's own triangles (add_object moves the
        # arrays into the world) draw the same picture: instances are traced in the mesh's own
        # coordinates, so a pixel whose sample grazes an edge may fall on its other side.
        instanced, left, right = two_cubes()
        flat = toonray.Scene()
        red = flat.add_material(toonray.Material("red", kd=(0.9, 0.1, 0.1)))
        p, t = cube()
        materials = np.full(12, red, dtype=np.uint32)
        self.assertEqual(flat.add_object(p, t, materials=materials, name="left",
                                         matrix=translation(-1, 0, 0)), left)
        self.assertEqual(flat.add_object(p, t, materials=materials, name="cube",
                                         matrix=translation(1, 0, 0, scale=0.5)), right)
        flat.camera = instanced.camera
        np.testing.assert_array_equal(flat.positions[:8], p + np.float32([-1, 0, 0]))
        a = toonray.render(instanced, 120, 80, {"lines.width": 4})
        b = toonray.render(flat, 120, 80, {"lines.width": 4})
        self.assertEqual(a.object_ids.shape, b.object_ids.shape)
        self.assertGreater((a.object_ids == b.object_ids).mean(), 0.99)
        self.assertGreater((a.image == b.image).all(axis=2).mean(), 0.99)
        self.assertEqual({s.object for s in a.strokes}, {s.object for s in b.strokes})
        # A mirrored instance or object keeps its faces facing out: the same picture as the
        # plain one (the cube is symmetric).
        pictures = []
        for instance in (False, True):
            for m in (np.eye(4), np.diag([-1.0, 1.0, 1.0, 1.0])):
                s = toonray.Scene()
                if instance:
                    s.add_instance(s.add_mesh(p, t, name="c"), m)
                else:
                    s.add_object(p, t, name="c", matrix=m)
                s.camera = toonray.Camera((0, -4, 0.5), (0, 0, 0), up=(0, 0, 1))
                pictures.append(toonray.render(s, 64, 64).image)
        self.assertTrue((pictures[0] == pictures[1]).all())
        self.assertGreater((pictures[2] == pictures[3]).all(axis=2).mean(), 0.99)
        self.assertGreater((pictures[0] == pictures[2]).all(axis=2).mean(), 0.99)

    def test_strokes_and_svg(self):
        scene, left, right = two_cubes()
        frame = toonray.render(scene, 120, 80, {"output.svg_hidden": True}, svg=True)
        self.assertTrue(frame.svg.startswith("<?xml") or frame.svg.startswith("<svg"))
        self.assertIn("hidden", frame.svg)
        strokes = frame.strokes
        self.assertTrue(strokes)
        self.assertEqual({s.object for s in strokes}, {left, right})
        self.assertIn("silhouette", {s.type for s in strokes})
        self.assertIn(False, {s.visible for s in strokes})
        points = strokes[0].points
        self.assertEqual(points.shape[1], 2)
        self.assertTrue((points >= -2).all() and (points[:, 0] <= 122).all())
        # Another mode keeps strokes only for the SVG.
        self.assertIsNone(toonray.render(scene, 60, 40, {"lines.mode": "robust"}).strokes)
        self.assertIsNone(toonray.render(scene, 60, 40).svg)

    def test_without_layers_only_the_picture(self):
        scene, _, _ = two_cubes()
        frame = toonray.render(scene, 60, 40, layers=False)
        self.assertEqual(frame.layers, {})
        self.assertIsNone(frame.object_ids)
        self.assertEqual(frame.png(), toonray.render(scene, 60, 40).png())

    def test_camera_lens_and_block(self):
        cam = toonray.Camera((0, -10, 0), (0, 0, 0), up=(0, 0, 1), lens=50, sensor_width=36)
        spec = cam.spec(1920, 1080)
        self.assertAlmostEqual(math.dist(spec["eye"], spec["gaze"]), 100 / 36, places=5)
        fov = toonray.Camera((0, -10, 0), (0, 0, 0), up=(0, 0, 1), fov=60).spec(100, 100)
        self.assertAlmostEqual(math.dist(fov["eye"], fov["gaze"]), 1 / math.tan(math.pi / 6), 5)
        shifted = toonray.Camera((0, -10, 0), (0, 0, 0), up=(0, 0, 1), shift=(0.1, 0)).spec(200, 100)
        self.assertAlmostEqual(shifted["shift"][0], 0.1, places=6)
        with self.assertRaises(toonray.Error) as caught:
            toonray.Camera((0, 0, 0), (0, 0, 0)).spec(10, 10)
        self.assertEqual(str(caught.exception), "invalid camera: eye and target are the same point")
        with self.assertRaises(toonray.Error):
            toonray.Camera.block((0, 0, 0), (0, 0, 0), (0, 1, 0))

    def test_bad_arrays_and_limits_are_errors(self):
        scene = toonray.Scene()
        p, t = cube()
        bad = t.copy()
        bad[3, 1] = 99
        with self.assertRaises(toonray.Error) as caught:
            scene.add_mesh(p, bad, name="cube")
        self.assertEqual(str(caught.exception),
                         "mesh 'cube': triangle 3 uses position 99, but there are 8")
        with self.assertRaises(ValueError):
            scene.add_mesh(p[:, :2], t)
        with self.assertRaises(toonray.Error):
            scene.add_mesh(p, t, materials=np.ones(12, dtype=np.uint32))  # no material 1 yet
        scene.add_object(p, t)
        with self.assertRaises(toonray.LimitError) as caught:
            toonray.render(scene, 32, 32, {"limits.triangles": "10"})
        self.assertEqual(str(caught.exception), "the scene has 12 triangles, more than the limit "
                                                "of 10 (limits.triangles raises it)")
        self.assertEqual(caught.exception.setting, "limits.triangles")
        with self.assertRaises(toonray.LimitError):
            toonray.render(scene, 100, 100, {"limits.image_pixels": "9999"})
        # The limits are the settings', for each render: the next one is not limited.
        toonray.render(scene, 32, 32)

    def test_limits_count_an_instanced_mesh_once(self):
        scene = toonray.Scene()
        p, t = cube()
        mesh = scene.add_mesh(p, t)
        for i in range(10):
            scene.add_instance(mesh, translation(2 * i, 0, 0))
        self.assertEqual(scene.instanced_triangle_count, 120)
        frame = toonray.render(scene, 96, 32, {"limits.triangles": "12"})
        self.assertEqual(len(np.unique(frame.object_ids)), 11)  # 10 cubes and the background
        scene.add_object(p, t)
        with self.assertRaises(toonray.LimitError) as caught:
            toonray.render(scene, 96, 32, {"limits.triangles": "12"})
        self.assertEqual(str(caught.exception), "the scene has 24 triangles, more than the limit "
                                                "of 12 (limits.triangles raises it)")


class ProgressAndCancel(unittest.TestCase):
    def big_scene(self):
        with TempDir() as d:
            scene = toonray.load(write_scene(d))
        return scene

    def test_progress_reaches_one_and_false_cancels(self):
        scene = self.big_scene()
        seen = []
        settings = {"sampling.samples": 16, "sampling.adaptive": False, "sampling.tile_size": 8,
                    "render.threads": 1}
        toonray.render(scene, 1280, 960, settings, progress=lambda f: seen.append(f))
        self.assertEqual(seen[-1], 1.0)
        self.assertEqual(seen, sorted(seen))
        self.assertGreater(len(seen), 2, "the callback is called while the frame renders")
        calls = []

        def stop(fraction):
            calls.append(fraction)
            return False

        start = time.monotonic()
        with self.assertRaises(toonray.Cancelled):
            toonray.render(scene, 640, 480, settings, progress=stop)
        self.assertEqual(len(calls), 1)
        self.assertLess(time.monotonic() - start, 1.0)

    def test_cancel_from_another_thread_and_the_next_frame_is_whole(self):
        scene = self.big_scene()
        # The frame of the test above, which reports progress more than twice: the cancel comes
        # from another thread while the frame is known to be rendering, whatever the machine's
        # speed.
        settings = {"sampling.samples": 16, "sampling.adaptive": False, "sampling.tile_size": 8,
                    "render.threads": 1}
        renderer = toonray.Renderer()
        cancels = []

        def cancel_from_another_thread(fraction):
            if fraction < 1.0 and not cancels:
                canceller = threading.Thread(target=renderer.cancel)
                canceller.start()
                canceller.join()
                cancels.append(fraction)

        with self.assertRaises(toonray.Cancelled):
            renderer.render(scene, 1280, 960, settings, progress=cancel_from_another_thread)
        self.assertEqual(len(cancels), 1)
        small = {"lines.mode": "robust"}
        self.assertEqual(renderer.render(scene, 96, 64, small).png(),
                         toonray.Renderer().render(scene, 96, 64, small).png())

    def test_an_exception_in_the_callback_cancels_and_is_raised(self):
        scene = self.big_scene()

        def fail(fraction):
            raise KeyError("from the callback")

        with self.assertRaises(KeyError):
            toonray.render(scene, 640, 480, {"sampling.samples": 16, "sampling.adaptive": False},
                           progress=fail)

    def test_the_gil_is_released_while_rendering(self):
        scene = self.big_scene()
        ticks = []
        done = threading.Event()

        def count():
            while not done.is_set():
                ticks.append(1)
                time.sleep(0.001)

        counter = threading.Thread(target=count)
        counter.start()
        try:
            before = len(ticks)
            toonray.render(scene, 640, 480, {"sampling.samples": 16, "sampling.adaptive": False})
            during = len(ticks) - before
        finally:
            done.set()
            counter.join()
        self.assertGreater(during, 10)

    def test_a_scene_being_rendered_cannot_change(self):
        scene = self.big_scene()
        errors = []

        def change(fraction):
            try:
                scene.add_object(*cube())
            except ValueError as e:
                errors.append(str(e))

        toonray.render(scene, 320, 240, {"sampling.samples": 16, "sampling.adaptive": False},
                       progress=change)
        self.assertTrue(errors)
        self.assertIn("being rendered", errors[0])


if __name__ == "__main__":
    unittest.main()
