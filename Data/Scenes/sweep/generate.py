#!/usr/bin/env python3
"""Writes the shadow-volume exactness sweep: every scene below under a sun, a low sun, a spot
and a point light, from two cameras (one scene file each, first light = the compared one).

    python3 Data/Scenes/sweep/generate.py        # rewrites Data/Scenes/sweep/*.json
    for size in 256x192 320x240 200x150; do
      build/bin/penumbra-bench --scenes "$(ls Data/Scenes/sweep/*.json | paste -sd,)" \\
        --techniques volumes,volumes:silhouettes=gpu --size $size --frames 1 --warmup 0 \\
        --no-images --out /tmp/sweep-$size
    done

Every row of results.csv must show 0 mismatches (volumes are exact, see
vtkPenumbraShadowVolumeShadows.h).
"""
import json
import os

HERE = os.path.dirname(os.path.abspath(__file__))


def plane(x0, x1, y0, y1, z, res=8):
    return {"type": "plane", "origin": [x0, y0, z], "point1": [x1, y0, z], "point2": [x0, y1, z],
            "resolution": res}


# name: objects, bounds (x0, x1, y0, y1, z0, z1), up axis, cameras (auto positions)
SCENES = {
    "bunny": ([{"name": "bunny", "file": "$DATA/meshes/bunny.ply"},
               {"name": "ground", "generator": {"type": "plane", "origin": [-0.2, 0.0329, -0.2],
                "point1": [-0.2, 0.0329, 0.2], "point2": [0.2, 0.0329, -0.2], "resolution": 8}}],
              (-0.095, 0.061, 0.033, 0.187, -0.062, 0.059), 1),
    "carotid": ([{"name": "vessels", "generator": {"type": "isosurface",
                  "file": "$DATA/volumes/carotid.vtk", "iso_value": 90}},
                 {"name": "floor", "generator": plane(90, 185, 70, 138, 0)}],
                (100, 175, 80, 128, 1, 45), 2),
    "st_helens": ([{"name": "terrain", "generator": {"type": "terrain",
                    "file": "$DATA/volumes/SainteHelens.dem", "sample_rate": 2}}],
                  (557945, 567725, 5107991, 5121971, 682, 2543), 2),
    "city": ([{"name": "city", "generator": {"type": "city_block", "rows": 4, "columns": 5,
               "spacing": 30, "min_height": 8, "max_height": 45, "seed": 7,
               "ground_margin": 25}}],
             (-100, 100, -85, 85, 0, 45), 2),
    "iso_dense": ([{"name": "field", "generator": {"type": "isosurface", "resolution": 160}},
                   {"name": "ground", "generator": plane(-2.5, 2.5, -2.5, 2.5, -1.2, 16)}],
                  (-1, 1, -1, 1, -1.2, 1), 2),
    "iso_huge": ([{"name": "field", "generator": {"type": "isosurface", "resolution": 320}},
                  {"name": "ground", "generator": plane(-2.5, 2.5, -2.5, 2.5, -1.2, 16)}],
                 (-1, 1, -1, 1, -1.2, 1), 2),
}


def lights(b, up):
    """Sun, low sun, spot and point light for bounds b, `up` the vertical axis index."""
    c = [(b[0] + b[1]) / 2, (b[2] + b[3]) / 2, (b[4] + b[5]) / 2]
    ext = [b[1] - b[0], b[3] - b[2], b[5] - b[4]]
    size = max(ext)

    def at(dx, dy, height):
        # dx, dy: horizontal offsets (fractions of the size); height above the top.
        p = list(c)
        horiz = [a for a in range(3) if a != up]
        p[horiz[0]] += dx * size
        p[horiz[1]] += dy * size
        p[up] = b[2 * up + 1] + height * size
        return p

    def direction(dx, dy, down):
        d = [0.0, 0.0, 0.0]
        horiz = [a for a in range(3) if a != up]
        d[horiz[0]], d[horiz[1]], d[up] = dx, dy, -down
        return d

    return {
        "sun": {"type": "directional", "direction": direction(0.4, 0.5, 1.0)},
        "lowsun": {"type": "directional", "direction": direction(-0.9, 0.3, 0.25)},
        "spot": {"type": "spot", "position": at(-0.3, -0.2, 0.5), "focal_point": c,
                 "cone_angle": 40},
        "point": {"type": "point", "position": at(0.1, 0.15, 0.15)},
    }


def cameras(up):
    v = [0, 0, 0]
    v[up] = 1
    if up == 1:
        return {"a": {"auto": True, "position": [0.3, 0.6, 1.0], "focal_point": [0, 0, 0],
                      "view_up": v},
                "b": {"auto": True, "position": [-1.0, 0.4, -0.3], "focal_point": [0, 0, 0],
                      "view_up": v, "zoom": 1.5}}
    return {"a": {"auto": True, "position": [-0.5, -1, 0.8], "focal_point": [0, 0, 0],
                  "view_up": v},
            "b": {"auto": True, "position": [1.0, 0.3, 0.35], "focal_point": [0, 0, 0],
                  "view_up": v, "zoom": 1.6}}


def main():
    for old in os.listdir(HERE):
        if old.endswith(".json"):
            os.remove(os.path.join(HERE, old))
    for name, (objects, bounds, up) in SCENES.items():
        for lname, light in lights(bounds, up).items():
            for cname, camera in cameras(up).items():
                scene = {
                    "description": f"Shadow-volume sweep: {name}, {lname} light, camera {cname}.",
                    "image": {"width": 256, "height": 192},
                    "objects": objects,
                    "lights": [light],
                    "camera": camera,
                    "technique": {"name": "volumes"},
                }
                write(f"{name}_{lname}_{cname}", scene)
    # The eight lights of city_lights.json (street lamps and spots close to the walls), each
    # as the compared first light.
    with open(os.path.join(HERE, "..", "city_lights.json")) as f:
        city = json.load(f)
    for k, light in enumerate(city["lights"]):
        for cname, camera in cameras(2).items():
            scene = dict(city, lights=[light], camera=camera,
                         image={"width": 256, "height": 192},
                         description=f"Shadow-volume sweep: city_lights light {k}, camera {cname}.")
            write(f"city_lamp{k}_{cname}", scene)


def write(stem, scene):
    with open(os.path.join(HERE, stem + ".json"), "w") as f:
        json.dump(scene, f, indent=1)
        f.write("\n")


if __name__ == "__main__":
    main()
