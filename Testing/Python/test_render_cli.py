"""penumbra-render end to end, headless: the default scene renders with visible shadows."""

import os
import tempfile
import unittest

import penumbra
from vtkmodules.vtkCommonDataModel import vtkImageData

from penumbra_testing import SCENES_DIR, image_luminance, run_render

GENERATED_BEGIN = "<!-- BEGIN technique options -->"
GENERATED_END = "<!-- END technique options -->"


def read_png(path):
    image = vtkImageData()
    io = penumbra.vtkPenumbraImageIO()
    if not io.Read(path, image):
        raise AssertionError(io.GetErrorMessage())
    return image


class RenderCliTest(unittest.TestCase):
    def render(self, tmp, technique):
        out = os.path.join(tmp, technique + ".png")
        code, stdout, stderr = run_render(os.path.join(SCENES_DIR, "default.json"), "-o", out,
                                          "--size", "160x120", "--technique", technique)
        self.assertEqual(code, 0, stderr)
        for phase in ("load", "setup", "first", "frame", "write", "total"):
            self.assertRegex(stdout, r"(?m)^%s\s+[0-9.]+ ms" % phase)
        image = read_png(out)
        self.assertEqual(image.GetDimensions()[:2], (160, 120))
        return image_luminance(image)

    def test_default_scene_has_shadows(self):
        with tempfile.TemporaryDirectory() as tmp:
            lit = self.render(tmp, "none")
            for technique in ("raytraced", "vtk-shadowmap"):
                with self.subTest(technique=technique):
                    shadowed = self.render(tmp, technique)
                    pixels = [(a, b) for ra, rb in zip(lit, shadowed) for a, b in zip(ra, rb)]
                    # Not blank: the scene covers most of the frame with varied shading.
                    values = sorted(a for a, _ in pixels)
                    self.assertGreater(values[int(0.9 * len(values))] - values[int(0.1 * len(values))], 30)
                    # Shadows only ever darken, and they darken a real part of the image.
                    darker = sum(1 for a, b in pixels if b < a - 25)
                    brighter = sum(1 for a, b in pixels if b > a + 25)
                    self.assertGreater(darker, 0.03 * len(pixels), "too few shadowed pixels")
                    self.assertLess(brighter, 0.002 * len(pixels), "shadowing must not brighten pixels")

    def test_showcase_is_what_users_see_first(self):
        """`./penumbra.sh render` renders showcase.json: coloured, hard and soft shadows
        (raytraced for the sun, gears for the sphere light), FXAA on edges and shadow edges."""
        import json
        scene = os.path.join(SCENES_DIR, "showcase.json")
        with tempfile.TemporaryDirectory() as tmp:
            smooth = os.path.join(tmp, "fxaa.png")
            code, stdout, stderr = run_render(scene, "-o", smooth, "--size", "320x180",
                                              "--explain")
            self.assertEqual(code, 0, stderr)
            self.assertRegex(stdout, r"light 0 \(directional light\): raytraced")
            self.assertRegex(stdout, r"light 1 \(disc light of diameter 6, 52 samples\): gears")
            with open(scene) as f:
                plain_scene = json.load(f)
            self.assertEqual(plain_scene["image"]["antialiasing"], "fxaa")
            plain_scene["image"]["antialiasing"] = "none"
            plain_path = os.path.join(tmp, "showcase_none.json")  # generators only: no paths
            plain = os.path.join(tmp, "none.png")
            with open(plain_path, "w") as f:
                json.dump(plain_scene, f)
            code, _, stderr = run_render(plain_path, "-o", plain, "--size", "320x180")
            self.assertEqual(code, 0, stderr)
            a, b = read_png(smooth), read_png(plain)
            sa, sb = a.GetPointData().GetScalars(), b.GetPointData().GetScalars()
            n = sa.GetNumberOfTuples()
            colours = {tuple(sa.GetTuple(i)[:3]) for i in range(n)}
            channels = [[sa.GetTuple(i)[c] for i in range(n)] for c in range(3)]
            # Coloured: the channels differ (not a grey image).
            self.assertGreater(sum(abs(r - g) + abs(g - bl) for r, g, bl in zip(*channels)) / n, 10)
            # FXAA blends edge pixels: a share of the frame changes, the rest does not.
            changed = sum(1 for i in range(n) if sa.GetTuple(i)[:3] != sb.GetTuple(i)[:3])
            self.assertGreater(changed, 0.005 * n)
            self.assertLess(changed, 0.5 * n)
            self.assertGreater(len(colours), 500)

    def test_baseline_check(self):
        scene = os.path.join(SCENES_DIR, "default.json")
        with tempfile.TemporaryDirectory() as tmp:
            ref = os.path.join(tmp, "ref.png")
            out = os.path.join(tmp, "out.png")
            common = ("--size", "96x72", "--technique", "raytraced")
            code, _, stderr = run_render(scene, "-o", ref, *common)
            self.assertEqual(code, 0, stderr)
            # The exact technique reproduces its own baseline.
            code, stdout, stderr = run_render(scene, "-o", out, *common, "--baseline", ref)
            self.assertEqual(code, 0, stderr)
            self.assertIn("matches " + ref, stdout)
            # Without shadows the image differs: exit 1, one line, a difference image.
            code, _, stderr = run_render(scene, "-o", out, "--size", "96x72", "--technique", "none",
                                         "--baseline", ref, "--threshold", "0.1")
            self.assertEqual(code, 1)
            lines = [l for l in stderr.splitlines() if l.strip()]
            self.assertEqual(len(lines), 1, stderr)
            self.assertIn("differs from " + ref, lines[0])
            self.assertIn("difference image: " + os.path.join(tmp, "out.diff.png"), lines[0])
            self.assertTrue(os.path.exists(os.path.join(tmp, "out.diff.png")))
            # A large enough allowance accepts the same difference.
            code, _, stderr = run_render(scene, "-o", out, "--size", "96x72", "--technique", "none",
                                         "--baseline", ref, "--threshold", "0.1", "--fail-percent", "100")
            self.assertEqual(code, 0, stderr)
            # Size mismatch: a failure that says why.
            code, _, stderr = run_render(scene, "-o", out, "--size", "64x48", "--technique", "raytraced",
                                         "--baseline", ref)
            self.assertEqual(code, 1)
            self.assertIn("is 64x48", stderr)
            # The Python helper gives the same verdicts.
            matches, message = penumbra.compare_images(ref, ref)
            self.assertTrue(matches, message)
            with self.assertRaises(ValueError):
                penumbra.compare_images(out, ref)
            for args, fragment in (((scene, "-o", out, "--baseline", os.path.join(tmp, "nope.png")), "not found"),
                                   ((scene, "-o", out, "--threshold", "0.1"), "need --baseline"),
                                   ((scene, "-o", out, "--baseline", ref, "--threshold", "2"), "--threshold")):
                with self.subTest(args=args[3:]):
                    code, _, stderr = run_render(*args)
                    self.assertEqual(code, 2)
                    self.assertIn(fragment, stderr)

    def test_forced_x_window_without_display_fails_clearly(self):
        with tempfile.TemporaryDirectory() as tmp:
            out = os.path.join(tmp, "x.png")
            code, _, stderr = run_render(os.path.join(SCENES_DIR, "default.json"), "-o", out,
                                         env={"PENUMBRA_HEADLESS": "0"})
            self.assertEqual(code, 3)
            self.assertIn("no X display", stderr)
            self.assertFalse(os.path.exists(out))

    def test_size_and_technique_arguments_are_checked(self):
        with tempfile.TemporaryDirectory() as tmp:
            out = os.path.join(tmp, "x.png")
            scene = os.path.join(SCENES_DIR, "default.json")
            for args, fragment in (((scene, "-o", out, "--size", "0x10"), "--size"),
                                   ((scene, "-o", out, "--technique", "nope"), "unknown technique"),
                                   ((scene,), "no output file"),
                                   ((scene, "-o", out, "--option", "resolution=-3"), "resolution")):
                with self.subTest(args=args[1:]):
                    code, _, stderr = run_render(*args)
                    self.assertEqual(code, 2)
                    self.assertIn(fragment, stderr)
                    self.assertFalse(os.path.exists(out))

    def test_schema_options_match_the_option_tables(self):
        # SCHEMA.md's technique section is generated from the registry's option tables; a
        # change to a table must come with `penumbra-render --options-markdown` pasted in.
        code, generated, stderr = run_render("--options-markdown")
        self.assertEqual(code, 0, stderr)
        with open(os.path.join(SCENES_DIR, "SCHEMA.md"), encoding="utf-8") as f:
            schema = f.read()
        begin = schema.index(GENERATED_BEGIN) + len(GENERATED_BEGIN) + 1
        end = schema.index(GENERATED_END)
        self.assertEqual(schema[begin:end], generated,
                         "Data/Scenes/SCHEMA.md is out of date: replace the text between the "
                         "markers with the output of `penumbra-render --options-markdown`")

    def test_list_techniques_shows_every_option(self):
        code, listing, stderr = run_render("--list-techniques")
        self.assertEqual(code, 0, stderr)
        t = penumbra.vtkPenumbraTechniques
        for index in range(t.GetNumberOfTechniques()):
            name = t.GetTechniqueName(index)
            self.assertIn(name + "\t" + t.GetTechniqueDescription(index), listing)
            for option in penumbra.technique_options(name):
                self.assertIn("    %s (%s; default " % (option["name"], option["type"]), listing)
                self.assertIn(option["doc"], listing)
                self.assertIn(option["doc"], penumbra.enable_shadows.__doc__)

    def test_explain_and_auto_by_default(self):
        # A scene without a technique block gets auto; --explain says per light what shadowed
        # it and why.
        with tempfile.TemporaryDirectory() as tmp:
            out = os.path.join(tmp, "x.png")
            code, stdout, stderr = run_render(os.path.join(SCENES_DIR, "mixed_lights.json"), "-o",
                                              out, "--size", "96x72", "--explain")
            self.assertEqual(code, 0, stderr)
            self.assertEqual(stderr, "")
            self.assertIn("technique auto)", stdout)
            self.assertIn("explain    technique auto", stdout)
            self.assertIn("light 0 (directional light): raytraced - hard light", stdout)
            self.assertIn("light 1 (point light): raytraced - hard light", stdout)
            self.assertIn("light 2 (area light, 8x8 samples): gears - soft light at k = 8", stdout)
            self.assertIn("skipped lights: 0; lights off: 0", stdout)

    def test_messages_are_sentences_said_once(self):
        # What a new user tripped over: a light a technique cannot shadow is said once, as a
        # sentence naming the light and what was done, never with VTK's "In file, line N".
        with tempfile.TemporaryDirectory() as tmp:
            out = os.path.join(tmp, "x.png")
            for scene, technique, fragment in (
                    ("mixed_lights.json", "conservative",
                     "penumbra-render: warning: Light 2 (area light, 8x8 samples): conservative "
                     "cannot shadow it; shadowed by gears instead"),
                    ("room_point_light.json", "vtk-shadowmap",
                     "penumbra-render: warning: Light 0 gets no shadow from vtk-shadowmap: VTK's "
                     "vtkShadowMapPass shadows only directional lights and spot lights")):
                with self.subTest(technique=technique):
                    code, _, stderr = run_render(os.path.join(SCENES_DIR, scene), "-o", out,
                                                 "--size", "96x72", "--technique", technique)
                    self.assertEqual(code, 0, stderr)
                    self.assertIn(fragment, stderr)
                    self.assertEqual(stderr.count(fragment), 1, stderr)
                    self.assertNotRegex(stderr, r"\.cxx|line [0-9]|0x[0-9a-f]{6}|WARN\|")


if __name__ == "__main__":
    unittest.main()
