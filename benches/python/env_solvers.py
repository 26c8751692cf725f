"""Solvers for the Gymnasium environments' stepping (BENCHMARKS.md): steps a
second over 200 steps of 10 ms, and the final tip's distance from the first
(tightest) run of each model. Reach-v0's model (stiff_flop) under random
chamber pressures; Track-v0's (finger_free) under a sine in pressure.

    pip install ./python && python benches/python/env_solvers.py
"""

import time

import numpy as np

import softarm

CASES = {
    ("stiff_flop", ("p0", "p1", "p2")): (
        np.random.default_rng(0).uniform(0, 1.1e5, (200, 3)),
        [("radau5", 1e-6), ("auto", 1e-6), ("radau5", 1e-4), ("radau5", 1e-3), ("bdf", 1e-4),
         ("bdf", 1e-3), ("dopri5", 1e-3), ("bs23", 1e-3)],
    ),
    ("finger_free", ("pressure",)): (
        (0.5e5 + 0.5e5 * np.sin(np.arange(200) * 0.0628))[:, None],
        [("auto", 1e-6), ("radau5", 1e-3), ("bdf", 1e-3), ("trbdf2", 1e-3), ("bs23", 1e-3),
         ("dopri5", 1e-3)],
    ),
}

for (name, inputs), (actions, solvers) in CASES.items():
    m = softarm.load(name)
    ref = None
    for solver, rtol in solvers:
        sim = m.simulator(0.01, inputs=list(inputs), solver=solver, rtol=rtol, atol=1e-6)
        t = time.perf_counter()
        for a in actions:
            sim.step(a)
        rate = len(actions) / (time.perf_counter() - t)
        ref = sim.tip if ref is None else ref
        print(f"{name} {solver} rtol {rtol:g}: {rate:.0f} steps/s, "
              f"tip off by {np.linalg.norm(sim.tip - ref) * 1e6:.1f} um", flush=True)
