"""Learnability aids: dense shaping terms (off by default, exact when on), error features."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import motiongym  # noqa: F401


def test_reach_closeness_term_decays_with_the_error():
    env = gym.make("motiongym/ExcavatorReach-v0", closeness=0.3)
    env.reset(seed=3)
    env.action_space.seed(3)
    for _ in range(5):
        _, reward, terminated, truncated, info = env.step(env.action_space.sample())
        error = info["position_error"] + info["angle_error"]
        assert info["reward_closeness"] == pytest.approx(0.3 * np.exp(-error / 0.5), rel=1e-9)
        terms = [value for key, value in info.items() if key.startswith("reward_")]
        assert reward == pytest.approx(np.sum(terms))


@pytest.mark.parametrize("env_id", ["motiongym/HarvestArmPlanar-v0", "motiongym/HarvestArm-v0"])
@pytest.mark.parametrize("weight", [0.0, 0.3])
def test_harvest_distance_term_is_weight_times_distance(env_id, weight):
    env = gym.make(env_id, distance=weight, terminate_on_collision=False)
    env.reset(seed=3)
    env.action_space.seed(3)
    for _ in range(5):
        _, reward, terminated, truncated, info = env.step(env.action_space.sample())
        expected = -weight * info["distance_to_fruit"]
        assert info["reward_distance"] == pytest.approx(expected, rel=1e-9, abs=1e-12)
        terms = [value for key, value in info.items() if key.startswith("reward_")]
        assert reward == pytest.approx(np.sum(terms))


def test_dig_cycle_approach_term_is_progress_toward_the_subgoal_from_zone_to_truck():
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
        tip = np.array(world.world.tip)
        action, _ = policy.predict(observation, deterministic=True)
        observation, reward, terminated, truncated, info = env.step(action)
        goal = world.subgoal()
        goals.append(goal)
        progress = np.linalg.norm(tip - goal) - np.linalg.norm(np.subtract(world.world.tip, goal))
        assert info["reward_approach"] == pytest.approx(0.5 * progress, rel=1e-9, abs=1e-12)
        if terminated or truncated:
            break
    assert info["is_success"]
    assert goals[0] == zone_goal
    assert goals[-1] == (truck.cx, truck.cy, truck.height + 1.0)


def test_dual_arm_advance_term_sums_to_twice_its_weight_over_a_completed_task():
    from motiongym.baselines import make_policy

    env = gym.make("motiongym/DualArmCell-v0", advance=3.0)
    policy = make_policy(
        "motiongym/DualArmCell-v0", "sequential", env.observation_space, env.action_space
    )
    observation, info = env.reset(seed=2)
    assert info["reward_advance"] == 0.0
    total, done = 0.0, False
    while not done:
        action, _ = policy.predict(observation, deterministic=True)
        observation, reward, terminated, truncated, info = env.step(action)
        assert info["reward_advance"] >= 0.0
        total += info["reward_advance"]
        done = terminated or truncated
    assert info["is_success"]
    assert total == pytest.approx(2 * 3.0, rel=1e-9)


@pytest.mark.parametrize("env_id", ["motiongym/HarvestArmPlanar-v0", "motiongym/HarvestArm-v0"])
def test_harvest_observation_holds_the_fruit_error(env_id):
    env = gym.make(env_id)
    layout = env.unwrapped.task.layout
    observation, info = env.reset(seed=4)
    for _ in range(3):
        error = layout.parse(observation)["fruit_error"]
        assert np.linalg.norm(error) == pytest.approx(info["distance_to_fruit"], rel=1e-5)
        observation, *_, info = env.step(env.action_space.sample())


def test_reach_observation_holds_the_target_error():
    from motiongym.envs.excavator.observation import layout

    env = gym.make("motiongym/ExcavatorReach-v0")
    slices = layout("reach")
    observation, info = env.reset(seed=4)
    for _ in range(3):
        error = observation[slices["target_error"]]
        target = observation[slices["target"]]
        tip, beta = observation[slices["tip"]], observation[slices["bucket"]][0]
        np.testing.assert_allclose(error[:3], target[:3] - tip, atol=1e-5)
        assert np.linalg.norm(error[:3]) == pytest.approx(info["position_error"], rel=1e-5)
        assert abs(error[3]) == pytest.approx(info["angle_error"], abs=1e-6)
        assert abs(error[3]) <= np.pi and error[3] == pytest.approx(
            np.remainder(target[3] - beta + np.pi, 2 * np.pi) - np.pi, abs=1e-5
        )
        observation, *_, info = env.step(env.action_space.sample())
