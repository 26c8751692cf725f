#!/usr/bin/env python3
"""The Cosserat rod's answer to the cantilever3d transient, from
PyElastica: the rod of models/cantilever3d.toml (L 0.3 m, r 10 mm, rho 1000
kg/m^3, E 1 MPa, G = E/3, PyElastica's shear factor 27/28) clamped at the
origin along +x, released straight under gravity (-z), undamped, for 2 s.

It runs a refinement sequence (n elements doubling), prints the table of
the tip's largest distance from the finest run over 2 s and over 0.5 s (%
of L), and writes the finest run's tip every 10 ms to tests/data/.

The constitutive law (--law):

* `section` (the default): the linear-elastic rod of constant section,
  n = S sigma and m = B kappa with S, B of the declared E, G, A, I, J.
  This is the rod softarm's methods discretise. PyElastica's own law
  thins the section as the rod stretches; this script undoes that in its
  internal force and couple (`constant_section`) and leaves the rotary
  inertia's 1/e: the sections' rotary inertia is under 1e-3 of the rod's
  about the clamp, so a 1 % change of it moves the tip by far less than
  the reference's own error.
  Written to tests/data/cantilever3d_cosserat_tip.csv.
* `pyelastica`: PyElastica's own law, for an incompressible material:
  internal force Q^T S sigma / e and bending couple B kappa / e^3 with e
  the dilatation. Its moment has no energy whose stretch derivative it
  balances, so no energy-based (TMT) model reproduces it; softarm's
  `incompressible = true` is the conservative form and differs from it.
  At 1 % stretch in the swing the two laws part by about 1 % of L over
  2 s. Written to tests/data/cantilever3d_cosserat_pyelastica_law_tip.csv.

--axial-factor F multiplies the stretch and shear stiffness by F: with F
= 1000 the rod is inextensible and unshearable to 1e-3 of its strains,
the reference of the inextensible methods (pcc, ebr, rom without
extension). Written to tests/data/cantilever3d_inextensible_tip.csv.

The clamp sits half an element out, which makes the convergence second
order (with the clamp at the first node, 50, 100 and 200 elements differ
from 400 by 4.9, 2.1 and 0.71 % of L over 0.5 s). The step is a fixed
fraction of the explicit limits (sound speed and the fastest bending wave);
400 elements need a smaller fraction late in the swing, so 200 elements
is the reference: 50 and 100 differ from it by about 0.32 and 0.09 % of L
over 2 s, so it is within about 0.03 % of the converged rod. The tables are
in docs/validation.md.

    python3 scripts/pyelastica_reference.py [--law section|pyelastica]
        [--axial-factor F] [n1 n2 ...]          (default 50 100 200)

Without PyElastica at hand it makes a virtual environment of its own
(target/pyelastica-venv, pyelastica 1.0.0, whose internals the constant
section patches) and runs itself there.
"""

import argparse
import os
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
VENV = ROOT / "target" / "pyelastica-venv"


def in_own_venv():
    """Re-run this script in VENV, made and filled on first use."""
    python = VENV / "bin" / "python"
    if os.environ.get("SOFTARM_PYELASTICA_VENV"):
        sys.exit(f"PyElastica did not import in {VENV}")
    if not python.exists():
        subprocess.run([sys.executable, "-m", "venv", str(VENV)], check=True)
        subprocess.run([str(python), "-m", "pip", "install", "--quiet", "pyelastica==1.0.0"],
                       check=True)
    env = {**os.environ, "SOFTARM_PYELASTICA_VENV": "1"}
    os.execve(str(python), [str(python), __file__, *sys.argv[1:]], env)


try:
    import numpy as np
    import elastica as ea
    import elastica.rod.cosserat_rod as cosserat
    from elastica._calculus import difference_kernel_for_block_structure
except ImportError:
    in_own_venv()

L, R, RHO, E = 0.3, 0.01, 1000.0, 1.0e6
G = E / 3.0
T_END, SAMPLE = 2.0, 0.01
DATA = ROOT / "tests" / "data"


def constant_section():
    """PyElastica 1.0's internal force and couple with the section kept:
    force Q^T n (not Q^T n / e), couple B kappa (not B kappa / e^3). The
    shear couple, (Q t) x n l_rest in PyElastica, is (Q dr/ds) x n =
    e (Q t) x n for this law: the force kernel leaves n e in
    internal_stress, which the couple reads."""
    forces_of_law = cosserat._compute_internal_forces
    torques_of_law = cosserat._compute_internal_torques

    def forces(position, volume, lengths, tangents, radius, rest_lengths,
               rest_voronoi_lengths, dilatation, voronoi_dilatation, directors,
               sigma, rest_sigma, shear_matrix, internal_stress, internal_forces,
               ghost_elems_idx):
        # The law's kernel computes e, sigma and n = S (sigma - rest).
        forces_of_law(position, volume, lengths, tangents, radius, rest_lengths,
                      rest_voronoi_lengths, dilatation, voronoi_dilatation, directors,
                      sigma, rest_sigma, shear_matrix, internal_stress, internal_forces,
                      ghost_elems_idx)
        lab = np.einsum("jik,jk->ik", directors, internal_stress)
        internal_forces[:] = difference_kernel_for_block_structure(lab, ghost_elems_idx)
        internal_stress *= dilatation

    def torques(position, velocity, tangents, lengths, rest_lengths, directors,
                rest_voronoi_lengths, bend_matrix, rest_kappa, kappa, voronoi_dilatation,
                *rest):
        torques_of_law(position, velocity, tangents, lengths, rest_lengths, directors,
                       rest_voronoi_lengths, bend_matrix, rest_kappa, kappa,
                       np.ones_like(voronoi_dilatation), *rest)

    cosserat._compute_internal_forces = forces
    cosserat._compute_internal_torques = torques


