"""penumbra-bench smoke run on tiny images: the CSV has a row per point with finite values,
the reference scores itself exactly, and the table and chart are written."""

import csv
import json
import math
import os
import subprocess
import tempfile
import unittest

from penumbra_testing import SCENES_DIR

BENCH = os.environ.get("PENUMBRA_BENCH", "penumbra-bench")
COLUMNS = ("scene", "technique", "setting", "median_ms", "mismatch_rate", "mae", "false_lit",
           "false_shadow", "ties", "ratio_to_no_shadow", "extraction_ms", "technique_ms")


def run_bench(out, *args):
    proc = subprocess.run([BENCH, "--out", out, "--size", "96x72", "--frames", "1", "--warmup", "0",
                           *args], capture_output=True, text=True, timeout=600)
    return proc.returncode, proc.stdout, proc.stderr


def read_csv(out, name):
    with open(os.path.join(out, name)) as f:
        return list(csv.DictReader(f))


class BenchTest(unittest.TestCase):
    def test_smoke(self):
        with tempfile.TemporaryDirectory() as out:
            code, stdout, stderr = run_bench(
                out, "--scenes", "default,torture/tiny_area_light",
                "--techniques", "none,vtk-shadowmap:resolution=512,raytraced")
            self.assertEqual(code, 0, stderr)
            self.assertIn("| scene | technique |", stdout)
            rows = read_csv(out, "results.csv")
            self.assertEqual(len(rows), 6)
            for col in COLUMNS:
                self.assertIn(col, rows[0])
            for row in rows:
                for col in ("median_ms", "mismatch_rate", "mae", "ratio_to_no_shadow"):
                    self.assertTrue(math.isfinite(float(row[col])), (row["technique"], col))
                self.assertGreater(float(row["median_ms"]), 0.0)
            by = {(r["scene"], r["technique"]): r for r in rows}
            # The ray-traced technique is the reference for hard lights: exact.
            ref = by[("default", "raytraced")]
            self.assertEqual(float(ref["mismatch_rate"]), 0.0)
            self.assertEqual(int(ref["false_lit"]) + int(ref["false_shadow"]), 0)
            self.assertGreaterEqual(float(ref["technique_ms"]), 0.0)
            # No shadows at all is wrong wherever the scene has shadows.
            self.assertGreater(int(by[("default", "none")]["false_lit"]), 0)
            self.assertEqual(int(by[("default", "none")]["false_shadow"]), 0)
            # An area light is scored softly against the converged estimate; a 1e-6 m light
            # is a point light, so its 4 x 4 samples agree with 64 x 64 ones.
            soft = by[("tiny_area_light", "raytraced")]
            self.assertEqual(soft["error_kind"], "soft")
            self.assertLess(float(soft["mae"]), 1e-3)
            self.assertGreater(os.path.getsize(os.path.join(out, "chart.png")), 2000)
            self.assertTrue(os.path.exists(os.path.join(out, "results.md")))
            self.assertTrue(os.path.exists(os.path.join(out, "default__raytraced_default_error.png")))

    def test_still_frames_and_moving_camera(self):
        # --still-frames adds the time of frames in which nothing changed; --moving-camera
        # makes every timed frame render the view samples again (a still camera keeps them).
        with tempfile.TemporaryDirectory() as out:
            code, _, stderr = run_bench(out, "--scenes", "default", "--techniques",
                                        "none,shadowmap,shadowmap:fit=view,raytraced",
                                        "--still-frames", "--moving-camera", "--frames", "2")
            self.assertEqual(code, 0, stderr)
            rows = {(r["technique"], r["setting"]): r for r in read_csv(out, "results.csv")}
            rows = {name if setting == "default" else name + ":" + setting: r
                    for (name, setting), r in rows.items()}
            for name in ("none", "shadowmap", "raytraced"):
                self.assertGreater(float(rows[name]["still_ms"]), 0.0)
                self.assertGreater(float(rows[name]["still_ratio_to_no_shadow"]), 0.0)
            for name in ("shadowmap:fit=view", "raytraced"):
                self.assertGreater(float(rows[name]["samples_ms"]), 0.0)
            # The camera sees the whole city: shadowmap's default fit is the scene's, whose
            # maps need no view samples while only the camera moves.
            self.assertEqual(float(rows["shadowmap"]["samples_ms"]), 0.0)
            self.assertEqual(float(rows["raytraced"]["mismatch_rate"]), 0.0)
            with open(os.path.join(out, "results.md")) as f:
                self.assertIn("the camera moving before every frame", f.read())

    def test_gears_points(self):
        # Equal-k points run only on the area-light scene; GEARS equals the ray tracer there
        # and reports its grid statistics.
        with tempfile.TemporaryDirectory() as out:
            code, stdout, stderr = run_bench(
                out, "--scenes", "default,area_light", "--no-images",
                "--techniques", "none,raytraced:samples=4,gears:samples=4")
            self.assertEqual(code, 0, stderr)
            rows = read_csv(out, "results.csv")
            # area_light has an area and a linear light: one row per light.
            self.assertEqual(sorted((r["scene"], r["technique"], r["light"]) for r in rows),
                             [("area_light", "gears", "0"), ("area_light", "gears", "1"),
                              ("area_light", "none", "0"), ("area_light", "none", "1"),
                              ("area_light", "raytraced", "0"), ("area_light", "raytraced", "1"),
                              ("default", "none", "0")])
            by = {(r["technique"], r["light"]): r for r in rows if r["scene"] == "area_light"}
            for light in ("0", "1"):
                self.assertEqual(float(by[("gears", light)]["mae"]),
                                 float(by[("raytraced", light)]["mae"]))
            self.assertEqual(by[("gears", "1")]["light_kind"], "linear")
            self.assertEqual(by[("gears", "1")]["light_technique"], "gears")
            # The report prints each technique's statistics table, whatever its class: GEARS'
            # grid and its agreement with the ray tracer at the same k.
            self.assertIn("Each technique's statistics of the last frame", stdout)
            self.assertRegex(stdout, r"- area_light gears samples=4 light 0: [^\n]*"
                                     r"occupied_cells [1-9][^\n]*differs_from_raytraced 0\n")
            self.assertRegex(stdout, r"- area_light raytraced samples=4 light 0: [^\n]*"
                                     r"rays [1-9]")

    def test_every_light_is_measured(self):
        # One row per light: a sun, a point light and an area light; a hard-shadow technique
        # is scored on the hard lights only (the pass gives the area light to its fallback).
        with tempfile.TemporaryDirectory() as out:
            code, stdout, stderr = run_bench(out, "--scenes", "mixed_lights", "--no-images",
                                             "--techniques", "none,raytraced,conservative")
            self.assertEqual(code, 0, stderr)
            rows = read_csv(out, "results.csv")
            got = sorted((r["technique"], r["light"], r["light_kind"]) for r in rows)
            self.assertEqual(got, [("conservative", "0", "directional"),
                                   ("conservative", "1", "point"),
                                   ("none", "0", "directional"), ("none", "1", "point"),
                                   ("none", "2", "area"),
                                   ("raytraced", "0", "directional"), ("raytraced", "1", "point"),
                                   ("raytraced", "2", "area")])
            for r in rows:
                if r["technique"] == "raytraced":
                    self.assertEqual(r["light_technique"], "raytraced")
                    self.assertEqual(float(r["mismatch_rate"]), 0.0, r)
            # Each light has its own shadows: no shadows is wrong for each of them.
            none = {r["light"]: r for r in rows if r["technique"] == "none"}
            self.assertGreater(int(none["0"]["false_lit"]), 0)
            self.assertGreater(int(none["1"]["false_lit"]), 0)
            self.assertGreater(float(none["2"]["mae"]), 0.0)
            self.assertIn("| mixed_lights | raytraced | default | 2 area | raytraced |", stdout)

    def test_skips_and_failures(self):
        # Hard-shadow techniques are not run under an area light; a scene that cannot be
        # measured (its only light is black, or its file is broken) is reported, and every
        # other point is still measured and written, with exit status 3.
        with tempfile.TemporaryDirectory() as out:
            with open(os.path.join(SCENES_DIR, "default.json")) as f:
                dark = json.load(f)
            dark["lights"][0]["intensity"] = 0.0
            dark_path = os.path.join(out, "dark.json")
            with open(dark_path, "w") as f:
                json.dump(dark, f)
            broken_path = os.path.join(out, "broken.json")
            with open(broken_path, "w") as f:
                f.write("{ not json")
            code, stdout, stderr = run_bench(
                out, "--scenes", dark_path + "," + broken_path + ",default,area_light",
                "--no-images",
                "--techniques", "none,conservative,gears:samples=4")
            self.assertEqual(code, 3, stderr)
            self.assertIn("dark: no light to measure", stderr)
            rows = read_csv(out, "results.csv")
            self.assertEqual(sorted((r["scene"], r["technique"]) for r in rows),
                             [("area_light", "gears"), ("area_light", "gears"),
                              ("area_light", "none"), ("area_light", "none"),
                              ("default", "conservative"), ("default", "none")])
            with open(os.path.join(out, "results.md")) as f:
                md = f.read()
            self.assertIn("Not measured", md)
            self.assertIn("- dark: no light to measure", md)
            self.assertIn("- broken: ", md)
            self.assertIn("invalid JSON", md)
            self.assertTrue(os.path.exists(os.path.join(out, "chart.png")))

    def test_bad_arguments(self):
        with tempfile.TemporaryDirectory() as out:
            # Refused before anything is measured, even after valid scenes and techniques.
            for args, fragment in ((("--techniques", "magic"), "unknown technique"),
                                   (("--scenes", "default,no_such_scene"), "no scene file"),
                                   (("--techniques", "raytraced,conservative:layers=1"),
                                    "layers: expected an integer in [2, 4], got 1"),
                                   (("--frames", "0"), "--frames"),
                                   (("--scale-sweep", "1e4,many"), "--scale-sweep expects"),
                                   (("--scale-sweep", "--scenes", "default"), "no --scenes"),
                                   (("--budget", "5"), "--budget bounds")):
                with self.subTest(args=args):
                    code, _, stderr = run_bench(out, *args)
                    self.assertEqual(code, 2)
                    self.assertIn(fragment, stderr)
                    self.assertFalse(os.path.exists(os.path.join(out, "results.csv")))
                    self.assertFalse(os.path.exists(os.path.join(out, "sweep.csv")))

    def test_scale_sweep(self):
        # Two counts, one technique next to none (added unasked), both cameras: a row per
        # point with its time, phases and memory, an exponent per series, and a chart.
        with tempfile.TemporaryDirectory() as out:
            code, stdout, stderr = run_bench(out, "--scale-sweep", "2000,20000",
                                             "--techniques", "shadowmap", "--size", "160x120")
            self.assertEqual(code, 0, stderr)
            rows = read_csv(out, "sweep.csv")
            self.assertEqual(len(rows), 8)
            asked = {}
            for row in rows:
                triangles = int(row["triangles"])
                asked.setdefault(2000 if triangles < 6000 else 20000, set()).add(
                    (row["technique"], row["camera"]))
                # The sphere is tessellated to the asked count, near enough for a log axis.
                self.assertLess(abs(triangles / (2000 if triangles < 6000 else 20000) - 1), 0.05)
                self.assertEqual(row["status"], "measured")
                self.assertGreater(float(row["median_ms"]), 0.0)
                self.assertTrue(math.isfinite(float(row["exponent"])), row)
                # Two counts: the slope over the two largest is the same line.
                self.assertAlmostEqual(float(row["exponent_last_two"]), float(row["exponent"]),
                                       places=2)
                self.assertGreaterEqual(float(row["peak_rss_mb"]), float(row["rss_before_mb"]))
                self.assertGreater(float(row["rss_before_mb"]), 0.0)
                # The cold first frame is timed once per technique, on its still row.
                self.assertEqual(row["first_frame_ms"] != "", row["camera"] == "still")
                if row["technique"] == "none":
                    self.assertEqual(row["technique_ms"], "")  # no Penumbra pass, no phases
                    self.assertEqual(float(row["exponent_minus_none"]), 0.0)
                    self.assertEqual(row["bytes_per_triangle_over_none"], "")
                else:
                    self.assertGreaterEqual(float(row["technique_ms"]), 0.0)
                    self.assertGreater(float(row["ratio_to_none"]), 0.0)
                    # The memory over the unshadowed row of the same count and camera, per
                    # caster triangle (the shadow map's own textures make it positive).
                    none_peak = [float(r["peak_rss_mb"]) for r in rows
                                 if r["technique"] == "none" and r["camera"] == row["camera"]
                                 and r["triangles"] == row["triangles"]][0]
                    self.assertAlmostEqual(
                        float(row["bytes_per_triangle_over_none"]),
                        (float(row["peak_rss_mb"]) - none_peak) * 2**20 / triangles,
                        delta=2**20 / triangles + 0.1)  # the CSV rounds both peaks to 1 MB
            series = {(t, c) for t in ("none", "shadowmap") for c in ("still", "moving")}
            self.assertEqual(asked, {2000: series, 20000: series})
            self.assertIn("| triangles | technique | camera |", stdout)
            self.assertIn("Cost exponent", stdout)
            self.assertIn("VmHWM", stdout)
            self.assertIn("B/tri over none", stdout)
            with open(os.path.join(out, "sweep.png"), "rb") as f:
                png = f.read()
            self.assertTrue(png.startswith(b"\x89PNG"))
            self.assertGreater(len(png), 2000)
            self.assertGreater(os.path.getsize(os.path.join(out, "sweep_scene.png")), 1000)

    def test_scale_sweep_moving_light(self):
        # --moving-light adds a row per technique with the sun turning: the shadow map is
        # refitted and rendered again every frame there, and kept while nothing moves.
        with tempfile.TemporaryDirectory() as out:
            code, _, stderr = run_bench(out, "--scale-sweep", "2000", "--moving-light",
                                        "--techniques", "shadowmap:fit=scene", "--size",
                                        "160x120", "--frames", "3")
            self.assertEqual(code, 0, stderr)
            rows = read_csv(out, "sweep.csv")
            cameras = {(row["technique"], row["camera"]): row for row in rows}
            self.assertEqual(set(cameras), {(t, c) for t in ("none", "shadowmap")
                                            for c in ("still", "moving", "light moving")})
            for row in rows:
                self.assertEqual(row["status"], "measured")
            still = float(cameras[("shadowmap", "still")]["technique_ms"])
            turning = float(cameras[("shadowmap", "light moving")]["technique_ms"])
            self.assertGreater(turning, 2.0 * still, (still, turning))
            self.assertGreater(float(cameras[("shadowmap", "light moving")]["ratio_to_none"]),
                               0.0)

    def test_scale_sweep_budget(self):
        # A row whose first frame after the technique is installed needs more than the
        # budget, or whose first timed frame needs more than its share of it, is not
        # measured, and the larger counts of its series are not even tried; with no point
        # left to chart the run says so (exit 3) instead of drawing an empty chart.
        with tempfile.TemporaryDirectory() as out:
            code, stdout, stderr = run_bench(out, "--scale-sweep", "2000,20000", "--frames", "2",
                                             "--techniques", "none", "--budget", "1e-6")
            self.assertEqual(code, 3, stderr)
            self.assertIn("no measured point", stderr)
            rows = read_csv(out, "sweep.csv")
            self.assertEqual(len(rows), 4)
            for row in rows:
                self.assertEqual(row["median_ms"], "")
                self.assertEqual(row["exponent"], "")
                if int(row["triangles"]) > 6000:
                    self.assertIn("over budget at a smaller count", row["status"])
                elif row["camera"] == "still":
                    self.assertIn("the first frame took", row["status"])
                else:
                    self.assertIn("one frame took", row["status"])


if __name__ == "__main__":
    unittest.main()
