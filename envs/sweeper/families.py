"""Map families for held-out studies: the floors a cleaning robot meets.

:func:`family_map` ``(family, seed, w, size)`` returns a closed ``(H, W)``
bool obstacle map (True: obstacle), a pure function of its four arguments
(its generator is seeded with the seed and a fixed code of the family's
name, so adding a family changes no other family's maps). ``w`` is the
robot's width in cells; passages are sized against it.

========================= ================================================
family                    content
========================= ================================================
``narrow-corridors``      a corridor network (a maze on a lattice with a
                          few loops, walls 1-3 cells) whose every passage
                          is exactly ``w`` cells wide
``corridors``             the same with corridors ``w + 1`` or ``w + 2``
``narrow-serpentine``     one corridor folded back and forth (horizontal
                          or vertical legs, walls 1-3 cells), every leg
                          and every turn exactly ``w`` wide
``serpentine``            the same, each leg ``w`` to ``w + 3`` wide and
                          each turn's opening ``w`` to ``w + 2``
``pillars``               a hall with a lattice of square pillars (side
                          1-4 cells, gaps ``w`` to ``3 w``, 50-100 % of the
                          lattice kept, half the maps jittered by one cell)
``offices``               a corridor ``w + 1`` to ``w + 4`` wide with
                          offices on one or both sides, a door ``w`` to
                          ``w + 2`` wide into each, desks in some
``hall``                  an open hall, up to two corners cut away (L and
                          Z shapes), up to three pieces of furniture
``mixed``                 the map cut by walls into two to four regions,
                          each of another family, joined by doors ``w``
                          to ``w + 2`` wide
========================= ================================================

Every map is *sealed* (:func:`seal`): the border is wall, and every free
cell lies under the footprint of some configuration of the one largest
4-connected set of free configurations (the rest is filled), so the free
space is connected at robot scale and every free cell can be swept. A
draw whose largest set holds less than half the free cells is drawn again
from the same generator (deterministic). In the two ``narrow-`` families
no ``(w + 1) x (w + 1)`` square of free cells exists anywhere: every
passage is exactly the robot's width.
"""

from __future__ import annotations

import zlib
from collections.abc import Callable
from typing import Any

import numpy as np
from scipy import ndimage

from motiongym.envs.checks import ArgumentError, check_choice, check_int
from motiongym.envs.sweeper import generator, occupancy

FAMILIES = (
    "narrow-corridors",
    "corridors",
    "narrow-serpentine",
    "serpentine",
    "pillars",
    "offices",
    "hall",
    "mixed",
)
NARROW = ("narrow-corridors", "narrow-serpentine")  # every passage exactly w wide
MAX_MAP_SEED = 2**32 - 1  # map seeds are integers in [0, MAX_MAP_SEED]
DEFAULT_SIZE = (40, 60)  # rows, columns
MAX_SIDE = 256  # as maps.MAX_SIDE
MAX_DRAWS = 50  # draws before giving up (never reached in the tests' seeds)


def min_side(w: int) -> int:
    """The shortest map side (cells) every family is built for: ``4 w + 6``."""
    return 4 * w + 6


def check_size(size: Any, w: int) -> tuple[int, int]:
    """``size`` as (rows, columns), each in ``[min_side(w), 256]``; None:
    :data:`DEFAULT_SIZE`, each side raised to ``min_side(w)`` where it is shorter."""
    low = min_side(w)
    if size is None:
        return (max(DEFAULT_SIZE[0], low), max(DEFAULT_SIZE[1], low))
    allowed = (
        f"(rows, columns), two integers in [{low}, {MAX_SIDE}] (at least 4 * robot_width + 6 "
        f"cells a side for robot_width={w})"
    )
    if not isinstance(size, (tuple, list, np.ndarray)) or len(size) != 2:
        raise ArgumentError(f"map_size must be {allowed}, got {size!r}")
    try:
        return (
            check_int("map_size", size[0], low, MAX_SIDE),
            check_int("map_size", size[1], low, MAX_SIDE),
        )
    except ArgumentError:
        pass
    raise ArgumentError(f"map_size must be {allowed}, got {size!r}")


