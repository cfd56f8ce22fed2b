"""The buried pipe and the truck body, and the arm's clearance to them.

The arm is three capsules about the segments boom (foot pin to stick pin),
stick (to the bucket pin) and bucket (pin to cutting edge), with the radii of
:attr:`Machine.link_radius`. Clearance is the distance between surfaces
(negative when they overlap):

* pipe: a capsule of radius ``r`` about a straight segment below the ground
  (a utility located by a locate survey); clearance = segment-segment
  distance (:func:`motiongym.envs.geometry.segment_distance`) - link radius - ``r``.
* truck: the body as a box (footprint ``length x width`` turned by ``yaw``,
  from the ground up to the rim height; the open bed is inside it, so a bucket
  must stay above the rim). The segment-box distance is exact, computed in
  the box's frame by :func:`segment_box_distance`.

Both are scalar math: the arm has three links, where NumPy's per-call
overhead would dominate. Broad phase: an environment step first takes cheap
lower bounds (:meth:`ExcavatorBase._clearances`) and runs the exact
computation only when a bound is under ``horizon``; beyond it the reported
clearance is that lower bound (it is then larger than ``horizon``, 1 m,
which is larger than every safety distance).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from motiongym.envs.geometry import segment_distance


@dataclass(frozen=True)
class Pipe:
    """A buried pipe: centre-line end points (m, frame M) and radius (m)."""

    a: tuple[float, float, float]
    b: tuple[float, float, float]
    radius: float

    @property
    def top(self) -> float:
        """Highest point of the pipe's surface (m)."""
        return max(self.a[2], self.b[2]) + self.radius

    def as_array(self) -> np.ndarray:
        """``[ax, ay, az, bx, by, bz, radius]``, shape (7,)."""
        return np.array([*self.a, *self.b, self.radius])


@dataclass(frozen=True)
class Truck:
    """A truck body: footprint centre and yaw, half length and width, rim height (m, rad).

    The box spans ``floor`` (the ground) to ``height`` (the rim), both heights in frame O.
    """

    cx: float
    cy: float
    yaw: float
    half_length: float
    half_width: float
    height: float
    floor: float = 0.0  # m: the ground under the body (0 on level ground)

    def as_array(self) -> np.ndarray:
        """``[cx, cy, yaw, half_length, half_width, height]``, shape (6,)."""
        return np.array(
            [self.cx, self.cy, self.yaw, self.half_length, self.half_width, self.height]
        )

    def to_local(self, x: float, y: float) -> tuple[float, float]:
        """Footprint coordinates (along, across) of a point (m)."""
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        dx, dy = x - self.cx, y - self.cy
        return c * dx + s * dy, -s * dx + c * dy

    def contains_xy(self, x: float, y: float, margin: float = 0.0) -> bool:
        """Whether ``(x, y)`` lies over the footprint shrunk by ``margin``."""
        u, v = self.to_local(x, y)
        return abs(u) <= self.half_length - margin and abs(v) <= self.half_width - margin

    def corners(self) -> list[tuple[float, float]]:
        """The footprint's corners ``(x, y)`` in frame M (m), counter-clockwise."""
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        hl, hw = self.half_length, self.half_width
        return [
            (self.cx + c * u - s * v, self.cy + s * u + c * v)
            for u, v in ((-hl, -hw), (hl, -hw), (hl, hw), (-hl, hw))
        ]

    def box(self) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
        """The box in its own frame (along, across, up): ``(low, high)`` corners (m)."""
        hl, hw = self.half_length, self.half_width
        return (-hl, -hw, self.floor), (hl, hw, self.height)


def pipe_clearance(
    points: Sequence[Sequence[float]],
    radii: Sequence[float],
    pipe: Pipe,
    lower_bounds: Sequence[float] | None = None,
) -> float:
    """Exact clearance of a chain of capsules (as in :func:`truck_clearance`) to the pipe (m).

    ``lower_bounds`` (optional, one per capsule) are lower bounds of each
    capsule's clearance: the capsules are then visited from the smallest
    bound up, and the visit stops at a bound not below the smallest clearance
    so far, which leaves the minimum unchanged.
    """
    order: Sequence[int] = range(len(radii))
    if lower_bounds is not None:
        order = sorted(order, key=lower_bounds.__getitem__)
    out = math.inf
    for k in order:
        if lower_bounds is not None and lower_bounds[k] >= out:
            break
        d = segment_distance(points[k], points[k + 1], pipe.a, pipe.b)
        out = min(out, d - radii[k] - pipe.radius)
    return float(out)


