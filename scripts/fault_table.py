#!/usr/bin/env python3
"""The fault table of docs/RELIABILITY.md: builds its own cases and runs vtbake on each.

Classes: page-file corruption with stale and with recomputed checksums (bit flips,
truncations, header field edits), hostile scenes (glTF/OBJ/PLY mutations), hostile images,
SIGKILL mid-bake (is the .vtpf/.glb pair intact?), disk full (a small tmpfs, else
RLIMIT_FSIZE), and a page file truncated while a reader has it open. Per class: cases tried,
crashes (killed by a signal), hangs (past the timeout), silent wrong outputs (exit 0 but the
output differs from the clean one, or verify passes a file that is not what was written) and
clear errors (a non-zero exit with a message naming the problem). Run through
scripts/fault-table.sh; not part of CI (minutes of work).
"""
import argparse
import ctypes
import hashlib
import json
import os
import random
import resource
import shutil
import signal
import struct
import subprocess
import sys
import threading
import time
import zlib

TIMEOUT = 20
XXH = ctypes.CDLL("libxxhash.so.0")
XXH.XXH3_64bits.restype = ctypes.c_uint64
XXH.XXH3_64bits.argtypes = [ctypes.c_char_p, ctypes.c_size_t]


def xxh3(data):
    return XXH.XXH3_64bits(bytes(data), len(data))


class Counts:
    def __init__(self, name):
        self.name, self.tried, self.crash, self.hang, self.silent = name, 0, 0, 0, 0
        self.clear, self.unclear, self.accepted, self.notes = 0, 0, 0, []

    def row(self):
        return [self.name, self.tried, self.crash, self.hang, self.silent, self.clear,
                self.unclear, self.accepted]


def run(vtbake, args, timeout=TIMEOUT, limit_as=4 << 30, preexec=None):
    """(kind, rc, stderr): kind is 'ok', 'error', 'unclear', 'crash' or 'hang'."""
    def setup():
        resource.setrlimit(resource.RLIMIT_AS, (limit_as, limit_as))
        resource.setrlimit(resource.RLIMIT_CORE, (0, 0))
        if preexec:
            preexec()
    try:
        p = subprocess.run([vtbake] + args, capture_output=True, timeout=timeout,
                           preexec_fn=setup)
    except subprocess.TimeoutExpired:
        return "hang", None, ""
    err = p.stderr.decode(errors="replace")
    if p.returncode < 0:
        return "crash", p.returncode, err
    if p.returncode == 0:
        return "ok", 0, err
    # A clear error names the problem in one vtbake line; an internal error, bad_alloc or a
    # library's stray line is not clear.
    if p.returncode == 1 and not err.strip():
        return "error", 1, err  # a finished run whose own checks failed (unwrap's atlas check)
    bad = ("internal error", "bad_alloc", "PNG library error", "terminate called")
    return ("unclear" if any(b in err for b in bad) or "vtbake" not in err else "error",
            p.returncode, err)


def tally(c, kind, err="", silent=False, note=""):
    c.tried += 1
    if kind == "crash":
        c.crash += 1
        c.notes.append("crash: " + note)
    elif kind == "hang":
        c.hang += 1
        c.notes.append("hang: " + note)
    elif kind == "unclear":
        c.unclear += 1
        c.notes.append("unclear: %s: %s" % (note, err.strip().splitlines()[-1:]))
    elif kind == "error":
        c.clear += 1
    elif silent:
        c.silent += 1
        c.notes.append("silent: " + note)
    else:
        c.accepted += 1


def digest(path):
    with open(path, "rb") as f:
        return hashlib.sha256(f.read()).hexdigest()


# ---- page files ------------------------------------------------------------------------

def page_file_layout(data):
    """Header fields and the layer records (offset, texel_bytes) of a page file, or None."""
    if len(data) < 128:
        return None
    hs, = struct.unpack_from("<I", data, 12)
    levels, layers = struct.unpack_from("<II", data, 32)
    io, isz, do, dsz, mo, msz = struct.unpack_from("<6Q", data, 48)
    recs, at = [], 120 + 8 * levels
    for _ in range(min(layers, 16)):
        if at + 16 > len(data):
            return None
        ch, tt, nl = data[at + 1], data[at + 2], data[at + 7]
        ts, = struct.unpack_from("<I", data, at + 8)
        recs.append((at, ch * (1, 2, 4)[tt] if tt < 3 else 0))
        at += 16 + (nl + ts + 7) // 8 * 8
    return dict(hs=hs, io=io, isz=isz, mo=mo, msz=msz, layers=recs)


