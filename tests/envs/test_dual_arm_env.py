"""DualArmCell-v0 and the PettingZoo parallel env: API, reward, determinism, errors."""

from __future__ import annotations

import os

os.environ.setdefault("MUJOCO_GL", "egl")

import pickle
import subprocess
import sys

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env
from pettingzoo.test import parallel_api_test, parallel_seed_test
from stable_baselines3.common.env_checker import check_env as sb3_check_env

import motiongym  # noqa: F401
from motiongym.envs.checks import MotiongymDeprecationWarning
from motiongym.envs.dual_arm import parallel_env
from motiongym.envs.dual_arm.task import LAYOUT, tasks_from_observation

ID = "motiongym/DualArmCell-v0"


@pytest.mark.parametrize("control", ["both", "robot_2"])
def test_api_checks(control):
    env = gym.make(ID, control=control)
    check_env(env.unwrapped, skip_render_check=True)
    sb3_check_env(env.unwrapped, warn=False)
    assert env.action_space.shape == ((2,) if control == "both" else (1,))


def test_reward_terms_sum_and_info():
    env = gym.make(ID)
    obs, info = env.reset(seed=1)
    for key in ("is_success", "cost", "distance", "makespan", "collision"):
        assert key in info
    rng = np.random.default_rng(0)
    for _ in range(300):
        obs, reward, terminated, truncated, info = env.step(rng.uniform(0, 1, 2))
        terms = sum(v for k, v in info.items() if k.startswith("reward_"))
        assert reward == pytest.approx(terms)
        assert env.observation_space.contains(obs)
        if terminated:
            assert info["collision"] or info["is_success"]
            assert info["cost"] == float(info["collision"])
            break
    measures = env.unwrapped.metadata["info_measures"]
    assert set(measures) <= set(info)


def test_determinism_and_tasks_in_observation():
    env = gym.make(ID)
    a, _ = env.reset(seed=7)
    b, _ = env.reset(seed=7)
    np.testing.assert_array_equal(a, b)
    c, _ = env.reset(seed=8)
    assert not np.array_equal(a, c)
    t1, t2 = tasks_from_observation(a)
    np.testing.assert_allclose(a[LAYOUT["q1"]], t1.samples()[0], atol=1e-6)
    np.testing.assert_allclose(a[LAYOUT["q2"]], t2.samples()[0], atol=1e-6)


def test_nominal_progress_follows_the_trajectory():
    env = gym.make(ID, pairs="paper")
    obs, _ = env.reset(seed=0)
    t1, t2 = tasks_from_observation(obs)
    for _ in range(10):
        obs, *_ = env.step(np.array([1.0, 0.0]))
    np.testing.assert_allclose(obs[LAYOUT["q1"]], t1.samples()[10], atol=1e-6)
    np.testing.assert_allclose(obs[LAYOUT["q2"]], t2.samples()[0], atol=1e-6)
    obs, *_ = env.step(np.array([0.5, 0.5]))  # halfway between samples
    np.testing.assert_allclose(
        obs[LAYOUT["q1"]], (t1.samples()[10] + t1.samples()[11]) / 2, atol=1e-6
    )


def test_undelayed_paper_case_collides_and_terminates():
    env = gym.make(ID, pairs="paper")
    env.reset(seed=0)
    for _ in range(200):
        _, reward, terminated, _, info = env.step(np.ones(2))
        if terminated:
            break
    assert info["collision"] and info["cost"] == 1.0 and not info["is_success"]
    assert 0.6 <= info["makespan"] <= 0.8  # first contact of the paper case at 0.72 s
    assert info["reward_collision"] == -10.0


def test_bad_input():
    env = gym.make(ID)
    env.reset(seed=0)
    with pytest.raises(ValueError, match="shape"):
        env.step(np.zeros(3))
    with pytest.raises(ValueError, match="NaN"):
        env.step(np.array([np.nan, 0.0]))
    with pytest.raises(ValueError, match=r"unknown reset option\(s\) \['speed'\]; valid: pairs"):
        env.reset(options={"speed": 2})
    with pytest.raises(ValueError, match="colliding"):
        env.reset(options={"pairs": "nope"})
    with pytest.raises(ValueError, match="robot_2"):
        gym.make(ID, control="robot_3")
    with pytest.raises(ValueError, match="unknown keyword argument\\(s\\) speed"):
        gym.make(ID, speed=2.0)
    with pytest.raises(ValueError, match="advance is paid"):
        gym.make(ID, advance=-1.0)
    with pytest.raises(ValueError, match="give time=1.0 for the same reward"):
        gym.make(ID, time=-1.0)
    with pytest.raises(ValueError, match="render_size"):
        gym.make(ID, render_size=(8, 8))


def test_task_is_the_deprecated_name_of_pairs():
    """``task`` (keyword and reset option) still works for one release, warns once, and
    means ``pairs``; giving both is an error."""
    from motiongym.envs.checks import _warned

    _warned.discard(("DualArmParams", "task"))
    _warned.discard(("reset option", "task"))
    with pytest.warns(MotiongymDeprecationWarning, match="'task' is deprecated.*'pairs'"):
        old = gym.make(ID, task="paper")
    assert old.unwrapped.params.pairs == "paper"
    new = gym.make(ID, pairs="paper")
    np.testing.assert_array_equal(old.reset(seed=0)[0], new.reset(seed=0)[0])
    with pytest.warns(MotiongymDeprecationWarning, match="reset option: 'task'"):
        a, _ = new.reset(seed=5, options={"task": "any"})
    b, _ = new.reset(seed=5, options={"pairs": "any"})
    np.testing.assert_array_equal(a, b)
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error", MotiongymDeprecationWarning)  # warned once: no second
        gym.make(ID, task="paper")
        new.reset(seed=5, options={"task": "any"})
    with pytest.raises(ValueError, match="not both"):
        gym.make(ID, task="paper", pairs="any")


