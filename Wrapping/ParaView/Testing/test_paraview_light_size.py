"""Soft shadows from a ParaView light's size, headless: a positional light added with AddLight
and given a ShadowRadius (the plugin's light property) is shadowed as the disc of that
radius; gears and raytraced equal the exact reference for that disc at its k, the penumbra
matches the converged disc (MAE stated), a hard technique hands the light to the soft
fallback, and ShadowRadius 0 is a point light again.

    pvpython test_paraview_light_size.py [PLUGIN.so]

Needs what test_paraview_plugin.py needs (the `penumbra` package built against ParaView's VTK
on PYTHONPATH, no DISPLAY); ./penumbra.sh paraview runs it. Exits non-zero on a failed check.
"""
import os
import sys

import paraview.simple as pvs

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import shadow_view  # noqa: E402

shadow_view.load_plugin(globals(), sys.argv[1] if len(sys.argv) > 1 else None)

from penumbra.vtkPenumbraScene import vtkPenumbraAreaLight  # noqa: E402
from penumbra.vtkPenumbraShadows import vtkPenumbraShadowPass  # noqa: E402
from penumbra.vtkPenumbraRayTracing import vtkPenumbraReference  # noqa: E402
from vtkmodules.vtkCommonCore import vtkFloatArray  # noqa: E402

SIZE = [192, 144]
RADIUS = 0.75
failures = []


def check(ok, what):
    print(("ok    " if ok else "FAIL  ") + what)
    if not ok:
        failures.append(what)


def report(view):
    view.UpdatePropertyInformation()
    return view.GetProperty("ShadowReport").GetData()


def shadow_pass(view):
    return vtkPenumbraShadowPass.GetInstalled(view.GetClientSideObject().GetRenderer())


def compare(view, technique):
    """(samples differing from the reference for the disc at its k, MAE against the converged
    disc, penumbra samples) of the last frame's light 0."""
    p = shadow_pass(view)
    disc = vtkPenumbraAreaLight.SafeDownCast(p.GetLight(0))
    check(disc is not None and disc.GetShapeAsString() == "Disc" and
          disc.GetWidth() == 2 * RADIUS,
          "%s: the pass shadows the light as its disc of diameter %g" % (technique, 2 * RADIUS))
    reference = vtkPenumbraReference()
    reference.SetGeometry(p.GetGeometry())
    at_k, converged = vtkFloatArray(), vtkFloatArray()
    samples = p.GetViewSamples()
    check(reference.ComputeVisibility(samples, disc, at_k) == 1 and
          reference.ComputeConvergedVisibility(samples, disc, 64, converged) == 1,
          "%s: the reference ran (%s)" % (technique, reference.GetErrorMessage()))
    mine = p.GetVisibility(0)
    differ = penumbra = valid = 0
    error = 0.0
    for i in range(at_k.GetNumberOfTuples()):
        exact = at_k.GetValue(i)
        if exact < 0.0:
            continue
        valid += 1
        v = mine.GetValue(i)
        differ += v != exact
        error += abs(v - converged.GetValue(i))
        penumbra += 0.02 < converged.GetValue(i) < 0.98
    return differ, error / max(valid, 1), penumbra


view = shadow_view.sun_view(SIZE, [0.0, 0.0, 10.0])
view.AdditionalLights[0].Type = "Positional"  # the sun of sun_view made a sphere light
light = view.AdditionalLights[0]
light.Position = [0.5, 0.3, 4.0]
light.FocalPoint = [0.5, 0.3, 0.0]
light.ConeAngle = 90.0
ground = pvs.Plane(Origin=[-4, -4, 0], Point1=[4, -4, 0], Point2=[-4, 4, 0],
                   XResolution=8, YResolution=8)
ball = pvs.Sphere(Center=[0.0, 0.0, 1.0], Radius=0.6, ThetaResolution=48, PhiResolution=48)
for source in (ground, ball):
    pvs.Show(source, view).ColorArrayName = ["POINTS", ""]
shadow_view.look_at(view, [5.0, -6.0, 5.0], [0.0, 0.0, 0.5])
check("ShadowRadius" in light.ListProperties(), "the light proxy has the plugin's ShadowRadius")

view.ShadowTechnique = "gears"
pvs.Render(view)
check("(point light)" in report(view), "ShadowRadius 0: a point light")

light.ShadowRadius = RADIUS
for technique in ("gears", "raytraced"):
    view.ShadowTechnique = technique
    pvs.Render(view)
    check("disc light of diameter 1.5, 52 samples): %s" % technique in report(view),
          "%s: the report names the disc light" % technique)
    differ, mae, penumbra = compare(view, technique)
    print("      %s, sphere light r = %g: %d samples differ from the reference for the disc at "
          "k = 8; MAE %.4f against the converged disc (64 x 64); %d penumbra samples"
          % (technique, RADIUS, differ, mae, penumbra))
    check(differ == 0, "%s: equal to the reference for the disc at its k" % technique)
    check(mae < 0.005 and penumbra > 200,
          "%s: a penumbra (%d samples) within MAE 0.005 of the converged disc" %
          (technique, penumbra))

# A hard technique: the pass's soft fallback shadows the disc, and says so.
view.ShadowTechnique = "shadowmap"
pvs.Render(view)
check("shadowmap cannot shadow it; shadowed by gears" in report(view),
      "shadowmap: the disc goes to the soft fallback")

light.ShadowRadius = 0.0
pvs.Render(view)
check("(point light): shadowmap" in report(view), "ShadowRadius back to 0: a point light again")

if failures:
    print("%d checks failed" % len(failures))
    sys.exit(1)
print("all checks passed")
