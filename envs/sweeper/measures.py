"""The sweeper's measures in ``info``, for one world or a batch.

Shared by :class:`~motiongym.envs.sweeper.env.SweeperEnv` (Python scalars)
and its NumPy-batched twin (arrays over sub-environments), so that both
compute every number from the same formulas.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from motiongym.envs.sweeper.task import REWARD_TERMS

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
