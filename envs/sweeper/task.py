"""The sweeper's task: which map, where the robot starts, what counts as done and paid.

:class:`SweeperTask` obeys :class:`motiongym.envs.core.Task`; it reads the
world (:class:`~motiongym.envs.sweeper.world.World`) and never moves it.

* ``sample(rng, options) -> Scenario``: drawn from the environment's
  ``np_random`` only (:func:`sample_scenario`): the map (a fixed one, or a
  procedural one when the map name starts with ``"random"``), the start
  configuration (uniform over free configurations) and the start heading
  (uniform over the four); the reset options ``start`` and ``heading``
  (:data:`OPTIONS`) fix them;
* ``begin(world)`` / ``evaluate(world, events)``: the reward terms of
  :func:`~motiongym.envs.sweeper.measures.reward_terms` (``events``: the
  cells the step newly swept), success (every reachable cell swept, which
  also terminates), the cost (1.0 on a bump) and the measures of
  :func:`~motiongym.envs.sweeper.measures.measures`;
* ``observe(world)``: the ``Dict`` observation of ``SweeperEnv``'s
  docstring (fresh arrays).

The reward, success and measures are the formulas of
:mod:`~motiongym.envs.sweeper.measures`, shared with the vector twin.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
from gymnasium import spaces

from motiongym.envs.core import START, ArgumentError, Outcome, check_int, zero_terms
from motiongym.envs.sweeper import families, generator, maps, occupancy
from motiongym.envs.sweeper.measures import REWARD_TERMS, is_success, measures, reward_terms
from motiongym.envs.sweeper.params import SweeperParams

__all__ = [
    "OPTIONS",
    "REWARD_TERMS",
    "Scenario",
    "SweeperTask",
    "is_success",
    "observation_space",
    "resolve_map",
    "reward_terms",
    "sample_scenario",
]


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
    """The fixed map of the environment (``grid``, ``map_file``, ``map_family`` with
    ``map_seed``, or a shipped ``map_name``, in that order), or None when maps are
    procedural."""
    w = params.robot_width
    if params.map_family is not None:
        if params.map_seed is None:
            return None
        return families.family_map(params.map_family, params.map_seed, w, params.map_size)
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


OPTIONS = {START: _start, "heading": _heading}  # reset option -> its check


def sample_scenario(
    rng: np.random.Generator,
    fixed: np.ndarray | None,
    map_name: str,
    w: int,
    options: Mapping[str, Any] | None,
    family: str | None = None,
    size: tuple[int, int] | None = None,
) -> Scenario:
    """Draw the map (if procedural), the start and the heading; apply ``options``
    (checked by :data:`OPTIONS`; None: none).

    A procedural map is of ``family`` (of ``size``) from a map seed drawn from
    ``rng`` when a family is given, else of the ``map_name`` kind of
    :func:`~motiongym.envs.sweeper.generator.random_map`.
    """
    options = options or {}
    if fixed is None and family is not None:
        seed = int(rng.integers(0, families.MAX_MAP_SEED + 1))
        obstacle = families.family_map(family, seed, w, size)
    elif fixed is None:
        kind = map_name.split("-", 1)[1] if "-" in map_name else None
        obstacle = generator.random_map(rng, w, kind)
        while not occupancy.config_free(obstacle, w).any():  # pragma: no cover - rare
            obstacle = generator.random_map(rng, w, kind)
    else:
        obstacle = fixed
    free = occupancy.config_free(obstacle, w)
    start = options.get(START)
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


def observation_space(params: SweeperParams) -> spaces.Dict:
    """The ``Dict`` observation space (``SweeperEnv``'s table)."""
    S, K = params.window, params.coarse
    side = float(maps.MAX_SIDE)
    window = spaces.Box(0.0, 1.0, (S * S,), np.float32)
    coarse_map = spaces.Box(0.0, 1.0, (K * K,), np.float32)
    keys: dict[str, spaces.Space] = {
        "sensed": window,
        "swept": window,
        "pose": spaces.Box(np.zeros(4, np.float32), np.array([side, side, 3.0, 1.0], np.float32)),
        "sweep_map": coarse_map,
        "obstacle_map": coarse_map,
    }
    if params.line_of_sight:
        keys["known"] = window
    return spaces.Dict(keys)


class SweeperTask:
    """Sweep every reachable cell (module docstring); ``fixed``: the fixed map or None."""

    reward_terms: tuple[str, ...] = REWARD_TERMS
    options: Mapping[str, Callable[[str, Any], Any]] = OPTIONS

    def __init__(self, params: SweeperParams) -> None:
        self.params = params
        self.fixed = resolve_map(params)  # the fixed map, or None (procedural)
        self.observation_space: spaces.Space = observation_space(params)

    def sample(self, rng: np.random.Generator, options: Mapping[str, Any]) -> Scenario:
        p = self.params
        return sample_scenario(
            rng, self.fixed, p.map_name, p.robot_width, options, p.map_family, p.map_size
        )

    def begin(self, world: Any) -> Outcome:
        return self._outcome(world.state, zero_terms(REWARD_TERMS), False)

    def evaluate(self, world: Any, events: int) -> Outcome:
        s = world.state
        return self._outcome(s, reward_terms(events, s.bump, self.params), True)

    def _outcome(self, s: Any, terms: dict[str, Any], stepped: bool) -> Outcome:
        """The outcome of the state ``s``; a reset (not ``stepped``) never terminates."""
        success = is_success(s.n_swept, s.n_reachable)
        done = measures(
            s.n_swept,
            s.n_reachable,
            s.n_overswept,
            s.travel,
            s.turns,
            s.bumps,
            s.steps,
            self.params.robot_width,
        )
        return Outcome(terms, success, 1.0 if s.bump else 0.0, done, stepped and success)

    def observe(self, world: Any) -> dict[str, np.ndarray]:
        """The observation (see ``SweeperEnv``'s table), fresh arrays."""
        s, S = world.state, world.S
        br, bc = s.believed_row, s.believed_col
        obs = {
            "sensed": s.window.flatten(),
            "swept": s.believed_swept[br : br + S, bc : bc + S].flatten(),
            "pose": np.array([br, bc, s.heading, float(s.bump)], np.float32),
            "sweep_map": (s.coarse_swept * world.inv_block).ravel(),
            "obstacle_map": (s.coarse_obstacles * world.inv_block).ravel(),
        }
        if s.visible is not None:
            obs["known"] = s.visible.flatten()
        return obs
