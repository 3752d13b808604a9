"""The PenumbraShadows plugin in ParaView, headless: each technique's visibility against the
exact reference on the same view samples, and shadows in the image.

    pvpython test_paraview_plugin.py [PLUGIN.so]

PLUGIN.so defaults to PenumbraShadows.so in the first folder of PV_PLUGIN_PATH.

Needs the `penumbra` package built against ParaView's VTK on PYTHONPATH (for the shadow pass's
read-back and the exact tracer) and no DISPLAY (Penumbra's EGL window). ./penumbra.sh paraview
runs it. Exits non-zero on the first failed check.

Scene: a ground plane and a box floating above it, one directional scene light (ParaView's
light kit off), 256 x 256 pixels. ParaView draws every representation through
vtkPVLODActor's internal device actor and a composite mapper: without the view-sample pass's
match by property keys no sample is valid and this test fails.
"""
import os
import sys

import paraview.simple as pvs

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import shadow_view  # noqa: E402

shadow_view.load_plugin(globals(), sys.argv[1] if len(sys.argv) > 1 else None)

import penumbra  # noqa: E402  (after ParaView: the same VTK, already loaded)
from penumbra.vtkPenumbraShadows import vtkPenumbraShadowPass  # noqa: E402
from penumbra.vtkPenumbraTechniques import vtkPenumbraTechniques  # noqa: E402
from penumbra.vtkPenumbraRayTracing import vtkPenumbraReference  # noqa: E402
from vtkmodules.vtkCommonCore import vtkFloatArray  # noqa: E402

SIZE = [256, 256]
failures = []


def check(ok, what):
    print(("ok    " if ok else "FAIL  ") + what)
    if not ok:
        failures.append(what)


def make_view():
    view = shadow_view.sun_view(SIZE, [-3.0, -2.0, 10.0])
    ground = pvs.Plane(Origin=[-4, -4, 0], Point1=[4, -4, 0], Point2=[-4, 4, 0],
                       XResolution=8, YResolution=8)
    box = pvs.Box(XLength=2.0, YLength=2.0, ZLength=1.0, Center=[0.0, 0.0, 2.0])
    for source in (ground, box):
        display = pvs.Show(source, view)
        display.ColorArrayName = ["POINTS", ""]
    shadow_view.look_at(view, [0.0, -9.0, 9.0], [0.0, 0.0, 0.5])
    return view


def installed_pass(view):
    renderer = view.GetClientSideObject().GetRenderer()
    return vtkPenumbraShadowPass.GetInstalled(renderer)


def mean_luminance(view, name):
    path = os.path.join(os.environ.get("PENUMBRA_TEST_OUTPUT", "."), "paraview-%s.png" % name)
    pvs.SaveScreenshot(path, view, ImageResolution=SIZE)
    from vtkmodules.vtkIOImage import vtkPNGReader
    reader = vtkPNGReader()
    reader.SetFileName(path)
    reader.Update()
    scalars = reader.GetOutput().GetPointData().GetScalars()
    total = 0.0
    for i in range(scalars.GetNumberOfTuples()):
        total += sum(scalars.GetTuple(i)[:3]) / 3.0
    return total / scalars.GetNumberOfTuples()


def count_against_reference(shadow_pass, light, what):
    """(valid, shadowed, mismatching) view samples of light `light`: the pass's visibility
    against the exact reference's, ties excluded. A light the pass left out (it reaches no
    sample: no read-back) counts as shadowing every sample."""
    visibility = shadow_pass.GetVisibility(light)
    reference = vtkPenumbraReference()
    reference.SetGeometry(shadow_pass.GetGeometry())
    exact = vtkFloatArray()
    check(reference.ComputeVisibility(shadow_pass.GetViewSamples(), shadow_pass.GetLight(light),
                                      exact) == 1,
          "%s: the exact tracer ran (%s)" % (what, reference.GetErrorMessage()))
    ties = reference.GetTies()
    valid = shadowed = mismatches = 0
    for i in range(exact.GetNumberOfTuples()):
        e = exact.GetValue(i)
        if e < 0.0:
            continue
        valid += 1
        shadowed += e < 0.5
        lit = visibility is not None and visibility.GetValue(i) >= 0.5
        if ties.GetValue(i) == 0 and lit != (e >= 0.5):
            mismatches += 1
    return valid, shadowed, mismatches


