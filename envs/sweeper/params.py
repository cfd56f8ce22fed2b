"""The sweeper's parameters: one frozen dataclass built from the environment's keywords.

:class:`SweeperParams` is what ``SweeperEnv(**kwargs)``, its vector twin and
the scripted policies all build from the same keyword arguments
(:meth:`SweeperParams.from_kwargs`), so every default is written here once
and every bad value is refused at construction, never per step.
"""

from __future__ import annotations

import dataclasses
import os
from collections.abc import Mapping
from typing import Any, ClassVar

from motiongym.envs.core import (
    ArgumentError,
    Deprecated,
    check_bool,
    check_choice,
    check_float,
    check_int,
    check_render_size,
    check_shape,
    check_weight,
    params_from_kwargs,
)
from motiongym.envs.sweeper import families, generator, maps

MAP_CHOICES = (*maps.SHIPPED_MAPS, "random", *(f"random-{k}" for k in generator.KINDS))
MAX_ROBOT_WIDTH = 10  # cells
MAX_SENSOR_RANGE = 16  # cells beyond the footprint
MAX_COARSE = 64  # K: the coarse maps hold K * K numbers each
MAX_CELL_PIXELS = 32  # deprecated cell_pixels: pixels per cell (a 256-cell side: 8,192 pixels)
MAX_NOISE = 1.0  # rad per action (heading), relative std (slip)


