"""The FMU of `softarm export --fmu`, in FMPy: its validation passes, and
FMPy's own simulation (CVODE on the FMU's binary) follows softarm's on the
same inputs, the tip within 1e-6 of the arm's length: the soft finger's
free swing, and the STIFF-FLOP module driven by its recorded chamber
pressures through their first pulse.

The inputs are held over each 10 ms, in both: softarm's stepping
simulator holds its input channels over each step, and FMPy is given each
change as a step (an input event, where CVODE restarts).

The CLI binary is $SOFTARM_BIN, else target/debug/softarm, else
target/release/softarm.
"""

import subprocess

import numpy as np
import pytest

fmpy = pytest.importorskip("fmpy", reason="FMPy (pip install fmpy) runs the FMU")
from fmpy.validation import validate_fmu  # noqa: E402

from cli import cli  # noqa: E402
import softarm  # noqa: E402

DT = 0.01


def export(name, tmp_path):
    fmu = tmp_path / f"{name}.fmu"
    out = subprocess.run([cli(), "export", name, "--fmu", str(fmu)], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert validate_fmu(str(fmu)) == []
    return fmu


def softarm_run(m, x0, inputs, values, t_end):
    """softarm's tip every DT with the input parameters held at `values`
    (a row a step) over each step."""
    sim = m.simulator(DT, inputs=inputs, rtol=1e-11, atol=1e-13)
    sim.reset(x0)
    tips = [sim.tip.copy()]
    for k in range(int(round(t_end / DT))):
        sim.step(values[k] if len(inputs) else None)
        tips.append(sim.tip.copy())
    return np.array(tips)


def fmpy_run(fmu, m, x0, inputs, values, t_end):
    """FMPy's tip every DT, from x0, with the inputs at `values`."""
    start = {f"q.{c}": v for c, v in zip(m.coordinates, x0[: m.dof])}
    start.update({f"qd.{c}": v for c, v in zip(m.coordinates, x0[m.dof:])})
    signals = None
    if inputs:
        # Held over each interval: each time twice, the value before and
        # the value from then on, which FMPy takes as a step (an input
        # event: CVODE restarts there, as softarm's simulator does).
        rows = []
        for k, row in enumerate(values):
            if k > 0:
                rows.append((k * DT, *values[k - 1]))
            rows.append((k * DT, *row))
        dtype = [("time", float)] + [(name, float) for name in inputs]
        signals = np.array(rows, dtype=dtype)
    r = fmpy.simulate_fmu(str(fmu), stop_time=t_end, output_interval=DT, relative_tolerance=1e-8,
                          start_values=start, input=signals, output=["tip_x", "tip_y", "tip_z"])
    # An input event records its time twice (the state is the same).
    _, first = np.unique(np.round(r["time"] / DT).astype(int), return_index=True)
    return np.column_stack([r["tip_x"], r["tip_y"], r["tip_z"]])[first]


def test_the_soft_finger_fmu_swings_as_softarm(tmp_path):
    fmu = export("soft_finger", tmp_path)
    m = softarm.load("soft_finger")
    x0 = np.zeros(2 * m.dof)
    ours = softarm_run(m, x0, [], [], 2.0)
    theirs = fmpy_run(fmu, m, x0, [], [], 2.0)
    assert theirs.shape == ours.shape
    assert np.max(np.abs(theirs - ours)) < 1e-6 * 0.12


def test_the_stiff_flop_fmu_follows_softarm_under_the_recorded_pressures(tmp_path):
    fmu = export("stiff_flop", tmp_path)
    m = softarm.load("stiff_flop")
    # The FMU's inputs are parameters; the chamber pressures are the
    # channels p0, p1, p2 as they are (the load cell's wrench stays 0).
    chambers = [f"chamber[0][{k}].pressure" for k in range(3)]
    inputs = [name for name in (v.name for v in fmpy.read_model_description(str(fmu)).modelVariables
                                if v.causality == "input")]
    assert set(chambers) <= set(inputs)
    # Chamber 0's first pulse (0.36 bar) comes at 9 to 11 s.
    t_end = 12.0
    times = np.arange(int(round(t_end / DT)) + 1) * DT
    params = m.parameters_at(times)
    values = params[:, [m.parameters.index(c) for c in chambers]]
    assert np.ptp(values) > 3e4, "the recorded pressures pulse in this window"
    q0 = m.static()["q"]
    x0 = np.concatenate([q0, np.zeros(m.dof)])
    ours = softarm_run(m, x0, ["p0", "p1", "p2"], values, t_end)
    theirs = fmpy_run(fmu, m, x0, chambers, values, t_end)
    assert np.max(np.abs(theirs - ours)) < 1e-6 * 0.044


def test_a_viscoelastic_fmu_creeps_as_softarm(tmp_path):
    """The soft finger (models/soft_finger.toml) of a relaxing material,
    two Prony branches: its relaxed forces are the FMU's states after q and
    qd, named as trajectory.csv names them, and it sags and creeps as
    softarm's run does."""
    spec = tmp_path / "relaxing_finger.toml"
    spec.write_text(RELAXING_FINGER)
    fmu = export(str(spec), tmp_path)
    names = [v.name for v in fmpy.read_model_description(str(fmu)).modelVariables]
    m = softarm.load(str(spec))
    assert f"relaxed1.{m.coordinates[-1]}" in names
    # At rest in the rest shape, relaxed: the relaxed forces zero too.
    x0 = np.zeros(2 * m.dof)
    # A second: both branches (0.05 and 0.5 s) relax within it.
    ours = softarm_run(m, np.zeros(4 * m.dof), [], [], 1.0)
    theirs = fmpy_run(fmu, m, x0, [], [], 1.0)
    assert theirs.shape == ours.shape
    assert np.max(np.abs(theirs - ours)) < 1e-6 * 0.12


# The soft finger (models/soft_finger.toml) as a model file of its own:
# the checkout may be out of reach. NAME and EXTRA are filled in.
FINGER = """
name = "NAME"
gravity = [0.0, -9.81, 0.0]
[base]
position = [0.0, 0.0, 0.0]
direction = [1.0, 0.0, 0.0]
[[segment]]
method = "pcc"
length = 0.12
elements = 8
density = 1070.0
outer_radius = 0.006
youngs_modulus = 1.0e6
EXTRA
[tip]
mass = 0.02
"""

RELAXING_FINGER = FINGER.replace("NAME", "relaxing_finger").replace(
    "EXTRA", "relaxation = [{ ratio = 0.3, time = 0.5 }, { ratio = 0.2, time = 0.05 }]")

# The finger above a table.
STRIKING_FINGER = FINGER.replace("NAME", "striking_finger").replace("EXTRA", "") + """
[[obstacle]]
name = "table"
shape = "plane"
point = [0.0, -0.04, 0.0]
normal = [0.0, 1.0, 0.0]

[contact]
model = "hunt_crossley"
stiffness = 2.0e4
exponent = 1.5
restitution = 0.5
friction = 0.3
slip_velocity = 1.0e-3
points_per_element = 2
"""


def test_a_finger_striking_a_table_in_the_fmu_rebounds_as_in_softarm(tmp_path):
    """The soft finger falls onto a table: the FMU's event indicators (the
    pairs' gaps) stop CVODE where a pair begins or ends to touch, and its
    records (each pair's impact speed, which the restitution damps by)
    follow softarm's, so the tip through the impacts matches."""
    spec = tmp_path / "striking_finger.toml"
    spec.write_text(STRIKING_FINGER)
    fmu = export(str(spec), tmp_path)
    m = softarm.load(str(spec))
    x0 = np.zeros(2 * m.dof)
    t_end = 0.4
    ours = softarm_run(m, x0, [], [], t_end)
    # Finer output: CVODE takes at most 500 steps between output points.
    r = fmpy.simulate_fmu(str(fmu), stop_time=t_end, output_interval=DT / 10,
                          relative_tolerance=1e-8, output=["tip_x", "tip_y", "tip_z"])
    _, first = np.unique(np.round(r["time"] / DT * 10).astype(int), return_index=True)
    theirs = np.column_stack([r["tip_x"], r["tip_y"], r["tip_z"]])[first][::10]
    assert theirs.shape == ours.shape
    # The finger (radius 6 mm) reaches into the table at y = -0.04.
    assert ours[:, 1].min() < -0.034
    assert np.max(np.abs(theirs - ours)) < 1e-6 * 0.12
