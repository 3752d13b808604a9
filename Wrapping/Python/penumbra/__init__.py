"""Penumbra: accurate hard and soft shadows for VTK render pipelines.

Use it exactly like VTK::

    import penumbra
    from vtkmodules.vtkRenderingCore import vtkRenderWindow, vtkRenderer

    renderer = vtkRenderer()                       # ... actors and lights as usual ...
    penumbra.enable_shadows(renderer)              # "auto": per light, exact shadows
    window.Render()
    shadow = penumbra.visibility(renderer, light=0)   # NumPy (height, width), 1 lit, 0 shadowed
    penumbra.disable_shadows(renderer)

Importing the package registers the headless render window: with no X display (or with
PENUMBRA_HEADLESS=1) ``vtkRenderWindow()`` renders offscreen on EGL without any X server;
PENUMBRA_HEADLESS=osmesa uses Mesa's OSMesa instead.
"""

# VTK's own OpenGL factory must be registered before ours decides whether to replace its
# render window, whatever order the user imports things in.
import vtkmodules.vtkRenderingOpenGL2  # noqa: F401

from .vtkPenumbraHeadless import *  # noqa: F401,F403
from .vtkPenumbraSources import *  # noqa: F401,F403
from .vtkPenumbraScene import *  # noqa: F401,F403
from .vtkPenumbraSceneIO import *  # noqa: F401,F403
from .vtkPenumbraRayTracing import *  # noqa: F401,F403
from .vtkPenumbraAnalysis import *  # noqa: F401,F403
from .vtkPenumbraShadows import *  # noqa: F401,F403
from .vtkPenumbraShadowMaps import *  # noqa: F401,F403
from .vtkPenumbraExactShadows import *  # noqa: F401,F403
from .vtkPenumbraGears import *  # noqa: F401,F403
from .vtkPenumbraTechniques import *  # noqa: F401,F403


def load_scene(path):
    """Reads a JSON scene file; returns the vtkPenumbraSceneReader or raises ValueError."""
    reader = vtkPenumbraSceneReader()
    reader.AddObserver("ErrorEvent", lambda *args: None)
    reader.SetFileName(str(path))
    if not reader.Read():
        raise ValueError(reader.GetErrorMessage())
    return reader


def enable_shadows(renderer, technique="auto", **options):
    """Shadows `renderer` with the named technique and returns its vtkPenumbraShadowPass (None
    for VTK's own `vtk-shadowmap` and for `none`).

    `technique`: a name of `penumbra-render --list-techniques` (default: `auto`, which picks
    per light the technique the project's measurements favour: exact `raytraced` shadows for
    hard lights, exact `gears` soft shadows for area and linear lights (`raytraced` at
    k <= 4); options `quality` ("balanced", "exact" or "fast") and `samples`); keyword
    options as in a scene file's technique block, e.g. ``resolution=4096, filter="pcf"`` for
    `shadowmap`. Raises ValueError naming the unknown technique or the option and its
    problem; the renderer is then left as it was.

    A renderer that already draws with a pass of its own (vtkOutlineGlowPass, vtkSSAOPass, a
    render-steps pass ...) keeps it: the shadows are composed with it (it draws the shadowed
    scene). One that holds a Penumbra pass in a composition of its own (the drop-in
    vtkPenumbraShadowMapPass) gets the technique there.
    """
    import json

    techniques = vtkPenumbraTechniques()
    try:
        text = json.dumps(options)
    except TypeError as error:
        raise ValueError("options must be numbers, strings or booleans: %s" % error) from None
    if not techniques.Apply(renderer, technique, text):
        raise ValueError(techniques.GetErrorMessage())
    return shadow_pass(renderer)


def technique_options(technique):
    """`technique`'s option table as a list of dicts with keys name, type ("integer", "number",
    "boolean" or "choice"), default, range (text: "64..8192" or the choices), unit and doc — the
    table vtkPenumbraTechniques validates against. An unknown technique has none."""
    import json

    t = vtkPenumbraTechniques
    return [{"name": t.GetOptionName(technique, i),
             "type": t.GetOptionType(technique, i),
             "default": json.loads(t.GetOptionDefault(technique, i)),
             "range": t.GetOptionRange(technique, i),
             "unit": t.GetOptionUnit(technique, i),
             "doc": t.GetOptionDoc(technique, i)}
            for i in range(t.GetNumberOfOptions(technique))]


def _techniques_doc():
    """The technique list appended to enable_shadows' docstring, read from the option tables."""
    lines = ["", "    Techniques and their options:", ""]
    for index in range(vtkPenumbraTechniques.GetNumberOfTechniques()):
        name = vtkPenumbraTechniques.GetTechniqueName(index)
        lines.append("    ``%s``: %s." % (name, vtkPenumbraTechniques.GetTechniqueDescription(index)))
        for option in technique_options(name):
            unit = "; " + option["unit"] if option["unit"] else ""
            lines.append("        ``%s`` (%s; default %r; %s%s): %s" % (
                option["name"], option["type"], option["default"], option["range"], unit,
                option["doc"]))
        lines.append("")
    return "\n".join(lines)


