"""The penumbra Python package: import, headless factory, a scene built in Python, pixels."""

import os
import unittest

import penumbra
from vtkmodules.vtkFiltersSources import vtkCubeSource, vtkPlaneSource
from vtkmodules.vtkRenderingCore import (vtkActor, vtkLight, vtkPolyDataMapper, vtkRenderWindow,
                                         vtkRenderer)

from penumbra_testing import window_luminance

SIZE = 96


def occluder_scene():
    """Unit-ish square occluder at z=1 over a plane at z=0; light travels along (-1, 0, -1).

    Seen from straight above with a parallel camera of scale 2, world (x, y) maps to pixel
    ((x + 2) / 4 * SIZE, (y + 2) / 4 * SIZE); the shadow covers x in [-1.5, -0.5]."""
    ren = vtkRenderer()
    ren.SetBackground(0, 0, 0)
    plane = vtkPlaneSource()
    plane.SetOrigin(-2, -2, 0)
    plane.SetPoint1(2, -2, 0)
    plane.SetPoint2(-2, 2, 0)
    box = vtkCubeSource()
    box.SetBounds(-0.5, 0.5, -0.5, 0.5, 0.98, 1.0)
    for src in (plane, box):
        mapper = vtkPolyDataMapper()
        mapper.SetInputConnection(src.GetOutputPort())
        actor = vtkActor()
        actor.SetMapper(mapper)
        actor.GetProperty().SetAmbient(0.1)
        actor.GetProperty().SetDiffuse(0.9)
        actor.GetProperty().SetSpecular(0.0)
        ren.AddActor(actor)
    light = vtkLight()
    light.SetLightTypeToSceneLight()
    light.SetPositional(False)
    light.SetPosition(1, 0, 1)
    light.SetFocalPoint(0, 0, 0)
    ren.AddLight(light)
    cam = ren.GetActiveCamera()
    cam.ParallelProjectionOn()
    cam.SetPosition(0, 0, 10)
    cam.SetFocalPoint(0, 0, 0)
    cam.SetViewUp(0, 1, 0)
    cam.SetParallelScale(2.0)
    ren.ResetCameraClippingRange()
    return ren


def pixel(x, y):
    return int((x + 2.0) / 4.0 * SIZE), int((y + 2.0) / 4.0 * SIZE)


