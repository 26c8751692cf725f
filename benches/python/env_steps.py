"""Environment steps per second of the softarm Gymnasium environments (BENCHMARKS.md):
the best of three 200-step episodes of random actions, after a reset; and a reset.
Then a model no build has seen (benches/tapered_tentacle.toml, on the linked
cells) as an environment of its three chamber pressures at 20 ms control steps.

    pip install ./python gymnasium && python benches/python/env_steps.py
"""
import time, sys, numpy as np, gymnasium as gym
from pathlib import Path
import softarm.envs
tentacle = str(Path(__file__).resolve().parents[1] / "tapered_tentacle.toml")
envs = [(name, lambda name=name: gym.make(name).unwrapped)
        for name in ['softarm/Reach-v0', 'softarm/Track-v0']]
envs.append(("tapered_tentacle (20 ms)", lambda: softarm.envs.SoftArmEnv(
    tentacle, inputs=["pa", "pb", "pc"], low=[0, 0, 0], high=[3e4, 3e4, 3e4],
    control_dt=0.02, settle_steps=5)))
for name, make in envs:
    env = make()
    env.reset(seed=0); env.action_space.seed(0)
    acts = [env.action_space.sample() for _ in range(env.max_steps)]
    best = 0
    for rep in range(3):
        env.reset(seed=rep)
        t = time.perf_counter()
        for a in acts:
            env.step(a)
        best = max(best, len(acts) / (time.perf_counter() - t))
    t = time.perf_counter(); env.reset(seed=9); r = time.perf_counter() - t
    print(f"{name}: {best:.0f} steps/s (control step {env.sim.dt} s, {env.model.backend}), reset {r*1e3:.1f} ms")
