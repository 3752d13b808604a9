"""The prop contract as scenes: one small scene per kind of prop a VTK script holds, each over
a ground plane under a sun, with what the contract says it does under shadows (see
docs/prop-contract.md): it is always drawn as plain VTK draws it; `receives` whether its
own surface gets shadows; `casts` what its shadow on the ground must look like, as a check
on the exact reference's visibility of the ground samples.

Every scene is written here from scratch (small enough to read); the kinds are those the
Kitware examples and ordinary VTK scripts use."""

import numpy as np
from vtkmodules.util.numpy_support import numpy_to_vtk
from vtkmodules.vtkCommonCore import vtkPoints
from vtkmodules.vtkCommonDataModel import (vtkCellArray, vtkImageData, vtkMultiBlockDataSet,
                                           vtkPlane, vtkPlaneCollection, vtkPolyData)
from vtkmodules.vtkFiltersCore import vtkElevationFilter
from vtkmodules.vtkFiltersModeling import vtkOutlineFilter
from vtkmodules.vtkFiltersSources import vtkConeSource, vtkPlaneSource, vtkSphereSource
from vtkmodules.vtkRenderingOpenGL2 import vtkCompositePolyDataMapper2
from vtkmodules.vtkRenderingCore import (vtkActor, vtkAssembly, vtkColorTransferFunction,
                                         vtkDataSetMapper,
                                         vtkFollower, vtkGlyph3DMapper, vtkImageActor,
                                         vtkLight, vtkPointGaussianMapper, vtkPolyDataMapper,
                                         vtkSkybox, vtkTextActor, vtkTexture, vtkVolume,
                                         vtkVolumeProperty)
from vtkmodules.vtkRenderingLOD import vtkLODActor
from vtkmodules.vtkRenderingVolumeOpenGL2 import vtkSmartVolumeMapper
import vtkmodules.vtkRenderingFreeType  # noqa: F401  (text actors)
import vtkmodules.vtkRenderingVolumeOpenGL2  # noqa: F401

# Where the props stand: above the ground's centre, the sun from the upper left. The camera
# sees the ground, the prop and its shadow.
CENTER = (0.0, 0.0, 1.5)


def _keep(obj, *sources):
    obj._penumbra_sources = sources  # the pipeline lives as long as the prop
    return obj


def polydata_actor(source, color=(0.9, 0.55, 0.25), mapper=None):
    mapper = mapper or vtkPolyDataMapper()
    mapper.SetInputConnection(source.GetOutputPort())
    actor = vtkActor()
    actor.SetMapper(mapper)
    actor.GetProperty().SetColor(*color)
    return _keep(actor, source, mapper)


def sphere(radius=0.8, center=CENTER, res=24):
    s = vtkSphereSource()
    s.SetCenter(*center)
    s.SetRadius(radius)
    s.SetThetaResolution(res)
    s.SetPhiResolution(res // 2)
    return s


def point_cloud(count, radius=0.7, center=CENTER):
    """`count` points spread over a sphere (a Fibonacci lattice: the same every run), as
    vertex cells."""
    i = np.arange(count) + 0.5
    z = 1.0 - 2.0 * i / count
    r = np.sqrt(1.0 - z * z)
    phi = np.pi * (1.0 + 5 ** 0.5) * i
    xyz = np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=1) * radius + np.array(center)
    poly = vtkPolyData()
    points = vtkPoints()
    points.SetData(numpy_to_vtk(xyz, deep=1))
    poly.SetPoints(points)
    verts = vtkCellArray()
    for k in range(count):
        verts.InsertNextCell(1)
        verts.InsertCellPoint(k)
    poly.SetVerts(verts)
    return poly


class Static:
    """A pipeline stage holding fixed data (for polydata_actor)."""

    def __init__(self, data):
        from vtkmodules.vtkFiltersCore import vtkPassThrough
        self.Filter = vtkPassThrough()
        self.Filter.SetInputData(data)
        self.Data = data

    def GetOutputPort(self):
        return self.Filter.GetOutputPort()


