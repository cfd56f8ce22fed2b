"""The sweeper's world: its state and dynamics, the only code that reads or writes the grid.

:class:`World` (a :class:`motiongym.envs.core.World`) holds one
:class:`~motiongym.envs.sweeper.state.SweeperState`: ``reset(scene,
rng)`` places the robot and keeps the episode's generator (the odometry
noise draws from it), ``advance(action)`` moves or turns it (sweeping and
sensing) and returns its events, the number of cells it newly swept (a
bump is ``state.bump``); ``action_masks()`` and ``render(size)`` read it.
The environment (:mod:`motiongym.envs.sweeper.env`) wires it to Gymnasium;
what a scenario is, what the reward counts and what the robot observes live
in :mod:`motiongym.envs.sweeper.task`.
"""

from __future__ import annotations

import math

import numpy as np
from gymnasium import spaces

from motiongym.envs.sweeper import occupancy, sight
from motiongym.envs.sweeper.occupancy import DC, DR
from motiongym.envs.sweeper.params import SweeperParams
from motiongym.envs.sweeper.render import frame
from motiongym.envs.sweeper.state import SweeperState
from motiongym.envs.sweeper.task import Scenario

FORWARD, LEFT, RIGHT = 0, 1, 2
MAX_SLIP = 1.4  # longest forward move under slip noise, cells


