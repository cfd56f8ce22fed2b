"""The sweeper's task: which map, where the robot starts, what counts as done.

A scenario is drawn from the environment's ``np_random`` only: the map (a
fixed one, or a procedural one when the map name is ``"random"``), the start
configuration (uniform over free configurations) and the start heading
(uniform over the four). ``reset(options=...)`` may fix the start and heading.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from motiongym.envs.sweeper import generator, maps, occupancy

MAP_CHOICES = (*maps.SHIPPED_MAPS, "random", *(f"random-{k}" for k in generator.KINDS))


@dataclass
class Scenario:
    """One episode's world: the map and the robot's start."""

    obstacle: np.ndarray  # (H, W) bool, True: obstacle
    free_configs: np.ndarray  # (H, W) bool, configurations whose footprint is free
    reach_configs: np.ndarray  # (H, W) bool, free configurations reachable from the start
    reachable: np.ndarray  # (H, W) bool, cells the robot can sweep (coverage target)
    start: tuple[int, int]  # footprint top-left cell (row, col)
    heading: int  # 0 east, 1 north, 2 west, 3 south


def resolve_map(
    map_name: str, map_file: str | None, grid: np.ndarray | None, w: int
) -> np.ndarray | None:
    """The fixed map of the environment, or None when maps are procedural."""
    if grid is not None:
        fixed = maps.validate_map(grid, source="grid")
    elif map_file is not None:
        fixed = maps.load_map_file(map_file)
    elif map_name in maps.SHIPPED_MAPS:
        fixed = maps.shipped_map(map_name)
    elif map_name in MAP_CHOICES:
        return None
    else:
        raise ValueError(f"unknown map_name {map_name!r}; choices: {', '.join(MAP_CHOICES)}")
    if not occupancy.config_free(fixed, w).any():
        raise maps.MapError(f"the map has no free place for a robot of width {w}")
    return fixed


def sample_scenario(
    rng: np.random.Generator,
    fixed: np.ndarray | None,
    map_name: str,
    w: int,
    options: dict | None,
) -> Scenario:
    """Draw the map (if procedural), the start and the heading; apply ``options``."""
    options = dict(options or {})
    unknown = set(options) - {"start", "heading"}
    if unknown:
        raise ValueError(f"unknown reset options {sorted(unknown)}; valid: 'start', 'heading'")
    if fixed is None:
        kind = map_name.split("-", 1)[1] if "-" in map_name else None
        obstacle = generator.random_map(rng, w, kind)
        while not occupancy.config_free(obstacle, w).any():  # pragma: no cover - rare
            obstacle = generator.random_map(rng, w, kind)
    else:
        obstacle = fixed
    free = occupancy.config_free(obstacle, w)
    if options.get("start") is not None:
        start = tuple(int(v) for v in options["start"])
        if len(start) != 2:
            raise ValueError(f"option 'start' must be (row, col), got {options['start']!r}")
        h, wd = obstacle.shape
        if not (0 <= start[0] < h and 0 <= start[1] < wd) or not free[start]:
            raise ValueError(
                f"option 'start' {start} is not a free configuration: the {w}x{w} footprint "
                f"anchored there must lie on free cells of the {h}x{wd} map"
            )
    else:
        cells = np.flatnonzero(free)
        k = int(cells[rng.integers(len(cells))])
        start = divmod(k, obstacle.shape[1])
    if options.get("heading") is not None:
        heading = options["heading"]
        if heading not in (0, 1, 2, 3):
            raise ValueError(
                f"option 'heading' must be 0 (east), 1 (north), 2 (west) or 3 (south), "
                f"got {heading!r}"
            )
        heading = int(heading)
    else:
        heading = int(rng.integers(4))
    reach_configs = occupancy.reachable_configs(free, start)
    reachable = occupancy.footprint_union(reach_configs, w)
    return Scenario(obstacle, free, reach_configs, reachable, start, heading)
