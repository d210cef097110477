#!/usr/bin/env python3
"""The conformance run's driver (scripts/conformance.sh sets it up): picks the models, bakes
and validates each with `vtbake --json`, and writes the Markdown table.

A model is in the run when it can show whether materials bake right: a glTF 2.0 file with a
material, or an OBJ/FBX/COLLADA/PLY/3DS/AC3D file that names a texture. Each gets one of:
  pass     baked, and validate passed every view within the default bounds
  refused  vtbake said no with exit status 2 and a message (an unsupported feature, a bad file)
  FAIL     anything else: a crash, a timeout, exit 1, or a bake that does not validate
"""
import argparse
import json
import os
import re
import struct
import subprocess
import sys
import time

SCENE_EXTS = {".gltf": "glTF", ".glb": "glTF", ".obj": "OBJ", ".fbx": "FBX", ".dae": "COLLADA",
              ".ply": "PLY", ".3ds": "3DS", ".ac": "AC3D", ".acc": "AC3D", ".ac3d": "AC3D"}
IMAGE_EXT_RE = re.compile(rb"\.(png|jpe?g|tga|bmp|dds|tiff?|exr|gif)\b", re.I)
NAME_BYTES = set(b"abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-. \\/:")


def image_names(data):
    """File names with an image extension inside a binary or text scene file."""
    names = set()
    for m in IMAGE_EXT_RE.finditer(data):
        start = m.start()
        while start > 0 and m.start() - start < 200 and data[start - 1] in NAME_BYTES:
            start -= 1
        if start < m.start():
            names.add(data[start:m.end()].strip().lower())
    return names


def gltf_document(path):
    with open(path, "rb") as f:
        data = f.read()
    if data[:4] == b"glTF":
        if len(data) < 20:
            return None
        length, kind = struct.unpack_from("<II", data, 12)
        if kind != 0x4E4F534A:
            return None
        data = data[20:20 + length]
    try:
        doc = json.loads(data.decode("utf-8-sig"))
    except (ValueError, UnicodeDecodeError):
        return None
    return doc if isinstance(doc, dict) else None


def entries(value):
    """The entries of a glTF array (2.0) or object map (1.0); dicts only."""
    seq = value.values() if isinstance(value, dict) else value if isinstance(value, list) else []
    return [e for e in seq if isinstance(e, dict)]


def gltf_features(doc):
    """What the file asks of the material model, in words the table can show."""
    feats = set()
    if str(doc.get("asset", {}).get("version", "2")).startswith("1"):
        feats.add("glTF 1.0")
    for e in doc.get("extensionsUsed", []) or []:
        feats.add(e)
    for s in entries(doc.get("samplers")):
        for k in ("wrapS", "wrapT"):
            if s.get(k) == 33648:
                feats.add("MIRRORED_REPEAT")
            elif s.get(k) == 33071:
                feats.add("CLAMP_TO_EDGE")
    for m in entries(doc.get("meshes")):
        for p in entries(m.get("primitives")):
            attrs = p.get("attributes", {}) if isinstance(p.get("attributes"), dict) else {}
            if "COLOR_0" in attrs:
                feats.add("COLOR_0")
            if "TEXCOORD_1" in attrs:
                feats.add("TEXCOORD_1")
            if "TANGENT" not in attrs and "NORMAL" in attrs:
                feats.add("no tangents")
            if "targets" in p:
                feats.add("morph targets")
            if p.get("mode", 4) not in (4,):
                feats.add("mode %d" % p.get("mode", 4))
    if doc.get("skins"):
        feats.add("skins")
    for m in entries(doc.get("materials")):
        if m.get("alphaMode") in ("MASK", "BLEND"):
            feats.add("alpha " + m["alphaMode"])
        if m.get("doubleSided"):
            feats.add("double-sided")
        if "normalTexture" in m:
            feats.add("normal map")
        if "emissiveTexture" in m or any(m.get("emissiveFactor", [0, 0, 0])):
            feats.add("emissive")
    if any("sparse" in a for a in entries(doc.get("accessors"))):
        feats.add("sparse accessors")
    for im in entries(doc.get("images")):
        if "bufferView" in im or str(im.get("uri", "")).startswith("data:"):
            feats.add("embedded images")
    return sorted(feats)