def compare_with_reference(shadow_pass, technique, max_mismatch_fraction):
    check(shadow_pass.GetNumberOfLights() == 1,
          "%s: the pass sees the one scene light (%d)" % (technique,
                                                          shadow_pass.GetNumberOfLights()))
    check(shadow_pass.GetVisibility(0) is not None,
          "%s: light 0 has a visibility read-back" % technique)
    valid, shadowed, mismatches = count_against_reference(shadow_pass, 0, technique)
    check(valid > 0.5 * SIZE[0] * SIZE[1] / 4,
          "%s: valid view samples through ParaView's device actors (%d)" % (technique, valid))
    check(shadowed > 0.01 * valid,
          "%s: the exact reference has shadowed samples (%d of %d)" % (technique, shadowed, valid))
    limit = int(max_mismatch_fraction * valid)
    check(mismatches <= limit,
          "%s: %d samples disagree with the exact reference (at most %d allowed)" %
          (technique, mismatches, limit))


view = make_view()

# The technique list and default come from Penumbra's registry, not from the plugin's XML.
view.UpdatePropertyInformation()
names = list(view.GetProperty("ShadowTechniqueNames"))
registry = [vtkPenumbraTechniques.GetTechniqueName(i)
            for i in range(vtkPenumbraTechniques.GetNumberOfTechniques())]
check(sorted(names) == sorted(registry), "technique list is the registry's: %s" % names)
check(names[0] == vtkPenumbraTechniques.GetDefaultTechnique(),
      "the list starts with the registry's default (%s)" % names[0])

# The Properties panel follows the proxy's property order: the Shadows group (technique,
# options, every option property) comes before the render view's own properties.
from paraview import servermanager  # noqa: E402
order = servermanager.vtkSMOrderedPropertyIterator()
order.SetProxy(view.SMProxy)
order.Begin()
panel_order = []
while not order.IsAtEnd():
    if not order.GetProperty().GetInformationOnly():
        panel_order.append(order.GetKey())
    order.Next()
groups = {view.SMProxy.GetPropertyGroup(i).GetXMLLabel(): view.SMProxy.GetPropertyGroup(i)
          for i in range(view.SMProxy.GetNumberOfPropertyGroups())}
shadows = groups.get("Shadows")
members = [shadows.GetProperty(i) for i in range(shadows.GetNumberOfProperties())] \
    if shadows else []
check(shadows is not None and view.GetProperty("ShadowTechnique").SMProperty in members and
      view.GetProperty("shadowmap/resolution").SMProperty in members,
      "a Shadows property group holds the technique and its options (%d properties)"
      % len(members))
check(panel_order[:2] == ["ShadowTechnique", "ShadowOptions"] and
      len(panel_order) > len(members) and
      all(view.GetProperty(k).SMProperty in members for k in panel_order[:len(members)]),
      "the Shadows group comes first in the view's property order (%s)" % panel_order[:3])

view.ShadowTechnique = "none"
pvs.Render(view)
unshadowed = mean_luminance(view, "none")
check(installed_pass(view) is None, "none: no Penumbra pass installed")

# Exact techniques: no mismatch outside ties; shadowmap: a shadow map's resolution errors
# along the shadow's edges only.
for technique, max_fraction in (("raytraced", 0.0), ("conservative", 0.0), ("volumes", 0.0),
                                  ("shadowmap", 0.01)):
    view.ShadowTechnique = technique
    view.ShadowOptions = ""
    pvs.Render(view)
    view.UpdatePropertyInformation()
    installed = view.GetProperty("InstalledShadowTechnique").GetData()
    check(installed == technique, "%s: installed (%s)" % (technique, installed))
    report = view.GetProperty("ShadowReport").GetData()
    check(("): %s - " % technique) in report and "figures: time_ms " in report,
          "%s: the view reports the technique and its statistics (%r)" % (technique, report))
    shadow_pass = installed_pass(view)
    check(shadow_pass is not None, "%s: the view draws through a Penumbra shadow pass" % technique)
    if shadow_pass is not None:
        compare_with_reference(shadow_pass, technique, max_fraction)
    shadowed_image = mean_luminance(view, technique)
    check(shadowed_image < unshadowed - 1.0,
          "%s: the image is darker than without shadows (%.1f vs %.1f)" %
          (technique, shadowed_image, unshadowed))