class PackageTest(unittest.TestCase):
    def test_every_module_is_wrapped(self):
        for name in ("vtkPenumbraEGLRenderWindow", "vtkPenumbraOSMesaRenderWindow",
                     "vtkPenumbraHeadlessFactory", "vtkPenumbraImageCompare",
                     "vtkPenumbraSceneReader", "vtkPenumbraAreaLight", "vtkPenumbraShadowKeys",
                     "vtkPenumbraTechniques", "vtkPenumbraImageIO", "vtkPenumbraReference", "vtkPenumbraCityBlockSource",
                     "vtkPenumbraIsosurfaceSource", "vtkPenumbraRoomSource",
                     "vtkPenumbraTerrainSource"):
            self.assertTrue(hasattr(penumbra, name), name)

    def test_headless_window_without_display(self):
        self.assertFalse(os.environ.get("DISPLAY"))
        self.assertTrue(penumbra.vtkPenumbraHeadlessFactory.IsInstalled())
        win = vtkRenderWindow()
        # PENUMBRA_HEADLESS=osmesa (the whole suite can run so) chooses OSMesa, else EGL.
        osmesa = os.environ.get("PENUMBRA_HEADLESS", "").lower() == "osmesa"
        self.assertEqual(penumbra.vtkPenumbraHeadlessFactory.OSMesaRequested(), osmesa)
        self.assertIsInstance(win, penumbra.vtkPenumbraOSMesaRenderWindow if osmesa
                              else penumbra.vtkPenumbraEGLRenderWindow)

    def test_shadow_from_python(self):
        ren = occluder_scene()
        techniques = penumbra.vtkPenumbraTechniques()
        self.assertEqual(techniques.Apply(ren, "vtk-shadowmap", '{"resolution": 1024}'), 1,
                         techniques.GetErrorMessage())
        win = vtkRenderWindow()
        win.SetSize(SIZE, SIZE)
        win.AddRenderer(ren)
        win.Render()
        lum = window_luminance(win)
        sx, sy = pixel(-1.0, 0.0)
        lx, ly = pixel(1.2, 0.0)
        self.assertLess(lum[sy][sx], 60, "shadow footprint should be dark")
        self.assertGreater(lum[ly][lx], 150, "open plane should be lit")
        # Without shadows the same pixel is lit: the darkness comes from the technique.
        self.assertEqual(techniques.Apply(ren, "none", ""), 1)
        win.Render()
        self.assertGreater(window_luminance(win)[sy][sx], 150)

    def test_technique_errors_name_the_option(self):
        techniques = penumbra.vtkPenumbraTechniques()
        ren = vtkRenderer()
        self.assertEqual(techniques.Apply(ren, "vtk-shadowmap", '{"resolutoin": 5}'), 0)
        self.assertIn("resolutoin: unknown option", techniques.GetErrorMessage())
        self.assertEqual(techniques.Apply(ren, "vtk-shadowmap", '{"resolution": 0}'), 0)
        self.assertIn("resolution", techniques.GetErrorMessage())
        self.assertEqual(techniques.Apply(ren, "magic", ""), 0)
        self.assertIn("unknown technique", techniques.GetErrorMessage())
        self.assertIsNone(ren.GetPass())

    def test_enable_shadows_and_visibility(self):
        ren = occluder_scene()
        win = vtkRenderWindow()
        win.SetSize(SIZE, SIZE)
        win.AddRenderer(ren)
        shadows = penumbra.enable_shadows(ren, "shadowmap", resolution=1024, filter="pcf")
        self.assertTrue(shadows.IsA("vtkPenumbraShadowPass"))
        self.assertEqual(shadows.GetTechnique().GetResolution(), 1024)
        win.Render()
        vis = penumbra.visibility(ren, light=0)
        self.assertEqual(vis.shape, (SIZE, SIZE))
        sx, sy = pixel(-1.0, 0.0)
        lx, ly = pixel(1.2, 0.0)
        self.assertEqual(vis[sy][sx], 0.0)  # row 0 at the bottom, like the window's pixels
        self.assertEqual(vis[ly][lx], 1.0)
        self.assertLess(window_luminance(win)[sy][sx], 60)
        with self.assertRaises(IndexError):
            penumbra.visibility(ren, light=1)
        penumbra.disable_shadows(ren)
        self.assertIsNone(ren.GetPass())
        self.assertIsNone(penumbra.visibility(ren))
        win.Render()
        self.assertGreater(window_luminance(win)[sy][sx], 150)

    def test_enable_shadows_defaults_to_auto(self):
        ren = occluder_scene()
        win = vtkRenderWindow()
        win.SetSize(SIZE, SIZE)
        win.AddRenderer(ren)
        shadows = penumbra.enable_shadows(ren)
        self.assertTrue(shadows.GetTechnique().IsA("vtkPenumbraAutoShadows"))
        win.Render()
        self.assertEqual(shadows.GetLightTechniqueName(0), "raytraced")
        self.assertIn("light 0 (directional light): raytraced - hard light", shadows.GetExplanation())
        figures = penumbra.statistics(ren, light=0)
        self.assertGreater(figures["rays"], 0)  # raytraced's own count, by name
        self.assertGreaterEqual(figures["technique_ms"], 0.0)
        with self.assertRaises(IndexError):
            penumbra.statistics(ren, light=1)
        sx, sy = pixel(-1.0, 0.0)
        self.assertEqual(penumbra.visibility(ren, light=0)[sy][sx], 0.0)
        with self.assertRaisesRegex(ValueError, "quality: expected one of"):
            penumbra.enable_shadows(ren, quality="best")
        self.assertEqual(penumbra.enable_shadows(ren, quality="fast").GetTechnique().GetQuality(),
                         penumbra.vtkPenumbraAutoShadows.QUALITY_FAST)

    def test_enable_shadows_names_the_bad_option(self):
        ren = vtkRenderer()
        with self.assertRaisesRegex(ValueError, "resolutoin: unknown option"):
            penumbra.enable_shadows(ren, "shadowmap", resolutoin=5)
        with self.assertRaisesRegex(ValueError, "resolution"):
            penumbra.enable_shadows(ren, "shadowmap", resolution=-1)
        with self.assertRaisesRegex(ValueError, "unknown technique"):
            penumbra.enable_shadows(ren, "magic")
        with self.assertRaises(ValueError):
            penumbra.enable_shadows(ren, "shadowmap", resolution=object())
        self.assertIsNone(ren.GetPass())
        self.assertIsNone(penumbra.enable_shadows(ren, "vtk-shadowmap"))
        self.assertIsNotNone(ren.GetPass())

    def test_technique_installs_a_render_pass(self):
        ren = vtkRenderer()
        penumbra.vtkPenumbraTechniques().Apply(ren, "vtk-shadowmap", "")
        self.assertIsNotNone(ren.GetPass())
        self.assertTrue(ren.GetPass().IsA("vtkCameraPass"))


if __name__ == "__main__":
    unittest.main()