def select(corpus, only):
    """(path, format, features) for every model the run covers."""
    picked = []
    for folder, _, files in os.walk(corpus):
        for name in sorted(files):
            path = os.path.join(folder, name)
            rel = os.path.relpath(path, corpus)
            ext = os.path.splitext(name)[1].lower()
            if ext not in SCENE_EXTS or (only and not re.search(only, rel)):
                continue
            fmt = SCENE_EXTS[ext]
            if fmt == "glTF":
                doc = gltf_document(path)
                if doc is None:
                    picked.append((path, fmt, ["not readable as glTF JSON"]))
                    continue
                mats = doc.get("materials")
                if mats:  # a list (2.0) or an object (1.0) with entries
                    feats = gltf_features(doc)
                    if entries(doc.get("textures")):
                        feats = sorted(feats + ["textured"])
                    picked.append((path, fmt, feats))
                continue
            with open(path, "rb") as f:
                data = f.read()
            if fmt == "OBJ":
                names = []
                for m in re.findall(rb"^\s*mtllib\s+(.+?)\s*$", data, re.M):
                    mtl = os.path.join(folder, m.decode("latin-1").replace("\\", "/"))
                    if os.path.exists(mtl):
                        with open(mtl, "rb") as f:
                            names += re.findall(rb"^\s*(?:map_\w+|bump|norm)\s+(.+)$",
                                                f.read(), re.M | re.I)
                if names:
                    picked.append((path, fmt, ["MTL maps: %d" % len(names)]))
                continue
            if data[:2] in (b"\xff\xfe", b"\xfe\xff"):  # UTF-16 with its byte-order mark
                data = data.decode("utf-16", "replace").encode("utf-8")
            hits = image_names(data)
            if hits:
                picked.append((path, fmt, ["textures named: %d" % len(hits)]))
    return sorted(picked)


def run(cmd, timeout):
    start = time.monotonic()
    try:
        p = subprocess.run(cmd, capture_output=True, timeout=timeout)
        return p.returncode, p.stdout.decode("utf-8", "replace"), p.stderr.decode(
            "utf-8", "replace"), time.monotonic() - start
    except subprocess.TimeoutExpired:
        return None, "", "timed out after %d s" % timeout, time.monotonic() - start


def last_error(stderr):
    lines = [l for l in stderr.strip().splitlines() if l.strip()]
    errs = [l for l in lines if not l.startswith("warning")]
    return (errs or lines or [""])[-1][:300]


def warnings_of(stderr):
    return [l[len("warning: "):] for l in stderr.splitlines() if l.startswith("warning: ")]


def one_model(args, path, index):
    base = os.path.join(args.work, "m%03d" % index)
    rec = {"bake": None, "bake_s": 0.0, "layers": [], "views": [], "warnings": []}
    rc, out, err, secs = run([args.vtbake, "--json", "bake", path, "-o", base + ".vtpf"],
                             args.timeout)
    rec["bake_s"] = secs
    rec["warnings"] = warnings_of(err)
    if rc != 0:
        if rc == 2:
            rec["why"] = last_error(err)
            # An unsupported feature is vtbake's gap; anything else is a defect of the input.
            rec["result"] = "refused"
            rec["refusal"] = "unsupported" if "not supported" in rec["why"] else "invalid file"
        else:
            rec["result"] = "FAIL"
            rec["why"] = ("exit %s: " % rc if rc is not None else "") + last_error(err)
        return rec
    try:
        summary = json.loads(out)
        rec["layers"] = [l["name"] for l in summary["build"]["layers"]]
        rec["atlas"] = "%dx%d" % (summary["build"]["width"], summary["build"]["height"])
    except (ValueError, KeyError):
        pass
    rc, out, err, secs = run([args.vtbake, "--json", "validate", path, base + ".vtpf"],
                             args.timeout)
    rec["validate_s"] = secs
    try:
        report = json.loads(out)
    except ValueError:
        report = None
    failures = layer_results(rec, report) if isinstance(report, dict) else []
    if rc == 0:
        rec["result"] = "pass"
    else:
        rec["result"] = "FAIL"
        why = "; ".join(failures[:3]) or last_error(err) or "(validate printed no reason)"
        rec["why"] = "validate exit %s: %s" % (rc, why)
    return rec