# ParaView's light kit (key, fill, two back lights, headlight) beside the scene sun: every
# light of the view is shadowed, each exactly.
view.UseLight = 1
view.ShadowTechnique = "raytraced"
pvs.Render(view)
kit_pass = installed_pass(view)
check(kit_pass.GetNumberOfLights() == 6,
      "light kit: the pass sees the sun and the kit's 5 lights (%d)" % kit_pass.GetNumberOfLights())
kit_shadowed = 0
for light in range(kit_pass.GetNumberOfLights()):
    valid, shadowed, mismatches = count_against_reference(kit_pass, light, "light kit")
    check(mismatches == 0, "light kit: light %d, %d samples disagree with the exact reference"
          % (light, mismatches))
    kit_shadowed += light > 0 and 0 < shadowed < valid
check(kit_shadowed > 0, "light kit: the kit's lights cast shadows (%d of 5)" % kit_shadowed)
view.UseLight = 0

# Options reach the technique through the registry's checker.
view.ShadowTechnique = "shadowmap"
view.ShadowOptions = '{"resolution": 512}'
pvs.Render(view)
view.UpdatePropertyInformation()
check(view.GetProperty("InstalledShadowTechnique").GetData() == "shadowmap",
      "shadowmap with {\"resolution\": 512} installed")
check(installed_pass(view).GetTechnique().GetResolution() == 512,
      "ShadowOptions' resolution reaches the technique")

# Every option of every technique is a typed property generated from the option tables, with
# the table's default; the JSON text overrides the properties it names.
for t in range(vtkPenumbraTechniques.GetNumberOfTechniques()):
    technique = vtkPenumbraTechniques.GetTechniqueName(t)
    for o in range(vtkPenumbraTechniques.GetNumberOfOptions(technique)):
        option = vtkPenumbraTechniques.GetOptionName(technique, o)
        prop = view.GetProperty("%s/%s" % (technique, option))
        default = vtkPenumbraTechniques.GetOptionDefault(technique, o)
        check(prop is not None and str(prop.GetData()).lower() in
              (default.strip('"').lower(), {"true": "1", "false": "0"}.get(default, "-")),
              "property %s/%s has the table's default %s" % (technique, option, default))
view.ShadowOptions = ""
view.ShadowmapResolution = 256
view.ShadowmapFilter = "pcf"
pvs.Render(view)
technique = installed_pass(view).GetTechnique()
check(technique.GetResolution() == 256 and technique.GetFilter() == technique.FILTER_PCF,
      "the ShadowmapResolution and ShadowmapFilter properties reach the technique")
view.ShadowOptions = '{"resolution": 1024}'
pvs.Render(view)
technique = installed_pass(view).GetTechnique()
check(technique.GetResolution() == 1024 and technique.GetFilter() == technique.FILTER_PCF,
      "ShadowOptions overrides the resolution property, the filter property stays")
view.ShadowOptions = ""
view.ShadowmapResolution = 3  # outside the table's range: refused, the last technique stays
pvs.Render(view)
check(installed_pass(view).GetTechnique().GetResolution() == 1024,
      "an out-of-range option property is refused and the view keeps its technique")
# A refused request is undone on the proxy: the properties show what draws.
check(view.ShadowmapResolution == 256 and view.ShadowOptions == '{"resolution": 1024}',
      "the refused option property is back to what draws (ShadowmapResolution %d, "
      "ShadowOptions %r)" % (view.ShadowmapResolution, view.ShadowOptions))
