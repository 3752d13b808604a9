"""Scene files: every shipped scene loads; each kind of bad input gives its own clear error,
a non-zero exit and no output file."""

import glob
import json
import math
import os
import tempfile
import time
import unittest

import penumbra

from penumbra_testing import BAD_SCENES_DIR, SCENES_DIR, run_render

# file -> fragment the one error line must contain (field and problem).
BAD_SCENES = {
    "missing_file.json": "objects[0].file: file not found",
    "nan_literal.json": "invalid JSON",
    "nan_mesh.json": "objects[0].file: reading",
    "negative_size.json": "lights[0].size: area light size must be positive",
    "zero_size_light.json": "lights[0].length: linear light length must be positive",
    "negative_light_radius.json": "lights[0].radius: light radius must be a finite length >= 0",
    "zero_disc_radius.json": "lights[0].radius: disc light radius must be positive",
    "bad_antialiasing.json": 'image.antialiasing: expected "none" or "fxaa", got "msaa"',
    "unknown_light.json": 'lights[0].type: unknown light type "sun"',
    "unknown_key.json": "objects[0].colour: unknown key",
    "empty_scene.json": "objects: the scene is empty",
    "no_lights.json": "lights: missing",
    "infinite_value.json": "invalid JSON: number overflow parsing '1e999'",
    "not_json.json": "invalid JSON",
    "unknown_technique.json": 'unknown technique "magic"',
    "bad_technique_option.json": "technique: resolution: expected an integer",
    "unknown_generator.json": 'objects[0].generator.type: unknown generator "teapot"',
    "spot_cone_too_wide.json": "lights[0].cone_angle",
    # Hostile mesh files, refused before VTK's readers see them.
    "truncated_ply.json": "binary PLY ends inside element \"vertex\"",
    "obj_missing_vertex.json": "OBJ line 6: vertex 7 does not exist (the file has 3)",
    "ply_bad_face_index.json": "vertex index 9 is outside the 3 vertices",
    "too_many_lights.json": "lights: 33 lights, at most 32 are allowed",
}


