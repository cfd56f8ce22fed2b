"""What the classical coverage references share: the robot's own map, paths, A*.

The references (:mod:`.boustrophedon`, :mod:`.ba_star`, :mod:`.spiral_stc`)
sense only what the robot senses: each observation's ``sensed`` / ``known`` /
``swept`` windows are written into a :class:`~.belief.RobotMap` at the
observation's ``pose`` (unknown cells count as free until sensed, as for
PSA + CWA; the window reaches ``R >= 1`` cells ahead, so a move into an
unknown cell is sensed before it is made). They are noise-free references:
under odometry error they trust the dead-reckoned ``pose`` (no localiser).

:class:`OnlineCoverage` is the plumbing: it keeps a path of configurations
(footprint top-left cells) and turns it into actions (turn towards the next
one, then forward), asks the subclass's current mode for a new path or an
action when the path is done, and reports ``mode``, ``done`` and ``log`` in
``diagnostics()``. :func:`astar` is a plain A* over a grid of free
configurations (Hart, Nilsson & Raphael 1968), BA*'s planner; the
transfers between cells and sub-cells use the quadtree of :mod:`.quadtree`.
"""

from __future__ import annotations

import heapq
from collections import deque
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from motiongym.baselines.policy import ScriptedPolicy
from motiongym.baselines.sweeper import psa, quadtree
from motiongym.baselines.sweeper.belief import OBSTACLE, RobotMap
from motiongym.baselines.sweeper.psa_cwa import robot_geometry
from motiongym.baselines.sweeper.steer import DIRECTION, turn_towards
from motiongym.envs.sweeper import occupancy
from motiongym.envs.sweeper.occupancy import DC, DR
from motiongym.envs.sweeper.world import FORWARD, LEFT

MAX_ROUNDS = 64  # mode changes per step before the policy gives up acting on this step

Cell = tuple[int, int]


@dataclass
class OnlineMemory:
    """One episode of a classical reference: its map, its path and its mode."""

    map: RobotMap
    mode: str = "start"
    path: deque = field(default_factory=deque)  # configurations still to visit (map frame)
    started: bool = False
    steps: int = 0
    log: list = field(default_factory=list)  # (kind, from cell, to cell / detail)


@dataclass(frozen=True)
class Known:
    """The robot's map on its explored box: ``occ``/``swept``/``cfree`` indexed from
    map cell ``origin``; ``cur`` the robot's configuration in those indices."""

    origin: Cell
    occ: np.ndarray  # (h, w) int8: -1 unknown, 0 free, 1 obstacle
    swept: np.ndarray  # (h, w) bool
    cfree: np.ndarray  # (h, w) bool: footprint holds no known obstacle
    cur: Cell

    def local(self, cell: Cell) -> Cell:
        return (cell[0] - self.origin[0], cell[1] - self.origin[1])

    def world(self, cell: Cell) -> Cell:
        return (cell[0] + self.origin[0], cell[1] + self.origin[1])

    def inside(self, cell: Cell) -> bool:
        return 0 <= cell[0] < self.cfree.shape[0] and 0 <= cell[1] < self.cfree.shape[1]

    def todo(self) -> np.ndarray:
        """``(h, w)`` bool: cells neither swept nor known obstacle."""
        return (~self.swept) & (self.occ != OBSTACLE)


