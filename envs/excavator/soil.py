"""The ground: a height map the bucket carves, and the soil's resistance.

Terrain
    Heights ``h[i, j]`` (m, up) of square cells of side ``cell`` (m); cell
    ``(i, j)`` covers ``x0 + [i, i+1) cell`` by ``y0 + [j, j+1) cell``. The
    bucket's cutting edge is a horizontal segment of the bucket width across
    the boom plane at the tip; between two steps it sweeps a quadrilateral and
    every cell it passes over is lowered to the edge's height there (sampled
    at the centres of sub-cells half a cell wide, ``np.minimum.at`` for cells
    hit twice: an aligned 1.2 m x 1.0 m sweep cuts exactly 12 x 10 cells).
    Only the cells under that quadrilateral are touched.

Bucket fill
    The soil cut goes into the bucket up to its capacity; a full bucket takes
    no more (the cut is scaled down so the removed volume equals the free
    capacity: the soil closes behind a full bucket instead of being created or
    destroyed). Soil leaves the bucket only by pouring (see the environment).
    Soil poured outside the truck is spread on the cells under the bucket.

Resistance (simplified fundamental earthmoving equation)
    Reece (1964): ``F = (gamma d^2 N_gamma + c d N_c + q d N_q) w`` for a blade
    of width ``w`` cutting at depth ``d`` (soil unit weight ``gamma``,
    cohesion ``c``, surcharge ``q``, dimensionless factors from the rake and
    friction angles). We drop the surcharge and the inertia term and keep
    ``N_gamma``, ``N_c`` constant (one soil, one rake angle), so
    ``F(d) = w (gamma N_gamma d^2 + c N_c d)``. The machine pushes with at
    most ``F_dig``; the bucket moves through soil at the fraction
    ``s = clip(1 - F / F_dig, s_min, 1)`` of the commanded joint rates
    (``s_min`` keeps it from locking, as an operator would still creep). With
    the default loam and a 1.2 m bucket: F(0.5 m) = 23.1 kN (s = 0.77),
    F(1.0 m) = 62.4 kN (s = 0.38); from about 1.3 m on the tip creeps at
    ``s_min`` = 5 %. The depth ``d`` is the depth of cut of the previous step
    (:attr:`Terrain.last_cut_depth`, the soil thickness the edge went through):
    the resistance acts with one step of lag, 0.1 s.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence

import numpy as np

from motiongym.envs.excavator.config import Machine

_ROUNDING = 1e-9  # m: covers the rounding of the edge heights interpolated between steps


def cutting_force(depth: float, width: float, m: Machine) -> float:
    """Simplified fundamental earthmoving equation ``F(d)`` in N (0 above ground)."""
    if depth <= 0.0:
        return 0.0
    return width * (
        m.soil_unit_weight * m.n_gamma * depth * depth + m.soil_cohesion * m.n_c * depth
    )


def speed_fraction(depth: float, width: float, m: Machine) -> float:
    """Fraction of the commanded rates the bucket achieves at ``depth`` (m below the surface)."""
    if depth <= 0.0:
        return 1.0
    return min(1.0, max(m.min_speed_fraction, 1.0 - cutting_force(depth, width, m) / m.dig_force))


@functools.lru_cache(maxsize=256)
def _sweep_weights(n_s: int, n_u: int) -> tuple[np.ndarray, np.ndarray]:
    """Bilinear weights of the sub-cell centres of the swept quad.

    Sample ``(s, u)`` at ``((k + 0.5) / n_s, (l + 0.5) / n_u)`` weighs the
    corners ``(a0, b0, a1, b1)`` by ``((1-s)(1-u), (1-s)u, s(1-u), su)``;
    also returns ``s`` per sample (for the edge height).
    """
    s = np.repeat((np.arange(n_s) + 0.5) / n_s, n_u)  # (n_s * n_u,)
    u = np.tile((np.arange(n_u) + 0.5) / n_u, n_s)
    weights = np.column_stack([(1 - s) * (1 - u), (1 - s) * u, s * (1 - u), s * u])
    weights.setflags(write=False)
    s.setflags(write=False)
    return weights, s


class Terrain:
    """A height map over a rectangle (see the module docstring)."""

    def __init__(self, heights: np.ndarray, origin: tuple[float, float], cell: float) -> None:
        self.h = np.array(heights, dtype=np.float64)  # (nx, ny) m
        self.x0, self.y0 = float(origin[0]), float(origin[1])
        self.cell = float(cell)
        self.nx, self.ny = self.h.shape
        self.version = 0  # bumped on every change (for caches)
        self.last_cut_depth = 0.0  # m: deepest cut of the last carve (the resistance depth)
        self.last_cut: tuple[int, int, np.ndarray] | None = None
        self.max_height = float(self.h.max())

    @property
    def extent(self) -> tuple[float, float, float, float]:
        """``(xmin, xmax, ymin, ymax)`` in m."""
        return (
            self.x0,
            self.x0 + self.nx * self.cell,
            self.y0,
            self.y0 + self.ny * self.cell,
        )

    def height_at(self, x: float, y: float) -> float:
        """Height of the cell under ``(x, y)`` (edge cells outside the map)."""
        i = min(max(int((x - self.x0) / self.cell), 0), self.nx - 1)
        j = min(max(int((y - self.y0) / self.cell), 0), self.ny - 1)
        return float(self.h[i, j])

    def heights_at(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """Vectorised :meth:`height_at`."""
        i = np.clip(((x - self.x0) / self.cell).astype(int), 0, self.nx - 1)
        j = np.clip(((y - self.y0) / self.cell).astype(int), 0, self.ny - 1)
        return self.h[i, j]

    def volume(self) -> float:
        """Soil volume above z = 0 minus the holes below it (m3)."""
        return float(self.h.sum() * self.cell * self.cell)

    def carve(
        self,
        edge0: tuple[Sequence[float], Sequence[float]],
        edge1: tuple[Sequence[float], Sequence[float]],
        z0: float,
        z1: float,
        free_capacity: float,
    ) -> float:
        """Lower the cells swept by the cutting edge; returns the volume taken (m3).

        Args:
            edge0, edge1: the edge's end points ``(a, b)`` (each xy, 2 floats) at the
                previous and the current step.
            z0, z1: the edge's height at those steps (m).
            free_capacity: room left in the bucket (m3); the cut is scaled to it.

        Sets :attr:`last_cut_depth`, the thickness of soil the edge went
        through (the depth of cut of the resistance model), and
        :attr:`last_cut`, ``(i0, j0, depths)``: the depth taken from each cell
        of the patch starting at cell ``(i0, j0)``.
        """
        self.last_cut_depth = 0.0
        swept = self._swept_cells(edge0, edge1, z0, z1)
        if swept is None:
            return 0.0
        i, j, zs, (i0, i1, j0, j1) = swept
        if free_capacity <= 0.0:
            # A full bucket takes nothing (the cut scaled to zero below), so only
            # the depth of cut is needed: the largest ``h - z`` over the samples.
            depth = float((self.h[i, j] - zs).max())
            if depth > 0.0:
                self.last_cut_depth = depth
                self.last_cut = (i0, j0, np.zeros((i1 - i0, j1 - j0)))
                self.version += 1
            return 0.0
        patch = self.h[i0:i1, j0:j1]  # a view
        old = patch.copy()
        np.minimum.at(self.h, (i, j), zs)
        cut = old - patch
        removed = float(cut.sum()) * self.cell * self.cell
        self.last_cut_depth = float(cut.max())
        if removed <= 0.0:
            return 0.0
        if removed > free_capacity:
            scale = max(free_capacity, 0.0) / removed
            cut *= scale
            patch[...] = old - cut
            removed = max(free_capacity, 0.0)
        self.last_cut = (i0, j0, cut)
        self.version += 1
        return removed

    def _swept_cells(
        self,
        edge0: tuple[Sequence[float], Sequence[float]],
        edge1: tuple[Sequence[float], Sequence[float]],
        z0: float,
        z1: float,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, tuple[int, int, int, int]] | None:
        """The edge's sweep sampled at half a cell: each sample's cell ``(i, j)`` and
        height, and the patch ``(i0, i1, j0, j1)`` holding them, clipped to the map;
        None when the sweep cuts nothing (above its cells, or off the map)."""
        half = 0.5 * self.cell
        n_u = max(int(math.ceil(math.dist(edge1[0], edge1[1]) / half)), 1)
        travel = max(math.dist(edge0[0], edge1[0]), math.dist(edge0[1], edge1[1]))
        n_s = max(int(math.ceil(travel / half)), 1)
        inv = 1.0 / self.cell
        xs = (edge0[0][0], edge0[1][0], edge1[0][0], edge1[1][0])
        ys = (edge0[0][1], edge0[1][1], edge1[0][1], edge1[1][1])
        i0, i1 = int((min(xs) - self.x0) * inv), int((max(xs) - self.x0) * inv) + 1
        j0, j1 = int((min(ys) - self.y0) * inv), int((max(ys) - self.y0) * inv) + 1
        # Most sweeps pass over the ground: nothing is cut when the edge stays
        # above every cell of the sweep's bounding box (on the map), which
        # holds every sample's cell.
        box = self.h[max(i0, 0) : min(i1, self.nx), max(j0, 0) : min(j1, self.ny)]
        if box.size == 0 or min(z0, z1) - _ROUNDING >= box.max():
            return None
        weights, along = _sweep_weights(n_s, n_u)  # (n_s * n_u, 4), (n_s * n_u,)
        pts = weights @ np.array((edge0[0], edge0[1], edge1[0], edge1[1]))  # (n_s * n_u, 2)
        zs = z0 + along * (z1 - z0)
        ij = ((pts - (self.x0, self.y0)) * inv).astype(np.intp)
        i, j = ij[:, 0], ij[:, 1]
        if min(xs) < self.x0 or min(ys) < self.y0 or i1 > self.nx or j1 > self.ny:
            keep = (i >= 0) & (i < self.nx) & (j >= 0) & (j < self.ny)  # partly off the map
            if not keep.any():
                return None
            i, j, zs = i[keep], j[keep], zs[keep]
            i0, i1 = max(i0, 0), min(i1, self.nx)
            j0, j1 = max(j0, 0), min(j1, self.ny)
        return i, j, zs, (i0, i1, j0, j1)

    def deposit(self, x: float, y: float, volume: float, radius: float = 0.5) -> None:
        """Spread ``volume`` (m3) evenly over the cells within ``radius`` of ``(x, y)``."""
        if volume <= 0.0:
            return
        r = int(math.ceil(radius / self.cell))
        ci = int((x - self.x0) / self.cell)
        cj = int((y - self.y0) / self.cell)
        i0, i1 = max(ci - r, 0), min(ci + r + 1, self.nx)
        j0, j1 = max(cj - r, 0), min(cj + r + 1, self.ny)
        if i0 >= i1 or j0 >= j1:
            return  # outside the map: the soil is lost from view but still counted as spill
        patch = self.h[i0:i1, j0:j1]
        patch += volume / (patch.size * self.cell * self.cell)
        self.max_height = max(self.max_height, float(patch.max()))
        self.version += 1
