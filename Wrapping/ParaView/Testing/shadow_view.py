"""Shared by the plugin's test scripts: a PenumbraShadowView lit by one sun, and a scene spread
over the MPI ranks."""
import os
import sys

import paraview.simple as pvs


def load_plugin(ns, plugin=None):
    """Loads PenumbraShadows.so (`plugin`, default: the first folder of PV_PLUGIN_PATH) into
    the namespace `ns` (the script's globals()); exits with a message when it is missing."""
    if plugin is None:
        plugin_dir = os.environ.get("PV_PLUGIN_PATH", "").split(os.pathsep)[0]
        plugin = os.path.join(plugin_dir, "PenumbraShadows.so")
    if not os.path.isfile(plugin):
        sys.exit("no plugin at %r: pass PenumbraShadows.so's path or set PV_PLUGIN_PATH" % plugin)
    pvs.LoadPlugin(plugin, remote=False, ns=ns)


def look_at(view, position, focal_point):
    """The camera at `position` looking at `focal_point`, z up."""
    view.CameraPosition = position
    view.CameraFocalPoint = focal_point
    view.CameraViewUp = [0.0, 0.0, 1.0]


def sun_view(size, sun_position):
    """A PenumbraShadowView of `size` pixels lit only by a directional scene light shining from
    `sun_position` towards the origin (ParaView's light kit off)."""
    view = pvs.CreateView("PenumbraShadowView")
    view.ViewSize = size
    view.OrientationAxesVisibility = 0
    view.UseLight = 0
    sun = pvs.AddLight(view=view)
    sun.Coords = "Scene"
    sun.Type = "Directional"
    sun.Position = sun_position
    sun.FocalPoint = [0.0, 0.0, 0.0]
    return view


def show_split(view, sources):
    """Triangulates `sources`, appends them into one data set spread over the ranks by
    RedistributeDataSet (each cell on one rank) and shows it in `view`, uncoloured. The
    camera looks at the origin from the front and above."""
    parts = [pvs.Triangulate(Input=s) for s in sources]
    scene = pvs.RedistributeDataSet(Input=pvs.AppendDatasets(Input=parts))
    scene.BoundaryMode = "Assign to one region"
    display = pvs.Show(scene, view)
    display.ColorArrayName = ["POINTS", ""]
    look_at(view, [2.0, -11.0, 9.0], [0.0, 0.0, 0.5])
    return scene


def show_ground_box_sphere(view):
    """A ground plane, a box and a sphere that shadow the ground under an oblique sun, shown
    in `view` split over the ranks (show_split). Returns the sphere's source."""
    ground = pvs.Plane(Origin=[-5, -5, 0], Point1=[5, -5, 0], Point2=[-5, 5, 0],
                       XResolution=24, YResolution=24)
    box = pvs.Box(XLength=1.5, YLength=1.5, ZLength=1.0, Center=[1.5, 1.0, 1.2])
    sphere = pvs.Sphere(Center=[-1.0, -1.5, 1.6], Radius=0.9, ThetaResolution=24,
                        PhiResolution=16)
    show_split(view, (ground, box, sphere))
    return sphere
