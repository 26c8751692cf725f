#!/usr/bin/env python3
"""100,000 seeded random steps of an environment, a new episode whenever one
ends: steps a second, episodes, and steps that ended an episode because the
integration could not go on."""
import sys, time
import gymnasium as gym
import softarm.envs  # noqa: F401

env_id, steps = sys.argv[1], int(sys.argv[2])
env = gym.make(env_id)
env.reset(seed=1)
env.action_space.seed(1)
episodes, start = 1, time.perf_counter()
for _ in range(steps):
    *_, terminated, truncated, _ = env.step(env.action_space.sample())
    if terminated or truncated:
        env.reset()
        episodes += 1
wall = time.perf_counter() - start
print(f"{env_id}: {steps} steps in {wall:.1f} s ({steps / wall:.0f} a second, resets included), "
      f"{episodes} episodes, {env.unwrapped.integration_failures} integration failures")