def recompute_checksums(data):
    """Every checksum made to match the (mutated) bytes, so that the structural checks and the
    decoders see the mutation rather than the checksum."""
    d = bytearray(data)
    lay = page_file_layout(d)
    if not lay or lay["hs"] < 16 or lay["hs"] > len(d) or not lay["layers"]:
        return bytes(d)
    n = len(lay["layers"])
    if lay["io"] + lay["isz"] <= len(d):
        for e in range(lay["io"], lay["io"] + lay["isz"] - 31, 32):
            state = d[e]
            size, = struct.unpack_from("<I", d, e + 4)
            if state == 2:
                off, = struct.unpack_from("<Q", d, e + 8)
                if off + size <= len(d):
                    struct.pack_into("<Q", d, e + 24, xxh3(d[off:off + size]))
            elif state == 1:
                tb = lay["layers"][((e - lay["io"]) // 32) % n][1]
                struct.pack_into("<Q", d, e + 24, xxh3(d[e + 8:e + 8 + tb]))
        struct.pack_into("<Q", d, 104, xxh3(d[lay["io"]:lay["io"] + lay["isz"]]))
    if lay["mo"] + lay["msz"] <= len(d):
        struct.pack_into("<Q", d, 112, xxh3(d[lay["mo"]:lay["mo"] + lay["msz"]]))
    hs = lay["hs"]
    struct.pack_into("<Q", d, hs - 8, xxh3(d[:hs - 8]))
    return bytes(d)


def header_field_edit(data, rng):
    d = bytearray(data)
    lay = page_file_layout(d)
    # Fixed-part fields (offset, width) and the layer records' bytes.
    fields = [(8, 4), (12, 4), (16, 4), (20, 4), (24, 4), (28, 4), (32, 4), (36, 4), (40, 4),
              (48, 8), (56, 8), (64, 8), (72, 8), (80, 8), (88, 8), (96, 8)]
    for at, _ in lay["layers"]:
        fields += [(at + k, 1) for k in range(8)] + [(at + 8, 4)]
    off, width = rng.choice(fields)
    old = int.from_bytes(d[off:off + width], "little")
    value = rng.choice([0, 1, 2, 3, 4, 5, old + 1, old - 1, old * 2, (1 << (8 * width)) - 1,
                        1 << (8 * width - 1), rng.getrandbits(8 * width)]) % (1 << (8 * width))
    d[off:off + width] = value.to_bytes(width, "little")
    return bytes(d), "field@%d=%d" % (off, value)


def page_mutations(clean, rng, n):
    """(name, bytes, region) triples: region 'data' for mutations inside stored page bytes."""
    lay = page_file_layout(clean)
    data_start = lay["io"] + lay["isz"]
    out = []
    for i in range(n):
        d = bytearray(clean)
        pos = rng.randrange(len(d))
        d[pos] ^= 1 << rng.randrange(8)
        out.append(("flip@%d" % pos, bytes(d), "data" if data_start <= pos < lay["mo"] else "meta"))
    for i in range(n // 4):
        cut = rng.randrange(len(clean))
        out.append(("truncate@%d" % cut, clean[:cut], "meta"))
    for i in range(n // 2):
        d, name = header_field_edit(clean, rng)
        out.append((name, d, "meta"))
    return out


def extract_all(vtbake, path, work, pairs, tag):
    """The (layer, level) pairs extracted as EXR; (worst kind, list of digests)."""
    outs, kinds, err = [], [], ""
    for layer, level in pairs:
        o = os.path.join(work, "%s_%d_%d.exr" % (tag, layer, level))
        if os.path.exists(o):
            os.unlink(o)
        kind, _, e = run(vtbake, ["extract", path, "--level", str(level), "--layer", str(layer),
                                  "-o", o])
        kinds.append(kind)
        err = err or e
        outs.append(digest(o) if kind == "ok" else None)
    for k in ("crash", "hang", "unclear", "error"):
        if k in kinds:
            return k, outs, err
    return "ok", outs, err


def page_file_classes(vtbake, work, rng, n, classes):
    sources = []
    for codec in ("dct", "bc", "raw"):
        p = os.path.join(work, "clean_%s.vtpf" % codec)
        subprocess.run([vtbake, "-q", "build", "procedural:300x260", "--layer",
                        "normal=procedural:300x260", "--codec", codec, "-o", p], check=True)
        info = json.loads(subprocess.run([vtbake, "--json", "info", p], capture_output=True,
                                         check=True).stdout)
        levels = info["level_count"]
        # Level 0 of each layer (the most pages), and the last level of the first.
        pairs = [(layer, 0) for layer in range(len(info["layers"]))] + [(0, levels - 1)]
        ref = extract_all(vtbake, p, work, pairs, "ref_" + codec)[1]
        with open(p, "rb") as f:
            sources.append((codec, f.read(), pairs, ref))
    stale = Counts("page file, stale checksums")
    rec_meta = Counts("page file, recomputed checksums: header/index")
    rec_data = Counts("page file, recomputed checksums: page bytes")
    target = os.path.join(work, "mutant.vtpf")
    for codec, clean, pairs, ref in sources:
        for name, mutated, region in page_mutations(clean, rng, n):
            for recompute in (False, True):
                data = recompute_checksums(mutated) if recompute else mutated
                if data == clean:
                    continue
                with open(target, "wb") as f:
                    f.write(data)
                c = stale if not recompute else rec_data if region == "data" else rec_meta
                note = "%s %s%s" % (codec, name, " (recomputed)" if recompute else "")
                vkind, _, verr = run(vtbake, ["verify", target])
                ekind, outs, eerr = extract_all(vtbake, target, work, pairs, "m")
                kinds = [vkind, ekind]
                kind = next((k for k in ("crash", "hang", "unclear") if k in kinds), None)
                if kind:
                    tally(c, kind, verr + eerr, note=note)
                elif vkind == "error":
                    tally(c, "error")
                elif ekind == "error":
                    # verify passed a file a reader refuses: not silent, but verify missed it.
                    tally(c, "error")
                    c.notes.append("verify passed, extract refused: " + note)
                else:
                    # Everything read: a silent wrong output when the texels changed. With
                    # recomputed checksums a flip inside page bytes is a consistent new file.
                    tally(c, "ok", silent=outs != ref, note=note)
    classes += [stale, rec_meta, rec_data]


# ---- scenes ----------------------------------------------------------------------------

def glb_quad():
    pos = struct.pack("<12f", 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0)
    uv = struct.pack("<8f", 0, 0, 1, 0, 1, 1, 0, 1)
    idx = struct.pack("<6H", 0, 1, 2, 0, 2, 3) + b"\0\0"
    binary = pos + uv + idx
    doc = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
           "nodes": [{"mesh": 0, "children": []}],
           "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1},
                                       "indices": 2, "material": 0}]}],
           "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [1, 0.5, 0.25, 1]}}],
           "buffers": [{"byteLength": len(binary)}],
           "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48},
                           {"buffer": 0, "byteOffset": 48, "byteLength": 32},
                           {"buffer": 0, "byteOffset": 80, "byteLength": 12}],
           "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
                          "min": [0, 0, 0], "max": [1, 1, 0]},
                         {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2"},
                         {"bufferView": 2, "componentType": 5123, "count": 6,
                          "type": "SCALAR"}]}
    return doc, binary


