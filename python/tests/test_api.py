"""softarm from Python against the command line, an independent front end
over the same core: mass, bias, outputs and the static tip agree exactly
(JSON prints every bit), a trajectory to the 13 digits trajectory.csv
prints; bad input raises clear exceptions.

The CLI binary is $SOFTARM_BIN, else target/debug/softarm (built by
`cargo test`), else target/release/softarm.
"""

import csv
import json
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

import softarm
from cli import cli

ROOT = Path(__file__).resolve().parents[2]
MODELS = ["double_pendulum", "soft_finger"]


def run(*args, cwd=None):
    out = subprocess.run([cli(), *args], capture_output=True, text=True, cwd=cwd)
    assert out.returncode == 0, out.stderr
    return out.stdout


def state(m, seed):
    rng = np.random.default_rng(seed)
    return rng.uniform(-0.5, 0.5, m.dof), rng.uniform(-1.0, 1.0, m.dof)


@pytest.mark.parametrize("name", MODELS)
def test_mass_bias_and_outputs_are_the_clis(name):
    m = softarm.load(name)
    q, qd = state(m, 1)
    fmt = lambda v: ",".join(repr(float(x)) for x in v)
    ref = json.loads(run("eom", name, "--q", fmt(q), "--qd", fmt(qd), "--t", "0.3", "--json"))
    M, h = m.mass_bias(q, qd, 0.3)
    assert np.array_equal(M, np.array(ref["mass"]))
    assert np.array_equal(h, np.array(ref["bias"]))
    assert np.array_equal(m.tip(q, 0.3), np.array(ref["tip_position"]))
    assert m.coordinates == ref["coordinates"]
    # M is symmetric positive definite.
    assert np.array_equal(M, M.T) and np.all(np.linalg.eigvalsh(M) > 0)


@pytest.mark.parametrize("name", MODELS)
def test_the_static_tip_is_the_clis(name):
    ref = json.loads(run("static", name, "--shape-points", "0", "--json"))
    sol = softarm.load(name).static()
    assert np.array_equal(sol["q"], np.array(ref["q"]))
    assert np.array_equal(sol["tip"], np.array(ref["tip_position"]))


def test_rho_inf_reaches_generalized_alpha_as_the_clis(tmp_path):
    # The same run as `--solver genalpha --rho-inf 0.5`, to the bit; and a
    # different rho_inf takes other steps (the value is not dropped).
    run("simulate", "soft_finger", "--t-end", "1", "--solver", "genalpha", "--rho-inf", "0.5",
        "--shape-points", "0", "--quiet", "--out", str(tmp_path))
    summary = json.loads((tmp_path / "summary.json").read_text())
    m = softarm.load("soft_finger")
    half = m.simulate(t_end=1.0, solver="genalpha", rho_inf=0.5)
    assert half["summary"]["steps"] == summary["steps"]
    with open(tmp_path / "trajectory.csv") as f:
        last = list(csv.DictReader(f))[-1]
    ref = np.array([float(last[c]) for c in m.coordinates])
    assert np.max(np.abs(half["q"][-1] - ref)) <= 1e-12 * np.max(np.abs(ref))
    other = m.simulate(t_end=1.0, solver="genalpha", rho_inf=1.0)
    assert other["summary"]["steps"] != summary["steps"]
    with pytest.raises(ValueError, match="rho_inf"):
        m.simulate(t_end=0.1, rho_inf=0.5, inputs={"p": lambda t, s: 0.0})


