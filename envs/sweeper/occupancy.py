"""The sweeper's occupancy grid: pure functions over NumPy arrays (no state).

The world is an occupancy bitmap ``obstacle`` of shape ``(H, W)`` (True: wall
or obstacle). The robot is a square of side ``w`` cells; its *configuration*
is the cell ``(r, c)`` of the footprint's top-left corner, so the footprint is
``obstacle[r:r + w, c:c + w]`` (paper section 4.1: the robot is a square of
the sweeping width). A configuration is free when its footprint holds no
obstacle. Headings are indices 0..3: east (+col), north (-row), west (-col),
south (+row); a left turn adds one, a right turn subtracts one (mod 4).

Everything here is a function of arrays, so that a batched twin of the
environment can reuse the same definitions.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import ndimage

DR = np.array([0, -1, 0, 1])  # row step per heading (E, N, W, S)
DC = np.array([1, 0, -1, 0])  # column step per heading
HEADING_NAMES = ("east", "north", "west", "south")


def box_sum(image: np.ndarray, w: int) -> np.ndarray:
    """Sum of ``image`` over every ``w x w`` window anchored at its top-left cell.

    Returns an ``(H, W)`` int array; windows that leave the image count only
    the cells inside it (so anchors near the bottom/right edge see fewer cells).
    """
    h, wd = image.shape
    s = np.zeros((h + w + 1, wd + w + 1), dtype=np.int64)
    s[1 : h + 1, 1 : wd + 1] = np.cumsum(np.cumsum(image, axis=0), axis=1)
    s[h + 1 :, 1 : wd + 1] = s[h : h + 1, 1 : wd + 1]
    s[:, wd + 1 :] = s[:, wd : wd + 1]
    return s[w : w + h, w : w + wd] - s[:h, w : w + wd] - s[w : w + h, :wd] + s[:h, :wd]


def config_free(obstacle: np.ndarray, w: int) -> np.ndarray:
    """``(H, W)`` bool: configurations whose ``w x w`` footprint lies inside and is free."""
    h, wd = obstacle.shape
    free = box_sum(obstacle.astype(np.int64), w) == 0
    free[h - w + 1 :, :] = False
    free[:, wd - w + 1 :] = False
    return free


def footprint_union(configs: np.ndarray, w: int) -> np.ndarray:
    """``(H, W)`` bool: cells covered by the footprint of any configuration in ``configs``."""
    # A cell (i, j) is covered by anchors (r, c) with i - w < r <= i, j - w < c <= j.
    flipped = configs[::-1, ::-1].astype(np.int64)
    return box_sum(flipped, w)[::-1, ::-1] > 0


def reachable_configs(free: np.ndarray, start: tuple[int, int]) -> np.ndarray:
    """``(H, W)`` bool: free configurations 4-connected to ``start`` (one-cell moves)."""
    labels, _ = ndimage.label(free)
    label = labels[start]
    if label == 0:
        return np.zeros_like(free)
    return labels == label


def reachable_cells(obstacle: np.ndarray, w: int, start: tuple[int, int]) -> np.ndarray:
    """``(H, W)`` bool: the cells the robot can sweep from ``start`` (the coverage target)."""
    return footprint_union(reachable_configs(config_free(obstacle, w), start), w)


def is_closed(obstacle: np.ndarray) -> bool:
    """True when no free cell lies on the map's border (the area is closed)."""
    border = np.concatenate([obstacle[0], obstacle[-1], obstacle[:, 0], obstacle[:, -1]])
    return bool(border.all())


def entering_mask(dr: int, dc: int, w: int) -> np.ndarray:
    """``(w, w)`` bool: cells of the new footprint that were not under the old one.

    The robot moved by ``(dr, dc)`` cells; entry ``[i, j]`` refers to the new
    footprint's cell ``(r + i, c + j)``.
    """
    i = np.arange(w)[:, None] + dr
    j = np.arange(w)[None, :] + dc
    return ~((i >= 0) & (i < w) & (j >= 0) & (j < w))


@dataclass(frozen=True)
class SmartDfsBound:
    """The exploration bound on one map at robot scale (see :func:`smartdfs_bound`)."""

    cells: int  # C: cells of the robot-scale polygon
    edges: int  # E: their boundary edges
    holes: int  # H: obstacles the robot can travel round
    area: int  # reachable cells of the map
    w: int  # robot width, cells (a step is w cells)

    @property
    def simple_steps(self) -> float:
        """SmartDFS's bound for a polygon without holes, ``C + E/2 - 3`` steps."""
        return self.cells + self.edges / 2.0 - 3.0

    @property
    def steps(self) -> float:
        """The bound that applies, in steps: ``C + E/2 + 3H - 2`` around ``H > 0`` obstacles."""
        if not self.holes:
            return self.simple_steps
        return self.cells + self.edges / 2.0 + 3.0 * self.holes - 2.0

    @property
    def ratio(self) -> float:
        """``w * steps`` over the lower bound ``area / w``."""
        return self._over_lower_bound(self.steps)

    @property
    def simple_ratio(self) -> float:
        """The same with the no-hole formula ``C + E/2 - 3`` (stricter on a map with holes)."""
        return self._over_lower_bound(self.simple_steps)

    def _over_lower_bound(self, steps: float) -> float:
        return self.w * self.w * steps / self.area if self.area else float("inf")


