"""The PenumbraShadows plugin under MPI: shadows cast across ranks.

    mpirun -np N pvbatch --mpi --symmetric --disable-xdisplay-test test_paraview_mpi.py \
        OUTDIR [TECHNIQUE,...]

Scene: a ground plane, a box and a sphere appended into one data set and spread over the
ranks by RedistributeDataSet (each cell on one rank), one oblique directional scene light,
192 x 192 pixels, so the box and the sphere shadow ground that another rank draws.

Checks on every rank (symmetric mode: each rank runs this script and reads its own view):
- the pass's geometry holds the rank's own triangles and at most the other ranks' casters
  (the need-based exchange, the default; with CasterExchange "all", every triangle);
- exact techniques: 0 of the rank's view samples disagree with the exact reference over
  every rank's casters (ties excluded), and on some rank the other ranks' casters change the
  answer (without them the test would prove nothing);
- an unchanged frame exchanges nothing; a caster that moves is exchanged again; exchanging
  every caster draws the same image as exchanging the needed ones;
- no error or warning reaches any rank's output window (pvbatch draws into ParaView's
  offscreen view window, whose GLEW message the view drops).
On rank 0: the composited image is written to OUTDIR/mpi-TECHNIQUE-npN.png, and when
OUTDIR/mpi-TECHNIQUE-np1.png exists (a run with -np 1 first) the two images agree pixel
for pixel within 2 levels (exact techniques; a shadow map on at most 0.5 % of the pixels).

Exit status: 0 when every check passed on every rank (./penumbra.sh paraview runs it).
"""
import os
import sys

import paraview.simple as pvs

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import shadow_view  # noqa: E402

shadow_view.load_plugin(globals())

import penumbra  # noqa: E402,F401  (after ParaView: the same VTK, already loaded)
from penumbra.vtkPenumbraShadows import vtkPenumbraShadowPass  # noqa: E402
from penumbra.vtkPenumbraRayTracing import vtkPenumbraReference  # noqa: E402
from penumbra.vtkPenumbraScene import vtkPenumbraSceneGeometry  # noqa: E402
from vtkmodules.vtkCommonCore import vtkFloatArray, vtkIntArray  # noqa: E402
from vtkmodules.vtkParallelCore import vtkCommunicator, vtkMultiProcessController  # noqa: E402

from vtkmodules.util.misc import calldata_type  # noqa: E402
from vtkmodules.util.vtkConstants import VTK_STRING  # noqa: E402
from vtkmodules.vtkCommonCore import vtkCommand, vtkOutputWindow  # noqa: E402

SIZE = [192, 192]
EXACT = ("raytraced", "conservative", "volumes", "llsm", "llsm-hybrid")
# Composite their maps across the ranks in distributed mode (no caster leaves its rank).
MAPS = ("shadowmap", "resm", "pcss", "single-sample-soft")
out_dir = sys.argv[1] if len(sys.argv) > 1 else "."
techniques = (sys.argv[2] if len(sys.argv) > 2 else "raytraced,conservative,volumes,llsm,shadowmap")
techniques = techniques.split(",")
# "small" (default): ground, box and sphere; "terrain": about 1 M triangles of hills under
# an oblique sun and a point light, where a rank must hold at most a third of the casters.
scene = sys.argv[3] if len(sys.argv) > 3 else "small"
prefix = "" if scene == "small" else scene + "-"
controller = vtkMultiProcessController.GetGlobalController()
rank = controller.GetLocalProcessId()
ranks = controller.GetNumberOfProcesses()
failures = []
messages = []
stats = {}


@calldata_type(VTK_STRING)
def on_message(_window, _event, text):
    messages.append(text)


for event in (vtkCommand.ErrorEvent, vtkCommand.WarningEvent):
    vtkOutputWindow.GetInstance().AddObserver(event, on_message)


def all_sum(value, op=vtkCommunicator.SUM_OP):
    """One integer reduced over all ranks (every rank gets the result)."""
    send, receive = vtkIntArray(), vtkIntArray()
    send.InsertNextValue(int(value))
    controller.AllReduce(send, receive, op)
    return receive.GetValue(0)


def check(ok, what, everywhere=True):
    """A check that holds on every rank (everywhere) or is decided the same on all."""
    failed_ranks = all_sum(0 if ok else 1) if everywhere else (0 if ok else 1)
    if rank == 0:
        print(("ok    " if failed_ranks == 0 else "FAIL  ") + what +
              ("" if failed_ranks == 0 or not everywhere else " (%d ranks)" % failed_ranks))
    if failed_ranks:
        failures.append(what)