@pytest.mark.parametrize("name", MODELS)
def test_a_trajectory_is_the_clis(name, tmp_path):
    run("simulate", name, "--t-end", "1", "--shape-points", "0", "--quiet",
        "--out", str(tmp_path))
    with open(tmp_path / "trajectory.csv") as f:
        rows = list(csv.DictReader(f))
    r = softarm.load(name).simulate(t_end=1.0)
    m = softarm.load(name)
    assert len(rows) == len(r["t"])
    cols = m.coordinates + [c + "_dot" for c in m.coordinates] + list(softarm.OUTPUT_NAMES)
    ref = np.array([[float(row[c]) for c in cols] for row in rows])
    ours = np.hstack([r["q"], r["qd"], r["outputs"]])
    scale = np.maximum(np.abs(ref), 1e-12)
    assert np.max(np.abs(ours - ref) / scale) < 1e-12
    assert np.allclose(r["t"], [float(row["t"]) for row in rows], rtol=0, atol=1e-9)
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert r["summary"]["steps"] == summary["steps"]
    assert r["summary"]["rhs_evaluations"] == summary["rhs_evaluations"]
    # Every column the CLI writes is the run's, by name.
    header = list(rows[0].keys())
    assert header == ["t"] + cols + list(r["columns"])
    for c in r["columns"]:
        ref = np.array([float(row[c]) for row in rows])
        assert np.allclose(r["columns"][c], ref, rtol=1e-12, atol=1e-12)
    # The summaries agree but for the CLI's own keys and the run's timing.
    own = {"options", "assembly_moved", "wall_s", "derive_s", "cache"}
    assert set(summary) - own == set(r["summary"]) - own
    for k in set(summary) - own - {"final_state"}:
        assert r["summary"][k] == summary[k], k


def test_overrides_change_numbers_not_the_backend():
    light = softarm.load("soft_finger", set={"tip.mass": 0.0})
    heavy = softarm.load("soft_finger", set={"tip.mass": 0.05})
    assert light.backend == heavy.backend == "compiled"
    assert heavy.static()["tip"][1] < light.static()["tip"][1]


def test_bad_input_raises_clear_exceptions():
    m = softarm.load("double_pendulum")
    with pytest.raises(ValueError, match="q has 3 values; the model has 2"):
        m.mass_bias(np.zeros(3))
    with pytest.raises(ValueError, match=r"q\[1\] is NaN"):
        m.mass_bias(np.array([0.0, np.nan]))
    with pytest.raises(ValueError, match="no_such_model"):
        softarm.load("no_such_model")
    with pytest.raises(ValueError, match="segment"):
        softarm.load("soft_finger", set={"segment.0.length": -1.0})
    with pytest.raises(ValueError, match="--rtol must be positive"):
        m.simulate(t_end=0.1, rtol=-1.0)
    with pytest.raises(ValueError, match="unknown solver"):
        m.simulate(t_end=0.1, solver="ode45")
    with pytest.raises(ValueError, match="the starts are"):
        m.simulate(t_end=0.1, start="moving")
    with pytest.raises(ValueError, match="a run returned in memory keeps at most 1000000"):
        m.simulate(t_end=1.0, output_dt=1e-6)


def test_a_run_that_gives_up_raises_with_its_report():
    m = softarm.load("soft_finger")
    with pytest.raises(softarm.IntegrationError) as e:
        m.simulate(t_end=1.0, max_steps=5)
    assert e.value.report["t_reached"] < 1.0
    assert e.value.report["suggestion"]


@pytest.mark.parametrize("name", MODELS)
def test_the_modes_are_the_clis(name):
    ref = json.loads(run("modes", name, "--json"))
    ours = softarm.load(name).modes()
    assert np.array_equal(ours["frequencies_hz"], np.array(ref["frequencies_hz"]))
    assert ours["shapes"].shape == (len(ref["equilibrium_q"]), len(ref["frequencies_hz"]))


def test_stepping_reproduces_a_run_at_its_steps():
    # rk4 at a step dividing the control step: the same arithmetic.
    m = softarm.load("soft_finger")
    run = m.simulate(t_end=0.2, solver="rk4", dt=1e-5, output_dt=0.05)
    sim = m.simulator(0.05, solver="rk4", step=1e-5)
    assert np.array_equal(sim.state, np.concatenate([run["q"][0], run["qd"][0]]))
    for k in range(1, len(run["t"])):
        x = sim.step()
        ref = np.concatenate([run["q"][k], run["qd"][k]])
        assert np.allclose(x, ref, rtol=1e-10, atol=1e-12), k
        assert abs(sim.t - run["t"][k]) < 1e-12
    # Adaptive: restarting at each step agrees to the tolerance asked.
    run = m.simulate(t_end=0.5, rtol=1e-10, atol=1e-12, output_dt=0.05)
    sim = m.simulator(0.05, rtol=1e-10, atol=1e-12)
    for k in range(1, len(run["t"])):
        sim.step()
    assert np.allclose(sim.q, run["q"][-1], rtol=0, atol=1e-7)


