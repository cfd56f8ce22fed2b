"""BA*: boustrophedon motions and A* to the best backtracking point (Viet et al. 2013).

Viet, Dang, Laskar & Chung, "BA*: an online complete coverage algorithm for
cleaning robots" (Applied Intelligence 38, 2013). The robot builds its model
``M`` of robot-size tiles online and repeats, until no backtracking point is
left:

1. **Boustrophedon motion** (the paper's Algorithm 1, BM): from the current
   tile, move to the neighbour tile that is free and not covered, checking
   north, south, east, west in that order; go on until a *critical point*:
   no such neighbour (:func:`bm_direction`).
2. **Backtracking list** ``L`` (eq. 2-3): the covered tiles ``s`` with
   ``b(s) >= 1``, where over ``s``'s eight neighbours ``s1 .. s8`` (east,
   north-east, north, north-west, west, south-west, south, south-east)
   ``b(s) = mu(s1,s8) + mu(s1,s2) + mu(s5,s6) + mu(s5,s4) + mu(s7,s6) +
   mu(s7,s8)`` and ``mu(a, b) = 1`` when ``a`` is free and not covered and
   ``b`` is blocked (obstacle or covered), else 0 (:func:`b_value`): corners
   where a new boustrophedon region can start.
3. **The best backtracking point** ``s_sp = argmin_{s in L} f(s, s_cp)``
   (eq. 4), ``f`` the distance from the critical point ``s_cp`` (here moves
   in the map).
4. **A*** from ``s_cp`` to ``s_sp`` over the known free tiles, then **path
   smoothing** (the paper's A*SPS: a waypoint is dropped while the next one
   is in line of sight, :func:`smooth`), follow it, and start BM again.

Our reading on the sweeper's grid (the robot moves one cell at a time; the
model is the robot's own map at cell resolution, :mod:`.online`):

- A *tile* is a robot configuration the robot stopped at; its axis
  neighbour in heading ``d`` is the configuration up to ``w`` cells on (fewer
  where a wall is nearer: the tile that hugs it), *free and not covered*
  when the move is free in the map and brings unswept floor under the
  footprint; a diagonal neighbour is the configuration ``w`` cells on in both
  axes, free and not covered when its footprint is free in the map and holds
  unswept floor. The tiles' model ``M`` is the set of stops.
- Line of sight on the grid: the robot moves on the grid's axes, so the
  smoothed path joins two waypoints by a free L-shaped run (one turn at
  most) where the A* path had a staircase; never longer (A*'s path is
  shortest), with fewer turns.
- Completeness (ours): when ``L`` is empty but a stop still has a free,
  uncovered axis neighbour (a region that ``b``'s corner test does not see,
  e.g. a strip narrower than a tile), that stop is a backtracking point; and
  when no stop has one, the nearest configuration holding reachable unswept
  floor is (logged ``leftover``). The policy declares itself done when the
  map holds no reachable unswept floor.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from motiongym.baselines.sweeper.online import Cell, Known, OnlineCoverage, OnlineMemory, astar
from motiongym.envs.sweeper import occupancy
from motiongym.envs.sweeper.occupancy import DC, DR

EAST, NORTH, WEST, SOUTH = 0, 1, 2, 3
BM_ORDER = (NORTH, SOUTH, EAST, WEST)  # the paper's priority
# s1 .. s8 as (row, column) steps in tiles
NEIGHBOURS = ((0, 1), (-1, 1), (-1, 0), (-1, -1), (0, -1), (1, -1), (1, 0), (1, 1))


def b_value(free: tuple[bool, ...]) -> int:
    """Eq. 3: ``b(s)`` from whether each of ``s1 .. s8`` is free and not covered."""
    s = (None, *free)  # 1-based, as in the paper

    def mu(a: int, b: int) -> int:
        return int(bool(s[a]) and not s[b])

    return mu(1, 8) + mu(1, 2) + mu(5, 6) + mu(5, 4) + mu(7, 6) + mu(7, 8)


def bm_direction(free: dict[int, bool]) -> int | None:
    """Algorithm 1's choice: the first of north, south, east, west whose neighbour tile is
    free and not covered; None at a critical point."""
    for d in BM_ORDER:
        if free.get(d):
            return d
    return None


def smooth(path: list[Cell], start: Cell, free: np.ndarray) -> list[Cell]:
    """The A* path ``start -> path`` with staircases replaced by L-shaped runs.

    From each kept waypoint, the next one kept is the furthest along the path
    that a free L-shaped run (rows first or columns first, at most one turn)
    joins to it (the grid's line of sight). Returns the cells from ``start``
    (excluded), as long as ``path`` when ``path`` is a shortest one.
    """
    points = [start, *path]
    out: list[Cell] = []
    i = 0
    while i < len(points) - 1:
        best: list[Cell] | None = None
        for j in range(i + 1, len(points)):
            run = _l_run(points[i], points[j], free)
            if run is None:
                break
            best = run
        assert best is not None, "consecutive path cells are neighbours"
        out += best
        i = points.index(best[-1], i + 1)
    return out


def _l_run(p: Cell, q: Cell, free: np.ndarray) -> list[Cell] | None:
    for rows_first in (False, True):
        run, (r, c) = [], p
        for axis in ("r", "c") if rows_first else ("c", "r"):
            while (r if axis == "r" else c) != (q[0] if axis == "r" else q[1]):
                if axis == "r":
                    r += 1 if q[0] > r else -1
                else:
                    c += 1 if q[1] > c else -1
                run.append((r, c))
        if all(free[x] for x in run):
            return run
    return None


@dataclass
class BaStarMemory(OnlineMemory):
    stops: list = field(default_factory=list)  # the tiles covered (configurations stopped at)
    stop_set: set = field(default_factory=set)
    backtracks: list = field(default_factory=list)  # (critical point, L, chosen, A*, smoothed)


class BaStarPolicy(OnlineCoverage):
    """BA*: boustrophedon motions, backtracking to the nearest corner left, A* and smoothing."""

    def new_memory(self) -> BaStarMemory:
        return BaStarMemory(self.new_map())

    def describe(self, memory: Any) -> dict[str, Any]:
        """As :class:`~.online.OnlineCoverage`, plus ``backtracks``: per critical point,
        ``(critical point, L, chosen point, A* length, smoothed path)`` (``L`` the
        backtracking list, empty where the completeness fallback chose)."""
        out = super().describe(memory)
        out["backtracks"] = list(memory.backtracks)
        return out

    def _start(self, m: BaStarMemory, r: int, c: int, h: int) -> None:
        m.mode = "bm"

    def _axis_free(self, m: OnlineMemory, p: Cell, d: int) -> bool:
        k = self.move_length(m, p, d, self.w)
        return self.strip_has_work(m, p, d, k)

    def _neighbours_free(self, m: OnlineMemory, p: Cell) -> tuple[bool, ...]:
        out = []
        for dr, dc in NEIGHBOURS:
            if dr and dc:
                q = (p[0] + dr * self.w, p[1] + dc * self.w)
                out.append(self.free(m, q) and self.has_work(m, q))
            else:
                d = {(0, 1): EAST, (-1, 0): NORTH, (0, -1): WEST, (1, 0): SOUTH}[(dr, dc)]
                out.append(self._axis_free(m, p, d))
        return tuple(out)

    def _bm(self, m: BaStarMemory, r: int, c: int, h: int) -> None:
        p = (r, c)
        if p not in m.stop_set:
            m.stop_set.add(p)
            m.stops.append(p)
        d = bm_direction({d: self._axis_free(m, p, d) for d in BM_ORDER})
        if d is None:
            m.mode = "backtrack"
            return
        k = self.move_length(m, p, d, self.w)
        m.path = deque((r + i * int(DR[d]), c + i * int(DC[d])) for i in range(1, k + 1))

    def _backtrack(self, m: BaStarMemory, r: int, c: int, h: int) -> None:
        k = self.known(m, r, c)
        dist = occupancy.bfs_distance(k.cfree, k.cur)
        big = np.iinfo(np.int64).max

        def reach(s: Cell) -> int:
            q = k.local(s)
            return int(dist[q]) if k.inside(q) and dist[q] >= 0 else big

        stops = [s for s in m.stops if reach(s) < big]
        backtracking = [s for s in stops if b_value(self._neighbours_free(m, s)) >= 1]
        candidates = backtracking or [
            s for s in stops if any(self._axis_free(m, s, d) for d in BM_ORDER)
        ]
        if candidates:
            target = min(candidates, key=reach)  # eq. 4, ties: the earliest stop
            kind = "backtrack"
        else:
            left = self.nearest_leftover(k)
            if left is None:
                m.mode = "done"
                return
            target, kind = left, "leftover"
        self._go(m, k, (r, c), target, backtracking, kind)

    def _go(self, m: BaStarMemory, k: Known, here: Cell, target: Cell, L: list, kind: str) -> None:
        m.mode = "bm"
        if target == here:
            return
        raw = astar(k.cfree, k.cur, k.local(target))
        assert raw is not None, "the target was reached by the distance transform"
        path = smooth(raw, k.cur, k.cfree)
        m.path = deque(k.world(p) for p in path)
        m.backtracks.append((here, list(L), target, len(raw), list(m.path)))
        m.log.append((kind, here, target))
