"""Run by gui_check.sh in the ParaView GUI (paraview --script=gui_check.py), connected to a
headless pvserver: replaces the GUI's render view by a PenumbraShadowView, shows a ground and
a box split over the server's ranks lit by one sphere light (a positional light with a Shadow
Radius), renders remotely with `gears` (soft shadows), leaves no source selected (so the
Properties panel shows the view's section) and
writes GUI_CHECK_READY (an environment variable: a file path) with its process id and the
properties it read, for the shell script to take the screenshot.
"""
import os

import paraview.simple as pvs

layout = pvs.GetLayout()
for old in list(pvs.GetViews()):
    pvs.Delete(old)
view = pvs.CreateView("PenumbraShadowView")
pvs.AssignViewToLayout(view=view, layout=layout, hint=0)
view.RemoteRenderThreshold = 0.0  # render on the server
view.OrientationAxesVisibility = 0
ground = pvs.Plane(Origin=[-4, -4, 0], Point1=[4, -4, 0], Point2=[-4, 4, 0],
                   XResolution=16, YResolution=16)
box = pvs.Box(XLength=2.0, YLength=2.0, ZLength=1.0, Center=[0.0, 0.0, 1.5])
scene = pvs.RedistributeDataSet(Input=pvs.AppendDatasets(
    Input=[pvs.Triangulate(Input=ground), pvs.Triangulate(Input=box)]))
display = pvs.Show(scene, view)
display.ColorArrayName = ["POINTS", ""]
view.CameraPosition = [0.0, -9.0, 9.0]
view.CameraFocalPoint = [0.0, 0.0, 0.5]
view.CameraViewUp = [0.0, 0.0, 1.0]
view.UseLight = 0  # the light kit off: the sphere light alone
light = pvs.AddLight(view=view)
light.Coords = "Scene"
light.Type = "Positional"
light.Position = [2.0, -2.0, 7.0]
light.FocalPoint = [0.0, 0.0, 0.0]
light.ConeAngle = 90.0
light.ShadowRadius = 1.0
view.ShadowTechnique = "gears"
pvs.Render(view)
pvs.Render(view)
pvs.SetActiveSource(None)
pvs.SetActiveView(view)
view.UpdatePropertyInformation()
with open(os.environ["GUI_CHECK_READY"], "w") as ready:
    ready.write("pid %d\n" % os.getpid())
    for name in ("ShadowTechnique", "InstalledShadowTechnique", "CasterGathers",
                 "RemoteCasterTriangles"):
        ready.write("%s %s\n" % (name, view.GetProperty(name).GetData()))
    ready.write("Light %s\n" % view.GetProperty("ShadowReport").GetData().split("\n")[0])
