"""Peak memory per caster triangle of every technique over the unshadowed frame, one process per
technique (so that no row holds what an earlier technique left resident): runs
`penumbra-bench --scale-sweep N --techniques none,T` for each technique T and prints the
sweep's `bytes_per_triangle_over_none` column as one markdown table (and a CSV with --csv).

Run from the checkout after a build (docs/benchmarks-scale-sweep.md, "Memory per triangle"):
  python3 docs/measure_memory.py --counts 1e7 [--bench build/bin/penumbra-bench]
      [--techniques raytraced,shadowmap,...] [--csv OUT.csv]
"""
import argparse
import csv
import os
import subprocess
import sys
import tempfile

# Every registered technique but `none` (the baseline of every row) and `vtk-shadowmap`
# (VTK's own pass, a peer: its memory is VTK's).
TECHNIQUES = ["raytraced", "auto", "adaptive-soft", "gears", "conservative", "llsm", "llsm-hybrid",
              "volumes", "shadowmap", "resm", "rmsm", "pcss", "single-sample-soft",
              "soft-shadowmap"]


def run(bench, count, technique, frames, budget, size):
    with tempfile.TemporaryDirectory() as out:
        command = [bench, "--scale-sweep", count, "--techniques", "none," + technique,
                   "--frames", str(frames), "--warmup", "1", "--budget", str(budget),
                   "--size", size, "--out", out]
        env = dict(os.environ, PENUMBRA_HEADLESS=os.environ.get("PENUMBRA_HEADLESS", "1"))
        subprocess.run(command, check=True, stdout=subprocess.DEVNULL, env=env)
        with open(os.path.join(out, "sweep.csv"), newline="") as f:
            return [row for row in csv.DictReader(f) if row["technique"] == technique]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--bench", default=os.path.join("build", "bin", "penumbra-bench"))
    parser.add_argument("--counts", default="1e7")
    parser.add_argument("--techniques", default=",".join(TECHNIQUES))
    parser.add_argument("--frames", type=int, default=1)
    parser.add_argument("--budget", type=int, default=600)
    parser.add_argument("--size", default="1280x720")
    parser.add_argument("--csv")
    args = parser.parse_args()
    rows = []
    for count in args.counts.split(","):
        for technique in args.techniques.split(","):
            found = run(args.bench, count, technique, args.frames, args.budget, args.size)
            rows += found
            for r in found:
                print(f"{r['triangles']} {technique} {r['camera']}: peak {r['peak_rss_mb']} MB, "
                      f"{r['bytes_per_triangle_over_none']} B/tri over none", file=sys.stderr,
                      flush=True)
    print("| triangles | technique | camera | peak RSS MB | B/tri over none | first frame ms |"
          " median ms |")
    print("|---:|---|---|---:|---:|---:|---:|")
    for r in rows:
        print(f"| {r['triangles']} | {r['technique']} | {r['camera']} | {r['peak_rss_mb']} | "
              f"{r['bytes_per_triangle_over_none']} | {r['first_frame_ms']} | {r['median_ms']} |")
    if args.csv:
        with open(args.csv, "w", newline="") as f:
            writer = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
            writer.writeheader()
            writer.writerows(rows)


if __name__ == "__main__":
    main()
