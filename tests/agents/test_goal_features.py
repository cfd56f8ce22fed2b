"""The goal_error features extractor of the goal IDs
(motiongym.agents.learners.goal.GoalError)."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
import torch

from motiongym.agents.learners.goal import GoalError
from motiongym.envs.excavator.observation import layout

GOAL = "motiongym/ExcavatorReachGoal-v1"


def _batch(observations: list[dict]) -> dict[str, torch.Tensor]:
    return {
        key: torch.as_tensor(np.stack([o[key] for o in observations]))
        for key in ("observation", "achieved_goal", "desired_goal")
    }


def _episode(env_id: str, seed: int, steps: int = 30) -> list:
    """Observations of ``env_id`` under a fixed sequence of random actions."""
    env = gym.make(env_id)
    rng = np.random.default_rng(seed)
    observations = [env.reset(seed=seed)[0]]
    for _ in range(steps):
        observations.append(env.step(rng.uniform(-1, 1, 4).astype(np.float32))[0])
    return observations


def test_the_error_is_the_base_tasks_target_error():
    """Independent truth: ExcavatorReach-v1 writes target - tip (angle wrapped) itself."""
    goal, base = _episode(GOAL, 7), _episode("motiongym/ExcavatorReach-v1", 7)
    extractor = GoalError(gym.make(GOAL).observation_space, angles=[3], error_scales=[0.03, 0.3])
    out = extractor(_batch(goal)).numpy()
    n = len(goal[0]["observation"])
    error = np.stack([b[layout("reach", "v1")["target_error"]] for b in base])
    np.testing.assert_allclose(out[:, n + 8 : n + 12], error, atol=2e-6)
    np.testing.assert_allclose(out[:, n + 12 : n + 16], np.tanh(error / 0.03), atol=1e-4)
    np.testing.assert_allclose(out[:, n + 16 :], np.tanh(error / 0.3), atol=1e-5)
    assert extractor.features_dim == n + 4 * 5 == out.shape[1]


def test_a_relabelled_goal_gets_its_own_features():
    """HER replaces desired_goal: the error follows it, the rest of the features do not."""
    observations = _episode(GOAL, 3, steps=5)
    extractor = GoalError(gym.make(GOAL).observation_space, keep=[0, 1], angles=[3])
    batch = _batch(observations)
    relabelled = dict(batch, desired_goal=batch["achieved_goal"].flip(0))
    a, b = extractor(batch), extractor(relabelled)
    assert torch.equal(a[:, :6], b[:, :6])  # kept observation and achieved goal
    expected = relabelled["desired_goal"] - relabelled["achieved_goal"]
    torch.testing.assert_close(b[:, 10:14], expected)


def test_angles_are_wrapped_as_the_success_test_wraps_them():
    space = gym.make(GOAL).observation_space
    extractor = GoalError(space, keep=[], angles=[3])
    achieved = torch.tensor([[0.0, 0.0, 0.0, 3.1]])
    desired = torch.tensor([[1.0, 0.0, 0.0, -3.1]])
    batch = {"observation": torch.zeros(1, 52), "achieved_goal": achieved, "desired_goal": desired}
    error = extractor(batch)[0, 8:12]
    torch.testing.assert_close(error, torch.tensor([1.0, 0.0, 0.0, 2 * np.pi - 6.2]))


def test_bad_keywords_are_named():
    space = gym.make(GOAL).observation_space
    with pytest.raises(ValueError, match="keep must be indices of the 52 observation entries"):
        GoalError(space, keep=[52])
    with pytest.raises(ValueError, match="angles must be indices of the 4 goal entries, got .4."):
        GoalError(space, angles=[4])
    with pytest.raises(ValueError, match="error_scales must be positive numbers, got .0.1, -1."):
        GoalError(space, error_scales=[0.1, -1])
    with pytest.raises(ValueError, match="goal_error needs a Dict observation"):
        GoalError(gym.make("motiongym/ExcavatorReach-v1").observation_space)
