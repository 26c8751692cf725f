"""The Gymnasium environments: they pass Gymnasium's own checker, are
reproducible from a seed, and their reward is the distance their
observation shows."""

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import softarm
import softarm.envs
from softarm.envs import SoftArmEnv

IDS = ["softarm/Reach-v0", "softarm/Track-v0"]


@pytest.mark.parametrize("env_id", IDS)
def test_gymnasiums_checker_passes(env_id):
    check_env(gym.make(env_id).unwrapped, skip_render_check=True)


@pytest.mark.parametrize("env_id", IDS)
def test_a_seed_reproduces_an_episode(env_id):
    runs = []
    for _ in range(2):
        env = gym.make(env_id)
        obs, info = env.reset(seed=7)
        env.action_space.seed(7)
        trace = [obs]
        for _ in range(5):
            obs, reward, term, trunc, info = env.step(env.action_space.sample())
            trace.append(obs)
        runs.append(np.array(trace))
        targets = env.unwrapped.target_at(10)
    assert np.array_equal(runs[0], runs[1])
    env = gym.make(env_id)
    env.reset(seed=8)
    assert not np.array_equal(env.unwrapped.target_at(10), targets), "another seed, another target"


@pytest.mark.parametrize("env_id", IDS)
def test_the_reward_is_the_observed_tip_distance(env_id):
    env = gym.make(env_id)
    obs, _ = env.reset(seed=1)
    n = env.unwrapped.model.dof
    for _ in range(3):
        obs, reward, term, trunc, info = env.step(env.action_space.sample())
        tip, target = obs[2 * n : 2 * n + 3], obs[2 * n + 3 :]
        assert reward == pytest.approx(-np.linalg.norm(tip - target), rel=1e-12)
        # The observed tip is the model's at the observed state.
        assert np.allclose(tip, env.unwrapped.model.tip(obs[:n], env.unwrapped.sim.t), rtol=0, atol=1e-15)


def test_any_model_wraps_by_naming_its_inputs():
    env = SoftArmEnv(model="finger_free", inputs=["pressure"], low=[0.0], high=[5e4],
                     control_dt=0.02, max_steps=3, settle_steps=2)
    obs, _ = env.reset(seed=0)
    assert obs.shape == (2 * env.model.dof + 6,)
    *_, truncated, _ = env.step([1e4])
    *_, truncated, _ = env.step([1e4])
    *_, truncated, _ = env.step([1e4])
    assert truncated
    with pytest.raises(ValueError, match="no channel"):
        SoftArmEnv(model="finger_free", inputs=["valve"], low=[0.0], high=[1.0])


def test_a_step_that_cannot_be_integrated_ends_its_episode():
    """An action the arm cannot follow (a pressure of 1e15 Pa) ends the
    episode truncated, with the reason and the count in `info`; the state
    is the step's start, and the next episode starts as the first."""
    # rk4's fixed steps leave the finite numbers within a step or two.
    env = SoftArmEnv(model="finger_free", inputs=["pressure"], low=[0.0], high=[1e15],
                     control_dt=0.02, max_steps=5, settle_steps=0, solver="rk4")
    first, _ = env.reset(seed=0)
    obs, reward, terminated, truncated, info = env.step([1e15])
    assert truncated and not terminated
    assert "integration_failed" in info and info["integration_failures"] == 1
    assert np.array_equal(obs, first) and np.isfinite(reward)
    again, _ = env.reset(seed=0)
    assert np.array_equal(again, first)


@pytest.mark.parametrize("env_id", IDS)
def test_random_actions_never_raise(env_id):
    """2000 seeded random steps, a new episode whenever one ends: no
    exception (a step that cannot be integrated ends its episode)."""
    env = gym.make(env_id)
    env.reset(seed=1)
    env.action_space.seed(1)
    for _ in range(2000):
        *_, terminated, truncated, _ = env.step(env.action_space.sample())
        if terminated or truncated:
            env.reset()