def segment_box_distance(
    p0: Sequence[float], p1: Sequence[float], low: Sequence[float], high: Sequence[float]
) -> float:
    """Exact distance from the segment ``p0 p1`` to the box ``[low, high]`` (3D, one frame).

    With ``p(t) = p0 + t (p1 - p0)``, the squared distance is
    ``g(t) = sum_i dist(p_i(t), [low_i, high_i])^2``: convex, and quadratic
    between the (at most six) parameters where the segment crosses a face
    plane. The pieces are visited in order of ``t``; on each, the axes outside
    the slab give ``g(t) = A t^2 + 2 B t + C`` with the minimiser ``-B / A``;
    the first piece whose minimiser is not beyond its end holds the global
    minimum (convexity), else the minimum is at ``t = 1``. The distance is
    evaluated at that ``t`` from the point itself (not from ``A, B, C``, which
    would lose digits to cancellation). 0 when the segment meets the box.
    Agrees with the closest of the 12 box edges and the two end points
    (Ericson's segment-segment routine, :mod:`motiongym.envs.geometry`) to
    rounding (tested).
    """
    axes = (
        (p0[0], p1[0] - p0[0], low[0], high[0]),
        (p0[1], p1[1] - p0[1], low[1], high[1]),
        (p0[2], p1[2] - p0[2], low[2], high[2]),
    )  # (start, direction, slab low, slab high) per axis
    cuts = [0.0]
    for a, d, lo, hi in axes:
        if d != 0.0:
            t = (lo - a) / d
            if 0.0 < t < 1.0:
                cuts.append(t)
            t = (hi - a) / d
            if 0.0 < t < 1.0:
                cuts.append(t)
    cuts.sort()
    cuts.append(1.0)
    for t0, t1 in zip(cuts[:-1], cuts[1:], strict=True):
        mid = 0.5 * (t0 + t1)
        quad = lin = 0.0
        for a, d, lo, hi in axes:
            x = a + mid * d
            if x < lo:
                quad += d * d
                lin += (a - lo) * d
            elif x > hi:
                quad += d * d
                lin += (a - hi) * d
        if quad == 0.0:  # g is constant on the piece (0 inside the box)
            t = t0
            break
        t = -lin / quad
        if t < t1:
            t = max(t, t0)
            break
    else:
        t = 1.0
    total = 0.0
    for a, d, lo, hi in axes:
        x = a + t * d
        gap = lo - x if x < lo else x - hi if x > hi else 0.0
        total += gap * gap
    return math.sqrt(total)


def truck_clearance(
    points: Sequence[Sequence[float]], radii: Sequence[float], truck: Truck
) -> float:
    """Exact clearance of a chain of capsules to the truck box (m).

    Capsule ``k`` is about the segment ``points[k] -> points[k + 1]`` (frame
    M) with radius ``radii[k]``, as the arm's links. In the box's frame, the
    gap between a segment's bounding box and the truck box is a lower bound
    of their distance (per axis, every point of the segment is at least that
    far from the box's slab): the capsules are visited from the smallest bound
    up, and the visit stops at a bound not below the smallest clearance so far
    (no later capsule can be closer), which leaves the minimum unchanged.
    """
    low, high = truck.box()
    c, s = math.cos(truck.yaw), math.sin(truck.yaw)
    local = []  # the points in the box's frame: along, across, up
    for p in points:
        dx, dy = p[0] - truck.cx, p[1] - truck.cy
        local.append((c * dx + s * dy, -s * dx + c * dy, p[2]))
    bounds = []
    for k, r in enumerate(radii):
        a, b = local[k], local[k + 1]
        gap = 0.0
        for i in range(3):
            lo, hi = (a[i], b[i]) if a[i] <= b[i] else (b[i], a[i])
            g = low[i] - hi if hi < low[i] else lo - high[i] if lo > high[i] else 0.0
            gap += g * g
        bounds.append(math.sqrt(gap) - r)
    out = math.inf
    for k in sorted(range(len(radii)), key=bounds.__getitem__):
        if bounds[k] >= out:
            break
        d = segment_box_distance(local[k], local[k + 1], low, high)
        out = min(out, d - radii[k])
    return float(out)
