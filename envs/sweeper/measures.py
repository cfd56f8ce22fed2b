"""The sweeper's reward, success and measures in ``info``, for one world or a batch.

Shared by :class:`~motiongym.envs.sweeper.task.SweeperTask` (Python
scalars, the single environment) and the NumPy-batched twin (arrays over
sub-environments, :mod:`motiongym.envs.sweeper.vector_env`), so that both
compute every number from the same formulas.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:  # pragma: no cover
    from motiongym.envs.sweeper.params import SweeperParams

REWARD_TERMS = ("sweep", "time", "bump")

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
    *(f"reward_{term}" for term in REWARD_TERMS),
)


def is_success(n_swept: Any, n_reachable: Any) -> Any:
    """Every reachable cell swept (for one world or a batch)."""
    return n_swept >= n_reachable


def reward_terms(new_cells: Any, bump: Any, params: SweeperParams) -> dict[str, Any]:
    """The reward's terms, for one world (scalars) or a batch (arrays).

    - ``sweep``: ``+params.sweep`` per fresh lane cell (newly swept reachable
      cells over the robot width ``w``);
    - ``time``: ``-params.time`` on every step (a cost);
    - ``bump``: ``-params.bump`` on a bump (a cost).
    """
    cost = -params.bump
    bumped = np.where(bump, cost, 0.0) if isinstance(bump, np.ndarray) else (cost if bump else 0.0)
    return {
        "sweep": params.sweep * new_cells / params.robot_width,
        "time": -params.time,
        "bump": bumped,
    }


def measures(
    n_swept: Any, n_reach: Any, n_over: Any, travel: Any, turns: Any, bumps: Any, steps: Any, w: int
) -> dict[str, Any]:
    """``coverage``, ``travel``, ``travel_ratio``, ``overlap``, ``turns``, ``bumps``, ``steps``.

    Counters are scalars for one world or arrays for a batch; batched values
    are copied, so later steps never change a returned ``info``.
    """
    own = np.array if isinstance(n_swept, np.ndarray) else (lambda value: value)
    return {
        "coverage": n_swept / n_reach,
        "travel": own(travel),
        "travel_ratio": travel * w / n_reach,
        "overlap": n_over / n_reach,
        "turns": own(turns),
        "bumps": own(bumps),
        "steps": own(steps),
    }


def batch_info(
    is_success: np.ndarray, bump: np.ndarray, terms: dict[str, Any], **measured: Any
) -> dict[str, Any]:
    """A batch's ``info`` as :func:`motiongym.envs.core.reward_and_info` lays out one
    world's: ``is_success``, ``cost``, the measures and ``reward_<term>`` (float64)."""
    n = len(is_success)
    info: dict[str, Any] = {"is_success": is_success, "cost": np.asarray(bump, np.float64)}
    info.update(measured)
    for key, value in terms.items():
        info[f"reward_{key}"] = np.broadcast_to(np.asarray(value, np.float64), (n,)).copy()
    return info
