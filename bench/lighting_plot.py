#!/usr/bin/env python3
"""Samples-versus-error plot of baked lighting (docs/BENCHMARKS.md, issue 21).

usage: lighting_plot.py BENCH.json OUT.svg

BENCH.json: `lighting_bench --benchmark_filter=BM_LitSceneSamples --benchmark_format=json`.
Draws two panels, log-log: relative RMSE against rays per texel, and relative RMSE against
CPU seconds per million covered texels (one thread), one line per (scene, AO or bounce). Plain SVG, no
plotting library.
"""
import json
import math
import sys

SCENES = {"0": "sample scene", "1": "VirtualCity"}
KINDS = {"0": "AO", "1": "bounce"}
COLOURS = ["#1f77b4", "#d62728", "#2ca02c", "#ff7f0e"]


def series(path):
    out = {}
    for b in json.load(open(path))["benchmarks"]:
        if not b["name"].startswith("BM_LitSceneSamples/") or b.get("error_occurred"):
            continue
        if b.get("run_type") == "aggregate" and b.get("aggregate_name") != "median":
            continue
        _, scene, kind, n = b["name"].split("/")[:4]
        key = "%s, %s" % (SCENES.get(scene, scene), KINDS.get(kind, kind))
        # CPU seconds (one thread): steadier than wall time on a shared machine.
        cpu_s = b["cpu_time"] * {"ms": 1e-3, "us": 1e-6, "ns": 1e-9, "s": 1.0}[b["time_unit"]]
        out.setdefault(key, []).append((int(n), b["rel_rmse"], cpu_s / (b["texels"] / 1e6)))
    return {k: sorted(v) for k, v in sorted(out.items())}


def panel(x0, title, xlabel, pts_by_series, xs_of, w=330, h=240):
    """One log-log panel at x offset x0: (svg text, ticks)."""
    allx = [xs_of(p) for pts in pts_by_series.values() for p in pts]
    ally = [p[1] for pts in pts_by_series.values() for p in pts]
    lx0, lx1 = math.floor(math.log10(min(allx))), math.ceil(math.log10(max(allx)))
    ly0, ly1 = math.floor(math.log10(min(ally))), math.ceil(math.log10(max(ally)))
    L, T = 50, 30

    def px(x):
        return x0 + L + (math.log10(x) - lx0) / max(lx1 - lx0, 1) * w

    def py(y):
        return T + h - (math.log10(y) - ly0) / max(ly1 - ly0, 1) * h

    s = ['<text x="%g" y="18" font-weight="bold">%s</text>' % (x0 + L, title)]
    s.append('<rect x="%g" y="%g" width="%g" height="%g" fill="none" stroke="#888"/>' %
             (x0 + L, T, w, h))
    for e in range(lx0, lx1 + 1):
        s.append('<line x1="%g" y1="%g" x2="%g" y2="%g" stroke="#ddd"/>' % (px(10**e), T, px(10**e), T + h))
        s.append('<text x="%g" y="%g" text-anchor="middle">%s</text>' % (px(10**e), T + h + 14, "%g" % 10**e))
    for e in range(ly0, ly1 + 1):
        s.append('<line x1="%g" y1="%g" x2="%g" y2="%g" stroke="#ddd"/>' % (x0 + L, py(10**e), x0 + L + w, py(10**e)))
        s.append('<text x="%g" y="%g" text-anchor="end">%s</text>' % (x0 + L - 4, py(10**e) + 4, "%g" % 10**e))
    s.append('<text x="%g" y="%g" text-anchor="middle">%s</text>' % (x0 + L + w / 2, T + h + 30, xlabel))
    for i, (name, pts) in enumerate(pts_by_series.items()):
        c = COLOURS[i % len(COLOURS)]
        d = " ".join("%s%.1f,%.1f" % ("M" if k == 0 else "L", px(xs_of(p)), py(p[1]))
                     for k, p in enumerate(pts))
        s.append('<path d="%s" fill="none" stroke="%s" stroke-width="1.5"/>' % (d, c))
        for p in pts:
            s.append('<circle cx="%.1f" cy="%.1f" r="2.5" fill="%s"/>' % (px(xs_of(p)), py(p[1]), c))
    return s


def main():
    data = series(sys.argv[1])
    W, H = 900, 330
    s = ['<svg xmlns="http://www.w3.org/2000/svg" width="%d" height="%d" font-family="sans-serif" '
         'font-size="11"><rect width="100%%" height="100%%" fill="white"/>' % (W, H)]
    s += panel(0, "AO: relative RMSE vs rays per texel", "rays per texel (reference: 4096)", data,
               lambda p: p[0])
    s += panel(420, "AO: relative RMSE vs bake time", "CPU s per million texels (1 thread)", data,
               lambda p: p[2])
    for i, name in enumerate(data):
        y = 300 + 0 * i
        x = 60 + i * 200
        s.append('<rect x="%d" y="%d" width="12" height="3" fill="%s"/>' % (x, y + 12, COLOURS[i % len(COLOURS)]))
        s.append('<text x="%d" y="%d">%s</text>' % (x + 16, y + 17, name))
    s.append("</svg>")
    with open(sys.argv[2], "w") as f:
        f.write("\n".join(s) + "\n")


if __name__ == "__main__":
    main()