view.ShadowTechnique = "nonexistent"
pvs.Render(view)
check(view.ShadowTechnique == "shadowmap" and
      installed_pass(view).GetTechnique().GetResolution() == 1024,
      "a refused technique name is back to the one that draws (%r)" % view.ShadowTechnique)
view.ShadowTechnique = "pcss"
view.ShadowOptions = '{"no_such_option": 1}'
pvs.Render(view)
check(view.ShadowTechnique == "shadowmap" and view.ShadowOptions == '{"resolution": 1024}',
      "a technique refused for its options is back to the one that draws (%r, %r)"
      % (view.ShadowTechnique, view.ShadowOptions))

# A scene file's shadow settings: its technique block and how MPI ranks share their casters.
import json  # noqa: E402
import tempfile  # noqa: E402

import penumbra_paraview  # noqa: E402

with tempfile.TemporaryDirectory() as folder:
    scene = os.path.join(folder, "scene.json")
    with open(scene, "w") as f:
        json.dump({"technique": {"name": "shadowmap", "resolution": 512},
                   "distributed": {"caster_exchange": "distributed", "memory_budget": 256}}, f)
    penumbra_paraview.apply_scene_settings(view, scene)
    pvs.Render(view)
    check(view.ShadowTechnique == "shadowmap" and view.CasterExchange == "distributed" and
          view.CasterMemoryBudget == 256.0 and
          installed_pass(view).GetTechnique().GetResolution() == 512,
          "a scene file's technique and distributed blocks reach the view (%r, %r, %g)"
          % (view.ShadowTechnique, view.CasterExchange, view.CasterMemoryBudget))
    with open(scene, "w") as f:
        json.dump({"distributed": {"memory_budget": -1}}, f)
    try:
        penumbra_paraview.apply_scene_settings(view, scene)
        refused = ""
    except ValueError as error:
        refused = str(error)
    check("distributed.memory_budget: must be 0 (no budget)" in refused and
          view.CasterMemoryBudget == 256.0,
          "a bad distributed block is refused with its field, the view unchanged (%r)" % refused)
    view.CasterExchange = "need"
    view.CasterMemoryBudget = 0

# Hidden blocks cast no shadows: the same ground and box as blocks of one data set; hiding
# the box block (BlockSelectors) must take its shadow away with it.
for source in pvs.GetSources().values():
    pvs.Hide(source, view)
ground = pvs.Plane(Origin=[-4, -4, 0], Point1=[4, -4, 0], Point2=[-4, 4, 0])
box = pvs.Box(XLength=2.0, YLength=2.0, ZLength=1.0, Center=[0.0, 0.0, 2.0])
pvs.RenameSource("BlockGround", ground)  # GroupDatasets names its blocks after the sources
blocks = pvs.Show(pvs.GroupDatasets(Input=[ground, box]), view)
view.ShadowTechnique = "raytraced"
view.ShadowOptions = ""


def shadowed_samples():
    pvs.Render(view)
    shadow_pass = installed_pass(view)
    visibility = shadow_pass.GetVisibility(0)  # none when nothing casts: the light is skipped
    count = 0 if visibility is None else sum(
        1 for i in range(visibility.GetNumberOfTuples()) if 0.0 <= visibility.GetValue(i) < 0.5)
    return count, shadow_pass.GetGeometry().GetNumberOfTriangles()


both = shadowed_samples()
blocks.BlockSelectors = ["/Root/BlockGround"]
ground_only = shadowed_samples()
check(both[0] > 0 and both[1] == 14, "blocks: the box block shadows the ground (%d samples)"
      % both[0])
check(ground_only == (0, 2), "blocks: a hidden box block casts no shadow (%d samples, %d "
      "triangles)" % ground_only)

if failures:
    print("%d check(s) failed" % len(failures))
else:
    print("all checks passed")
# sys.exit() with a shadow view alive: ParaView destroys its views after Embree's state at
# exit, so an exit that aborts (or hangs) in Embree fails this test through its exit status.
sys.exit(1 if failures else 0)
