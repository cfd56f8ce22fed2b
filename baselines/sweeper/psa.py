"""Plane Sweeping Algorithm with a LIFO stack (paper section 3.1, Fig. 3-5).

PSA, as the paper states it:

1. Move straight, sweeping, until an obstacle or a wall blocks the robot.
2. Alongside the segment just travelled, consider a virtual segment on each
   side, one sweeping width away.
3. If a side segment holds cells not yet swept, push its start point on a
   stack.
4. At the blocking point shift one sweeping width to the right or the left,
   alternating, reverse the heading and go on (a boustrophedon). When no
   shift is possible, pop the stack (LIFO: the latest point is usually the
   nearest one), skip points already swept according to the sweep map, move
   there (point-to-point transfer, :mod:`.quadtree`) and restart PSA; stop
   when the stack is empty.

Choices where the paper is open (documented and tested):

- A lane also ends where the cells ahead are all swept already (the sweep
  map is consulted, as in step 3): otherwise a restarted run would re-sweep
  finished lanes until a wall.
- "Right or left, alternating" relative to the heading is a constant side in
  the map frame: the run's *shift side*. The first run shifts to the right of
  the start heading; a run restarted from a popped segment shifts away from
  the lane that pushed it. The alternation starts at the run's first shift:
  where that side is closed at the end of the run's first lane (a wall right
  beside it) or holds nothing to sweep, the run shifts to the other side and
  keeps that side. (Without this, a robot started along a wall ended its
  first run after one lane and left the open side to the stack's bottom.)
- A shift moves up to one sweeping width; a shorter shift (a wall nearer than
  ``w``) is still a shift. The run ends when no shift cell is free or the new
  lane holds nothing to sweep.
- Where the segment one width away is blocked (a strip narrower than the
  robot between the lane and a wall), the segment is moved back towards the
  lane, one cell at a time, until a configuration along it is free.
- Steps 2-3 also look *behind* a lane that starts after a shift: where the
  lane before it was blocked sooner (a cupboard's corner), the new lane's
  extension backwards, in line with it, lies beside no lane, and neither
  side segment holds it (:func:`behind_segment`). That segment, over the
  configurations behind the lane known to be free and as long as the lane
  before, is pushed when it holds unswept cells. (Without it such a strip,
  one robot width wide along a wall, was left to CWA's scan, which found it
  after the whole stack, usually from the far side of the map.) Only a
  run's later lanes look behind, not its first one.
- A pushed entry keeps its whole side segment (start, heading, length, side):
  on popping, the restart point is the end of the segment's still-unswept
  part that is nearer to the robot (the paper's "start point" taken from
  whichever end the robot reaches first, in the spirit of its LIFO choice:
  the nearest point first), and the run sweeps towards the other end. When
  only the start point is stored, a segment whose start was swept later but
  whose far end was not would be skipped.
- A popped segment that yields a restart point goes back on the stack, under
  everything the new run pushes: the paper pushes a point "when the side
  segment holds unswept cells", and after the run the segment may still hold
  some (its unswept part was cut by an obstacle or by swept floor, and the
  run sweeps only the piece it started on). It is popped again, LIFO, once
  the new run's own segments are done, and skipped when swept. Each restart
  sweeps at least the cell that made its point a target, so this ends.
  (Dropping the segment lost those pieces until CWA's scan found them,
  usually from the far side of the map.)
- LIFO by runs: every entry carries the run that pushed it, and a pop takes,
  among the entries of the latest run still on the stack, the one whose
  restart point is nearest (grid distance in the known map); older runs'
  entries wait, in LIFO order, until that run's entries are done or stale.
  The paper prefers a stack because "the point taken from it is likely near
  where the previous sweep ended"; the order in which one run pushed its
  segments says nothing about which is nearer at the run's end (a run of
  lanes pushes its entries along its length, and ends at one end of it).
- The heading of a run restarted at a popped point (section 3.1 does not
  say): along the popped segment, as the lane that pushed it ran, unless
  lanes across cost less for the unswept stretch at the restart point
  (:func:`restart_heading`, :func:`sweep_cost`: ``ceil(across / w)`` lanes,
  so a corridor 7 cells wide is swept in lanes across it, each of which
  sweeps fresh floor, rather than in three lanes along it that sweep 9
  rows for 7). The restart heading is a local estimate: lanes turned
  across one strip run on into the side corridors they meet. It is on by
  default; ``PsaCwaPolicy.restart_axis`` switches it.

The travel each of these choices saves (or costs) is measured in
``docs/experiments/Sweeper-v0.md``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from motiongym.envs.sweeper.occupancy import DC, DR, box_sum


@dataclass(frozen=True)
class Segment:
    """A virtual side segment pushed on the PSA stack."""

    start: tuple[int, int]  # configuration (footprint top-left cell), map frame
    heading: int  # direction of travel along the segment (0 E, 1 N, 2 W, 3 S)
    length: int  # configurations along it, start included
    side: int  # the heading pointing away from the lane that pushed it


def left_of(heading: int) -> int:
    return (heading + 1) % 4


def right_of(heading: int) -> int:
    return (heading + 3) % 4


def side_segments(
    start: tuple[int, int], end: tuple[int, int], heading: int, w: int
) -> list[Segment]:
    """Step 2: the two virtual segments one sweeping width beside the lane ``start -> end``."""
    length = abs(end[0] - start[0]) + abs(end[1] - start[1]) + 1
    out = []
    for side in (left_of(heading), right_of(heading)):
        s = (start[0] + w * int(DR[side]), start[1] + w * int(DC[side]))
        out.append(Segment(s, heading, length, side))
    return out


def behind_segment(start: tuple[int, int], heading: int, length: int, side: int) -> Segment:
    """The virtual segment in line behind a lane that starts at ``start`` in ``heading``."""
    back = (heading + 2) % 4
    first = (start[0] + int(DR[back]), start[1] + int(DC[back]))
    return Segment(first, back, length, side)


def toward_lane(seg: Segment, j: int) -> Segment:
    """``seg`` moved ``j`` cells back towards the lane that pushed it.

    A strip narrower than the robot between the lane and a wall cannot be
    reached one full width away; the robot sweeps it from a position
    overlapping the lane instead.
    """
    back = (seg.side + 2) % 4
    start = (seg.start[0] + j * int(DR[back]), seg.start[1] + j * int(DC[back]))
    return Segment(start, seg.heading, seg.length, seg.side)


def segment_configs(seg: Segment) -> tuple[np.ndarray, np.ndarray]:
    """Rows and columns of the configurations along ``seg``: ``(length,)`` each."""
    k = np.arange(seg.length)
    return seg.start[0] + k * int(DR[seg.heading]), seg.start[1] + k * int(DC[seg.heading])


def covers_unswept(occ: np.ndarray, swept: np.ndarray, w: int, at_least: int = 1) -> np.ndarray:
    """``(H, W)`` bool: configurations whose footprint holds ``at_least`` cells neither
    swept nor obstacle."""
    todo = (~swept) & (occ != 1)
    return box_sum(todo.astype(np.int64), w) >= at_least


def entering_gains(todo: np.ndarray, w: int) -> np.ndarray:
    """``(4, H, W)`` int: ``todo`` cells entering the footprint when the robot moves
    into configuration ``(r, c)`` in heading ``k`` (0 E, 1 N, 2 W, 3 S)."""
    h, wd = todo.shape
    pad = np.zeros((h + w, wd + w), np.int64)
    pad[:h, :wd] = todo
    col = np.zeros((h + 1, wd + w), np.int64)  # col[r, c]: todo in pad[r : r + w, c]
    row = np.zeros((h + w, wd + 1), np.int64)  # row[r, c]: todo in pad[r, c : c + w]
    cs = np.vstack([np.zeros((1, wd + w), np.int64), pad.cumsum(0)])
    col[:, :] = cs[w : w + h + 1] - cs[: h + 1]
    rs = np.hstack([np.zeros((h + w, 1), np.int64), pad.cumsum(1)])
    row[:, :] = rs[:, w : w + wd + 1] - rs[:, : wd + 1]
    out = np.empty((4, h, wd), np.int64)
    out[0] = col[:h, w - 1 : w - 1 + wd]  # east: the column at c + w - 1
    out[1] = row[:h, :wd]  # north: the row r
    out[2] = col[:h, :wd]  # west: the column c
    out[3] = row[w - 1 : w - 1 + h, :wd]  # south: the row r + w - 1
    return out


def first_target(
    seg: Segment,
    origin: tuple[int, int],
    cfree: np.ndarray,
    todo_cfg: np.ndarray,
    dist: np.ndarray | None = None,
) -> tuple[tuple[int, int], int] | None:
    """Step 3 on popping: where along ``seg`` to restart, and the heading to sweep in.

    ``cfree`` / ``todo_cfg``: configurations free in the known map / covering
    unswept cells, as arrays whose cell ``[0, 0]`` is map cell ``origin``.
    The candidates are the first and the last configuration along the
    segment that are free and cover an unswept cell; with ``dist`` (grid
    distances from the robot) the nearer one is taken and the run heads
    towards the other, else the first one with the segment's heading.
    Returns ``((row, col), heading)`` in the map frame, or None.
    """
    rr, cc = segment_configs(seg)
    rr, cc = rr - origin[0], cc - origin[1]
    h, wd = cfree.shape
    inside = (rr >= 0) & (rr < h) & (cc >= 0) & (cc < wd)
    rr, cc = rr[inside], cc[inside]
    ok = cfree[rr, cc] & todo_cfg[rr, cc]
    if not ok.any():
        return None
    idx = np.flatnonzero(ok)
    first, last = int(idx[0]), int(idx[-1])
    k, heading = first, seg.heading
    if dist is not None and 0 <= dist[rr[last], cc[last]] < dist[rr[first], cc[first]]:
        k, heading = last, (seg.heading + 2) % 4
    return (int(rr[k] + origin[0]), int(cc[k] + origin[1])), heading


def lane_open(occ_fp_next: np.ndarray, swept_edge: np.ndarray) -> bool:
    """Step 1: the next configuration has no known obstacle and brings an unswept cell."""
    return not (occ_fp_next == 1).any() and not swept_edge.all()


def stretches(todo: np.ndarray, cfg: tuple[int, int]) -> tuple[int, ...]:  # 4 values
    """Per heading (E, N, W, S): how many ``todo`` configurations follow ``cfg`` in a row."""
    h, wd = todo.shape
    out = []
    for k in range(4):
        n, (r, c) = 0, cfg
        while True:
            r, c = r + int(DR[k]), c + int(DC[k])
            if not (0 <= r < h and 0 <= c < wd and todo[r, c]):
                break
            n += 1
        out.append(n)
    return tuple(out)


def sweep_cost(along: int, across: int, w: int) -> int:
    """Travel of a boustrophedon over an ``along x across`` rectangle of cells, lanes ``along``.

    ``ceil(across / w)`` lanes of ``along - w`` moves each, joined by shifts
    summing to ``across - w`` moves. Lanes across a 7-cell corridor (``w = 3``)
    cost 3 lanes' worth less than along it: three lanes along it sweep 9
    rows for 7.
    """
    return -(-across // w) * max(along - w, 0) + max(across - w, 0)


def restart_heading(stretch: tuple[int, ...], heading: int, side: int, w: int):
    """The heading and shift side a run restarted at a popped point sweeps with.

    ``stretch[k]``: configurations covering unswept cells met in a row from
    the restart point going in heading ``k`` (0 E, 1 N, 2 W, 3 S). The
    region is taken as the rectangle these stretches span, in cells; the
    lanes keep the segment's axis (``heading``, ``side``) unless lanes
    along the other axis cost less by :func:`sweep_cost`, in which case the
    run heads the longer way along that axis and shifts to the longer side.
    """
    extent = (stretch[0] + stretch[2] + w, stretch[1] + stretch[3] + w)  # cells E-W, N-S
    axis = heading % 2
    if sweep_cost(extent[1 - axis], extent[axis], w) >= sweep_cost(
        extent[axis], extent[1 - axis], w
    ):
        return heading, side
    new = max((1 - axis, 3 - axis), key=lambda k: stretch[k])
    return new, max((left_of(new), right_of(new)), key=lambda k: stretch[k])


class PsaStack:
    """The LIFO stack of side segments (the paper prefers it to a FIFO queue).

    Each entry carries the number of the run that pushed it; :meth:`top_run`
    lists the entries of the latest run still on the stack.
    """

    def __init__(self) -> None:
        self.items: list[Segment] = []
        self.runs: list[int] = []

    def push(self, seg: Segment, run: int = 0) -> None:
        self.items.append(seg)
        self.runs.append(run)

    def pop(self, k: int = -1) -> tuple[Segment, int]:
        """Remove entry ``k`` (the top by default); return it with its run."""
        return self.items.pop(k), self.runs.pop(k)

    def top_run(self) -> list[int]:
        """Indices of the entries pushed by the same run as the top entry, bottom to top."""
        return [k for k, run in enumerate(self.runs) if run == self.runs[-1]]

    def __len__(self) -> int:
        return len(self.items)
