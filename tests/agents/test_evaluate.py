"""The one episode loop: a per-step hook that returns True ends the episode there."""

from __future__ import annotations

import gymnasium as gym

from motiongym.agents.evaluation.episodes import run_episode


class Always:
    """A predictor that always pushes right."""

    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        return 1, state


def test_hook_returning_true_ends_the_episode_after_that_step() -> None:
    env = gym.make("CartPole-v1")
    seen = []

    def hook(step) -> bool:
        seen.append(step.index)
        return step.index == 4

    result = run_episode(env, Always(), seed=0, hook=hook)
    assert result["length"] == 5 and seen == [0, 1, 2, 3, 4]
    full = run_episode(env, Always(), seed=0, hook=lambda step: None)
    assert full["length"] > 5  # a hook returning None never stops it
