#!/usr/bin/env python3
"""Log-log plot (SVG, no dependencies) of tip error / deflection against DOF
per method, from the markdown tables that convergence3d.py prints.

    python3 scripts/convergence3d.py large > large.md
    python3 scripts/convergence3d.py weight > weight.md
    python3 scripts/plot_convergence.py large.md weight.md docs/convergence3d.svg
"""
import math, re, sys

COLOURS = {"pcc": "#1f77b4", "ebr": "#ff7f0e", "rigid": "#2ca02c", "rom": "#d62728", "eba": "#9467bd"}

def read(path):
    series = {}
    for line in open(path):
        m = re.match(r"\| (\w+) \| (\d+) \| (\d+) \| ([0-9.e+-]+) \| ([0-9.]+) % \|", line)
        if m:
            method, dof, pct = m.group(1), int(m.group(3)), float(m.group(5))
            series.setdefault(method, []).append((dof, pct))
    return series

def panel(series, x0, title):
    w, h, pad = 380, 300, 50
    xs = lambda d: x0 + pad + (math.log10(d) - math.log10(2)) / (math.log10(128) - math.log10(2)) * (w - pad - 10)
    ys = lambda p: 20 + (2 - math.log10(p)) / 4 * (h - 60)  # 100 % .. 0.01 %
    out = [f'<text x="{x0 + w / 2}" y="14" text-anchor="middle" font-size="13">{title}</text>']
    out.append(f'<rect x="{x0 + pad}" y="20" width="{w - pad - 10}" height="{h - 60}" fill="none" stroke="#888"/>')
    for p in [100, 10, 1, 0.1, 0.01]:
        y = ys(p)
        out.append(f'<line x1="{x0 + pad}" x2="{x0 + w - 10}" y1="{y}" y2="{y}" stroke="#eee"/>')
        out.append(f'<text x="{x0 + pad - 4}" y="{y + 4}" text-anchor="end" font-size="10">{p:g} %</text>')
    for d in [2, 4, 8, 16, 32, 64, 128]:
        x = xs(d)
        out.append(f'<text x="{x}" y="{h - 26}" text-anchor="middle" font-size="10">{d}</text>')
    out.append(f'<text x="{x0 + w / 2}" y="{h - 10}" text-anchor="middle" font-size="11">DOF</text>')
    y1 = ys(1)
    out.append(f'<line x1="{x0 + pad}" x2="{x0 + w - 10}" y1="{y1}" y2="{y1}" stroke="#999" stroke-dasharray="4 3"/>')
    for i, (method, pts) in enumerate(sorted(series.items())):
        pts = [(d, p) for d, p in pts if p > 0 and 2 <= d <= 128]
        c = COLOURS.get(method, "#000")
        path = " ".join(f"{xs(d):.1f},{ys(p):.1f}" for d, p in pts)
        out.append(f'<polyline points="{path}" fill="none" stroke="{c}" stroke-width="1.8"/>')
        for d, p in pts:
            out.append(f'<circle cx="{xs(d):.1f}" cy="{ys(p):.1f}" r="2.5" fill="{c}"/>')
        out.append(f'<text x="{x0 + w - 60}" y="{40 + 14 * i}" font-size="11" fill="{c}">{method}</text>')
    return out

if __name__ == "__main__":
    large, weight, target = sys.argv[1:4]
    body = panel(read(large), 0, "tip load P L^2/EI = 10 (error / deflection)")
    body += panel(read(weight), 400, "self-weight (error / deflection)")
    svg = ['<svg xmlns="http://www.w3.org/2000/svg" width="790" height="300" font-family="sans-serif">',
           '<rect width="790" height="300" fill="white"/>'] + body + ["</svg>"]
    open(target, "w").write("\n".join(svg) + "\n")
