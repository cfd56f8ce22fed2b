"""docs/adding_a_world.md, checked: a toy world added with one call works everywhere."""

from __future__ import annotations

import gymnasium as gym
import pytest
from gymnasium.utils.env_checker import check_env

from motiongym import systems
from motiongym.agents.evaluation.episodes import run_episode
from motiongym.agents.reproduce import experiments, reproduce
from motiongym.baselines import make_policy, scripted_policies
from motiongym.envs.registration import env_ids

TOY = "motiongym/ToyLine-v0"


@pytest.fixture
def toy_system():
    system = systems.System("toy-line", "toy_world", "toy_world", "toy_world")
    systems.add_system(system)
    yield system
    systems.SYSTEMS.remove(system)
    gym.registry.pop(TOY, None)


def test_one_line_adds_a_world_to_every_registry(toy_system, tmp_path):
    assert TOY in env_ids()
    env = gym.make(TOY)
    check_env(env.unwrapped)
    assert list(scripted_policies(TOY)) == ["walk-to-goal"]
    policy = make_policy(TOY, "walk-to-goal", env.observation_space, env.action_space)
    assert run_episode(env, policy, seed=3)["is_success"] == 1.0
    assert "toy-line" in experiments()
    assert reproduce("toy-line", tmp_path, quick=True) == {"success": 1.0}
    assert systems.declared("envs", "BENCH_GOALS")[TOY] == ("CartPole-v1", 0.01)


def test_a_system_name_is_taken_once(toy_system):
    with pytest.raises(ValueError, match="exists already"):
        systems.add_system(toy_system)


def test_the_toy_world_refuses_bad_input_in_the_core_style(toy_system):
    with pytest.raises(ValueError, match="length must be a finite number in"):
        gym.make(TOY, length=float("nan"))
    with pytest.raises(ValueError, match="unknown keyword argument"):
        gym.make(TOY, lenght=5.0)