def half_alpha_texture(interpolate):
    """A 16 x 16 RGBA texture: opaque green on the left half, alpha 0 on the right."""
    image = vtkImageData()
    image.SetDimensions(16, 16, 1)
    texels = np.zeros((16, 16, 4), np.uint8)
    texels[..., :3] = (40, 200, 40)
    texels[:, :8, 3] = 255
    image.GetPointData().SetScalars(numpy_to_vtk(texels.reshape(-1, 4), deep=1))
    texture = vtkTexture()
    texture.SetInputData(image)
    texture.SetInterpolate(interpolate)
    return _keep(texture, image)


def card(alpha_texture=None, textured=False):
    """A 1.6 x 1.6 card facing the sun's side, textured."""
    plane = vtkPlaneSource()
    plane.SetOrigin(-0.8, 0.0, 0.7)
    plane.SetPoint1(0.8, 0.0, 0.7)
    plane.SetPoint2(-0.8, 0.0, 2.3)
    actor = polydata_actor(plane, (1, 1, 1))
    if alpha_texture is not None:
        actor.SetTexture(alpha_texture)
    elif textured:
        image = vtkImageData()
        image.SetDimensions(8, 8, 1)
        texels = np.random.default_rng(1).integers(60, 255, (64, 3)).astype(np.uint8)
        image.GetPointData().SetScalars(numpy_to_vtk(texels, deep=1))
        texture = vtkTexture()
        texture.SetInputData(image)
        actor.SetTexture(_keep(texture, image))
    return actor


# --- the rows: each returns the props to add (the ground and sun are added by the runner) ---

def row_surface():
    return [polydata_actor(sphere())]


def row_scalar_colors():
    elevation = vtkElevationFilter()
    source = sphere()
    elevation.SetInputConnection(source.GetOutputPort())
    elevation.SetLowPoint(0, 0, 0.7)
    elevation.SetHighPoint(0, 0, 2.3)
    return [_keep(polydata_actor(elevation), elevation, source)]


def row_edges():
    actor = polydata_actor(sphere(res=12))
    actor.GetProperty().EdgeVisibilityOn()
    actor.GetProperty().SetLineWidth(2)
    return [actor]


def row_wireframe():
    actor = polydata_actor(sphere(res=8))
    actor.GetProperty().SetRepresentationToWireframe()
    return [actor]


def row_points():
    actor = polydata_actor(sphere(res=8))
    actor.GetProperty().SetRepresentationToPoints()
    actor.GetProperty().SetPointSize(2)
    return [actor]


def row_outline():
    outline = vtkOutlineFilter()
    source = sphere()
    outline.SetInputConnection(source.GetOutputPort())
    actor = _keep(polydata_actor(outline, (0.1, 0.1, 0.1)), outline, source)
    return [actor]


def row_tubes():
    outline = vtkOutlineFilter()
    source = sphere()
    outline.SetInputConnection(source.GetOutputPort())
    actor = _keep(polydata_actor(outline, (0.2, 0.3, 0.9)), outline, source)
    actor.GetProperty().SetLineWidth(2)
    actor.GetProperty().RenderLinesAsTubesOn()
    return [actor]


def row_spheres():
    actor = polydata_actor(Static(point_cloud(20, 0.8)), (0.9, 0.2, 0.2))
    actor.GetProperty().SetPointSize(4)
    actor.GetProperty().RenderPointsAsSpheresOn()
    return [actor]


def row_glyphs():
    points = vtkPolyData()
    pts = vtkPoints()
    for x in (-0.6, 0.0, 0.6):
        for y in (-0.6, 0.6):
            pts.InsertNextPoint(x, y, 1.5)
    points.SetPoints(pts)
    cone = vtkConeSource()
    cone.SetResolution(12)
    mapper = vtkGlyph3DMapper()
    mapper.SetInputData(points)
    mapper.SetSourceConnection(cone.GetOutputPort())
    mapper.SetScaleFactor(0.5)
    actor = vtkActor()
    actor.SetMapper(mapper)
    actor.GetProperty().SetColor(0.3, 0.7, 0.3)
    return [_keep(actor, points, cone, mapper)]


def row_splats():
    points = Static(point_cloud(30))
    mapper = vtkPointGaussianMapper()
    mapper.SetInputConnection(points.GetOutputPort())
    mapper.SetScaleFactor(0.05)
    actor = vtkActor()
    actor.SetMapper(mapper)
    return [_keep(actor, points, mapper)]


