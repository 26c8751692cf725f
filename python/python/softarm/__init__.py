"""softarm from Python: soft robot arm dynamics, compiled.

    >>> import softarm
    >>> arm = softarm.load("soft_finger", set={"tip.mass": 0.01})
    >>> run = arm.simulate(t_end=2.0)
    >>> run["tip"].shape                     # (rows, 3)

Every call runs softarm's Rust core: the same equations, solvers and
defaults as the `softarm` command line, to the bit. Arrays are numpy
float64; errors are exceptions (`ValueError` naming the key path for a bad
model or argument, `IntegrationError` when the integrator gives up).
"""

from __future__ import annotations

import json
from typing import Any, Mapping, Optional, Sequence

import numpy as np

from . import _softarm
from ._softarm import IntegrationError

__all__ = ["load", "models", "sweep", "Model", "Simulator", "IntegrationError", "OUTPUT_NAMES"]

#: The columns of `Model.outputs` and of a run's "outputs".
OUTPUT_NAMES = tuple(_softarm.OUTPUT_NAMES)


def models() -> list[str]:
    """The names of the compiled-in models."""
    return list(_softarm.models())


def _override(path: str, value: Any) -> str:
    # Strings go as they are (a method name); numbers and lists as JSON.
    text = value if isinstance(value, str) else json.dumps(value)
    return f"{path}={text}"


def load(name_or_path: str, set: Optional[Mapping[str, Any]] = None) -> "Model":
    """Load a compiled-in model by name or a model file (TOML or JSON).

    `set` overrides values as `softarm --set` does, by key path:
    ``{"segment.0.length": 0.25, "tip.force": [0, -2, 0]}``. A model whose
    structure is compiled in runs compiled whatever its numbers; another is
    derived once into the tape cache (``.softarm-cache``).
    """
    overrides = [_override(k, v) for k, v in (set or {}).items()]
    return Model(_softarm.load_model(str(name_or_path), overrides))


def _vector(x: Any) -> Optional[np.ndarray]:
    return None if x is None else np.ascontiguousarray(x, dtype=np.float64)


