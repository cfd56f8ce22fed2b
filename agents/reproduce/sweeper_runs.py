"""Whole sweeper runs for studies and the bench, on the one episode loop.

``sweep("maze", seed=0)`` makes ``motiongym/Sweeper-v0`` on the maze, runs
PSA + CWA from the seeded start through
:func:`motiongym.agents.evaluation.episodes.run_episode` until every reachable cell is
swept (or ``max_steps``), and returns the final ``info`` (coverage, travel,
overlap, turns, ...) with the wall time, the coverage reached when PSA handed
over to CWA (``psa_coverage``), the travel split by what the robot was doing
(``travel_by_mode``: lanes, shifts, transfers between runs, corner work) and
the policy's decisions (``transfers``). Everything about the policy is read
from its public ``diagnostics()`` (``mode``, ``log``) by the loop's per-step
hook.

The travel goal is set by SmartDFS's bound,
:func:`motiongym.envs.sweeper.occupancy.smartdfs_bound`.
"""

from __future__ import annotations

import time
from typing import Any

import gymnasium as gym

from motiongym.agents.evaluation.episodes import Step, run_episode
from motiongym.baselines import make_policy

ENV_ID = "motiongym/Sweeper-v0"

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


class _RunHook:
    """Per-step hook: travel by mode, PSA's coverage at the hand-over (the coverage after
    the last step PSA acted in; 0.0 if the policy never acted in PSA), the last info."""

    def __init__(self, max_steps: int | None) -> None:
        self.max_steps = max_steps
        self.by_mode = dict.fromkeys(("lane", "shift", "transfer", "cwa", "other"), 0.0)
        self.psa_coverage: float | None = None
        self.coverage, self.travel = 0.0, 0.0  # before the step
        self.info: dict[str, Any] = {}

    def __call__(self, step: Step) -> bool:
        mode = step.predictor.diagnostics().get("mode", "")  # the mode it acted in
        if self.psa_coverage is None and mode.startswith(("cwa", "done")):
            self.psa_coverage = self.coverage
        self.by_mode[MODE_GROUPS.get(mode, "other")] += step.info["travel"] - self.travel
        self.coverage, self.travel = step.info["coverage"], step.info["travel"]
        self.info = step.info
        return self.max_steps is not None and step.index + 1 >= self.max_steps


def run_sweep(
    env: gym.Env,
    policy: Any,
    seed: int,
    options: dict | None = None,
    max_steps: int | None = None,
) -> dict[str, Any]:
    """One episode of ``policy``; the last ``info`` plus ``wall_s``, ``psa_coverage``,
    ``travel_by_mode`` (cells moved per :data:`MODE_GROUPS` group) and ``transfers``
    (the policy's logged decisions, where it keeps them)."""
    hook = _RunHook(max_steps)
    start = time.perf_counter()
    run_episode(env, policy, seed, hook=hook, options=options)
    out = dict(hook.info)
    out["wall_s"] = time.perf_counter() - start
    out["psa_coverage"] = out["coverage"] if hook.psa_coverage is None else hook.psa_coverage
    out["travel_by_mode"] = hook.by_mode
    out["transfers"] = policy.diagnostics().get("log", [])
    return out


def sweeper_policy(name: str, env: gym.Env, env_kwargs: dict[str, Any]) -> Any:
    """The scripted policy ``name`` of :data:`ENV_ID`, built from ``env_kwargs``."""
    return make_policy(ENV_ID, name, env.observation_space, env.action_space, env_kwargs)


def sweep(
    map_name: str = "maze",
    seed: int = 0,
    options: dict | None = None,
    policy: str = "psa-cwa",
    max_steps: int | None = None,
    **env_kwargs: Any,
) -> dict[str, Any]:
    """Make ``Sweeper-v0`` with ``map_name`` and ``env_kwargs`` and run ``policy`` once."""
    kwargs = {"map_name": map_name, **env_kwargs}
    env = gym.make(ENV_ID, **kwargs)
    full_kwargs = {**gym.spec(ENV_ID).kwargs, **kwargs}
    try:
        return run_sweep(env, sweeper_policy(policy, env, full_kwargs), seed, options, max_steps)
    finally:
        env.close()
