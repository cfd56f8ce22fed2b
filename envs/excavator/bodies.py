"""Collision bodies that contain the machine's parts (physics v1).

Every part is a convex body that contains it (a capsule about a link's
pin-to-pin line, or an oriented box); contact with the pipe, the truck or the
machine itself is a distance between bodies <= 0. Dimensions (m) of the 20 t
class (Cat 320 / Komatsu PC210 / Volvo EC220 spec-sheet overall sizes),
rounded up so the body contains the part:

===========  ================================================================
part         body
===========  ================================================================
boom         capsule, radius 0.40 about foot pin - stick pin (contains a
             0.60 m deep x 0.45 m wide box girder: half diagonal 0.375)
stick        capsule, radius 0.30 about stick pin - bucket pin (contains a
             0.45 x 0.30 section: half diagonal 0.27)
bucket       box in the bucket frame: along the pin-to-tip axis ``u`` from
             -0.15 to ``L4`` + 0.05, behind the opening (``-n``, the shell's
             bulge) from -0.05 to 0.95 (shell and plate), across ``+-(bucket_width / 2 + 0.05)``
             (the cutting edge's full width and the side plates)
house        box turning with the swing: ``x'`` (ahead along the swing
             azimuth) -2.8 to 1.0 (tail swing radius 2.8 m), ``y'`` +-1.4,
             z 0.95 to 2.95 above the ground (cab roof)
tracks       box fixed to the base: x +-2.25 (4.5 m track length), y +-1.5
             (3.0 m over 600 mm shoes), z 0 to 0.92
===========  ================================================================

:func:`machine_bodies` places them from the arm points (frame O, any base
pose); the pairs checked for self-collision are :data:`SELF_PAIRS` (a link is
not checked against the part it hangs from). Distances are exact:
capsule-capsule by :func:`motiongym.envs.geometry.segment_distance`,
capsule-box by :func:`.obstacles.segment_box_distance` in the box's frame,
box-box as the smallest distance from each box's 12 edges to the other box
(exact for disjoint convex boxes: a closest pair always has a point on an
edge of one of them), 0 when one box's centre lies in the other.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

from motiongym.envs.excavator.obstacles import segment_box_distance
from motiongym.envs.geometry import segment_distance

BOOM_RADIUS = 0.40
STICK_RADIUS = 0.30
BUCKET_BACK = 0.95  # m: the shell (0.90 m behind the opening) and its 5 cm plate
BUCKET_SIDE = 0.05  # m: side plates beyond the cutting edge
HOUSE = ((-2.8, 1.0), (-1.4, 1.4), (0.95, 2.95))  # x', y', z (m)
TRACKS = ((-2.25, 2.25), (-1.5, 1.5), (0.0, 0.92))  # x, y, z (m, frame M)
# The boom is not checked against the tracks: the straight pin-to-pin line of
# a bent boom passes where the real boom does not (within the joint limits,
# the boom's underside meets the ground first, which stops it).
PART_NAMES = ("boom", "stick", "bucket", "house", "tracks")
SELF_PAIRS = (("bucket", "tracks"), ("bucket", "house"), ("stick", "tracks"), ("stick", "house"))

SKIP = 1e-9  # m: a lower bound this far above the distance of interest rules a body out
Vec = tuple[float, ...]  # x, y, z


@dataclass(frozen=True)
class Capsule:
    a: Vec
    b: Vec
    radius: float

    def sphere(self) -> tuple[Vec, float]:
        """A bounding sphere ``(centre, radius)``."""
        c = tuple(0.5 * (p + q) for p, q in zip(self.a, self.b, strict=True))
        return c, 0.5 * math.dist(self.a, self.b) + self.radius


class Box(NamedTuple):
    """An oriented box: centre, unit axes (rows), half extents (m).

    A named tuple (immutable, compared by value): a step builds a few.
    """

    centre: Vec
    axes: tuple[Vec, Vec, Vec]
    half: Vec

    def local(self, p) -> Vec:
        c, (a, b, e) = self.centre, self.axes
        x, y, z = p[0] - c[0], p[1] - c[1], p[2] - c[2]
        return (
            a[0] * x + a[1] * y + a[2] * z,
            b[0] * x + b[1] * y + b[2] * z,
            e[0] * x + e[1] * y + e[2] * z,
        )

    def gap(self, p) -> float:
        """Distance from the point ``p`` to the box (0 inside)."""
        c, (a, b, e), (hx, hy, hz) = self.centre, self.axes, self.half
        x, y, z = p[0] - c[0], p[1] - c[1], p[2] - c[2]
        total = 0.0
        g = abs(a[0] * x + a[1] * y + a[2] * z) - hx
        if g > 0.0:
            total += g * g
        g = abs(b[0] * x + b[1] * y + b[2] * z) - hy
        if g > 0.0:
            total += g * g
        g = abs(e[0] * x + e[1] * y + e[2] * z) - hz
        if g > 0.0:
            total += g * g
        return math.sqrt(total)

    def world(self, u: float, v: float, w: float) -> Vec:
        a0, a1, a2 = self.axes
        c = self.centre
        return (
            c[0] + u * a0[0] + v * a1[0] + w * a2[0],
            c[1] + u * a0[1] + v * a1[1] + w * a2[1],
            c[2] + u * a0[2] + v * a1[2] + w * a2[2],
        )

    def corners(self) -> list[Vec]:
        hx, hy, hz = self.half
        return [
            self.world(sx * hx, sy * hy, sz * hz)
            for sx in (-1, 1)
            for sy in (-1, 1)
            for sz in (-1, 1)
        ]

    def edges(self) -> list[tuple[Vec, Vec]]:
        c = self.corners()  # index bits: x 4, y 2, z 1
        return [(c[i], c[i | bit]) for bit in (4, 2, 1) for i in range(8) if not i & bit]

    def sphere(self) -> tuple[Vec, float]:
        return self.centre, math.sqrt(sum(h * h for h in self.half))

    def contains(self, p) -> bool:
        return all(abs(x) <= h for x, h in zip(self.local(p), self.half, strict=True))


_new_box = tuple.__new__  # Box(...) without the named tuple's Python-level __new__


def box_from_ranges(origin: Vec, axes, ranges) -> Box:
    """The box spanning ``ranges`` ((lo, hi) per axis) along ``axes`` from ``origin``."""
    (l0, h0), (l1, h1), (l2, h2) = ranges
    m0, m1, m2 = 0.5 * (l0 + h0), 0.5 * (l1 + h1), 0.5 * (l2 + h2)
    a, b, c = axes
    centre = (  # sum() as the reference: the same rounding on every Python
        origin[0] + sum((m0 * a[0], m1 * b[0], m2 * c[0])),
        origin[1] + sum((m0 * a[1], m1 * b[1], m2 * c[1])),
        origin[2] + sum((m0 * a[2], m1 * b[2], m2 * c[2])),
    )
    half = (0.5 * (h0 - l0), 0.5 * (h1 - l1), 0.5 * (h2 - l2))
    return _new_box(Box, (centre, (tuple(a), tuple(b), tuple(c)), half))


def segment_to_box(a, b, box: Box, above: float = math.inf) -> float:
    """Distance from the segment ``a b`` to ``box`` (0 when they meet).

    First a lower bound: the gap between the segment's bounding box and the
    box, in the box's frame (per axis, every point of the segment is at least
    that far from the box's slab). When it is ``SKIP`` or more above
    ``above``, the bound is returned instead of the distance.
    """
    la, lb, half = box.local(a), box.local(b), box.half
    if above < math.inf:
        bound = _aabb_gap(la, lb, half)
        if bound - above >= SKIP:
            return bound
    return segment_box_distance(la, lb, (-half[0], -half[1], -half[2]), half)


def separation(p: Box, q: Box) -> float:
    """A lower bound of the distance between two boxes: the widest gap between their
    projections on the six face normals (separating-axis test; <= 0: not separated)."""
    (px, py, pz), (qx, qy, qz) = p.centre, q.centre
    dx, dy, dz = qx - px, qy - py, qz - pz
    sides = [(h, a) for box in (p, q) for h, a in zip(box.half, box.axes, strict=True)]
    best = -math.inf
    for x, y, z in (*p.axes, *q.axes):
        along = abs(dx * x + dy * y + dz * z)
        for h, (a, b, c) in sides:
            along -= h * abs(a * x + b * y + c * z)
        best = along if along > best else best
    return best


def box_to_box(p: Box, q: Box) -> float:
    """Distance between two boxes (0 when they overlap).

    The smallest distance from an edge of one box to the other box, both
    ways. Each box's corners are put in the other's frame once; the edges
    are visited from the smallest bounding-box bound (as in
    :func:`segment_to_box`) up, and the visit stops at a bound ``SKIP``
    above the smallest distance so far (no later edge can be closer).
    """
    if p.contains(q.centre) or q.contains(p.centre):
        return 0.0
    best = math.inf
    for one, other in ((p, q), (q, p)):
        corners = [other.local(c) for c in one.corners()]
        half = other.half
        low = (-half[0], -half[1], -half[2])
        edges = sorted(
            (_aabb_gap(corners[i], corners[i | bit], half), i, i | bit)
            for bit in (4, 2, 1)
            for i in range(8)
            if not i & bit
        )
        for bound, i, j in edges:
            if bound - best >= SKIP:
                break
            d = segment_box_distance(corners[i], corners[j], low, half)
            if d < best:
                best = d
                if d == 0.0:
                    return 0.0
    return best


def _aabb_gap(a: Vec, b: Vec, half: Vec) -> float:
    """Distance from the segment ``a b``'s bounding box to the box ``[-half, half]``
    (one frame): a lower bound of the segment's distance to that box."""
    total = 0.0
    for p, q, h in ((a[0], b[0], half[0]), (a[1], b[1], half[1]), (a[2], b[2], half[2])):
        g = (p if p < q else q) - h
        if g <= 0.0:
            g = -h - (q if p < q else p)
        if g > 0.0:
            total += g * g
    return math.sqrt(total)


