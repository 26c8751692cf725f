#!/usr/bin/env python3
"""Convergence tables of the cantilever (docs/validation.md).

Runs `softarm static` and `softarm modes` on models/cantilever.toml for
several element counts and methods, and prints Markdown tables. The
elastica reference is solved here independently (shooting on
theta'' = alpha cos theta with RK4), as in tests/pcc.rs.

Usage: python3 scripts/cantilever_convergence.py [path/to/softarm]
"""
import json
import math
import subprocess
import sys

EXE = sys.argv[1] if len(sys.argv) > 1 else "target/release/softarm"
E, R, L, RHO = 1e6, 0.01, 0.3, 1000.0
EI = E * math.pi * R**4 / 4
AREA = math.pi * R * R


def run(*args):
    out = subprocess.run([EXE, *args], capture_output=True, text=True, check=True)
    return json.loads(out.stdout)


def static_tip(method, n, p):
    d = run("static", "cantilever", "--set", f"segment.0.method={method}",
            "--set", f"segment.0.elements={n}", "--set", f"tip.force=[0,{-p},0]", "--json")
    return d["tip_position"][0] / L, -d["tip_position"][1] / L


def elastica(alpha, steps=4000):
    def rhs(s):
        return [s[1], alpha * math.cos(s[0]), math.cos(s[0]), math.sin(s[0])]

    def shoot(c):
        h, y = 1.0 / steps, [0.0, c, 0.0, 0.0]
        for _ in range(steps):
            k1 = rhs(y)
            k2 = rhs([a + h / 2 * b for a, b in zip(y, k1)])
            k3 = rhs([a + h / 2 * b for a, b in zip(y, k2)])
            k4 = rhs([a + h * b for a, b in zip(y, k3)])
            y = [a + h / 6 * (b + 2 * c2 + 2 * d + e) for a, b, c2, d, e in zip(y, k1, k2, k3, k4)]
        return y

    lo, hi = -alpha, 0.0
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if shoot(mid)[1] > 0:
            hi = mid
        else:
            lo = mid
    y = shoot(0.5 * (lo + hi))
    return y[2], -y[3]


counts = [2, 5, 10, 20]
print("### Small tip load (F L^3 / (3 E I) = 1 % of L)\n")
f = 0.01 * L * 3 * EI / L**3
print("| elements | pcc error | rigid (Hencky) error |\n|---|---|---|")
for n in counts:
    row = []
    for method in ["pcc", "rigid"]:
        _, d = static_tip(method, n, f)
        row.append(f"{100 * (d - 0.01) / 0.01:+.3f} %")
    print(f"| {n} | {row[0]} | {row[1]} |")

print("\n### Large tip load: tip (x, y) / L against the elastica\n")
print("| alpha = P L^2/(E I) | elastica x/L, -y/L | elements | pcc error / L | rigid error / L |\n|---|---|---|---|---|")
for alpha in [1, 5, 10]:
    ref = elastica(alpha)
    for n in [5, 10, 20, 40]:
        errs = []
        for method in ["pcc", "rigid"]:
            x, y = static_tip(method, n, alpha * EI / L**2)
            errs.append(math.hypot(x - ref[0], y - ref[1]))
        print(f"| {alpha} | {ref[0]:.5f}, {ref[1]:.5f} | {n} | {errs[0]:.2e} | {errs[1]:.2e} |")

print("\n### Bending frequencies against Euler-Bernoulli\n")
scale = math.sqrt(EI / (RHO * AREA * L**4))
exact = [b * b / (2 * math.pi) * scale for b in (1.875104, 4.694091)]
print(f"Euler-Bernoulli: f1 = {exact[0]:.5f} Hz, f2 = {exact[1]:.5f} Hz\n")
print("| elements | pcc f1 error | pcc f2 error | rigid f1 error | rigid f2 error |\n|---|---|---|---|---|")
for n in [5, 10, 20, 40]:
    row = []
    for method in ["pcc", "rigid"]:
        fr = run("modes", "cantilever", "--set", f"segment.0.method={method}",
                 "--set", f"segment.0.elements={n}", "--json")["frequencies_hz"]
        row += [f"{100 * (fr[k] - exact[k]) / exact[k]:+.3f} %" for k in range(2)]
    print(f"| {n} | " + " | ".join(row) + " |")
