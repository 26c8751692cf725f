#!/usr/bin/env python3
"""rom by order on the cantilever3d rod released straight under gravity:
steps of a 0.5 s run at rtol 1e-9 and the mass matrix's
condition number at the straight state. Prints a markdown table for
docs/validation.md. Run from the repository root after `cargo build
--release` (orders not compiled in are derived once into the cache).
"""
import json
import subprocess
import sys

import numpy as np

BIN = "target/release/softarm"
SETS = ["--set", "gravity=[0,0,-9.81]", "--set", "segment.0.method=rom"]


def softarm(*args):
    out = subprocess.run([BIN, *args], capture_output=True, text=True)
    if out.returncode != 0:
        sys.exit(out.stderr)
    return out.stdout


print("| order | coordinates | cond(M) straight | steps (rejected), 0.5 s at rtol 1e-9 | wall |")
print("|---|---|---|---|---|")
for order in range(1, 9):
    sets = SETS + ["--set", f"segment.0.order={order}"]
    eom = json.loads(softarm("eom", "cantilever3d", *sets, "--json"))
    m = np.array(eom["mass"])
    softarm("simulate", "cantilever3d", *sets, "--t-end", "0.5", "--rtol", "1e-9", "--atol", "1e-12",
            "--solver", "dopri5", "--shape-points", "0", "--quiet", "--out", f"/tmp/rom_order{order}")
    s = json.load(open(f"/tmp/rom_order{order}/summary.json"))
    print(f"| {order} | {len(m)} | {np.linalg.cond(m):.3g} | {s['steps']} ({s['rejected_steps']}) | "
          f"{s['wall_s']:.2f} s |")
