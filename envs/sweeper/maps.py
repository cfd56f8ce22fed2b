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

import os
import pathlib

import numpy as np
from scipy import ndimage

from motiongym.envs.sweeper.occupancy import config_free, is_closed

MAPS_DIR = pathlib.Path(__file__).with_name("map_files")
SHIPPED_MAPS = ("room", "apartment", "maze")
MAX_SIDE = 256  # largest map side (cells) the observation space allows
MAX_MAP_BYTES = 1 << 20  # largest map file: a 256 x 256 text map is 66 kB


class MapError(ValueError):
    """A map that cannot be used; the one-line message names the line and column.

    Text maps count lines and columns from 1, as editors do; bitmaps (arrays,
    PNG) count rows and columns from 0, as NumPy does.
    """


def parse_text_map(text: str, source: str = "<text>") -> np.ndarray:
    """Parse ``#``/``.`` rows into an ``(H, W)`` bool obstacle array.

    Every line must have the same length and hold only ``#`` and ``.``
    (blank lines after the map are ignored), so that line ``i`` is row ``i - 1``.
    Lines end at ``\n`` (or ``\r\n``) only: any other character, a form feed
    or a Unicode line separator included, is refused with its place. At most
    :data:`MAX_SIDE` lines and columns, checked before the cells are read.
    """
    lines = [line.removesuffix("\r") for line in text.split("\n")]
    while lines and not lines[-1].strip():
        lines.pop()
    if not lines:
        raise MapError(f"map {source} is empty")
    first, last = 0, len(lines) - 1
    width = len(lines[first])
    if len(lines) > MAX_SIDE or width > MAX_SIDE:
        raise MapError(
            f"map {source} has {len(lines)} lines of {width} cells; at most {MAX_SIDE} "
            "of each are allowed"
        )
    grid = np.ones((last - first + 1, width), dtype=bool)
    for i in range(first, last + 1):
        row = lines[i]
        for j, char in enumerate(row):
            if char not in "#.":
                raise MapError(
                    f"map {source} line {i + 1}, column {j + 1}: character {char!r}; "
                    "use '#' (obstacle) and '.' (free)"
                )
        if len(row) != width:
            column = min(len(row), width) + 1
            raise MapError(
                f"map {source} line {i + 1}, column {column}: ragged rows, this line has "
                f"{len(row)} cells where line {first + 1} has {width}"
            )
        grid[i - first] = np.frombuffer(row.encode(), dtype=np.uint8) == ord("#")
    return grid


def to_text(grid: np.ndarray) -> str:
    """The text form of an obstacle array (inverse of :func:`parse_text_map`)."""
    return "\n".join("".join("#" if v else "." for v in row) for row in grid) + "\n"


def load_map_file(path: str | os.PathLike, w: int = 1) -> np.ndarray:
    """Load a user map from a ``.txt`` or ``.png`` file and validate it for robot width ``w``."""
    path = pathlib.Path(path)
    if not path.is_file():
        raise MapError(f"map_file must be an existing .txt or .png file, got {str(path)!r}")
    suffix = path.suffix.lower()
    if suffix not in (".png", ".txt", ".map"):
        raise MapError(f"map file {str(path)!r}: unknown format {suffix!r}; use .txt or .png")
    size = path.stat().st_size
    if size > MAX_MAP_BYTES:
        raise MapError(f"map file {str(path)!r} is {size} bytes; at most {MAX_MAP_BYTES} allowed")
    if suffix == ".png":
        grid, text = _read_png(path), False
    else:
        try:
            content = path.read_bytes().decode("utf-8")
        except UnicodeDecodeError as error:
            raise MapError(
                f"map file {str(path)!r}: byte {error.start} is not UTF-8 text; "
                "use '#' (obstacle) and '.' (free)"
            ) from None
        grid, text = parse_text_map(content, source=repr(str(path))), True
    return validate_map(grid, w, source=f"map {str(path)!r}", text=text)


def _read_png(path: pathlib.Path) -> np.ndarray:
    """The obstacle array of a PNG map (dark pixels), its size checked before decoding."""
    from PIL import Image

    try:
        with Image.open(path, formats=["PNG"]) as image:
            width, height = image.size
            if max(width, height) > MAX_SIDE:
                raise MapError(
                    f"map file {str(path)!r} is {width} x {height} pixels; at most "
                    f"{MAX_SIDE} on a side allowed"
                )
            grey = np.asarray(image.convert("L"))
    except MapError:
        raise
    except Exception as error:  # noqa: BLE001 - any image from anyone: PIL's many errors
        problem = " ".join(str(error).split())[:200]
        raise MapError(f"map file {str(path)!r} is not a readable PNG ({problem})") from None
    return grey < 128


def _cell(r: int, c: int, text: bool) -> str:
    """Where a cell is, as the user counts: text lines from 1, bitmap rows from 0."""
    return f"line {r + 1}, column {c + 1}" if text else f"row {r}, column {c}"


def validate_map(
    grid: np.ndarray, w: int = 1, source: str = "map", text: bool = False
) -> np.ndarray:
    """Check shape, closedness and room for a ``w x w`` robot; return the map as a bool array.

    ``text``: name cells by line and column from 1 (a text map) rather than
    by row and column from 0.
    """
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
            f"{source} is not closed: {_cell(int(rows[k]), int(cols[k]), text)} is a free "
            "cell on the border; surround the area with obstacle cells"
        )
    if not config_free(grid, w).any():
        k = max(v for v in range(1, w) if config_free(grid, v).any()) if w > 1 else 0
        r, c = np.argwhere(config_free(grid, k))[0] if k else (0, 0)
        raise MapError(
            f"{source} has no free place for a robot of width {w}: the widest free "
            f"square is {k} x {k} cells, at {_cell(int(r), int(c), text)} (its top-left)"
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
