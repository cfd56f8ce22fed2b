"""Physics v1 of the excavator world: a machine that cannot pass through soil, pipe or itself.

:class:`ExcavatorWorldV1` has the API of :class:`.world.ExcavatorWorld`
(``reset(scene, rng)``, ``advance(actions)``, ``render(size)``, the same
state attributes) and
adds ``self_clear`` (m), ``ground_contact``, ``cut_force`` (N),
``advance_fraction``, ``pushed`` (m3 bank pushed by a full bucket this
step), ``rotation`` (the base's ``R``, None when level) and
:meth:`soil_volume`. One step of ``dt`` s:

1. hydraulics (:mod:`.hydraulics`): rate, acceleration and shared pump-flow
   limits turn the actions into joint rates; joints held in their ranges;
2. the candidate pose's contact with the ground (:mod:`.digging`): no part
   but the cutting edge may enter the ground (bucket shell, stick, boom,
   house: sample points on their bodies' undersides): a pose whose deepest
   sample is more than 2 cm under the surface is allowed only while that
   depth shrinks (a part already in the ground may only leave it); the edge
   likewise, except while it cuts (moving within 60 deg of the opening's
   normal), against the earthmoving-equation resistance. The step is cut
   short (bisection on the fraction of the step, to 1/64) where the ground
   stops a part, and scaled by ``1 - F / F_dig`` while cutting; the joint
   rates are what was achieved;
3. carving (the edge's sweep, bank volume times ``swell`` into the bucket,
   a full bucket's surplus pushed ahead), pouring (as v0, but not while the
   edge is in the ground; the truck and the bucket hold loose volume);
4. clearances of the collision bodies of :mod:`.bodies` (boom, stick,
   bucket with its full width and shell, house, tracks) to the pipe, the
   truck and each other (self-collision): exact below 1 m, a lower bound
   above.

The base stands on the plane of its roll and pitch (the paper's ``H_M^O``,
eq. 1-2; ``Scene.base``): the arm points are turned by ``R`` into frame O,
where the ground, pipe and truck are. Contact (episode end): pipe, truck or
self clearance <= 0; ``ground_contact`` (1 on a step where the ground
stopped a part other than the cutting edge) is reported, not ended on.
"""

from __future__ import annotations

import math
from math import cos, sin

from motiongym.envs.excavator import bodies
from motiongym.envs.excavator.clearances_v1 import (
    HOUSE_RADIUS,
    SKIP,
    UNDER_REACH,
    ClearancesV1,
)
from motiongym.envs.excavator.digging import DEPTH_TOLERANCE, PUSH, cuts, stall_fraction
from motiongym.envs.excavator.hydraulics import hydraulic_rates
from motiongym.envs.excavator.kinematics import base_rotation
from motiongym.envs.excavator.scenes import (
    CELL_XS,
    CELL_YS,
    GRID_CELL,
    GRID_ORIGIN,
    GRID_SHAPE,
    ground_plane,
)
from motiongym.envs.excavator.soil import Terrain, cutting_force
from motiongym.envs.excavator.world import POUR_NZ, POUR_TIME, ExcavatorWorld

BISECTIONS = 6
# The bucket shell's underside in the bucket frame: (fraction of L4 along u, m behind the opening).
SHELL = ((0.0, 0.75), (0.6, 0.9), (0.85, 0.55))
SHELL_INSET = 0.1  # m: shell points this far inside the side plates (one cell of the map)