def lower_bound(p, q) -> float:
    """A cheap lower bound of :func:`distance` (separating axes for two boxes)."""
    if isinstance(p, Box) and isinstance(q, Box):
        return separation(p, q)
    return -math.inf


def distance(p, q) -> float:
    """Surface distance between two bodies (capsules or boxes), negative for a capsule inside."""
    if isinstance(p, Capsule) and isinstance(q, Capsule):
        return segment_distance(p.a, p.b, q.a, q.b) - p.radius - q.radius
    if isinstance(p, Capsule):
        return segment_to_box(p.a, p.b, q) - p.radius
    if isinstance(q, Capsule):
        return segment_to_box(q.a, q.b, p) - q.radius
    return box_to_box(p, q)


def sphere_gap(p, q) -> float:
    """A lower bound of :func:`distance` from the bodies' bounding spheres."""
    (c1, r1), (c2, r2) = p.sphere(), q.sphere()
    return math.dist(c1, c2) - r1 - r2


def bucket_box(pin: Vec, tip: Vec, lateral: Vec, width: float) -> Box:
    """The bucket's body: ``u`` = pin to tip, ``-n`` = ``lateral x u`` (behind the opening)."""
    length = math.dist(pin, tip)
    u = ((tip[0] - pin[0]) / length, (tip[1] - pin[1]) / length, (tip[2] - pin[2]) / length)
    back = _cross(lateral, u)
    ranges = (
        (-0.15, length + 0.05),
        (-0.05, BUCKET_BACK),
        (-(0.5 * width + BUCKET_SIDE), 0.5 * width + BUCKET_SIDE),
    )
    return box_from_ranges(pin, (u, back, lateral), ranges)


