"""RGB image of the sweeper world: map, swept cells, path, robot (paper Fig. 7-14 style).

:func:`frame` is what ``render()`` returns (the single environment and its
vector twin): with ``render_size`` None, the map at ``cell_pixels`` (8 by
default) pixels per cell, the frame as large as the map; with
``render_size`` = (rows, columns), a frame of exactly that shape, the map
drawn at the largest whole number of pixels per cell that fits and centred,
the margin in the obstacle colour (outside the map is obstacle). A map
larger than the frame at one pixel per cell is shrunk to fit by
nearest-neighbour sampling. So the frames of an episode, or of random maps
of several sizes, all have one shape.
"""

from __future__ import annotations

import numpy as np

from motiongym.envs.sweeper.occupancy import DC, DR
from motiongym.envs.sweeper.state import SweeperState

OBSTACLE = np.array([20, 20, 20], np.uint8)
UNREACHABLE = np.array([150, 150, 170], np.uint8)
FREE = np.array([255, 255, 255], np.uint8)
SWEPT = np.array([190, 190, 190], np.uint8)  # the paper's grey
OVERSWEPT = np.array([130, 130, 130], np.uint8)  # swept more than once
PATH = np.array([30, 90, 220], np.uint8)
ROBOT = np.array([220, 40, 40], np.uint8)
BELIEVED = np.array([250, 160, 0], np.uint8)


CELL_PIXELS = 8  # pixels per cell without a render_size


def frame(
    state: SweeperState, w: int, render_size: tuple[int, int] | None, cell_pixels: int | None
) -> np.ndarray:
    """The rendered frame of a world's ``state`` (module docstring)."""
    if render_size is None:
        return draw(state, w, cell_pixels or CELL_PIXELS)
    rows, cols = render_size
    h, wd = state.scenario.obstacle.shape
    px = min(rows // h, cols // wd)
    if px >= 1:
        img = draw(state, w, px)
    else:
        scale = min(rows / h, cols / wd)
        nh, nw = max(1, int(h * scale)), max(1, int(wd * scale))
        img = draw(state, w, 1)[(np.arange(nh) * h) // nh][:, (np.arange(nw) * wd) // nw]
    out = np.empty((rows, cols, 3), np.uint8)
    out[:] = OBSTACLE
    top, left = (rows - img.shape[0]) // 2, (cols - img.shape[1]) // 2
    out[top : top + img.shape[0], left : left + img.shape[1]] = img
    return out


def draw(state: SweeperState, w: int, px: int = CELL_PIXELS) -> np.ndarray:
    """``(H * px, W * px, 3)`` uint8 image of a world's ``state`` (robot width ``w``).

    The believed footprint is outlined too where odometry error moved it off
    the true one.
    """
    sc = state.scenario
    h, wd = sc.obstacle.shape
    img = np.empty((h, wd, 3), np.uint8)
    img[:] = FREE
    img[~sc.reachable & ~sc.obstacle] = UNREACHABLE
    img[sc.obstacle] = OBSTACLE
    img[state.sweeps == 1] = SWEPT
    img[state.sweeps > 1] = OVERSWEPT
    img = img.repeat(px, axis=0).repeat(px, axis=1)
    centre = (w * px) // 2
    dot = max(1, px // 4)
    for r, c in state.path:  # path of the footprint centre
        y, x = r * px + centre, c * px + centre
        img[y - dot : y + dot, x - dot : x + dot] = PATH
    if (state.believed_row, state.believed_col) != (state.row, state.col):
        _square(img, state.believed_row * px, state.believed_col * px, w * px, BELIEVED)
    _square(img, state.row * px, state.col * px, w * px, ROBOT)
    y, x = state.row * px + centre, state.col * px + centre
    for k in range(centre):  # heading marker
        yy, xx = y + int(DR[state.heading]) * k, x + int(DC[state.heading]) * k
        img[yy - dot : yy + dot, xx - dot : xx + dot] = ROBOT
    return img


def _square(img: np.ndarray, y: int, x: int, size: int, colour: np.ndarray) -> None:
    t = max(1, size // 12)
    img[y : y + t, x : x + size] = colour
    img[y + size - t : y + size, x : x + size] = colour
    img[y : y + size, x : x + t] = colour
    img[y : y + size, x + size - t : x + size] = colour
