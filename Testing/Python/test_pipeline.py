"""Shadows added to an existing VTK pipeline with the two lines the README promises: the
renderer's own pass is kept, the drop-in pass is found, the first frame is shadowed, picking
still works, and a scene with nothing to shadow gets no shadow work."""

import unittest

import feature_matrix
import penumbra
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkFiltersSources import vtkPlaneSource
from vtkmodules.vtkRenderingCore import (vtkHardwareSelector, vtkLight, vtkRenderWindow,
                                         vtkRenderer, vtkWindowToImageFilter)
from vtkmodules.vtkRenderingOpenGL2 import (vtkCameraPass, vtkOutlineGlowPass,
                                            vtkRenderPassCollection, vtkRenderStepsPass,
                                            vtkSequencePass)

SIZE = 96


def actor_of(source, color=(0.8, 0.8, 0.8)):
    return feature_matrix.polydata_actor(source, color)


def ball_over_ground(sun=True):
    """A sphere over a ground plane, seen obliquely; a sun (or VTK's automatic headlight)."""
    renderer = vtkRenderer()
    feature_matrix.build("surface", renderer)
    if not sun:
        renderer.RemoveAllLights()
    return renderer


def vtk_shadow_composition(renderer, shadows):
    """VTK's composition for its shadow pass (or the drop-in): CameraPass -> Sequence[baker,
    shadows]; returns the camera pass and the sequence's collection."""
    passes = vtkRenderPassCollection()
    passes.AddItem(shadows.GetShadowMapBakerPass())
    passes.AddItem(shadows)
    sequence = vtkSequencePass()
    sequence.SetPasses(passes)
    camera = vtkCameraPass()
    camera.SetDelegatePass(sequence)
    renderer.SetPass(camera)
    camera._sequence = sequence
    return camera, passes


def window_for(renderer):
    window = vtkRenderWindow()
    window.SetSize(SIZE, SIZE)
    window.SetMultiSamples(0)
    window.AddRenderer(renderer)
    return window


def pixels(window):
    grab = vtkWindowToImageFilter()
    grab.SetInput(window)
    grab.SetInputBufferTypeToRGB()
    grab.ReadFrontBufferOff()
    grab.Update()
    image = grab.GetOutput()
    return vtk_to_numpy(image.GetPointData().GetScalars()).reshape(SIZE, SIZE, 3).astype(int)


def shadowed(renderer, light=0):
    vis = penumbra.visibility(renderer, light)
    return 0 if vis is None else int(((vis >= 0) & (vis < 0.5)).sum())


