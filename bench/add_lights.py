#!/usr/bin/env python3
"""Lights a copy of a glTF level for the lighting figures (docs/BENCHMARKS.md, issue 21).

usage: add_lights.py IN.gltf OUT_DIR [--points N]

Writes OUT_DIR/NAME.gltf: the scene with KHR_lights_punctual lights added at nodes of their own
(listed in extensionsRequired, as Blender exports a lit level): a sun slanted 35 degrees from
straight down (3 lux), N point lights (40 cd, range a quarter of the scene's size) spread over
the scene a little above its middle height, and a spot (200 cd, cone 0.3/0.6) over the centre.
The scene's other files (buffers, images) are copied beside it (a link would point outside the
scene's folder, which vtbake refuses). The source is never changed.
"""
import argparse
import json
import math
import os
import shutil


def mat_mul(a, b):  # column-major 4x4
    return [sum(a[r + 4 * k] * b[k + 4 * c] for k in range(4)) for c in range(4) for r in range(4)]


def node_matrix(n):
    if "matrix" in n:
        return list(n["matrix"])
    t = n.get("translation", [0, 0, 0])
    x, y, z, w = n.get("rotation", [0, 0, 0, 1])
    s = n.get("scale", [1, 1, 1])
    r = [1 - 2 * (y * y + z * z), 2 * (x * y + z * w), 2 * (x * z - y * w),
         2 * (x * y - z * w), 1 - 2 * (x * x + z * z), 2 * (y * z + x * w),
         2 * (x * z + y * w), 2 * (y * z - x * w), 1 - 2 * (x * x + y * y)]
    return [r[0] * s[0], r[1] * s[0], r[2] * s[0], 0, r[3] * s[1], r[4] * s[1], r[5] * s[1], 0,
            r[6] * s[2], r[7] * s[2], r[8] * s[2], 0, t[0], t[1], t[2], 1]


def world_bounds(doc):
    lo, hi = [math.inf] * 3, [-math.inf] * 3
    ident = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]

    def walk(i, parent):
        n = doc["nodes"][i]
        m = mat_mul(parent, node_matrix(n))
        if "mesh" in n:
            for p in doc["meshes"][n["mesh"]]["primitives"]:
                a = doc["accessors"][p["attributes"]["POSITION"]]
                for cx in (a["min"][0], a["max"][0]):
                    for cy in (a["min"][1], a["max"][1]):
                        for cz in (a["min"][2], a["max"][2]):
                            w = [m[r] * cx + m[4 + r] * cy + m[8 + r] * cz + m[12 + r]
                                 for r in range(3)]
                            for k in range(3):
                                lo[k], hi[k] = min(lo[k], w[k]), max(hi[k], w[k])
        for c in n.get("children", []):
            walk(c, m)

    for r in doc["scenes"][doc.get("scene", 0)]["nodes"]:
        walk(r, ident)
    return lo, hi


def aim(direction):
    """A rotation quaternion turning the node's -Z onto unit `direction`."""
    dx, dy, dz = direction
    # axis = (-Z) x d, angle between -Z and d
    ax, ay, az = dy * 1.0, -dx * 1.0, 0.0
    c = -dz
    s = math.sqrt(ax * ax + ay * ay)
    if s < 1e-9:
        return [0, 0, 0, 1] if c > 0 else [1, 0, 0, 0]
    half = math.atan2(s, c) / 2
    k = math.sin(half) / s
    return [ax * k, ay * k, az * k, math.cos(half)]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("input")
    ap.add_argument("out_dir")
    ap.add_argument("--points", type=int, default=3)
    a = ap.parse_args()
    with open(a.input) as f:
        doc = json.load(f)
    lo, hi = world_bounds(doc)
    size = [hi[k] - lo[k] for k in range(3)]
    mid = [(hi[k] + lo[k]) / 2 for k in range(3)]
    up = 1  # glTF is +Y up
    lights = [{"type": "directional", "name": "sun", "intensity": 3.0, "color": [1, 0.95, 0.85]}]
    tilt = math.radians(35)
    sun_dir = [math.sin(tilt) * 0.8, -math.cos(tilt), math.sin(tilt) * 0.6]
    nodes = [{"name": "sun", "rotation": aim(sun_dir), "extensions": {"KHR_lights_punctual": {"light": 0}}}]
    reach = 0.25 * max(size[0], size[2])
    for i in range(a.points):
        lights.append({"type": "point", "name": "lamp%d" % i, "intensity": 40.0 * (reach / 10) ** 2,
                       "range": reach, "color": [1, 0.8, 0.6]})
        t = (i + 0.5) / a.points
        pos = [lo[0] + size[0] * (0.2 + 0.6 * t), lo[1] + size[1] * 0.35,
               lo[2] + size[2] * (0.3 + 0.4 * ((i * 0.618) % 1))]
        nodes.append({"name": "lamp%d" % i, "translation": pos,
                      "extensions": {"KHR_lights_punctual": {"light": len(lights) - 1}}})
    lights.append({"type": "spot", "name": "spot", "intensity": 200.0 * (reach / 10) ** 2,
                   "color": [0.8, 0.9, 1], "spot": {"innerConeAngle": 0.3, "outerConeAngle": 0.6}})
    nodes.append({"name": "spot", "translation": [mid[0], hi[up] + 0.1 * size[up], mid[2]],
                  "rotation": aim([0, -1, 0]),
                  "extensions": {"KHR_lights_punctual": {"light": len(lights) - 1}}})
    scene = doc["scenes"][doc.get("scene", 0)]
    for n in nodes:
        scene["nodes"].append(len(doc["nodes"]))
        doc["nodes"].append(n)
    doc.setdefault("extensions", {})["KHR_lights_punctual"] = {"lights": lights}
    for key in ("extensionsUsed", "extensionsRequired"):
        doc[key] = sorted(set(doc.get(key, [])) | {"KHR_lights_punctual"})
    os.makedirs(a.out_dir, exist_ok=True)
    src = os.path.dirname(os.path.abspath(a.input))
    for name in os.listdir(src):
        dst = os.path.join(a.out_dir, name)
        if not name.endswith(".gltf") and not os.path.exists(dst):
            shutil.copy(os.path.join(src, name), dst)
    out = os.path.join(a.out_dir, os.path.basename(a.input))
    with open(out, "w") as f:
        json.dump(doc, f)
    print("%s: bounds %s .. %s, %d lights" % (out, [round(v, 2) for v in lo],
                                               [round(v, 2) for v in hi], len(lights)))


if __name__ == "__main__":
    main()
