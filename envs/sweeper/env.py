"""``motiongym/Sweeper-v0`` and ``-v1``: a cleaning robot covering an unknown closed area."""

from __future__ import annotations

from typing import Any

import numpy as np

from motiongym.envs.core import ArgumentError, SystemEnv
from motiongym.envs.sweeper.params import SweeperParams
from motiongym.envs.sweeper.state import SweeperState
from motiongym.envs.sweeper.task import Scenario, SweeperTask
from motiongym.envs.sweeper.world import FORWARD, LEFT, RIGHT, World

__all__ = ["FORWARD", "LEFT", "RIGHT", "SweeperEnv"]


class SweeperEnv(SystemEnv):
    """Sweep every reachable free cell of an unknown closed area (Park & Lee 1998).

    The world is an occupancy bitmap (paper 4.1). The robot is a square of
    ``robot_width`` cells that sweeps the cells under it. It starts at a free
    configuration (its footprint's top-left cell) with a heading, both random
    unless fixed by ``reset(options=...)``, and knows nothing of the map: it
    senses obstacles within ``sensor_range`` cells of its footprint and feels
    bumps. Distances are in cells (the paper's "base units").

    ``motiongym/Sweeper-v1`` (``line_of_sight=True``) senses through lines of
    sight: a window cell is sensed when the Bresenham line from some footprint
    cell to it crosses no obstacle cell before it (the obstacle itself is
    sensed, what lies behind it is not; cells outside the map are obstacles);
    see :mod:`motiongym.envs.sweeper.sight`. ``motiongym/Sweeper-v0`` is the
    see-through variant: every obstacle in the window is sensed.

    ## Action space: ``Discrete(3)``

    ===== ==========================================================
    0     move forward one cell (a move into an obstacle is a bump:
          the robot stays and senses it)
    1     turn 90 degrees left (counter-clockwise) in place
    2     turn 90 degrees right (clockwise) in place
    ===== ==========================================================

    ## Observation space: ``Dict``
    With ``w = robot_width``, ``R = sensor_range``, ``S = w + 2R``, ``K = coarse``:

    Windows and maps are flattened row-major (SB3's vector form); reshape
    them to ``(S, S)`` and ``(K, K)``.

    ============= ======== ===================================================
    key           shape    meaning
    ============= ======== ===================================================
    sensed        (S*S,)   obstacles sensed around the footprint (1.0; outside
                           the map counts as obstacle), world-aligned (row 0
                           north): entry ``[i, j]`` is the cell at offset
                           ``(i - R, j - R)`` from the footprint's top-left
                           cell (at the true pose; the robot files it at
                           its believed pose)
    swept         (S*S,)   the robot's own sweep map over the same window
                           (1.0: swept)
    pose          (4,)     believed pose: footprint top-left row, column
                           (cells, map frame), heading (0 east, 1 north,
                           2 west, 3 south), bump on the last step (0/1)
    sweep_map     (K*K,)   the robot's built sweep map, coarse: each entry
                           covers a ``ceil(H/K) x ceil(W/K)`` block of the
                           map and holds the fraction swept
    obstacle_map  (K*K,)   same blocks: fraction of known obstacle cells
    known         (S*S,)   v1 only: 1.0 for a window cell sensed at the
                           current pose (visible from the footprint; the
                           window is read after every move), 0.0 for
                           unknown; same layout as ``sensed``, which in v1
                           is 1.0 only for a sensed obstacle (0.0: free or
                           unknown)
    ============= ======== ===================================================

    Everything is float32 in [0, 1] except ``pose`` (rows/columns up to 256).
    The maps are coarse to keep the space small (2 K^2 numbers); a policy that
    needs the full-resolution maps builds them from ``sensed``, ``swept``
    and ``pose``, as the scripted policies do. Without odometry noise the believed pose is
    the true pose.

    ## Reward
    Three named terms, summed; each is in ``info`` as ``reward_<term>``:

    - ``sweep``: ``+sweep * (newly swept reachable cells) / w`` (+1 for
      a forward move onto fresh floor, by default)
    - ``time``: ``-time`` on every step (a step cost; -0.05 by default)
    - ``bump``: ``-bump`` on a bump (-1 by default)

    Each term's weight is the keyword argument of the same name, a
    magnitude in [0, 1e6]: a cost is subtracted, and a negative weight is
    refused (for ``time`` and ``bump`` the message names the positive weight
    of the same reward).

    ## Termination and truncation
    Terminated when every reachable free cell (the union of footprints over
    configurations reachable from the start) is swept; truncation is left to
    ``TimeLimit`` (``max_episode_steps``).

    ## info
    ``is_success`` (all reachable cells swept), ``cost`` (1.0 on a bump),
    ``coverage`` (fraction of reachable cells swept, on the true pose),
    ``travel`` (distance moved, cells), ``travel_ratio`` (travel over the
    lower bound reachable area / w), ``overlap`` (fraction of reachable cells
    swept more than once: entered by the footprint on two or more moves),
    ``turns``, ``bumps``, ``steps``, and the reward terms.

    ## Odometry error (the paper's open problem, section 4.2 / Fig. 20)
    With ``heading_noise`` (rad, std added to the true heading on every
    action) or ``slip_noise`` (relative std of each forward move's length),
    the true pose is continuous and drifts from the believed pose, which
    advances by exactly one cell per unblocked move. Sensing and sweeping
    happen at the true pose (rounded to cells); the robot files the
    ``sensed`` window in its maps at the believed pose, so its maps drift.
    The believed pose is clipped to the map's extent. A move whose rounded true pose leaves the
    reachable configurations is a bump.

    ## Action masks (sb3-contrib's MaskablePPO)
    ``action_masks()`` -> (3,) bool: forward is masked out when the
    ``sensed`` window shows an obstacle (or the map's edge) in the row of
    cells directly ahead of the footprint along the believed heading; turns
    are always allowed. It is a function of the current observation, so it
    gives a learner nothing the observation does not. With odometry noise an
    allowed forward move can still bump.

    ## reset options
    ``start``: (row, col) integers, the footprint's top-left cell (a free
    configuration); ``heading``: integer 0..3. Either may be None (drawn).
    Anything else (another key, a non-dict ``options``) is a ValueError.

    ## Rendering
    ``render()`` (``render_mode="rgb_array"``) returns the map, swept cells
    (grey; darker: swept twice), the path, the robot and its heading. With
    ``render_size=None`` (the default) at 8 pixels per cell, the frame as
    large as the map; with ``render_size=(rows, columns)`` a frame of that
    shape, the map at the largest whole number of pixels per cell that fits,
    centred (so frames of random maps of several sizes share one shape); see
    :mod:`motiongym.envs.sweeper.render`.

    ## Keyword arguments
    ``render_mode`` (None, "rgb_array", or "human": a window) and the world's parameters, each
    checked at construction (type, finiteness, range, size limits; see
    :class:`~motiongym.envs.sweeper.params.SweeperParams` for the table):
    ``map_name`` ("room", "apartment", "maze", "random", "random-room",
    "random-apartment", "random-maze"), ``map_file`` (a .txt or .png path,
    overrides map_name), ``grid`` (an (H, W) bool array, overrides both),
    ``map_family`` (a generated family of
    :mod:`~motiongym.envs.sweeper.families`: "narrow-corridors",
    "corridors", "narrow-serpentine", "serpentine", "pillars", "offices",
    "hall", "mixed"; overrides map_name), ``map_seed`` (an integer in
    [0, 2**32 - 1]: one fixed map of the family; None: a map seed drawn
    from each reset's generator), ``map_size`` ((rows, columns), at least
    ``4 * robot_width + 6`` and at most 256 a side; None: (40, 60)),
    ``robot_width`` (cells, 3), ``sensor_range`` (cells beyond the footprint,
    default ``robot_width``), ``coarse`` (K, 16), ``heading_noise``,
    ``slip_noise``, ``sweep``, ``time``, ``bump`` (the reward weights),
    ``render_size`` ((rows, columns) of a frame, or None), ``cell_pixels``
    (deprecated: pixels per cell; use ``render_size``), ``line_of_sight``
    (False; True in v1).

    ## Actions, reset
    An action is what ``Discrete(3).contains`` accepts (a Python int or a
    NumPy integer scalar / 0-d array in 0..2); anything else is a ValueError
    naming the space. The unwrapped ``step()`` / ``render()`` before
    ``reset()`` raise RuntimeError.

    ## Version history

    - v1: line-of-sight sensing (an obstacle hides what lies behind it) and
      the ``known`` observation key telling unknown from free.
    - v0: first version; the window sees through walls (kept as the
      see-through variant).

    ``map_family``, ``map_seed`` and ``map_size`` were added to both without
    a new version: left unset, they change nothing.
    """

    metadata = {
        "render_modes": ["rgb_array", "human"],
        "render_fps": 30,
        "info_measures": {
            "coverage": "last",
            "travel": "last",
            "travel_ratio": "last",
            "overlap": "last",
            "turns": "last",
            "bumps": "last",
            "steps": "last",
            "cost": "sum",
            "is_success": "last",
        },
        "info_units": {
            "coverage": "fraction",
            "travel": "cells",
            "travel_ratio": "ratio",
            "overlap": "fraction",
            "turns": "count",
            "bumps": "count",
            "steps": "steps",
            "cost": "steps",
            "is_success": "rate",
        },
    }

    Params = SweeperParams
    params: SweeperParams
    world: World
    task: SweeperTask
    ACTION_MEANING = "0 forward, 1 left, 2 right: an int or a NumPy integer scalar"

    def make_world(self, params: SweeperParams) -> World:
        return World(params)

    def make_task(self, params: SweeperParams) -> SweeperTask:
        return SweeperTask(params)

    def check_action(self, action: Any) -> int:
        if type(action) is int and 0 <= action <= 2:
            return action
        try:
            allowed = self.action_space.contains(action)
        except (OverflowError, TypeError, ValueError):  # e.g. an int past int64
            allowed = False
        if not allowed:
            raise ArgumentError(
                f"action must be in {self.action_space} ({self.ACTION_MEANING}), got {action!r}"
            )
        return int(action)

    @property
    def fixed(self) -> np.ndarray | None:
        """The fixed map, or None when every episode draws a procedural one."""
        return self.task.fixed

    @property
    def state(self) -> SweeperState | None:
        """The world's state (None before the first reset)."""
        return self.world.state

    @property
    def scenario(self) -> Scenario | None:
        """This episode's map and start (None before the first reset)."""
        return self.world.scene

    def action_masks(self) -> np.ndarray:
        """(3,) bool: which actions are allowed (see "Action masks" above)."""
        return self.world.action_masks()
