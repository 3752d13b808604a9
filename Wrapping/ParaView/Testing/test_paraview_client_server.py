"""The PenumbraShadows plugin in client/server mode: pvpython connected to a headless
`mpirun -np 2 pvserver`, which this script starts (twice) on a free port.

    pvpython test_paraview_client_server.py [OUTDIR [PVBATCH_IMAGE [REPEATS]]]

Needs no DISPLAY (both the client and the server draw with Penumbra's EGL window),
penumbra_paraview on PYTHONPATH and the plugin in the first folder of PV_PLUGIN_PATH;
./penumbra.sh paraview runs it. As root, OpenMPI needs OMPI_ALLOW_RUN_AS_ROOT and
OMPI_ALLOW_RUN_AS_ROOT_CONFIRM (set here for the server) and --oversubscribe.

1. A server that loaded the plugin from its PV_PLUGIN_PATH: penumbra_paraview.load_plugin
   loads nothing and raises nothing (LoadPlugin(remote=True) raises here, see its module).
   Remote rendering (RemoteRenderThreshold 0) of a ground, a box and a sphere split over the
   two ranks, `raytraced`:
   - no error reaches the client and the server logs none (the GLEW message of ParaView's
     offscreen view window is dropped);
   - the statistics properties are the server's: a gather happened, triangles and bytes came
     from the other rank, ShadowReport names the technique; an unchanged frame gathers
     nothing;
   - the image is darker than without shadows;
   - a refused technique, and a technique with a refused option, put ShadowTechnique and
     ShadowOptions back to what draws.
2. A server without the plugin: load_plugin loads it there, and the view draws with it.
3. With PVBATCH_IMAGE (test_paraview_mpi.py's mpi-raytraced-np4.png): the same scene on a
   4-rank pvserver draws the same image, pixel for pixel, REPEATS times (default 1), each
   with a new server, none of them hanging.

Exit status 0 when every check passed. OUTDIR (default .) receives the server logs and
images.
"""
import gc
import os
import signal
import socket
import subprocess
import sys
import time

import paraview.simple as pvs
from paraview import servermanager
from vtkmodules.util.misc import calldata_type
from vtkmodules.util.vtkConstants import VTK_STRING
from vtkmodules.vtkCommonCore import vtkCommand, vtkOutputWindow

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import shadow_view  # noqa: E402
import penumbra_paraview  # noqa: E402

out_dir = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else ".")
failures = []
messages = []  # errors and warnings that reached this process's output window


def check(ok, what):
    print(("ok    " if ok else "FAIL  ") + what)
    sys.stdout.flush()
    if not ok:
        failures.append(what)


@calldata_type(VTK_STRING)
def on_message(_window, _event, text):
    messages.append(text)


output = vtkOutputWindow.GetInstance()
output.AddObserver(vtkCommand.ErrorEvent, on_message)
output.AddObserver(vtkCommand.WarningEvent, on_message)


def free_port():
    with socket.socket() as s:
        s.bind(("localhost", 0))
        return s.getsockname()[1]


