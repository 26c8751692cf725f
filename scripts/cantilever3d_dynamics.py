#!/usr/bin/env python3
"""softarm's methods on the cantilever3d transient against the committed
Cosserat reference (tests/data/cantilever3d_cosserat_tip.csv, from
scripts/pyelastica_reference.py): the rod released straight under gravity,
undamped, 2 s. Prints the table of docs/validation.md: per method and
resolution, coordinates, the tip's largest distance from the reference
over 0.5 s and 2 s (% of L), and wall time.

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
# PyElastica's shear factor (27/28), for the methods that shear.
K = ["--set", "segment.0.shear_factor=0.9642857142857143"]
SIX = ["--set", "segment.0.extension=true", "--set", "segment.0.shear=true", *K]
# (method, model, settings): cantilever3d with gravity along -z, or
# rod_swing (the same rod as 10 compiled pcs elements).
CASES = [
    ("pcc", "cantilever3d", ["--set", "segment.0.elements=5"]),
    ("pcc", "cantilever3d", ["--set", "segment.0.elements=10"]),
    ("ebr", "cantilever3d", ["--set", "segment.0.method=ebr", "--set", "segment.0.elements=10"]),
    ("rom", "cantilever3d", ["--set", "segment.0.method=rom", "--set", "segment.0.order=4"]),
    ("pcs", "cantilever3d", ["--set", "segment.0.method=pcs", "--set", "segment.0.elements=5", *K]),
    ("pcs", "rod_swing", []),
    ("rom", "cantilever3d", ["--set", "segment.0.method=rom", "--set", "segment.0.order=4", *SIX]),
]
if len(sys.argv) > 1:
    # Only the cases of these methods (e.g. `pcs rom`).
    CASES = [c for c in CASES if c[0] in sys.argv[1:]]


def reference():
    rows = [r for r in csv.reader(open(ROOT / "tests/data/cantilever3d_cosserat_tip.csv"))
            if r and not r[0].startswith("#")]
    return {round(float(r[0]), 6): [float(x) for x in r[1:]] for r in rows}


def error(run_dir, ref, t_max):
    rows = list(csv.DictReader(open(run_dir / "trajectory.csv")))
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
    ref = reference()
    print("| method | settings | coordinates | max tip error over 0.5 s (% of L) | over 2 s | wall |")
    print("|---|---|---|---|---|---|")
    for method, model, sets in CASES:
        with tempfile.TemporaryDirectory() as d:
            out = Path(d)
            cmd = [str(BIN), "simulate", model, "--set", "gravity=[0,0,-9.81]", *sets,
                   "--t-end", "2", "--output-dt", "0.01", "--rtol", "1e-8", "--atol", "1e-11",
                   "--shape-points", "0", "--quiet", "--out", str(out)]
            done = subprocess.run(cmd, capture_output=True, text=True)
            if done.returncode != 0:
                sys.exit(done.stderr)
            s = json.load(open(out / "summary.json"))
            n = len(s["final_state"]["q"])
            settings = " ".join(sets[1::2]) or model
            print(f"| {method} | {settings} | {n} | {error(out, ref, 0.5):.2f} | "
                  f"{error(out, ref, 2.0):.2f} | {s['wall_s']:.2f} s |", flush=True)


if __name__ == "__main__":
    main()
