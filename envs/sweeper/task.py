"""The sweeper's task: which map, where the robot starts, what counts as done and paid.

A scenario is drawn from the environment's ``np_random`` only: the map (a
fixed one, or a procedural one when the map name is ``"random"``), the start
configuration (uniform over free configurations) and the start heading
(uniform over the four). ``reset(options=...)`` may fix the start and heading
(:data:`OPTIONS`). Success is every reachable cell swept; the reward is three
named terms (:func:`reward_terms`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from motiongym.envs.core import ArgumentError, check_int, check_options
from motiongym.envs.sweeper import generator, maps, occupancy
from motiongym.envs.sweeper.params import SweeperParams

REWARD_TERMS = ("sweep", "time", "bump")


@dataclass
class Scenario:
    """One episode's world: the map and the robot's start."""

    obstacle: np.ndarray  # (H, W) bool, True: obstacle
    free_configs: np.ndarray  # (H, W) bool, configurations whose footprint is free
    reach_configs: np.ndarray  # (H, W) bool, free configurations reachable from the start
    reachable: np.ndarray  # (H, W) bool, cells the robot can sweep (coverage target)
    start: tuple[int, int]  # footprint top-left cell (row, col)
    heading: int  # 0 east, 1 north, 2 west, 3 south


def resolve_map(params: SweeperParams) -> np.ndarray | None:
    """The fixed map of the environment (``grid``, ``map_file`` or a shipped
    ``map_name``, in that order), or None when maps are procedural."""
    w = params.robot_width
    if params.grid is not None:
        return maps.validate_map(params.grid, w, source="grid")
    if params.map_file is not None:
        return maps.load_map_file(params.map_file, w)
    if params.map_name in maps.SHIPPED_MAPS:
        return maps.validate_map(maps.shipped_map(params.map_name), w, f"map {params.map_name!r}")
    return None


def _start(name: str, value: Any) -> tuple[int, int] | None:
    """A reset option ``start``: None or (row, col) non-negative integers."""
    if value is None:
        return None
    if isinstance(value, (str, bytes)) or not hasattr(value, "__len__") or len(value) != 2:
        raise ArgumentError(f"{name} must be (row, col), two integers, got {value!r}")
    return (check_int(f"{name}[0]", value[0], 0), check_int(f"{name}[1]", value[1], 0))


def _heading(name: str, value: Any) -> int | None:
    """A reset option ``heading``: None or 0 (east), 1 (north), 2 (west), 3 (south)."""
    return None if value is None else check_int(name, value, 0, 3)


OPTIONS = {"start": _start, "heading": _heading}  # reset option -> its check


def sample_scenario(
    rng: np.random.Generator,
    fixed: np.ndarray | None,
    map_name: str,
    w: int,
    options: Any,
) -> Scenario:
    """Draw the map (if procedural), the start and the heading; apply ``options``."""
    options = check_options(options, OPTIONS)
    if fixed is None:
        kind = map_name.split("-", 1)[1] if "-" in map_name else None
        obstacle = generator.random_map(rng, w, kind)
        while not occupancy.config_free(obstacle, w).any():  # pragma: no cover - rare
            obstacle = generator.random_map(rng, w, kind)
    else:
        obstacle = fixed
    free = occupancy.config_free(obstacle, w)
    start = options.get("start")
    if start is not None:
        h, wd = obstacle.shape
        if not (start[0] < h and start[1] < wd) or not free[start]:
            raise ArgumentError(
                f"options['start'] must be a free configuration: the {w}x{w} footprint "
                f"anchored there must lie on free cells of the {h}x{wd} map, got {start}"
            )
    else:
        cells = np.flatnonzero(free)
        k = int(cells[rng.integers(len(cells))])
        start = divmod(k, obstacle.shape[1])
    heading = options.get("heading")
    if heading is None:
        heading = int(rng.integers(4))
    reach_configs = occupancy.reachable_configs(free, start)
    reachable = occupancy.footprint_union(reach_configs, w)
    return Scenario(obstacle, free, reach_configs, reachable, start, heading)


def is_success(n_swept: Any, n_reachable: Any) -> Any:
    """Every reachable cell swept (for one world or a batch)."""
    return n_swept >= n_reachable


def reward_terms(new_cells: Any, bump: Any, params: SweeperParams) -> dict[str, Any]:
    """The reward's terms, for one world (scalars) or a batch (arrays).

    - ``sweep``: ``params.sweep`` per fresh lane cell (newly swept reachable
      cells over the robot width ``w``);
    - ``time``: ``params.time`` on every step;
    - ``bump``: ``params.bump`` on a bump.
    """
    weight = params.bump
    batched = isinstance(bump, np.ndarray)
    bumped = np.where(bump, weight, 0.0) if batched else (weight if bump else 0.0)
    return {
        "sweep": params.sweep * new_cells / params.robot_width,
        "time": params.time,
        "bump": bumped,
    }
