"""PSA + CWA beside the field's classical coverage references on Sweeper-v1, noise-free.

``python -m motiongym.agents.reproduce.sweeper_classical [starts]`` runs
``psa-cwa``, ``boustrophedon``, ``ba-star`` and ``spiral-stc`` on each shipped
map from the seeded starts ``0 .. starts - 1`` (5 by default) through the one
episode loop, each until it declares itself done (``diagnostics()["done"]``) or
the environment ends the episode on full coverage, and prints a Markdown
table of the means: coverage at done (and its minimum), travel, travel ratio,
turns, overlap and steps to done.
"""

from __future__ import annotations

import sys
from typing import Any

import gymnasium as gym
import numpy as np

from motiongym.agents.evaluation.episodes import run_episode
from motiongym.baselines import make_policy
from motiongym.envs.sweeper.maps import SHIPPED_MAPS

ENV_ID = "motiongym/Sweeper-v1"
POLICIES = ("psa-cwa", "boustrophedon", "ba-star", "spiral-stc")
MAX_STEPS = 8000


def run_to_done(policy_name: str, map_name: str, seed: int) -> dict[str, Any]:
    """One noise-free episode until ``policy_name`` declares itself done; the last info."""
    env = gym.make(ENV_ID, map_name=map_name, max_episode_steps=MAX_STEPS)
    kwargs = {**gym.spec(ENV_ID).kwargs, "map_name": map_name}
    policy = make_policy(ENV_ID, policy_name, env.observation_space, env.action_space, kwargs)
    last: dict[str, Any] = {}

    def hook(step) -> bool:
        last.update(step.info)
        return bool(policy.diagnostics().get("done"))

    try:
        run_episode(env, policy, seed, hook=hook)
    finally:
        env.close()
    return last


def table(starts: int = 5) -> str:
    keys = ("coverage", "travel", "travel_ratio", "turns", "overlap", "steps")
    lines = [
        "| map | policy | coverage at done (mean / min) | travel | travel ratio | turns "
        "| overlap | steps to done |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for map_name in SHIPPED_MAPS:
        for name in POLICIES:
            runs = [run_to_done(name, map_name, seed) for seed in range(starts)]
            v = {k: np.array([float(r[k]) for r in runs]) for k in keys}
            lines.append(
                f"| {map_name} | {name} | {100 * v['coverage'].mean():.1f} % / "
                f"{100 * v['coverage'].min():.1f} % | {v['travel'].mean():.0f} | "
                f"{v['travel_ratio'].mean():.2f} | {v['turns'].mean():.0f} | "
                f"{100 * v['overlap'].mean():.1f} % | {v['steps'].mean():.0f} |"
            )
    return "\n".join(lines)


if __name__ == "__main__":
    print(table(int(sys.argv[1]) if len(sys.argv) > 1 else 5))
