"""Shared by the dual-arm tests: a pure start delay, or a policy, run in the environment."""

from __future__ import annotations

import gymnasium as gym
import numpy as np


def run_pure_delay(env: gym.Env, seed: int, delay: int, waiting: int = 1) -> bool:
    """Does the pure delay ``delay`` (robot ``waiting``, 0 or 1, waits ``delay`` steps, then
    runs at full speed; the other runs at nominal speed throughout) run to the end without
    collision in ``env``?"""
    env.reset(seed=seed)
    t, done = 0, False
    while not done:
        action = np.ones(2, np.float32)
        action[waiting] = 1.0 if t >= delay else 0.0
        _, _, terminated, truncated, info = env.step(action)
        done, t = terminated or truncated, t + 1
    return bool(info["is_success"])


def run_policy(env: gym.Env, policy, seed: int, options: dict | None = None) -> dict:
    """Run ``policy`` (a scripted policy) for one episode from ``seed``; the last info."""
    obs, info = env.reset(seed=seed, options=options)
    policy.reset()
    done = False
    while not done:
        action, _ = policy.predict(obs)
        obs, _, terminated, truncated, info = env.step(action)
        done = terminated or truncated
    return info