def row_composite():
    blocks = vtkMultiBlockDataSet()
    for i, x in enumerate((-0.6, 0.6)):
        s = sphere(0.45, (x, 0, 1.5))
        s.Update()
        blocks.SetBlock(i, s.GetOutput())
    mapper = vtkCompositePolyDataMapper2()
    mapper.SetInputDataObject(blocks)
    actor = vtkActor()
    actor.SetMapper(mapper)
    return [_keep(actor, blocks, mapper)]


def row_dataset_mapper():
    from vtkmodules.vtkFiltersCore import vtkDelaunay3D
    delaunay = vtkDelaunay3D()
    delaunay.SetInputData(point_cloud(80, 0.8))
    return [polydata_actor(delaunay, mapper=vtkDataSetMapper())]


def row_lod_actor():
    s = sphere()
    mapper = vtkPolyDataMapper()
    mapper.SetInputConnection(s.GetOutputPort())
    actor = vtkLODActor()
    actor.SetMapper(mapper)
    return [_keep(actor, s, mapper)]


def row_follower(camera):
    cone = vtkConeSource()
    cone.SetHeight(1.6)
    cone.SetRadius(0.7)
    cone.SetResolution(16)
    mapper = vtkPolyDataMapper()
    mapper.SetInputConnection(cone.GetOutputPort())
    follower = vtkFollower()
    follower.SetMapper(mapper)
    follower.SetPosition(*CENTER)
    follower.SetCamera(camera)
    return [_keep(follower, cone, mapper)]


def row_assembly():
    parts = vtkAssembly()
    for x in (-0.5, 0.5):
        parts.AddPart(polydata_actor(sphere(0.4, (x, 0, 0))))
    parts.SetPosition(0, 0, 1.5)
    parts.RotateZ(30)
    return [parts]


def row_assembly_and_alone():
    """One actor drawn twice: by itself and as the part of an assembly (which lends it its
    own property keys while it draws the part)."""
    part = polydata_actor(sphere(0.5, (0, 0, 0)))
    parts = vtkAssembly()
    parts.AddPart(part)
    parts.SetPosition(0.6, 0, 1.5)
    part.SetPosition(-0.6, 0, 1.5)
    return [parts, part]


def row_backface_property():
    """An open bowl, its inside (back faces) drawn with a property of its own."""
    from vtkmodules.vtkFiltersCore import vtkClipPolyData
    from vtkmodules.vtkRenderingCore import vtkProperty
    source = sphere(0.8, res=32)
    cut = vtkPlane()
    cut.SetOrigin(0, 0, 1.9)
    cut.SetNormal(0, 0, 1)
    clip = vtkClipPolyData()
    clip.SetInputConnection(source.GetOutputPort())
    clip.SetClipFunction(cut)
    clip.InsideOutOn()
    inside = vtkProperty()
    inside.SetColor(0.3, 0.5, 0.9)
    actor = polydata_actor(clip)
    actor.SetBackfaceProperty(inside)
    return [_keep(actor, source, cut, clip, inside)]


def row_clipped():
    """Half a sphere (32 x 16 facets: its twin is row_surface's 24 x 12, about as large)."""
    s = sphere(res=32)
    mapper = vtkPolyDataMapper()
    plane = vtkPlane()
    plane.SetOrigin(*CENTER)
    plane.SetNormal(-1, 0, 0)  # keep x <= 0: half a sphere
    planes = vtkPlaneCollection()
    planes.AddItem(plane)
    mapper.SetClippingPlanes(planes)
    return [polydata_actor(s, mapper=_keep(mapper, plane, planes))]


def row_texture():
    return [card(textured=True)]


def row_alpha_cutout():
    return [card(half_alpha_texture(True))]


def row_backface_culling():
    actor = polydata_actor(sphere())
    actor.GetProperty().BackfaceCullingOn()
    return [actor]


def row_translucent():
    actor = polydata_actor(sphere())
    actor.GetProperty().SetOpacity(0.5)
    return [actor]


