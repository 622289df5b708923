"""The settings document from Python: the same keys, values, rules and messages as the TOML
document and the command line (frame/settings.h)."""

import os
import pathlib
import unittest

import toonray
from support import TempDir


class SettingsDocument(unittest.TestCase):
    def test_keys_defaults_and_values(self):
        keys = toonray.setting_keys()
        by_key = {k["key"]: k for k in keys}
        self.assertEqual(by_key["lines.width"]["flag"], "--line-width")
        self.assertEqual(by_key["lines.width"]["default"], 2.0)
        self.assertEqual(by_key["sampling.samples"]["default"], 4)
        self.assertIsNone(by_key["scene.auto_smooth"]["default"])
        self.assertFalse(by_key["render.threads"]["picture"])
        values = toonray.settings({"lines.width": 3, "shading": {"shadows": True},
                                   "lines.colour": (1, 0, 0.5)})
        self.assertEqual(values["lines.width"], 3.0)
        self.assertIs(values["shading.shadows"], True)
        self.assertEqual(values["lines.colour"], "1,0,0.5")
        self.assertEqual(values["lines.rule"], [])
        self.assertEqual(toonray.settings()["lines.mode"], "ink")
        self.assertEqual(toonray.LINE_MODES, ["ink", "robust", "classic"])
        self.assertEqual(toonray.LINE_TYPES, ["silhouette", "crease", "depth", "object", "material"])
        self.assertEqual(toonray.line_layers("classic"), ["depth", "normal"])
        self.assertIn("border", toonray.line_layers("ink"))
        self.assertIn("object", toonray.line_rule_keys())

    def test_rules_round_trip_through_toml(self):
        document = {"lines.rule": [{"object": "w*", "lines": "hidden", "draw": True,
                                    "width": 1.5, "dash": [4, 2], "color": "#808080"}]}
        rules = toonray.settings(document)["lines.rule"]
        self.assertEqual(rules, [{"object": "w*", "lines": "hidden", "draw": "yes",
                                  "color": "#808080", "width": "1.5", "dash": "4,2"}])
        with TempDir() as d:
            path = os.path.join(d, "s.toml")
            with open(path, "w") as f:
                f.write(toonray.settings_toml(document))
            self.assertEqual(toonray.settings(pathlib.Path(path)), toonray.settings(document))

    def test_messages_name_the_key(self):
        def error(document):
            with self.assertRaises(toonray.Error) as caught:
                toonray.settings(document)
            return str(caught.exception)

        self.assertEqual(error({"lines.widht": 2}), "unknown key 'lines.widht'")
        self.assertEqual(error({"lines": {"width": "thick"}}),
                         "lines.width: expected a number, got 'thick'")
        self.assertEqual(error({"sampling.samples": 5}),
                         "sampling.samples: 5 samples per pixel: must be 1, 4, 9 or 16 (a square "
                         "grid per pixel)")
        self.assertEqual(error({"lines": 3}), "unknown key 'lines'")
        # What no single key can say (check_settings), named by the key.
        self.assertTrue(error({"lines.types": "depth"}).startswith(
            "lines.types: the ink mode finds no depth lines"))
        self.assertEqual(error({"lines.rule": [{"width": "x"}]}),
                         "lines.rule[1].width: expected a number, got 'x'")
        with self.assertRaises(TypeError):
            toonray.settings(42)


if __name__ == "__main__":
    unittest.main()
