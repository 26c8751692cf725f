#!/usr/bin/env python3
"""PyElastica on the steel rod of examples/steel_rod.toml (Till, Aloi and
Rucker's cantilever: E 200 GPa, G 80 GPa, r 1 mm, rho 8000 kg/m^3, L 0.5 m,
gravity across it), at the step its explicit scheme's stability needs: how
long 25 s would take.

PyElastica's PositionVerlet is explicit: its step is bounded by the sound
speed across an element (sqrt(E / rho) = 5 km/s in steel) and by the fastest
bending wave. This script finds the largest stable step of a ladder of
fractions of dx / c (stable: the tip stays within the rod's length of its
start over 0.2 s), times 0.2 s at it, and extrapolates to 25 s (the cost per
step does not change along a run). The rod starts straight and falls under
gravity; the released static bend of the example changes the motion, not
the cost of a step.

    python3 benches/peers/steel_rod_pyelastica.py [elements]   (default 40, Till's grid)

Needs pyelastica (1.0.0 measured) and numpy.
"""

import sys
import time

import numpy as np
import elastica as ea

E, G, R, RHO, L = 200e9, 80e9, 1e-3, 8000.0, 0.5
SPAN, T_FULL = 0.2, 25.0


class Rod(ea.BaseSystemCollection, ea.Constraints, ea.Forcing):
    pass


def run(n, dt, span):
    sim = Rod()
    rod = ea.CosseratRod.straight_rod(
        n, start=np.zeros(3), direction=np.array([1.0, 0.0, 0.0]),
        normal=np.array([0.0, 0.0, 1.0]), base_length=L, base_radius=R,
        density=RHO, youngs_modulus=E, shear_modulus=G,
    )
    sim.append(rod)
    sim.constrain(rod).using(ea.OneEndFixedBC, constrained_position_idx=(0,),
                             constrained_director_idx=(0,))
    sim.add_forcing_to(rod).using(ea.GravityForces, acc_gravity=np.array([0.0, 0.0, -9.81]))
    sim.finalize()
    steps = int(round(span / dt))
    started = time.perf_counter()
    ea.integrate(ea.PositionVerlet(), sim, span, steps, progress_bar=False)
    wall = time.perf_counter() - started
    tip = rod.position_collection[:, -1]
    stable = bool(np.all(np.isfinite(tip))) and np.linalg.norm(tip - [L, 0, 0]) < L
    return stable, steps, wall


def main():
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 40
    dx, c = L / n, np.sqrt(E / RHO)
    run(n, dx / c, 1e-3)  # numba's compilation, outside the timing
    for fraction in [1.0, 0.5, 0.25, 0.1, 0.05]:
        dt = fraction * dx / c
        stable, steps, wall = run(n, dt, SPAN)
        print(f"dt = {dt:.3e} s ({fraction} dx/c): {'stable' if stable else 'unstable'}, "
              f"{steps} steps in {wall:.2f} s")
        if stable:
            full = wall * T_FULL / SPAN
            print(f"PyElastica, {n} elements, dt {dt:.2e} s: {steps / wall:,.0f} steps a second; "
                  f"25 s would take {full:,.0f} s ({T_FULL / full:.4f} of real time)")
            return
    sys.exit("no stable step in the ladder")


if __name__ == "__main__":
    main()