def _cross(a, b) -> Vec:
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def machine_bodies(
    points, swing: float, rotation, bucket_width: float, L0: float, names=None
) -> dict:
    """``{part: body}`` in frame O from the arm points (frame O) and the base rotation.

    ``points`` are foot, stick pin, bucket pin and tip; ``rotation`` is the
    base's ``R`` (rows, 3 x 3, frame M to O; None on level ground). The
    house and the tracks are centred on the swing axis, at ``x = -L0`` in M.
    ``names`` (default: all five) selects the parts built.
    """
    foot, stick_pin, pin, tip = points
    rot = _apply(rotation)
    axis, up = swing_axis(rotation, L0)
    out: dict[str, Capsule | Box] = {}
    for name in names or PART_NAMES:
        if name == "boom":
            out[name] = Capsule(foot, stick_pin, BOOM_RADIUS)
        elif name == "stick":
            out[name] = Capsule(stick_pin, pin, STICK_RADIUS)
        elif name == "bucket":  # the lateral axis is the joint axis z = (s1, -c1, 0)
            lateral = rot((math.sin(swing), -math.cos(swing), 0.0))
            out[name] = bucket_box(pin, tip, lateral, bucket_width)
        elif name == "house":
            out[name] = house_box(axis, up, math.cos(swing), math.sin(swing), rotation)
        else:
            out[name] = box_from_ranges(
                axis, (rot((1.0, 0.0, 0.0)), rot((0.0, 1.0, 0.0)), up), TRACKS
            )
    return out


def swing_axis(rotation, L0: float) -> tuple[Vec, Vec]:
    """Where the swing axis meets the ground (``x = -L0`` in M) and the base's z, in frame O."""
    rot = _apply(rotation)
    return rot((-L0, 0.0, 0.0)), rot((0.0, 0.0, 1.0))


def house_box(axis: Vec, up: Vec, c1: float, s1: float, rotation) -> Box:
    """The house's body at the swing angle of cosine ``c1`` and sine ``s1``; ``axis``
    and ``up`` as :func:`swing_axis` gives them, ``rotation`` as in :func:`machine_bodies`."""
    if rotation is None:
        ahead, side = (c1, s1, 0.0), (-s1, c1, 0.0)
    else:  # R (c1, s1, 0) and R (-s1, c1, 0), as _apply
        (a, b, c), (d, e, f), (g, h, i) = rotation
        ahead = (a * c1 + b * s1 + c * 0.0, d * c1 + e * s1 + f * 0.0, g * c1 + h * s1 + i * 0.0)
        side = (a * -s1 + b * c1 + c * 0.0, d * -s1 + e * c1 + f * 0.0, g * -s1 + h * c1 + i * 0.0)
    return box_from_ranges(axis, (ahead, side, up), HOUSE)


def _apply(rotation):
    if rotation is None:
        return lambda v: v
    (a, b, c), (d, e, f), (g, h, i) = rotation
    return lambda v: (
        a * v[0] + b * v[1] + c * v[2],
        d * v[0] + e * v[1] + f * v[2],
        g * v[0] + h * v[1] + i * v[2],
    )
