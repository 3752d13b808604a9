"""The memory and traffic model of distributed shadows, fitted to and checked against the
measurements of Wrapping/ParaView/Testing/measure_distributed.py (docs/paraview.md).

    python3 docs/distributed_model.py MEASUREMENTS.csv

Model, for N triangles spread spatially over P ranks (each rank a piece of side s of a
scene of area A, s = sqrt(A / P)), with lights that reach a band of width l around a piece
(a sun's shadow length, the part of a point light's cone near the piece):

- need: a rank holds its own N / P triangles and the other ranks' casters inside the band:
  held = c_need * N / sqrt(P) (the band's area l * s over the piece's s * s is l / s, which
  grows as sqrt(P)); bytes on a data or light change = 72 * held (the triangles' doubles);
  a static or camera frame: 4 bytes (one all-reduce).
- distributed: a rank holds only its own triangles; every frame it sends the lit samples'
  rays that cross other ranks' caster boxes, 28 bytes a ray and a bit back:
  rays = c_rays * pixels / sqrt(P) (the samples near the piece's boundary, a band of the
  piece's share of the screen, pixels / P, times its perimeter ratio sqrt(P)), independent
  of N.
- memory per rank = N / P * own_bytes + held * 333 (the held triangle's copies as of
  2026-11; 297 since 2026-12-07, kept at 333 to reproduce docs/paraview.md), own_bytes from
  the 1-rank run's peak RSS.

c_need and c_rays are fitted (least squares through the origin) on the measured ranks > 1;
the table prints measured against model, then the projection to 64..1024 ranks and 1e8, 1e9
triangles at the measured image size.
"""
import csv
import math
import sys


def load(path):
    rows = list(csv.DictReader(open(path)))
    for r in rows:
        for k, v in r.items():
            if k not in ("mode", "frame"):
                r[k] = float(v)
    return rows


def fit(points):
    """c minimising sum (y - c x)^2."""
    sxx = sum(x * x for x, _ in points)
    return sum(x * y for x, y in points) / sxx if sxx else 0.0


def measured(rows):
    """The measurements, a row per rank count and mode."""
    kinds = ("first", "static", "camera", "light", "data")
    print("| ranks | mode | peak RSS per rank (MiB) | other ranks' triangles held (most, first frame) | "
          "KiB sent per rank: first / static / camera / light / data | "
          "frame ms: first / static / camera / light / data |")
    print("|---:|---|---:|---:|---|---|")
    keys = sorted({(int(r["ranks"]), r["mode"]) for r in rows},
                  key=lambda k: (k[0], ("need", "all", "distributed").index(k[1])))
    for p, m in keys:
        by = {r["frame"]: r for r in rows if int(r["ranks"]) == p and r["mode"] == m}
        if not all(k in by for k in kinds):
            continue
        print("| %d | %s | %.0f | %.0f | %s | %s |" % (
            p, m, max(by[k]["max_peak_rss_mib"] for k in kinds), by["first"]["max_held"],
            " / ".join("%.0f" % (by[k]["max_bytes_sent"] / 1024.0) for k in kinds),
            " / ".join("%.0f" % by[k]["max_frame_ms"] for k in kinds)))
    print()


def main(path):
    rows = load(path)
    measured(rows)
    pixels = 512 * 384
    first = {(r["mode"], int(r["ranks"])): r for r in rows if r["frame"] == "first"}
    camera = {(r["mode"], int(r["ranks"])): r for r in rows if r["frame"] == "camera"}
    n = next(iter(first.values()))["triangles"]
    # Fitted where the pieces tile the ground (RedistributeDataSet cuts x, then y, then z: at
    # 8 ranks each quadrant is cut into its lower and upper half).
    need = [(n / math.sqrt(p), r["max_held"]) for (m, p), r in first.items()
            if m == "need" and 1 < p <= 4]
    rays = [(pixels / math.sqrt(p), r["max_rays_sent"]) for (m, p), r in camera.items()
            if m == "distributed" and 1 < p <= 4]
    c_need, c_rays = fit(need), fit(rays)
    one = first.get(("need", 1))
    own_bytes = one["max_peak_rss_mib"] * 1048576.0 / n if one else 600.0
    print("fitted: c_need = %.3f, c_rays = %.3f, own %.0f bytes a triangle (1-rank peak RSS)"
          % (c_need, c_rays, own_bytes))
    print("\n| ranks | held, measured | held, model | rays/frame, measured | rays/frame, model |")
    print("|---:|---:|---:|---:|---:|")
    for p in sorted({p for _, p in first}):
        if p == 1:
            continue
        held = first.get(("need", p), {}).get("max_held", float("nan"))
        sent = camera.get(("distributed", p), {}).get("max_rays_sent", float("nan"))
        if p <= 4:
            model = "%.0f" % (c_need * n / math.sqrt(p))
            ray_model = "%.0f" % (c_rays * pixels / math.sqrt(p))
        else:
            # Pieces cut in z too: a valley half holds its hill twin (N / P) and the band of
            # the quadrant tiling (P / 2 tiles); its rays are not modelled.
            model = "%.0f (z cut: N/P + band of P/2 tiles)" % (
                n / p + c_need * n / math.sqrt(p / 2))
            ray_model = "-"
        print("| %d | %.0f | %s | %.0f | %s |" % (p, held, model, sent, ray_model))
    print("\n| triangles | ranks | need: held per rank | need: MiB per rank | need: MiB sent on "
          "a change | distributed: MiB per rank | distributed: KiB per frame |")
    print("|---:|---:|---:|---:|---:|---:|---:|")
    for total in (1e8, 1e9):
        for p in (64, 128, 256, 512, 1024):
            held = c_need * total / math.sqrt(p)
            own = total / p * own_bytes
            ray_kib = c_rays * pixels / math.sqrt(p) * (28 + 1.0 / 8) / 1024.0
            print("| %.0e | %d | %.3g | %.0f | %.0f | %.0f | %.0f |" % (
                total, p, held, (own + 333 * held) / 1048576.0, 72 * held / 1048576.0,
                own / 1048576.0, ray_kib))


if __name__ == "__main__":
    main(sys.argv[1])
