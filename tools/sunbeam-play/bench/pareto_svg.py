#!/usr/bin/env python3
"""Pareto plot of the response map: CIEDE2000 p99 against map size (MiB), one
point per budget (budget.sh CSV), with the former table's error as a line;
each point is labelled with its grid and its frame time at 512 x 512 as a
multiple of the Lambert mode's in the same run (budget.sh's frame_ms / lambert_ms).
Plain SVG, no dependencies:

    python3 tools/sunbeam-play/bench/pareto_svg.py BUDGET.csv TABLE_P99 TITLE > out.svg
"""
import csv, math, sys

rows = list(csv.DictReader(open(sys.argv[1])))
table = float(sys.argv[2])
title = sys.argv[3] if len(sys.argv) > 3 else ""
W, H, L, R, T, B = 560, 360, 70, 20, 40, 50
xs = [int(r["map_bytes"]) / 2**20 for r in rows]
ys = [float(r["p99"]) for r in rows]
x0, x1 = math.log2(min(xs) / 1.5), math.log2(max(xs) * 1.5)
y1 = max(ys + [table]) * 1.15
px = lambda x: L + (math.log2(x) - x0) / (x1 - x0) * (W - L - R)
py = lambda y: H - B - y / y1 * (H - T - B)
o = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="{H}" font-family="sans-serif" font-size="12">',
     f'<rect width="{W}" height="{H}" fill="white"/>',
     f'<text x="{W/2}" y="20" text-anchor="middle" font-size="14">{title}</text>',
     f'<line x1="{L}" y1="{H-B}" x2="{W-R}" y2="{H-B}" stroke="black"/>',
     f'<line x1="{L}" y1="{T}" x2="{L}" y2="{H-B}" stroke="black"/>',
     f'<text x="{(L+W-R)/2}" y="{H-12}" text-anchor="middle">response map size (MiB, log scale)</text>',
     f'<text x="16" y="{(T+H-B)/2}" transform="rotate(-90 16 {(T+H-B)/2})" text-anchor="middle">CIEDE2000 p99 over lit pixels</text>']
for k in range(int(math.floor(x0)), int(math.ceil(x1)) + 1):
    v = 2.0**k
    if x0 <= k <= x1:
        o.append(f'<text x="{px(v):.1f}" y="{H-B+16}" text-anchor="middle">{v:g}</text>')
for i in range(0, 6):
    v = y1 * i / 5
    o.append(f'<text x="{L-6}" y="{py(v)+4:.1f}" text-anchor="end">{v:.1f}</text>')
    o.append(f'<line x1="{L}" y1="{py(v):.1f}" x2="{W-R}" y2="{py(v):.1f}" stroke="#ddd"/>')
o.append(f'<line x1="{L}" y1="{py(table):.1f}" x2="{W-R}" y2="{py(table):.1f}" stroke="#c33" stroke-dasharray="6 4"/>')
o.append(f'<text x="{W-R-4}" y="{py(table)-6:.1f}" text-anchor="end" fill="#c33">former table (32 MiB f32, built at start-up)</text>')
o.append(f'<line x1="{L}" y1="{py(1):.1f}" x2="{W-R}" y2="{py(1):.1f}" stroke="#393" stroke-dasharray="2 3"/>')
pts = sorted(zip(xs, ys, rows))
o.append('<polyline fill="none" stroke="#236" points="' + " ".join(f"{px(x):.1f},{py(y):.1f}" for x, y, _ in pts) + '"/>')
for idx, (x, y, r) in enumerate(pts):
    o.append(f'<circle cx="{px(x):.1f}" cy="{py(y):.1f}" r="4" fill="#236"/>')
    label = r["grid"]
    if r.get("frame_ms") and r.get("lambert_ms"):
        label += f', {float(r["frame_ms"]) / float(r["lambert_ms"]):.2f}x Lambert'
    right = px(x) > 0.6 * W  # label to the left of points near the right edge
    dy = 18 if right and idx % 2 == 1 else -8  # alternate below/above where labels crowd
    o.append(f'<text x="{px(x) + (-6 if right else 6):.1f}" y="{py(y) + dy:.1f}"'
             f' text-anchor="{"end" if right else "start"}">{label}</text>')
o.append("</svg>")
print("\n".join(o))
