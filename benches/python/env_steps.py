"""Environment steps per second of the softarm Gymnasium environments (BENCHMARKS.md):
the best of three 200-step episodes of random actions, after a reset; and a reset.

    pip install ./python gymnasium && python benches/python/env_steps.py
"""
import time, sys, numpy as np, gymnasium as gym
import softarm.envs
for name in ['softarm/Reach-v0', 'softarm/Track-v0']:
    env = gym.make(name).unwrapped
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
    print(f"{name}: {best:.0f} steps/s (control step {env.sim.dt} s), reset {r*1e3:.1f} ms")
