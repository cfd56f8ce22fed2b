"""One sweeper world's state: what the observation, ``info`` and the renderer read.

:class:`SweeperState` is written by :class:`~motiongym.envs.sweeper.world.World`
(the single environment) and exported per sub-environment by the vector twin
(:meth:`~motiongym.envs.sweeper.vector_env.SweeperVectorEnv.state`); the
renderer draws it. Cells are ``(row, col)`` in the map frame; *padded* arrays
carry ``P = sensor_range`` obstacle cells on every side of the ``(H, W)`` map,
so map cell ``(y, x)`` is padded cell ``(y + P, x + P)`` and the sensing
window of a footprint at ``(r, c)`` is padded rows ``r .. r + S - 1``,
columns ``c .. c + S - 1`` (``S = w + 2P``).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from motiongym.envs.sweeper.task import Scenario


@dataclass
class SweeperState:
    """The robot's true and believed pose, the sweep and belief maps, the counters."""

    scenario: Scenario  # the map, the reachable cells, the start
    row: int  # true footprint top-left cell
    col: int
    heading: int  # commanded heading, 0 east, 1 north, 2 west, 3 south
    believed_row: int  # the pose the robot believes (odometry); the true one without noise
    believed_col: int
    y: float  # continuous true pose under odometry noise (cells); row, col are it rounded
    x: float
    heading_error: float  # rad, true heading minus the commanded one
    sweeps: np.ndarray  # (H, W) int32 times each cell was swept (the vector twin stops at 2)
    believed_swept: np.ndarray  # (H+2P, W+2P) float32 the robot's own sweep map (1.0 swept)
    known_obstacles: np.ndarray  # (H+2P, W+2P) bool the robot's obstacle map
    coarse_swept: np.ndarray  # (K, K) float32 believed swept cells per coarse block
    coarse_obstacles: np.ndarray  # (K, K) float32 known obstacle cells per coarse block
    window: np.ndarray  # (S, S) float32 sensed obstacles around the true footprint
    visible: np.ndarray | None  # (S, S) float32 cells sensed (line of sight, v1); None in v0
    n_reachable: int  # cells the robot can sweep from its start (the coverage target)
    n_swept: int = 0  # reachable cells swept at least once
    n_overswept: int = 0  # cells entered by the footprint on two or more moves
    turns: int = 0
    bumps: int = 0
    steps: int = 0
    travel: float = 0.0  # cells moved
    bump: bool = False  # the last step bumped
    path: list[tuple[int, int]] = field(default_factory=list)  # true footprint cells visited
