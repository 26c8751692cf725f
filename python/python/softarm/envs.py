"""Gymnasium environments on softarm models.

    import gymnasium as gym
    import softarm.envs  # registers the environments
    env = gym.make("softarm/Reach-v0")

* ``softarm/Reach-v0``: the STIFF-FLOP module (``stiff_flop``): the three
  chamber-pair pressures (Pa, up to the 1.1 bar of its recorded
  experiment) are the action, the observation is
  (q, qd, tip, target), the reward the negative tip distance to a target
  drawn at reset among tips the module reaches.
* ``softarm/Track-v0``: the pneumatic soft finger (``finger_free``): its
  chamber pressure is the action; the tip follows a target moving on the
  arc the finger sweeps (a sine in pressure, unknown to the agent).

`SoftArmEnv` wraps any bundled or user model by naming its input
channels. Each step holds the action over `control_dt` seconds on
softarm's compiled dynamics (`Model.simulator`). A step whose integration
cannot go on ends its episode (`truncated`, the reason in
``info["integration_failed"]``, the count in `integration_failures`)
instead of raising: an agent may try any action in the space.
"""

from __future__ import annotations

from typing import Any, Optional, Sequence

import gymnasium as gym
import numpy as np
from gymnasium import spaces

import softarm


class SoftArmEnv(gym.Env):
    """A softarm model as a Gymnasium environment.

    Parameters: `model` (a bundled name or a model file) with `set`
    overrides; `inputs`, the channels the action drives, with their bounds
    `low` and `high`; `control_dt` (s) per step; `max_steps` per episode;
    `solver` and tolerances of the integration. Targets: at reset, the tip
    reached by holding a random action (drawn from the env's generator) for
    `settle_steps` steps from the start, so every target is reachable.
    """

    metadata = {"render_modes": []}

    def __init__(
        self,
        model: str,
        inputs: Sequence[str],
        low: Sequence[float],
        high: Sequence[float],
        control_dt: float = 0.01,
        max_steps: int = 200,
        settle_steps: int = 50,
        set: Optional[dict] = None,
        solver: Optional[str] = None,
        rtol: Optional[float] = None,
        atol: Optional[float] = None,
    ):
        self.model = softarm.load(model, set=set)
        self.sim = self.model.simulator(control_dt, inputs=list(inputs), solver=solver,
                                        rtol=rtol, atol=atol)
        n = self.model.dof
        self.action_space = spaces.Box(np.asarray(low, np.float64), np.asarray(high, np.float64),
                                       dtype=np.float64)
        self.observation_space = spaces.Box(-np.inf, np.inf, shape=(2 * n + 6,), dtype=np.float64)
        self.max_steps = int(max_steps)
        self.settle_steps = int(settle_steps)
        self.target = np.zeros(3)
        self._steps = 0
        # Steps whose integration could not go on (each ended its episode).
        self.integration_failures = 0

    def _observation(self) -> np.ndarray:
        return np.concatenate([self.sim.state, self.sim.tip, self.target])

    def _draw_target(self) -> np.ndarray:
        """A tip the arm reaches: hold a random action from the start
        (another one where the integration of one cannot go on)."""
        for _ in range(10):
            a = self.np_random.uniform(self.action_space.low, self.action_space.high)
            self.sim.reset()
            try:
                for _ in range(self.settle_steps):
                    self.sim.step(a)
                return self.sim.tip.copy()
            except softarm.IntegrationError:
                self.integration_failures += 1
        self.sim.reset()
        return self.sim.tip.copy()

    def target_at(self, step: int) -> np.ndarray:
        """The target at a step of the episode (fixed here)."""
        return self.target

    def reset(self, *, seed: Optional[int] = None, options: Optional[dict] = None):
        super().reset(seed=seed)
        self.target = self._draw_target()
        self.sim.reset()
        self._steps = 0
        return self._observation(), {"target": self.target.copy()}

    def step(self, action):
        a = np.clip(np.asarray(action, dtype=np.float64), self.action_space.low,
                    self.action_space.high)
        try:
            self.sim.step(a)
        except softarm.IntegrationError as e:
            # The episode ends where the integration cannot go on (the state
            # stays the step's start); the reason is in `info`.
            self.integration_failures += 1
            distance = float(np.linalg.norm(self.sim.tip - self.target))
            return self._observation(), -distance, False, True, {
                "distance": distance, "integration_failed": str(e),
                "integration_failures": self.integration_failures}
        self._steps += 1
        self.target = self.target_at(self._steps)
        distance = float(np.linalg.norm(self.sim.tip - self.target))
        truncated = self._steps >= self.max_steps
        return self._observation(), -distance, False, truncated, {"distance": distance}


class TrackEnv(SoftArmEnv):
    """The tip follows a target that moves as the tip would under a sine
    in the input: reachable at every step, its motion not observed."""

    def __init__(self, period: float = 1.0, **kwargs: Any):
        super().__init__(**kwargs)
        self.period = float(period)
        self._path: list[np.ndarray] = []

    def reset(self, *, seed: Optional[int] = None, options: Optional[dict] = None):
        gym.Env.reset(self, seed=seed)
        low, high = self.action_space.low, self.action_space.high
        phase = self.np_random.uniform(0.0, 2.0 * np.pi)
        self.sim.reset()
        self._path = [self.sim.tip.copy()]
        for k in range(1, self.max_steps + 1):
            s = 0.5 + 0.5 * np.sin(2.0 * np.pi * k * self.sim.dt / self.period + phase)
            self.sim.step(low + s * (high - low))
            self._path.append(self.sim.tip.copy())
        self.sim.reset()
        self._steps = 0
        self.target = self._path[0]
        return self._observation(), {"target": self.target.copy()}

    def target_at(self, step: int) -> np.ndarray:
        return self._path[min(step, len(self._path) - 1)]


def _register() -> None:
    gym.register(
        id="softarm/Reach-v0",
        entry_point=SoftArmEnv,
        # bs23 at rtol 1e-3: the tip within 2 um of an rtol 1e-6 run over
        # 200 random steps, five times faster (BENCHMARKS.md).
        kwargs=dict(model="stiff_flop", inputs=["p0", "p1", "p2"], low=[0.0] * 3,
                    high=[1.1e5] * 3, control_dt=0.01, max_steps=200, solver="bs23",
                    rtol=1e-3, atol=1e-6),
    )
    gym.register(
        id="softarm/Track-v0",
        entry_point=TrackEnv,
        # Pressed, the finger is stiff: an L-stable implicit method.
        kwargs=dict(model="finger_free", inputs=["pressure"], low=[0.0], high=[1.5e5],
                    control_dt=0.01, max_steps=100, solver="trbdf2", rtol=1e-3, atol=1e-6),
    )


if "softarm/Reach-v0" not in gym.registry:
    _register()