def pack_glb(doc, binary):
    j = json.dumps(doc).encode()
    j += b" " * (-len(j) % 4)
    body = struct.pack("<II", len(j), 0x4E4F534A) + j + struct.pack("<II", len(binary),
                                                                    0x004E4942) + binary
    return struct.pack("<4sII", b"glTF", 2, 12 + len(body)) + body


def gltf_doc_mutations(rng, n):
    """Structural edits of the JSON document (counts, indices, the node graph, URIs)."""
    out = []
    edits = [
        lambda d: d["accessors"][rng.randrange(3)].update(count=rng.choice(
            [0, 5, 1 << 27, (1 << 31) - 1, -1, 1 << 40])),
        lambda d: d["accessors"][rng.randrange(3)].update(
            byteOffset=rng.choice([1, 3, 4096, -8])),
        lambda d: d["bufferViews"][rng.randrange(3)].update(
            byteLength=rng.choice([0, 1, 1 << 30, -1])),
        lambda d: d["bufferViews"][rng.randrange(3)].update(byteStride=rng.choice([1, 3, 256])),
        lambda d: d["buffers"][0].update(byteLength=rng.choice([0, 1, 1 << 33])),
        lambda d: d["nodes"][0].update(children=[0]),
        lambda d: d["nodes"].append({"children": [0]}) or d["nodes"][0].update(children=[1]),
        lambda d: d["nodes"][0].update(mesh=rng.choice([1, -2, 99])),
        lambda d: d["meshes"][0]["primitives"][0].update(material=rng.choice([5, -3])),
        lambda d: d["meshes"][0]["primitives"][0]["attributes"].update(
            TEXCOORD_0=rng.choice([7, 0, 2])),
        lambda d: d["meshes"][0]["primitives"][0].update(mode=rng.choice([0, 1, 6, 9])),
        lambda d: d["accessors"][2].update(componentType=rng.choice([5120, 5126, 1, 5125])),
        lambda d: d.update(images=[{"uri": "../../../../etc/passwd"}], textures=[{"source": 0}])
        or d["materials"][0]["pbrMetallicRoughness"].update(baseColorTexture={"index": 0}),
        lambda d: d["materials"][0].update(normalTexture={"index": 3}),
        lambda d: d.update(extensionsRequired=["KHR_unknown"]),
    ]
    for i in range(n):
        doc, binary = glb_quad()
        edit = rng.randrange(len(edits))
        edits[edit](doc)
        out.append(("glb edit %d" % edit, "glb", pack_glb(doc, binary)))
    return out


