"""Each dual-arm scripted policy reaches its stated success rate in the environment."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import motiongym  # noqa: F401
from motiongym.baselines import make_policy, scripted_policies

ID = "motiongym/DualArmCell-v0"
EXPECTED = {  # success rate on sampled colliding pairs
    "boundary-following": 1.0,
    "exhaustive-delay": 1.0,
    "sequential": 1.0,
    "min-makespan": 1.0,
    "undelayed": 0.0,
}


def _run(env, policy, seed, options=None):
    obs, info = env.reset(seed=seed, options=options)
    policy.reset()
    done = False
    while not done:
        action, _ = policy.predict(obs)
        obs, _, terminated, truncated, info = env.step(action)
        done = terminated or truncated
    return info


def test_declared():
    assert set(scripted_policies(ID)) == set(EXPECTED)


@pytest.mark.parametrize("control", ["both", "robot_2"])
@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_success_rate(name, control):
    env = gym.make(ID, control=control)
    policy = make_policy(ID, name, env.observation_space, env.action_space, {"control": control})
    infos = [_run(env, policy, seed) for seed in range(4)]
    assert np.mean([i["is_success"] for i in infos]) == EXPECTED[name]


def test_makespans_ordered_on_the_paper_case():
    env = gym.make(ID)
    span = {}
    for name in ("boundary-following", "exhaustive-delay", "sequential", "min-makespan"):
        policy = make_policy(ID, name, env.observation_space, env.action_space, {})
        info = _run(env, policy, 0, {"task": "paper"})
        assert info["is_success"]
        span[name] = info["makespan"]
    assert span["boundary-following"] == span["exhaustive-delay"]
    assert span["min-makespan"] <= span["boundary-following"] < span["sequential"]


def test_batched_predict_keeps_one_plan_per_env():
    env = gym.make(ID)
    policy = make_policy(ID, "boundary-following", env.observation_space, env.action_space, {})
    a, _ = env.reset(seed=1)
    b, _ = env.reset(seed=2)
    actions, _ = policy.predict(np.stack([a, b]), episode_start=np.array([True, True]))
    assert actions.shape == (2, 2)
    assert policy.diagnostics(0)["delay"] != policy.diagnostics(1)["delay"]


def test_track_progress_replays_the_schedule_and_leads_back_onto_it():
    """``track_progress``: along the schedule's own run the same actions as the replay, bit
    for bit; with robot 2 pushed ahead of its schedule it waits (0) until robot 1 has
    moved on, and a robot 2 held back catches up at full advance (1)."""
    env_id = "motiongym/DualArmCell-v1"
    env = gym.make(env_id)

    def policy(track):
        return make_policy(
            env_id,
            "boundary-following",
            env.observation_space,
            env.action_space,
            env.spec.kwargs,
            track_progress=track,
        )

    for seed in (100_000, 100_003):
        runs = []
        for track in (False, True):
            pol, (obs, _), actions, done = policy(track), env.reset(seed=seed), [], False
            while not done:
                action, _ = pol.predict(obs)
                obs, _, terminated, truncated, _ = env.step(action)
                actions.append(action)
                done = terminated or truncated
            runs.append(np.array(actions))
        np.testing.assert_array_equal(runs[0], runs[1])
    pol = policy(True)
    obs, _ = env.reset(seed=100_000)
    pol.predict(obs)
    delay = pol.diagnostics()["delay"]
    assert delay > 10
    for _ in range(delay + 5):  # robot 2 started with robot 1: 5 samples past its delay
        obs, *_ = env.step(np.array([1.0, 1.0], np.float32))
    assert pol.predict(obs)[0][1] == 0.0  # ahead by the whole delay: wait
    obs, _ = env.reset(seed=100_000)
    pol.predict(obs, episode_start=np.array([True]))
    for _ in range(delay + 5):  # robot 2 held: 5 samples behind its schedule
        obs, *_ = env.step(np.array([1.0, 0.0], np.float32))
    assert pol.predict(obs)[0][1] == 1.0
    with pytest.raises(ValueError, match="track_progress"):
        policy("yes")
