"""Every registered ID: API conformance, conventions, determinism, pickling, spawning.

These run over ``ENV_IDS``, so a new environment is checked as soon as it is
registered.
"""

from __future__ import annotations

import pickle
import subprocess
import sys

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env as gym_check_env
from stable_baselines3.common.env_checker import check_env as sb3_check_env
from stable_baselines3.common.env_util import make_vec_env
from stable_baselines3.common.vec_env import SubprocVecEnv

from motiongym.agents.evaluation.episodes import AGGREGATIONS, info_measures
from motiongym.envs import ENV_IDS

STEPS = 40


def _rollout(env: gym.Env, seed: int, steps: int = STEPS):
    """Observations, rewards and infos of ``steps`` seeded random actions."""
    observation, info = env.reset(seed=seed)
    env.action_space.seed(seed)
    trace = [(observation, 0.0, info)]
    for _ in range(steps):
        observation, reward, terminated, truncated, info = env.step(env.action_space.sample())
        trace.append((observation, reward, info))
        if terminated or truncated:
            break
    return trace


def _assert_same(a, b):
    if isinstance(a, dict):
        assert a.keys() == b.keys()
        for key in a:
            _assert_same(a[key], b[key])
    elif isinstance(a, tuple | list):
        assert len(a) == len(b)
        for x, y in zip(a, b, strict=True):
            _assert_same(x, y)
    else:
        np.testing.assert_array_equal(np.asarray(a), np.asarray(b))


def test_at_least_one_environment_is_registered():
    assert "motiongym/Sweeper-v0" in ENV_IDS
    assert all(env_id.startswith("motiongym/") for env_id in ENV_IDS)


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_gymnasium_and_sb3_checkers(env_id):
    env = gym.make(env_id)
    gym_check_env(env.unwrapped, skip_render_check=True)
    made = gym.make(env_id)
    # SB3's checker calls compute_reward on the env it is given; Gymnasium 1's
    # wrappers no longer forward attributes, so a GoalEnv is checked unwrapped.
    sb3_check_env(made.unwrapped if hasattr(made.unwrapped, "compute_reward") else made, warn=True)


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_same_seed_same_episode_other_seed_other_scenario(env_id):
    first = _rollout(gym.make(env_id), seed=3)
    second = _rollout(gym.make(env_id), seed=3)
    assert len(first) == len(second)
    for a, b in zip(first, second, strict=True):
        _assert_same(a, b)
    other = gym.make(env_id).reset(seed=4)[0]
    with pytest.raises(AssertionError):
        _assert_same(first[0][0], other)


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_info_conventions_and_reward_terms_sum_to_reward(env_id):
    env = gym.make(env_id)
    measures = info_measures(env)
    assert {"is_success", "cost"} <= set(measures)
    assert set(measures.values()) <= set(AGGREGATIONS)
    for _, reward, info in _rollout(env, seed=0)[1:]:
        assert set(measures) <= set(info)
        assert info["cost"] in (0.0, 1.0)
        terms = [value for key, value in info.items() if key.startswith("reward_")]
        assert terms, "reward terms are reported as info['reward_<term>']"
        assert sum(terms) == pytest.approx(reward, abs=1e-6)


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_bad_actions_are_rejected_with_a_message(env_id):
    env = gym.make(env_id)
    env.reset(seed=0)
    space = env.action_space
    if isinstance(space, gym.spaces.Box):
        with pytest.raises(ValueError, match="(?i)nan|finite"):
            env.step(np.full(space.shape, np.nan, dtype=space.dtype))
        with pytest.raises(ValueError, match="(?i)shape"):
            env.step(np.zeros(space.shape[0] + 1, dtype=space.dtype))
    elif isinstance(space, gym.spaces.Discrete):
        with pytest.raises(ValueError, match="(?i)action"):
            env.step(space.n + 3)


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_unwrapped_step_before_reset_is_a_clear_error(env_id):
    env = gym.make(env_id).unwrapped  # without Gymnasium's OrderEnforcing
    with pytest.raises(RuntimeError, match=r"call reset\(\) before step\(\)"):
        env.step(env.action_space.sample())
    env.close()


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_pickled_environment_continues_identically(env_id):
    env = gym.make(env_id)
    env.reset(seed=1)
    env.action_space.seed(1)
    actions = [env.action_space.sample() for _ in range(10)]
    env.step(actions[0])
    clone = pickle.loads(pickle.dumps(env))
    for action in actions[1:]:
        a, b = env.step(action), clone.step(action)
        _assert_same(a[0], b[0])
        assert a[1] == b[1]


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_runs_in_spawned_subprocesses(env_id):
    # A spawned process has not imported motiongym: the "module:ID" form imports it.
    # Gymnasium's AsyncVectorEnv: its workers import gymnasium and motiongym only.
    venv = gym.make_vec(
        f"motiongym:{env_id}",
        num_envs=2,
        vectorization_mode="async",
        vector_kwargs={"context": "spawn"},
    )
    venv.reset(seed=0)
    for _ in range(5):
        venv.step(venv.action_space.sample())
    venv.close()


def test_runs_in_sb3_spawned_subprocesses():
    # SB3's SubprocVecEnv (each worker imports SB3 and torch): one ID stands for all, the
    # spawning itself is checked for every ID above.
    venv = make_vec_env(
        "motiongym:motiongym/DualArmCell-v1",
        n_envs=2,
        seed=0,
        vec_env_cls=SubprocVecEnv,
        vec_env_kwargs={"start_method": "spawn"},
    )
    venv.reset()
    for _ in range(5):
        venv.step(np.stack([venv.action_space.sample() for _ in range(2)]))
    venv.close()


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_rgb_rendering(env_id):
    env = gym.make(env_id, render_mode="rgb_array")
    env.reset(seed=0)
    frame = env.render()
    assert frame.ndim == 3 and frame.shape[2] == 3 and frame.dtype == np.uint8
    assert frame.std() > 0
    env.close()


def test_make_by_string_registers_without_import():
    code = (
        "import gymnasium as gym, sys; "
        f"ids = {list(ENV_IDS)!r}; "
        "[gym.make('motiongym:' + i) for i in ids]; "
        "assert 'motiongym' in sys.modules; print('ok')"
    )
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "ok"
