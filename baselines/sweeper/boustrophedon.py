"""Boustrophedon cellular decomposition, online (Choset & Pignon 1997; Choset 2000).

Choset & Pignon, "Coverage path planning: the boustrophedon cellular
decomposition" (FSR 1997), and Choset, "Coverage of known spaces: the
boustrophedon cellular decomposition" (Autonomous Robots 9, 2000): a slice
(here a column of robot configurations, the sweep line vertical) swept across
the free space changes connectivity only at *critical points* of the obstacle
boundaries; between two critical points the slices form a *cell*, covered by
boustrophedon lanes (back-and-forth motions along the slice); the cells and
their adjacency (the Reeb graph) are visited one after the other, moving
between cells through the free space. At an IN critical point one slice
interval splits into two (a cell ends, two begin); at an OUT critical point
two intervals merge into one (two cells end, one begins).

Online variant (Acar & Choset 2002, "Sensor-based coverage of unknown
environments", IJRR 21: cells discovered as critical points are sensed),
on the robot's own map (:mod:`.online`): nothing is known in advance and the
slices are read from what has been sensed, unknown cells counting as free.

- **Slices.** A slice is a column of configurations (footprint top-left
  cells); its *intervals* are its runs of configurations free in the map.
- **Lanes.** Lanes run north-south, wall to wall: a lane ends where the next
  configuration holds a known obstacle (the cell's floor or ceiling). The
  next lane lies ``w`` columns on (less where a wall is nearer, the last lane
  hugging it), in the cell's sweep direction (east or west), and runs the
  other way: lanes alternate direction inside a cell. It starts at the end
  of the next interval nearer the robot, so a ceiling that rises between
  lanes is swept from its top.
- **Critical points** (:func:`next_slice`), checked at each lane's end from
  the map as sensed then: the next slice's intervals that overlap the lane's
  interval are ``J1..Jn``; none: the cell is closed on that side; two or more:
  a split (IN), the cell ends and each ``Ji`` opens a new cell; one, ``J``,
  overlapping two or more intervals of the lane's slice: a merge (OUT), the
  cell ends and ``J`` opens a new cell; else the cell goes on into ``J``.
- **Behind a cell's first lane**: the intervals of the slice behind it that
  overlap the lane and hold unswept floor open cells swept the other way (the
  side of the start and the other branch of a merge: Acar & Choset's robot
  finds them the same way, from the critical point's other side).
- **Travel between cells.** Open cells wait in a list; the next one is the
  nearest (moves in the map) that still holds unswept floor, reached with
  the quadtree transfer (:mod:`.quadtree`, A* over free squares), entered at
  the point of its interval nearest the lane that opened it; its first move
  runs to the nearer end of its interval.
- **Our choice, completeness.** Lanes sample the slices every ``w`` columns,
  so a critical point lying between two lanes (a notch narrower than ``w``)
  can be stepped over. When no open cell is left, the map is scanned for
  reachable unswept floor and, if any, a cell is opened at the nearest
  (logged ``leftover``); the policy declares itself done when there is none.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from motiongym.baselines.sweeper.online import Cell, Known, OnlineCoverage, OnlineMemory
from motiongym.baselines.sweeper.steer import turn_towards
from motiongym.envs.sweeper import occupancy
from motiongym.envs.sweeper.occupancy import DC, DR
from motiongym.envs.sweeper.world import FORWARD

EAST, NORTH, WEST, SOUTH = 0, 1, 2, 3

Interval = tuple[int, int]  # first and last row of a run of free configurations


def intervals(column: np.ndarray) -> list[Interval]:
    """The runs of True in a 1-D bool array, as ``(first, last)`` indices."""
    padded = np.concatenate([[False], column.astype(bool), [False]])
    edges = np.flatnonzero(np.diff(padded.astype(np.int8)))
    return [(int(a), int(b) - 1) for a, b in zip(edges[::2], edges[1::2], strict=True)]


def _overlap(a: Interval, b: Interval) -> bool:
    return a[0] <= b[1] and b[0] <= a[1]


def interval_at(column: np.ndarray, row: int) -> Interval | None:
    """The run of True in ``column`` holding ``row`` (None if ``column[row]`` is False)."""
    for run in intervals(column):
        if run[0] <= row <= run[1]:
            return run
    return None


def next_slice(
    cfree: np.ndarray, col: int, lane: Interval, dx: int, w: int
) -> tuple[str, int, list[Interval]]:
    """The critical-point test at a lane's end: ``(event, k, J)``.

    ``cfree``: free configurations; ``lane``: the interval of slice ``col``
    the lane swept; ``dx``: +1 (sweeping east) or -1 (west). The next slice is
    ``col + k * dx`` for the largest ``k <= w`` whose intervals overlap the
    lane's (``J``, top to bottom). ``event``: ``"closed"`` (no such slice,
    ``k = 0``), ``"split"`` (two or more), ``"merge"`` (one, overlapping two or
    more intervals of slice ``col``) or ``"continue"``. At a split or a merge
    ``k`` is then the smallest at which the same event is seen: the new cells
    start at the first slice past the critical point.
    """
    for k in range(w, 0, -1):
        c2 = col + k * dx
        if not 0 <= c2 < cfree.shape[1]:
            continue
        js = [j for j in intervals(cfree[:, c2]) if _overlap(j, lane)]
        if js:
            break
    else:
        return "closed", 0, []
    event = _event(cfree, col, lane, js)
    if event in ("split", "merge"):  # the new cells start at the first slice past the point
        for k2 in range(1, k):
            js2 = [j for j in intervals(cfree[:, col + k2 * dx]) if _overlap(j, lane)]
            if js2 and _event(cfree, col, lane, js2) == event:
                return event, k2, js2
    return event, k, js


def _event(cfree: np.ndarray, col: int, lane: Interval, js: list[Interval]) -> str:
    if len(js) >= 2:
        return "split"
    back = [i for i in intervals(cfree[:, col]) if _overlap(i, js[0])]
    return "merge" if len(back) >= 2 else "continue"


@dataclass
class BcdMemory(OnlineMemory):
    sweep: int = EAST  # the cell's sweep direction (EAST or WEST)
    lane_heading: int = NORTH
    approach: bool = True  # the move to the interval's end before the cell's first lane
    first_lane: bool = True
    lane_start: Cell | None = None
    cell: int = -1  # index into cells of the cell being swept
    cells: list = field(default_factory=list)  # (event, column, interval, sweep) per cell
    lanes: list = field(default_factory=list)  # (cell, column, heading, from row, to row)
    pending: list = field(default_factory=list)  # (config, sweep, event): cells to visit


class BoustrophedonPolicy(OnlineCoverage):
    """Online boustrophedon cellular decomposition: lanes in cells opened at critical points."""

    def new_memory(self) -> BcdMemory:
        return BcdMemory(self.new_map())

    def describe(self, memory: Any) -> dict[str, Any]:
        """As :class:`~.online.OnlineCoverage`, plus ``cells`` (``(event, column,
        interval, sweep)``: how each cell was opened: ``start``, ``split``, ``merge``,
        ``behind`` or ``leftover``) and ``lanes`` (``(cell, column, heading, from row,
        to row)``)."""
        out = super().describe(memory)
        out["cells"] = list(memory.cells)
        out["lanes"] = list(memory.lanes)
        return out

    # ------------------------------------------------------------------ modes
    def _start(self, m: BcdMemory, r: int, c: int, h: int) -> None:
        m.pending.append(((r, c), EAST, "start"))
        m.mode = "next_cell"

    def _next_cell(self, m: BcdMemory, r: int, c: int, h: int) -> None:
        k = self.known(m, r, c)
        dist = occupancy.bfs_distance(k.cfree, k.cur)
        best = None
        for i, (cfg, _, _) in enumerate(m.pending):
            p = k.local(cfg)
            if not k.inside(p) or dist[p] < 0 or not self._slice_has_work(k, p):
                continue
            if best is None or dist[p] < best[0]:
                best = (int(dist[p]), i)
        if best is None:
            m.pending.clear()
            left = self.nearest_leftover(k)
            if left is None:
                m.mode = "done"
                return
            m.pending.append((left, EAST, "leftover"))
            return
        cfg, sweep, event = m.pending.pop(best[1])
        column = k.cfree[:, k.local(cfg)[1]]
        lo, hi = interval_at(column, k.local(cfg)[0]) or (k.local(cfg)[0],) * 2
        m.cells.append((event, cfg[1], (lo + k.origin[0], hi + k.origin[0]), sweep))
        m.cell, m.sweep, m.mode = len(m.cells) - 1, sweep, "enter"
        m.log.append(("cell", (r, c), cfg))
        if (r, c) != cfg:
            self.transfer(m, k, cfg)

    def _enter(self, m: BcdMemory, r: int, c: int, h: int) -> None:
        k = self.known(m, r, c)
        run = interval_at(k.cfree[:, k.cur[1]], k.cur[0])
        assert run is not None, "the robot stands on a free configuration"
        up, down = k.cur[0] - run[0], run[1] - k.cur[0]
        m.lane_heading = NORTH if up <= down else SOUTH
        m.approach, m.first_lane, m.mode = True, True, "lane"

    def _lane(self, m: BcdMemory, r: int, c: int, h: int) -> int | None:
        heading = m.lane_heading
        if self.free(m, (r + int(DR[heading]), c + int(DC[heading]))):
            if m.lane_start is None and not m.approach:
                m.lane_start = (r, c)
            return FORWARD if h == heading else turn_towards(h, heading)
        if m.approach:  # at the interval's end: the cell's first lane starts here
            m.approach, m.lane_start = False, None
            m.lane_heading = (heading + 2) % 4
            return None
        if m.lane_start is None:
            m.lane_start = (r, c)
            if self.free(m, (r + int(DR[heading]), c + int(DC[heading]))):
                return None
        m.lanes.append((m.cell, c, heading, m.lane_start[0], r))
        k = self.known(m, r, c)
        run = interval_at(k.cfree[:, k.cur[1]], k.cur[0])
        assert run is not None, "the robot stands on a free configuration"
        if m.first_lane:
            m.first_lane = False
            self._open_behind(m, k, run)
        dx = 1 if m.sweep == EAST else -1
        event, step, js = next_slice(k.cfree, k.cur[1], run, dx, self.w)
        if event == "continue":
            j = js[0]
            row = j[0] if heading == NORTH else j[1]
            target = k.world((row, k.cur[1] + step * dx))
            if self._slice_has_work(k, k.local(target)) and self.transfer(m, k, target):
                m.lane_heading, m.lane_start = (heading + 2) % 4, None
                m.log.append(("shift", (r, c), target))
                return None
        for j in js if event in ("split", "merge") else []:
            row = min(max(k.cur[0], j[0]), j[1])
            m.pending.append((k.world((row, k.cur[1] + step * dx)), m.sweep, event))
        m.mode = "next_cell"
        return None

    def _open_behind(self, m: BcdMemory, k: Known, run: tuple[int, int]) -> None:
        """Open cells behind the cell's first lane, swept the other way."""
        dx = -1 if m.sweep == EAST else 1
        _, step, js = next_slice(k.cfree, k.cur[1], run, dx, self.w)
        for j in js:
            row = min(max(k.cur[0], j[0]), j[1])
            p = (row, k.cur[1] + step * dx)
            if self._slice_has_work(k, p):
                m.pending.append((k.world(p), (m.sweep + 2) % 4, "behind"))

    def _slice_has_work(self, k: Known, p: Cell) -> bool:
        """The interval of slice ``p[1]`` holding ``p`` covers unswept floor."""
        if not k.cfree[p]:
            return False
        run = interval_at(k.cfree[:, p[1]], p[0])
        assert run is not None
        todo = k.todo()[run[0] : run[1] + self.w, p[1] : p[1] + self.w]
        return bool(todo.any())