def psnr_range(values):
    values = [v for v in values if v is not None]
    if not values:
        return ""
    lo, hi = min(values), max(values)
    return "%.1f" % lo if abs(hi - lo) < 0.05 else "%.1f-%.1f" % (lo, hi)


def layer_results(rec, report):
    """Fills rec's per-layer cells from validate's report.json; returns every failure line."""
    views = [v for v in report.get("views", []) if isinstance(v, dict)]
    failures = ["view %s: %s" % (v.get("view"), f) for v in views for f in v.get("failures", [])]
    rec["views"] = ["%.1f" % v["psnr_rgb"] for v in views if "psnr_rgb" in v]
    rec["albedo"] = "%s (tile >= %s)" % (
        psnr_range([v.get("psnr_rgb") for v in views]),
        psnr_range([min(v.get("worst_tile_psnr", 100) for v in views)])) if views else ""
    lit = report.get("lit", {}) or {}
    lit_views = [v["lit"] for v in views if isinstance(v.get("lit"), dict)]
    lit_layers = [l for l in lit.get("layers", []) if l != "albedo"]
    if lit_views:
        rec["lit"] = "%s: %s (tile >= %s)" % (
            " ".join(lit_layers) or "albedo only", psnr_range([v.get("psnr_rgb") for v in lit_views]),
            psnr_range([min(v.get("worst_tile_psnr", 100) for v in lit_views)]))
    else:
        rec["lit"] = "not run" + (": " + "; ".join(lit.get("skipped", [])) if lit.get("skipped") else "")
    exact = report.get("exact", {}) or {}
    if exact.get("ran"):
        ev = [v for v in exact.get("views", []) if v.get("pixels_compared")]
        ok = all(v.get("passed", False) for v in exact.get("views", []))
        rec["exact"] = "%s %s (%d of %d views compared)" % (
            "pass" if ok else "FAIL", psnr_range([v.get("psnr") for v in ev]), len(ev),
            len(exact.get("views", [])))
    else:
        rec["exact"] = exact.get("note", "") or "not run"
    atlas = report.get("atlas", {}) or {}
    if atlas.get("ran"):
        rec["atlas_check"] = " ".join(
            "%s %s %.1f" % (l.get("name"), "pass" if l.get("passed") else "FAIL",
                            l.get("min_psnr", 0)) for l in atlas.get("layers", []))
        failures += ["atlas check: " + f for f in atlas.get("failures", [])]
    else:
        rec["atlas_check"] = atlas.get("note", "") or "not run"
    return failures


def valid_gltf2(row):
    """A glTF 2.0 model that is not refused for a defect of the file."""
    _, fmt, feats, rec = row
    return (fmt == "glTF" and "glTF 1.0" not in feats and "not readable as glTF JSON" not in feats
            and rec.get("refusal") != "invalid file")


def totals_line(rows):
    counts = {}
    for _, _, _, rec in rows:
        key = rec["result"] + (" (%s)" % rec["refusal"] if "refusal" in rec else "")
        counts[key] = counts.get(key, 0) + 1
    fails = counts.get("FAIL", 0)
    gl = [r for r in rows if valid_gltf2(r)]
    gl_tex = [r for r in gl if "textured" in r[2]]
    passed = lambda rs: sum(1 for r in rs if r[3]["result"] == "pass")
    line = "Totals: %d models; %s; %d FAIL. Valid glTF 2.0 models passing: %d of %d (%.0f%%); " \
        "textured ones: %d of %d (%.0f%%)." % (
            len(rows), ", ".join("%d %s" % (n, k) for k, n in sorted(counts.items()) if k != "FAIL"),
            fails, passed(gl), len(gl), 100.0 * passed(gl) / max(1, len(gl)), passed(gl_tex),
            len(gl_tex), 100.0 * passed(gl_tex) / max(1, len(gl_tex)))
    return line, counts


