"""Sweeper action masks: forward is masked exactly when it would bump (no odometry noise)."""

from __future__ import annotations

import copy

import gymnasium as gym
import numpy as np
import pytest

import motiongym  # noqa: F401


@pytest.mark.parametrize("map_name", ["room", "maze", "random-apartment"])
def test_forward_is_masked_exactly_when_it_bumps(map_name):
    env = gym.make("motiongym/Sweeper-v0", map_name=map_name).unwrapped
    env.reset(seed=11)
    rng = np.random.default_rng(11)
    masked = allowed = 0
    for _ in range(600):
        mask = env.action_masks()
        assert mask.dtype == bool and mask.shape == (3,) and mask[1] and mask[2]
        probe = copy.deepcopy(env)
        *_, info = probe.step(0)
        assert bool(info["cost"]) == (not mask[0])
        masked += not mask[0]
        allowed += bool(mask[0])
        env.step(int(rng.choice(3, p=[0.6, 0.2, 0.2])))
    assert masked > 10 and allowed > 10
