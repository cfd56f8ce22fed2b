"""Each dual-arm scripted policy reaches its stated success rate in the environment."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
from dual_arm_runs import run_policy

import motiongym  # noqa: F401
from motiongym.baselines import make_policy, scripted_policies

ID = "motiongym/DualArmCell-v0"
EXPECTED = {  # success rate on sampled colliding pairs
    "boundary-following": 1.0,
    "exhaustive-delay": 1.0,
    "sequential": 1.0,
    "min-makespan": 1.0,
    "undelayed": 0.0,
    "either-waits": 1.0,
}


def test_declared():
    assert set(scripted_policies(ID)) == set(EXPECTED)


@pytest.mark.parametrize("control", ["both", "robot_2"])
@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_success_rate(name, control):
    env = gym.make(ID, control=control)
    if name == "either-waits" and control == "robot_2":
        pytest.skip("test_either_waits_needs_both_arms_and_no_map_settings")
    policy = make_policy(ID, name, env.observation_space, env.action_space, {"control": control})
    infos = [run_policy(env, policy, seed) for seed in range(4)]
    assert np.mean([i["is_success"] for i in infos]) == EXPECTED[name]


def test_either_waits_needs_both_arms_and_no_map_settings():
    """Under control="robot_2" robot 1 cannot yield; and either-waits plans on no map, so a
    map policy's setting is an error naming it, not silently ignored."""
    env = gym.make(ID, control="robot_2")
    with pytest.raises(ValueError, match="control='both'"):
        make_policy(
            ID, "either-waits", env.observation_space, env.action_space, {"control": "robot_2"}
        )
    env = gym.make(ID)
    for setting in ({"plan_margin": 0.01}, {"n_levels": 50}, {"verify": False}):
        with pytest.raises(TypeError, match=next(iter(setting))):
            make_policy(ID, "either-waits", env.observation_space, env.action_space, {}, **setting)


def test_makespans_ordered_on_the_paper_case():
    env = gym.make(ID)
    span = {}
    for name in ("boundary-following", "exhaustive-delay", "sequential", "min-makespan"):
        policy = make_policy(ID, name, env.observation_space, env.action_space, {})
        info = run_policy(env, policy, 0, {"pairs": "paper"})
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
