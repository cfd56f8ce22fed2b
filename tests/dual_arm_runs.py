"""Shared by the dual-arm tests: a pure start delay run in the environment itself."""

from __future__ import annotations

import gymnasium as gym
import numpy as np


def run_pure_delay(env: gym.Env, seed: int, delay: int) -> bool:
    """Does the pure delay ``delay`` (robot 1 nominal, robot 2 waiting ``delay`` steps,
    then at full speed) run to the end without collision in ``env``?"""
    env.reset(seed=seed)
    t, done = 0, False
    while not done:
        action = np.array([1.0, 1.0 if t >= delay else 0.0], np.float32)
        _, _, terminated, truncated, info = env.step(action)
        done, t = terminated or truncated, t + 1
    return bool(info["is_success"])
