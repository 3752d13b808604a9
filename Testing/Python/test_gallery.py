"""docs/make_gallery.py, reduced (one scene, VTK's pass, the reference and shadowmap): the
pictures are there and show something (neither flat nor black), and every caption's error
is the one the bench measured for that frame."""
import csv
import os
import re
import subprocess
import sys
import tempfile
import unittest

from vtkmodules.vtkIOImage import vtkPNGReader

from penumbra_testing import SOURCE_DIR

BENCH = os.environ.get("PENUMBRA_BENCH", "penumbra-bench")


def luminance_stats(path):
    reader = vtkPNGReader()
    reader.SetFileName(path)
    reader.Update()
    scalars = reader.GetOutput().GetPointData().GetScalars()
    values = [sum(scalars.GetTuple(i)[:3]) / 3.0 for i in range(scalars.GetNumberOfTuples())]
    mean = sum(values) / len(values)
    spread = (sum((v - mean) ** 2 for v in values) / len(values)) ** 0.5
    return mean, spread


class GalleryTest(unittest.TestCase):
    def test_reduced_gallery(self):
        with tempfile.TemporaryDirectory() as out:
            proc = subprocess.run([sys.executable, os.path.join(SOURCE_DIR, "docs", "make_gallery.py"),
                                   "--bench", BENCH, "--out", out, "--reduced", "--size", "128x96",
                                   "--frames", "1"], capture_output=True, text=True, timeout=900)
            self.assertEqual(proc.returncode, 0, proc.stderr)
            with open(os.path.join(out, "gallery.md")) as f:
                text = f.read()
            pictures = re.findall(r"!\[[^\]]*\]\((gallery/[^)]+\.png)\)", text)
            self.assertEqual(len(pictures), 6, text)  # 3 frames, 3 error images
            for picture in pictures:
                self.assertTrue(os.path.isfile(os.path.join(out, picture)), picture)
                if picture.endswith("_error.png"):
                    continue  # the reference's own error image may be uniform
                mean, spread = luminance_stats(os.path.join(out, picture))
                self.assertGreater(mean, 20.0, picture + " is black")
                self.assertGreater(spread, 8.0, picture + " is flat")
            with open(os.path.join(out, "gallery", "default_results.csv")) as f:
                rows = {r["technique"]: r for r in csv.DictReader(f) if r["light"] == "0"}
            header = re.search(r"^\| (`.*`) \|$", text, re.M).group(1)
            techniques = re.findall(r"`([^`]+)`", header)
            self.assertEqual(techniques, ["vtk-shadowmap", "raytraced", "shadowmap"])
            captions = text.strip().splitlines()[-1].strip("| ").split(" | ")
            self.assertEqual(len(captions), 3, captions)
            for technique, text_caption in zip(techniques, captions):
                measured = float(rows[technique]["mismatch_rate"])
                quoted = float(re.match(r"mismatch (\S+),", text_caption).group(1))
                self.assertAlmostEqual(quoted, measured, delta=0.005 * measured + 1e-12,
                                       msg=(technique, text_caption))
            # The exact reference has no error; VTK's own pass has plenty.
            self.assertEqual(float(rows["raytraced"]["mismatch_rate"]), 0.0)
            self.assertGreater(float(rows["vtk-shadowmap"]["mismatch_rate"]), 0.05)


if __name__ == "__main__":
    unittest.main()
