"""What shadows cost on small ordinary VTK scenes, and what they cost where there is nothing to
shadow: the median frame of every technique against the unshadowed frame, the camera turning
1 degree a frame (a user orbiting the scene), on the scenes of the feature-matrix test
(Testing/Python/feature_matrix.py) plus three with nothing to shadow: 2D text alone, a volume
alone, surfaces with lighting off.

Run from a build (docs/benchmarks.md, "Small ordinary scenes"):
  PYTHONPATH=build/lib/python3/dist-packages PENUMBRA_HEADLESS=1 /usr/bin/python3 \
      docs/measure_pipeline_cost.py [--frames N] [--size WxH] [--rows a,b,...]
"""
import argparse
import os
import sys
import time

import penumbra
from vtkmodules.vtkRenderingCore import vtkRenderWindow, vtkRenderer

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "Testing",
                                "Python"))
import feature_matrix  # noqa: E402


def nothing_to_shadow(kind, renderer):
    """The scenes with nothing to shadow: 2D text alone, a volume alone, unlit surfaces."""
    if kind == "2D text only":
        props = feature_matrix.row_text()[1:]
        renderer.AddActor2D(props[0])
        return props
    if kind == "volume only":
        props = feature_matrix.row_volume()
        renderer.AddVolume(props[0])
        renderer.GetActiveCamera().SetPosition(3, -8, 6)
        renderer.GetActiveCamera().SetFocalPoint(0, 0, 1.5)
        renderer.ResetCamera()
        return props
    props = feature_matrix.build("surface", renderer)  # "unlit": the same, lighting off
    actors = renderer.GetActors()
    for i in range(actors.GetNumberOfItems()):
        actors.GetItemAsObject(i).GetProperty().SetLighting(False)
    return props


NOTHING = ("2D text only", "volume only", "unlit surfaces")


def median_ms(row, technique, frames, size):
    renderer = vtkRenderer()
    keep = (nothing_to_shadow(row, renderer) if row in NOTHING
            else feature_matrix.build(row, renderer))
    window = vtkRenderWindow()
    window.SetSize(*size)
    window.SetMultiSamples(0)
    window.AddRenderer(renderer)
    if technique != "none":
        penumbra.enable_shadows(renderer, technique)
    camera = renderer.GetActiveCamera()
    window.Render()
    window.Render()  # warm-up: shaders compiled, caches built
    times = []
    for _ in range(frames):
        camera.Azimuth(1.0)
        renderer.ResetCameraClippingRange()
        start = time.perf_counter()
        window.Render()
        window.WaitForCompletion()
        times.append(1000.0 * (time.perf_counter() - start))
    if technique != "none":
        penumbra.disable_shadows(renderer)
    window.Finalize()
    del keep
    return sorted(times)[frames // 2]


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--frames", type=int, default=15)
    parser.add_argument("--size", default="400x300")
    parser.add_argument("--rows", default="")
    parser.add_argument("--techniques", default="")
    args = parser.parse_args()
    size = tuple(int(v) for v in args.size.split("x"))
    rows = args.rows.split(",") if args.rows else list(NOTHING) + list(feature_matrix.ROWS)
    names = [penumbra.vtkPenumbraTechniques.GetTechniqueName(i)
             for i in range(penumbra.vtkPenumbraTechniques.GetNumberOfTechniques())]
    techniques = args.techniques.split(",") if args.techniques else names
    if "none" not in techniques:
        techniques.insert(0, "none")
    print("| scene | none ms | " + " | ".join(t for t in techniques if t != "none") +
          " | slowest |")
    print("|---|---:|" + "---:|" * (len(techniques) - 1) + "---|")
    for row in rows:
        ms = {t: median_ms(row, t, args.frames, size) for t in techniques}
        ratios = {t: ms[t] / ms["none"] for t in techniques if t != "none"}
        slowest = max(ratios, key=ratios.get)
        print("| %s | %.2f | %s | %s |" % (row, ms["none"], " | ".join(
            "%.2f" % ratios[t] for t in techniques if t != "none"), slowest), flush=True)


if __name__ == "__main__":
    main()
