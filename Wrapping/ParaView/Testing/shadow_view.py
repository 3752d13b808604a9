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
    RedistributeDataSet (each cell on one rank) and shows it in `view`, uncoloured, after one
    render. The camera looks at the origin from the front and above."""
    parts = [pvs.Triangulate(Input=s) for s in sources]
    scene = pvs.RedistributeDataSet(Input=pvs.AppendDatasets(Input=parts))
    scene.BoundaryMode = "Assign to one region"
    display = pvs.Show(scene, view)
    display.ColorArrayName = ["POINTS", ""]
    # paraview.simple resets the camera at a view's first render in pvbatch, not always in a
    # client: one render first, so that the camera is this one everywhere.
    pvs.Render(view)
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


def show_terrain(view, resolution=708):
    """Rolling hills over [-50, 50]^2 (a plane of `resolution`^2 squares, 2 triangles each:
    about 1 M triangles by default) shown in `view` split over the ranks (show_split), seen
    from above and the south. Returns the warped surface."""
    plane = pvs.Plane(Origin=[-50, -50, 0], Point1=[50, -50, 0], Point2=[-50, 50, 0],
                      XResolution=resolution, YResolution=resolution)
    hills = pvs.Calculator(Input=plane, ResultArrayName="height",
                           Function="3*sin(coordsX*0.21)*cos(coordsY*0.17)"
                                    "+1.5*sin(coordsX*0.05+coordsY*0.09)")
    terrain = pvs.WarpByScalar(Input=hills, Scalars=["POINTS", "height"],
                               Normal=[0, 0, 1], UseNormal=1)
    show_split(view, (terrain,))
    look_at(view, [0.0, -78.0, 62.0], [0.0, -2.0, -3.0])
    return terrain


def add_point_light(view, position):
    """A point light (all directions) at `position`, scene coordinates."""
    light = pvs.AddLight(view=view)
    light.Coords = "Scene"
    light.Type = "Positional"
    light.Position = position
    light.FocalPoint = [position[0], position[1], 0.0]
    light.ConeAngle = 90.0
    light.Intensity = 0.45
    return light


def compare_images(path, reference_path, tolerance=2):
    """The number of pixels whose colour differs by more than `tolerance` levels in some
    channel between two PNG images of one size; -1 when their sizes differ."""
    from vtkmodules.vtkIOImage import vtkPNGReader
    images = []
    for p in (path, reference_path):
        reader = vtkPNGReader()
        reader.SetFileName(p)
        reader.Update()
        images.append(reader.GetOutput().GetPointData().GetScalars())
    a, b = images
    if a.GetNumberOfTuples() != b.GetNumberOfTuples():
        return -1
    differing = 0
    for i in range(a.GetNumberOfTuples()):
        ta, tb = a.GetTuple(i), b.GetTuple(i)
        differing += max(abs(ta[c] - tb[c]) for c in range(3)) > tolerance
    return differing
