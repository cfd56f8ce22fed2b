"""The buried pipe and the truck body, and the arm's clearance to them.

The arm is three capsules about the segments boom (foot pin to stick pin),
stick (to the bucket pin) and bucket (pin to cutting edge), with the radii of
:attr:`Machine.link_radius`. Clearance is the distance between surfaces
(negative when they overlap), computed with :mod:`motiongym.envs.geometry`:

* pipe: a capsule of radius ``r`` about a straight segment below the ground
  (a utility located by a locate survey); clearance = segment-segment
  distance - link radius - ``r``.
* truck: the body as a box (footprint ``length x width`` turned by ``yaw``,
  from the ground up to the rim height; the open bed is inside it, so a bucket
  must stay above the rim). The segment-box distance is exact: for disjoint
  convex sets the closest pair is an end point against the box or a segment
  against one of the 12 edges; a segment crossing the box (slab test) has
  distance 0.

Broad phase: an environment step first takes cheap lower bounds (the pipe is
below the arm's lowest point, a capsule's bounding sphere against the box) and
runs the exact computation only when a bound is under ``horizon``; beyond it
the reported clearance is that lower bound (it is then larger than
``horizon``, 1 m, which is larger than every safety distance).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from motiongym.envs.geometry import closest_points_between_segments


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
    """A truck body: footprint centre and yaw, half length and width, rim height (m, rad)."""

    cx: float
    cy: float
    yaw: float
    half_length: float
    half_width: float
    height: float

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

    def point_distance(self, x: float, y: float, z: float) -> float:
        """Distance from a point to the box (0 inside), scalar math."""
        u, v = self.to_local(x, y)
        du = max(abs(u) - self.half_length, 0.0)
        dv = max(abs(v) - self.half_width, 0.0)
        dz = max(-z, z - self.height, 0.0)
        return math.sqrt(du * du + dv * dv + dz * dz)

    def edges(self) -> tuple[np.ndarray, np.ndarray]:
        """The 12 edges of the box in frame M: ``(starts, ends)``, each (12, 3)."""
        hl, hw, h = self.half_length, self.half_width, self.height
        corners = np.array([[sx * hl, sy * hw] for sx, sy in ((-1, -1), (1, -1), (1, 1), (-1, 1))])
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        xy = corners @ np.array([[c, s], [-s, c]]) + (self.cx, self.cy)  # (4, 2)
        low = np.column_stack([xy, np.zeros(4)])
        high = np.column_stack([xy, np.full(4, h)])
        nxt = [1, 2, 3, 0]
        starts = np.concatenate([low, high, low])
        ends = np.concatenate([low[nxt], high[nxt], high])
        return starts, ends


def pipe_clearance(starts: np.ndarray, ends: np.ndarray, radii: np.ndarray, pipe: Pipe) -> float:
    """Exact clearance of the capsules ``starts[k] -> ends[k]`` (k, 3) to the pipe (m)."""
    d, _, _ = closest_points_between_segments(
        starts, ends, np.asarray(pipe.a, float), np.asarray(pipe.b, float)
    )
    return float(np.min(d - radii)) - pipe.radius


def _segment_hits_box(p0, p1, truck: Truck) -> bool:
    """Slab test: whether the segment ``p0 p1`` (frame M) meets the box."""
    u0, v0 = truck.to_local(p0[0], p0[1])
    u1, v1 = truck.to_local(p1[0], p1[1])
    enter, leave = 0.0, 1.0
    for a, b, lo, hi in (
        (u0, u1, -truck.half_length, truck.half_length),
        (v0, v1, -truck.half_width, truck.half_width),
        (p0[2], p1[2], 0.0, truck.height),
    ):
        d = b - a
        if d == 0.0:
            if a < lo or a > hi:
                return False
            continue
        t0, t1 = (lo - a) / d, (hi - a) / d
        if t0 > t1:
            t0, t1 = t1, t0
        enter, leave = max(enter, t0), min(leave, t1)
        if enter > leave:
            return False
    return True


def truck_clearance(
    starts: np.ndarray,
    ends: np.ndarray,
    radii: np.ndarray,
    truck: Truck,
    edges: tuple[np.ndarray, np.ndarray] | None = None,
) -> float:
    """Exact clearance of the capsules ``starts[k] -> ends[k]`` (k, 3) to the truck box (m).

    ``edges`` may pass :meth:`Truck.edges`, computed once per scene.
    """
    e0, e1 = truck.edges() if edges is None else edges  # (12, 3) each
    d_edges, _, _ = closest_points_between_segments(
        starts[:, None, :], ends[:, None, :], e0[None], e1[None]
    )  # (k, 12)
    dist = d_edges.min(axis=1).tolist()
    out = math.inf
    for k, (p0, p1) in enumerate(zip(starts.tolist(), ends.tolist(), strict=True)):
        if _segment_hits_box(p0, p1, truck):
            d = 0.0
        else:
            d = min(dist[k], truck.point_distance(*p0), truck.point_distance(*p1))
        out = min(out, d - float(radii[k]))
    return out