class SceneFilesTest(unittest.TestCase):
    def test_every_example_scene_loads(self):
        scenes = sorted(glob.glob(os.path.join(SCENES_DIR, "*.json")))
        self.assertGreaterEqual(len(scenes), 10)
        for path in scenes:
            with self.subTest(scene=os.path.basename(path)):
                reader = penumbra.load_scene(path)
                self.assertGreater(reader.GetNumberOfObjects(), 0)
                self.assertTrue(penumbra.vtkPenumbraTechniques.HasTechnique(reader.GetTechniqueName()))
                ren = reader.GetRenderer()
                self.assertGreater(ren.GetLights().GetNumberOfItems(), 0)
                bounds = ren.ComputeVisiblePropBounds()
                self.assertTrue(all(math.isfinite(b) for b in bounds))
                self.assertLess(bounds[0], bounds[1])

    def test_every_bad_scene_is_covered(self):
        shipped = {os.path.basename(p) for p in glob.glob(os.path.join(BAD_SCENES_DIR, "*.json"))}
        self.assertEqual(shipped, set(BAD_SCENES))

    def test_bad_scenes_fail_clearly_without_output(self):
        with tempfile.TemporaryDirectory() as tmp:
            for name, fragment in sorted(BAD_SCENES.items()):
                with self.subTest(scene=name):
                    out = os.path.join(tmp, name + ".png")
                    code, stdout, stderr = run_render(os.path.join(BAD_SCENES_DIR, name), "-o", out)
                    self.assertEqual(code, 2, stderr)
                    lines = [l for l in stderr.splitlines() if l.strip()]
                    self.assertEqual(len(lines), 1, "exactly one error line expected:\n" + stderr)
                    self.assertIn(name, lines[0], "the message names the file")
                    self.assertIn(fragment, lines[0])
                    self.assertFalse(os.path.exists(out), "no output file on error")
            self.assertEqual(os.listdir(tmp), [], "no partial files left behind")

    def test_thousands_of_lights_are_refused_at_once(self):
        lights = ",".join('{"type": "point", "position": [%d, 0, 5]}' % i for i in range(3000))
        text = '{"objects": [{"generator": {"type": "plane"}}], "lights": [%s]}' % lights
        reader = penumbra.vtkPenumbraSceneReader()
        reader.AddObserver("ErrorEvent", lambda *a: None)
        start = time.monotonic()
        self.assertEqual(reader.ReadFromString(text, "inline", ""), 0)
        self.assertLess(time.monotonic() - start, 5.0)
        self.assertIn("lights: 3000 lights, at most %d are allowed"
                      % penumbra.vtkPenumbraSceneReader.MaximumNumberOfLights, reader.GetErrorMessage())

    def test_reader_reports_without_raising(self):
        reader = penumbra.vtkPenumbraSceneReader()
        reader.AddObserver("ErrorEvent", lambda *a: None)
        self.assertEqual(reader.ReadFromString('{"objects": 3}', "inline", ""), 0)
        self.assertIn("inline: objects: missing", reader.GetErrorMessage())
        self.assertIsNone(reader.GetRenderer())

    def test_loaded_scene_details(self):
        text = """{
          "objects": [
            {"name": "a", "generator": {"type": "box", "bounds": [0, 1, 0, 1, 0, 1]},
             "transform": {"scale": 2, "rotate": [90, 0, 0, 1], "translate": [10, 0, 0]},
             "cast_shadows": false, "material": {"model": "pbr", "roughness": 0.25}},
            {"name": "b", "generator": {"type": "plane"}, "receive_shadows": false}
          ],
          "lights": [
            {"type": "area", "position": [0, 0, 5], "normal": [0, 0, -1], "size": [2, 1],
             "up": [0, 1, 0], "samples": 4},
            {"type": "directional", "direction": [0, 0, -1], "on": false}
          ],
          "image": {"width": 320, "height": 200, "antialiasing": "fxaa"},
          "technique": {"name": "none"}
        }"""
        reader = penumbra.vtkPenumbraSceneReader()
        self.assertEqual(reader.ReadFromString(text, "inline", ""), 1, reader.GetErrorMessage())
        self.assertEqual((reader.GetWidth(), reader.GetHeight()), (320, 200))
        self.assertTrue(reader.GetRenderer().GetUseFXAA())
        a = reader.GetObjectActor(0)
        b = reader.GetObjectActor(1)
        # scale 2, then 90 degrees about z, then translate: (1, 0, 0) -> (10, 2, 0).
        m = a.GetMatrix()
        p = [sum(m.GetElement(r, c) * v for c, v in enumerate((1, 0, 0, 1))) for r in range(3)]
        for got, want in zip(p, (10, 2, 0)):
            self.assertAlmostEqual(got, want, places=9)
        self.assertFalse(penumbra.vtkPenumbraShadowKeys.CastsShadows(a))
        self.assertTrue(penumbra.vtkPenumbraShadowKeys.ReceivesShadows(a))
        self.assertTrue(penumbra.vtkPenumbraShadowKeys.CastsShadows(b))
        self.assertFalse(penumbra.vtkPenumbraShadowKeys.ReceivesShadows(b))
        self.assertEqual(a.GetProperty().GetInterpolationAsString(), "Physically based rendering")
        lights = reader.GetRenderer().GetLights()
        area = lights.GetItemAsObject(0)
        self.assertIsInstance(area, penumbra.vtkPenumbraAreaLight)
        self.assertEqual(area.GetNumberOfSamples(), 16)
        # U = V x N with V = up = +y and N = -z gives U = -x; sample 0 is the (-,-) corner cell.
        pos = [0.0, 0.0, 0.0]
        self.assertTrue(area.GetSamplePosition(0, pos))
        for got, want in zip(pos, (0.75, -0.375, 5.0)):
            self.assertAlmostEqual(got, want, places=12)
        self.assertFalse(area.GetSamplePosition(16, pos))
        self.assertEqual(lights.GetItemAsObject(1).GetSwitch(), 0)

    def test_distributed_block(self):
        """How MPI ranks share their casters: read and checked like every other block."""
        base = ('{"objects": [{"generator": {"type": "plane"}}], '
                '"lights": [{"type": "directional"}]%s}')
        reader = penumbra.vtkPenumbraSceneReader()
        reader.AddObserver("ErrorEvent", lambda *a: None)
        self.assertEqual(reader.ReadFromString(base % "", "inline", ""), 1)
        self.assertEqual((reader.GetCasterExchange(), reader.GetCasterMemoryBudget()), ("need", 0))
        good = ', "distributed": {"caster_exchange": "distributed", "memory_budget": 512.5}'
        self.assertEqual(reader.ReadFromString(base % good, "inline", ""), 1,
                         reader.GetErrorMessage())
        self.assertEqual(reader.GetCasterExchange(), "distributed")
        self.assertEqual(reader.GetCasterMemoryBudget(), 512.5)
        for block, message in (
                ('"distributed": 3', "distributed: expected an object"),
                ('"distributed": {"caster_exchange": "some"}',
                 'distributed.caster_exchange: expected "need", "distributed" or "all", got "some"'),
                ('"distributed": {"memory_budget": -1}',
                 "distributed.memory_budget: must be 0 (no budget) or a positive number"),
                ('"distributed": {"memory_budget": "1 GB"}',
                 "distributed.memory_budget: expected a number"),
                ('"distributed": {"budget": 1}', "distributed.budget: unknown key")):
            with self.subTest(block=block):
                self.assertEqual(reader.ReadFromString(base % (", " + block), "inline", ""), 0)
                self.assertIn("inline: " + message, reader.GetErrorMessage())
        # The settings alone (for a ParaView view): no objects needed, the blocks still checked.
        reader.SettingsOnlyOn()
        settings = ('{"technique": {"name": "shadowmap", "resolution": 512}, '
                    '"distributed": {"caster_exchange": "all"}}')
        self.assertEqual(reader.ReadFromString(settings, "inline", ""), 1, reader.GetErrorMessage())
        self.assertIsNone(reader.GetRenderer())
        self.assertEqual((reader.GetTechniqueName(), reader.GetCasterExchange()),
                         ("shadowmap", "all"))
        self.assertEqual(reader.GetTechniqueOptions(), '{"resolution":512}')
        self.assertEqual(reader.ReadFromString('{"distributed": {"memory_budget": -2}}',
                                               "inline", ""), 0)
        self.assertIn("inline: distributed.memory_budget", reader.GetErrorMessage())
        self.assertEqual(reader.ReadFromString('{"lighting": 1}', "inline", ""), 0)
        self.assertIn("inline: lighting: unknown key", reader.GetErrorMessage())

    def test_disc_and_sphere_lights(self):
        text = """{
          "objects": [{"generator": {"type": "plane"}}],
          "lights": [
            {"type": "disc", "position": [1, 2, 5], "focal_point": [1, 2, 0], "radius": 0.5,
             "samples": 8},
            {"type": "point", "position": [0, 0, 4], "radius": 0.25},
            {"type": "spot", "position": [0, 0, 4], "focal_point": [0, 0, 0]}
          ]
        }"""
        reader = penumbra.vtkPenumbraSceneReader()
        self.assertEqual(reader.ReadFromString(text, "inline", ""), 1, reader.GetErrorMessage())
        lights = reader.GetRenderer().GetLights()
        disc = lights.GetItemAsObject(0)
        self.assertIsInstance(disc, penumbra.vtkPenumbraAreaLight)
        self.assertEqual(disc.GetShapeAsString(), "Disc")
        self.assertEqual(disc.GetWidth(), 1.0)
        # The cells of the 8 x 8 grid whose centre lies inside the disc; every sample on it.
        self.assertEqual(disc.GetNumberOfSamples(), 52)
        for j in range(52):
            p = [0.0, 0.0, 0.0]
            self.assertTrue(disc.GetSamplePosition(j, p))
            self.assertLessEqual(math.hypot(p[0] - 1, p[1] - 2), 0.5)
            self.assertAlmostEqual(p[2], 5.0, places=12)
        keys = penumbra.vtkPenumbraShadowKeys
        self.assertEqual(keys.GetLightRadius(lights.GetItemAsObject(1)), 0.25)
        self.assertEqual(keys.GetLightRadius(lights.GetItemAsObject(2)), 0.0)
        # The pass's stand-in for the point light: the disc of that radius facing down.
        stand_in = penumbra.vtkPenumbraAreaLight()
        self.assertTrue(stand_in.SetFromLightRadius(lights.GetItemAsObject(1), 0.25))
        self.assertEqual((stand_in.GetShape(), stand_in.GetWidth()), (stand_in.Disc, 0.5))
        u, v, n = [0.0] * 3, [0.0] * 3, [0.0] * 3
        self.assertTrue(stand_in.GetAxes(u, v, n))
        self.assertEqual(n, [0.0, 0.0, -1.0])
        self.assertFalse(stand_in.SetFromLightRadius(lights.GetItemAsObject(1), 0.0))


