#!/usr/bin/env python3
"""A ground truth for a rectangle of one validate view, made outside vtbake's renderer: each
pixel ray-cast at GRID x GRID sub-pixel points through the view's camera onto the unwrapped
scene (the .glb `vtbake bake` wrote beside the page file), each point's source UV (TEXCOORD_0)
sampled bilinearly at level 0 of its material's base colour image (repeat wrap, codes as
stored), the points averaged. Prints the PSNR of the reference and the virtual render against it
and against each other, over the pixels the textured surface covers whole. Needs python3 and
oiiotool (to read the images); pure Python, so keep the rectangle small.

  scripts/pixel_truth.py BAKE.glb VALIDATE_DIR VIEW X0 Y0 X1 Y1 [--grid N]

VALIDATE_DIR is what `vtbake validate --out` wrote (report.json, view_N_reference.png,
view_N_virtual.png). Used for docs/BENCHMARKS.md, "Sheared footprints".
"""
import argparse
import json
import math
import os
import struct
import subprocess
import tempfile


def read_glb(path):
    data = open(path, "rb").read()
    length, _ = struct.unpack_from("<II", data, 12)
    doc = json.loads(data[20:20 + length])
    off = 20 + length
    blen, _ = struct.unpack_from("<II", data, off)
    return doc, data[off + 8:off + 8 + blen]


def accessor(doc, blob, i):
    a = doc["accessors"][i]
    bv = doc["bufferViews"][a["bufferView"]]
    n = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4}[a["type"]]
    fmt = {5126: "f", 5125: "I", 5123: "H", 5121: "B"}[a["componentType"]]
    size = struct.calcsize(fmt)
    stride = bv.get("byteStride", size * n)
    base = bv.get("byteOffset", 0) + a.get("byteOffset", 0)
    return [struct.unpack_from("<" + fmt * n, blob, base + k * stride) for k in range(a["count"])]


def read_rgb(path, tmp):
    """(width, height, bytes) of an image's RGB channels, through oiiotool and binary PPM."""
    out = os.path.join(tmp, "%d.ppm" % len(os.listdir(tmp)))
    subprocess.run(["oiiotool", path, "--ch", "R,G,B", "-o", out], check=True)
    raw = open(out, "rb").read()
    parts = raw.split(b"\n", 3)
    w, h = map(int, parts[1].split())
    return w, h, parts[3]


def mat_mul(a, b):
    return [[sum(a[r][k] * b[k][c] for k in range(4)) for c in range(4)] for r in range(4)]