class OnlineCoverage(ScriptedPolicy):
    """Base of the classical references: subclasses write ``_<mode>(m, r, c, h)`` methods
    that return an action, or None after setting ``m.path`` or ``m.mode``."""

    def __init__(self, observation_space, action_space, env_kwargs=None) -> None:
        super().__init__(observation_space, action_space, env_kwargs)
        self.w, self.R = robot_geometry(observation_space, self.env_kwargs)
        self.pad = 2 * self.w  # unknown cells planned over beyond the explored box

    def new_map(self) -> RobotMap:
        """The robot's empty map for a new episode."""
        return RobotMap(self.w, self.R)

    def new_memory(self) -> Any:
        return OnlineMemory(self.new_map())

    def describe(self, memory: OnlineMemory) -> dict[str, Any]:
        """``mode`` (the algorithm's step), ``done`` (True once it has declared its coverage
        complete) and ``log`` (its decisions so far: ``(kind, from, to)``)."""
        return {"mode": memory.mode, "done": memory.mode == "done", "log": list(memory.log)}

    def act(self, observation: Any, memory: OnlineMemory) -> int:
        m = memory
        m.steps += 1
        r, c, h, bump = m.map.integrate(observation)
        if bump:  # noisy odometry only: the plan no longer matches the floor
            m.path.clear()
        for _ in range(MAX_ROUNDS):
            a = self._follow(m, r, c, h)
            if a is not None:
                return a
            a = getattr(self, "_" + m.mode)(m, r, c, h)
            if a is not None:
                return int(a)
        m.path.clear()
        return LEFT

    def _done(self, m: OnlineMemory, r: int, c: int, h: int) -> int:
        return LEFT  # nothing left that it knows of: turn in place

    def _follow(self, m: OnlineMemory, r: int, c: int, h: int) -> int | None:
        """Turn towards the path's next configuration, then move; None when there is none
        or it is blocked in the map (the mode replans)."""
        while m.path and m.path[0] == (r, c):
            m.path.popleft()
        if not m.path:
            return None
        nr, nc = m.path[0]
        if abs(nr - r) + abs(nc - c) != 1 or not self.free(m, (nr, nc)):
            m.path.clear()
            return None
        d = DIRECTION[(nr - r, nc - c)]
        return FORWARD if d == h else turn_towards(h, d)

    # ------------------------------------------------------------------ map queries
    def free(self, m: OnlineMemory, cfg: Cell) -> bool:
        """The footprint at ``cfg`` holds no known obstacle."""
        occ, _ = m.map.footprint(*cfg)
        return not (occ == OBSTACLE).any()

    def has_work(self, m: OnlineMemory, cfg: Cell) -> bool:
        """The footprint at ``cfg`` holds a cell neither swept nor known obstacle."""
        occ, swept = m.map.footprint(*cfg)
        return bool(((~swept) & (occ != OBSTACLE)).any())

    def known(self, m: OnlineMemory, r: int, c: int) -> Known:
        """The map on the explored box padded by ``pad`` cells of unknown (free) floor, so
        that a slice or a path may run on past what has been sensed."""
        mp, pad = m.map, self.pad
        lo = np.maximum(mp.lo - pad, 0)
        hi = np.minimum(mp.hi + pad, mp.occ.shape[0])
        occ = mp.occ[lo[0] : hi[0], lo[1] : hi[1]]
        swept = mp.swept[lo[0] : hi[0], lo[1] : hi[1]]
        r0, c0 = int(lo[0] - mp.off), int(lo[1] - mp.off)
        cfree = occupancy.config_free(occ == OBSTACLE, self.w)
        cur = (r - r0, c - c0)
        cfree[cur] = True  # the robot stands there, whatever the map says
        return Known((r0, c0), occ, swept, cfree, cur)

    def transfer(self, m: OnlineMemory, k: Known, goal: Cell) -> bool:
        """Plan a point-to-point transfer to ``goal`` (map frame) with the quadtree of
        :mod:`.quadtree` (sweeping the most unswept cells on its way); False if unreachable."""
        g = k.local(goal)
        if not k.inside(g) or not k.cfree[g]:
            return False
        gains = psa.entering_gains(k.todo(), self.w)
        path = quadtree.plan(k.cfree, k.cur, g, gains)
        if path is None:
            return False
        m.path = deque(k.world(p) for p in path)
        return True

    def move_length(self, m: OnlineMemory, cfg: Cell, heading: int, most: int) -> int:
        """How many one-cell moves (up to ``most``) from ``cfg`` in ``heading`` stay free."""
        k = 0
        while k < most and self.free(
            m, (cfg[0] + (k + 1) * int(DR[heading]), cfg[1] + (k + 1) * int(DC[heading]))
        ):
            k += 1
        return k

    def strip_has_work(self, m: OnlineMemory, cfg: Cell, heading: int, k: int) -> bool:
        """Moving ``k`` cells from ``cfg`` in ``heading`` brings an unswept, not-obstacle cell
        under the footprint."""
        if k <= 0:
            return False
        w, o = self.w, m.map.off
        r, c = cfg
        dr, dc = int(DR[heading]), int(DC[heading])
        if dr:
            rows = (r + w, r + w + k) if dr > 0 else (r - k, r)
            cols = (c, c + w)
        else:
            cols = (c + w, c + w + k) if dc > 0 else (c - k, c)
            rows = (r, r + w)
        occ = m.map.occ[rows[0] + o : rows[1] + o, cols[0] + o : cols[1] + o]
        sw = m.map.swept[rows[0] + o : rows[1] + o, cols[0] + o : cols[1] + o]
        return bool(((~sw) & (occ != OBSTACLE)).any())

    def nearest_leftover(self, k: Known) -> Cell | None:
        """The reachable configuration nearest to the robot (moves) whose footprint holds
        unswept floor of the map, in map frame; None when the map holds none."""
        reach = occupancy.reachable_configs(k.cfree, k.cur)
        goal = reach & (occupancy.box_sum(k.todo().astype(np.int64), self.w) > 0)
        if not goal.any():
            return None
        dist = occupancy.bfs_distance(k.cfree, k.cur)
        d = np.where(goal & (dist >= 0), dist, np.iinfo(np.int64).max)
        return k.world(divmod(int(np.argmin(d)), d.shape[1]))


def astar(free: np.ndarray, start: Cell, goal: Cell) -> list[Cell] | None:
    """A shortest 4-connected path over ``free`` from ``start`` (excluded) to ``goal``, by A*
    with the Manhattan distance as heuristic (admissible on unit moves); None if none.

    Ties in ``f`` are broken towards the larger ``g`` (deeper nodes first), then by
    insertion order, so the search is deterministic.
    """
    if not free[goal]:
        return None
    h, w = free.shape
    g_cost = {start: 0}
    parent: dict[Cell, Cell] = {}
    count = 0
    heap = [(abs(start[0] - goal[0]) + abs(start[1] - goal[1]), 0, count, start)]
    closed: set[Cell] = set()
    while heap:
        _, neg_g, _, u = heapq.heappop(heap)
        if u in closed:
            continue
        if u == goal:
            path = [u]
            while path[-1] != start:
                path.append(parent[path[-1]])
            return path[-2::-1]
        closed.add(u)
        for k in range(4):
            v = (u[0] + int(DR[k]), u[1] + int(DC[k]))
            if not (0 <= v[0] < h and 0 <= v[1] < w) or not free[v] or v in closed:
                continue
            g = -neg_g + 1
            if g < g_cost.get(v, 1 << 60):
                g_cost[v], parent[v] = g, u
                count += 1
                f = g + abs(v[0] - goal[0]) + abs(v[1] - goal[1])
                heapq.heappush(heap, (f, -g, count, v))
    return None