def family_map(family: str, seed: int, w: int, size: Any = None) -> np.ndarray:
    """The map of ``family`` drawn from ``seed`` for a robot of width ``w``, ``size`` = (H, W).

    Raises :class:`~motiongym.envs.checks.ArgumentError` naming ``map_family``,
    ``map_seed`` or ``map_size`` for a family not in :data:`FAMILIES`, a seed
    outside ``[0, MAX_MAP_SEED]``, or a size below :func:`min_side`.
    """
    check_choice("map_family", family, FAMILIES)
    seed = check_int("map_seed", seed, 0, MAX_MAP_SEED)
    w = check_int("robot_width", w, 1)
    h, wd = check_size(size, w)
    rng = np.random.default_rng([seed, zlib.crc32(family.encode())])
    for _ in range(MAX_DRAWS):
        sealed = seal(BUILDERS[family](rng, h, wd, w), w)
        if sealed is not None:
            return sealed
    raise RuntimeError(  # pragma: no cover - never seen
        f"family {family!r}, seed {seed}: no connected map in {MAX_DRAWS} draws"
    )


def seal(grid: np.ndarray, w: int) -> np.ndarray | None:
    """Close the border and fill every free cell outside the largest robot-scale component.

    Returns None when that component covers less than half the free cells
    (the draw is then repeated) or when no configuration is free.
    """
    grid = grid.copy()
    grid[0, :] = grid[-1, :] = True
    grid[:, 0] = grid[:, -1] = True
    labels, n = ndimage.label(occupancy.config_free(grid, w))
    if n == 0:
        return None
    sizes = [int(occupancy.footprint_union(labels == k, w).sum()) for k in range(1, n + 1)]
    kept = occupancy.footprint_union(labels == 1 + int(np.argmax(sizes)), w)
    if 2 * int(kept.sum()) < int((~grid).sum()):
        return None
    return grid | ~kept


