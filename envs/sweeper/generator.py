"""Procedural maps for training variety: furnished rooms, apartments, mazes.

Every generator draws only from the ``numpy.random.Generator`` it is given
and returns a closed ``(H, W)`` bool obstacle map (True: obstacle). Openings
(doors, corridors) are always wider than the robot so that the free space is
mostly connected at robot scale; small pockets may remain, and the
environment's coverage target counts only what the robot can reach.

The map families of held-out studies (corridors of the robot's width,
serpentines, pillar fields, offices, halls, mixed plans; every map sealed to
be connected at robot scale) are in :mod:`motiongym.envs.sweeper.families`.
"""

from __future__ import annotations

import numpy as np

KINDS = ("room", "apartment", "maze")


def empty_room(height: int, width: int) -> np.ndarray:
    """A closed rectangular room: a one-cell wall around free floor."""
    grid = np.zeros((height, width), dtype=bool)
    grid[0, :] = grid[-1, :] = True
    grid[:, 0] = grid[:, -1] = True
    return grid


def corner_room(size: int = 41) -> np.ndarray:
    """A room of the paper's Fig. 6 kind: every wall at 45 degrees to the lanes.

    A diamond room (a square turned by 45 degrees, its walls staircases of
    one-cell steps, ``size`` odd) with a diamond pillar and a round one.
    Each lane stops where its footprint first meets a step and leaves a
    small triangle between its front and the staircase unswept: the
    leftovers along walls and obstacles of the paper's Fig. 9 that its
    corner work sweeps (Fig. 10).
    """
    if size < 31 or size % 2 == 0:
        raise ValueError(f"corner_room: size = {size}; allowed: an odd number >= 31")
    h = size // 2
    r, c = np.mgrid[0:size, 0:size]
    grid = np.abs(r - h) + np.abs(c - h) > h - 1  # outside the diamond (its rim is wall)
    grid |= np.abs(r - h + size // 6) + np.abs(c - h) <= 3  # diamond pillar
    grid |= (r - h - size // 6) ** 2 + (c - h) ** 2 <= 9  # round pillar
    return grid


def furnished_room(rng: np.random.Generator, height: int, width: int, w: int) -> np.ndarray:
    """A room with 2-6 rectangular pieces of furniture, some against the walls."""
    grid = empty_room(height, width)
    for _ in range(int(rng.integers(2, 7))):
        fh, fw = int(rng.integers(2, max(3, height // 4))), int(rng.integers(2, max(3, width // 4)))
        r = int(rng.integers(1, height - fh - 1))
        c = int(rng.integers(1, width - fw - 1))
        if rng.random() < 0.3:  # against a wall
            r = 1 if rng.random() < 0.5 else height - fh - 1
        grid[r : r + fh, c : c + fw] = True
    return grid


def apartment(rng: np.random.Generator, height: int, width: int, w: int) -> np.ndarray:
    """Rooms by recursive splitting with one-cell walls and doors of width ``w + 2..w + 4``."""
    grid = empty_room(height, width)
    min_room = 3 * w + 4

    def split(r0: int, c0: int, r1: int, c1: int, depth: int) -> None:
        h, wd = r1 - r0, c1 - c0
        if depth > 3 or (h < 2 * min_room and wd < 2 * min_room):
            if h > 2 * w + 4 and wd > 2 * w + 4 and rng.random() < 0.6:
                fh = int(rng.integers(2, max(3, h // 3)))
                fw = int(rng.integers(2, max(3, wd // 3)))
                grid[r0 + 1 : r0 + 1 + fh, c0 + 1 : c0 + 1 + fw] = True
            return
        vertical = wd >= h if min(h, wd) >= 2 * min_room else wd >= 2 * min_room
        if vertical:
            c = int(rng.integers(c0 + min_room, c1 - min_room + 1))
            grid[r0:r1, c] = True
            door = int(rng.integers(w + 2, w + 5))
            d = int(rng.integers(r0 + 1, max(r0 + 2, r1 - door)))
            grid[d : d + door, c] = False
            split(r0, c0, r1, c, depth + 1)
            split(r0, c + 1, r1, c1, depth + 1)
        else:
            r = int(rng.integers(r0 + min_room, r1 - min_room + 1))
            grid[r, c0:c1] = True
            door = int(rng.integers(w + 2, w + 5))
            d = int(rng.integers(c0 + 1, max(c0 + 2, c1 - door)))
            grid[r, d : d + door] = False
            split(r0, c0, r, c1, depth + 1)
            split(r + 1, c0, r1, c1, depth + 1)

    split(1, 1, height - 1, width - 1, 0)
    grid[0, :] = grid[-1, :] = True
    grid[:, 0] = grid[:, -1] = True
    return grid


def maze(
    rng: np.random.Generator, rows: int, cols: int, corridor: int, wall: int = 2
) -> np.ndarray:
    """A perfect maze (recursive backtracker) of ``rows x cols`` cells.

    Corridors are ``corridor`` cells wide, walls ``wall`` cells thick; the map
    is ``rows * (corridor + wall) + wall`` by ``cols * (corridor + wall) + wall``.
    """
    pitch = corridor + wall
    grid = np.ones((rows * pitch + wall, cols * pitch + wall), dtype=bool)
    seen = np.zeros((rows, cols), dtype=bool)
    stack = [(int(rng.integers(rows)), int(rng.integers(cols)))]
    seen[stack[0]] = True
    while stack:
        i, j = stack[-1]
        r, c = wall + i * pitch, wall + j * pitch
        grid[r : r + corridor, c : c + corridor] = False
        options = [
            (i + di, j + dj)
            for di, dj in ((0, 1), (1, 0), (0, -1), (-1, 0))
            if 0 <= i + di < rows and 0 <= j + dj < cols and not seen[i + di, j + dj]
        ]
        if not options:
            stack.pop()
            continue
        ni, nj = options[int(rng.integers(len(options)))]
        seen[ni, nj] = True
        top, left = wall + min(i, ni) * pitch, wall + min(j, nj) * pitch
        if ni != i:  # open the wall between vertically adjacent cells
            grid[top : top + 2 * corridor + wall, left : left + corridor] = False
        else:
            grid[top : top + corridor, left : left + 2 * corridor + wall] = False
        stack.append((ni, nj))
    return grid


def random_map(rng: np.random.Generator, w: int, kind: str | None = None) -> np.ndarray:
    """A procedural map of a random (or the given) kind, sides between 24 and 56 cells."""
    if kind is None:
        kind = KINDS[int(rng.integers(len(KINDS)))]
    if kind not in KINDS:
        raise ValueError(f"unknown map kind {kind!r}; kinds: {', '.join(KINDS)}")
    if kind == "room":
        return furnished_room(rng, int(rng.integers(24, 41)), int(rng.integers(24, 49)), w)
    if kind == "apartment":
        return apartment(rng, int(rng.integers(32, 49)), int(rng.integers(36, 57)), w)
    corridor = int(rng.integers(w + 2, 3 * w + 1))
    n = max(2, 48 // (corridor + 2))
    return maze(rng, int(rng.integers(2, n + 1)), int(rng.integers(2, n + 1)), corridor)
