"""The sweeper's reward terms and ``info`` of a step, for one world or a batch.

Shared by :class:`~motiongym.envs.sweeper.env.SweeperEnv` (Python scalars)
and its NumPy-batched twin (arrays over sub-environments), so that both
compute every number from the same formulas.
"""

from __future__ import annotations

from typing import Any

import numpy as np

INFO_KEYS = (
    "is_success",
    "cost",
    "coverage",
    "travel",
    "travel_ratio",
    "overlap",
    "turns",
    "bumps",
    "steps",
    "reward_sweep",
    "reward_time",
    "reward_bump",
)


def reward_terms(
    new_cells: Any, bump: Any, w: int, sweep_reward: float, time_reward: float, bump_reward: float
) -> tuple[Any, float, Any]:
    """``(sweep, time, bump)``: ``sweep_reward`` per fresh lane cell (newly swept
    reachable cells over the robot width ``w``), the step cost, the bump penalty."""
    r_sweep = sweep_reward * new_cells / w
    r_bump = np.where(bump, bump_reward, 0.0) if np.ndim(bump) else (bump_reward if bump else 0.0)
    return r_sweep, time_reward, r_bump


def step_info(
    n_swept: Any,
    n_reach: Any,
    n_over: Any,
    travel: Any,
    turns: Any,
    bumps: Any,
    steps: Any,
    w: int,
    bump: Any,
    rewards: tuple[Any, float, Any],
) -> dict[str, Any]:
    """The ``info`` of a step (see ``SweeperEnv``'s docstring for the keys).

    Counters are scalars for one world or arrays for a batch; batched values
    are copied, so later steps never change a returned ``info``.
    """
    batched = np.ndim(n_swept) > 0
    own = np.array if batched else (lambda value: value)
    r_sweep, r_time, r_bump = rewards
    return {
        "is_success": n_swept >= n_reach,
        "cost": np.asarray(bump, np.float64) if batched else (1.0 if bump else 0.0),
        "coverage": n_swept / n_reach,
        "travel": own(travel),
        "travel_ratio": travel * w / n_reach,
        "overlap": n_over / n_reach,
        "turns": own(turns),
        "bumps": own(bumps),
        "steps": own(steps),
        "reward_sweep": np.asarray(r_sweep, np.float64) if batched else r_sweep,
        "reward_time": np.full(np.shape(n_swept), r_time, np.float64) if batched else r_time,
        "reward_bump": np.asarray(r_bump, np.float64) if batched else r_bump,
    }
