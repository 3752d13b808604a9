"""The examples in Examples/ run as documented and produce non-blank images."""

import os
import subprocess
import sys
import tempfile
import unittest

import penumbra
from vtkmodules.vtkCommonDataModel import vtkImageData

from penumbra_testing import SCENES_DIR, SOURCE_DIR, image_luminance


def spread(path):
    image = vtkImageData()
    io = penumbra.vtkPenumbraImageIO()
    if not io.Read(path, image):
        raise AssertionError(io.GetErrorMessage())
    values = sorted(v for row in image_luminance(image) for v in row)
    return values[int(0.95 * len(values))] - values[int(0.05 * len(values))]


def dark_share(path):
    image = vtkImageData()
    io = penumbra.vtkPenumbraImageIO()
    if not io.Read(path, image):
        raise AssertionError(io.GetErrorMessage())
    values = [v for row in image_luminance(image) for v in row]
    return sum(v < 20 for v in values) / len(values)


class ExamplesTest(unittest.TestCase):
    def test_cxx_example(self):
        with tempfile.TemporaryDirectory() as tmp:
            out = os.path.join(tmp, "city.png")
            subprocess.run([os.environ["PENUMBRA_EXAMPLE_CXX"], out], check=True, timeout=300)
            self.assertGreater(spread(out), 40)

    def test_python_example(self):
        script = os.path.join(SOURCE_DIR, "Examples", "Python", "shadowed_scene.py")
        with tempfile.TemporaryDirectory() as tmp:
            out = os.path.join(tmp, "iso.png")
            subprocess.run([sys.executable, script, os.path.join(SCENES_DIR, "isosurface.json"), out],
                           check=True, timeout=300)
            self.assertGreater(spread(out), 40)

    def test_two_line_example(self):
        # A plain VTK script with `import penumbra` and `penumbra.enable_shadows(renderer)`.
        script = os.path.join(SOURCE_DIR, "Examples", "Python", "add_shadows.py")
        with open(script, encoding="utf-8") as f:
            self.assertEqual(f.read().count("# added line"), 2)
        with tempfile.TemporaryDirectory() as tmp:
            out = os.path.join(tmp, "shadows.png")
            subprocess.run([sys.executable, script, out], check=True, timeout=300)
            # The shadows on the ground: 2.5 % of the image is black with them, 1.1 % (the
            # cone's and sphere's own dark sides) without.
            self.assertGreater(dark_share(out), 0.018)


if __name__ == "__main__":
    unittest.main()