def robot_scale_cells(
    reachable: np.ndarray, w: int, anchor: tuple[int, int] = (0, 0)
) -> tuple[int, int]:
    """``(C, E)`` of the reachable area seen as a grid polygon of ``w x w`` cells.

    The map is cut into ``w x w`` blocks, one of them at ``anchor`` (the
    robot's start configuration: the grid the robot itself would explore
    in steps of ``w``). A *cell* is a 4-connected piece of the reachable
    cells inside one block: a block split by a wall thinner than ``w``
    holds one cell on each side. Two cells are neighbours when their
    pieces touch across the common side of their blocks; ``E`` counts the
    sides of cells with no neighbour across. (Counting a block once however
    its reachable cells lie joins rooms across every wall thinner than the
    robot: the maze became its empty bounding square, E = its perimeter.)
    """
    top, left = (-anchor[0]) % w, (-anchor[1]) % w
    h, wd = reachable.shape
    hb, wb = -(-(h + top) // w), -(-(wd + left) // w)
    grid = np.zeros((hb * w, wb * w), dtype=bool)
    grid[top : top + h, left : left + wd] = reachable
    # blocks spread apart by one empty row and column, so no piece spans two blocks
    apart = np.zeros((hb, w + 1, wb, w + 1), dtype=bool)
    apart[:, :w, :, :w] = grid.reshape(hb, w, wb, w)
    labels, c_count = ndimage.label(apart.reshape(hb * (w + 1), wb * (w + 1)))
    labels = labels.reshape(hb, w + 1, wb, w + 1)[:, :w, :, :w].reshape(hb * w, wb * w)
    has_neighbour = np.zeros((c_count + 1, 4), dtype=bool)  # per cell: E, N, W, S
    west, east = labels[:, w - 1 : -1 : w], labels[:, w::w]  # across vertical block sides
    touch = (west > 0) & (east > 0)
    has_neighbour[west[touch], 0] = has_neighbour[east[touch], 2] = True
    north, south = labels[w - 1 : -1 : w, :], labels[w::w, :]  # across horizontal sides
    touch = (north > 0) & (south > 0)
    has_neighbour[south[touch], 1] = has_neighbour[north[touch], 3] = True
    return c_count, int(4 * c_count - has_neighbour[1:].sum())


def obstacle_count(reachable: np.ndarray) -> int:
    """Obstacles the robot can travel round: bounded 8-connected pieces of unreachable cells."""
    _, pieces = ndimage.label(np.pad(~reachable, 1, constant_values=True), np.ones((3, 3)))
    return pieces - 1  # the piece holding the map's frame is the outside


def smartdfs_bound(
    reachable: np.ndarray, w: int, anchor: tuple[int, int] = (0, 0)
) -> SmartDfsBound:
    """The travel bound of Icking, Kamphans and Langetepe's online exploration, at robot scale.

    "Exploring grid polygons online" (Icking, Kamphans, Langetepe 2005,
    arXiv:1012.5240): a robot that senses its four neighbour cells explores
    a grid polygon of ``C`` cells and ``E`` boundary edges and returns to
    its start in at most ``C + E/2 - 3`` steps when the polygon has no
    holes (SmartDFS), and in at most ``C + E/2 + 3H + W_cw - 2`` steps
    around ``H`` obstacles (``W_cw >= 0`` measures the polygon's
    sinuosity). ``C`` and ``E`` come from :func:`robot_scale_cells`, ``H``
    from :func:`obstacle_count`. Our choice: with obstacles the bound drops
    ``W_cw`` (which needs the strategy's own tour to measure), so it is
    never above the theorem's; ``simple_ratio`` keeps the no-hole formula
    on every map, a stricter yardstick still. Both tours return to the
    start, which a sweep need not do. A step is ``w`` cells; ratios are
    over the lower bound ``area / w``.
    """
    c_count, edges = robot_scale_cells(reachable, w, anchor)
    return SmartDfsBound(c_count, edges, obstacle_count(reachable), int(reachable.sum()), w)


def bfs_distance(free: np.ndarray, start: tuple[int, int] | np.ndarray) -> np.ndarray:
    """``(H, W)`` int: 4-connected step distance from ``start`` over ``free`` (-1: unreached).

    ``start``: one cell, or an ``(H, W)`` bool mask of sources (the distance to the
    nearest of them; sources off ``free`` are ignored). A wavefront expansion, one NumPy
    dilation per distance level.
    """
    dist = np.full(free.shape, -1, dtype=np.int64)
    frontier = np.zeros_like(free)
    frontier[start] = True
    frontier &= free
    if not frontier.any():
        return dist
    dist[frontier] = 0
    seen = frontier.copy()
    level = 0
    while frontier.any():
        level += 1
        grown = np.zeros_like(frontier)
        grown[1:, :] |= frontier[:-1, :]
        grown[:-1, :] |= frontier[1:, :]
        grown[:, 1:] |= frontier[:, :-1]
        grown[:, :-1] |= frontier[:, 1:]
        frontier = grown & free & ~seen
        seen |= frontier
        dist[frontier] = level
    return dist


def descend(dist: np.ndarray, goal: tuple[int, int]) -> list[tuple[int, int]]:
    """The path of cells from the BFS source to ``goal`` (source excluded) down ``dist``."""
    if dist[goal] < 0:
        raise ValueError(f"goal {goal} is not reachable")
    path = [goal]
    r, c = goal
    h, wd = dist.shape
    while dist[r, c] > 0:
        d = dist[r, c]
        for k in range(4):
            rr, cc = r - DR[k], c - DC[k]
            if 0 <= rr < h and 0 <= cc < wd and dist[rr, cc] == d - 1:
                r, c = int(rr), int(cc)
                break
        path.append((r, c))
    path.pop()  # the source
    return path[::-1]
