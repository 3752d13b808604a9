"""Penumbra: accurate hard and soft shadows for VTK render pipelines.

Use it exactly like VTK::

    import penumbra
    from vtkmodules.vtkRenderingCore import vtkRenderWindow, vtkRenderer

    renderer = vtkRenderer()
    penumbra.vtkPenumbraTechniques().Apply(renderer, "vtk-shadowmap", "{}")

Importing the package registers the headless EGL render window: with no X display (or with
PENUMBRA_HEADLESS=1) ``vtkRenderWindow()`` renders offscreen without any X server.
"""

# VTK's own OpenGL factory must be registered before ours decides whether to replace its
# render window, whatever order the user imports things in.
import vtkmodules.vtkRenderingOpenGL2  # noqa: F401

from .vtkPenumbraHeadless import *  # noqa: F401,F403
from .vtkPenumbraSources import *  # noqa: F401,F403
from .vtkPenumbraScene import *  # noqa: F401,F403
from .vtkPenumbraAnalysis import *  # noqa: F401,F403
from .vtkPenumbraRendering import *  # noqa: F401,F403


def load_scene(path):
    """Reads a JSON scene file; returns the vtkPenumbraSceneReader or raises ValueError."""
    reader = vtkPenumbraSceneReader()
    reader.AddObserver("ErrorEvent", lambda *args: None)
    reader.SetFileName(str(path))
    if not reader.Read():
        raise ValueError(reader.GetErrorMessage())
    return reader
