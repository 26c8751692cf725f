"""Swing the bundled soft finger from Python, read its natural frequencies,
and plot the tip (examples/python/swing.png) when matplotlib is there.

    pip install ./python matplotlib && python examples/python/swing.py
"""

import softarm

arm = softarm.load("soft_finger", set={"tip.mass": 0.02})
run = arm.simulate(t_end=2.0)
print(f"{arm}: {len(run['t'])} rows, {run['summary']['steps']} steps, "
      f"{run['summary']['wall_s'] * 1e3:.1f} ms")
print("first frequencies (Hz):", arm.modes()["frequencies_hz"][:3].round(2))

try:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:
    print("matplotlib not installed: no plot")
else:
    plt.plot(run["t"], run["tip"][:, 1] * 1e3)
    plt.xlabel("t (s)")
    plt.ylabel("tip y (mm)")
    plt.title("soft_finger swinging under gravity")
    plt.savefig("examples/python/swing.png", dpi=100)
    print("wrote examples/python/swing.png")
