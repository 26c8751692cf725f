"""Track a circle with STIFF-FLOP's tip by model predictive control on
softarm's linearisation, the pressures kept within their valves' range.

Every 20 ms the controller predicts the tip over the next 0.2 s with the
discrete linear model about the operating point (all chambers at 0.2 bar,
from `Model.linearize`), and chooses the pressures that keep the predicted
tip nearest the circle: a bounded least-squares problem (scipy's
`lsq_linear`), pressures between 0 and 0.5 bar, moves penalised. The
first move is applied to the nonlinear model (`Model.simulator`) and the
rest discarded; the measured tip corrects the prediction's offset. Prints
the tracking error; exits non-zero unless its RMS over the second lap is
under 0.5 mm with every pressure within its range. (A circle of 8 mm
drives the pressures onto both bounds, and the tip falls behind it.)

    pip install ./python scipy && python examples/python/mpc_stiff_flop.py
"""

import sys

import numpy as np
from scipy.optimize import lsq_linear
from scipy.signal import cont2discrete

import softarm

PRESSURES = ["p0", "p1", "p2"]
U0 = np.full(3, 2.0e4)          # Pa: the operating point
LO, HI = 0.0, 5.0e4             # Pa: the valves' range
DT, H = 0.02, 10                # s, steps: control period and horizon
RADIUS, PERIOD = 4e-3, 2.0      # m, s: the circle in the tip's x-y plane
MOVE = 1e-15                    # m^2 per Pa^2: 0.1 bar of change weighs as 0.3 mm of error

arm = softarm.load("stiff_flop")
lin = arm.linearize(inputs=PRESSURES, u0=U0)
A, B, C = lin["A"], lin["B"], lin["C"]
n = A.shape[0]
Ad, Bd, *_ = cont2discrete((A, B, C, np.zeros((3, 3))), DT)

# Predicted tips over the horizon: y = F dx0 + G du (du stacked), the
# condensed form of the linear model.
F = np.vstack([C @ np.linalg.matrix_power(Ad, k + 1) for k in range(H)])
G = np.zeros((3 * H, 3 * H))
for k in range(H):
    for j in range(k + 1):
        G[3 * k:3 * k + 3, 3 * j:3 * j + 3] = C @ np.linalg.matrix_power(Ad, k - j) @ Bd
# Moves: the difference of consecutive inputs, the first from the last applied.
D = np.eye(3 * H) - np.eye(3 * H, k=-3)

sim = arm.simulator(dt=DT, inputs=PRESSURES)
x0 = np.concatenate([lin["q0"], np.zeros(n // 2)])
sim.reset(x0)
tip0 = sim.tip.copy()  # the operating point's tip


def circle(t):
    a = 2 * np.pi * t / PERIOD
    return tip0 + np.array([RADIUS * np.sin(a), RADIUS * (np.cos(a) - 1.0), 0.0])


du_last = np.zeros(3)
errors, pressures = [], []
steps = int(2 * PERIOD / DT)
for k in range(steps):
    t = sim.t
    dx = sim.state - x0
    offset = sim.tip - (tip0 + C @ dx)      # what the linear model misses
    ref = np.concatenate([circle(t + (j + 1) * DT) - tip0 - offset for j in range(H)])
    prev = np.concatenate([du_last, np.zeros(3 * (H - 1))])
    w = np.sqrt(MOVE)
    M = np.vstack([G, w * D])
    rhs = np.concatenate([ref - F @ dx, w * prev])
    plan = lsq_linear(M, rhs, bounds=(LO - U0[0], HI - U0[0])).x
    du_last = plan[:3]
    sim.step(U0 + du_last)
    pressures.append(U0 + du_last)
    errors.append(np.linalg.norm(sim.tip - circle(sim.t)))
    if k % 25 == 24:
        print(f"t = {sim.t:4.2f} s: tracking error {1e3 * errors[-1]:.3f} mm, "
              f"pressures {np.round((U0 + du_last) / 1e5, 3)} bar")

second_lap = np.array(errors[steps // 2:])
rms = 1e3 * np.sqrt(np.mean(second_lap ** 2))
p = np.array(pressures)
print(f"second lap: RMS tracking error {rms:.3f} mm, pressures {p.min() / 1e5:.3f} "
      f"to {p.max() / 1e5:.3f} bar")
sys.exit(0 if rms < 0.5 and p.min() >= LO - 1e-6 and p.max() <= HI + 1e-6 else 1)
