#!/usr/bin/env python3
"""Tip error of every lumped 3D method against the Cosserat rod, by DOF.

Runs `softarm static` on models/cantilever3d.toml (release build) and prints
the markdown tables of docs/validation.md. Usage:
    python3 scripts/convergence3d.py [large|weight]
"""
import json, math, subprocess, sys

E, R, L = 1e6, 0.01, 0.3
EI = E * math.pi * R**4 / 4

def static(sets):
    args = ["cargo", "run", "-q", "--release", "--", "static", "cantilever3d", "--json"]
    for s in sets:
        args += ["--set", s]
    out = subprocess.run(args, capture_output=True, text=True, check=True).stdout
    return json.loads(out)

def table(load_sets, counts, label):
    ref = static(load_sets + ["segment.0.method=cosserat"])["tip_position"]
    defl = math.hypot(ref[1], ref[2])
    print(f"{label}: Cosserat tip {ref}, lateral deflection {defl:.6g} m\n")
    print("| method | elements (rom: order) | DOF | tip error (m) | error / deflection |")
    print("|---|---|---|---|---|")
    for method in ["pcc", "ebr", "rigid", "rom"]:
        key = "order" if method == "rom" else "elements"
        for n in ([0, 1, 2, 3, 4, 5] if method == "rom" else counts):
            sets = load_sets + [f"segment.0.method={method}", f"segment.0.{key}={n}", "segment.0.twist=false"]
            d = static(sets)
            tip, dof = d["tip_position"], len(d["q"])
            err = math.dist(tip, ref)
            print(f"| {method} | {n} | {dof} | {err:.3e} | {100 * err / defl:.3f} % |")
    print()
    # eba is extensible and shearable: against the extensible rod.
    ref = static(load_sets + ["segment.0.method=cosserat", "segment.0.extension=true"])["tip_position"]
    print(f"eba against the extensible, shearable Cosserat rod (tip {ref}):\n")
    print("| method | elements | DOF | tip error (m) | error / deflection |")
    print("|---|---|---|---|---|")
    for n in counts:
        d = static(load_sets + ["segment.0.method=eba", f"segment.0.elements={n}"])
        err = math.dist(d["tip_position"], ref)
        print(f"| eba | {n} | {len(d['q'])} | {err:.3e} | {100 * err / defl:.3f} % |")
    print()

if __name__ == "__main__":
    what = sys.argv[1] if len(sys.argv) > 1 else "large"
    if what == "large":
        p = 10 * EI / L**2
        table([f"tip.force=[0, {-0.6 * p}, {0.8 * p}]"], [1, 2, 4, 8, 16], f"P L^2/EI = 10 along (0, -0.6, 0.8), P = {p:.4f} N")
    else:
        table(["gravity=[0, -9.81, 0]"], [1, 2, 3, 4, 5, 6, 8], "self-weight, g = 9.81 along -y")
