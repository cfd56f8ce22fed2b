"""The sweeper's grid world: pure functions over NumPy arrays.

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


def smartdfs_bound(
    reachable: np.ndarray, w: int, anchor: tuple[int, int] = (0, 0)
) -> tuple[int, int, float]:
    """SmartDFS's travel bound ``C + E/2 - 3`` on the map, at robot scale.

    SmartDFS (Icking, Kamphans, Klein, Langetepe, "Exploring simple grid
    polygons", COCOON 2005) explores a simple grid polygon of ``C`` cells
    and ``E`` boundary edges, returning to the start, in at most
    ``C + E/2 - 3`` steps. The theorem is for polygons without holes and a
    closed tour, so against a sweep that need not return it is a strict
    yardstick. Here the map is cut into ``w x w`` blocks, one of them at
    ``anchor`` (the robot's start configuration: the grid the robot itself
    would explore); ``C`` counts blocks holding a reachable cell and ``E``
    the block edges between such a block and any other. Returns
    ``(C, E, ratio)``: the bound in cells, ``w (C + E/2 - 3)`` (a step is
    ``w`` cells), over the lower bound ``area / w``.
    """
    top, left = (-anchor[0]) % w, (-anchor[1]) % w
    reachable = np.pad(reachable, ((top, 0), (left, 0)))
    h, wd = reachable.shape
    hb, wb = -(-h // w), -(-wd // w)
    pad = np.zeros((hb * w, wb * w), dtype=bool)
    pad[:h, :wd] = reachable
    blocks = pad.reshape(hb, w, wb, w).any(axis=(1, 3))
    b = np.pad(blocks, 1)
    c_count = int(blocks.sum())
    edges = int((b[1:, :] != b[:-1, :]).sum() + (b[:, 1:] != b[:, :-1]).sum())
    area = float(reachable.sum())
    ratio = w * (c_count + edges / 2.0 - 3.0) / (area / w) if area else float("inf")
    return c_count, edges, ratio


def bfs_distance(free: np.ndarray, start: tuple[int, int]) -> np.ndarray:
    """``(H, W)`` int: 4-connected step distance from ``start`` over ``free`` (-1: unreached).

    A wavefront expansion, one NumPy dilation per distance level.
    """
    dist = np.full(free.shape, -1, dtype=np.int64)
    if not free[start]:
        return dist
    dist[start] = 0
    frontier = np.zeros_like(free)
    frontier[start] = True
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