def test_a_new_run_begins_its_contacts_afresh():
    # finger_tap touches its table at 0.13 s: a second run of the model,
    # and the simulator after reset, are the first, with no record of how
    # the last run's contacts began.
    m = softarm.load("finger_tap")
    a = m.simulate(t_end=0.3, output_dt=0.01)
    b = m.simulate(t_end=0.3, output_dt=0.01)
    assert np.array_equal(a["q"], b["q"])
    sim = m.simulator(0.01)
    first = np.array([sim.step() for _ in range(30)])
    sim.reset()
    again = np.array([sim.step() for _ in range(30)])
    assert np.array_equal(first, again)


def test_a_held_input_is_the_constant_channel():
    # finger_free's pressure held at 1e5 Pa step by step is the run whose
    # pressure ramps from 1e5 to 1e5 (a constant).
    c = 1.0e5
    m = softarm.load("finger_free", set={"inputs.pressure.from": c, "inputs.pressure.to": c})
    # (rk4 at 1e-6 s: pressed, the finger is stiff.)
    run = m.simulate(t_end=0.05, solver="rk4", dt=1e-6, output_dt=0.01)
    sim = softarm.load("finger_free").simulator(0.01, inputs=["pressure"], solver="rk4", step=1e-6)
    assert sim.inputs == ["pressure"]
    for k in range(1, len(run["t"])):
        sim.step([c])
    assert np.allclose(sim.q, run["q"][-1], rtol=1e-10, atol=1e-12)
    assert np.allclose(sim.tip, run["tip"][-1], rtol=1e-10, atol=1e-12)
    # reset: back to the start.
    x = sim.reset()
    assert sim.t == 0.0 and np.array_equal(x, np.concatenate([run["q"][0], run["qd"][0]]))


def test_bad_simulator_input_is_named():
    m = softarm.load("finger_free")
    with pytest.raises(ValueError, match="no channel \"pressur\""):
        m.simulator(0.01, inputs=["pressur"])
    sim = m.simulator(0.01, inputs=["pressure"])
    with pytest.raises(ValueError, match="u has 2 values"):
        sim.step([1.0, 2.0])
    with pytest.raises(ValueError, match="dt = 0"):
        m.simulator(0.0)


def test_linearize_is_the_clis_and_its_a_is_the_rhs_jacobian():
    ref = json.loads(run("linearize", "stiff_flop", "--inputs", "p0,p1,p2", "--u0", "20000,5000,0",
                         "--json"))
    m = softarm.load("stiff_flop")
    lin = m.linearize(["p0", "p1", "p2"], u0=[2e4, 5e3, 0.0])
    for key in "ABCD":
        assert np.array_equal(lin[key], np.array(ref[key])), key
    assert np.array_equal(lin["q0"], np.array(ref["q0"]))
    # Small-signal check: one step of the simulator from the equilibrium
    # with a small pressure change follows A and B to first order.
    n = m.dof
    sim = m.simulator(1e-4, inputs=["p0", "p1", "p2"], rtol=1e-12, atol=1e-14)
    du = np.array([50.0, 0.0, 0.0])
    sim.reset(np.concatenate([lin["q0"], np.zeros(n)]))
    x1 = sim.step(lin["u0"] + du)
    dx = x1 - np.concatenate([lin["q0"], np.zeros(n)])
    from math import factorial
    # x(h) - x0 = sum_k h^k A^(k-1) B du / k! for the linear system.
    h, term, pred = 1e-4, lin["B"] @ du, np.zeros(2 * n)
    for k in range(1, 12):
        pred += h**k / factorial(k) * term
        term = lin["A"] @ term
    assert np.allclose(dx, pred, rtol=1e-3, atol=1e-3 * np.abs(pred).max())