def make_view():
    # ParaView applies FXAA after IceT's compositing but not to a single process's render
    # pass: off, so that the -np 1 and -np N images can be compared pixel for pixel.
    if scene == "terrain":
        view = shadow_view.sun_view(SIZE, [-2.0, -1.0, 1.2])
        view.AdditionalLights[0].Intensity = 0.7
        view.UseFXAA = 0
        terrain = shadow_view.show_terrain(view)
        shadow_view.add_point_light(view, [10.0, 5.0, 30.0])
        return view, terrain
    view = shadow_view.sun_view(SIZE, [-6.0, -2.0, 6.0])
    view.UseFXAA = 0
    return view, shadow_view.show_ground_box_sphere(view)


def full_geometry(renderer, local):
    """This rank's props plus every other rank's caster triangles (all of them, as one
    shadow-only prop): the whole scene, as one process would hold it."""
    import numpy
    from vtkmodules.util import numpy_support
    from vtkmodules.vtkCommonCore import vtkDoubleArray, vtkIdTypeArray
    from vtkmodules.vtkCommonDataModel import vtkCellArray, vtkPolyData
    from vtkmodules.vtkCommonCore import vtkPoints
    from vtkmodules.vtkRenderingCore import vtkActor, vtkPolyDataMapper, vtkPropCollection
    mine = vtkDoubleArray()
    local.GetCasterWorldTriangles(mine)
    count, counts = vtkIdTypeArray(), vtkIdTypeArray()
    count.InsertNextValue(mine.GetNumberOfTuples())
    controller.AllGather(count, counts)
    everything = vtkDoubleArray()
    controller.AllGatherV(mine, everything)
    xyz = numpy_support.vtk_to_numpy(everything).reshape(-1, 9)
    sizes = [counts.GetValue(r) for r in range(ranks)]
    first = sum(sizes[:rank])
    others = numpy.concatenate((xyz[:first], xyz[first + sizes[rank]:])).reshape(-1, 3)
    points = vtkPoints()
    points.SetData(numpy_support.numpy_to_vtk(numpy.ascontiguousarray(others), deep=1))
    cells = vtkCellArray()
    n = others.shape[0] // 3
    cells.SetData(numpy_support.numpy_to_vtkIdTypeArray(numpy.arange(0, 3 * n + 1, 3), deep=1),
                  numpy_support.numpy_to_vtkIdTypeArray(numpy.arange(3 * n), deep=1))
    data = vtkPolyData()
    data.SetPoints(points)
    data.SetPolys(cells)
    mapper = vtkPolyDataMapper()
    mapper.SetInputData(data)
    actor = vtkActor()
    actor.SetMapper(mapper)
    props = vtkPropCollection()
    props.AddItem(actor)
    full = vtkPenumbraSceneGeometry()
    full.SetShadowOnlyProps(props)
    full.Update(renderer)
    full._keep = (props, actor, mapper, data)
    return full, int(sum(sizes))