def node_matrix(node):
    if "matrix" in node:
        m = node["matrix"]
        return [[m[c * 4 + r] for c in range(4)] for r in range(4)]
    t = node.get("translation", [0, 0, 0])
    x, y, z, w = node.get("rotation", [0, 0, 0, 1])
    s = node.get("scale", [1, 1, 1])
    r = [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
         [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
         [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]
    return [[r[i][0] * s[0], r[i][1] * s[1], r[i][2] * s[2], t[i]] for i in range(3)] + [[0, 0, 0, 1]]


def sub(a, b):
    return [a[0] - b[0], a[1] - b[1], a[2] - b[2]]


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def unit(a):
    n = math.sqrt(dot(a, a))
    return [c / n for c in a]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("glb")
    ap.add_argument("validate_dir")
    ap.add_argument("view", type=int)
    ap.add_argument("rect", type=int, nargs=4, metavar="X0 Y0 X1 Y1")
    ap.add_argument("--grid", type=int, default=8)
    args = ap.parse_args()
    x0, y0, x1, y1 = args.rect
    doc, blob = read_glb(args.glb)
    report = json.load(open(os.path.join(args.validate_dir, "report.json")))
    cam = report["view_plan"]["views"][args.view]
    width, height = report["width"], report["height"]
    tmp = tempfile.mkdtemp()
    glb_dir = os.path.dirname(os.path.abspath(args.glb))
    images = {}

    def image_of(material):
        tex = doc["materials"][material].get("pbrMetallicRoughness", {}).get("baseColorTexture")
        if tex is None:
            return None
        src = doc["textures"][tex["index"]]["source"]
        if src not in images:
            images[src] = read_rgb(os.path.join(glb_dir, doc["images"][src]["uri"]), tmp)
        return images[src]

    # World-space triangles: (positions, source UVs or None, image or None).
    tris = []

    def walk(n, parent):
        node = doc["nodes"][n]
        m = mat_mul(parent, node_matrix(node))
        if "mesh" in node:
            for p in doc["meshes"][node["mesh"]]["primitives"]:
                a = p["attributes"]
                pos = [[sum(m[r][c] * q[c] for c in range(3)) + m[r][3] for r in range(3)]
                       for q in accessor(doc, blob, a["POSITION"])]
                img = image_of(p["material"]) if "material" in p else None
                uv = accessor(doc, blob, a["TEXCOORD_0"]) if img and "TEXCOORD_0" in a else None
                idx = [k[0] for k in accessor(doc, blob, p["indices"])]
                for t in range(len(idx) // 3):
                    v = idx[3 * t:3 * t + 3]
                    tris.append(([pos[k] for k in v], [uv[k] for k in v] if uv else None, img))
        for c in node.get("children", []):
            walk(c, m)

    identity = [[float(r == c) for c in range(4)] for r in range(4)]
    for root in doc["scenes"][doc.get("scene", 0)]["nodes"]:
        walk(root, identity)

    eye = cam["eye"]
    f = unit(sub(cam["target"], eye))
    s = unit(cross(f, cam["up"]))
    u = cross(s, f)
    t = 1 / math.tan(math.radians(cam["fov_y_deg"]) / 2)
    aspect = width / height

    def ndc(px, py):
        return px / width * 2 - 1, py / height * 2 - 1  # Vulkan: row 0 at the top

    def project(p):
        d = sub(p, eye)
        z = dot(d, f)
        return (dot(d, s) / z * t / aspect, -dot(d, u) / z * t) if z > 0 else None

    lo, hi = ndc(x0, y0), ndc(x1, y1)
    near = []
    for tri in tris:
        pp = [project(p) for p in tri[0]]
        if None not in pp and (max(q[0] for q in pp) < lo[0] or min(q[0] for q in pp) > hi[0] or
                               max(q[1] for q in pp) < lo[1] or min(q[1] for q in pp) > hi[1]):
            continue
        near.append(tri)

    def hit(nx, ny):
        d = unit([f[i] + s[i] * nx * aspect / t - u[i] * ny / t for i in range(3)])
        best = None
        for tri in near:
            a, b, c = tri[0]
            e1, e2 = sub(b, a), sub(c, a)
            pv = cross(d, e2)
            det = dot(e1, pv)
            if abs(det) < 1e-14:
                continue
            tv = sub(eye, a)
            l1 = dot(tv, pv) / det
            if l1 < 0 or l1 > 1:
                continue
            qv = cross(tv, e1)
            l2 = dot(d, qv) / det
            if l2 < 0 or l1 + l2 > 1:
                continue
            z = dot(e2, qv) / det
            if z > 0 and (best is None or z < best[0]):
                best = (z, tri, l1, l2)
        return best

    def bilinear(img, sv, tv):
        w, h, px = img
        x, y = sv * w - 0.5, tv * h - 0.5
        fx, fy = math.floor(x), math.floor(y)
        ax, ay = x - fx, y - fy

        def texel(i, j, ch):
            return px[((j % h) * w + (i % w)) * 3 + ch]

        return [(texel(fx, fy, ch) * (1 - ax) + texel(fx + 1, fy, ch) * ax) * (1 - ay) +
                (texel(fx, fy + 1, ch) * (1 - ax) + texel(fx + 1, fy + 1, ch) * ax) * ay
                for ch in range(3)]

    truth = {}
    g = args.grid
    for py in range(y0, y1):
        for px in range(x0, x1):
            total, whole = [0.0, 0.0, 0.0], True
            for j in range(g):
                for i in range(g):
                    h = hit(*ndc(px + (i + 0.5) / g, py + (j + 0.5) / g))
                    if h is None or h[1][1] is None:
                        whole = False
                        break
                    _, tri, l1, l2 = h
                    uv = [tri[1][0][k] * (1 - l1 - l2) + tri[1][1][k] * l1 + tri[1][2][k] * l2
                          for k in range(2)]
                    total = [a + b for a, b in zip(total, bilinear(tri[2], uv[0], uv[1]))]
                if not whole:
                    break
            if whole:
                truth[(px, py)] = [c / (g * g) for c in total]

    renders = {}
    for name in ("reference", "virtual"):
        w, _, px = read_rgb(os.path.join(args.validate_dir, "view_%d_%s.png" % (args.view, name)),
                            tmp)
        renders[name] = lambda x, y, w=w, px=px: [px[(y * w + x) * 3 + c] for c in range(3)]

    def psnr(a, b):
        se = sum((ca - cb) ** 2 for k in truth for ca, cb in zip(a(*k), b(*k)))
        return 10 * math.log10(255 ** 2 * 3 * len(truth) / se) if se else float("inf")

    exact = lambda x, y: truth[(x, y)]
    print("pixels covered whole by textured surfaces: %d" % len(truth))
    if truth:
        print("reference vs truth  %.2f dB" % psnr(renders["reference"], exact))
        print("virtual   vs truth  %.2f dB" % psnr(renders["virtual"], exact))
        print("reference vs virtual %.2f dB" % psnr(renders["reference"], renders["virtual"]))


if __name__ == "__main__":
    main()