class Pose:
    """The machine at joint angles ``q``: arm points, tip, bucket axes, cutting edge (O).

    :meth:`under` gives the sample points of the bodies' undersides (house
    corners, boom and stick bottoms, bucket shell), computed when asked.
    """

    __slots__ = (
        "q",
        "points",
        "tip",
        "beta",
        "n",
        "u",
        "lat",
        "low_arm",
        "low_edge",
        "_world",
        "c1",
        "s1",
        "edge_memo",
        "body_memo",
    )

    def __init__(self, q, world) -> None:
        self.q, self._world = q, world
        # (terrain, its version, depth): the exact depths below, kept while the ground stays.
        self.edge_memo: tuple[Terrain | None, int, float] = (None, -1, 0.0)
        self.body_memo: tuple[Terrain | None, int, float] = (None, -1, 0.0)
        # arm_points (eq. 4, scalar form) written out with the same arithmetic; the
        # bucket's angle beta = q2 + q3 + q4 is its last joint sum (cos, sin shared).
        L0, L1, d1, d2, L2, L3, L4 = world._links
        q1, q2, q3, q4 = q
        self.c1, self.s1 = c1, s1 = cos(q1), sin(q1)
        a3 = q2 + q3
        beta = a3 + q4
        cb, sb = cos(beta), sin(beta)
        fx, fy = -L0 + c1 * L1 + s1 * d2, s1 * L1 - c1 * d2
        r2, z2 = L2 * cos(q2), L2 * sin(q2)
        r3, z3 = r2 + L3 * cos(a3), z2 + L3 * sin(a3)
        r4, z4 = r3 + L4 * cb, z3 + L4 * sb
        p1 = (fx + c1 * r2, fy + s1 * r2, d1 + z2)
        p2 = (fx + c1 * r3, fy + s1 * r3, d1 + z3)
        tip = (fx + c1 * r4, fy + s1 * r4, d1 + z4)
        foot = (fx, fy, d1)
        n, u, lat = (c1 * sb, s1 * sb, -cb), (c1 * cb, s1 * cb, sb), (s1, -c1, 0.0)
        if world.rotation is not None:  # R v for each point and axis
            foot, p1, p2, tip, n, u, lat = world._rot_all((foot, p1, p2, tip, n, u, lat))
        self.points, self.tip, self.beta = (foot, p1, p2, tip), tip, beta
        self.n, self.u, self.lat = n, u, lat
        half = world._edge_half
        lx, ly, lz = half * lat[0], half * lat[1], half * lat[2]
        # Heights above the ground plane: of the lowest arm point past the foot, and the edge.
        gx, gy = world._gx, world._gy
        (x1, y1, z1), (x2, y2, z2), (x3, y3, z3) = p1, p2, tip
        h1, h2, h3 = z1 - gx * x1 - gy * y1, z2 - gx * x2 - gy * y2, z3 - gx * x3 - gy * y3
        low = h2 if h2 < h1 else h1
        self.low_arm = h3 if h3 < low else low
        self.low_edge = h3 - abs(lz) - abs(gx * lx + gy * ly)

    def edge(self) -> tuple[tuple[float, float, float], ...]:
        """The cutting edge's two ends and its middle (the tip), O."""
        tip, half, lat = self.tip, self._world._edge_half, self.lat
        lx, ly, lz = half * lat[0], half * lat[1], half * lat[2]
        return (
            (tip[0] + lx, tip[1] + ly, tip[2] + lz),
            tip,
            (tip[0] - lx, tip[1] - ly, tip[2] - lz),
        )

    def under(self) -> list[tuple[float, float, float]]:
        """Points on the undersides of house, boom, stick and bucket shell (O)."""
        world = self._world
        m = world.m
        c1, s1 = self.c1, self.s1
        x0, z0 = -m.L0, bodies.HOUSE[2][0]
        out = []
        for x in bodies.HOUSE[0]:
            for y in bodies.HOUSE[1]:
                out.append((x0 + c1 * x - s1 * y, s1 * x + c1 * y, z0))
        if world.rotation is not None:
            out = world._rot_all(out)
        foot, stick_pin, pin, _ = self.points
        for a, b, r in (
            (foot, stick_pin, bodies.BOOM_RADIUS),
            (stick_pin, stick_pin, bodies.BOOM_RADIUS),
            (stick_pin, pin, bodies.STICK_RADIUS),
            (pin, pin, bodies.STICK_RADIUS),
        ):
            out.append((0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1]), 0.5 * (a[2] + b[2]) - r))
        (ux, uy, uz), (nx, ny, nz), (lx, ly, lz) = self.u, self.n, self.lat
        side = 0.5 * m.bucket_width - SHELL_INSET
        px, py, pz = pin
        for along, back in SHELL:
            a = along * m.L4
            for s in (side, -side):  # pin + a u - back n + s lat
                out.append(
                    (
                        px + a * ux - back * nx + s * lx,
                        py + a * uy - back * ny + s * ly,
                        pz + a * uz - back * nz + s * lz,
                    )
                )
        return out


