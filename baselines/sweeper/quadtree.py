"""Point-to-point transfer by approximate cell decomposition with a quadtree (paper 3.2).

The paper moves the robot between sweeping runs with "approximate cell
decomposition" over a quadtree (Latombe, *Robot Motion Planning*, ch. 6): the
known workspace is split recursively into squares until each square is
wholly free or wholly blocked (down to single cells); a path is a chain of
adjacent free squares, searched with A* between square centres. The
decomposition is complete at cell resolution: whenever a 4-connected path
of free cells exists, a chain of free leaves exists.

Here the decomposition runs in configuration space: a cell of ``free`` is a
robot configuration whose whole footprint is free (obstacles grown by the
robot, as in the paper's bitmap simulation). The chain of squares is turned
into cell moves: inside a free square any monotone (L-shaped) path between
two of its cells stays in it, so the path goes from the current cell to the
exit cell facing the next square, steps across, and so on to the goal.

The quadtree plans the route (our reading of Latombe's "channel"): A* over
the free leaves' adjacency graph (edge cost: distance between the squares'
centres) gives the chain of squares; the robot moves inside the union of
those squares only (the channel), along a shortest path within it and, of
those, one that sweeps the most cells not yet swept on its way
(:func:`best_path`, gains from :func:`.psa.entering_gains`): a transfer
that passes along a leftover strip sweeps it. Without gains the cells
follow the chain square by square with L-shaped moves. :func:`bfs_plan`,
the shortest path over all known free configurations with the quadtree only
deciding that one exists, is kept as the ablation (the policy's earlier
transfers); docs/experiments/Sweeper-v1.md compares their travel.
"""

from __future__ import annotations

import heapq

import numpy as np

from motiongym.envs.sweeper import occupancy
from motiongym.envs.sweeper.occupancy import DC, DR


