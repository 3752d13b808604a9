"""An ordinary VTK script (a cone and a sphere over a ground plane, one sun) that gets exact
shadows from two added lines, marked below. Writes a PNG.

    PYTHONPATH=build/lib/python3/dist-packages /usr/bin/python3 Examples/Python/add_shadows.py out.png
"""

import sys

from vtkmodules.vtkFiltersSources import vtkConeSource, vtkPlaneSource, vtkSphereSource
from vtkmodules.vtkIOImage import vtkPNGWriter
from vtkmodules.vtkRenderingCore import (vtkActor, vtkLight, vtkPolyDataMapper, vtkRenderer,
                                         vtkRenderWindow, vtkWindowToImageFilter)
import vtkmodules.vtkRenderingOpenGL2  # noqa: F401

import penumbra  # added line 1 (also lets the window render without an X server)


def actor(source, color):
    mapper = vtkPolyDataMapper()
    mapper.SetInputConnection(source.GetOutputPort())
    a = vtkActor()
    a.SetMapper(mapper)
    a.GetProperty().SetColor(*color)
    return a


def main(out):
    ground = vtkPlaneSource()
    ground.SetOrigin(-4, -4, 0)
    ground.SetPoint1(4, -4, 0)
    ground.SetPoint2(-4, 4, 0)
    cone = vtkConeSource()
    cone.SetCenter(-1, 0, 1)
    cone.SetDirection(0, 0, 1)
    cone.SetHeight(2)
    cone.SetResolution(48)
    sphere = vtkSphereSource()
    sphere.SetCenter(1.2, 0.5, 1.2)
    sphere.SetThetaResolution(48)
    sphere.SetPhiResolution(24)

    renderer = vtkRenderer()
    renderer.AddActor(actor(ground, (0.9, 0.9, 0.9)))
    renderer.AddActor(actor(cone, (0.9, 0.5, 0.3)))
    renderer.AddActor(actor(sphere, (0.3, 0.6, 0.9)))
    sun = vtkLight()
    sun.SetLightTypeToSceneLight()
    sun.SetPositional(False)
    sun.SetPosition(-1.0, -0.6, 1.4)
    sun.SetFocalPoint(0, 0, 0)
    renderer.AddLight(sun)
    renderer.SetBackground(0.55, 0.68, 0.85)
    camera = renderer.GetActiveCamera()
    camera.SetPosition(2, -9, 6)
    camera.SetFocalPoint(0, 0, 0.5)
    camera.SetViewUp(0, 0, 1)

    window = vtkRenderWindow()
    window.SetSize(480, 320)
    window.AddRenderer(renderer)
    penumbra.enable_shadows(renderer)  # added line 2: auto, exact shadows for every light
    window.Render()

    grab = vtkWindowToImageFilter()
    grab.SetInput(window)
    writer = vtkPNGWriter()
    writer.SetFileName(out)
    writer.SetInputConnection(grab.GetOutputPort())
    writer.Write()


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "shadows.png")