class ExcavatorWorldV1(ClearancesV1, ExcavatorWorld):
    """See the module docstring."""

    def reset(self, scene, rng=None) -> None:
        base = tuple(scene.base)
        self.rotation = None if base == (0.0, 0.0, 0.0) else base_rotation(*base).tolist()
        # R's rows flat (empty on level ground, where nothing is turned)
        self._rows: tuple[float, ...] = (
            () if self.rotation is None else tuple(sum(self.rotation, []))
        )
        m = self.m
        self._links = (m.L0, m.L1, m.d1, m.d2, m.L2, m.L3, m.L4)
        self.self_clear = math.inf
        self.ground_contact = 0.0
        self.cut_force = 0.0
        self.advance_fraction = 1.0
        self.pushed = 0.0
        self._obstacle_bounds(scene)
        self._ground_and_body_bounds(scene, base)
        super().reset(scene, rng)

    def _obstacle_bounds(self, scene) -> None:
        """The pipe's and the truck's bodies and the constants of their bounds."""
        pipe, truck = scene.pipe, scene.truck
        # Every constant a step reads is a Python float (a scene's NumPy scalars hold the
        # same doubles, at several times the cost per operation).
        self._pipe_body = _floats(bodies.Capsule(pipe.a, pipe.b, pipe.radius))
        self._pipe_top = float(max(pipe.a[2], pipe.b[2]) + pipe.radius)
        self._truck_height = float(truck.height)
        self._truck_centre = (truck.cx, truck.cy)
        self._truck_radius = math.hypot(truck.half_length, truck.half_width)
        self._axis = (-self.m.L0, 0.0)
        self._limits = tuple((lo, hi) for _, _, lo, hi in self._joints)
        self._edge_half = 0.5 * self.m.bucket_width - 0.05  # the edge's half-width past the plates
        # The house stays within HOUSE_RADIUS of the axis: its bound to the truck is fixed.
        self._house_truck = (
            math.hypot(truck.cx + self.m.L0, truck.cy) - self._truck_radius - HOUSE_RADIUS
        )
        self._house_top = bodies.HOUSE[2][1] + 0.35  # + the tilt's lift at 3.5 m
        d = tuple(b - a for a, b in zip(pipe.a, pipe.b, strict=True))
        self._pipe_line3 = _floats((pipe.a, d, 1.0 / max(sum(x * x for x in d), 1e-12)))
        c, s = math.cos(truck.yaw), math.sin(truck.yaw)
        self._truck_body = _floats(
            bodies.box_from_ranges(
                (truck.cx, truck.cy, 0.0),
                ((c, s, 0.0), (-s, c, 0.0), (0.0, 0.0, 1.0)),
                (
                    (-truck.half_length, truck.half_length),
                    (-truck.half_width, truck.half_width),
                    (truck.floor, truck.height),
                ),
            )
        )

    def _ground_and_body_bounds(self, scene, base) -> None:
        """The ground plane under the base, the relief bound, and the house's, the
        bucket's and the tracks' fixed bounds."""
        self._gx, self._gy = _floats(ground_plane(base))
        self._plane = self._gx * CELL_XS[:, None] + self._gy * CELL_YS[None, :]
        # + 0.01 m: the plane's change within a cell (the map holds cell centres).
        self._relief_max = float((scene.heights - self._plane).max()) + 0.01
        tilt = math.hypot(self._gx, self._gy)
        # The plane's change from a cell's centre to its corners, and the map's extent.
        self._cell_tilt = float(0.5 * GRID_CELL * (abs(self._gx) + abs(self._gy)) + SKIP)
        nx, ny = GRID_SHAPE
        self._map_xy = (
            (GRID_ORIGIN[0], GRID_ORIGIN[0] + nx * GRID_CELL),
            (GRID_ORIGIN[1], GRID_ORIGIN[1] + ny * GRID_CELL),
        )
        self._house_relief = bodies.HOUSE[2][0] - 3.0 * tilt
        half = [0.5 * (hi - lo) for lo, hi in bodies.HOUSE]
        self._house_radius = math.sqrt(sum(h * h for h in half))
        self._house_mid = tuple(0.5 * (lo + hi) for lo, hi in bodies.HOUSE)
        m = self.m
        # The bucket's box (bodies.bucket_box): -0.15 to L4 + 0.05 along u, -0.05 to
        # BUCKET_BACK behind the opening; its bounding sphere about the box's centre.
        along, back = 0.5 * (m.L4 - 0.1), 0.5 * (bodies.BUCKET_BACK - 0.05)
        box_half = (0.5 * (m.L4 + 0.2), back + 0.05, 0.5 * m.bucket_width + bodies.BUCKET_SIDE)
        self._bucket_sphere = along, back, math.sqrt(sum(h * h for h in box_half))
        self._bucket_slack = 1e-9  # rounding: the sphere contains the box
        self._sphere_slack = {"bucket": self._bucket_slack, "house": 0.0}
        self._swing_axis, self._up = bodies.swing_axis(self.rotation, m.L0)
        origin = ((0.0, 0.0, 0.0),) * 4  # the tracks do not depend on the arm
        self._tracks_box = bodies.machine_bodies(
            origin, 0.0, self.rotation, self.m.bucket_width, self.m.L0, ("tracks",)
        )["tracks"]
        self._tracks_sphere = self._tracks_box.sphere()

    # ------------------------------------------------------------------ step
    def advance(self, values: list[float]) -> None:
        m, dt = self.m, self.dt
        q0 = self.q
        r0, r1, r2, r3 = hydraulic_rates(values, self.qdot, m, dt)
        target = [q0[0] + r0 * dt, q0[1] + r1 * dt, q0[2] + r2 * dt, q0[3] + r3 * dt]
        for k, (lo, hi) in enumerate(self._limits):  # held in the joint ranges
            new = target[k]
            if new < lo or new > hi:
                target[k] = lo if new < lo else hi
        pose0, pose1 = self._pose_now, Pose(target, self)
        depth1 = self._edge_depth(pose1)
        cutting = False
        if self.carve and depth1 > 0.0:
            tip0, tip1 = pose0.tip, pose1.tip
            v = (tip1[0] - tip0[0], tip1[1] - tip0[1], tip1[2] - tip0[2])
            cutting = cuts(v, pose1.n)
        # The pose's ground tests (free, below), with the old pose's depths read only when needed.
        body1 = self._penetration(pose1)
        body_stop = body1 > DEPTH_TOLERANCE and body1 >= self._penetration(pose0)
        t, pose = 1.0, pose1
        if body_stop or not (
            cutting or depth1 <= DEPTH_TOLERANCE or depth1 < self._edge_depth(pose0)
        ):
            t, pose = self._bisect(q0, target, self._free(pose0, cutting))
        self.cut_force = cutting_force(depth1, m.bucket_width, m) if cutting else 0.0
        if cutting:
            f = stall_fraction(self.cut_force, m.dig_force)
            if f < t:
                t, pose = f, self._pose(_lerp(q0, target, f))
        self.ground_contact = 1.0 if body_stop else 0.0
        self.advance_fraction = t
        self.q = q = list(pose.q)
        self.qdot = [
            (q[0] - q0[0]) / dt,
            (q[1] - q0[1]) / dt,
            (q[2] - q0[2]) / dt,
            (q[3] - q0[3]) / dt,
        ]
        self._set_pose(pose)
        self.steps += 1
        self.elapsed = self.steps * dt
        self.taken = self.pushed = 0.0
        if self.carve:
            if cutting and t > 0.0:
                self._cut(pose0, pose)
            self._pour_if_tipped()
        self._clearances()

    def _free(self, pose0: Pose, cutting: bool):
        """The test of a pose reached from ``pose0``: into the ground only where a part
        is not yet, or on its way out (the edge: or while it cuts)."""
        edge0, body0 = self._edge_depth(pose0), self._penetration(pose0)

        def free(pose: Pose) -> bool:
            body = self._penetration(pose)
            if body > DEPTH_TOLERANCE and body >= body0:
                return False
            if cutting:
                return True
            edge = self._edge_depth(pose)
            return edge <= DEPTH_TOLERANCE or edge < edge0

        return free

    def _bisect(self, q0, target, free) -> tuple[float, Pose]:
        """The largest fraction of the step (to 1/64) whose pose is ``free``."""
        lo, hi, best = 0.0, 1.0, self._pose_now
        for _ in range(BISECTIONS):
            mid = 0.5 * (lo + hi)
            pose = self._pose(_lerp(q0, target, mid))
            if free(pose):
                lo, best = mid, pose
            else:
                hi = mid
        return lo, best

    @property
    def contact(self) -> bool:
        """Whether a body touches the pipe, the truck or another part of the machine."""
        return self.pipe_clear <= 0.0 or self.truck_clear <= 0.0 or self.self_clear <= 0.0

    def measures(self) -> dict[str, float]:
        """``self_clearance`` (m), ``self_contact``, ``ground_contact`` (0/1),
        ``cut_force`` (N), ``advance_fraction`` (of the commanded step), ``pushed_soil`` (m3)."""
        return {
            "self_clearance": float(self.self_clear),
            "self_contact": 1.0 if self.self_clear <= 0.0 else 0.0,
            "ground_contact": self.ground_contact,
            "cut_force": float(self.cut_force),
            "advance_fraction": float(self.advance_fraction),
            "pushed_soil": float(self.pushed),
        }

    def soil_volume(self) -> float:
        """Bank volume of all soil (m3): ground, bucket and truck; constant to round-off."""
        return self.terrain.volume() + (self.fill + self.truck_soil) / self.m.swell

    # --------------------------------------------------------------- physics
    def _rot_all(self, vectors) -> list[tuple[float, float, float]]:
        """``R v`` for each of ``vectors``: frame M to frame O (the base rotation, its rows
        flat in ``_rows``); one call for all of a pose's points and axes."""
        a, b, c, d, e, f, g, h, i = self._rows
        out = []
        for x, y, z in vectors:
            out.append((a * x + b * y + c * z, d * x + e * y + f * z, g * x + h * y + i * z))
        return out

    def _pose(self, q) -> Pose:
        return Pose(q, self)

    def _forward(self) -> None:
        self._set_pose(self._pose(list(self.q)))

    def _set_pose(self, pose: Pose) -> None:
        self._pose_now = pose
        self.points, self.tip, self.beta = pose.points, pose.tip, pose.beta

    def _edge_depth(self, pose: Pose) -> float:
        """Largest soil depth over the cutting edge (m; negative: above the ground).

        Far above the ground (the edge higher over the ground plane than the
        highest relief) a negative bound is returned without reading the map.
        """
        gap = pose.low_edge - self._relief_max
        if gap > 0.0:
            return -gap
        t = self.terrain
        memo = pose.edge_memo
        if memo[0] is t and memo[1] == t.version:
            return memo[2]
        h = t.height_at
        a, b, c = pose.edge()
        depth = max(h(a[0], a[1]) - a[2], h(b[0], b[1]) - b[2], h(c[0], c[1]) - c[2])
        pose.edge_memo = (t, t.version, depth)
        return depth

    def _penetration(self, pose: Pose) -> float:
        """Deepest point of the bodies' undersides below the ground (m; negative: above),
        exact where it matters: over ``DEPTH_TOLERANCE``, else a value not over it.

        The undersides lie at most ``UNDER_REACH`` below the arm points and the
        house's corners at least ``0.95 - 3 tan(tilt)`` above the plane: above
        the highest relief by more, a negative bound is returned. A point that
        the relief bound alone keeps out of that tolerance is not looked up in
        the map (its bound stands for it: the steps' ground tests compare a
        depth with the tolerance, and two depths only when one is over it).
        """
        low = pose.low_arm - UNDER_REACH
        gap = (low if low < self._house_relief else self._house_relief) - self._relief_max
        if gap > 0.0:
            return -gap
        t = self.terrain
        memo = pose.body_memo
        if memo[0] is t and memo[1] == t.version:
            return memo[2]
        h, gx, gy = t.height_at, self._gx, self._gy
        relief = self._relief_max + self._cell_tilt  # over the plane anywhere in a cell
        (x0, x1), (y0, y1) = self._map_xy
        depth = -math.inf
        for x, y, z in pose.under():
            d = relief + gx * x + gy * y - z
            if d > DEPTH_TOLERANCE - SKIP or not (x0 < x < x1 and y0 < y < y1):
                d = h(x, y) - z
            if d > depth:
                depth = d
        pose.body_memo = (t, t.version, depth)
        return depth

    def _deposit(self, x: float, y: float, volume: float) -> None:
        """Soil on the ground at ``(x, y)``; the relief bound follows."""
        self.terrain.deposit(x, y, volume)
        t = self.terrain
        i, j = int((x - t.x0) / t.cell), int((y - t.y0) / t.cell)
        i0, i1 = max(i - 7, 0), min(i + 8, t.nx)
        j0, j1 = max(j - 7, 0), min(j + 8, t.ny)
        if i0 < i1 and j0 < j1:
            patch = t.h[i0:i1, j0:j1] - self._plane[i0:i1, j0:j1]
            self._relief_max = max(self._relief_max, float(patch.max()))

    def _cut(self, pose0: Pose, pose1: Pose) -> None:
        """Carve the edge's sweep; the bucket takes what it holds, the rest is pushed ahead."""
        m = self.m
        (a0, _, b0), (a1, _, b1) = pose0.edge(), pose1.edge()
        e0, e1 = ((a0[0], a0[1]), (b0[0], b0[1])), ((a1[0], a1[1]), (b1[0], b1[1]))
        removed = self.terrain.carve(e0, e1, pose0.tip[2], pose1.tip[2], math.inf)
        if removed <= 0.0:
            return
        room = max(m.bucket_capacity - self.fill, 0.0) / m.swell
        taken = min(removed, room)
        self.fill += taken * m.swell
        self.taken = removed
        surplus = removed - taken
        if surplus > 0.0:
            n = pose1.n
            norm = math.hypot(n[0], n[1]) or 1.0
            x = pose1.tip[0] + PUSH * n[0] / norm
            y = pose1.tip[1] + PUSH * n[1] / norm
            self._deposit(x, y, surplus)
            self.pushed = surplus

    def _pour_if_tipped(self) -> None:
        """As v0, except while the edge touches the ground (the cut face holds the soil in)."""
        pose = self._pose_now
        if self.fill > 0.0 and pose.n[2] < POUR_NZ and self._edge_depth(pose) < -DEPTH_TOLERANCE:
            self._pour(min(self.fill, self.m.bucket_capacity * self.dt / POUR_TIME))

    def _spill_on_ground(self, x: float, y: float, amount: float) -> None:
        """Loose soil (m3) returns to the ground as bank volume, ``amount / swell``."""
        self._deposit(x, y, amount / self.m.swell)


def _floats(value):
    """``value`` (a number, or tuples, named tuples and capsules of them) with every
    number a Python float: the same doubles."""
    if isinstance(value, bodies.Capsule):
        return bodies.Capsule(_floats(value.a), _floats(value.b), float(value.radius))
    if isinstance(value, tuple):
        items = [_floats(v) for v in value]
        return type(value)(*items) if hasattr(value, "_fields") else tuple(items)
    return float(value)


def _lerp(a, b, t: float) -> list[float]:
    return [x + t * (y - x) for x, y in zip(a, b, strict=True)]
