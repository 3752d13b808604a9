#!/usr/bin/env python3
"""Writes docs/gallery.md and its pictures: every technique family on a scene where it
matters, beside VTK's own vtkShadowMapPass and the exact reference, each with its error image
(red: lit where the reference is shadowed, blue: shadowed where it is lit; soft lights: the
absolute visibility error) and a caption of the figures the bench measured for it.

    python3 docs/make_gallery.py [--bench build/bin/penumbra-bench] [--out docs]
                                 [--size 256x192] [--frames 3] [--reduced]

Everything comes from one penumbra-bench run per scene (frames, error images, results.csv),
so the captions are the bench's own figures. --reduced renders one scene with three
techniques (the suite's check, Testing/Python/test_gallery.py).
"""
import argparse
import csv
import os
import shutil
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))

# (scene, title, why it is shown there, techniques). raytraced is the exact reference and
# vtk-shadowmap VTK's own pass, in every row.
SCENES = [
    ("default", "City under a low sun",
     "Long, thin building shadows: the hard-shadow families, exact and map-based",
     ["shadowmap", "resm", "rmsm", "conservative", "llsm-hybrid", "volumes"]),
    ("isosurface", "Isosurface, self-shadowing",
     "A curved closed surface that shadows itself",
     ["shadowmap", "conservative", "volumes"]),
    ("bunny_area_light", "Scanned mesh under an area light",
     "A dense scanned mesh under a rectangular light: the soft-shadow families",
     ["gears", "adaptive-soft", "soft-shadowmap", "single-sample-soft", "pcss"]),
    ("room_point_light", "Point light in a room",
     "An omnidirectional light inside closed walls: cube maps and shadow volumes",
     ["shadowmap", "llsm", "volumes"]),
    ("torture/grazing_light", "Grazing light",
     "A light nearly parallel to the receivers: shadow-map aliasing at its worst",
     ["shadowmap", "resm", "rmsm", "conservative"]),
    ("torture/georef_1e7", "Huge coordinates",
     "A city at 1e7 m from the origin: float32 alone cannot hold it",
     ["shadowmap", "conservative", "volumes"]),
]
REDUCED = [("default", "City under a low sun", "The suite's reduced gallery",
            ["shadowmap"])]
PEERS = ["vtk-shadowmap", "raytraced"]


def caption(row):
    """The bench's figures for one row: its error (hard lights: the share of lit-candidate
    samples it gets wrong; soft lights: the mean absolute error) and the frame time as a
    multiple of the unshadowed frame."""
    if row["error_kind"] == "hard":
        error = "mismatch %.2e" % float(row["mismatch_rate"])
    else:
        error = "MAE %.4f" % float(row["mae"])
    return "%s, %.2f × unshadowed" % (error, float(row["ratio_to_no_shadow"]))


def run_scene(bench, scene, techniques, size, frames, work):
    out = os.path.join(work, scene.replace("/", "_"))
    names = ["none"] + PEERS + techniques
    proc = subprocess.run([bench, "--scenes", scene, "--techniques", ",".join(names),
                           "--size", size, "--frames", str(frames), "--warmup", "1",
                           "--out", out], capture_output=True, text=True, timeout=1800)
    if proc.returncode != 0:
        sys.exit("penumbra-bench failed on %s:\n%s" % (scene, proc.stderr[-2000:]))
    with open(os.path.join(out, "results.csv")) as f:
        rows = [r for r in csv.DictReader(f) if r["light"] == "0"]
    return out, rows


def write_gallery(bench, scenes, size, frames, out_dir):
    pictures = os.path.join(out_dir, "gallery")
    os.makedirs(pictures, exist_ok=True)
    lines = ["# Gallery", "",
             "Every technique family on a scene where it matters, beside VTK's own "
             "`vtkShadowMapPass` (`vtk-shadowmap`) and the exact reference (`raytraced`). Under "
             "each frame its error image against the reference on the same view samples: red "
             "where it is lit and the reference is shadowed, blue where it is shadowed and the "
             "reference is lit (soft lights: the absolute visibility error). The captions are "
             "the bench's figures for that frame: the error (hard lights: the share of "
             "lit-candidate samples it gets wrong; soft lights: the mean absolute error of "
             "visibility) and the frame time as a multiple of the unshadowed frame, measured "
             "in the same run (Mesa llvmpipe, 2 cores, no GPU). For soft lights the "
             "yardstick is the converged 64 × 64-sample estimate, so `raytraced`'s own MAE "
             "there is the sampling error of the light's k (`gears` equals it). Regenerate with "
             "`python3 docs/make_gallery.py` (%s pixels, the median of %d frames; each "
             "scene's bench table is beside the pictures, `gallery/<scene>_results.csv`); "
             "docs/results.md has the figures at 1280 × 720." % (size, frames), ""]
    with tempfile.TemporaryDirectory() as work:
        for scene, title, why, techniques in scenes:
            out, rows = run_scene(bench, scene, techniques, size, frames, work)
            # The bench's own figures beside the pictures, as the captions quote them.
            shutil.copyfile(os.path.join(out, "results.csv"),
                            os.path.join(pictures, scene.replace("/", "_") + "_results.csv"))
            by_name = {r["technique"]: r for r in rows}
            shown = [t for t in PEERS + techniques if t in by_name]
            lines += ["## %s (`%s`)" % (title, scene), "", why + ".", "",
                      "| " + " | ".join("`%s`" % t for t in shown) + " |",
                      "|" + "---|" * len(shown)]
            cells, errors, captions = [], [], []
            for t in shown:
                row = by_name[t]
                stem = "%s__%s_%s" % (row["scene"], t, row["setting"])  # the bench's names
                for suffix, column in (("", cells), ("_error", errors)):
                    source = os.path.join(out, stem + suffix + ".png")
                    target = "%s_%s%s.png" % (scene.replace("/", "_"), t, suffix)
                    shutil.copyfile(source, os.path.join(pictures, target))
                    column.append("![%s%s](gallery/%s)" % (t, suffix.replace("_", " "), target))
                captions.append(caption(row))
            lines += ["| " + " | ".join(cells) + " |", "| " + " | ".join(errors) + " |",
                      "| " + " | ".join(captions) + " |", ""]
    with open(os.path.join(out_dir, "gallery.md"), "w") as f:
        f.write("\n".join(lines))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--bench", default=os.path.join(HERE, "..", "build", "bin",
                                                        "penumbra-bench"))
    parser.add_argument("--out", default=HERE)
    parser.add_argument("--size", default="256x192")
    parser.add_argument("--frames", type=int, default=3)
    parser.add_argument("--reduced", action="store_true")
    args = parser.parse_args()
    if not os.path.isfile(args.bench):
        sys.exit("no penumbra-bench at %s: build first (./penumbra.sh build) or pass --bench"
                 % args.bench)
    write_gallery(args.bench, REDUCED if args.reduced else SCENES, args.size, args.frames,
                  args.out)


if __name__ == "__main__":
    main()
