#!/usr/bin/env python3
"""softarm's methods on the cantilever3d transient against the committed
Cosserat references (tests/data/, from scripts/pyelastica_reference.py):
the rod released straight under gravity, undamped, 2 s. Prints the table
of docs/validation.md: per method and resolution, coordinates, the tip's
largest distance over 0.5 s and 2 s (% of L) from the extensible rod of
constant section, from PyElastica's own law, and from the inextensible
rod, and wall time.

    cargo build --release && python3 scripts/cantilever3d_dynamics.py [METHOD ...]
"""

import csv
import json
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
BIN = ROOT / "target" / "release" / "softarm"
L = 0.3
REFERENCES = [
    ("rod", "cantilever3d_cosserat_tip.csv"),
    ("PyElastica's law", "cantilever3d_cosserat_pyelastica_law_tip.csv"),
    ("inextensible", "cantilever3d_inextensible_tip.csv"),
]
# PyElastica's shear factor (27/28), for the methods that shear.
K = ["--set", "segment.0.shear_factor=0.9642857142857143"]
SIX = ["--set", "segment.0.extension=true", "--set", "segment.0.shear=true", *K]
ROM = ["--set", "segment.0.method=rom"]
# (method, model, settings, rtol): cantilever3d with gravity along -z, or
# rod_swing (10 compiled pcs elements) and rod_swing_rom (rom of order 5
# with all six strains, compiled) at their own tolerances.
CASES = [
    ("pcc", "cantilever3d", ["--set", "segment.0.elements=5"], 1e-8),
    ("pcc", "cantilever3d", ["--set", "segment.0.elements=10"], 1e-8),
    ("pcc", "cantilever3d", ["--set", "segment.0.elements=20"], 1e-8),
    ("ebr", "cantilever3d", ["--set", "segment.0.method=ebr", "--set", "segment.0.elements=10"], 1e-8),
    ("rom", "cantilever3d", [*ROM, "--set", "segment.0.order=4", "--set", "segment.0.quadrature=8"], 1e-8),
    ("rom", "cantilever3d", [*ROM, "--set", "segment.0.order=6", "--set", "segment.0.quadrature=8"], 1e-8),
    ("pcs", "cantilever3d", ["--set", "segment.0.method=pcs", "--set", "segment.0.elements=5", *K], 1e-8),
    ("pcs", "rod_swing", [], 1e-6),
    ("pcs", "rod_swing", ["--set", "segment.0.elements=20"], 1e-6),
    ("rom", "rod_swing_rom", ["--set", "segment.0.order=3"], 1e-5),
    ("rom", "rod_swing_rom", ["--set", "segment.0.order=4"], 1e-5),
    ("rom", "rod_swing_rom", [], 1e-5),
    ("rom", "rod_swing_rom", ["--set", "segment.0.order=6"], 1e-5),
    ("rom", "rod_swing_rom", ["--set", "segment.0.order=5", "--set", "segment.0.quadrature=4"], 1e-5),
]
if len(sys.argv) > 1:
    # Only the cases of these methods (e.g. `pcs rom`).
    CASES = [c for c in CASES if c[0] in sys.argv[1:]]


def reference(name):
    rows = [r for r in csv.reader(open(ROOT / "tests" / "data" / name))
            if r and not r[0].startswith("#")]
    return {round(float(r[0]), 6): [float(x) for x in r[1:]] for r in rows}


def error(rows, ref, t_max):
    worst = 0.0
    for r in rows:
        t = round(float(r["t"]), 6)
        if t > t_max + 1e-9 or t not in ref:
            continue
        p = [float(r["tip_x"]), float(r["tip_y"]), float(r["tip_z"])]
        d = sum((a - b) ** 2 for a, b in zip(p, ref[t])) ** 0.5
        worst = max(worst, d)
    return 100 * worst / L


def main():
    refs = [(label, reference(name)) for label, name in REFERENCES]
    heads = " | ".join(f"{label}: 0.5 s / 2 s" for label, _ in refs)
    print(f"| method | model and settings | coordinates | {heads} | rtol | steps | wall |")
    print("|---|---|---|" + "---|" * len(refs) + "---|---|---|")
    for method, model, sets, rtol in CASES:
        with tempfile.TemporaryDirectory() as d:
            out = Path(d)
            cmd = [str(BIN), "simulate", model, "--set", "gravity=[0,0,-9.81]", *sets,
                   "--t-end", "2", "--output-dt", "0.01", "--rtol", str(rtol),
                   "--atol", str(rtol * 1e-3), "--shape-points", "0", "--quiet", "--out", str(out)]
            done = subprocess.run(cmd, capture_output=True, text=True)
            if done.returncode != 0:
                sys.exit(done.stderr)
            s = json.load(open(out / "summary.json"))
            rows = list(csv.DictReader(open(out / "trajectory.csv")))
            n = len(s["final_state"]["q"])
            settings = " ".join([model, *sets[1::2]])
            errors = " | ".join(f"{error(rows, ref, 0.5):.3f} / {error(rows, ref, 2.0):.3f}"
                                for _, ref in refs)
            how = {"unused": "compiled", "linked": "linked cells"}.get(s.get("cache"), "interpreted")
            print(f"| {method} | {settings} | {n} | {errors} | {rtol:g} | {s['steps']} | "
                  f"{s['wall_s']:.2f} s ({how}) |", flush=True)


if __name__ == "__main__":
    main()