def byte_mutations(name, ext, clean, rng, n):
    out = []
    for i in range(n):
        d = bytearray(clean)
        for _ in range(rng.randint(1, 8)):
            d[rng.randrange(len(d))] = rng.randrange(256)
        out.append(("%s bytes" % name, ext, bytes(d)))
    for i in range(n // 3):
        out.append(("%s truncated" % name, ext, clean[:rng.randrange(len(clean))]))
    return out


OBJ = (b"v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
       b"f 1/1 2/2 3/3\nf 1/1 3/3 4/4\n")


def ply_binary(vertices=4, declared=None):
    head = ("ply\nformat binary_little_endian 1.0\nelement vertex %d\nproperty float x\n"
            "property float y\nproperty float z\nelement face 2\n"
            "property list uchar int vertex_indices\nend_header\n" % (declared or vertices))
    body = struct.pack("<12f", 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0)
    body += struct.pack("<B3i", 3, 0, 1, 2) + struct.pack("<B3i", 3, 0, 2, 3)
    return head.encode() + body


def text_token_mutations(name, ext, clean, rng, n):
    tokens = [b"nan", b"inf", b"-1", b"0", b"99999999999", b"1e39", b"-0", b"/", b"4294967296"]
    out = []
    words = clean.split(b" ")
    for i in range(n):
        w = list(words)
        for _ in range(rng.randint(1, 3)):
            k = rng.randrange(len(w))
            w[k] = rng.choice(tokens) + (b"\n" if w[k].endswith(b"\n") else b"")
        out.append(("%s tokens" % name, ext, b" ".join(w)))
    return out


def scene_class(vtbake, work, rng, n, classes):
    doc, binary = glb_quad()
    cases = gltf_doc_mutations(rng, n)
    cases += byte_mutations("glb", "glb", pack_glb(doc, binary), rng, n)
    cases += byte_mutations("obj", "obj", OBJ, rng, n // 2) + text_token_mutations(
        "obj", "obj", OBJ, rng, n // 2)
    ply = ply_binary()
    cases += byte_mutations("ply", "ply", ply, rng, n // 2)
    cases += [("ply declares 1e8 vertices", "ply", ply_binary(declared=100000000))]
    c = Counts("hostile scenes (glTF/GLB, OBJ, PLY)")
    for name, ext, data in cases:
        path = os.path.join(work, "scene_case." + ext)
        with open(path, "wb") as f:
            f.write(data)
        kind, _, err = run(vtbake, ["-q", "unwrap", path, "-o", os.path.join(work, "u.glb"),
                                    "--size", "1"])
        tally(c, kind, err, note=name)
    classes.append(c)


# ---- images ----------------------------------------------------------------------------

def png_bytes(w, h, fix_crc=True, ihdr=None):
    def chunk(t, d):
        crc = zlib.crc32(t + d) & 0xFFFFFFFF
        return struct.pack(">I", len(d)) + t + d + struct.pack(">I", crc if fix_crc else 0)
    raw = b"".join(b"\0" + bytes((x * 7 + y) % 256 for x in range(w * 3)) for y in range(h))
    hdr = ihdr or struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", hdr) + chunk(b"IDAT", zlib.compress(raw)) +
            chunk(b"IEND", b""))


def image_class(vtbake, work, rng, n, classes):
    clean_png = png_bytes(64, 48)
    cases = byte_mutations("png", "png", clean_png, rng, n)
    for w, h in ((1 << 30, 1 << 30), (0, 5), (65536, 65536), (100000, 1)):
        cases.append(("png header %dx%d" % (w, h), "png",
                      png_bytes(64, 48, ihdr=struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))))
    # Other formats from the page file the build writes (OpenImageIO writes them).
    src = os.path.join(work, "img_src.vtpf")
    subprocess.run([vtbake, "-q", "build", "procedural:200x150", "-o", src], check=True)
    for ext in ("exr", "tif", "jpg"):
        p = os.path.join(work, "img_src." + ext)
        subprocess.run([vtbake, "-q", "extract", src, "--level", "0", "-o", p], check=True)
        with open(p, "rb") as f:
            cases += byte_mutations(ext, ext, f.read(), rng, n // 2)
    c = Counts("hostile images (PNG, EXR, TIFF, JPEG)")
    for name, ext, data in cases:
        path = os.path.join(work, "image_case." + ext)
        with open(path, "wb") as f:
            f.write(data)
        kind, _, err = run(vtbake, ["-q", "build", path, "-o", os.path.join(work, "img.vtpf")])
        tally(c, kind, err, note=name)
    classes.append(c)


# ---- kills, disk full, concurrent truncation ----------------------------------------

def write_bake_scene(folder, colour):
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, "tex.png"), "wb") as f:
        f.write(png_bytes(256, 256) if colour == 0 else png_bytes(200, 300))
    with open(os.path.join(folder, "s.mtl"), "w") as f:
        f.write("newmtl M\nmap_Kd tex.png\n")
    with open(os.path.join(folder, "s.obj"), "wb") as f:
        f.write(b"mtllib s.mtl\nusemtl M\n" + OBJ)
    return os.path.join(folder, "s.obj")