class PipelineTest(unittest.TestCase):
    def test_first_frame_under_the_automatic_headlight(self):
        # No light added: VTK creates a headlight at the first render. That frame is shadowed
        # (the headlight's own shadows hide behind the objects, but its light gets shadow
        # work and visibility() answers after one render).
        renderer = ball_over_ground(sun=False)
        window = window_for(renderer)
        penumbra.enable_shadows(renderer, "raytraced")
        window.Render()
        self.assertEqual(renderer.GetLights().GetNumberOfItems(), 1)
        self.assertEqual(penumbra.shadow_pass(renderer).GetNumberOfLights(), 1)
        self.assertIsNotNone(penumbra.visibility(renderer, 0))
        first = pixels(window)
        window.Render()
        self.assertEqual(int((abs(first - pixels(window)) > 2).sum()), 0)

    def test_a_users_pass_is_kept(self):
        # A renderer drawing with vtkOutlineGlowPass keeps its glow: the shadow pass is
        # composed before it, and removing the shadows gives the user's pass back.
        renderer = ball_over_ground()
        steps = vtkRenderStepsPass()
        glow = vtkOutlineGlowPass()
        glow.SetDelegatePass(steps)
        renderer.SetPass(glow)
        window = window_for(renderer)
        window.Render()
        plain = pixels(window)
        shadows = penumbra.enable_shadows(renderer, "raytraced")
        self.assertIsNotNone(shadows)
        self.assertIs(shadows.GetDelegatePass(), glow)
        window.Render()
        self.assertGreater(shadowed(renderer), 50)
        glowing = pixels(window)
        # The glow draws outlines on black: few lit pixels, not a flat copy of the scene.
        self.assertLess(int((glowing.sum(axis=2) > 30).sum()), SIZE * SIZE // 3)
        self.assertGreater(int((glowing.sum(axis=2) > 30).sum()), 20)
        penumbra.enable_shadows(renderer, "shadowmap")  # another technique: still composed
        self.assertIs(penumbra.shadow_pass(renderer).GetDelegatePass(), glow)
        penumbra.disable_shadows(renderer)
        self.assertIs(renderer.GetPass(), glow)
        window.Render()
        self.assertEqual(int((abs(plain - pixels(window)) > 2).sum()), 0)
        with self.assertRaises(ValueError) as caught:
            penumbra.enable_shadows(renderer, "vtk-shadowmap")
        self.assertIn("vtkOutlineGlowPass", str(caught.exception))
        self.assertIs(renderer.GetPass(), glow)

    def test_drop_in_pass_is_found(self):
        # VTK's own composition, CameraPass -> Sequence[baker, shadows], with the drop-in pass.
        renderer = ball_over_ground()
        shadows = penumbra.vtkPenumbraShadowMapPass()
        camera, passes = vtk_shadow_composition(renderer, shadows)
        window = window_for(renderer)
        window.Render()
        self.assertIs(penumbra.shadow_pass(renderer), shadows)
        self.assertGreater(shadowed(renderer), 50)
        # A technique given by name goes into the user's composition, which stays.
        penumbra.enable_shadows(renderer, "raytraced")
        self.assertIs(renderer.GetPass(), camera)
        self.assertEqual(shadows.GetTechnique().GetTechniqueName(), "raytraced")
        window.Render()
        self.assertGreater(shadowed(renderer), 50)

    def test_vtk_shadow_passes_are_replaced_where_they_stand(self):
        # VTK's own composition with its shadow passes (Rendering/Shadows.py): Penumbra's pass
        # takes their place (no shadows drawn twice); removing the shadows puts them back.
        from vtkmodules.vtkRenderingOpenGL2 import vtkShadowMapPass
        renderer = ball_over_ground()
        vtk_shadows = vtkShadowMapPass()
        camera, passes = vtk_shadow_composition(renderer, vtk_shadows)
        window = window_for(renderer)
        ours = penumbra.enable_shadows(renderer, "raytraced")
        names = [passes.GetItemAsObject(i).GetClassName() for i in range(2)]
        self.assertEqual(names[1], "vtkPenumbraShadowPass")
        self.assertIs(passes.GetItemAsObject(1), ours)
        self.assertIs(renderer.GetPass(), camera)
        window.Render()
        self.assertGreater(shadowed(renderer), 50)
        penumbra.disable_shadows(renderer)
        self.assertIs(passes.GetItemAsObject(0), vtk_shadows.GetShadowMapBakerPass())
        self.assertIs(passes.GetItemAsObject(1), vtk_shadows)
        window.Render()

    def test_picking_gets_no_shadow_work(self):
        renderer = ball_over_ground()
        window = window_for(renderer)
        penumbra.enable_shadows(renderer, "raytraced")
        window.Render()
        selector = vtkHardwareSelector()
        selector.SetRenderer(renderer)
        selector.SetArea(0, 0, SIZE - 1, SIZE - 1)
        selection = selector.Select()
        self.assertGreaterEqual(selection.GetNumberOfNodes(), 2)  # ground and ball picked
        window.Render()
        self.assertGreater(shadowed(renderer), 50)

    def test_nothing_to_shadow(self):
        # Unlit props receive no light, so no shadow: no shadow work, the frame is drawn as
        # without shadows.
        renderer = ball_over_ground()
        actors = renderer.GetActors()
        actors.InitTraversal()
        for _ in range(actors.GetNumberOfItems()):
            actors.GetNextActor().GetProperty().LightingOff()
        window = window_for(renderer)
        window.Render()
        plain = pixels(window)
        shadows = penumbra.enable_shadows(renderer, "raytraced")
        window.Render()
        self.assertIsNone(penumbra.visibility(renderer, 0))
        self.assertIn("no lit surface receives shadows", shadows.GetExplanation())
        self.assertEqual(int((abs(plain - pixels(window)) > 2).sum()), 0)

    def test_translucent_receivers_under_the_shader_lookup(self):
        # A translucent tube (front and back walls blend in every pixel) and an outline under
        # VTK's headlight: nothing is visibly shadowed. shadowmap's lookup in the receivers'
        # own shaders shadowed the tube's far wall by its near one (1,209 pixels darker than
        # plain VTK at 200 x 200, with visibility() reporting none); the translucent layer
        # takes the nearest surface's visibility in every fragment, as for every technique.
        from vtkmodules.vtkFiltersCore import vtkTubeFilter
        from vtkmodules.vtkFiltersSources import vtkLineSource, vtkOutlineSource
        renderer = vtkRenderer()
        line = vtkLineSource()
        line.SetPoint1(1, 0, 0)
        line.SetPoint2(0, 1, 0)
        tube = vtkTubeFilter()
        tube.SetInputConnection(line.GetOutputPort())
        tube.SetRadius(0.05)
        tube.SetNumberOfSides(30)
        glass = actor_of(tube)
        glass.GetProperty().SetOpacity(0.5)
        renderer.AddActor(glass)
        outline = vtkOutlineSource()
        outline.SetBounds(-0.2, 1.2, -0.2, 1.2, -0.3, 0.3)
        renderer.AddActor(actor_of(outline, (1, 1, 0)))
        renderer.ResetCamera()
        renderer.GetActiveCamera().Azimuth(20)
        renderer.GetActiveCamera().Elevation(20)
        renderer.ResetCameraClippingRange()
        window = window_for(renderer)
        window.Render()
        plain = pixels(window)
        for technique in ("shadowmap", "raytraced"):
            penumbra.enable_shadows(renderer, technique)
            window.Render()
            vis = penumbra.visibility(renderer, 0, translucent=True)
            self.assertGreater(int((vis >= 0).sum()), 100, technique)
            self.assertEqual(int(((vis >= 0) & (vis < 1)).sum()), 0, technique)
            differ = int((abs(plain - pixels(window)).max(axis=2) > 2).sum())
            self.assertEqual(differ, 0, "%s: %d pixels differ from plain VTK" % (technique, differ))
            penumbra.disable_shadows(renderer)

    def test_multisampled_edges(self):
        # A multisampled window (VTK's default: 8 samples) shades partly covered edge pixels
        # at a pixel centre that can lie outside the primitive. The shader lookups take the
        # covered samples' position: under the headlight nothing visible is shadowed, and a
        # self-intersecting surface (Boy's) and a plane's far edge stay as plain VTK draws
        # them (a dark row at the plane's edge; 202-238 dark dots on Boy's surface at the
        # pixel centres, about 20 where its sheets cross at nearly equal depth, which a
        # shadow map's bias cannot tell apart).
        from vtkmodules.vtkCommonComputationalGeometry import vtkParametricBoy
        from vtkmodules.vtkFiltersSources import vtkParametricFunctionSource
        for name in ("plane", "boy"):
            for technique in ("shadowmap", "shadowmap:fit=scene"):
                with self.subTest(scene=name, technique=technique):
                    renderer = vtkRenderer()
                    if name == "plane":
                        source = vtkPlaneSource()
                        source.SetOrigin(-2, -2, 0)
                        source.SetPoint1(2, -2, 0)
                        source.SetPoint2(-2, 2, 0)
                    else:
                        source = vtkParametricFunctionSource()
                        source.SetParametricFunction(vtkParametricBoy())
                    renderer.AddActor(actor_of(source))
                    camera = renderer.GetActiveCamera()
                    camera.SetPosition(0, -6, 3)
                    camera.SetFocalPoint(0, 0, 0)
                    camera.SetViewUp(0, 0, 1)
                    renderer.ResetCamera()
                    window = window_for(renderer)
                    window.SetMultiSamples(8)
                    window.Render()
                    plain = pixels(window)
                    name_, _, option = technique.partition(":")
                    options = dict([option.split("=")]) if option else {}
                    penumbra.enable_shadows(renderer, name_, **options)
                    window.Render()
                    differ = int((abs(plain - pixels(window)).max(axis=2) > 8).sum())
                    self.assertLessEqual(differ, 0 if name == "plane" else 30,
                                         "%d pixels differ" % differ)

    def test_props_that_cast_nothing_are_named_once(self):
        # A volume is drawn but casts no shadow: the pass says so once per prop and
        # technique, naming both.
        import feature_matrix
        from vtkmodules.vtkCommonCore import vtkOutputWindow, vtkStringOutputWindow
        log = vtkStringOutputWindow()
        previous = vtkOutputWindow.GetInstance()
        vtkOutputWindow.SetInstance(log)
        try:
            renderer = vtkRenderer()
            feature_matrix.build("volume", renderer)
            window = window_for(renderer)
            penumbra.enable_shadows(renderer, "raytraced")
            window.Render()
            window.Render()
            penumbra.enable_shadows(renderer, "shadowmap")
            window.Render()
        finally:
            vtkOutputWindow.SetInstance(previous)
        said = [line for line in log.GetOutput().splitlines() if "volumes cast no shadows" in line]
        self.assertEqual(len(said), 2, log.GetOutput())
        self.assertIn("vtkVolume (prop 1): volumes cast no shadows", said[0])
        self.assertIn("raytraced", said[0])
        self.assertIn("shadowmap", said[1])

    def test_techniques_named_for_what_they_do(self):
        # A soft-shadow technique shadows a sun with the hard technique it is built on, and a
        # light a technique refuses is explained in one sentence naming what shadowed it.
        renderer = ball_over_ground()
        window = window_for(renderer)
        for technique, name in (("pcss", "shadowmap"), ("single-sample-soft", "shadowmap"),
                                ("soft-shadowmap", "shadowmap"), ("adaptive-soft", "raytraced"),
                                ("shadowmap", "shadowmap")):
            with self.subTest(technique=technique):
                shadows = penumbra.enable_shadows(renderer, technique)
                window.Render()
                self.assertEqual(shadows.GetLightTechniqueName(0), name)
        point = vtkLight()
        point.SetLightTypeToSceneLight()
        point.SetPositional(True)
        point.SetConeAngle(180)
        point.SetPosition(1, 1, 4)
        renderer.RemoveAllLights()
        renderer.AddLight(point)
        shadows = penumbra.enable_shadows(renderer, "rmsm")
        window.Render()
        explanation = shadows.GetExplanation()
        self.assertIn("light 0 (point light): raytraced - rmsm cannot shadow it; shadowed by "
                      "raytraced instead", explanation)
        self.assertNotIn("soft", explanation)


if __name__ == "__main__":
    unittest.main()