def decompose(free: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Quadtree leaves of ``free``.

    Returns:
        ``(leaves, label)``: ``leaves`` an ``(n, 3)`` int array of free squares
        ``(row, col, size)``; ``label`` an ``(H, W)`` int array giving each
        cell's leaf index (-1 for blocked cells).
    """
    h, w = free.shape
    n = 1
    while n < max(h, w):
        n *= 2
    sat = np.zeros((n + 1, n + 1), np.int64)  # summed-area table of blocked cells
    blocked = np.ones((n, n), np.int64)
    blocked[:h, :w] = ~free
    sat[1:, 1:] = blocked.cumsum(0).cumsum(1)
    leaves: list[tuple[int, int, int]] = []
    stack = [(0, 0, n)]
    while stack:
        r, c, s = stack.pop()
        count = sat[r + s, c + s] - sat[r, c + s] - sat[r + s, c] + sat[r, c]
        if count == s * s:
            continue
        if count == 0:
            leaves.append((r, c, s))
            continue
        half = s // 2
        stack.extend(
            ((r, c, half), (r, c + half, half), (r + half, c, half), (r + half, c + half, half))
        )
    label = np.full((h, w), -1, np.int64)
    for i, (r, c, s) in enumerate(leaves):
        label[r : r + s, c : c + s] = i
    return np.array(leaves, np.int64).reshape(-1, 3), label


def _adjacency(label: np.ndarray) -> dict[int, set[int]]:
    pairs = []
    for a, b in ((label[:, :-1], label[:, 1:]), (label[:-1, :], label[1:, :])):
        m = (a >= 0) & (b >= 0) & (a != b)
        pairs.append(np.stack([a[m], b[m]], axis=1))
    both = np.unique(np.concatenate(pairs), axis=0)
    adj: dict[int, set[int]] = {}
    for a, b in both.tolist():
        adj.setdefault(a, set()).add(b)
        adj.setdefault(b, set()).add(a)
    return adj


def leaf_chain(
    leaves: np.ndarray, label: np.ndarray, start: tuple[int, int], goal: tuple[int, int]
) -> list[int] | None:
    """A* over the leaves' adjacency, cost = distance between square centres."""
    a, b = int(label[start]), int(label[goal])
    if a < 0 or b < 0:
        return None
    if a == b:
        return [a]
    centre = leaves[:, :2] + leaves[:, 2:3] / 2.0
    adj = _adjacency(label)
    best = {a: 0.0}
    parent = {a: -1}
    heap = [(float(np.linalg.norm(centre[a] - centre[b])), a)]
    while heap:
        _, u = heapq.heappop(heap)
        if u == b:
            chain = [b]
            while parent[chain[-1]] >= 0:
                chain.append(parent[chain[-1]])
            return chain[::-1]
        for v in adj.get(u, ()):
            g = best[u] + float(np.linalg.norm(centre[u] - centre[v]))
            if g < best.get(v, np.inf):
                best[v], parent[v] = g, u
                heapq.heappush(heap, (g + float(np.linalg.norm(centre[v] - centre[b])), v))
    return None


def _l_path(p: tuple[int, int], q: tuple[int, int]) -> list[tuple[int, int]]:
    """Cells from ``p`` (excluded) to ``q``: along the longer axis first, then the other."""
    (r, c), (qr, qc) = p, q
    out = []
    order = ("c", "r") if abs(qc - c) >= abs(qr - r) else ("r", "c")
    for axis in order:
        if axis == "r":
            step = 1 if qr > r else -1
            while r != qr:
                r += step
                out.append((r, c))
        else:
            step = 1 if qc > c else -1
            while c != qc:
                c += step
                out.append((r, c))
    return out


def best_path(
    corridor: np.ndarray, start: tuple[int, int], goal: tuple[int, int], gains: np.ndarray
) -> list[tuple[int, int]]:
    """Of the shortest 4-connected paths over ``corridor``, one of greatest total gain.

    ``gains``: ``(4, H, W)``, what entering cell ``(r, c)`` by a move in
    heading ``k`` (0 E, 1 N, 2 W, 3 S) is worth. Dynamic programming over
    the distance layers of the cells that lie on a shortest path. Returns
    the cells from ``start`` (excluded) to ``goal``; ``goal`` must be reachable.
    """
    ds = occupancy.bfs_distance(corridor, start)
    dg = occupancy.bfs_distance(corridor, goal)
    n = int(ds[goal])
    on = (ds >= 0) & (dg >= 0) & (ds + dg == n)
    value = np.full(corridor.shape, -1, np.int64)
    value[start] = 0
    came = np.zeros(corridor.shape, np.int64)  # heading of the move into each cell
    h, w = corridor.shape
    for d in range(1, n + 1):
        layer = on & (ds == d)
        for k in range(4):
            dr, dc = int(DR[k]), int(DC[k])
            prev = np.full(corridor.shape, -1, np.int64)  # value of the cell one move back
            prev[max(dr, 0) : h + min(dr, 0), max(dc, 0) : w + min(dc, 0)] = value[
                max(-dr, 0) : h + min(-dr, 0), max(-dc, 0) : w + min(-dc, 0)
            ]
            cand = np.where(layer & (prev >= 0), prev + gains[k], -1)
            better = cand > value
            value[better] = cand[better]
            came[better] = k
    path = [goal]
    while path[-1] != start:
        r, c = path[-1]
        k = int(came[r, c])
        path.append((r - int(DR[k]), c - int(DC[k])))
    return path[-2::-1]


def channel(leaves: np.ndarray, chain: list[int], shape: tuple[int, ...]) -> np.ndarray:
    """``(H, W)`` bool: the union of the chain's squares (4-connected from end to end)."""
    out = np.zeros(shape, bool)
    for r, c, s in leaves[chain].tolist():
        out[r : r + s, c : c + s] = True
    return out


def plan(
    free: np.ndarray,
    start: tuple[int, int],
    goal: tuple[int, int],
    gains: np.ndarray | None = None,
) -> list[tuple[int, int]] | None:
    """Cells from ``start`` (excluded) to ``goal`` through the quadtree's chain, or None.

    The chain of free squares (:func:`leaf_chain`) is the route. Without
    ``gains``: L-shaped moves square by square along the chain. With
    ``gains`` (see :func:`best_path`): of the shortest paths inside the
    chain's squares (:func:`channel`), one of greatest gain.
    """
    leaves, label = decompose(free)
    chain = leaf_chain(leaves, label, start, goal)
    if chain is None:
        return None
    if gains is not None:
        return best_path(channel(leaves, chain, free.shape), start, goal, gains)
    return _chain_cells(leaves, chain, start, goal)


def bfs_plan(
    free: np.ndarray, start: tuple[int, int], goal: tuple[int, int], gains: np.ndarray
) -> list[tuple[int, int]] | None:
    """Ablation of :func:`plan`: the quadtree only decides that a path exists; the path is,
    of the shortest ones over all of ``free``, one of greatest gain (never longer)."""
    leaves, label = decompose(free)
    if leaf_chain(leaves, label, start, goal) is None:
        return None
    return best_path(free, start, goal, gains)


def _chain_cells(
    leaves: np.ndarray, chain: list[int], start: tuple[int, int], goal: tuple[int, int]
) -> list[tuple[int, int]]:
    """L-shaped moves inside each square of ``chain``, crossing to the next where they touch."""
    path: list[tuple[int, int]] = []
    p = start
    for u, v in zip(chain[:-1], chain[1:], strict=True):
        ur, uc, us = leaves[u].tolist()
        vr, vc, vs = leaves[v].tolist()
        if vc == uc + us or vc + vs == uc:  # side by side: share rows
            lo, hi = max(ur, vr), min(ur + us, vr + vs) - 1
            row = min(max(p[0], lo), hi)
            exit_ = (row, uc + us - 1) if vc == uc + us else (row, uc)
            entry = (row, vc) if vc == uc + us else (row, vc + vs - 1)
        else:  # one above the other: share columns
            lo, hi = max(uc, vc), min(uc + us, vc + vs) - 1
            col = min(max(p[1], lo), hi)
            exit_ = (ur + us - 1, col) if vr == ur + us else (ur, col)
            entry = (vr, col) if vr == ur + us else (vr + vs - 1, col)
        path += _l_path(p, exit_)
        path.append(entry)
        p = entry
    path += _l_path(p, goal)
    return path