def kill_class(vtbake, work, rng, n, classes):
    a = write_bake_scene(os.path.join(work, "kill_a"), 0)
    b = write_bake_scene(os.path.join(work, "kill_b"), 1)
    out = os.path.join(work, "kill_out")
    os.makedirs(out, exist_ok=True)
    vtpf, glb = os.path.join(out, "k.vtpf"), os.path.join(out, "k.glb")
    bake = lambda scene: [vtbake, "-q", "--threads", "1", "bake", scene, "-o", vtpf, "--size",
                          "6"]
    pairs = {}
    quiet = dict(check=True, stdout=subprocess.DEVNULL)
    for name, scene in (("a", a), ("b", b)):
        t0 = time.time()
        subprocess.run(bake(scene), **quiet)
        pairs[name] = (digest(vtpf), digest(glb), time.time() - t0)
    duration = pairs["b"][2]
    c = Counts("SIGKILL mid-bake (pair replaced together?)")
    staging = lambda: [f for f in os.listdir(out) if ".tmp-" in f or ".old-" in f]
    left_by_kills = unswept = 0
    for i in range(n + 1):
        # This bake also sweeps what the previous kill left (format/atomic_output.h).
        subprocess.run(bake(a), **quiet)
        stale = staging()
        if stale:
            unswept += len(stale)
            c.notes.append("case %d: the next bake left %d staging file(s) of the kill: %s"
                           % (i - 1, len(stale), ", ".join(stale)))
            for f in stale:
                os.unlink(os.path.join(out, f))
        if i == n:
            break
        p = subprocess.Popen(bake(b), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        time.sleep(rng.uniform(0, duration * 1.1))
        p.send_signal(signal.SIGKILL)
        p.wait()
        now = (digest(vtpf), digest(glb))
        intact = now in (pairs["a"][:2], pairs["b"][:2])
        c.tried += 1
        if not intact:
            c.silent += 1
            c.notes.append("mixed pair after a kill at case %d" % i)
        else:
            c.accepted += 1
        left_by_kills += 1 if staging() else 0
    c.notes.append("%d of %d kills left staging files; the next bake swept all but %d"
                   % (left_by_kills, n, unswept))
    classes.append(c)


def disk_full_class(vtbake, work, rng, n, classes):
    mnt = os.path.join(work, "tmpfs")
    os.makedirs(mnt, exist_ok=True)
    mounted = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=4m", "tmpfs", mnt],
                             capture_output=True).returncode == 0
    scene = write_bake_scene(os.path.join(work, "disk_scene"), 0)
    c = Counts("disk full (%s)" % ("4 MiB tmpfs" if mounted else "RLIMIT_FSIZE"))
    try:
        for i in range(n):
            # Fill the file system so that only `room` bytes are left, then build and bake.
            room = rng.randrange(0, 400000)
            for f in os.listdir(mnt):
                os.unlink(os.path.join(mnt, f))
            if mounted:
                st = os.statvfs(mnt)
                with open(os.path.join(mnt, "filler"), "wb") as f:
                    f.write(b"\0" * max(0, st.f_bavail * st.f_frsize - room))
                pre = None
            else:
                def pre(room=room):
                    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
                    resource.setrlimit(resource.RLIMIT_FSIZE, (room, room))
            target = mnt if mounted else work
            args = (["build", "procedural:900x700", "-o", os.path.join(target, "d.vtpf")]
                    if i % 2 == 0 else
                    ["bake", scene, "-o", os.path.join(target, "d.vtpf"), "--size", "4",
                     "--scratch-dir", target])
            kind, _, err = run(vtbake, ["-q"] + args, preexec=pre)
            # Exit 0 must mean a complete file: verify it.
            silent = False
            if kind == "ok":
                silent = run(vtbake, ["verify", os.path.join(target, "d.vtpf")])[0] != "ok"
            tally(c, kind, err, silent=silent, note="%s with %d bytes free" % (args[0], room))
            left = [f for f in os.listdir(target) if ".tmp-" in f]
            if left:
                c.notes.append("%s left %s" % (args[0], left))
    finally:
        if mounted:
            subprocess.run(["umount", mnt])
    classes.append(c)