def row_pbr():
    """PBR with a normal map (bumps), which needs texture coordinates and tangents."""
    from vtkmodules.vtkFiltersCore import vtkPolyDataTangents
    from vtkmodules.vtkFiltersTexture import vtkTextureMapToSphere
    source = sphere(res=32)
    mapped = vtkTextureMapToSphere()
    mapped.SetInputConnection(source.GetOutputPort())
    mapped.PreventSeamOff()
    tangents = vtkPolyDataTangents()
    tangents.SetInputConnection(mapped.GetOutputPort())
    image = vtkImageData()
    image.SetDimensions(32, 32, 1)
    u, v = np.meshgrid(np.linspace(0, 4 * np.pi, 32), np.linspace(0, 4 * np.pi, 32))
    bumps = np.stack([0.5 + 0.3 * np.cos(u), 0.5 + 0.3 * np.cos(v), np.ones_like(u)], axis=2)
    image.GetPointData().SetScalars(numpy_to_vtk((255 * bumps).astype(np.uint8).reshape(-1, 3),
                                                 deep=1))
    normals = vtkTexture()
    normals.SetInputData(image)
    normals.InterpolateOn()
    actor = polydata_actor(tangents)
    actor.GetProperty().SetInterpolationToPBR()
    actor.GetProperty().SetMetallic(0.2)
    actor.GetProperty().SetRoughness(0.5)
    actor.GetProperty().SetNormalTexture(normals)
    return [_keep(actor, source, mapped, image, normals)]


def row_image_slice():
    image = vtkImageData()
    image.SetDimensions(16, 16, 1)
    image.SetSpacing(0.1, 0.1, 1)
    image.SetOrigin(-0.8, -0.8, 1.5)
    values = np.random.default_rng(2).integers(40, 255, 256).astype(np.uint8)
    image.GetPointData().SetScalars(numpy_to_vtk(values, deep=1))
    actor = vtkImageActor()
    actor.GetMapper().SetInputData(image)
    return [_keep(actor, image)]


def row_volume():
    image = vtkImageData()
    image.SetDimensions(12, 12, 12)
    image.SetSpacing(0.12, 0.12, 0.12)
    image.SetOrigin(-0.66, -0.66, 0.84)
    grid = np.indices((12, 12, 12)).reshape(3, -1).T - 5.5
    values = (255 * np.exp(-(grid ** 2).sum(axis=1) / 12.0)).astype(np.uint8)
    image.GetPointData().SetScalars(numpy_to_vtk(values, deep=1))
    mapper = vtkSmartVolumeMapper()
    mapper.SetInputData(image)
    color = vtkColorTransferFunction()
    color.AddRGBPoint(0, 0, 0, 0)
    color.AddRGBPoint(255, 1, 0.8, 0.4)
    from vtkmodules.vtkCommonDataModel import vtkPiecewiseFunction
    opacity = vtkPiecewiseFunction()
    opacity.AddPoint(0, 0)
    opacity.AddPoint(255, 0.8)
    prop = vtkVolumeProperty()
    prop.SetColor(color)
    prop.SetScalarOpacity(opacity)
    volume = vtkVolume()
    volume.SetMapper(mapper)
    volume.SetProperty(prop)
    return [_keep(volume, image, mapper, color, opacity, prop)]


def row_skybox():
    image = vtkImageData()
    image.SetDimensions(8, 8, 1)
    texels = np.tile(np.array([[110, 150, 230]], np.uint8), (64, 1))
    image.GetPointData().SetScalars(numpy_to_vtk(texels, deep=1))
    texture = vtkTexture()
    texture.SetInputData(image)
    sky = vtkSkybox()
    sky.SetTexture(texture)
    sky.SetProjectionToSphere()
    return [polydata_actor(sphere()), _keep(sky, image, texture)]


def row_text():
    text = vtkTextActor()
    text.SetInput("Penumbra")
    text.SetPosition(4, 4)
    text.GetTextProperty().SetFontSize(14)
    return [polydata_actor(sphere()), text]


def row_solid_twin():
    """The wireframe's and points' sphere drawn as a surface."""
    return [polydata_actor(sphere(res=8))]


