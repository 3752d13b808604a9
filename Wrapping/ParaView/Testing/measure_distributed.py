"""What distributed shadows cost each rank, per kind of frame (docs/paraview.md).

    mpirun -np N pvbatch --mpi --symmetric --disable-xdisplay-test measure_distributed.py \
        OUT.csv [MODE] [TERRAIN_RESOLUTION] [TECHNIQUE]

The terrain of the MPI test (shadow_view.show_terrain: 2 * RESOLUTION^2 triangles, default
708: about 1 M) split over the ranks, an oblique sun and a point light, 512 x 384 pixels,
CasterExchange MODE (need, all or distributed; default need), TECHNIQUE (default raytraced).
Five frames: the first, a static one, a camera move, a light move and a data change. Per
frame and rank: the wall time of the render, the bytes sent and received (caster exchange
and ray queries), the other ranks' triangles held, the rays sent; per rank the peak
resident memory. Rank 0 appends one row per frame to OUT.csv (created with a header):
ranks, mode, frame, triangles, the maximum and mean over the ranks of frame ms, bytes sent,
bytes received, triangles held, rays sent, and the maximum peak RSS (MiB).
"""
import os
import resource
import sys
import time

import paraview.simple as pvs

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import shadow_view  # noqa: E402

shadow_view.load_plugin(globals())

from vtkmodules.vtkCommonCore import vtkDoubleArray  # noqa: E402
from vtkmodules.vtkParallelCore import vtkCommunicator, vtkMultiProcessController  # noqa: E402

out_csv = sys.argv[1]
mode = sys.argv[2] if len(sys.argv) > 2 else "need"
resolution = int(sys.argv[3]) if len(sys.argv) > 3 else 708
technique = sys.argv[4] if len(sys.argv) > 4 else "raytraced"
controller = vtkMultiProcessController.GetGlobalController()
rank = controller.GetLocalProcessId()
ranks = controller.GetNumberOfProcesses()

view = shadow_view.sun_view([512, 384], [-2.0, -1.0, 1.2])
view.AdditionalLights[0].Intensity = 0.7
view.UseFXAA = 0
terrain = shadow_view.show_terrain(view, resolution)
shadow_view.add_point_light(view, [10.0, 5.0, 30.0])
view.CasterExchange = mode
view.ShadowTechnique = technique


def figures():
    view.UpdatePropertyInformation()
    get = lambda name: float(view.GetProperty(name).GetData())  # noqa: E731
    return {"exchanges": get("CasterGathers"), "sent": get("CasterBytesSent"),
            "received": get("CasterBytesReceived"), "held": get("RemoteCasterTriangles"),
            "rays": get("RaysSent"), "ray_sent": get("RayBytesSent"),
            "ray_received": get("RayBytesReceived")}


def reduce(values):
    """(max, mean) over the ranks of each value."""
    send, total, most = vtkDoubleArray(), vtkDoubleArray(), vtkDoubleArray()
    for v in values:
        send.InsertNextValue(v)
    controller.AllReduce(send, total, vtkCommunicator.SUM_OP)
    controller.AllReduce(send, most, vtkCommunicator.MAX_OP)
    return [(most.GetValue(i), total.GetValue(i) / ranks) for i in range(len(values))]


def frame(name, change):
    before = figures()
    change()
    controller.Barrier()
    start = time.perf_counter()
    pvs.Render(view)
    ms = 1000.0 * (time.perf_counter() - start)
    after = figures()
    exchanged = after["exchanges"] > before["exchanges"]
    sent = (after["sent"] if exchanged else 0.0) + after["ray_sent"]
    received = (after["received"] if exchanged else 0.0) + after["ray_received"]
    # Nothing is sent in a frame without an exchange but one 4-byte all-reduce.
    if not exchanged:
        sent += 4.0
        received += 4.0
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    stats = reduce([ms, sent, received, after["held"], after["rays"], peak])
    if rank == 0:
        new = not os.path.isfile(out_csv)
        with open(out_csv, "a") as f:
            if new:
                f.write("ranks,mode,frame,triangles,max_frame_ms,mean_frame_ms,max_bytes_sent,"
                        "mean_bytes_sent,max_bytes_received,mean_bytes_received,max_held,"
                        "mean_held,max_rays_sent,mean_rays_sent,max_peak_rss_mib\n")
            cells = [str(ranks), mode, name, str(2 * resolution * resolution)]
            for most, mean in stats[:5]:
                cells += ["%.1f" % most, "%.1f" % mean]
            cells.append("%.0f" % stats[5][0])
            f.write(",".join(cells) + "\n")
        print("%s: %s" % (name, ", ".join(cells[4:])))
        sys.stdout.flush()


def move_camera():
    camera = pvs.GetActiveCamera()
    camera.Azimuth(10.0)


def move_light():
    view.AdditionalLights[0].Position = [-2.0, -1.2, 1.1]


def change_data():
    terrain.ScaleFactor = 1.1


frame("first", lambda: None)
frame("static", lambda: None)
frame("camera", move_camera)
frame("light", move_light)
frame("data", change_data)
