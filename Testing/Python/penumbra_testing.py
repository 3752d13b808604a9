"""Helpers shared by the Python tests: paths from the environment and pixel statistics."""

import os
import subprocess

from vtkmodules.vtkRenderingCore import vtkWindowToImageFilter

SOURCE_DIR = os.environ.get("PENUMBRA_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
RENDER = os.environ.get("PENUMBRA_RENDER", "penumbra-render")
SCENES_DIR = os.path.join(SOURCE_DIR, "Data", "Scenes")
BAD_SCENES_DIR = os.path.join(SOURCE_DIR, "Testing", "Scenes", "bad")


def run_render(*args, env=None):
    """Runs penumbra-render (optionally with extra environment); returns (code, stdout, stderr)."""
    full_env = dict(os.environ, **(env or {}))
    proc = subprocess.run([RENDER, *map(str, args)], capture_output=True, text=True, timeout=600,
                          env=full_env)
    return proc.returncode, proc.stdout, proc.stderr


def window_luminance(window):
    """Mean-of-RGB per pixel of the window's current frame, rows bottom-up, as a list of rows."""
    grab = vtkWindowToImageFilter()
    grab.SetInput(window)
    grab.SetInputBufferTypeToRGB()
    grab.ReadFrontBufferOff()
    grab.Update()
    return image_luminance(grab.GetOutput())


def image_luminance(image):
    width, height, _ = image.GetDimensions()
    scalars = image.GetPointData().GetScalars()
    comps = scalars.GetNumberOfComponents()
    rows = []
    for y in range(height):
        row = []
        for x in range(width):
            t = scalars.GetTuple(y * width + x)
            row.append(sum(t[:3]) / 3.0 if comps >= 3 else t[0])
        rows.append(row)
    return rows