def row_outline_twin():
    """The box the outline draws, as a solid."""
    from vtkmodules.vtkFiltersSources import vtkCubeSource
    box = vtkCubeSource()
    box.SetBounds(-0.8, 0.8, -0.8, 0.8, 0.7, 2.3)
    return [polydata_actor(box)]


def row_card_twin():
    return [card()]


def row_points_twin():
    return [polydata_actor(sphere(0.8))]


# name -> (builder, receives, casts, twin). Builders taking the camera get it. `casts` says
# what the exact shadow on the ground must be, as shadowed ground samples of the reference:
#   "solid"    some (a surface casts its triangles; checked exactly against the tracer by
#              every exact technique below; splats cast their whole drawn footprint, as
#              VTK's default splat shader draws every fragment of its triangle),
#   "thin"     lines or points: between 1 % and 60 % of the shadow of `twin` (the same
#              shape drawn as a surface),
#   "part"     a clipped or cut-out surface: between 25 % and 75 % of `twin`'s (uncut),
#   "nothing"  none.
ROWS = {
    "surface": (row_surface, True, "solid", None),
    "scalar colours": (row_scalar_colors, True, "solid", None),
    "edges on a surface": (row_edges, True, "solid", None),
    "wireframe": (row_wireframe, False, "thin", row_solid_twin),
    "points representation": (row_points, False, "thin", row_solid_twin),
    "lines without normals": (row_outline, False, "thin", row_outline_twin),
    "lines as tubes": (row_tubes, False, "thin", row_outline_twin),
    "points as spheres": (row_spheres, False, "thin", row_points_twin),
    "glyph instances": (row_glyphs, True, "solid", None),
    "point-gaussian splats": (row_splats, False, "solid", None),
    "composite blocks": (row_composite, True, "solid", None),
    "data-set mapper": (row_dataset_mapper, True, "solid", None),
    "LOD actor": (row_lod_actor, True, "solid", None),
    "follower": (row_follower, True, "solid", None),
    "assembly": (row_assembly, True, "solid", None),
    "assembly part drawn alone too": (row_assembly_and_alone, True, "solid", None),
    "back-face property": (row_backface_property, True, "solid", None),
    "clipping plane": (row_clipped, True, "part", row_surface),
    "texture": (row_texture, True, "solid", None),
    "alpha cut-out": (row_alpha_cutout, True, "part", row_card_twin),
    "backface culling": (row_backface_culling, True, "solid", None),
    "translucent": (row_translucent, True, "solid", None),
    "PBR": (row_pbr, True, "solid", None),
    "image slice": (row_image_slice, False, "solid", None),
    "volume": (row_volume, False, "nothing", None),
    "skybox": (row_skybox, True, "solid", None),
    "2D text": (row_text, True, "solid", None),
}


def add_ground_and_sun(renderer):
    ground = vtkPlaneSource()
    ground.SetOrigin(-4, -4, 0)
    ground.SetPoint1(4, -4, 0)
    ground.SetPoint2(-4, 4, 0)
    renderer.AddActor(polydata_actor(ground, (0.85, 0.85, 0.85)))
    sun = vtkLight()
    sun.SetLightTypeToSceneLight()
    sun.SetPositional(False)
    sun.SetPosition(-0.6, -0.4, 1.6)
    sun.SetFocalPoint(0, 0, 0)
    renderer.AddLight(sun)
    camera = renderer.GetActiveCamera()
    camera.SetPosition(3, -8, 6)
    camera.SetFocalPoint(0.4, 0.3, 0.8)
    camera.SetViewUp(0, 0, 1)
    renderer.SetBackground(0.2, 0.25, 0.3)
    renderer.ResetCameraClippingRange()


def build(row, renderer, twin=False):
    """Adds row `row`'s props (its twin's with `twin`), the ground and the sun to
    `renderer`."""
    builder = ROWS[row][3] if twin else ROWS[row][0]
    add_ground_and_sun(renderer)
    props = builder(renderer.GetActiveCamera()) if builder is row_follower else builder()
    for prop in props:
        if prop.IsA("vtkActor2D"):
            renderer.AddActor2D(prop)
        elif prop.IsA("vtkVolume"):
            renderer.AddVolume(prop)
        else:
            renderer.AddViewProp(prop)
    renderer.ResetCameraClippingRange()
    return props
