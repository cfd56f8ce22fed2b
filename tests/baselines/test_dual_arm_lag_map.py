"""The lag map (baselines/dual_arm/lag_map.py) and the re-planning boundary-following
teacher, checked against the environment itself: pure delays run in the environment."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
from dual_arm_runs import run_pure_delay

from motiongym.baselines import make_policy
from motiongym.baselines.dual_arm.lag_map import LagMap
from motiongym.envs.dual_arm.world import OBS, tasks_from_observation

V0, V1 = "motiongym/DualArmCell-v0", "motiongym/DualArmCell-v1"


@pytest.mark.parametrize("env_id", [V0, V1])
def test_first_clear_go_is_the_environments_minimum_delay(env_id):
    """Waiting at the start, the first step whose "go now" row is clear is a delay the
    environment runs without collision, and one step earlier collides (scenes 100000-100002,
    v0's check at the samples and v1's over the motion)."""
    env = gym.make(env_id)
    params = env.unwrapped.params
    for seed in (100000, 100001, 100002):
        obs, _ = env.reset(seed=seed)
        lag_map = LagMap(
            *tasks_from_observation(obs), params.safety_margin, params.collision_check == "swept"
        )
        first = next(x for x in range(lag_map.n1 + 1) if lag_map.clear_now(x, 0.0))
        assert first > 0  # "colliding" pairs: starting together collides
        assert run_pure_delay(env, seed, first), (env_id, seed, first)
        assert not run_pure_delay(env, seed, first - 1), (env_id, seed, first)


def test_window_rows_are_the_further_waits():
    """Row ``j`` of the window is "wait lags[j], then go": at the start, row 0 of the window
    at step ``x`` equals row ``w`` at step ``x - w`` (the same pure delay), bin by bin; each
    row's last entry is its first colliding step over the horizon."""
    env = gym.make(V1)
    obs, _ = env.reset(seed=100003)
    lag_map = LagMap(*tasks_from_observation(obs), 0.0, True)
    lags = [0, 5, 12]
    later = lag_map.window(12, 0.0, [0], 1, 300)
    earlier = lag_map.window(0, 0.0, lags, 1, 312)
    assert earlier.shape == (3, 313)
    assert np.array_equal(earlier[2, 12:312], later[0, :300])
    assert earlier[2, :12].sum() == lag_map.table[:12, 0].sum()  # waiting at the start
    for row in earlier:
        hits = np.flatnonzero(row[:312])
        assert row[312] == np.float32(hits[0] / 312 if len(hits) else 1.0)


@pytest.mark.parametrize("seed", [100000, 100065])
def test_replanning_teacher_acts_as_the_planned_delay_on_v1(seed):
    """On v1, where boundary following's delay is exact, the re-planning teacher's actions
    along its own episode are the planned schedule's, step for step until robot 2 is done
    (after that the advance moves nothing)."""
    env = gym.make(V1)
    kwargs = dict(env.spec.kwargs)
    plain = make_policy(V1, "boundary-following", env.observation_space, env.action_space, kwargs)
    replan = make_policy(
        V1, "boundary-following", env.observation_space, env.action_space, kwargs, replan=True
    )
    obs, _ = env.reset(seed=seed)
    start, done = np.array([True]), False
    while not done:
        a, _ = plain.predict(obs, episode_start=start)
        b, _ = replan.predict(obs, episode_start=start)
        if obs[OBS["progress"]][1] < 1.0:
            assert np.array_equal(a, b)
        obs, _, terminated, truncated, info = env.step(a)
        start, done = np.array([False]), terminated or truncated
    assert info["is_success"]


@pytest.mark.parametrize("bad", ["yes", 1, None])
def test_replan_must_be_a_bool(bad):
    env = gym.make(V1)
    with pytest.raises(ValueError, match="replan"):
        make_policy(
            V1,
            "boundary-following",
            env.observation_space,
            env.action_space,
            dict(env.spec.kwargs),
            replan=bad,
        )