class Server:
    """`mpirun -np RANKS pvserver` on a free port, without DISPLAY, with or without the plugin
    on its PV_PLUGIN_PATH; its output goes to OUTDIR/NAME.log. Stopped (TERM, then KILL) by pid
    on exit."""

    def __init__(self, name, with_plugin, ranks=2):
        self.log_path = os.path.join(out_dir, name + ".log")
        self.port = free_port()
        # pvpython initialised MPI as a singleton: its OMPI_/PMIX_ variables would make the
        # server's mpirun think it runs inside a job.
        env = {k: v for k, v in os.environ.items()
               if not k.startswith(("OMPI_", "PMIX_", "PRTE_")) and k != "DISPLAY"}
        env.update(OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
        if not with_plugin:
            env.pop("PV_PLUGIN_PATH", None)
        # --disable-xdisplay-test: without it a server with no X display reports that it
        # cannot render, and ParaView renders everything on the client instead.
        command = ["timeout", "-s", "KILL", "600", "mpirun", "--oversubscribe", "-np", str(ranks),
                   "pvserver", "--disable-xdisplay-test", "--server-port=%d" % self.port]
        self.log = open(self.log_path, "w")
        self.process = subprocess.Popen(command, env=env, stdout=self.log,
                                        stderr=subprocess.STDOUT)

    def __enter__(self):
        deadline = time.time() + 120
        while time.time() < deadline and self.process.poll() is None:
            with open(self.log_path) as log:
                if "Accepting connection" in log.read():
                    pvs.Connect("localhost", self.port, timeout=60)
                    return self
            time.sleep(0.5)
        raise RuntimeError("pvserver did not start (exit status %s); see %s"
                           % (self.process.poll(), self.log_path))

    def __exit__(self, *exc):
        if servermanager.ActiveConnection is not None:
            # Nothing of this session may outlive it: a proxy destroyed later writes to the
            # closed socket. The checks keep their proxies in locals of functions that have
            # returned; the simple module's and the proxy manager's references go here.
            pvs.SetActiveView(None)
            pvs.SetActiveSource(None)
            servermanager.ProxyManager().UnRegisterProxies()
            gc.collect()
            pvs.Disconnect()
        if self.process.poll() is None:
            self.process.send_signal(signal.SIGTERM)
        try:
            self.process.wait(timeout=30)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()
        self.log.close()
        return False

    def errors(self):
        """The server's error lines (loguru marks them ERR)."""
        with open(self.log_path) as log:
            return [line for line in log if " ERR| " in line or "ERROR:" in line]


def make_view():
    """The scene, view and light of test_paraview_mpi.py's small scene, rendered on the
    server (FXAA off there too, so the images compare pixel for pixel)."""
    view = shadow_view.sun_view([192, 192], [-6.0, -2.0, 6.0])
    view.RemoteRenderThreshold = 0.0  # always render on the server
    view.UseFXAA = 0
    shadow_view.show_ground_box_sphere(view)
    return view


def statistics(view):
    view.UpdatePropertyInformation()
    return {name: view.GetProperty(name).GetData() for name in
            ("InstalledShadowTechnique", "ShadowReport", "CasterGathers", "CasterGatherMs",
             "RemoteCasterTriangles", "CasterBytesReceived")}


def mean_luminance(view, name):
    path = os.path.join(out_dir, "client-server-%s.png" % name)
    pvs.SaveScreenshot(path, view, ImageResolution=[192, 192])
    from vtkmodules.vtkIOImage import vtkPNGReader
    reader = vtkPNGReader()
    reader.SetFileName(path)
    reader.Update()
    scalars = reader.GetOutput().GetPointData().GetScalars()
    n = scalars.GetNumberOfTuples()
    return sum(sum(scalars.GetTuple(i)[:3]) / 3.0 for i in range(n)) / n


def check_refusals(view):
    """A refused technique and a refused option put the request back to what draws."""
    del messages[:]
    view.ShadowTechnique = "nonexistent"
    pvs.Render(view)
    check(view.ShadowTechnique == "raytraced",
          "refused technique: ShadowTechnique is back to what draws (%r)" % view.ShadowTechnique)
    check(len(messages) > 0, "refused technique: the refusal is reported (%d messages)"
          % len(messages))
    view.ShadowTechnique = "shadowmap"
    view.ShadowOptions = '{"no_such_option": 1}'
    pvs.Render(view)
    check(view.ShadowTechnique == "raytraced" and view.ShadowOptions == "",
          "refused option: ShadowTechnique and ShadowOptions are back to what draws (%r, %r)"
          % (view.ShadowTechnique, view.ShadowOptions))
    check(statistics(view)["InstalledShadowTechnique"] == "raytraced",
          "refused option: raytraced still draws")


def remote_rendering_checks():
    view = make_view()
    view.ShadowTechnique = "none"
    pvs.Render(view)
    unshadowed = mean_luminance(view, "none")
    del messages[:]
    view.ShadowTechnique = "raytraced"
    pvs.Render(view)
    shadowed = mean_luminance(view, "raytraced")
    check(messages == [], "no error or warning reached the client while rendering (%d: %s)"
          % (len(messages), [m[:120] for m in messages[:2]]))
    stats = statistics(view)
    check(stats["InstalledShadowTechnique"] == "raytraced", "raytraced installed (%s)"
          % stats["InstalledShadowTechnique"])
    check(stats["CasterGathers"] >= 1 and stats["CasterGatherMs"] > 0.0,
          "the server's gather statistics reach the client (%d gathers, %.2f ms)"
          % (stats["CasterGathers"], stats["CasterGatherMs"]))
    check(stats["RemoteCasterTriangles"] > 0 and
          stats["CasterBytesReceived"] >= 72 * stats["RemoteCasterTriangles"],
          "rank 0 received the other rank's casters (%d triangles, %d bytes)"
          % (stats["RemoteCasterTriangles"], stats["CasterBytesReceived"]))
    check("raytraced - " in stats["ShadowReport"] and "figures:" in stats["ShadowReport"],
          "ShadowReport is the server's (%r)" % stats["ShadowReport"][:80])
    pvs.Render(view)
    check(statistics(view)["CasterGathers"] == stats["CasterGathers"],
          "an unchanged frame gathers no casters")
    check(shadowed < unshadowed - 1.0, "the image is darker than without shadows "
          "(%.1f vs %.1f)" % (shadowed, unshadowed))
    check_refusals(view)
    check_light_size(view)


def check_light_size(view):
    """The light's ShadowRadius reaches the server's ranks: the server's report names the
    disc, and the soft shadow changes the image."""
    light = view.AdditionalLights[0]
    light.Type = "Positional"
    light.Position = [-3.0, -1.0, 6.0]
    light.ConeAngle = 90.0  # all directions: a point light
    view.ShadowTechnique = "gears"
    pvs.Render(view)
    hard = mean_luminance(view, "point-light")
    check("(point light): " in statistics(view)["ShadowReport"], "ShadowRadius 0: a point light")
    light.ShadowRadius = 0.5
    pvs.Render(view)
    report = statistics(view)["ShadowReport"]
    check("(disc light of diameter 1, 52 samples): gears" in report,
          "ShadowRadius 0.5 reaches the server: %r" % report[:90])
    check(mean_luminance(view, "sphere-light") != hard, "the sphere light's image differs")
    light.ShadowRadius = 0.0


def session_with_plugin():
    with Server("pvserver-with-plugin", with_plugin=True) as server:
        loaded = penumbra_paraview.load_plugin(ns=globals())
        check(loaded == [], "server with the plugin: load_plugin loads nothing (%s)" % loaded)
        remote_rendering_checks()
    errors = [e for e in server.errors() if "refused" not in e]
    check(errors == [], "the server logged no error except the refusals (%d: %s)"
          % (len(errors), [e[:160] for e in errors[:2]]))


def loaded_plugin_checks():
    view = make_view()
    view.ShadowTechnique = "raytraced"
    pvs.Render(view)
    stats = statistics(view)
    check(stats["InstalledShadowTechnique"] == "raytraced" and stats["CasterGathers"] >= 1,
          "the plugin loaded on the server draws and gathers (%s, %d gathers)"
          % (stats["InstalledShadowTechnique"], stats["CasterGathers"]))


def session_without_plugin():
    with Server("pvserver-without-plugin", with_plugin=False):
        loaded = penumbra_paraview.load_plugin(ns=globals())
        check(loaded == ["server"], "server without the plugin: load_plugin loads it there (%s)"
              % loaded)
        loaded_plugin_checks()


def four_rank_checks(reference, run):
    view = make_view()
    view.ShadowTechnique = "raytraced"
    pvs.Render(view)
    path = os.path.join(out_dir, "client-server-4-ranks-%d.png" % run)
    pvs.SaveScreenshot(path, view, ImageResolution=[192, 192])
    stats = statistics(view)
    report = penumbra_paraview.exchange_report(view)
    if run == 1:
        print(report)
    check(report.count("\nrank ") == 4 and "(need)" in report,
          "4-rank pvserver: the client reads every rank's exchange figures")
    differing = shadow_view.compare_images(path, reference)
    check(differing == 0 and stats["RemoteCasterTriangles"] > 0,
          "4-rank pvserver, run %d: the image equals pvbatch's on 4 ranks (%d pixels "
          "differ; rank 0 holds %d triangles of the others)"
          % (run, differing, stats["RemoteCasterTriangles"]))


def session_four_ranks(reference, run):
    """pvpython on a 4-rank pvserver draws the image pvbatch draws on 4 ranks. The checks'
    proxies are gone (their function returned) before the session ends."""
    with Server("pvserver-4-ranks", with_plugin=True, ranks=4):
        penumbra_paraview.load_plugin(ns=globals())
        four_rank_checks(reference, run)


os.makedirs(out_dir, exist_ok=True)
session_with_plugin()
session_without_plugin()
# With pvbatch's 4-rank image of the same scene (test_paraview_mpi.py), the same image from a
# 4-rank pvserver, REPEATS times.
if len(sys.argv) > 2:
    for run in range(int(sys.argv[3]) if len(sys.argv) > 3 else 1):
        session_four_ranks(os.path.abspath(sys.argv[2]), run + 1)
print("%d check(s) failed" % len(failures) if failures else "all checks passed")
sys.stdout.flush()
sys.exit(1 if failures else 0)
