"""``motiongym/Sweeper-v0``: a cleaning robot covering an unknown closed area."""

from __future__ import annotations

import math
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from motiongym.envs.core import check_bool
from motiongym.envs.sweeper import maps, occupancy, sight, task
from motiongym.envs.sweeper.measures import reward_terms, step_info
from motiongym.envs.sweeper.occupancy import DC, DR

FORWARD, LEFT, RIGHT = 0, 1, 2


class SweeperEnv(gym.Env):
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
    known         (S*S,)   v1 only: 1.0 for a window cell sensed on this step
                           (visible from the footprint), 0.0 for unknown;
                           same layout as ``sensed``, which in v1 is 1.0
                           only for a sensed obstacle (0.0: free or unknown)
    ============= ======== ===================================================

    Everything is float32 in [0, 1] except ``pose`` (rows/columns up to 256).
    The maps are coarse to keep the space small (2 K^2 numbers); a policy that
    needs the full-resolution maps builds them from ``sensed``, ``swept``
    and ``pose``, as the scripted policies do. Without odometry noise the believed pose is
    the true pose.

    ## Reward
    Three named terms, summed; each is in ``info`` as ``reward_<term>``:

    - ``sweep``: ``sweep_reward * (newly swept reachable cells) / w`` (+1 for
      a forward move onto fresh floor, by default)
    - ``time``: ``time_reward`` on every step (a step cost, negative)
    - ``bump``: ``bump_reward`` on a bump (negative)

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
    ``start``: (row, col) of the footprint's top-left cell (a free
    configuration); ``heading``: 0..3.

    ## Keyword arguments
    ``map_name`` ("room", "apartment", "maze", "random", "random-room",
    "random-apartment", "random-maze"), ``map_file`` (a .txt or .png path,
    overrides map_name), ``grid`` (an (H, W) bool array, overrides both),
    ``robot_width`` (cells, 3), ``sensor_range`` (cells beyond the footprint,
    default ``robot_width``), ``coarse`` (K, 16), ``heading_noise``,
    ``slip_noise``, ``sweep_reward``, ``time_reward``, ``bump_reward``,
    ``render_mode`` ("rgb_array"), ``cell_pixels`` (render scale),
    ``line_of_sight`` (False; True in v1).

    ## Version history
    - v1: line-of-sight sensing (an obstacle hides what lies behind it) and
      the ``known`` observation key telling unknown from free.
    - v0: first version; the window sees through walls (kept as the
      see-through variant).
    """

    metadata = {
        "render_modes": ["rgb_array"],
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
    }

    def __init__(
        self,
        map_name: str = "room",
        map_file: str | None = None,
        grid: np.ndarray | None = None,
        robot_width: int = 3,  # cells
        sensor_range: int | None = None,  # cells beyond the footprint
        coarse: int = 16,  # built-map resolution in the observation
        heading_noise: float = 0.0,  # rad, std per action
        slip_noise: float = 0.0,  # relative std of a forward move's length
        sweep_reward: float = 1.0,
        time_reward: float = -0.05,
        bump_reward: float = -1.0,
        render_mode: str | None = None,
        cell_pixels: int = 8,
        line_of_sight: bool = False,
    ) -> None:
        if int(robot_width) != robot_width or robot_width < 1:
            raise ValueError(f"robot_width must be a positive integer, got {robot_width!r}")
        self.w = int(robot_width)
        self.R = self.w if sensor_range is None else int(sensor_range)
        if self.R < 1:
            raise ValueError(f"sensor_range must be at least 1 cell, got {sensor_range!r}")
        if int(coarse) < 1:
            raise ValueError(f"coarse must be a positive integer, got {coarse!r}")
        if heading_noise < 0 or slip_noise < 0:
            raise ValueError("heading_noise and slip_noise must be >= 0")
        if render_mode not in (None, *self.metadata["render_modes"]):
            raise ValueError(
                f"unknown render_mode {render_mode!r}; valid: {self.metadata['render_modes']}"
            )
        self.map_name = map_name
        self.fixed = task.resolve_map(map_name, map_file, grid, self.w)
        self.K = int(coarse)
        self.heading_noise = float(heading_noise)
        self.slip_noise = float(slip_noise)
        self.noisy = self.heading_noise > 0 or self.slip_noise > 0
        self.sweep_reward = float(sweep_reward)
        self.time_reward = float(time_reward)
        self.bump_reward = float(bump_reward)
        self.render_mode = render_mode
        self.cell_pixels = int(cell_pixels)

        self.S = self.w + 2 * self.R
        self.line_of_sight = check_bool("line_of_sight", line_of_sight)
        self._rays = sight.ray_matrix(self.w, self.R) if self.line_of_sight else None
        side = float(maps.MAX_SIDE)
        window = spaces.Box(0.0, 1.0, (self.S * self.S,), np.float32)
        coarse_map = spaces.Box(0.0, 1.0, (self.K * self.K,), np.float32)
        keys = {
            "sensed": window,
            "swept": window,
            "pose": spaces.Box(
                np.zeros(4, np.float32), np.array([side, side, 3.0, 1.0], np.float32)
            ),
            "sweep_map": coarse_map,
            "obstacle_map": coarse_map,
        }
        if self.line_of_sight:
            keys["known"] = window
        self.observation_space = spaces.Dict(keys)
        self.action_space = spaces.Discrete(3)
        # Cells entering the footprint on a one-cell move, per heading: (w,) offsets.
        self._enter = []
        for k in range(4):
            rr, cc = np.nonzero(occupancy.entering_mask(int(DR[k]), int(DC[k]), self.w))
            self._enter.append((rr, cc))
        # Leading edge of the sensing window per heading, as slices and cell indices.
        S, last = self.S, self.S - 1
        full = np.arange(S)
        self._edges = [
            (slice(None), slice(last, S)),
            (slice(0, 1), slice(None)),
            (slice(None), slice(0, 1)),
            (slice(last, S), slice(None)),
        ]
        self._edge_cells = [
            (full, np.array([last])),
            (np.array([0]), full),
            (full, np.array([0])),
            (np.array([last]), full),
        ]
        self.scenario: task.Scenario | None = None

    # ------------------------------------------------------------------ reset
    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict, dict]:
        super().reset(seed=seed)
        sc = task.sample_scenario(self.np_random, self.fixed, self.map_name, self.w, options)
        self.scenario = sc
        h, wd = sc.obstacle.shape
        P = self.R
        self.P = P
        self.obst_bool = np.pad(sc.obstacle, P, constant_values=True)
        self.obst_pad = self.obst_bool.astype(np.float32)
        self.reach_cfg = sc.reach_configs
        self.n_reach = int(sc.reachable.sum())
        self.sweeps = np.zeros((h, wd), np.int32)  # true sweep counts
        self.bswept = np.zeros((h + 2 * P, wd + 2 * P), np.float32)  # believed sweep map
        self.kobst = np.zeros((h + 2 * P, wd + 2 * P), bool)  # believed obstacle map
        self.bh_, self.bw_ = -(-h // self.K), -(-wd // self.K)
        self.inv_block = np.float32(1.0 / (self.bh_ * self.bw_))
        self.coarse_swept = np.zeros((self.K, self.K), np.float32)
        self.coarse_obst = np.zeros((self.K, self.K), np.float32)
        self.r, self.c = sc.start  # true footprint cell
        self.ty, self.tx, self.err = float(self.r), float(self.c), 0.0  # noisy true pose
        self.br, self.bc, self.h = sc.start[0], sc.start[1], sc.heading  # believed pose
        self.n_swept = self.n_over = self.turns = self.bumps = self.steps = 0
        self.travel = 0.0
        self.path = [(self.r, self.c)]
        w = self.w
        self.sweeps[self.r : self.r + w, self.c : self.c + w] = 1
        self.n_swept = w * w
        self._mark_believed(np.arange(w).repeat(w) + self.br, np.tile(np.arange(w), w) + self.bc)
        self._sense()
        info = self._info((0.0, 0.0, 0.0), False)
        return self._obs(False), info

    # ------------------------------------------------------------------- step
    def step(self, action: Any) -> tuple[dict, float, bool, bool, dict]:
        a = self._check_action(action)
        if self.scenario is None:
            raise RuntimeError("call reset() before step()")
        self.steps += 1
        bump = False
        new = 0
        if a == FORWARD:
            new, bump = self._noisy_forward() if self.noisy else self._forward()
        else:
            self.h = (self.h + (1 if a == LEFT else -1)) % 4
            self.turns += 1
            if self.noisy:
                self.err += float(self.np_random.normal(0.0, self.heading_noise))
        if a == FORWARD and not bump:  # a turn or a bump leaves the window unchanged
            self._sense(None if self.noisy else self.h)
        rewards = reward_terms(
            new, bump, self.w, self.sweep_reward, self.time_reward, self.bump_reward
        )
        reward = sum(rewards)
        terminated = self.n_swept >= self.n_reach
        info = self._info(rewards, bump)
        return self._obs(bump), float(reward), terminated, False, info

    def _check_action(self, action: Any) -> int:
        if type(action) is int or isinstance(action, np.integer):
            if 0 <= action <= 2:
                return int(action)
        arr = np.asarray(action)
        if arr.size != 1:
            raise ValueError(
                f"action must be a single integer in {{0, 1, 2}}, got shape {arr.shape}"
            )
        value = arr.reshape(()).item()
        if isinstance(value, float) and (math.isnan(value) or value != int(value)):
            raise ValueError(f"action must be an integer in {{0, 1, 2}}, got {value!r}")
        a = int(value)
        if a not in (0, 1, 2):
            raise ValueError(f"action must be 0 (forward), 1 (left) or 2 (right), got {a}")
        return a

    def _forward(self) -> tuple[int, bool]:
        h = self.h
        nr, nc = self.r + int(DR[h]), self.c + int(DC[h])
        if not self.reach_cfg[nr, nc]:
            self.bumps += 1
            return 0, True
        rr, cc = self._enter[h]
        rr, cc = rr + nr, cc + nc
        new = self._sweep_cells(rr, cc)
        self.r, self.c = self.br, self.bc = nr, nc
        self.travel += 1.0
        self.path.append((nr, nc))
        self._mark_believed(rr, cc)
        return new, False

    def _noisy_forward(self) -> tuple[int, bool]:
        rng = self.np_random
        self.err += float(rng.normal(0.0, self.heading_noise)) if self.heading_noise else 0.0
        d = 1.0 + (float(rng.normal(0.0, self.slip_noise)) if self.slip_noise else 0.0)
        d = min(max(d, 0.0), 1.4)
        ang = self.h * math.pi / 2 + self.err
        ny, nx = self.ty - d * math.sin(ang), self.tx + d * math.cos(ang)
        nr, nc = int(round(ny)), int(round(nx))
        dr, dc = nr - self.r, nc - self.c
        ok = abs(dr) <= 1 and abs(dc) <= 1 and self.reach_cfg[nr, nc]
        if ok and dr and dc:  # no corner cutting through a blocked configuration
            ok = bool(self.reach_cfg[self.r + dr, self.c] or self.reach_cfg[self.r, self.c + dc])
        if not ok:
            self.bumps += 1
            return 0, True
        new = 0
        if dr or dc:
            rr, cc = np.nonzero(occupancy.entering_mask(dr, dc, self.w))
            new = self._sweep_cells(rr + nr, cc + nc)
            self.r, self.c = nr, nc
            self.path.append((nr, nc))
        self.ty, self.tx = ny, nx
        self.travel += d
        h, wd = self.scenario.obstacle.shape
        self.br = min(max(self.br + int(DR[self.h]), 0), h - self.w)
        self.bc = min(max(self.bc + int(DC[self.h]), 0), wd - self.w)
        e = np.nonzero(occupancy.entering_mask(int(DR[self.h]), int(DC[self.h]), self.w))
        self._mark_believed(e[0] + self.br, e[1] + self.bc)
        return new, False

    def _sweep_cells(self, rr: np.ndarray, cc: np.ndarray) -> int:
        """Sweep the true cells ``(rr, cc)``; return how many were never swept before."""
        before = self.sweeps[rr, cc]
        self.sweeps[rr, cc] = before + 1
        new = int(np.count_nonzero(before == 0))
        self.n_swept += new
        self.n_over += int(np.count_nonzero(before == 1))
        return new

    def _mark_believed(self, rr: np.ndarray, cc: np.ndarray) -> None:
        """Mark cells swept in the robot's own (believed) sweep map and its coarse copy."""
        P = self.P
        fresh = self.bswept[rr + P, cc + P] == 0
        if fresh.any():
            rr, cc = rr[fresh], cc[fresh]
            self.bswept[rr + P, cc + P] = 1.0
            cs, bh, bw = self.coarse_swept, self.bh_, self.bw_
            for r, c in zip(rr.tolist(), cc.tolist(), strict=True):
                cs[r // bh, c // bw] += 1.0

    def _sense(self, heading: int | None = None) -> None:
        """Read the obstacle window at the true pose; record it at the believed pose.

        ``heading``: the window just moved one cell that way with the believed
        pose equal to the true one, so only its leading edge can hold news.
        """
        P, R, S = self.P, self.R, self.S
        r0, c0 = self.r + P - R, self.c + P - R
        self.win = self.obst_pad[r0 : r0 + S, c0 : c0 + S]
        win = self.obst_bool[r0 : r0 + S, c0 : c0 + S]
        if self.line_of_sight:  # v1: only what a line from the footprint reaches
            vis = sight.visible(win.ravel(), self._rays).reshape(S, S)
            self.vis = vis.astype(np.float32)
            win = win & vis
            self.win = win.astype(np.float32)
            heading = None
        known = self.kobst[self.br : self.br + S, self.bc : self.bc + S]
        if heading is not None:
            edge = self._edges[heading]
            win, known = win[edge], known[edge]
        fresh = win & ~known
        if fresh.any():
            known |= fresh
            rr, cc = np.nonzero(fresh)
            if heading is not None:
                er, ec = self._edge_cells[heading]
                rr, cc = er[rr], ec[cc]
            rr, cc = rr + self.br - R, cc + self.bc - R
            h, wd = self.scenario.obstacle.shape
            inside = (rr >= 0) & (rr < h) & (cc >= 0) & (cc < wd)
            np.add.at(self.coarse_obst, (rr[inside] // self.bh_, cc[inside] // self.bw_), 1.0)

    def action_masks(self) -> np.ndarray:
        """(3,) bool: which actions are allowed (see "Action masks" above)."""
        R, w = self.R, self.w
        ahead = (
            self.win[R : R + w, R + w],  # east: the column right of the footprint
            self.win[R - 1, R : R + w],  # north: the row above it
            self.win[R : R + w, R - 1],  # west
            self.win[R + w, R : R + w],  # south
        )[self.h]
        return np.array([not ahead.any(), True, True])

    def _obs(self, bump: bool) -> dict:
        S = self.S
        obs = {
            "sensed": self.win.flatten(),
            "swept": self.bswept[self.br : self.br + S, self.bc : self.bc + S].flatten(),
            "pose": np.array([self.br, self.bc, self.h, float(bump)], np.float32),
            "sweep_map": (self.coarse_swept * self.inv_block).ravel(),
            "obstacle_map": (self.coarse_obst * self.inv_block).ravel(),
        }
        if self.line_of_sight:
            obs["known"] = self.vis.flatten()
        return obs

    def _info(self, rewards: tuple[float, float, float], bump: bool) -> dict:
        return step_info(
            self.n_swept,
            self.n_reach,
            self.n_over,
            self.travel,
            self.turns,
            self.bumps,
            self.steps,
            self.w,
            bump,
            rewards,
        )

    # ----------------------------------------------------------------- render
    def render(self) -> np.ndarray | None:
        if self.render_mode != "rgb_array" or self.scenario is None:
            return None
        from motiongym.envs.sweeper.render import draw

        return draw(self, self.cell_pixels)
