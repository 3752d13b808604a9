#!/usr/bin/python3
"""Shadows in a Python VTK script: load a scene file (or build one), pick a technique, render
headless, save a PNG.

    PYTHONPATH=build/lib/python3/dist-packages /usr/bin/python3 Examples/Python/shadowed_scene.py \
        Data/Scenes/isosurface.json out.png
"""

import sys

import penumbra
from vtkmodules.vtkRenderingCore import vtkRenderWindow, vtkWindowToImageFilter


def main(scene_path, out_path, technique=None):
    reader = penumbra.load_scene(scene_path)  # raises ValueError with a clear message
    renderer = reader.GetRenderer()
    techniques = penumbra.vtkPenumbraTechniques()
    name = technique or reader.GetTechniqueName()
    options = reader.GetTechniqueOptions() if technique is None else "{}"
    if not techniques.Apply(renderer, name, options):
        raise SystemExit(techniques.GetErrorMessage())

    window = vtkRenderWindow()  # headless EGL window when there is no X display
    window.SetOffScreenRendering(1)
    window.SetSize(reader.GetWidth(), reader.GetHeight())
    window.AddRenderer(renderer)
    window.Render()

    grab = vtkWindowToImageFilter()
    grab.SetInput(window)
    grab.ReadFrontBufferOff()
    grab.Update()
    io = penumbra.vtkPenumbraImageIO()
    if not io.Write(grab.GetOutput(), out_path):
        raise SystemExit(io.GetErrorMessage())
    print("wrote", out_path)


if __name__ == "__main__":
    if len(sys.argv) < 3:
        raise SystemExit(__doc__)
    main(sys.argv[1], sys.argv[2], *sys.argv[3:4])