class Rod(ea.BaseSystemCollection, ea.Constraints, ea.Forcing, ea.CallBacks):
    pass


class TipEvery(ea.CallBackBaseClass):
    def __init__(self, every, out):
        super().__init__()
        self.every, self.out = every, out

    def make_callback(self, system, time, current_step):
        if current_step % self.every == 0:
            self.out.append([time, *system.position_collection[:, -1]])


def run(n, axial_factor):
    # The clamp half an element out: n elements of dx = L / (n - 1/2) from
    # x = -dx / 2, node 0 and the first director held, so the rod's
    # clamped cross-section sits at the origin and the tip at L.
    dx = L / (n - 0.5)
    sim = Rod()
    rod = ea.CosseratRod.straight_rod(
        n, start=np.array([-0.5 * dx, 0.0, 0.0]), direction=np.array([1.0, 0.0, 0.0]),
        normal=np.array([0.0, 0.0, 1.0]), base_length=n * dx, base_radius=R,
        density=RHO, youngs_modulus=E, shear_modulus=G,
    )
    rod.shear_matrix *= axial_factor
    sim.append(rod)
    sim.constrain(rod).using(ea.OneEndFixedBC, constrained_position_idx=(0,),
                             constrained_director_idx=(0,))
    sim.add_forcing_to(rod).using(ea.GravityForces, acc_gravity=np.array([0.0, 0.0, -9.81]))
    # A step well inside the explicit limits: the sound speed sqrt(E / rho)
    # across an element, and the fastest bending wave, whose frequency
    # grows as (pi / dx)^2 sqrt(E I / rho A) (a limit in dx^2: with the
    # first rule alone 400 elements blow up); a whole number per sample.
    bending = (np.pi / dx) ** 2 * np.sqrt(E * R**2 / (4.0 * RHO))
    dt_max = min(0.1 * dx / np.sqrt(axial_factor * E / RHO), 2.0 / bending)
    per_sample = int(np.ceil(SAMPLE / dt_max))
    steps = per_sample * int(round(T_END / SAMPLE))
    tip = []
    sim.collect_diagnostics(rod).using(TipEvery, every=per_sample, out=tip)
    sim.finalize()
    started = time.perf_counter()
    ea.integrate(ea.PositionVerlet(), sim, T_END, steps, progress_bar=False)
    return np.array(tip), time.perf_counter() - started


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--law", choices=["section", "pyelastica"], default="section")
    ap.add_argument("--axial-factor", type=float, default=1.0)
    ap.add_argument("elements", nargs="*", type=int, default=[50, 100, 200])
    a = ap.parse_args()
    if a.law == "section":
        constant_section()
    if a.axial_factor != 1.0:
        name, what = "cantilever3d_inextensible_tip.csv", f"stretch and shear stiffness x {a.axial_factor:g}"
    elif a.law == "section":
        name, what = "cantilever3d_cosserat_tip.csv", "constant section"
    else:
        name, what = "cantilever3d_cosserat_pyelastica_law_tip.csv", "PyElastica's law"
    ns = a.elements
    runs = {}
    for n in ns:
        tip, wall = run(n, a.axial_factor)
        runs[n] = tip
        print(f"n = {n:4d}: {len(tip)} samples, {wall:.1f} s", flush=True)
    finest = runs[ns[-1]]
    print("\n| elements | max tip distance from the finest over 2 s (% of L) | over 0.5 s |")
    print("|---|---|---|")
    for n in ns[:-1]:
        k = min(len(runs[n]), len(finest))
        d = np.linalg.norm(runs[n][:k, 1:] - finest[:k, 1:], axis=1)
        half = finest[:k, 0] <= 0.5 + 1e-9
        print(f"| {n} | {100 * d.max() / L:.4f} | {100 * d[half].max() / L:.4f} |")
    out = DATA / name
    out.parent.mkdir(parents=True, exist_ok=True)
    np.savetxt(out, finest, delimiter=",", fmt="%.10e",
               header=f"PyElastica {ns[-1]} elements, {what} (scripts/pyelastica_reference.py)\nt,x,y,z",
               comments="# ")
    print(f"\nwrote {out}")


if __name__ == "__main__":
    main()