def truncation_class(vtbake, work, rng, n, classes):
    p = os.path.join(work, "live.vtpf")
    subprocess.run([vtbake, "-q", "build", "procedural:1200x1000", "--codec", "raw", "-o", p],
                   check=True)
    with open(p, "rb") as f:
        clean = f.read()
    ref_out = os.path.join(work, "live_ref.exr")
    subprocess.run([vtbake, "-q", "extract", p, "--level", "0", "-o", ref_out], check=True)
    ref = digest(ref_out)
    c = Counts("page file truncated while open")
    for i in range(n):
        with open(p, "wb") as f:
            f.write(clean)
        stop = threading.Event()

        def vandal():
            while not stop.is_set():
                with open(p, "r+b") as f:
                    f.truncate(rng.randrange(len(clean)))
                time.sleep(0.002)
                with open(p, "r+b") as f:
                    f.write(clean)
                time.sleep(0.002)
        t = threading.Thread(target=vandal)
        out = os.path.join(work, "live_out.exr")
        cmd = ["verify", p] if i % 2 else ["extract", p, "--level", "0", "-o", out]
        t.start()
        kind, _, err = run(vtbake, cmd)
        stop.set()
        t.join()
        silent = kind == "ok" and cmd[0] == "extract" and digest(out) != ref
        tally(c, kind, err, silent=silent, note=" ".join(cmd[:1]))
    classes.append(c)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--vtbake", default="build/release/cli/vtbake")
    ap.add_argument("--work", default="/tmp/vtbake-faults")
    ap.add_argument("--seed", type=int, default=20)
    ap.add_argument("--cases", type=int, default=40, help="scale of each class")
    ap.add_argument("--only", default="", help="comma-separated: pages,scenes,images,kills,"
                                               "disk,truncation")
    a = ap.parse_args()
    vtbake = os.path.abspath(a.vtbake)
    shutil.rmtree(a.work, ignore_errors=True)
    os.makedirs(a.work)
    rng = random.Random(a.seed)
    classes = []
    steps = [("pages", page_file_classes, a.cases // 2), ("scenes", scene_class, a.cases),
             ("images", image_class, a.cases), ("kills", kill_class, a.cases // 2),
             ("disk", disk_full_class, a.cases // 2), ("truncation", truncation_class, a.cases)]
    t0 = time.time()
    for name, fn, n in steps:
        if a.only and name not in a.only.split(","):
            continue
        s = time.time()
        fn(vtbake, a.work, rng, n, classes)
        print("%s: %.0f s" % (name, time.time() - s), file=sys.stderr)
    head = ["class", "cases", "crashes", "hangs", "silent wrong", "clear errors",
            "unclear errors", "accepted"]
    print("| " + " | ".join(head) + " |")
    print("|" + " --- |" * len(head))
    for c in classes:
        print("| " + " | ".join(str(v) for v in c.row()) + " |")
    print("\nseed %d, --cases %d, %.0f s" % (a.seed, a.cases, time.time() - t0))
    for c in classes:
        for note in c.notes[:12]:
            print("- %s: %s" % (c.name, note))
        if len(c.notes) > 12:
            print("- %s: %d more notes" % (c.name, len(c.notes) - 12))


if __name__ == "__main__":
    main()
