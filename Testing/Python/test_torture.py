"""Torture scenes: each loads, renders headless with the exact technique, and behaves as its
extreme case demands."""

import glob
import math
import os
import tempfile
import unittest

import penumbra
from vtkmodules.vtkRenderingCore import vtkLight, vtkRenderWindow

from penumbra_testing import SCENES_DIR, run_render

TORTURE_DIR = os.path.join(SCENES_DIR, "torture")


def render_with_pass(path, size=(96, 72), technique="raytraced"):
    reader = penumbra.load_scene(path)
    ren = reader.GetRenderer()
    techniques = penumbra.vtkPenumbraTechniques()
    assert techniques.Apply(ren, technique, "{}"), techniques.GetErrorMessage()
    win = vtkRenderWindow()
    win.SetSize(*size)
    win.SetMultiSamples(0)
    win.AddRenderer(ren)
    win.Render()
    return reader, ren, win, ren.GetPass().GetDelegatePass()


def values(array):
    return [array.GetValue(i) for i in range(array.GetNumberOfTuples())]


class TortureTest(unittest.TestCase):
    def test_every_torture_scene_renders(self):
        scenes = sorted(glob.glob(os.path.join(TORTURE_DIR, "*.json")))
        self.assertGreaterEqual(len(scenes), 12)
        with tempfile.TemporaryDirectory() as tmp:
            for path in scenes:
                with self.subTest(scene=os.path.basename(path)):
                    out = os.path.join(tmp, "x.png")
                    code, _, stderr = run_render(path, "-o", out, "--size", "64x48")
                    self.assertEqual(code, 0, stderr)
                    self.assertTrue(os.path.exists(out))

    def test_georeferenced_scenes_shadow_like_the_local_one(self):
        # The same block at 0, 1e6 and 1e7 m offsets: the fraction of shadowed samples must not
        # depend on where the world origin is.
        fractions = []
        for name in ("georef_1e6.json", "georef_1e7.json"):
            _, _, _, shadow = render_with_pass(os.path.join(TORTURE_DIR, name))
            vis = [v for v in values(shadow.GetVisibility(0)) if v >= 0]
            self.assertGreater(len(vis), 1000)
            fractions.append(sum(1 for v in vis if v == 0.0) / len(vis))
        self.assertGreater(fractions[0], 0.02)
        self.assertAlmostEqual(fractions[0], fractions[1], delta=0.01)

    def test_tiny_area_light_equals_point_light(self):
        # A 1e-6 m rectangle, and a 1e-6 m sphere light (shadowed as its disc).
        for name in ("tiny_area_light.json", "tiny_sphere_light.json"):
            with self.subTest(scene=name):
                _, ren, win, shadow = render_with_pass(os.path.join(TORTURE_DIR, name))
                area = values(shadow.GetVisibility(0))
                area_light = shadow.GetLight(0)  # as shadowed: the sphere light's disc
                self.assertIsInstance(area_light, penumbra.vtkPenumbraAreaLight)
                point = vtkLight()
                point.SetLightTypeToSceneLight()
                point.SetPositional(True)
                point.SetConeAngle(180)
                point.SetPosition(area_light.GetPosition())
                ren.GetLights().GetItemAsObject(0).SwitchOff()  # the scene's own light
                ren.AddLight(point)
                win.Render()
                hard = values(shadow.GetVisibility(0))
                self.assertEqual(len(area), len(hard))
                differ = sum(1 for a, h in zip(area, hard) if a != h)
                self.assertEqual(differ, 0)
                self.assertGreater(sum(1 for h in hard if h == 0.0), 50)

    def test_huge_area_light_is_smooth_and_finite(self):
        reader, _, _, shadow = render_with_pass(os.path.join(TORTURE_DIR, "huge_area_light.json"))
        samples = shadow.GetViewSamples()
        vis = values(shadow.GetVisibility(0))
        self.assertTrue(all(math.isfinite(v) and -1.0 <= v <= 1.0 for v in vis))
        # On the ground (prop 0) the ball hides a few of the 1 km light's samples at most:
        # a penumbra under it, and no umbra anywhere.
        ground = [v for i, v in enumerate(vis) if samples.GetPropIndices().GetValue(i) == 0]
        self.assertGreater(len(ground), 1000)
        self.assertGreater(min(ground), 0.5)
        self.assertGreater(sum(1 for v in ground if v < 1.0), 10)

    def face_visibility(self, name):
        """The room shell's (prop 0) view samples' visibility per face, faces seen by > 20."""
        reader, ren, win, shadow = render_with_pass(os.path.join(TORTURE_DIR, name),
                                                    size=(160, 120))
        samples = shadow.GetViewSamples()
        vis = shadow.GetVisibility(0)
        origin = samples.GetOrigin()
        faces = {}
        for i in range(samples.GetNumberOfSamples()):
            if samples.GetPropIndices().GetValue(i) < 0:
                continue
            p = [samples.GetPositions().GetComponent(i, c) + origin[c] for c in range(3)]
            n = [samples.GetNormals().GetComponent(i, c) for c in range(3)]
            axis = max(range(3), key=lambda c: abs(n[c]))
            bound = (5.0, 5.0, 4.0 if n[2] < 0 else 0.0)[axis]
            on_shell = abs(abs(p[axis]) - bound) < 1e-3 if axis < 2 else abs(p[2] - bound) < 1e-3
            if on_shell:
                key = (axis, n[axis] > 0)
                faces.setdefault(key, []).append(vis.GetValue(i))
        return {k: v for k, v in faces.items() if len(v) > 20}

    def test_point_light_in_room_shadows_every_face(self):
        # Samples on each of the room's faces must include shadow.
        visible = self.face_visibility("point_light_in_room.json")
        self.assertGreaterEqual(len(visible), 4, visible.keys())
        for face, vals in visible.items():
            self.assertTrue(any(v == 0.0 for v in vals), "no shadow on face %s" % (face,))
            self.assertTrue(any(v == 1.0 for v in vals), "face %s entirely dark" % (face,))

    def test_sphere_light_in_room_has_penumbrae_on_every_face(self):
        # The disc of a sphere light inside the scene shines both ways: the ceiling is lit
        # too, and every face seen has lit samples and penumbrae.
        visible = self.face_visibility("sphere_light_in_room.json")
        self.assertGreaterEqual(len(visible), 4, visible.keys())
        self.assertIn((2, False), visible)  # the ceiling
        for face, vals in visible.items():
            self.assertTrue(any(v == 1.0 for v in vals), "face %s entirely dark" % (face,))
            self.assertGreater(sum(1 for v in vals if 0.0 < v < 1.0), 5,
                               "no penumbra on face %s" % (face,))

    def test_bad_triangles_are_survived(self):
        _, _, _, shadow = render_with_pass(os.path.join(TORTURE_DIR, "bad_triangles.json"))
        geometry = shadow.GetGeometry()
        self.assertGreaterEqual(geometry.GetNumberOfDegenerateTriangles(), 3)
        vis = [v for v in values(shadow.GetVisibility(0)) if v >= 0]
        self.assertGreater(sum(1 for v in vis if v == 0.0), 0)


if __name__ == "__main__":
    unittest.main()
