"""Occupancy bitmaps: the shipped maps, user map files, validation, rotation.

A map is an ``(H, W)`` bool array, True for wall/obstacle cells (the paper's
black pixels, section 4.1). Text files use ``#`` for an obstacle and ``.``
for a free cell, one row per line; PNG files are read as grey levels, dark
pixels (< 128) being obstacles.

Shipped maps (our stand-ins for the paper's figures, which the text lacks):

========== ======= ==================================================
name       H x W   content
========== ======= ==================================================
room       30 x 40 a room with a table, a cabinet and a pillar (Fig. 6)
apartment  40 x 60 five rooms, a corridor, doors, furniture (Fig. 11)
maze       48 x 48 a 5 x 5 maze, corridors 7 cells, walls 2 (Fig. 12)
========== ======= ==================================================
"""

from __future__ import annotations

import pathlib

import numpy as np
from scipy import ndimage

from motiongym.envs.sweeper.occupancy import is_closed

MAPS_DIR = pathlib.Path(__file__).with_name("map_files")
SHIPPED_MAPS = ("room", "apartment", "maze")
MAX_SIDE = 256  # largest map side (cells) the observation space allows


class MapError(ValueError):
    """A map that cannot be used: missing, empty of free cells, or not closed."""


def parse_text_map(text: str, source: str = "<text>") -> np.ndarray:
    """Parse ``#``/``.`` rows into an ``(H, W)`` bool obstacle array."""
    rows = [line.rstrip("\n\r") for line in text.splitlines() if line.strip()]
    if not rows:
        raise MapError(f"map {source} is empty")
    width = max(len(row) for row in rows)
    grid = np.ones((len(rows), width), dtype=bool)
    for i, row in enumerate(rows):
        bad = set(row) - {"#", "."}
        if bad:
            raise MapError(
                f"map {source} row {i} has characters {sorted(bad)}; "
                "use '#' (obstacle) and '.' (free)"
            )
        grid[i, : len(row)] = np.frombuffer(row.encode(), dtype=np.uint8) == ord("#")
    return grid


def to_text(grid: np.ndarray) -> str:
    """The text form of an obstacle array (inverse of :func:`parse_text_map`)."""
    return "\n".join("".join("#" if v else "." for v in row) for row in grid) + "\n"


def load_map_file(path: str | pathlib.Path) -> np.ndarray:
    """Load a user map from a ``.txt`` or ``.png`` file and validate it."""
    path = pathlib.Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"map file {str(path)!r} does not exist")
    suffix = path.suffix.lower()
    if suffix == ".png":
        from PIL import Image

        grey = np.asarray(Image.open(path).convert("L"))
        grid = grey < 128
    elif suffix in (".txt", ".map"):
        grid = parse_text_map(path.read_text(), source=repr(str(path)))
    else:
        raise MapError(f"map file {str(path)!r}: unknown format {suffix!r}; use .txt or .png")
    return validate_map(grid, source=repr(str(path)))


def validate_map(grid: np.ndarray, w: int = 1, source: str = "map") -> np.ndarray:
    """Check shape, closedness and free space; return the map as a bool array."""
    grid = np.asarray(grid, dtype=bool)
    if grid.ndim != 2:
        raise MapError(f"{source}: expected a 2-D bitmap, got shape {grid.shape}")
    if max(grid.shape) > MAX_SIDE:
        raise MapError(f"{source}: shape {grid.shape} exceeds the largest side {MAX_SIDE}")
    if grid.all():
        raise MapError(f"{source} has no free cell")
    if not is_closed(grid):
        rows, cols = np.nonzero(~grid)
        on_border = (rows == 0) | (cols == 0) | (rows == grid.shape[0] - 1)
        on_border |= cols == grid.shape[1] - 1
        k = int(np.argmax(on_border))
        raise MapError(
            f"{source} is not closed: free cell ({rows[k]}, {cols[k]}) lies on the border; "
            "surround the area with obstacle cells"
        )
    return grid


def shipped_map(name: str) -> np.ndarray:
    """One of the maps shipped with the package (see :data:`SHIPPED_MAPS`)."""
    if name not in SHIPPED_MAPS:
        raise MapError(f"unknown map {name!r}; shipped maps: {', '.join(SHIPPED_MAPS)}")
    return validate_map(
        parse_text_map((MAPS_DIR / f"{name}.txt").read_text(), name), source=f"map {name!r}"
    )


def rotate_map(grid: np.ndarray, angle_deg: float, upsample: int = 1) -> np.ndarray:
    """The map turned by ``angle_deg`` about its centre, re-closed with a border wall.

    Used for the start-orientation study (paper 4.1.3): our robot moves on the
    grid's axes, so a robot placed at an angle to the walls is modelled by
    turning the walls instead. Nearest-neighbour resampling; cells outside the
    original map become obstacles.
    """
    big = np.kron(grid, np.ones((upsample, upsample), dtype=bool)) if upsample > 1 else grid
    turned = ndimage.rotate(
        big.astype(np.uint8), angle_deg, reshape=True, order=0, mode="constant", cval=1
    ).astype(bool)
    turned[0, :] = turned[-1, :] = True
    turned[:, 0] = turned[:, -1] = True
    return turned
