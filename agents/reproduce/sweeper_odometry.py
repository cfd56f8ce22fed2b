"""The sweeper's odometry table (paper 4.2, its open problem).

PSA + CWA on ``Sweeper-v1`` (line-of-sight sensing) under heading noise
(rad per action, a random walk of the heading), slip (relative std of a
move) and both, with the localiser (:mod:`motiongym.baselines.sweeper.localise`)
and without it (:class:`~motiongym.baselines.sweeper.psa_cwa.PsaCwaDeadReckoningPolicy`),
on the room, the apartment, the maze and procedural maps.

Episodes run through the one episode loop
(:func:`motiongym.agents.evaluation.episodes.run_episode`); its per-step hook reads the
policy's public ``diagnostics()["done"]`` and ends the episode at the step
the policy declares the area swept, so the coverage recorded is the
coverage at that moment: a premature stop shows as coverage below 100 %,
not hidden by the environment ending on the true coverage. An episode whose
policy never declares itself done ends at the environment's step limit
(20,000) or when every reachable cell is swept.
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np

from motiongym.agents.evaluation.episodes import run_episode
from motiongym.baselines.sweeper.psa_cwa import PsaCwaDeadReckoningPolicy, PsaCwaPolicy

ENV_ID = "motiongym/Sweeper-v1"
#: (heading noise rad/action, slip relative std): heading alone, slip alone, both
LEVELS = (
    (0.005, 0.0), (0.01, 0.0), (0.02, 0.0), (0.0, 0.05), (0.0, 0.1), (0.01, 0.05), (0.02, 0.1),
)  # fmt: skip
QUICK_LEVELS = ((0.01, 0.05),)
MAPS = ("room", "apartment", "maze", "random")
PROCEDURAL_SEED = 2000  # first seed of the procedural maps (the map is drawn from the seed)


def episode(map_name: str, heading: float, slip: float, seed: int, localise: bool) -> dict:
    """One episode; ``coverage`` at the step the policy declared itself done (or at the end)."""
    kwargs: dict[str, Any] = {"map_name": map_name, "heading_noise": heading, "slip_noise": slip}
    env = gym.make(ENV_ID, **kwargs)
    cls = PsaCwaPolicy if localise else PsaCwaDeadReckoningPolicy
    policy = cls(env.observation_space, env.action_space, {**gym.spec(ENV_ID).kwargs, **kwargs})
    seen: dict[str, Any] = {"done_at": None}

    def hook(step) -> bool:
        seen.update(coverage=step.info["coverage"], steps=step.index + 1)
        if policy.diagnostics()["done"]:
            seen["done_at"] = step.index + 1
            return True
        return False

    try:
        run_episode(env, policy, seed, hook=hook)
    finally:
        env.close()
    done = seen["done_at"] is not None
    return {
        "coverage": float(seen["coverage"]),
        "steps": int(seen["steps"]),
        "declared_done": done,
        "early": done and seen["coverage"] < 1.0,
    }


def odometry_table(quick: bool = False, seeds: int | None = None) -> dict:
    """Rows per (noise level, map, localiser): coverage mean and min, early stops.

    ``seeds``: episodes per row (default 1 with ``quick``, else 2); the
    shipped maps start from seeds ``0 .. seeds-1``, procedural maps from
    :data:`PROCEDURAL_SEED` on (a new map per seed).
    """
    n = seeds if seeds is not None else (1 if quick else 2)
    rows = []
    for heading, slip in QUICK_LEVELS if quick else LEVELS:
        for map_name in ("room", "maze") if quick else MAPS:
            first = PROCEDURAL_SEED if map_name == "random" else 0
            for localise in (True, False):
                runs = [episode(map_name, heading, slip, first + k, localise) for k in range(n)]
                cov = [r["coverage"] for r in runs]
                rows.append(
                    {
                        "heading_noise": heading,
                        "slip_noise": slip,
                        "map": map_name,
                        "localise": localise,
                        "coverage": float(np.mean(cov)),
                        "coverage_min": float(np.min(cov)),
                        "early_stops": int(sum(r["early"] for r in runs)),
                        "never_done": int(sum(not r["declared_done"] for r in runs)),
                        "steps": float(np.mean([r["steps"] for r in runs])),
                        "episodes": n,
                    }
                )
    return {"env_id": ENV_ID, "rows": rows, "seeds": n}


def summary(rows: list[dict]) -> dict[str, dict[str, float]]:
    """Per localiser on / off: mean coverage over rows, worst row minimum, early stops."""
    out = {}
    for localise in (True, False):
        sel = [r for r in rows if r["localise"] is localise]
        out["localised" if localise else "dead reckoning"] = {
            "coverage": float(np.mean([r["coverage"] for r in sel])),
            "coverage_min": float(np.min([r["coverage_min"] for r in sel])),
            "early_stops": int(sum(r["early_stops"] for r in sel)),
            "episodes": int(sum(r["episodes"] for r in sel)),
        }
    return out