def rank_view_check(view, technique):
    """This rank's samples against the exact reference on every rank's casters."""
    renderer = view.GetClientSideObject().GetRenderer()
    shadow_pass = vtkPenumbraShadowPass.GetInstalled(renderer)
    check(shadow_pass is not None, "%s: a Penumbra pass draws the view" % technique)
    if shadow_pass is None:
        return
    local = vtkPenumbraSceneGeometry()
    local.Update(renderer)
    geometry = shadow_pass.GetGeometry()
    full, casters = full_geometry(renderer, local)
    total = all_sum(local.GetNumberOfTriangles())
    held = geometry.GetNumberOfTriangles() - local.GetNumberOfTriangles()
    check(ranks == 1 or local.GetNumberOfTriangles() < total,
          "%s: the data is split over the ranks" % technique)
    if view.CasterExchange == "all":
        check(geometry.GetNumberOfTriangles() == total,
              "%s: every rank's pass holds all %d triangles of all ranks" % (technique, total))
    elif view.CasterExchange == "distributed" or view.CasterMemoryBudget:
        check(held == 0, "%s (distributed): every rank's pass holds its own triangles only"
              % technique)
    else:
        most = all_sum(held, vtkCommunicator.MAX_OP)
        # Fewer than all of them: an all-gather would hold every other rank's caster.
        check(ranks == 1 or held < casters - local.GetNumberOfTriangles(),
              "%s: every rank's pass holds fewer than the other ranks' casters (at most %d "
              "of %d)" % (technique, most, casters), everywhere=True)
        stats.setdefault("held", {})[technique] = (most, casters)
    if technique not in EXACT:
        return
    samples = shadow_pass.GetViewSamples()
    light_count = shadow_pass.GetNumberOfLights()
    mismatches = needed = 0
    for index in range(light_count):
        light = shadow_pass.GetLight(index)
        visibility = shadow_pass.GetVisibility(index)
        if light is None or visibility is None:
            continue
        reference = vtkPenumbraReference()
        reference.SetGeometry(full)
        exact = vtkFloatArray()
        reference.ComputeVisibility(samples, light, exact)
        ties = reference.GetTies()
        alone = vtkPenumbraReference()
        alone.SetGeometry(local)
        local_only = vtkFloatArray()
        alone.ComputeVisibility(samples, light, local_only)
        for i in range(exact.GetNumberOfTuples()):
            e = exact.GetValue(i)
            if e < 0.0 or ties.GetValue(i):
                continue
            mismatches += (visibility.GetValue(i) < 0.5) != (e < 0.5)
            needed += (local_only.GetValue(i) < 0.5) != (e < 0.5)
    mismatches = all_sum(mismatches)
    check(mismatches == 0,
          "%s: %d view samples over all ranks disagree with the exact reference over all "
          "ranks' casters" % (technique, mismatches), everywhere=False)
    needed = all_sum(needed)
    check(ranks == 1 or needed > 0,
          "%s: %d samples are shadowed only by other ranks' casters" % (technique, needed),
          everywhere=False)


def image_check(view, technique):
    path = os.path.join(out_dir, "mpi-%s%s-np%d.png" % (prefix, technique, ranks))
    pvs.SaveScreenshot(path, view, ImageResolution=SIZE)
    reference_path = os.path.join(out_dir, "mpi-%s%s-np1.png" % (prefix, technique))
    differing = 0
    if rank == 0 and ranks > 1 and os.path.isfile(reference_path):
        differing = shadow_view.compare_images(path, reference_path)
        print("      %s (%s): %d pixels differ from the -np 1 image"
              % (technique, view.CasterExchange, differing))
    # A shadow map fitted to the view is fitted to the receivers each rank sees (composited
    # maps: all ranks' receivers, hidden ones included): its texels, and so its errors along
    # shadow edges, may differ from one process's; exact techniques may not differ at all.
    limit = 0 if technique in EXACT else SIZE[0] * SIZE[1] // 200
    check(all_sum(differing) <= limit,
          "%s: the image equals the -np 1 image (at most %d pixels differ)" % (technique, limit),
          everywhere=False)


def gather_stats(view):
    view.UpdatePropertyInformation()
    return (view.GetProperty("CasterGathers").GetData(),
            view.GetProperty("CasterGatherMs").GetData(),
            view.GetProperty("RemoteCasterTriangles").GetData(),
            view.GetProperty("CasterBytesReceived").GetData())


view, sphere = make_view()
for technique in techniques:
    # Exact techniques also with every rank keeping its own casters and sending rays.
    for mode in ("need", "distributed") if ranks > 1 and technique in EXACT + MAPS else ("need",):
        view.CasterExchange = mode
        view.ShadowTechnique = technique
        pvs.Render(view)
        view.UpdatePropertyInformation()
        check(view.GetProperty("InstalledShadowTechnique").GetData() == technique,
              "%s: installed" % technique)
        rank_view_check(view, technique)
        image_check(view, technique)
        if mode == "distributed" and technique in MAPS:
            check(view.GetProperty("RaysSent").GetData() == 0,
                  "%s (distributed): the maps are composited, no ray is sent" % technique)
        if mode == "distributed":
            if rank == 0:
                print("      " + view.GetProperty("CasterExchangeReport").GetData().replace(
                    "\n", "\n      "))
            pvs.Render(view)
            view.UpdatePropertyInformation()
            check(view.GetProperty("RaysSent").GetData() == 0 and
                  view.GetProperty("RayBytesSent").GetData() == 0,
                  "%s (distributed): an unchanged frame is reused, no ray sent" % technique)
view.CasterExchange = "need"
for technique, (most, casters) in stats.get("held", {}).items():
    if rank == 0:
        print("      %s: a rank holds at most %d of the %d caster triangles (%.1f %%)"
              % (technique, most, casters, 100.0 * most / max(casters, 1)))
    if scene == "terrain" and ranks > 1:
        check(3 * most <= casters, "%s: no rank holds more than a third of the casters for "
              "other ranks" % technique, everywhere=False)

