"""Start-position spread against the maze's size in robot widths (paper 4.1.2).

The paper reports the travel from every start of its maze within about 3 %
(max 20843, min 20193 base units) and gives neither the maze's size nor the
robot's width in base units. Ours, on the shipped maze with ``W = 3``, spreads
far more (:func:`.sweeper.start_position_study`; docs/experiments/Sweeper-v0.md).
This study asks what that
relative figure depends on: the maze is enlarged ``k`` times (every cell
becomes a ``k x k`` block, :func:`numpy.kron`; the layout is the same, only
its size in robot widths grows) and PSA + CWA runs from the same number of
start configurations drawn at random on each (seeded), heading east, as the
paper's study. Sweeping (lanes and shifts) grows with the area, ``k^2``; the
travel between runs (transfers and corner work), whose order the start decides,
grows with the side, ``k``; so the relative spread should fall as the maze
grows. Reported per ``k``, for our PSA and for the paper's reading (the plain
stack, ``pop_order = "stack"``, ``restart_axis = False``): the mean travel in
cells and in robot widths, the spread ``(max - min) / min`` (the paper's), the
5-95 % range over the median (robust to the sample size), and the mean travel
between runs.
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np

from motiongym.agents.reproduce.sweeper_runs import run_sweep, sweeper_policy
from motiongym.envs.sweeper import maps, occupancy

ENV_ID = "motiongym/Sweeper-v0"  # the reproduction's ID (travel needs no line of sight)
W = 3  # robot width, cells
READINGS = {"ours": {}, "paper's stack": {"pop_order": "stack", "restart_axis": False}}


def enlarged_maze(k: int) -> np.ndarray:
    """The shipped maze with every cell a ``k x k`` block (True: obstacle)."""
    return np.kron(maps.shipped_map("maze"), np.ones((k, k), dtype=bool)).astype(bool)


def spread_at_scale(k: int, starts: int, reading: str = "ours", seed: int = 0) -> dict[str, Any]:
    """Travel of PSA + CWA from ``starts`` random start configurations of the maze enlarged
    ``k`` times (heading east); the draw is ``default_rng(seed)`` over the feasible starts."""
    grid = enlarged_maze(k)
    kwargs = {**gym.spec(ENV_ID).kwargs, "robot_width": W, "grid": grid}
    env = gym.make(ENV_ID, robot_width=W, grid=grid, max_episode_steps=10**7)
    free = np.argwhere(occupancy.config_free(grid, W))
    rng = np.random.default_rng(seed)
    picked = rng.choice(len(free), size=min(starts, len(free)), replace=False)
    travel, between = [], []
    for i in picked:
        policy = sweeper_policy("psa-cwa", env, kwargs)
        for name, value in READINGS[reading].items():
            setattr(policy, name, value)
        start = (int(free[i][0]), int(free[i][1]))
        run = run_sweep(env, policy, 0, {"start": start, "heading": 0})
        if run["coverage"] < 1.0:
            raise RuntimeError(f"maze x{k}, start {start}: coverage {run['coverage']:.4f} < 1")
        travel.append(run["travel"])
        between.append(run["travel_by_mode"]["transfer"] + run["travel_by_mode"]["cwa"])
    env.close()
    t = np.asarray(travel, float)
    p5, p50, p95 = np.percentile(t, [5, 50, 95])
    return {
        "k": k,
        "reading": reading,
        "starts": len(t),
        "feasible_starts": len(free),
        "travel_mean": float(t.mean()),
        "travel_mean_widths": float(t.mean() / W),
        "spread": float((t.max() - t.min()) / t.min()),
        "spread_p5_p95": float((p95 - p5) / p50),
        "between_runs_mean": float(np.mean(between)),
    }


def scale_study(quick: bool) -> list[dict[str, Any]]:
    """Every reading at k = 1..4 with 200 starts each (quick: k = 1, 2 with 4 starts)."""
    scales, starts = ((1, 2), 4) if quick else ((1, 2, 3, 4), 200)
    return [spread_at_scale(k, starts, reading) for reading in READINGS for k in scales]