def write_table(args, rows):
    totals, counts = totals_line(rows)
    lines = [
        "# Conformance: Debian's assimp-testmodels",
        "",
        "Written by `scripts/conformance.sh` (do not edit by hand): every model of the",
        "`assimp-testmodels` package that has a material (glTF) or names a texture (OBJ, FBX,",
        "COLLADA, PLY, 3DS, AC3D), baked with default flags and validated with default bounds.",
        "**pass**: baked and validate passed every check on every layer; **refused**: exit 2 with",
        "the message shown, either for a feature vtbake does not support (*unsupported*) or for a",
        "defect of the file (*invalid file*: it breaks the glTF schema or spec, or names a file the",
        "package lacks); **FAIL**: a crash, a timeout, exit 1, or a bake that does not validate.",
        "Validation columns, from validate's report.json: *albedo* is the PSNR range over the views",
        "(dB) and the worst 16x16 tile; *lit* the lit pass (the layers it shades with, PSNR range,",
        "worst tile); *exact* the streaming check against the baked levels; *atlas* the per-layer",
        "atlas check (worst page PSNR). Valid glTF 2.0 models are the glTF 2.0 files not refused as",
        "invalid. Times are wall-clock seconds on the machine that ran it (load average at the",
        "start: %s)." % args.load,
        "",
        "Rules behind some rows: a material that reads a UV set its primitive lacks is refused",
        "(glTF 2.0 requires the set to exist; baking the factor alone would hide a texture the",
        "author meant, so `issue_3269/texcoord_crash.gltf` is an invalid file). A COLLADA material",
        "with opacity 0 is read as opaque with a warning (3ds Max writes `<transparency>`",
        "inverted). The draft `KHR_technique_webgl` (not `KHR_techniques_webgl`) carries only",
        "shader-technique values, no metallic-roughness block: its common-profile values are baked",
        "as metallic-roughness (diffuse as base colour, emission, transparency as alpha, metallic 0,",
        "roughness from shininess) with a warning.",
        "",
        totals,
        "",
        "| model | format | features | result | bake s | layers | albedo | lit | exact | atlas "
        "| note |",
        "| --- | --- | --- | --- | ---: | --- | --- | --- | --- | --- | --- |",
    ]
    for path, fmt, feats, rec in rows:
        note = rec.get("why", "")
        if not note and rec["warnings"]:
            note = "warning: " + "; ".join(rec["warnings"][:2])
        note = note.replace("|", "\\|").replace(args.corpus + "/", "")
        result = rec["result"] + (" (%s)" % rec["refusal"] if "refusal" in rec else "")
        cells = [os.path.relpath(path, args.corpus), fmt, ", ".join(feats).replace("|", "/"),
                 result, "%.1f" % rec["bake_s"], " ".join(rec["layers"]), rec.get("albedo", ""),
                 rec.get("lit", ""), rec.get("exact", ""), rec.get("atlas_check", ""), note]
        lines.append("| " + " | ".join(c.replace("|", "/") if i < 10 else c
                                       for i, c in enumerate(cells)) + " |")
    with open(args.out, "w") as f:
        f.write("\n".join(lines) + "\n")
    return totals, counts


def main():
    ap = argparse.ArgumentParser()
    for k in ("vtbake", "corpus", "work", "out", "only"):
        ap.add_argument("--" + k, default="")
    ap.add_argument("--timeout", type=int, default=600)
    args = ap.parse_args()
    args.corpus = os.path.abspath(args.corpus)
    args.load = open("/proc/loadavg").read().split()[0] if os.path.exists("/proc/loadavg") else "?"
    models = select(args.corpus, args.only)
    rows = []
    for i, (path, fmt, feats) in enumerate(models):
        rec = one_model(args, path, i)
        rows.append((path, fmt, feats, rec))
        write_table(args, rows)  # a stopped run still leaves the rows it has
        print("[%d/%d] %-8s %6.1f s  %s  %s" % (i + 1, len(models), rec["result"], rec["bake_s"],
                                                os.path.relpath(path, args.corpus),
                                                rec.get("why", "")), flush=True)
    totals, counts = write_table(args, rows)
    print("conformance: %s Table in %s" % (totals, args.out))
    return 1 if counts.get("FAIL") else 0


if __name__ == "__main__":
    sys.exit(main())