# The checks below on the first technique, which is installed again first.
view.ShadowTechnique = techniques[0]
pvs.Render(view)
gathers = None
if ranks > 1:
    gathers, ms, remote, received = gather_stats(view)
    if rank == 0:
        print("      rank 0: %d exchanges, last %.2f ms, %d triangles (%d bytes) from other "
              "ranks" % (gathers, ms, remote, received))
        print("      " + view.GetProperty("CasterExchangeReport").GetData().replace(
            "\n", "\n      "))
    pvs.Render(view)
    check(gather_stats(view)[0] == gathers, "an unchanged frame exchanges no casters",
          everywhere=False)
if scene == "terrain":
    sphere.ScaleFactor = 1.2  # the hills grow
else:
    sphere.Center = [-1.0, -1.0, 1.6]
pvs.Render(view)
if gathers is not None:
    check(gather_stats(view)[0] == gathers + 1, "a moved caster is exchanged again",
          everywhere=False)
rank_view_check(view, techniques[0])
# Every caster to every rank: the same image as the need-based exchange's.
if ranks > 1:
    need_path = os.path.join(out_dir, "mpi-%sneed-np%d.png" % (prefix, ranks))
    all_path = os.path.join(out_dir, "mpi-%sall-np%d.png" % (prefix, ranks))
    pvs.SaveScreenshot(need_path, view, ImageResolution=SIZE)
    view.CasterExchange = "all"
    pvs.Render(view)
    rank_view_check(view, techniques[0])
    pvs.SaveScreenshot(all_path, view, ImageResolution=SIZE)
    differing = shadow_view.compare_images(need_path, all_path) if rank == 0 else 0
    check(all_sum(differing) == 0, "%s: exchanging all casters draws the same image as "
          "exchanging the needed ones" % techniques[0], everywhere=False)
    # Shadow maps are composited over the budget, as in distributed mode: that image.
    distributed_path = os.path.join(out_dir, "mpi-%sdistributed-np%d.png" % (prefix, ranks))
    if techniques[0] not in EXACT:
        view.CasterExchange = "distributed"
        pvs.Render(view)
        pvs.SaveScreenshot(distributed_path, view, ImageResolution=SIZE)
    view.CasterExchange = "need"
    # A budget no exchange fits in: the ranks keep their own casters and send rays instead.
    view.CasterMemoryBudget = 0.001
    pvs.Render(view)
    view.UpdatePropertyInformation()
    # The report of every rank's figures is on rank 0.
    distributed = rank == 0 and "(distributed)" in view.GetProperty(
        "CasterExchangeReport").GetData()
    check(all_sum(distributed) == 1,
          "a need-based exchange over the memory budget becomes distributed", everywhere=False)
    budget_path = os.path.join(out_dir, "mpi-%sbudget-np%d.png" % (prefix, ranks))
    rank_view_check(view, techniques[0])
    pvs.SaveScreenshot(budget_path, view, ImageResolution=SIZE)
    # Exact techniques draw the same image either way; the shadow maps composited over the
    # budget are those of the distributed mode.
    same_as = need_path if techniques[0] in EXACT else distributed_path
    differing = shadow_view.compare_images(same_as, budget_path) if rank == 0 else 0
    check(all_sum(differing) == 0, "%s: the image over the budget equals the %s one"
          % (techniques[0], "need-based" if same_as == need_path else "distributed"),
          everywhere=False)
    view.CasterMemoryBudget = 0

# An area (sphere) light in distributed mode sees each rank's own casters only: said.
if ranks > 1 and scene == "small":
    view.CasterExchange = "distributed"
    view.ShadowTechnique = "raytraced"
    sun = view.AdditionalLights[0]
    sun.Type = "Positional"
    sun.Position = [-6.0, -2.0, 6.0]
    sun.ConeAngle = 90.0
    sun.ShadowRadius = 0.5
    pvs.Render(view)
    check(any("own casters only" in m for m in messages),
          "distributed: a sphere light's rank-local shadows are reported")
    del messages[:]

check(not messages, "no error or warning reached the output window (%s)"
      % [m[:160] for m in messages[:1]])

failed = all_sum(len(failures), vtkCommunicator.MAX_OP)
if rank == 0:
    print("%d check(s) failed" % len(failures) if failed else "all checks passed")
sys.stdout.flush()
if failed:
    raise SystemExit(1)