def test_pickle_mid_episode():
    env = gym.make(ID)
    env.reset(seed=3)
    for _ in range(5):
        env.step(np.array([1.0, 0.3]))
    clone = pickle.loads(pickle.dumps(env))
    a = env.step(np.array([0.7, 0.7]))
    b = clone.step(np.array([0.7, 0.7]))
    np.testing.assert_array_equal(a[0], b[0])
    assert a[1] == b[1]


_RENDER = """
import gymnasium as gym, numpy as np, motiongym
env = gym.make("motiongym/DualArmCell-v0", render_mode="rgb_array")
env.reset(seed=0)
frame = env.render()
print(frame.shape, frame.dtype, float(frame.std()))
env.close()
"""


def test_render_rgb_array():
    # In a fresh process: the GL backend is fixed when mujoco is first imported.
    out = subprocess.run(
        [sys.executable, "-c", _RENDER],
        env={**os.environ, "MUJOCO_GL": "egl"},
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert out.returncode == 0, out.stderr
    dtype, std = out.stdout.split()[-2:]
    assert "(480, 640, 3)" in out.stdout and dtype == "uint8" and float(std) > 5


def test_pettingzoo_parallel_env():
    parallel_api_test(parallel_env(), num_cycles=200)
    parallel_seed_test(lambda: parallel_env())
    env = parallel_env(pairs="paper")
    obs, infos = env.reset(seed=0)
    assert set(obs) == {"robot_1", "robot_2"}
    steps = 0
    while env.agents:
        _, rewards, terms, truncs, infos = env.step({"robot_1": np.ones(1), "robot_2": np.zeros(1)})
        assert rewards["robot_1"] == rewards["robot_2"]
        steps += 1
    # robot 2 never moves: robot 1 finishes alone, but robot 2 is not done: truncated
    assert truncs["robot_1"] and steps == 1000


def test_pettingzoo_state_test_passes():
    from pettingzoo.test import state_test
    from pettingzoo.utils.conversions import parallel_to_aec

    from motiongym.envs.dual_arm import parallel_env

    state_test(parallel_to_aec(parallel_env()), parallel_env())


def test_v1_colliding_pairs_run_one_after_the_other_without_contact_in_motion():
    # seed 50167: clear one after the other at the samples, not in motion (robot 2's
    # path grazes robot 1's end between two samples); v1's sampler draws on past it
    from motiongym.envs.dual_arm import task

    rng = np.random.default_rng(50167)
    t1, t2 = task.sample_pair(rng, "colliding")
    assert task.sequential_clear(t1, t2) and not task.sequential_clear_in_motion(t1, t2)
    u1, u2 = task.sample_pair(np.random.default_rng(50167), "colliding", check="swept")
    assert task.sequential_clear_in_motion(u1, u2)
    assert u1.duration != t1.duration or not np.array_equal(u1.vias, t1.vias)


@pytest.mark.parametrize("env_id", [ID, "motiongym/DualArmCell-v1"])
def test_the_world_and_the_planners_share_one_collision_rule(env_id):
    """The environment's verdict on a schedule (robot 2 undelayed, then started when
    robot 1 ends) is :func:`collision.schedule_collides` on the environment's check;
    a check given as anything but its name is refused, naming ``check``."""
    from motiongym.baselines.dual_arm.lag_map import LagMap
    from motiongym.envs.dual_arm import collision, task

    env = gym.make(env_id, control="robot_2", pairs="paper").unwrapped
    check = env.params.collision_check
    t1, t2 = task.paper_case()
    for delay in (0, t1.n_samples):
        advances = np.zeros(delay + t2.n_samples, dtype=np.int64)
        advances[delay:] = 1
        env.reset(seed=0)
        collided = False
        for a2 in advances:
            _, _, terminated, _, info = env.step(np.array([float(a2)], np.float32))
            collided |= info["collision"]
            if terminated:
                break
        assert collided == collision.schedule_collides(check, t1, t2, advances)
        assert collided == (delay == 0)
    with pytest.raises(ValueError, match="check must be one of 'samples', 'swept', got True"):
        LagMap(t1, t2, 0.0, True)


def test_obs_is_the_deprecated_name_of_the_layout():
    """``world.OBS`` / ``world.OBS_SIZE`` (the old dict of slices) still read, warning once."""
    from motiongym.envs.checks import _warned
    from motiongym.envs.dual_arm import world

    _warned.discard(("motiongym.envs.dual_arm.world", "OBS"))
    _warned.discard(("motiongym.envs.dual_arm.world", "OBS_SIZE"))
    with pytest.warns(MotiongymDeprecationWarning, match="'OBS' is deprecated.*LAYOUT"):
        assert world.OBS == LAYOUT.slices
    assert world.OBS["progress"] == slice(12, 14)
    with pytest.warns(MotiongymDeprecationWarning, match="'OBS_SIZE' is deprecated.*LAYOUT"):
        assert world.OBS_SIZE == LAYOUT.size == 94


def test_parallel_env_refuses_bad_options_and_unknown_agents():
    from motiongym.envs.dual_arm import parallel_env

    env = parallel_env()
    with pytest.raises(ValueError, match="options must be a dict or None, got 'x'"):
        env.reset(options="x")
    for ask in (env.observation_space, env.action_space):
        with pytest.raises(
            ValueError, match=r"agent must be one of \['robot_1', 'robot_2'\], got 'robot_3'"
        ):
            ask("robot_3")
    env.close()