# ---------------------------------------------------------------- builders
def _corridor_net(rng: np.random.Generator, h: int, wd: int, corridor: int) -> np.ndarray:
    """A maze of ``corridor``-wide passages on a lattice, walls 1-3, a few loops opened."""
    wall = int(rng.integers(1, 4))
    while wall > 1 and min(h - wall, wd - wall) // (corridor + wall) < 2:
        wall -= 1
    pitch = corridor + wall
    rows, cols = max(1, (h - wall) // pitch), max(1, (wd - wall) // pitch)
    net = generator.maze(rng, rows, cols, corridor, wall)
    loops = float(rng.uniform(0.0, 0.15))
    for i in range(rows):
        for j in range(cols):
            top, left = wall + i * pitch, wall + j * pitch
            if j + 1 < cols and rng.random() < loops:  # the wall east of lattice cell (i, j)
                net[top : top + corridor, left + corridor : left + pitch] = False
            if i + 1 < rows and rng.random() < loops:  # the wall south of it
                net[top + corridor : top + pitch, left : left + corridor] = False
    grid = np.ones((h, wd), dtype=bool)
    grid[: net.shape[0], : net.shape[1]] = net
    return grid


def narrow_corridors(rng: np.random.Generator, h: int, wd: int, w: int) -> np.ndarray:
    return _corridor_net(rng, h, wd, w)


def corridors(rng: np.random.Generator, h: int, wd: int, w: int) -> np.ndarray:
    return _corridor_net(rng, h, wd, w + int(rng.integers(1, 3)))


def _transposed(
    build: Callable[[np.random.Generator, int, int, int], np.ndarray],
) -> Callable[[np.random.Generator, int, int, int], np.ndarray]:
    """``build`` on the transposed size half the time (vertical instead of horizontal)."""

    def turned(rng: np.random.Generator, h: int, wd: int, w: int) -> np.ndarray:
        if rng.random() < 0.5:
            return build(rng, wd, h, w).T.copy()
        return build(rng, h, wd, w)

    return turned


def _serpentine(rng: np.random.Generator, h: int, wd: int, w: int, narrow: bool) -> np.ndarray:
    """Horizontal legs from wall to wall, each opening into the next at alternate ends."""
    grid = np.ones((h, wd), dtype=bool)
    wall = int(rng.integers(1, 4))
    east = bool(rng.random() < 0.5)  # the first turn at the east end

    def leg_width() -> int:
        return w if narrow else int(rng.integers(w, w + 4))

    r, width = 1, leg_width()
    while r + width <= h - 1:
        grid[r : r + width, 1 : wd - 1] = False
        nxt = leg_width()
        below = r + width + wall
        if below + nxt > h - 1:
            break
        gap = w if narrow else int(rng.integers(w, w + 3))
        cols = slice(wd - 1 - gap, wd - 1) if east else slice(1, 1 + gap)
        grid[r + width : below, cols] = False
        r, width, east = below, nxt, not east
    return grid


def narrow_serpentine(rng: np.random.Generator, h: int, wd: int, w: int) -> np.ndarray:
    return _transposed(lambda g, a, b, c: _serpentine(g, a, b, c, True))(rng, h, wd, w)


def serpentine(rng: np.random.Generator, h: int, wd: int, w: int) -> np.ndarray:
    return _transposed(lambda g, a, b, c: _serpentine(g, a, b, c, False))(rng, h, wd, w)


def pillars(rng: np.random.Generator, h: int, wd: int, w: int) -> np.ndarray:
    """A lattice of square pillars: side 1-4, gaps ``w..3w``, some left out, maybe jittered."""
    grid = generator.empty_room(h, wd)
    side = int(rng.integers(1, 5))
    gap = int(rng.integers(w, 3 * w + 1))
    keep = float(rng.choice([1.0, 0.8, 0.5]))
    jitter = bool(rng.random() < 0.5)
    pitch = side + gap
    r0, c0 = 1 + int(rng.integers(w, gap + 1)), 1 + int(rng.integers(w, gap + 1))
    for r in range(r0, h - 1 - w - side + 1, pitch):
        for c in range(c0, wd - 1 - w - side + 1, pitch):
            dr, dc = (int(v) for v in rng.integers(-1, 2, 2)) if jitter else (0, 0)
            if rng.random() < keep:
                grid[r + dr : r + dr + side, c + dc : c + dc + side] = True
    return grid


def _offices(rng: np.random.Generator, h: int, wd: int, w: int) -> np.ndarray:
    """A corridor along the map with a row of offices on one or both sides."""
    grid = generator.empty_room(h, wd)
    cw = int(rng.integers(w + 1, w + 5))
    rest = h - 2 - cw - 2  # rows for the two rows of offices
    if rest >= 2 * (w + 2):
        above = int(rng.integers(w + 2, rest - (w + 2) + 1))
        sides = [(1, above, 1 + above, -1)]  # (first row, depth, wall row, door side)
        below_wall = 1 + above + 1 + cw
        sides.append((below_wall + 1, h - 2 - below_wall, below_wall, 1))
    elif rest + 1 >= w + 2:
        above = h - 2 - cw - 1
        sides = [(1, above, 1 + above, -1)]
    else:  # too low for offices: a corridor alone
        return grid
    for first, depth, wall_row, _ in sides:
        grid[wall_row, :] = True
        c = 1
        while c < wd - 1:
            width = int(rng.integers(w + 3, 3 * w + 7))
            if wd - 1 - (c + width) < w + 4:
                width = wd - 1 - c
            if c + width < wd - 1:
                grid[first : first + depth, c + width] = True  # partition
            door = min(int(rng.integers(w, w + 3)), width)
            d = c + int(rng.integers(0, width - door + 1))
            grid[wall_row, d : d + door] = False
            if depth > w + 3 and width > w + 3 and rng.random() < 0.5:  # a desk
                dh = int(rng.integers(2, max(3, depth // 3)))
                dw = int(rng.integers(2, max(3, width // 3)))
                off = int(rng.integers(0, 2))  # against the back wall or one cell off it
                top = first + off if wall_row > first else first + depth - dh - off
                dc = c + int(rng.integers(1, max(2, width - dw)))
                grid[top : top + dh, dc : dc + dw] = True
            c += width + 1
    return grid


def offices(rng: np.random.Generator, h: int, wd: int, w: int) -> np.ndarray:
    return _transposed(_offices)(rng, h, wd, w)


def hall(rng: np.random.Generator, h: int, wd: int, w: int) -> np.ndarray:
    """An open hall, up to two corners cut away, up to three pieces of furniture."""
    grid = generator.empty_room(h, wd)
    corners = [(0, 0), (0, 1), (1, 0), (1, 1)]
    for k in rng.permutation(4)[: int(rng.integers(0, 3))]:
        bottom, right = corners[int(k)]
        ch_max, cw_max = h // 2 - w, wd // 2 - w
        if ch_max <= h // 5 or cw_max <= wd // 5:
            continue
        ch, cw = int(rng.integers(h // 5, ch_max + 1)), int(rng.integers(wd // 5, cw_max + 1))
        rows = slice(h - ch, h) if bottom else slice(0, ch)
        cols = slice(wd - cw, wd) if right else slice(0, cw)
        grid[rows, cols] = True
    for _ in range(int(rng.integers(0, 4))):
        fh, fw = int(rng.integers(2, max(3, h // 6))), int(rng.integers(2, max(3, wd // 6)))
        r, c = int(rng.integers(1, h - fh - 1)), int(rng.integers(1, wd - fw - 1))
        grid[r : r + fh, c : c + fw] = True
    return grid


def mixed(rng: np.random.Generator, h: int, wd: int, w: int) -> np.ndarray:
    """Regions of other families, cut by one-cell walls (at most two levels), joined by doors."""
    low = min_side(w)
    grid = np.ones((h, wd), dtype=bool)
    cuts: list[tuple[bool, int, int, int]] = []  # (vertical, at, span start, span end)
    others = [f for f in FAMILIES if f != "mixed"]

    def fill(r0: int, c0: int, r1: int, c1: int, depth: int) -> None:  # rows r0..r1 inclusive
        rh, rw = r1 - r0 + 1, c1 - c0 + 1
        vertical = rw >= rh
        span = rw if vertical else rh
        if depth < 2 and span >= 2 * low - 1 and (depth == 0 or rng.random() < 0.6):
            at = int(rng.integers(low - 1, span - low + 1))
            if vertical:
                cuts.append((True, c0 + at, r0, r1))
                fill(r0, c0, r1, c0 + at, depth + 1)
                fill(r0, c0 + at, r1, c1, depth + 1)
            else:
                cuts.append((False, r0 + at, c0, c1))
                fill(r0, c0, r0 + at, c1, depth + 1)
                fill(r0 + at, c0, r1, c1, depth + 1)
            return
        family = others[int(rng.integers(len(others)))]
        for _ in range(MAX_DRAWS):
            part = seal(BUILDERS[family](rng, rh, rw, w), w)
            if part is not None:
                break
        else:  # pragma: no cover - never seen
            part = generator.empty_room(rh, rw)
        grid[r0 : r1 + 1, c0 : c1 + 1] &= part

    fill(0, 0, h - 1, wd - 1, 0)
    for vertical, at, lo, hi in cuts:
        g = grid.T if vertical else grid  # a view: the cut is a row of g
        door = int(rng.integers(w, w + 3))
        # a door where the robot can stand on both sides, else one carved w deep
        side = [
            k
            for k in range(lo + 1, hi - door + 1)
            if not g[at - w : at, k : k + door].any()
            and not g[at + 1 : at + 1 + w, k : k + door].any()
        ]
        k = side[int(rng.integers(len(side)))] if side else int(rng.integers(lo + 1, hi - door + 1))
        g[at - w : at + 1 + w, k : k + door] = False
    return grid


BUILDERS: dict[str, Callable[[np.random.Generator, int, int, int], np.ndarray]] = {
    "narrow-corridors": narrow_corridors,
    "corridors": corridors,
    "narrow-serpentine": narrow_serpentine,
    "serpentine": serpentine,
    "pillars": pillars,
    "offices": offices,
    "hall": hall,
    "mixed": mixed,
}