def test_inputs_as_samples_replace_a_channel():
    # finger_free's own ramp (0 to 1.5 bar between 0.1 s and 0.11 s),
    # given as samples instead: the same run.
    m = softarm.load("finger_free")
    own = m.simulate(t_end=0.3)
    given = m.simulate(t_end=0.3, inputs={"pressure": ([0.1, 0.11], [0.0, 1.5e5])})
    assert np.array_equal(given["q"], own["q"])
    # The run reports the channel: 0 before the ramp, 1.5 bar after it.
    p = given["inputs"]["pressure"]
    assert np.array_equal(p, own["inputs"]["pressure"])
    assert p[given["t"] < 0.1].max() == 0.0 and p[given["t"] > 0.11].min() == 1.5e5
    # A constant as samples: the model with its ramp set flat.
    c = 7e4
    flat = softarm.load("finger_free", set={"inputs.pressure.from": c, "inputs.pressure.to": c})
    assert np.array_equal(m.simulate(t_end=0.2, inputs={"pressure": ([0.0], [c])})["q"],
                          flat.simulate(t_end=0.2)["q"])
    # The model itself is unchanged by a run with other inputs.
    assert np.array_equal(m.simulate(t_end=0.3)["q"], own["q"])
    with pytest.raises(ValueError, match="no channel"):
        m.simulate(t_end=0.1, inputs={"presure": ([0.0], [1.0])})


def test_a_callable_input_is_a_controller_in_the_loop():
    m = softarm.load("finger_free")
    seen = []

    def law(t, x):
        seen.append(t)
        return 5e4 if t < 0.05 else 0.0

    run = m.simulate(t_end=0.1, inputs={"pressure": law}, control_dt=0.01)
    sim = m.simulator(0.01, inputs=["pressure"])
    for k in range(10):
        sim.step([5e4 if 0.01 * k < 0.05 - 1e-12 else 0.0])
    assert np.array_equal(run["q"][-1], sim.q)
    assert len(run["t"]) == 11 and len(seen) == 10
    assert np.array_equal(run["inputs"]["pressure"][:5], [5e4] * 5)

    def broken(t, x):
        if t > 0.02:
            raise ZeroDivisionError("controller failed")
        return 0.0

    with pytest.raises(ZeroDivisionError, match="controller failed"):
        m.simulate(t_end=0.1, inputs={"pressure": broken}, control_dt=0.01)


def test_contact_forces_and_the_jacobian_are_the_clis(tmp_path):
    run("simulate", "finger_tap", "--t-end", "0.5", "--shape-points", "0", "--quiet",
        "--out", str(tmp_path))
    with open(tmp_path / "trajectory.csv") as f:
        rows = list(csv.DictReader(f))
    r = softarm.load("finger_tap").simulate(t_end=0.5)
    assert set(r["columns"]) == {"contact_table_fn", "contact_table_ft"}
    for name, col in r["columns"].items():
        ref = np.array([float(row[name]) for row in rows])
        assert np.allclose(col, ref, rtol=1e-12, atol=1e-12 * np.abs(ref).max())
    assert r["columns"]["contact_table_fn"].max() > 0, "the finger touched"
    # The Jacobian: central differences of the right-hand side (M, h).
    m = softarm.load("double_pendulum")
    q, qd = state(m, 4)
    J = m.jacobian(q, qd)

    def f(x):
        M, h = m.mass_bias(x[:2], x[2:])
        return np.concatenate([x[2:], -np.linalg.solve(M, h)])

    x = np.concatenate([q, qd])
    fd = np.column_stack([(f(x + e) - f(x - e)) / 2e-6 for e in np.eye(4) * 1e-6])
    assert np.allclose(J, fd, rtol=1e-6, atol=1e-8)


def test_nan_in_an_input_is_refused():
    m = softarm.load("finger_free")
    with pytest.raises(ValueError, match="pressure"):
        m.simulate(t_end=0.1, inputs={"pressure": ([0.0, 1.0], [0.0, np.nan])})
    sim = m.simulator(0.01, inputs=["pressure"])
    with pytest.raises(ValueError, match="u\\[0\\] is NaN"):
        sim.step([np.nan])


