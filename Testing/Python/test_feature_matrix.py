"""The VTK feature matrix: every row of the prop contract (feature_matrix.ROWS) with every
technique, on the window this process renders with (EGL, or OSMesa with
PENUMBRA_HEADLESS=osmesa; the suite runs both). For each row and technique:

- drawn as plain VTK draws it: outside the shadows (pixels that both the technique and the
  exact reference call lit or give no sample, one pixel away from any shadowed one, and
  where no translucent surface blends layers the samples do not hold) the image equals the
  unshadowed one;
- receives as the contract says: the row's prop has view samples only if it receives;
- casts what is drawn: the exact reference's shadow on the ground is as large as the
  contract says (a solid's, a part of it, thin lines, nothing);
- shadows right: exact techniques agree with the reference on every sample outside its
  ties, approximate ones within their bound;
- never an error: no VTK error (a shader that fails to compile, a failed technique) is
  reported while rendering.
"""

import os
import unittest

import numpy as np
import penumbra
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkCommonCore import vtkOutputWindow, vtkStringOutputWindow
from vtkmodules.vtkRenderingCore import vtkRenderWindow, vtkRenderer, vtkWindowToImageFilter

import feature_matrix

WIDTH, HEIGHT = 160, 120
# Exact techniques agree with the reference sample for sample; approximate ones may miss
# this share of the shadow candidates (samples lit or shadowed in either answer).
EXACT = ("auto", "raytraced", "conservative", "llsm", "llsm-hybrid", "volumes", "gears")
# Approximate techniques miss casters thinner than their texels: one-pixel lines and points
# are the worst case. Measured maxima over the rows: resm 0.33 (its texels are
# sized to a pixel), soft-shadowmap 0.16, the 2048-texel maps 0.04.
APPROXIMATE_BOUNDS = {"resm": 0.4, "soft-shadowmap": 0.2}
APPROXIMATE_BOUND = 0.08
# The peer: VTK's own pass is only checked for drawing without errors.
PEER = "vtk-shadowmap"


def techniques():
    names = [penumbra.vtkPenumbraTechniques.GetTechniqueName(i)
             for i in range(penumbra.vtkPenumbraTechniques.GetNumberOfTechniques())]
    return [n for n in names if n != "none"]


def grab(window):
    f = vtkWindowToImageFilter()
    f.SetInput(window)
    f.SetInputBufferTypeToRGB()
    f.ReadFrontBufferOff()
    f.Update()
    scalars = f.GetOutput().GetPointData().GetScalars()
    return vtk_to_numpy(scalars).reshape(HEIGHT, WIDTH, 3).astype(int)


def dilate(mask):
    """`mask` grown by one pixel in the eight directions."""
    grown = mask.copy()
    grown[1:, :] |= mask[:-1, :]
    grown[:-1, :] |= mask[1:, :]
    out = grown.copy()
    out[:, 1:] |= grown[:, :-1]
    out[:, :-1] |= grown[:, 1:]
    return out


class Row:
    """One row's scene in a window of its own, rendered plain and with the reference."""

    def __init__(self, name, twin=False):
        self.Name = name
        self.Renderer = vtkRenderer()
        self.Props = feature_matrix.build(name, self.Renderer, twin)
        self.Window = vtkRenderWindow()
        self.Window.SetSize(WIDTH, HEIGHT)
        self.Window.SetMultiSamples(0)
        self.Window.AddRenderer(self.Renderer)
        self.Window.Render()
        self.Plain = grab(self.Window)
        shadows = penumbra.enable_shadows(self.Renderer, "raytraced")
        self.Window.Render()
        self.Reference = penumbra.visibility(self.Renderer, 0)
        self.TranslucentReference = penumbra.visibility(self.Renderer, 0, translucent=True)
        samples = shadows.GetViewSamples()
        self.SampleProps = vtk_to_numpy(samples.GetPropIndices()).reshape(HEIGHT, WIDTH)
        # Translucent receivers' samples are the second layer's.
        layer = shadows.GetTranslucentViewSamples()
        self.TranslucentProps = (vtk_to_numpy(layer.GetPropIndices()).reshape(HEIGHT, WIDTH)
                                 if layer else np.full((HEIGHT, WIDTH), -1))
        geometry = shadows.GetGeometry()
        self.Ground = geometry.GetPropIndex(self.Renderer.GetActors().GetItemAsObject(0))
        # Every extracted entry of the row's props (an actor drawn twice has two).
        parts = set()
        for prop in self.Props:
            parts.add(prop.GetAddressAsString("vtkObject"))
            if prop.IsA("vtkAssembly"):
                paths = prop.GetParts()
                for i in range(paths.GetNumberOfItems()):
                    parts.add(paths.GetItemAsObject(i).GetAddressAsString("vtkObject"))
        self.RowProps = [i for i in range(geometry.GetNumberOfProps())
                         if geometry.GetProp(i).GetAddressAsString("vtkObject") in parts]
        # The reference's ties (first sample layer: the opaque one, as visibility() gives).
        ties = shadows.GetTechnique().GetReference().GetTies()
        self.Ties = vtk_to_numpy(ties)[:WIDTH * HEIGHT].reshape(HEIGHT, WIDTH)

    def ground_shadow(self):
        """Ground samples the exact reference calls shadowed."""
        return int(((self.SampleProps == self.Ground) & (self.Reference >= 0)
                    & (self.Reference < 0.5)).sum())

    def close(self):
        penumbra.disable_shadows(self.Renderer)
        self.Window.Finalize()


class FeatureMatrixTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.Log = vtkStringOutputWindow()
        cls.LogRead = 0
        vtkOutputWindow.SetInstance(cls.Log)

    def assertNoErrors(self, what):
        text = self.Log.GetOutput()[type(self).LogRead:]
        type(self).LogRead += len(text)
        errors = [line for line in text.splitlines() if "ERROR" in line or "ERR|" in line
                  or "error:" in line]
        self.assertEqual(errors, [], what)

    def check_row(self, name):
        row = Row(name)
        receives, casts, twin = feature_matrix.ROWS[name][1:]
        self.assertNoErrors(name + " plain / reference")
        # Casts what is drawn (on the reference: what every exact technique must match).
        shadow = row.ground_shadow()
        if casts == "nothing":
            self.assertEqual(shadow, 0, "%s casts %d shadowed ground samples" % (name, shadow))
        elif casts == "solid":
            self.assertGreater(shadow, 40, "%s casts only %d shadowed samples" % (name, shadow))
        else:
            solid = Row(name, twin=True)
            whole = solid.ground_shadow()
            solid.close()
            low, high = {"part": (0.25, 0.75), "thin": (0.01, 0.6)}[casts]
            self.assertTrue(low * whole <= shadow <= high * whole,
                            "%s casts %d shadowed ground samples, %s wants %.2f..%.2f x %d "
                            "(drawn as a surface)" % (name, shadow, casts, low, high, whole))
        # Receives as the contract says.
        own = int(np.isin(row.SampleProps, row.RowProps).sum() +
                  np.isin(row.TranslucentProps, row.RowProps).sum()) if row.RowProps else 0
        if receives and row.RowProps:
            self.assertGreater(own, 20, name + ": its surface should receive (have samples)")
        elif not receives:
            self.assertEqual(own, 0, name + ": it should give no view samples")
        for technique in techniques():
            with self.subTest(row=name, technique=technique):
                self.check_technique(row, technique)
        row.close()

    def check_technique(self, row, technique):
        penumbra.enable_shadows(row.Renderer, technique)
        row.Window.Render()
        image = grab(row.Window)
        self.assertNoErrors("%s with %s" % (row.Name, technique))
        if technique == PEER:
            return
        vis = penumbra.visibility(row.Renderer, 0)
        self.assertIsNotNone(vis, "%s: no visibility from %s" % (row.Name, technique))
        ref = row.Reference
        shadowed = ((ref >= 0) & (ref < 0.999)) | ((vis >= 0) & (vis < 0.999))
        # Where translucent surfaces are seen, several layers blend, each with its own
        # visibility (the layers behind the nearest are not sampled): not judged here.
        if row.TranslucentReference is not None:
            shadowed |= row.TranslucentReference >= 0
        outside = ~dilate(shadowed)
        differ = (np.abs(image - row.Plain).max(axis=2) > 2) & outside
        self.assertEqual(int(differ.sum()), 0, "%s with %s: %d pixels outside the shadows "
                         "differ from plain VTK" % (row.Name, technique, int(differ.sum())))
        valid = ref >= 0
        if row.Ties is not None:
            valid &= row.Ties == 0
        wrong = valid & ((vis < 0.5) != (ref < 0.5))
        if technique in EXACT:
            self.assertEqual(int(wrong.sum()), 0, "%s with %s: %d samples differ from the "
                             "exact reference" % (row.Name, technique, int(wrong.sum())))
        else:
            candidates = max(1, int((valid & shadowed).sum()))
            if os.environ.get("PENUMBRA_MATRIX_RATES"):
                print("RATE %-24s %-20s %.3f" % (row.Name, technique, wrong.sum() / candidates))
            bound = APPROXIMATE_BOUNDS.get(technique, APPROXIMATE_BOUND)
            self.assertLessEqual(wrong.sum() / candidates, bound,
                                 "%s with %s: %d of %d shadow candidates wrong"
                                 % (row.Name, technique, int(wrong.sum()), candidates))


def _add(name):
    def test(self):
        self.check_row(name)
    test.__name__ = "test_" + name.replace(" ", "_").replace("-", "_").replace("2D", "twod")
    setattr(FeatureMatrixTest, test.__name__, test)


for _name in feature_matrix.ROWS:
    _add(_name)


if __name__ == "__main__":
    unittest.main()
