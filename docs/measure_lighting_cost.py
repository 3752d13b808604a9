"""How much of the unshadowed frame VTK's per-pixel lighting costs: the most an extended light
map (Brabec 2003, ch. 7) could save, since it replaces that lighting by a projective read.

Run from a build (docs/benchmarks.md, "Extended light maps"):
  PYTHONPATH=build/lib/python3/dist-packages PENUMBRA_HEADLESS=1 /usr/bin/python3 docs/measure_lighting_cost.py
"""
import time

import penumbra  # noqa: F401  (registers the headless render windows)
from penumbra import vtkPenumbraCityBlockSource
import vtkmodules.vtkRenderingOpenGL2  # noqa: F401
from vtkmodules.vtkRenderingCore import vtkActor, vtkPolyDataMapper, vtkRenderer, vtkRenderWindow


def city(lit):
    """The default scene's city block and camera, lit by VTK or not at all."""
    source = vtkPenumbraCityBlockSource()
    source.SetRows(4)
    source.SetColumns(5)
    source.SetSpacing(30)
    source.SetMinHeight(8)
    source.SetMaxHeight(45)
    source.SetSeed(7)
    source.SetGroundMargin(25)
    mapper = vtkPolyDataMapper()
    mapper.SetInputConnection(source.GetOutputPort())
    actor = vtkActor()
    actor.SetMapper(mapper)
    actor.GetProperty().SetLighting(lit)
    renderer = vtkRenderer()
    renderer.AddActor(actor)
    camera = renderer.GetActiveCamera()
    camera.SetPosition(-1, -1.4, 0.9)
    camera.SetFocalPoint(0, 0, 0)
    camera.SetViewUp(0, 0, 1)
    renderer.ResetCamera()
    camera.Zoom(1.3)
    return renderer


def median_frame_ms(lit, frames=21):
    window = vtkRenderWindow()
    window.SetOffScreenRendering(1)
    window.SetSize(1280, 720)
    window.SetMultiSamples(0)
    window.AddRenderer(city(lit))
    window.Render()
    times = []
    for _ in range(frames):
        start = time.perf_counter()
        window.Render()
        window.WaitForCompletion()
        times.append(1000.0 * (time.perf_counter() - start))
    window.Finalize()
    return sorted(times)[frames // 2]


if __name__ == "__main__":
    for lit in (True, False):
        print("lighting %-3s median ms %.2f" % ("on" if lit else "off", median_frame_ms(lit)))
