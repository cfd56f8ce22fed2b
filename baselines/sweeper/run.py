"""Run a sweeper policy for one episode: the entry point for studies and benchmarks.

``sweep("maze", seed=0)`` makes ``motiongym/Sweeper-v0`` on the maze, runs
PSA + CWA from the seeded start until every reachable cell is swept, and
returns the final ``info`` (coverage, travel, overlap, turns, ...) with the
wall time, the coverage reached when PSA handed over to CWA and the travel
split by what the robot was doing (``travel_by_mode``: lanes, shifts,
transfers between runs, corner work).

The travel goal is set by SmartDFS's bound,
:func:`motiongym.envs.sweeper.occupancy.smartdfs_bound`.
"""

from __future__ import annotations

import time
from typing import Any

import gymnasium as gym

from motiongym.baselines.policy import ScriptedPolicy

POLICY_CLASSES = {
    "psa-cwa": "motiongym.baselines.sweeper.psa_cwa:PsaCwaPolicy",
    "psa-cwa-nearest": "motiongym.baselines.sweeper.psa_cwa:PsaCwaNearestPolicy",
    "wall-follow": "motiongym.baselines.sweeper.wall_follow:WallFollowPolicy",
}


def make_policy(name: str, env: gym.Env, env_kwargs: dict[str, Any]) -> ScriptedPolicy:
    """A sweeper policy by name (see :data:`POLICY_CLASSES`)."""
    import importlib

    if name not in POLICY_CLASSES:
        raise ValueError(f"unknown sweeper policy {name!r}; choices: {', '.join(POLICY_CLASSES)}")
    module, cls = POLICY_CLASSES[name].split(":")
    return getattr(importlib.import_module(module), cls)(
        env.observation_space, env.action_space, env_kwargs
    )


#: policy modes grouped for the travel breakdown (anything else counts as "other")
MODE_GROUPS = {
    "lane": "lane",
    "shift": "shift",
    "pop": "transfer",
    "transfer": "transfer",
    "cwa_scan": "cwa",
    "cwa_pop": "cwa",
    "cwa_follow": "cwa",
}


def run_episode(
    env: gym.Env,
    policy: ScriptedPolicy,
    seed: int | None = None,
    options: dict | None = None,
    max_steps: int | None = None,
) -> dict[str, Any]:
    """One episode; returns the last ``info`` plus ``wall_s``, ``psa_coverage``,
    ``travel_by_mode`` (cells moved per :data:`MODE_GROUPS` group) and ``memory``."""
    obs, info = env.reset(seed=seed, options=options)
    memory = policy.new_memory()
    psa_coverage = None
    t0 = time.perf_counter()
    steps = 0
    by_mode = dict.fromkeys(("lane", "shift", "transfer", "cwa", "other"), 0.0)
    while True:
        action = policy.act(obs, memory)
        mode = getattr(memory, "mode", "")
        if psa_coverage is None and mode.startswith(("cwa", "done")):
            psa_coverage = info["coverage"]
        travel = info["travel"]
        obs, _, terminated, truncated, info = env.step(action)
        by_mode[MODE_GROUPS.get(mode, "other")] += info["travel"] - travel
        steps += 1
        if terminated or truncated or (max_steps is not None and steps >= max_steps):
            break
    out = dict(info)
    out["wall_s"] = time.perf_counter() - t0
    out["psa_coverage"] = info["coverage"] if psa_coverage is None else psa_coverage
    out["travel_by_mode"] = by_mode
    out["memory"] = memory
    return out


def sweep(
    map_name: str = "maze",
    seed: int | None = 0,
    options: dict | None = None,
    policy: str = "psa-cwa",
    max_steps: int | None = None,
    **env_kwargs: Any,
) -> dict[str, Any]:
    """Make ``Sweeper-v0`` with ``map_name`` and ``env_kwargs`` and run ``policy`` once."""
    kwargs = {"map_name": map_name, **env_kwargs}
    env = gym.make("motiongym/Sweeper-v0", **kwargs)
    full_kwargs = {**gym.spec("motiongym/Sweeper-v0").kwargs, **kwargs}
    try:
        return run_episode(env, make_policy(policy, env, full_kwargs), seed, options, max_steps)
    finally:
        env.close()
