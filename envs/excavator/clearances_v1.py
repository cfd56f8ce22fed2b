"""Clearances of the v1 excavator's collision bodies to the pipe, the truck and itself.

:class:`ClearancesV1` is the part of :class:`.world_v1.ExcavatorWorldV1` that
measures, after each step, the pipe, truck and self clearances (m) of the
bodies of :mod:`.bodies` (boom, stick, bucket with its full width and shell,
house, tracks): exact below the horizons (``HORIZON`` 1 m for pipe and
truck, :data:`SELF_HORIZON` for self), a lower bound above. A part is
measured exactly only where its cheap bounds (plan-view gaps, heights,
bounding spheres, separating axes) cannot show that it is not the nearest:
a bound at least :data:`SKIP` above the smallest value so far leaves it out,
so the minimum is the same as with every part measured (tested with ``SKIP``
infinite). The world's ``reset`` sets the fixed bounds these methods read
(``_pipe_body``, ``_truck_body``, ``_tracks_box``, the spheres' sizes, ...).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

from motiongym.envs.excavator import bodies
from motiongym.envs.excavator.world import HORIZON

if TYPE_CHECKING:
    from motiongym.envs.excavator.config import Machine
    from motiongym.envs.excavator.obstacles import Pipe, Truck
    from motiongym.envs.excavator.world_v1 import Pose

SELF_HORIZON = 0.3  # m: self clearance exact below this
UNDER_REACH = 1.3  # m: how far any body (bucket box: 1.12 m) reaches from the arm's polyline
PARTS = ("boom", "stick", "bucket")  # the arm's links, in the order of its polyline
HOUSE_RADIUS = 3.5  # m: house and tracks lie within this of the swing axis (3.13 m, 0.3 m tilt)
REACH = (bodies.BOOM_RADIUS, bodies.STICK_RADIUS, UNDER_REACH)  # each part's from its segment
SKIP = bodies.SKIP  # m: a bound this far above the smallest clearance so far leaves its part out


class ClearancesV1:
    """Mixin of :class:`.world_v1.ExcavatorWorldV1`: the clearances (module docstring)."""

    # What the mixin reads of the world (set by its reset and step; declarations only).
    m: Machine
    pipe: Pipe
    truck: Truck
    q: list[Any]
    points: tuple[tuple[float, float, float], ...]
    rotation: Any  # 3 x 3 rows (frame M to O), None on level ground
    _pose_now: Pose
    _pipe_body: bodies.Capsule
    _pipe_top: float  # m
    _pipe_line3: tuple[bodies.Vec, bodies.Vec, float]  # a, b - a, 1 / |b - a|^2
    _truck_body: bodies.Box
    _truck_centre: tuple[float, float]  # m, plan view
    _truck_radius: float  # m
    _truck_height: float  # m, the truck bed's top
    _axis: tuple[float, float]  # m, the swing axis in plan view
    _house_truck: float  # m, the house's fixed lower bound to the truck
    _house_top: float  # m
    _house_mid: bodies.Vec
    _house_radius: float  # m
    _bucket_sphere: tuple[float, float, float]  # along, back, radius (m)
    _bucket_slack: float  # m
    _sphere_slack: dict[str, float]  # m, per part
    _swing_axis: bodies.Vec
    _up: bodies.Vec
    _tracks_box: Any  # the tracks' body (bodies.machine_bodies)
    _tracks_sphere: tuple[tuple[float, float, float], float]  # its bounding sphere (centre, radius)

    def _clearances(self) -> None:
        """Exact body distances below the horizons, lower bounds above.

        Pipe and truck: exact below ``HORIZON`` (1 m; the house against the
        truck below ``SELF_HORIZON``); self: exact below ``SELF_HORIZON``
        (0.3 m). Each part's bound, cheapest first: its segment of the arm's
        polyline (the bucket's body lies within ``UNDER_REACH`` of it, a
        link's within its radius; house and tracks within ``HOUSE_RADIUS``
        of the swing axis) against the obstacle's bounding circle in plan
        and its top; the bucket's bounding sphere next; a body is built only
        when its bound is under its horizon. A clearance is the smallest of
        these values; a part whose bound (``SKIP`` above it to cover
        rounding) is not below the smallest so far cannot change it and is
        left out: the values are those of computing every part.
        """
        pts = self.points
        z0, z1, z2, z3 = pts[0][2], pts[1][2], pts[2][2], pts[3][2]
        lows = (z1 if z1 < z0 else z0, z2 if z2 < z1 else z1, z3 if z3 < z2 else z2)
        cache: dict = {}
        top = self._pipe_top
        d0, d1, d2 = lows[0] - REACH[0] - top, lows[1] - REACH[1] - top, lows[2] - REACH[2] - top
        if d0 >= HORIZON and d1 >= HORIZON and d2 >= HORIZON:  # far: the bounds stand
            self.pipe_clear = d0 if d0 <= d1 and d0 <= d2 else d1 if d1 <= d2 else d2
        else:
            self.pipe_clear = self._pipe_clearance(cache, (d0, d1, d2))
        self.truck_clear = self._truck_clearance(cache, lows)
        self.self_clear = self._self_clearance(cache, lows)

    def _pipe_clearance(self, cache: dict, bounds) -> float:
        """The pipe clearance from the parts' bounds ``bounds`` (one under ``HORIZON``)."""
        best = math.inf
        for k, name in enumerate(PARTS):
            d = bounds[k]
            if d < HORIZON:
                if d - best >= SKIP:
                    continue
                d = self._exact(cache, name, self._pipe_body, self._pipe_gap, HORIZON, best)
            if d < best:
                best = d
        return best

    def _truck_clearance(self, cache: dict, lows) -> float:
        """The house (its fixed bound, then its sphere's), then boom, stick and bucket.

        A link's bound is its plan-view gap or its height over the rim, whichever
        is larger; the height alone (no plan view) already leaves out a part
        ``SKIP`` or more above the smallest value so far.
        """
        box, best = self._truck_body, self._house_truck
        if best < SELF_HORIZON:
            c, r = self._sphere(cache, "house")
            best = box.gap(c) - r
            if best < SELF_HORIZON:
                best = self._box_distance(cache, "house", box, SELF_HORIZON, math.inf)
        radius, height, pts = self._truck_radius, self._truck_height, self.points
        cx, cy = self._truck_centre
        for k in range(3):
            above, reach = lows[k] - height, REACH[k]
            if above - reach - best >= SKIP:  # d >= above - reach: not the smallest
                continue
            gap = _segment_gap(cx, cy, pts[k], pts[k + 1]) - radius
            d = (above if above > gap else gap) - reach
            if d < HORIZON:
                if d - best >= SKIP:
                    continue
                if k < 2:  # a link's capsule
                    d = bodies.segment_to_box(pts[k], pts[k + 1], box, best + reach) - reach
                else:  # the bucket: its sphere's bound, then its box
                    c, r = self._sphere(cache, "bucket")
                    d = box.gap(c) - r
                    if d < HORIZON and d - self._bucket_slack - best < SKIP:
                        d = self._box_distance(cache, "bucket", box, HORIZON, best)
            if d < best:
                best = d
        return best

    def _self_clearance(self, cache: dict, lows) -> float:
        """Bucket, then stick, against tracks and house (the bucket's cheap bounds first).

        The stick's bound comes first: over the horizon it is the stick's
        value, and it can leave out the bucket's bodies; the tracks' and the
        house's boxes are visited only where their spheres' bound could be
        the smallest.
        """
        top, horizon, (ax, ay), pts = self._house_top, SELF_HORIZON, self._axis, self.points
        above = lows[1] - top
        gap = _segment_gap(ax, ay, pts[1], pts[2]) - HOUSE_RADIUS
        stick = (above if above > gap else gap) - REACH[1]
        best = stick if stick >= horizon else math.inf  # the stick's value
        above = lows[2] - top
        if above - UNDER_REACH - best < SKIP:  # else the bucket's bound is not the smallest
            gap = _segment_gap(ax, ay, pts[2], pts[3]) - HOUSE_RADIUS
            d = (above if above > gap else gap) - UNDER_REACH
            if d >= horizon:
                best = d if d < best else best
            else:  # the bucket: its sphere's bounds first
                best = self._bucket_self(cache, best)
        if stick >= horizon or stick - best >= SKIP:
            return best
        reach = REACH[1]  # the stick's capsule against each box
        for other in (self._tracks_box, self._part(cache, "house")):
            d = bodies.segment_to_box(pts[1], pts[2], other, best + reach) - reach
            if d < best:
                best = d
        return best

    def _bucket_self(self, cache: dict, best: float) -> float:
        """The bucket against the tracks and the house (``best``: the smallest value so
        far); a box whose sphere is ``SKIP`` or more farther than ``best`` is left out."""
        c, r = self._sphere(cache, "bucket")
        slack, horizon = self._bucket_slack, SELF_HORIZON
        for name in ("tracks", "house"):
            (x, y, z), radius = self._sphere(cache, name)
            x, y, z = c[0] - x, c[1] - y, c[2] - z
            if math.sqrt(x * x + y * y + z * z) - radius - r - slack - best >= SKIP:
                continue  # the spheres' gap: this box is farther than best
            box = self._part(cache, name)
            d = box.gap(c) - r
            if d < horizon and d - slack - best < SKIP:
                d = self._box_distance(cache, "bucket", box, horizon, best)
            if d < best:
                best = d
        return best

    def _exact(self, cache: dict, name: str, other, gap, horizon: float, best=math.inf) -> float:
        """Distance of part ``name`` to ``other``; for a box, its sphere's and its
        separating axes' bounds first (the bound is returned when not under ``horizon``).

        A bound ``SKIP`` or more above ``best`` is returned as it is (the
        distance, not smaller, would not be the smallest either).
        """
        if name == "bucket" or name == "house":
            c, r = self._sphere(cache, name)
            d = (gap(c) if gap is not None else other.gap(c)) - r
            if d >= horizon or d - self._sphere_slack[name] - best >= SKIP:
                return d
            return self._box_distance(cache, name, other, horizon, best)
        if isinstance(other, bodies.Box):
            k, pts = PARTS.index(name), self.points
            return bodies.segment_to_box(pts[k], pts[k + 1], other, best + REACH[k]) - REACH[k]
        return bodies.distance(self._part(cache, name), other)

    def _box_distance(self, cache: dict, name: str, other, horizon: float, best: float) -> float:
        """Distance of the bucket's or the house's box to ``other``: the separating axes'
        bound when not under ``horizon`` (or ``SKIP`` above ``best``), else exact."""
        body = self._part(cache, name)
        d = bodies.lower_bound(body, other)
        if d >= horizon or d - best >= SKIP:
            return d
        return bodies.distance(body, other)

    def _part(self, cache: dict, name: str):
        if name == "tracks":
            return self._tracks_box
        if name not in cache:
            if name == "house":
                pose = self._pose_now
                cache[name] = bodies.house_box(
                    self._swing_axis, self._up, pose.c1, pose.s1, self.rotation
                )
            else:
                cache.update(self._bodies((name,)))
        return cache[name]

    def _pipe_gap(self, c) -> float:
        """Distance from the point ``c`` to the pipe's surface (a lower bound's core)."""
        (ax, ay, az), (dx, dy, dz), inv = self._pipe_line3
        px, py, pz = c[0] - ax, c[1] - ay, c[2] - az
        t = (px * dx + py * dy + pz * dz) * inv
        t = 0.0 if t < 0.0 else 1.0 if t > 1.0 else t
        x, y, z = px - t * dx, py - t * dy, pz - t * dz
        return math.sqrt(x * x + y * y + z * z) - self.pipe.radius

    def _bodies(self, names=None) -> dict:
        return bodies.machine_bodies(
            self.points, self.q[0], self.rotation, self.m.bucket_width, self.m.L0, names
        )

    def _sphere(self, cache: dict, name: str) -> tuple[tuple[float, float, float], float]:
        """Bounding sphere ``(centre, radius)`` of the bucket's, the house's or the tracks' body."""
        if name == "tracks":
            return self._tracks_sphere
        key = _SPHERE_KEYS[name]
        if key in cache:
            return cache[key]
        if name == "bucket":
            pin, pose = self.points[2], self._pose_now
            along, back, radius = self._bucket_sphere
            u, n = pose.u, pose.n
            centre = (
                pin[0] + along * u[0] - back * n[0],
                pin[1] + along * u[1] - back * n[1],
                pin[2] + along * u[2] - back * n[2],
            )
            cache[key] = centre, radius
            return cache[key]
        c1, s1 = self._pose_now.c1, self._pose_now.s1
        x, y, z = self._house_mid
        house = (-self.m.L0 + c1 * x - s1 * y, s1 * x + c1 * y, z)
        if self.rotation:
            (a, b, c), (d, e, f), (g, h, i) = self.rotation
            x, y, z = house
            house = (a * x + b * y + c * z, d * x + e * y + f * z, g * x + h * y + i * z)
        cache[key] = house, self._house_radius
        return cache[key]


_SPHERE_KEYS = {"bucket": "bucket sphere", "house": "house sphere"}  # in a step's cache


def _segment_gap(x: float, y: float, a, b) -> float:
    """Plan-view distance from ``(x, y)`` to the segment ``a b`` (points, z ignored)."""
    ax, ay = a[0], a[1]
    dx, dy = b[0] - ax, b[1] - ay
    px, py = x - ax, y - ay
    length2 = dx * dx + dy * dy
    t = (px * dx + py * dy) / length2 if length2 > 1e-18 else 0.0
    t = 0.0 if t < 0.0 else 1.0 if t > 1.0 else t
    return math.hypot(px - t * dx, py - t * dy)