enable_shadows.__doc__ += _techniques_doc()


def disable_shadows(renderer):
    """Removes the shadows enable_shadows() (or vtkPenumbraTechniques) installed: `renderer`
    draws as it did before, with VTK's default drawing or the pass of its own it had (which
    the shadows were composed with)."""
    if not vtkPenumbraTechniques().Apply(renderer, "none", ""):
        raise ValueError("cannot remove the shadows")


def shadow_pass(renderer):
    """The vtkPenumbraShadowPass `renderer` draws with, or None."""
    return vtkPenumbraShadowPass.GetInstalled(renderer)


def visibility(renderer, light=0, translucent=False):
    """Light `light`'s visibility per pixel in the last frame as a NumPy float32 array of shape
    (height, width), row 0 at the bottom like VTK images: 1 lit, 0 shadowed, fractions for
    soft shadows, -1 where no surface was seen. `light` counts the switched-on lights in the
    renderer's order; `translucent` gives the nearest translucent surfaces' layer. None when
    that light got no shadow work (off, black, or no Penumbra pass). Raises IndexError for a
    light that does not exist.
    """
    from vtkmodules.util.numpy_support import vtk_to_numpy

    shadows = shadow_pass(renderer)
    if shadows is None:
        return None
    if not 0 <= light < shadows.GetNumberOfLights():
        raise IndexError("light %d: the last frame had %d switched-on lights"
                         % (light, shadows.GetNumberOfLights()))
    samples = shadows.GetTranslucentViewSamples() if translucent else shadows.GetViewSamples()
    values = (shadows.GetTranslucentVisibility(light) if translucent
              else shadows.GetVisibility(light))
    if samples is None or values is None:
        return None
    return vtk_to_numpy(values).reshape(samples.GetHeight(), samples.GetWidth()).copy()


def statistics(renderer, light=0):
    """The last frame's figures for light `light` as a dict name -> value: the pass's phase
    times (``extraction_ms``, ``samples_ms``, ``technique_ms``, ``shading_ms``) and the
    counts and phase times of the technique that shadowed it (vtkPenumbraStatistics; for
    example ``rays`` for raytraced, ``cells`` and ``traced_rays`` for gears). Empty when there
    is no Penumbra pass or no computed frame; raises IndexError for a light that does not
    exist.
    """
    shadows = shadow_pass(renderer)
    if shadows is None:
        return {}
    if not 0 <= light < shadows.GetNumberOfLights():
        raise IndexError("light %d: the last frame had %d switched-on lights"
                         % (light, shadows.GetNumberOfLights()))
    table = vtkPenumbraStatistics()
    shadows.GetLightStatistics(light, table)
    return {table.GetName(i): table.GetValue(i) for i in range(table.GetNumberOfEntries())}


def compare_images(image, baseline, threshold=None, fail_percent=None, diff=None):
    """Compares the image file `image` with the baseline file `baseline` the way OpenImageIO's
    ``idiff -fail threshold -failpercent fail_percent`` does (vtkPenumbraImageCompare: a pixel
    fails when a channel differs by more than `threshold`, values in [0, 1]; default 0.02).

    Returns ``(matches, message)``. On a mismatch, writes the difference image to `diff` if
    given. Raises ValueError if a file cannot be read or the sizes or channels differ.
    """
    compare = vtkPenumbraImageCompare()
    if threshold is not None:
        compare.SetThreshold(threshold)
    if fail_percent is not None:
        compare.SetFailFraction(fail_percent / 100.0)
    verdict = compare.Compare(str(image), str(baseline))
    if verdict < 0:
        raise ValueError(compare.GetMessage())
    if verdict == 0 and diff is not None and not compare.WriteDifference(str(diff)):
        raise ValueError(compare.GetMessage())
    return verdict == 1, compare.GetMessage()


def assert_matches_baseline(window, baseline, output, threshold=None, fail_percent=None):
    """For a user's regression test: writes `window`'s last frame to `output` (PNG), compares it
    with `baseline` (see compare_images) and raises AssertionError naming the difference image
    (`output` with ``.diff.png``) on a mismatch."""
    import os

    from vtkmodules.vtkRenderingCore import vtkWindowToImageFilter

    grab = vtkWindowToImageFilter()
    grab.SetInput(window)
    grab.SetInputBufferTypeToRGB()
    grab.ReadFrontBufferOff()
    grab.Update()
    io = vtkPenumbraImageIO()
    if not io.Write(grab.GetOutput(), str(output)):
        raise ValueError(io.GetErrorMessage())
    diff = os.path.splitext(str(output))[0] + ".diff.png"
    matches, message = compare_images(output, baseline, threshold, fail_percent, diff)
    if not matches:
        raise AssertionError("%s %s; difference image: %s" % (output, message, diff))
