"""Spiral-STC: online spanning-tree coverage (Gabriely & Rimon 2002).

Gabriely & Rimon, "Spiral-STC: an on-line coverage algorithm of grid
environments by a mobile robot" (ICRA 2002). The work area is cut into
cells of size ``2D x 2D`` (``D`` the tool's size), each made of four
*sub-cells* of the tool's size. The robot grows a spanning tree of the free
``2D`` cells depth-first as it discovers them and moves along the tree
(circumnavigates it), through sub-cells, so that it covers every sub-cell of
every tree cell once and ends where it started:

- from the cell it is in, it scans the neighbour cells in counterclockwise
  order, starting from the parent cell; the first new free one becomes a
  child (a tree edge) and the robot moves into it; when none is left it
  moves back to the parent;
- the resulting sub-cell path goes round the tree counterclockwise, the
  tree on the robot's left (the paper's Fig. 3-4).

As the move rule of one sub-cell step (:func:`next_step`): a robot in
quadrant ``q`` of cell ``x`` looks across the one side of ``x`` it would
pass next going counterclockwise round ``x``'s centre (from the NE quadrant
north, NW west, SW south, SE east); if a tree edge crosses that side, or
the neighbour there is new and free (the edge is added, the online
step), it steps into the neighbour's quadrant beside the edge, else it steps
to the next quadrant of ``x``. Scanning in that order starts from the parent
(the robot enters a cell beside the edge from its parent) and visits each
neighbour once, as the paper's counterclockwise scan does. The start cell
has no parent: the robot has finished when it is back in the start
quadrant after the start cell's four sides have been looked across.

Our reading on the sweeper's grid (:mod:`.online`, the robot's own map):

- ``D = w`` (the robot is its tool), the cell grid anchored at the start
  configuration: it is the start cell's NW quadrant, or the NE, SW or SE one
  (the first, in that order, whose cell holds no obstacle in the first
  window; the window of ``R >= w`` cells round the footprint covers it).
- A ``2D`` cell is *free* when none of its four sub-cells holds a known
  obstacle and the sub-cell the robot would step into has been seen (a cell
  of it sensed free: not floor hidden behind a wall; it lies ahead of the
  robot in the quadrant that looks across); the others count as free while
  unknown (the sensor reaches ``R`` cells beyond the footprint, less than a
  neighbour cell's far sub-cells). A sub-cell that turns out blocked when
  the robot is to step into it is skipped: the rule goes on without the
  robot to the next free sub-cell of the tour, which it reaches by the
  quadtree transfer (:mod:`.quadtree`). The tree may so hold cells partly
  occupied; every free sub-cell of it is still visited once.
- Spiral-STC covers the free ``2D`` cells only: floor in cells partly
  occupied (along walls not on the grid, in doorways narrower than ``2D``)
  is left (the paper's limit, which its "Full Spiral-STC" addresses;
  docs/experiments/Sweeper-v1.md measures what it leaves).
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field
from typing import Any

from motiongym.baselines.sweeper.belief import FREE
from motiongym.baselines.sweeper.online import Cell, OnlineCoverage, OnlineMemory

NE, NW, SW, SE = 0, 1, 2, 3  # quadrants, in counterclockwise order
OFFSET = {NE: (0, 1), NW: (0, 0), SW: (1, 0), SE: (1, 1)}  # sub-cell (row, col) in a cell
SIDE = {NE: (-1, 0), NW: (0, -1), SW: (1, 0), SE: (0, 1)}  # the side each quadrant looks across
ACROSS = {NE: SE, NW: NE, SW: NW, SE: SW}  # the neighbour's quadrant beside the edge

Mega = tuple[int, int]  # a 2D cell's (row, col) index on the grid


def next_step(x: Mega, q: int, tree: set[frozenset], is_new_free: Any) -> tuple[Mega, int, bool]:
    """One sub-cell step of the circumnavigation: ``(cell, quadrant, grew)``.

    ``tree``: the edges (``frozenset`` of two cells), grown in place;
    ``is_new_free(y)``: whether cell ``y`` is free and not yet in the tree.
    """
    y = (x[0] + SIDE[q][0], x[1] + SIDE[q][1])
    edge = frozenset((x, y))
    if edge in tree:
        return y, ACROSS[q], False
    if is_new_free(y):
        tree.add(edge)
        return y, ACROSS[q], True
    return x, (q + 1) % 4, False


@dataclass
class StcMemory(OnlineMemory):
    origin: Cell | None = None  # cell (0, 0)'s NW sub-cell (a configuration)
    cell: Mega = (0, 0)
    quadrant: int = NW
    start_quadrant: int = NW
    tree: set = field(default_factory=set)
    cells: set = field(default_factory=set)  # cells in the tree
    looked: int = 0  # sides of the start cell looked across
    visits: list = field(default_factory=list)  # (cell, quadrant) the robot stepped into
    skipped: list = field(default_factory=list)  # (cell, quadrant) found blocked


class SpiralStcPolicy(OnlineCoverage):
    """Spiral-STC: grow a spanning tree of free 2D cells online, go round it counterclockwise."""

    def new_memory(self) -> StcMemory:
        return StcMemory(self.new_map())

    def describe(self, memory: Any) -> dict[str, Any]:
        """As :class:`~.online.OnlineCoverage`, plus ``tree`` (edges as pairs of cell
        indices), ``cells`` (the tree's cells), ``visits`` (the sub-cells ``(cell,
        quadrant)`` the robot stepped into, in order; quadrants 0 NE, 1 NW, 2 SW, 3 SE),
        ``skipped`` (sub-cells found blocked) and ``origin`` (cell (0, 0)'s NW
        sub-cell, a configuration)."""
        out = super().describe(memory)
        out["tree"] = sorted(tuple(sorted(e)) for e in memory.tree)
        out["cells"] = sorted(memory.cells)
        out["visits"] = list(memory.visits)
        out["skipped"] = list(memory.skipped)
        out["origin"] = memory.origin
        return out

    def sub_cell(self, m: StcMemory, x: Mega, q: int) -> Cell:
        """The configuration of quadrant ``q`` of cell ``x``."""
        assert m.origin is not None, "set on the first step"
        w = self.w
        return (
            m.origin[0] + 2 * w * x[0] + w * OFFSET[q][0],
            m.origin[1] + 2 * w * x[1] + w * OFFSET[q][1],
        )

    def _cell_free(self, m: StcMemory, y: Mega) -> bool:
        return all(self.free(m, self.sub_cell(m, y, q)) for q in range(4))

    def _start(self, m: StcMemory, r: int, c: int, h: int) -> None:
        m.cell = (0, 0)
        for q in (NW, NE, SW, SE):  # the first alignment whose start cell is free
            dr, dc = OFFSET[q]
            m.origin, m.quadrant = (r - self.w * dr, c - self.w * dc), q
            if self._cell_free(m, (0, 0)):
                break
        m.start_quadrant = m.quadrant
        m.cells.add((0, 0))
        m.visits.append(((0, 0), m.quadrant))
        m.mode = "walk"

    def _walk(self, m: StcMemory, r: int, c: int, h: int) -> None:
        def is_new_free(y: Mega) -> bool:
            if y in m.cells or not self._cell_free(m, y):
                return False
            occ, _ = m.map.footprint(*self.sub_cell(m, y, ACROSS[m.quadrant]))
            return bool((occ == FREE).any())  # seen: not a cell behind a wall

        for _ in range(4 * len(m.cells) + 8):  # skipped sub-cells are stepped over here
            if m.cell == (0, 0):
                if m.looked == 4 and m.quadrant == m.start_quadrant:
                    m.mode = "done"
                    return
                m.looked += 1
            x, q, grew = next_step(m.cell, m.quadrant, m.tree, is_new_free)
            if grew:
                m.cells.add(x)
            m.cell, m.quadrant = x, q
            target = self.sub_cell(m, x, q)
            if not self.free(m, target):
                m.skipped.append((x, q))
                continue
            m.visits.append((x, q))
            if not self._straight(m, (r, c), target):
                k = self.known(m, r, c)
                if not self.transfer(m, k, target):
                    m.skipped.append((x, q))
                    continue
                m.log.append(("transfer", (r, c), target))
            return
        m.mode = "done"  # pragma: no cover - the tour is finite

    def _straight(self, m: StcMemory, here: Cell, target: Cell) -> bool:
        """Set the path to ``target`` along one axis when it is free all the way."""
        dr, dc = target[0] - here[0], target[1] - here[1]
        if dr and dc:
            return False
        n = abs(dr) + abs(dc)
        sr, sc = (dr > 0) - (dr < 0), (dc > 0) - (dc < 0)
        path = [(here[0] + i * sr, here[1] + i * sc) for i in range(1, n + 1)]
        if not all(self.free(m, p) for p in path):
            return False
        m.path = deque(path)
        return True
