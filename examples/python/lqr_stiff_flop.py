"""Hold STIFF-FLOP's tip on a target under a disturbance with an LQR
controller designed on softarm's linearisation.

The module hangs down with its three chamber pairs at 0.2 bar (the
operating point). `Model.linearize` gives the state-space model about that
equilibrium; a discrete LQR with integral action on the tip error is
designed from it (scipy), and run in closed loop on the nonlinear model
(`Model.simulator`, 10 ms control steps). At t = 1 s a 0.1 N sideways push
acts on the tip (the model's `fy` input, in the tip's frame), which alone
moves it by over a millimetre with the pressures held; the integral action
returns the tip to its target. Prints the tip error over time; exits
non-zero unless the controller holds the tip within 0.2 mm at the end and
the push alone moves it by over 1 mm.

    pip install ./python scipy && python examples/python/lqr_stiff_flop.py
"""

import sys

import numpy as np
from scipy.linalg import solve_discrete_are
from scipy.signal import cont2discrete

import softarm

PRESSURES = ["p0", "p1", "p2"]
U0 = np.full(3, 2.0e4)              # Pa: the operating point
TARGET = np.array([3e-3, -2e-3, 0.0])  # m: tip offset from the operating point
DT = 0.01                           # s: control step
PUSH = 0.1                          # N across the tip (its frame's y), from t = 1 s

arm = softarm.load("stiff_flop")
lin = arm.linearize(inputs=PRESSURES, u0=U0)
A, B, C = lin["A"], lin["B"], lin["C"]
n = A.shape[0]

# The steady state that puts the tip on the target: A dx + B du = 0,
# C dx = target (three pressures, three tip coordinates).
K = np.block([[A, B], [C, np.zeros((3, 3))]])
sol = np.linalg.lstsq(K, np.concatenate([np.zeros(n), TARGET]), rcond=None)[0]
x_ref, u_ref = sol[:n], sol[n:]

# Discrete model with the integral of the tip error as three more states.
Ad, Bd, *_ = cont2discrete((A, B, C, np.zeros((3, 3))), DT)
Aa = np.block([[Ad, np.zeros((n, 3))], [DT * C, np.eye(3)]])
Ba = np.vstack([Bd, np.zeros((3, 3))])
Q = np.diag(np.concatenate([np.zeros(n), np.zeros(3)]))
Q[:n, :n] = 1e6 * C.T @ C + 1e-6 * np.eye(n)
Q[n:, n:] = 1e7 * np.eye(3)
R = 1e-9 * np.eye(3)  # Pa^-2: a bar costs about as much as a tenth of a millimetre
P = solve_discrete_are(Aa, Ba, Q, R)
gain = np.linalg.solve(R + Ba.T @ P @ Ba, Ba.T @ P @ Aa)

sim = arm.simulator(dt=DT, inputs=PRESSURES + ["fy"])
x0 = np.concatenate([lin["q0"], np.zeros(n // 2)])
sim.reset(x0)
tip0 = sim.tip.copy()
target = tip0 + TARGET
integral = np.zeros(3)
for k in range(400):
    t = k * DT
    dx = sim.state - x0 - x_ref
    du = u_ref - gain @ np.concatenate([dx, integral])
    push = PUSH if t >= 1.0 else 0.0
    sim.step(np.concatenate([U0 + du, [push]]))
    err = sim.tip - target
    integral += DT * err
    if k % 25 == 24:
        print(f"t = {t + DT:4.2f} s: tip error {1e3 * np.linalg.norm(err):6.3f} mm, "
              f"pressures {np.round((U0 + du) / 1e5, 3)} bar")
final = 1e3 * np.linalg.norm(sim.tip - target)

# The same push with the pressures held at the target's: no feedback.
sim.reset(x0)
for k in range(400):
    sim.step(np.concatenate([U0 + u_ref, [PUSH if k * DT >= 1.0 else 0.0]]))
open_loop = 1e3 * np.linalg.norm(sim.tip - target)
print(f"final tip error {final:.3f} mm with the controller, {open_loop:.3f} mm without")
sys.exit(0 if final < 0.2 and open_loop > 1.0 else 1)
