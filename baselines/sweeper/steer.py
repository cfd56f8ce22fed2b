"""Following a path of cells when every move is turned by an estimated heading error.

Under odometry error a commanded heading ``g`` moves the robot along
``g * pi / 2 + e`` (``e`` the heading error, a random walk that no action
undoes: turns are quarter turns). Past a few tenths of a radian, "turn to
the next cell's direction, then forward" lands beside the path, the robot
replans and does it again. :func:`steer` instead predicts, from the
estimated continuous pose ``(y, x)`` and heading error (the localiser's), the
cell each of the four commanded headings leads to (the odometry model of the
environment, its mean move of one cell; a one-step model-predictive choice
of the command, the predict-then-act loop of Thrun, Burgard & Fox 2005,
"Probabilistic Robotics", ch. 5 and 17) and takes the heading that reaches
the path's next cell (or the one after it, a diagonal step) with the fewest
turns; when none does, the one whose predicted position comes closest to
the next cell's centre without leaving the current cell or entering a
blocked one (the continuous pose creeps until a move rounds onto the path).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Collection, Sequence

from motiongym.envs.sweeper.occupancy import DC, DR
from motiongym.envs.sweeper.world import FORWARD, LEFT, RIGHT

# cell step -> heading, the inverse of the world's (DR, DC)
DIRECTION = {(int(DR[h]), int(DC[h])): h for h in range(4)}


def turn_towards(heading: int, target: int) -> int:
    """The turn action that brings ``heading`` closer to ``target`` (left on a reversal)."""
    return RIGHT if (target - heading) % 4 == 3 else LEFT


def _turns(h: int, g: int) -> int:
    return (0, 1, 2, 1)[(g - h) % 4]


def steer(
    h: int,
    pose: tuple[float, float, float],
    cell: tuple[int, int],
    path: Sequence[tuple[int, int]],
    free: Callable[[tuple[int, int]], bool],
    blocked: Collection[int] = (),
) -> int | None:
    """The action (0 forward, 1 left, 2 right) towards ``path[0]``.

    Args:
        h: the commanded heading now (0 east, 1 north, 2 west, 3 south).
        pose: ``(y, x, e)``: estimated continuous row, column and heading error.
        cell: the estimated cell (``round(y), round(x)`` or the localiser's).
        path: the next cells, ``path[0]`` next to ``cell``.
        free: whether the robot may stand at a cell (its footprint free in the map).
        blocked: commanded headings that bumped from this cell (never taken again here).

    Returns None when no heading is left to try (every useful one bumped here).
    """
    y, x, e = pose
    r, c = cell
    target = path[0]
    best: tuple | None = None
    here = math.hypot(y - target[0], x - target[1])
    for g in range(4):
        if g in blocked:
            continue
        a = g * math.pi / 2 + e
        py, px = y - math.sin(a), x + math.cos(a)
        q = (int(round(py)), int(round(px)))
        dr, dc = q[0] - r, q[1] - c
        if abs(dr) > 1 or abs(dc) > 1 or (q != cell and not free(q)):
            continue
        if dr and dc and not (free((r + dr, c)) or free((r, c + dc))):
            continue  # the environment refuses a corner cut past a blocked cell
        if q == target:
            progress = 1
        elif len(path) > 1 and q == path[1]:
            progress = 2
        elif q == cell and math.hypot(py - target[0], px - target[1]) < here:
            progress = 0
        else:
            continue  # off the path
        dist = math.hypot(py - target[0], px - target[1])
        key = (progress > 0, progress, -_turns(h, g), -dist) if progress else (False, 0, -dist, 0)
        if best is None or key > best[0]:
            best = (key, g)
    if best is None:  # nothing predicted to stay on the path: the plain rule
        g = DIRECTION.get((target[0] - r, target[1] - c), h)
        if g in blocked:
            return None
    else:
        g = best[1]
    return FORWARD if g == h else turn_towards(h, g)
