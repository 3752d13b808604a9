"""What the PenumbraShadows view's caster gather costs each rank (docs/paraview.md).

    mpirun -np N pvbatch --mpi --symmetric --disable-xdisplay-test measure_caster_gather.py \
        [SPHERE_RESOLUTION] [TECHNIQUE]

A ground plane and a sphere of about 2 * RESOLUTION^2 / 2 triangles (default 700: ~0.5 M),
split over the ranks by RedistributeDataSet, one directional light, 512 x 512 pixels. Each
rank prints one line: its own triangles, the triangles and bytes it received, the first
gather's time, the time of a frame that gathers nothing, the remote casters' memory and the
process's peak resident memory.
"""
import os
import resource
import sys
import time

import paraview.simple as pvs

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import shadow_view  # noqa: E402

shadow_view.load_plugin(globals())

import penumbra  # noqa: E402,F401
from penumbra.vtkPenumbraScene import vtkPenumbraSceneGeometry  # noqa: E402
from vtkmodules.vtkParallelCore import vtkMultiProcessController  # noqa: E402

resolution = int(sys.argv[1]) if len(sys.argv) > 1 else 700
technique = sys.argv[2] if len(sys.argv) > 2 else "raytraced"
controller = vtkMultiProcessController.GetGlobalController()
rank = controller.GetLocalProcessId()

view = shadow_view.sun_view([512, 512], [-6.0, -2.0, 6.0])
ground = pvs.Plane(Origin=[-5, -5, 0], Point1=[5, -5, 0], Point2=[-5, 5, 0],
                   XResolution=64, YResolution=64)
sphere = pvs.Sphere(Center=[0.0, 0.0, 1.8], Radius=1.2, ThetaResolution=resolution,
                    PhiResolution=resolution)
shadow_view.show_split(view, (ground, sphere))
view.ShadowTechnique = technique

pvs.Render(view)
view.UpdatePropertyInformation()
first_ms = view.GetProperty("CasterGatherMs").GetData()
start = time.perf_counter()
pvs.Render(view)
still_ms = 1000.0 * (time.perf_counter() - start)
view.UpdatePropertyInformation()
gathers = view.GetProperty("CasterGathers").GetData()
remote = view.GetProperty("RemoteCasterTriangles").GetData()
received = view.GetProperty("CasterBytesReceived").GetData()
local = vtkPenumbraSceneGeometry()
local.Update(view.GetClientSideObject().GetRenderer())
peak_mib = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
line = ("rank %d: %d local triangles, %d received (%.1f MiB), gather %.1f ms, "
        "still frame %.1f ms (%d gathers in 2 frames), peak RSS %.0f MiB" %
        (rank, local.GetNumberOfTriangles(), remote, received / 1048576.0, first_ms, still_ms,
         gathers, peak_mib))
# One rank after the other, so that the lines do not interleave.
for r in range(controller.GetNumberOfProcesses()):
    if r == rank:
        print(line)
        sys.stdout.flush()
    controller.Barrier()