@dataclasses.dataclass(frozen=True, eq=False)
class SweeperParams:
    """Every keyword argument of ``SweeperEnv``, checked, with its default.

    ============== ========= ===================================================
    name           default   allowed (the limits bound memory and time per step)
    ============== ========= ===================================================
    map_name       "room"    "room", "apartment", "maze", "random",
                             "random-room", "random-apartment", "random-maze"
    map_file       None      a path (str or os.PathLike) to a .txt or .png map;
                             overrides ``map_name``
    grid           None      an (H, W) array of bools or finite numbers
                             (nonzero: obstacle), at most 256 a side;
                             overrides both
    map_family     None      None or a family of
                             :mod:`~motiongym.envs.sweeper.families`
                             ("narrow-corridors", "corridors",
                             "narrow-serpentine", "serpentine", "pillars",
                             "offices", "hall", "mixed"); overrides
                             ``map_name``; not with ``grid`` or ``map_file``
    map_seed       None      None or an integer in [0, 2**32 - 1]: the map
                             of ``map_family`` drawn from it, fixed for every
                             episode; None: each reset draws a map seed from
                             the episode's generator. Only with ``map_family``
    map_size       None      None or (rows, columns), integers in
                             [4 * robot_width + 6, 256]; None: (40, 60), each
                             side raised to 4 * robot_width + 6 where shorter.
                             Only with ``map_family``
    robot_width    3         integer cells in [1, 10]
    sensor_range   None      integer cells in [1, 16] beyond the footprint;
                             None: ``robot_width``
    coarse         16        K, integer in [1, 64] (coarse maps of K * K)
    heading_noise  0.0       rad std per action, finite in [0, 1]
    slip_noise     0.0       relative std of a move's length, finite in [0, 1]
    sweep          1.0       weight of the ``sweep`` reward term (paid per
                             fresh lane cell); a reward weight is a magnitude,
                             finite in [0, 1e6] (so are the next two)
    time           0.05      weight of the ``time`` term, a cost: subtracted
                             on every step
    bump           1.0       weight of the ``bump`` term, a cost: subtracted
                             on a bump
    render_size    None      (rows, columns) of a frame, integers in
                             [16, 2048]; None: 8 pixels per cell, the frame
                             as large as the map
    cell_pixels    None      deprecated (use ``render_size``): pixels per
                             cell, integer in [1, 32]; not with ``render_size``
    line_of_sight  False     True or False (True: ``Sweeper-v1``)
    ============== ========= ===================================================

    A negative reward weight is refused, never flipped (a silent flip would
    turn a cost into a reward); for ``time`` and ``bump`` the message names
    the positive weight of the same reward
    (:func:`motiongym.envs.core.check_weight`).

    Maps are at most 256 cells a side (:data:`maps.MAX_SIDE`), checked when
    the map is loaded. So the sensing window has at most ``S = 10 + 2 * 16 =
    42`` cells a side, a step touches at most ``S^2`` cells (and, with line
    of sight, a product over at most 2.36 M line entries, built once), and a
    frame has at most ``8,192^2`` pixels (``cell_pixels`` = 32), else at
    most ``2,048^2``.
    """

    map_name: str = "room"
    map_file: str | os.PathLike | None = None
    grid: Any = None
    map_family: str | None = None  # a generated family (families.FAMILIES)
    map_seed: int | None = None  # in [0, families.MAX_MAP_SEED]; None: drawn per episode
    map_size: tuple[int, int] | None = None  # rows, columns (cells); None: (40, 60)
    robot_width: int = 3  # cells
    # cells beyond the footprint; None given: robot_width (an int after __post_init__)
    sensor_range: int = None  # type: ignore[assignment]
    coarse: int = 16  # built-map resolution in the observation
    heading_noise: float = 0.0  # rad, std per action
    slip_noise: float = 0.0  # relative std of a forward move's length
    sweep: float = 1.0  # per fresh lane cell
    time: float = 0.05  # per step, subtracted
    bump: float = 1.0  # per bump, subtracted
    render_size: tuple[int, int] | None = None  # rows, columns; None: 8 pixels per cell
    cell_pixels: int | None = None  # deprecated: pixels per cell
    line_of_sight: bool = False  # v1's sensing

    DEPRECATED: ClassVar[dict[str, Deprecated]] = {
        "cell_pixels": Deprecated(None, note="use render_size=(rows, columns)"),
    }

    def __post_init__(self) -> None:
        check_choice("map_name", self.map_name, MAP_CHOICES)
        if self.map_file is not None and not isinstance(self.map_file, (str, os.PathLike)):
            raise ArgumentError(f"map_file must be None or a path, got {self.map_file!r}")
        if self.grid is not None:  # its size, closedness and room: maps.validate_map
            check_shape("grid", self.grid, (None, None))
        w = check_int("robot_width", self.robot_width, 1, MAX_ROBOT_WIDTH)
        R = w if self.sensor_range is None else self.sensor_range
        R = check_int("sensor_range", R, 1, MAX_SENSOR_RANGE)
        set_ = object.__setattr__
        self._check_family(w)
        set_(self, "robot_width", w)
        set_(self, "sensor_range", R)
        set_(self, "coarse", check_int("coarse", self.coarse, 1, MAX_COARSE))
        for name in ("heading_noise", "slip_noise"):
            set_(self, name, check_float(name, getattr(self, name), 0.0, MAX_NOISE))
        for name in ("sweep", "time", "bump"):
            set_(self, name, check_weight(name, getattr(self, name), cost=name != "sweep"))
        if self.render_size is not None:
            set_(self, "render_size", check_render_size("render_size", self.render_size))
        if self.cell_pixels is not None:
            px = check_int("cell_pixels", self.cell_pixels, 1, MAX_CELL_PIXELS)
            set_(self, "cell_pixels", px)
            if self.render_size is not None:
                raise ArgumentError(
                    f"give render_size or the deprecated cell_pixels, not both; got "
                    f"render_size={self.render_size!r}, cell_pixels={px!r}"
                )
        set_(self, "line_of_sight", check_bool("line_of_sight", self.line_of_sight))

    def _check_family(self, w: int) -> None:
        """Check ``map_family``, ``map_seed``, ``map_size`` (and that they come alone)."""
        set_ = object.__setattr__
        if self.map_family is None:
            listed = ", ".join(map(repr, families.FAMILIES))
            for name in ("map_seed", "map_size"):
                if getattr(self, name) is not None:
                    raise ArgumentError(
                        f"{name} needs map_family (one of {listed}); got "
                        f"{name}={getattr(self, name)!r} with map_family=None"
                    )
            return
        check_choice("map_family", self.map_family, families.FAMILIES)
        for name in ("grid", "map_file"):
            if getattr(self, name) is not None:
                raise ArgumentError(
                    f"give map_family or {name}, not both; got map_family={self.map_family!r} "
                    f"and {name}={getattr(self, name)!r}"
                )
        if self.map_seed is not None:
            set_(self, "map_seed", check_int("map_seed", self.map_seed, 0, families.MAX_MAP_SEED))
        if self.map_size is not None:
            set_(self, "map_size", families.check_size(self.map_size, w))

    @classmethod
    def from_kwargs(cls, kwargs: Mapping[str, Any]) -> SweeperParams:
        """The parameters from an environment's keywords (``render_mode`` and
        ``max_episode_steps``, which are not the world's, are ignored)."""
        return params_from_kwargs(cls, kwargs, ignore=("render_mode", "max_episode_steps"))

    @property
    def window(self) -> int:
        """``S``: side of the sensing window, ``robot_width + 2 * sensor_range`` cells."""
        return self.robot_width + 2 * self.sensor_range

    @property
    def noisy(self) -> bool:
        """True when odometry noise makes the believed pose drift from the true one."""
        return self.heading_noise > 0 or self.slip_noise > 0