class Model:
    """A loaded model: its dynamics M(q) qdd + h(q, qd, t) = 0."""

    def __init__(self, core: Any):
        self._core = core

    @property
    def name(self) -> str:
        return self._core.name

    @property
    def dof(self) -> int:
        """The number of generalised coordinates n."""
        return self._core.dof

    @property
    def coordinates(self) -> list[str]:
        """The coordinates' names, in order."""
        return list(self._core.coordinates)

    @property
    def parameters(self) -> list[str]:
        """The runtime parameters' names (values change without a rebuild)."""
        return list(self._core.parameters)

    @property
    def backend(self) -> str:
        """"compiled" or "interpreted"."""
        return self._core.backend

    def __repr__(self) -> str:
        return f"<softarm.Model {self.name!r}: {self.dof} coordinates, {self.backend}>"

    def simulator(
        self,
        dt: float,
        inputs: Sequence[str] = (),
        solver: Optional[str] = None,
        rtol: Optional[float] = None,
        atol: Optional[float] = None,
        step: Optional[float] = None,
    ) -> "Simulator":
        """A stepping simulator for closed-loop control: each ``step(u)``
        holds the input channels named in `inputs` at u and integrates dt
        seconds (`step`: a fixed-step solver's own step). It runs its own
        copy of the model."""
        core = self._core.simulator(float(dt), list(inputs), solver, rtol, atol, step)
        return Simulator(core, self.dof)

    def linearize(self, inputs: Sequence[str] = (), u0=None, q0=None) -> dict:
        """The state-space model about an equilibrium, for controller design:
        d(dx)/dt = A dx + B du, dy = C dx + D du, with x = (q, qd), u the
        input channels named in `inputs` held at `u0` (default zero), y the
        tip position. About `q0`, or else the static equilibrium under u0.
        A is the generated analytic Jacobian; B, C, D central differences.
        Also as ``softarm linearize MODEL --inputs ... --json``."""
        a, b, c, d, q, u = self._core.linearize(list(inputs), _vector(u0), _vector(q0))
        coords = self.coordinates
        return {"A": a, "B": b, "C": c, "D": d, "q0": q, "u0": u,
                "states": coords + [f"{c}_dot" for c in coords], "inputs": list(inputs),
                "outputs": ["tip_x", "tip_y", "tip_z"]}

    def jacobian(self, q, qd=None, t: float = 0.0) -> np.ndarray:
        """The right-hand side's Jacobian d(q', qd')/d(q, qd), (2n, 2n): the
        generated analytic one that the implicit solvers use."""
        return self._core.jacobian(_vector(q), _vector(qd), float(t))

    def mass_bias(self, q, qd=None, t: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
        """The mass matrix M (n, n) and bias h (n,) at (q, qd, t)."""
        return self._core.mass_bias(_vector(q), _vector(qd), float(t))

    def parameters_at(self, t) -> np.ndarray:
        """The base parameters (`parameters`' order) at each time of t,
        (len(t), len(parameters)): the model's values with its inputs
        applied, as the kernels read them (and as an exported C library or
        FMU is given them)."""
        return self._core.parameters_at(np.ascontiguousarray(t, dtype=float).ravel())

    def outputs(self, q, qd=None, t: float = 0.0) -> np.ndarray:
        """The outputs (`OUTPUT_NAMES`) at (q, qd, t)."""
        return self._core.outputs(_vector(q), _vector(qd), float(t))

    def tip(self, q, t: float = 0.0) -> np.ndarray:
        """The tip position (3,) at q."""
        return self.outputs(q, None, t)[:3]

    def static(self, q0=None) -> dict:
        """The static equilibrium under gravity, the loads and the inputs at
        t = 0, from q0 (default: the model's start): q, tip, residual,
        iterations."""
        q, residual, iterations = self._core.equilibrium(_vector(q0))
        return {"q": q, "tip": self.tip(q), "residual": residual, "iterations": iterations}

    def fit(
        self,
        free: Mapping[str, Any],
        window: Optional[Sequence[float]] = None,
        validate: Any = None,
        rtol: Optional[float] = None,
        atol: Optional[float] = None,
        max_iterations: int = 40,
    ) -> dict:
        """Fit model values to the model's [compare] record, as `softarm
        fit` does; returns fit.json's content.

        `free` maps each value's key path to its bounds ``(lo, hi)`` (either
        may be None) or to None (unbounded):
        ``{"segment.0.youngs_modulus": (5e4, 5e5), "tip.mass": None}``.
        `window` is the fit's (a, b) in seconds; `validate` another window
        (a, b) or another model file with its own record.
        """
        def spec(path: str, bounds: Any) -> str:
            if bounds is None:
                return path
            lo, hi = bounds
            return f"{path}={'' if lo is None else repr(float(lo))}:{'' if hi is None else repr(float(hi))}"

        if isinstance(validate, (tuple, list)):
            validate = f"{float(validate[0])!r}:{float(validate[1])!r}"
        text = self._core.fit(
            [spec(k, v) for k, v in free.items()],
            None if window is None else (float(window[0]), float(window[1])),
            None if validate is None else str(validate),
            rtol,
            atol,
            max_iterations,
        )
        return json.loads(text)

    def modes(self, q0=None) -> dict:
        """Natural frequencies (Hz, ascending) and mode shapes (columns)
        about the static equilibrium."""
        q = self.static(q0)["q"]
        shapes, f = self._core.modes(q)
        return {"frequencies_hz": f, "shapes": shapes, "equilibrium_q": q}

    def simulate(
        self,
        t_end: Optional[float] = None,
        solver: Optional[str] = None,
        *,
        rtol: Optional[float] = None,
        atol: Optional[float] = None,
        dt: Optional[float] = None,
        output_dt: Optional[float] = None,
        max_steps: Optional[int] = None,
        q0=None,
        qd0=None,
        start: Optional[str] = None,
        inputs: Optional[Mapping[str, Any]] = None,
        control_dt: Optional[float] = None,
        rho_inf: Optional[float] = None,
    ) -> dict:
        """Integrate as ``softarm simulate`` does. Options left out come from
        the model's ``[simulate]``, else the defaults (5 s, auto, rtol 1e-6,
        atol 1e-9, a row every t_end / 500). `rho_inf` is generalized-alpha's
        spectral radius at infinity (``--rho-inf``; 1 none, 0 the most
        numerical damping of unresolved modes); not with a callable input.

        `inputs` replaces input channels for this run, by name: a pair of
        arrays ``(t, values)`` (linear between samples, held beyond them),
        or a callable ``f(t, state) -> value`` evaluated every `control_dt`
        seconds (default: the output spacing) and held in between, a
        controller in the loop; the rows are then the control steps. An
        exception raised by a callable stops the run and propagates.

        Returns a dict of arrays: ``t`` (N,), ``q`` and ``qd`` (N, n),
        ``tip`` (N, 3), ``kinetic_energy``, ``potential_energy`` (N,),
        ``tip_orientation`` (N, 4), ``outputs`` (N, 9), ``columns`` (the
        joints' and contacts' forces by trajectory.csv's names), ``inputs``
        (every input channel's value at the rows) and ``summary``.
        Raises `IntegrationError` (with ``.report``) when the integrator
        gives up.
        """
        inputs = dict(inputs or {})
        if any(callable(f) for f in inputs.values()):
            if rho_inf is not None:
                raise ValueError("rho_inf: a run with a controller in the loop steps with the "
                                 "Simulator, which takes the solver's defaults; leave rho_inf out")
            return self._simulate_closed_loop(inputs, t_end, solver, rtol, atol, dt, output_dt,
                                              control_dt, q0, qd0)
        sampled = []
        for name, value in inputs.items():
            try:
                ts, vs = value
            except (TypeError, ValueError):
                raise ValueError(f"inputs[{name!r}]: give (t, values) arrays or a callable f(t, state)")
            ts = np.ascontiguousarray(ts, dtype=np.float64).ravel()
            vs = np.ascontiguousarray(vs, dtype=np.float64).ravel()
            sampled.append((name, ts.tolist(), vs.tolist()))
        try:
            t, x, out, summary, names, columns, channels, values = self._core.simulate(
                t_end, solver, rtol, atol, dt, output_dt, max_steps,
                _vector(q0), _vector(qd0), start, sampled, rho_inf,
            )
        except IntegrationError as e:
            message, report = e.args
            err = IntegrationError(message)
            err.report = json.loads(report)
            raise err from None
        run = self._arrays(t, x, out, json.loads(summary))
        run["columns"] = {name: columns[:, k] for k, name in enumerate(names)}
        run["inputs"] = {name: values[:, k] for k, name in enumerate(channels)}
        return run

    def _arrays(self, t, x, out, summary) -> dict:
        n = self.dof
        return {
            "t": t,
            "q": x[:, :n],
            "qd": x[:, n:],
            "tip": out[:, :3],
            "kinetic_energy": out[:, 3],
            "potential_energy": out[:, 4],
            "tip_orientation": out[:, 5:9],
            "outputs": out,
            "summary": summary,
        }

    def _simulate_closed_loop(self, inputs, t_end, solver, rtol, atol, dt, output_dt,
                              control_dt, q0, qd0) -> dict:
        names = list(inputs)
        if not all(callable(f) for f in inputs.values()):
            raise ValueError("inputs: give every channel as a callable, or none")
        t_end = 5.0 if t_end is None else float(t_end)
        step = control_dt or output_dt or t_end / 500
        sim = self.simulator(step, inputs=names, solver=solver, rtol=rtol, atol=atol, step=dt)
        if q0 is not None or qd0 is not None:
            n = self.dof
            state = sim.state
            if q0 is not None:
                state[:n] = _vector(q0)
            if qd0 is not None:
                state[n:] = _vector(qd0)
            sim.state = state
        steps = int(round(t_end / step))
        ts, xs, outs, us = [0.0], [sim.state], [sim.outputs()], []
        for _ in range(steps):
            u = np.array([float(inputs[c](sim.t, sim.state)) for c in names])
            us.append(u)
            xs.append(sim.step(u))
            ts.append(sim.t)
            outs.append(sim.outputs())
        summary = {"model": self.name, "control_dt": step, "steps": steps, "status": "ok"}
        run = self._arrays(np.array(ts), np.array(xs), np.array(outs), summary)
        run["inputs"] = {c: np.array([u[i] for u in us]) for i, c in enumerate(names)}
        return run


class Simulator:
    """Closed-loop stepping: ``state = sim.step(u)``.

    The state is (q, qd), 2n values; ``sim.state`` reads and sets it,
    ``sim.t`` is the time, ``sim.reset()`` returns to t = 0 and the start.
    Inputs hold zero until the first step.
    """

    def __init__(self, core: Any, dof: int):
        self._core = core
        self._n = dof

    @property
    def dt(self) -> float:
        return self._core.dt

    @property
    def inputs(self) -> list[str]:
        """The controlled channels, in the order of u."""
        return list(self._core.inputs)

    @property
    def t(self) -> float:
        return self._core.t

    @t.setter
    def t(self, value: float) -> None:
        self._core.t = float(value)

    @property
    def state(self) -> np.ndarray:
        return self._core.state

    @state.setter
    def state(self, x) -> None:
        self._core.state = _vector(x)

    @property
    def q(self) -> np.ndarray:
        return self.state[: self._n]

    @property
    def qd(self) -> np.ndarray:
        return self.state[self._n :]

    def outputs(self) -> np.ndarray:
        """The outputs (`OUTPUT_NAMES`) at the current state."""
        return self._core.outputs()

    @property
    def tip(self) -> np.ndarray:
        return self.outputs()[:3]

    def step(self, u=None) -> np.ndarray:
        """Hold the inputs at u for dt seconds; the new state."""
        try:
            return self._core.step(_vector(u))
        except IntegrationError as e:
            message, report = e.args
            err = IntegrationError(message)
            err.report = json.loads(report)
            raise err from None

    def reset(self, state=None) -> np.ndarray:
        """Back to t = 0 and the start state (or `state`); the state."""
        return self._core.reset(_vector(state))


from .sweeps import sweep  # noqa: E402  (after Model: the sweep's workers load models)