class World:
    """One sweeper world (see ``SweeperEnv``'s docstring for the rules)."""

    def __init__(self, params: SweeperParams) -> None:
        self.params = params
        self.w, self.R, self.S, self.K = (
            params.robot_width,
            params.sensor_range,
            params.window,
            params.coarse,
        )
        w, S, last = self.w, self.S, self.S - 1
        # Cells entering the footprint on a one-cell move, per heading: (w,) offsets.
        self._enter = [
            np.nonzero(occupancy.entering_mask(int(DR[k]), int(DC[k]), w)) for k in range(4)
        ]
        # The sensing window's leading edge per heading, as slices and cell indices.
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
        self._rays = sight.ray_matrix(w, self.R) if params.line_of_sight else None
        self.action_space: spaces.Space = spaces.Discrete(3)
        # None until reset() (the environment refuses a step or render before it)
        self.state: SweeperState = None  # type: ignore[assignment]
        self._rng: np.random.Generator = None  # type: ignore[assignment]

    @property
    def scene(self) -> Scenario | None:
        """This episode's map and start (None before the first reset)."""
        return None if self.state is None else self.state.scenario

    # ------------------------------------------------------------------ reset
    def reset(self, scene: Scenario, rng: np.random.Generator) -> None:
        """Place the robot at the scenario's start; sweep its footprint; sense.

        ``rng``: the episode's generator (the environment's ``np_random``),
        kept for the odometry noise.
        """
        self._rng = rng
        scenario = scene
        h, wd = scenario.obstacle.shape
        P, K, w = self.R, self.K, self.w
        self._obstacle = np.pad(scenario.obstacle, P, constant_values=True)  # padded, bool
        self._obstacle_f32 = self._obstacle.astype(np.float32)
        self._block = (-(-h // K), -(-wd // K))  # coarse block, cells
        self.inv_block = np.float32(1.0 / (self._block[0] * self._block[1]))
        r, c = scenario.start
        self.state = s = SweeperState(
            scenario=scenario,
            row=r,
            col=c,
            heading=scenario.heading,
            believed_row=r,
            believed_col=c,
            y=float(r),
            x=float(c),
            heading_error=0.0,
            sweeps=np.zeros((h, wd), np.int32),
            believed_swept=np.zeros((h + 2 * P, wd + 2 * P), np.float32),
            known_obstacles=np.zeros((h + 2 * P, wd + 2 * P), bool),
            coarse_swept=np.zeros((K, K), np.float32),
            coarse_obstacles=np.zeros((K, K), np.float32),
            window=self._obstacle_f32[:0, :0],
            visible=None,
            n_reachable=int(scenario.reachable.sum()),
            path=[(r, c)],
        )
        s.sweeps[r : r + w, c : c + w] = 1
        s.n_swept = w * w
        self._mark_believed(np.arange(w).repeat(w) + r, np.tile(np.arange(w), w) + c)
        self._sense()

    # ---------------------------------------------------------------- advance
    def advance(self, action: int) -> int:
        """Apply ``action`` (0 forward, 1 left, 2 right); return the newly swept cells.

        The odometry noise draws from the generator given to :meth:`reset`.
        """
        s, p, rng = self.state, self.params, self._rng
        s.steps += 1
        bump, new = False, 0
        if action == FORWARD:
            new, bump = self._noisy_forward(rng) if p.noisy else self._forward()
        else:
            s.heading = (s.heading + (1 if action == LEFT else -1)) % 4
            s.turns += 1
            if p.noisy:
                s.heading_error += float(rng.normal(0.0, p.heading_noise))
        if action == FORWARD and not bump:  # a turn or a bump leaves the window unchanged
            self._sense(None if p.noisy else s.heading)
        s.bump = bump
        return new

    def _forward(self) -> tuple[int, bool]:
        s = self.state
        h = s.heading
        nr, nc = s.row + int(DR[h]), s.col + int(DC[h])
        if not s.scenario.reach_configs[nr, nc]:
            s.bumps += 1
            return 0, True
        rr, cc = self._enter[h]
        rr, cc = rr + nr, cc + nc
        new = self._sweep_cells(rr, cc)
        s.row, s.col = s.believed_row, s.believed_col = nr, nc
        s.y, s.x = float(nr), float(nc)
        s.travel += 1.0
        s.path.append((nr, nc))
        self._mark_believed(rr, cc)
        return new, False

    def _noisy_forward(self, rng: np.random.Generator) -> tuple[int, bool]:
        s, p, w = self.state, self.params, self.w
        s.heading_error += float(rng.normal(0.0, p.heading_noise)) if p.heading_noise else 0.0
        d = 1.0 + (float(rng.normal(0.0, p.slip_noise)) if p.slip_noise else 0.0)
        d = min(max(d, 0.0), MAX_SLIP)
        angle = s.heading * math.pi / 2 + s.heading_error
        ny, nx = s.y - d * math.sin(angle), s.x + d * math.cos(angle)
        nr, nc = int(round(ny)), int(round(nx))
        dr, dc = nr - s.row, nc - s.col
        reach = s.scenario.reach_configs
        ok = abs(dr) <= 1 and abs(dc) <= 1 and reach[nr, nc]
        if ok and dr and dc:  # no corner cutting through a blocked configuration
            ok = bool(reach[s.row + dr, s.col] or reach[s.row, s.col + dc])
        if not ok:
            s.bumps += 1
            return 0, True
        new = 0
        if dr or dc:
            rr, cc = np.nonzero(occupancy.entering_mask(dr, dc, w))
            new = self._sweep_cells(rr + nr, cc + nc)
            s.row, s.col = nr, nc
            s.path.append((nr, nc))
        s.y, s.x = ny, nx
        s.travel += d
        h, wd = s.scenario.obstacle.shape
        s.believed_row = min(max(s.believed_row + int(DR[s.heading]), 0), h - w)
        s.believed_col = min(max(s.believed_col + int(DC[s.heading]), 0), wd - w)
        rr, cc = self._enter[s.heading]
        self._mark_believed(rr + s.believed_row, cc + s.believed_col)
        return new, False

    def _sweep_cells(self, rr: np.ndarray, cc: np.ndarray) -> int:
        """Sweep the true cells ``(rr, cc)``; return how many were never swept before."""
        s = self.state
        before = s.sweeps[rr, cc]
        s.sweeps[rr, cc] = before + 1
        new = int(np.count_nonzero(before == 0))
        s.n_swept += new
        s.n_overswept += int(np.count_nonzero(before == 1))
        return new

    def _mark_believed(self, rr: np.ndarray, cc: np.ndarray) -> None:
        """Mark cells swept in the robot's own (believed) sweep map and its coarse copy."""
        s, P = self.state, self.R
        fresh = s.believed_swept[rr + P, cc + P] == 0
        if fresh.any():
            rr, cc = rr[fresh], cc[fresh]
            s.believed_swept[rr + P, cc + P] = 1.0
            counts, (bh, bw) = s.coarse_swept, self._block
            for r, c in zip(rr.tolist(), cc.tolist(), strict=True):
                counts[r // bh, c // bw] += 1.0

    def _sense(self, heading: int | None = None) -> None:
        """Read the obstacle window at the true pose; file it at the believed pose.

        ``heading``: the window just moved one cell that way with the believed
        pose equal to the true one, so only its leading edge can hold news
        (v0; line of sight can reveal cells anywhere in the window).
        """
        s, R, S = self.state, self.R, self.S
        r0, c0 = s.row, s.col  # the window's top-left, padded coordinates
        s.window = self._obstacle_f32[r0 : r0 + S, c0 : c0 + S]
        win = self._obstacle[r0 : r0 + S, c0 : c0 + S]
        if self._rays is not None:  # v1: only what a line from the footprint reaches
            vis = sight.visible(win.ravel(), self._rays).reshape(S, S)
            s.visible = vis.astype(np.float32)
            win = win & vis
            s.window = win.astype(np.float32)
            heading = None
        br, bc = s.believed_row, s.believed_col
        known = s.known_obstacles[br : br + S, bc : bc + S]
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
            rr, cc = rr + br - R, cc + bc - R
            h, wd = s.scenario.obstacle.shape
            inside = (rr >= 0) & (rr < h) & (cc >= 0) & (cc < wd)
            bh, bw = self._block
            np.add.at(s.coarse_obstacles, (rr[inside] // bh, cc[inside] // bw), 1.0)

    # ---------------------------------------------------------------- readers
    def action_masks(self) -> np.ndarray:
        """(3,) bool: forward allowed unless the sensed row ahead holds an obstacle."""
        s, R, w = self.state, self.R, self.w
        win = s.window
        ahead = (
            win[R : R + w, R + w],  # east: the column right of the footprint
            win[R - 1, R : R + w],  # north: the row above it
            win[R : R + w, R - 1],  # west
            win[R + w, R : R + w],  # south
        )[s.heading]
        return np.array([not ahead.any(), True, True])

    def render(self, size: tuple[int, int] | None) -> np.ndarray:
        """An RGB frame of the state: ``size`` = (rows, columns), or None for the map at
        ``cell_pixels`` (8) pixels per cell (:func:`~motiongym.envs.sweeper.render.frame`)."""
        return frame(self.state, self.w, size, self.params.cell_pixels)
