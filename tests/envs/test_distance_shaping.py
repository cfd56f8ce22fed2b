"""The dense ``distance`` shaping term of the reaching tasks: off by default, exact when on."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import motiongym  # noqa: F401

# ID -> the info key(s) whose sum is the distance the term penalises
CASES = {
    "motiongym/ExcavatorReach-v0": ("position_error", "angle_error"),
    "motiongym/HarvestArmPlanar-v0": ("distance_to_fruit",),
    "motiongym/HarvestArm-v0": ("distance_to_fruit",),
}


@pytest.mark.parametrize("env_id", CASES)
@pytest.mark.parametrize("weight", [0.0, 0.3])
def test_distance_term_is_weight_times_distance(env_id, weight):
    kwargs = {} if weight == 0.0 else {"distance": weight}
    env = gym.make(env_id, **kwargs)
    env.reset(seed=3)
    env.action_space.seed(3)
    for _ in range(5):
        _, reward, terminated, truncated, info = env.step(env.action_space.sample())
        distance = sum(info[key] for key in CASES[env_id])
        assert distance > 0.0
        assert info["reward_distance"] == pytest.approx(-weight * distance, rel=1e-9, abs=1e-12)
        terms = [value for key, value in info.items() if key.startswith("reward_")]
        assert reward == pytest.approx(np.sum(terms))
        if terminated or truncated:
            break


def test_dig_cycle_approach_term_follows_the_subgoal_from_zone_to_truck():
    from motiongym.baselines import make_policy

    env = gym.make("motiongym/Excavator-v0", approach=0.5)
    policy = make_policy(
        "motiongym/Excavator-v0", "dig-cycle", env.observation_space, env.action_space
    )
    observation, _ = env.reset(seed=5)
    world = env.unwrapped
    zone_goal = world.subgoal()
    truck = world.scene.truck
    goals = []
    for _ in range(600):
        action, _ = policy.predict(observation, deterministic=True)
        observation, reward, terminated, truncated, info = env.step(action)
        goal = world.subgoal()
        goals.append(goal)
        distance = float(np.linalg.norm(np.subtract(world.tip, goal)))
        assert info["reward_approach"] == pytest.approx(-0.5 * distance, rel=1e-9)
        if terminated or truncated:
            break
    assert info["is_success"]
    assert goals[0] == zone_goal
    assert goals[-1] == (truck.cx, truck.cy, truck.height + 1.0)
