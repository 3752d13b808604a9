"""The project's regression images: each technique x scene in Testing/Data/Baseline renders
within its threshold under both headless windows (EGL and OSMesa), and a deliberately broken
shadow-map bias (acne without bias, leaks with a huge one) fails the same check.

To regenerate after an intended change (review the images before committing them):

    for s in default room_point_light; do for t in raytraced shadowmap; do
      build/bin/penumbra-render Data/Scenes/$s.json -o Testing/Data/Baseline/${s}_$t.png \\
        --size 128x96 --technique $t; done; done
"""

import os
import tempfile
import unittest

from penumbra_testing import SCENES_DIR, SOURCE_DIR, run_render

BASELINE_DIR = os.path.join(SOURCE_DIR, "Testing", "Data", "Baseline")
SIZE = "128x96"
SCENES = ("default", "room_point_light")
# technique -> (per-channel threshold, percentage of pixels allowed over it). The exact
# technique must match bit for bit in shadow and within the last bits of shading; the shadow
# map may move a few edge pixels (about 4 of 12288 between bias 1e-4 and 0.02), while acne or
# leaks change 59..4568 pixels on these scenes.
THRESHOLDS = {"raytraced": (0.02, 0.0), "shadowmap": (0.02, 0.1)}
WINDOWS = ("egl", "osmesa")


class BaselineTest(unittest.TestCase):
    def check(self, tmp, scene, technique, window, *options):
        threshold, percent = THRESHOLDS[technique]
        out = os.path.join(tmp, "%s_%s_%s.png" % (scene, technique, window))
        return run_render(os.path.join(SCENES_DIR, scene + ".json"), "-o", out, "--size", SIZE,
                          "--technique", technique, *options,
                          "--baseline", os.path.join(BASELINE_DIR, "%s_%s.png" % (scene, technique)),
                          "--threshold", str(threshold), "--fail-percent", str(percent),
                          env={"PENUMBRA_HEADLESS": window})

    def test_every_baseline_matches_on_both_windows(self):
        with tempfile.TemporaryDirectory() as tmp:
            for scene in SCENES:
                for technique in THRESHOLDS:
                    for window in WINDOWS:
                        with self.subTest(scene=scene, technique=technique, window=window):
                            code, stdout, stderr = self.check(tmp, scene, technique, window)
                            self.assertEqual(code, 0, stderr)
                            self.assertIn("matches", stdout)

    def test_broken_bias_fails_the_baseline(self):
        with tempfile.TemporaryDirectory() as tmp:
            for scene in SCENES:
                for options in (("--option", "bias=0", "--option", "slope_bias=0"),  # acne
                                ("--option", "bias=0.1")):  # light leaks
                    with self.subTest(scene=scene, options=options):
                        code, _, stderr = self.check(tmp, scene, "shadowmap", "egl", *options)
                        self.assertEqual(code, 1, stderr)
                        self.assertIn("differs from", stderr)


if __name__ == "__main__":
    unittest.main()