def test_a_long_run_releases_the_gil_and_stops_on_ctrl_c():
    import signal
    import threading
    import time

    m = softarm.load("soft_finger")
    # Other Python threads run while a simulation does.
    count = [0]
    done = threading.Event()

    def spin():
        while not done.is_set():
            count[0] += 1

    spinner = threading.Thread(target=spin)
    spinner.start()
    time.sleep(0.05)
    before, t0 = count[0], time.perf_counter()
    time.sleep(0.2)  # the spinner alone: its rate
    rate = (count[0] - before) / (time.perf_counter() - t0)
    before, t0 = count[0], time.perf_counter()
    m.simulate(t_end=3.0)
    during = (count[0] - before) / (time.perf_counter() - t0)
    done.set()
    spinner.join()
    # Holding the GIL would leave the spinner a switch interval or two.
    assert during > 0.3 * rate, f"the other thread ran at {during:.0f}/s of {rate:.0f}/s"
    # SIGINT (Ctrl-C) stops a run of minutes within moments. (A process
    # started in the background by a non-interactive shell ignores SIGINT,
    # and Python then installs no handler for it: install Python's own.)
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        timer = threading.Timer(0.3, lambda: os.kill(os.getpid(), signal.SIGINT))
        started = time.perf_counter()
        timer.start()
        with pytest.raises(KeyboardInterrupt):
            m.simulate(t_end=1e4)
        assert time.perf_counter() - started < 5.0
    finally:
        signal.signal(signal.SIGINT, previous)


def test_a_fit_is_the_clis(tmp_path):
    """`Model.fit` returns fit.json's content: the same values, errors and
    costs as `softarm fit`, to the bit."""
    free = {"segment.0.youngs_modulus": (5e4, 5e5), "segment.0.bending_damping": (1e-7, None)}
    args = ["--window", "1:4", "--validate", "4:6", "--rtol", "1e-5", "--max-iterations", "3"]
    for path, (lo, hi) in free.items():
        args += ["--free", f"{path}={lo!r}:{'' if hi is None else repr(hi)}"]
    subprocess.run([cli(), "fit", "stiff_flop", *args, "--out", str(tmp_path / "f"), "--quiet"],
                   check=True)
    expected = json.loads((tmp_path / "f" / "fit.json").read_text())
    got = softarm.load("stiff_flop").fit(free, window=(1, 4), validate=(4, 6), rtol=1e-5,
                                         max_iterations=3)
    for key in ["parameters", "initial", "std_error", "correlation", "cost", "iterations",
                "evaluations", "status", "at_bound"]:
        assert got[key] == expected[key], key
    with pytest.raises(ValueError, match="structural"):
        softarm.load("stiff_flop").fit({"segment.0.elements": None})


MIDSPAN = """
name = "midspan"
dimensions = 3
gravity = [0.0, 0.0, 0.0]
[base]
direction = [1.0, 0.0, 0.0]
[[segment]]
method = "pcc"
length = 0.2
elements = 16
density = 1000.0
outer_radius = 0.01
youngs_modulus = 1.0e6
[[load]]
segment = 0
s = 0.1
force_inputs = ["zero", "zero", "push"]
[inputs.zero]
kind = "constant"
value = 0.0
[inputs.push]
kind = "constant"
value = -0.01
"""


def test_a_load_along_the_arm_acts_from_python_as_from_the_cli(tmp_path):
    # A point force P at mid-span of a cantilever, driven by an input
    # channel: the tip deflects by 5 P L^3 / (48 E I) (beam theory, 0.3 %
    # of L here), in Python's statics exactly as in the CLI's.
    path = tmp_path / "midspan.toml"
    path.write_text(MIDSPAN)
    ref = json.loads(run("static", str(path), "--shape-points", "0", "--json", cwd=tmp_path))
    m = softarm.load(str(path))
    sol = m.static()
    assert np.array_equal(sol["tip"], np.array(ref["tip_position"]))
    ei = 1.0e6 * np.pi * 0.01**4 / 4.0
    want = -5.0 * 0.01 * 0.2**3 / (48.0 * ei)
    assert abs(sol["tip"][2] - want) < 2e-3 * abs(want), (sol["tip"], want)
    # Simulated from straight, undamped, it swings about that deflection
    # and so past it (to about twice it, at 0.22 s: half its first mode's
    # period): the load acts in the run too.
    r = m.simulate(t_end=0.3)
    tip_z = r["outputs"][:, list(softarm.OUTPUT_NAMES).index("tip_z")]
    assert np.isfinite(tip_z).all()
    assert 1.5 * want > np.min(tip_z) > 2.5 * want, (np.min(tip_z), want)