if __name__ == "__main__":
    unittest.main()


class SceneUpAxisTest(unittest.TestCase):
    """A scene's "up" axis turns the sun's elevation and azimuth (and the default camera):
    the z-up convention rotated by the shortest turn taking +z to up."""

    def sun_direction(self, up, elevation, azimuth):
        scene = {"objects": [{"generator": {"type": "city_block"}}],
                 "lights": [{"type": "directional", "elevation": elevation, "azimuth": azimuth}]}
        if up is not None:
            scene["up"] = up
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "scene.json")
            with open(path, "w") as f:
                json.dump(scene, f)
            reader = penumbra.load_scene(path)
        light = reader.GetRenderer().GetLights().GetItemAsObject(0)
        # Position - focal point points toward the sun.
        p, f = light.GetPosition(), light.GetFocalPoint()
        toward = [p[i] - f[i] for i in range(3)]
        norm = math.sqrt(sum(c * c for c in toward))
        return [c / norm for c in toward], reader

    def assertDirection(self, got, expected):
        for g, e in zip(got, expected):
            self.assertAlmostEqual(g, e, places=9, msg=(got, expected))

    def test_default_is_z_up(self):
        self.assertDirection(self.sun_direction(None, 90, 0)[0], [0, 0, 1])
        self.assertDirection(self.sun_direction(None, 0, 0)[0], [0, 1, 0])   # north
        self.assertDirection(self.sun_direction(None, 0, 90)[0], [1, 0, 0])  # east

    def test_y_up(self):
        for up in ("y", [0, 1, 0], [0, 5, 0]):
            with self.subTest(up=up):
                self.assertDirection(self.sun_direction(up, 90, 0)[0], [0, 1, 0])
                self.assertDirection(self.sun_direction(up, 0, 0)[0], [0, 0, -1])  # north: -z
                self.assertDirection(self.sun_direction(up, 0, 90)[0], [1, 0, 0])  # east: +x
        # The automatic camera looks with the scene's up.
        _, reader = self.sun_direction("y", 45, 135)
        up = reader.GetRenderer().GetActiveCamera().GetViewUp()
        self.assertEqual(max(range(3), key=lambda i: abs(up[i])), 1, up)
        self.assertGreater(up[1], 0.5)

    def test_other_axes(self):
        self.assertDirection(self.sun_direction("-z", 90, 0)[0], [0, 0, -1])
        self.assertDirection(self.sun_direction("x", 90, 0)[0], [1, 0, 0])
        self.assertDirection(self.sun_direction("-y", 90, 0)[0], [0, -1, 0])

    def test_bad_up_is_refused(self):
        for up, message in (("w", "up: expected"), ([0, 0, 0], "up: must be a non-zero vector"),
                            ([1, 2], "up")):
            with self.subTest(up=up), tempfile.TemporaryDirectory() as d:
                path = os.path.join(d, "scene.json")
                with open(path, "w") as f:
                    json.dump({"up": up, "objects": [{"generator": {"type": "city_block"}}],
                               "lights": [{"type": "directional"}]}, f)
                with self.assertRaises(ValueError) as caught:
                    penumbra.load_scene(path)
                self.assertIn(message, str(caught.exception))
