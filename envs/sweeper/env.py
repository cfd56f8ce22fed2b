"""``motiongym/Sweeper-v0`` and ``-v1``: a cleaning robot covering an unknown closed area."""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from motiongym.envs.core import (
    ArgumentError,
    NeedsReset,
    check_render_mode,
    reward_and_info,
    zero_terms,
)
from motiongym.envs.rendering import Renders
from motiongym.envs.sweeper import maps, task
from motiongym.envs.sweeper.measures import measures
from motiongym.envs.sweeper.params import SweeperParams
from motiongym.envs.sweeper.render import draw
from motiongym.envs.sweeper.state import SweeperState
from motiongym.envs.sweeper.world import FORWARD, LEFT, RIGHT, World

__all__ = ["FORWARD", "LEFT", "RIGHT", "SweeperEnv"]


class SweeperEnv(NeedsReset, Renders, gym.Env):
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

    - ``sweep``: ``sweep * (newly swept reachable cells) / w`` (+1 for
      a forward move onto fresh floor, by default)
    - ``time``: ``time`` on every step (a step cost, negative)
    - ``bump``: ``bump`` on a bump (negative)

    Each term's weight is the keyword argument of the same name.

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

    ## Keyword arguments
    ``render_mode`` (None, "rgb_array", or "human": a window) and the world's parameters, each
    checked at construction (type, finiteness, range, size limits; see
    :class:`~motiongym.envs.sweeper.params.SweeperParams` for the table):
    ``map_name`` ("room", "apartment", "maze", "random", "random-room",
    "random-apartment", "random-maze"), ``map_file`` (a .txt or .png path,
    overrides map_name), ``grid`` (an (H, W) bool array, overrides both),
    ``robot_width`` (cells, 3), ``sensor_range`` (cells beyond the footprint,
    default ``robot_width``), ``coarse`` (K, 16), ``heading_noise``,
    ``slip_noise``, ``sweep``, ``time``, ``bump`` (the reward weights),
    ``cell_pixels`` (render scale), ``line_of_sight`` (False; True in v1).

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

    def __init__(self, render_mode: str | None = None, **kwargs: Any) -> None:
        self.params = p = SweeperParams.from_kwargs(kwargs)
        self.render_mode = check_render_mode(render_mode, self.metadata["render_modes"])
        self.fixed = task.resolve_map(p)  # the fixed map, or None (procedural)
        self.world = World(p)
        S, K = p.window, p.coarse
        side = float(maps.MAX_SIDE)
        window = spaces.Box(0.0, 1.0, (S * S,), np.float32)
        coarse_map = spaces.Box(0.0, 1.0, (K * K,), np.float32)
        keys: dict[str, spaces.Space] = {
            "sensed": window,
            "swept": window,
            "pose": spaces.Box(
                np.zeros(4, np.float32), np.array([side, side, 3.0, 1.0], np.float32)
            ),
            "sweep_map": coarse_map,
            "obstacle_map": coarse_map,
        }
        if p.line_of_sight:
            keys["known"] = window
        self.observation_space = spaces.Dict(keys)
        self.action_space = spaces.Discrete(3)

    @property
    def state(self) -> SweeperState | None:
        """The world's state (None before the first reset)."""
        return self.world.state

    @property
    def scenario(self) -> task.Scenario | None:
        """This episode's map and start (None before the first reset)."""
        return None if self.world.state is None else self.world.state.scenario

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict, dict]:
        super().reset(seed=seed)
        p = self.params
        scenario = task.sample_scenario(
            self.np_random, self.fixed, p.map_name, p.robot_width, options
        )
        self.world.reset(scenario)
        self._was_reset = True
        _, info = self._reward_and_info(zero_terms(task.REWARD_TERMS))
        self._show_if_human()
        return self.world.observation(), info

    def step(self, action: Any) -> tuple[dict, float, bool, bool, dict]:
        self._require_reset("step")
        if type(action) is not int or not 0 <= action <= 2:
            action = self._checked_action(action)
        new = self.world.advance(action, self.np_random)
        s = self.world.state
        reward, info = self._reward_and_info(task.reward_terms(new, s.bump, self.params))
        self._show_if_human()
        return self.world.observation(), reward, info["is_success"], False, info

    def _checked_action(self, action: Any) -> int:
        try:
            allowed = self.action_space.contains(action)
        except (OverflowError, TypeError, ValueError):  # e.g. an int past int64
            allowed = False
        if not allowed:
            raise ArgumentError(
                f"action must be in {self.action_space} (0 forward, 1 left, 2 right: "
                f"an int or a NumPy integer scalar), got {action!r}"
            )
        return int(action)

    def _reward_and_info(self, terms: dict[str, float]) -> tuple[float, dict]:
        s = self.world.state
        return reward_and_info(
            terms,
            cost=1.0 if s.bump else 0.0,
            is_success=task.is_success(s.n_swept, s.n_reachable),
            **measures(
                s.n_swept,
                s.n_reachable,
                s.n_overswept,
                s.travel,
                s.turns,
                s.bumps,
                s.steps,
                self.params.robot_width,
            ),
        )

    def action_masks(self) -> np.ndarray:
        """(3,) bool: which actions are allowed (see "Action masks" above)."""
        return self.world.action_masks()

    def _frame(self) -> np.ndarray:
        return draw(self.world.state, self.params.robot_width, self.params.cell_pixels)
