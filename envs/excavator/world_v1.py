"""Physics v1 of the excavator world: a machine that cannot pass through soil, pipe or itself.

:class:`ExcavatorWorldV1` has the API of :class:`.world.ExcavatorWorld`
(``reset(scene, q0)``, ``advance(actions)``, the same state attributes) and
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

from motiongym.envs.excavator import bodies
from motiongym.envs.excavator.digging import DEPTH_TOLERANCE, PUSH, cuts, stall_fraction
from motiongym.envs.excavator.hydraulics import hydraulic_rates
from motiongym.envs.excavator.kinematics import arm_points, base_rotation
from motiongym.envs.excavator.scenes import CELL_XS, CELL_YS, ground_plane
from motiongym.envs.excavator.soil import cutting_force
from motiongym.envs.excavator.world import HORIZON, POUR_NZ, POUR_TIME, ExcavatorWorld

BISECTIONS = 6
SELF_HORIZON = 0.3  # m: self clearance exact below this
UNDER_REACH = 1.3  # m: how far any body (bucket box: 1.12 m) reaches from the arm's polyline
PARTS = ("boom", "stick", "bucket")  # the arm's links, in the order of its polyline
HOUSE_RADIUS = 3.5  # m: house and tracks lie within this of the swing axis (3.13 m, 0.3 m tilt)
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
        "edge",
        "low_arm",
        "low_edge",
        "_world",
    )

    def __init__(self, q, world) -> None:
        self.q, self._world = q, world
        m, r = world.m, world.rotation
        q1, q2, q3, q4 = q
        pts = arm_points(q1, q2, q3, q4, m)
        c1, s1 = math.cos(q1), math.sin(q1)
        beta = q2 + q3 + q4
        cb, sb = math.cos(beta), math.sin(beta)
        n, u, lat = (c1 * sb, s1 * sb, -cb), (c1 * cb, s1 * cb, sb), (s1, -c1, 0.0)
        if r is not None:
            (a, b, c), (d, e, f), (g, h, i) = r
            pts, n, u, lat = (
                tuple(
                    (a * x + b * y + c * z, d * x + e * y + f * z, g * x + h * y + i * z)
                    for x, y, z in vectors
                )
                for vectors in (pts, (n,), (u,), (lat,))
            )
            n, u, lat = n[0], u[0], lat[0]
        self.points, self.tip, self.beta = pts, pts[3], beta
        self.n, self.u, self.lat = n, u, lat
        tip, half = pts[3], 0.5 * m.bucket_width - 0.05
        lx, ly, lz = half * lat[0], half * lat[1], half * lat[2]
        self.edge = (
            (tip[0] + lx, tip[1] + ly, tip[2] + lz),
            tip,
            (tip[0] - lx, tip[1] - ly, tip[2] - lz),
        )
        # Heights above the ground plane: of the lowest arm point past the foot, and the edge.
        gx, gy = world._gx, world._gy
        self.low_arm = min(p[2] - gx * p[0] - gy * p[1] for p in pts[1:])
        self.low_edge = tip[2] - gx * tip[0] - gy * tip[1] - abs(lz) - abs(gx * lx + gy * ly)

    def under(self) -> list[tuple[float, float, float]]:
        """Points on the undersides of house, boom, stick and bucket shell (O)."""
        world = self._world
        m, rot = world.m, world._rot if world.rotation is not None else None
        c1, s1 = math.cos(self.q[0]), math.sin(self.q[0])
        x0, z0 = -m.L0, bodies.HOUSE[2][0]
        out = [
            (x0 + c1 * x - s1 * y, s1 * x + c1 * y, z0)
            for x in bodies.HOUSE[0]
            for y in bodies.HOUSE[1]
        ]
        if rot is not None:
            out = [rot(p) for p in out]
        foot, stick_pin, pin, _ = self.points
        for a, b, r in (
            (foot, stick_pin, bodies.BOOM_RADIUS),
            (stick_pin, stick_pin, bodies.BOOM_RADIUS),
            (stick_pin, pin, bodies.STICK_RADIUS),
            (pin, pin, bodies.STICK_RADIUS),
        ):
            out.append((0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1]), 0.5 * (a[2] + b[2]) - r))
        u, n, lat = self.u, self.n, self.lat
        side = 0.5 * m.bucket_width - SHELL_INSET
        for along, back in SHELL:
            a = along * m.L4
            for s in (side, -side):
                out.append(tuple(pin[i] + a * u[i] - back * n[i] + s * lat[i] for i in range(3)))
        return out


class ExcavatorWorldV1(ExcavatorWorld):
    """See the module docstring."""

    def reset(self, scene, q0) -> None:
        base = tuple(scene.base)
        self.rotation = None if base == (0.0, 0.0, 0.0) else base_rotation(*base).tolist()
        self.self_clear = math.inf
        self.ground_contact = 0.0
        self.cut_force = 0.0
        self.advance_fraction = 1.0
        self.pushed = 0.0
        pipe, truck = scene.pipe, scene.truck
        self._pipe_body = bodies.Capsule(pipe.a, pipe.b, pipe.radius)
        self._pipe_top = max(pipe.a[2], pipe.b[2]) + pipe.radius
        self._truck_centre = (truck.cx, truck.cy)
        self._truck_radius = math.hypot(truck.half_length, truck.half_width)
        self._axis = (-self.m.L0, 0.0)
        # The house stays within HOUSE_RADIUS of the axis: its bound to the truck is fixed.
        self._house_truck = (
            math.hypot(truck.cx + self.m.L0, truck.cy) - self._truck_radius - HOUSE_RADIUS
        )
        self._house_top = bodies.HOUSE[2][1] + 0.35  # + the tilt's lift at 3.5 m
        d = tuple(b - a for a, b in zip(pipe.a, pipe.b, strict=True))
        self._pipe_line3 = (pipe.a, d, 1.0 / max(sum(x * x for x in d), 1e-12))
        c, s = math.cos(truck.yaw), math.sin(truck.yaw)
        self._truck_body = bodies.box_from_ranges(
            (truck.cx, truck.cy, 0.0),
            ((c, s, 0.0), (-s, c, 0.0), (0.0, 0.0, 1.0)),
            (
                (-truck.half_length, truck.half_length),
                (-truck.half_width, truck.half_width),
                (truck.floor, truck.height),
            ),
        )
        self._gx, self._gy = ground_plane(base)
        self._plane = self._gx * CELL_XS[:, None] + self._gy * CELL_YS[None, :]
        # + 0.01 m: the plane's change within a cell (the map holds cell centres).
        self._relief_max = float((scene.heights - self._plane).max()) + 0.01
        tilt = math.hypot(self._gx, self._gy)
        self._house_relief = bodies.HOUSE[2][0] - 3.0 * tilt
        half = [0.5 * (hi - lo) for lo, hi in bodies.HOUSE]
        self._house_radius = math.sqrt(sum(h * h for h in half))
        origin = ((0.0, 0.0, 0.0),) * 4  # the tracks do not depend on the arm
        self._tracks_box = bodies.machine_bodies(
            origin, 0.0, self.rotation, self.m.bucket_width, self.m.L0, ("tracks",)
        )["tracks"]
        super().reset(scene, q0)

    # ------------------------------------------------------------------ step
    def advance(self, values: list[float]) -> None:
        m, dt = self.m, self.dt
        q0 = list(self.q)
        rates = hydraulic_rates(values, self.qdot, m, dt)
        target = []
        for (k, _, lo, hi), r in zip(self._joints, rates, strict=True):
            new = q0[k] + r * dt
            target.append(lo if new < lo else hi if new > hi else new)
        pose0, pose1 = self._pose_now, self._pose(target)
        v = tuple(b - a for a, b in zip(pose0.tip, pose1.tip, strict=True))
        depth1 = self._edge_depth(pose1)
        cutting = self.carve and depth1 > 0.0 and cuts(v, pose1.n)
        edge0, body0 = self._edge_depth(pose0), self._penetration(pose0)

        def free(pose: Pose) -> bool:
            # Into the ground only where a part is not yet, or on its way out.
            body = self._penetration(pose)
            if body > DEPTH_TOLERANCE and body >= body0:
                return False
            if cutting:
                return True
            edge = self._edge_depth(pose)
            return edge <= DEPTH_TOLERANCE or edge < edge0

        t, pose = 1.0, pose1
        body1 = self._penetration(pose1)
        body_stop = body1 > DEPTH_TOLERANCE and body1 >= body0
        if body_stop or not free(pose1):
            t, pose = self._bisect(q0, target, free)
        self.cut_force = cutting_force(depth1, m.bucket_width, m) if cutting else 0.0
        if cutting:
            f = stall_fraction(self.cut_force, m.dig_force)
            if f < t:
                t, pose = f, self._pose(_lerp(q0, target, f))
        self.ground_contact = 1.0 if body_stop else 0.0
        self.advance_fraction = t
        self.q = list(pose.q)
        self.qdot = [(a - b) / dt for a, b in zip(self.q, q0, strict=True)]
        self._set_pose(pose)
        self.steps += 1
        self.elapsed = self.steps * dt
        self.taken = self.pushed = 0.0
        if self.carve:
            if cutting and t > 0.0:
                self._cut(pose0, pose)
            self._pour_if_tipped()
        self._clearances()

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
    def _rot(self, v) -> tuple[float, float, float]:
        """``R v``: a vector of frame M in frame O (the base rotation)."""
        (a, b, c), (d, e, f), (g, h, i) = self.rotation
        x, y, z = v
        return (a * x + b * y + c * z, d * x + e * y + f * z, g * x + h * y + i * z)

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
        h = self.terrain.height_at
        return max(h(p[0], p[1]) - p[2] for p in pose.edge)

    def _penetration(self, pose: Pose) -> float:
        """Deepest point of the bodies' undersides below the ground (m; negative: above).

        The undersides lie at most ``UNDER_REACH`` below the arm points and the
        house's corners at least ``0.95 - 3 tan(tilt)`` above the plane: above
        the highest relief by more, a negative bound is returned.
        """
        low = pose.low_arm - UNDER_REACH
        gap = (low if low < self._house_relief else self._house_relief) - self._relief_max
        if gap > 0.0:
            return -gap
        h = self.terrain.height_at
        return max(h(p[0], p[1]) - p[2] for p in pose.under())

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
        e0 = ((pose0.edge[0][0], pose0.edge[0][1]), (pose0.edge[2][0], pose0.edge[2][1]))
        e1 = ((pose1.edge[0][0], pose1.edge[0][1]), (pose1.edge[2][0], pose1.edge[2][1]))
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

    def _clearances(self) -> None:
        """Exact body distances below the horizons, lower bounds above.

        Pipe and truck: exact below ``HORIZON`` (1 m; the house against the
        truck below ``SELF_HORIZON``); self: exact below ``SELF_HORIZON``
        (0.3 m). Each part's bound, cheapest first: its segment of the arm's
        polyline (the bucket's body lies within ``UNDER_REACH`` of it, a
        link's within its radius; house and tracks within ``HOUSE_RADIUS``
        of the swing axis) against the obstacle's bounding circle in plan
        and its top; the bucket's bounding sphere next; a body is built only
        when its bound is under its horizon.
        """
        pts = self.points
        reach = (bodies.BOOM_RADIUS, bodies.STICK_RADIUS, UNDER_REACH)
        cache: dict = {}
        best = math.inf
        for k, name in enumerate(PARTS):
            d = min(pts[k][2], pts[k + 1][2]) - reach[k] - self._pipe_top
            if d < HORIZON:
                d = self._exact(cache, name, self._pipe_body, self._pipe_gap, HORIZON)
            best = d if d < best else best
        self.pipe_clear = best
        cx, cy = self._truck_centre
        best = self._house_truck
        if best < SELF_HORIZON:
            best = self._exact(cache, "house", self._truck_body, self._truck_body.gap, SELF_HORIZON)
        for k, name in enumerate(PARTS):
            plan = _plan_gap(pts[k], pts[k + 1], cx, cy) - self._truck_radius
            above = min(pts[k][2], pts[k + 1][2]) - self.truck.height
            d = max(plan, above) - reach[k]
            if d < HORIZON:
                d = self._exact(cache, name, self._truck_body, self._truck_body.gap, HORIZON)
            best = d if d < best else best
        self.truck_clear = best
        ax, ay = self._axis
        best = math.inf
        for k, name in ((1, "stick"), (2, "bucket")):
            plan = _plan_gap(pts[k], pts[k + 1], ax, ay) - HOUSE_RADIUS
            above = min(pts[k][2], pts[k + 1][2]) - self._house_top
            d = max(plan, above) - reach[k]
            if d < SELF_HORIZON:
                d = min(
                    self._exact(cache, name, self._part(cache, other), None, SELF_HORIZON)
                    for other in ("tracks", "house")
                )
            best = d if d < best else best
        self.self_clear = best

    def _exact(self, cache: dict, name: str, other, gap, horizon: float) -> float:
        """Distance of part ``name`` to ``other``; for a box, its sphere's and its
        separating axes' bounds first (the bound is returned when not under ``horizon``)."""
        if name == "bucket" or name == "house":
            c, r = self._sphere(name)
            d = (gap(c) if gap is not None else other.gap(c)) - r
            if d >= horizon:
                return d
            body = self._part(cache, name)
            d = bodies.lower_bound(body, other)
            if d >= horizon:
                return d
            return bodies.distance(body, other)
        return bodies.distance(self._part(cache, name), other)

    def _part(self, cache: dict, name: str):
        if name == "tracks":
            return self._tracks_box
        if name not in cache:
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

    def _sphere(self, name: str) -> tuple[tuple[float, float, float], float]:
        """Bounding sphere ``(centre, radius)`` of the bucket's or the house's body."""
        m = self.m
        if name == "bucket":
            pin, pose = self.points[2], self._pose_now
            along, back = 0.5 * (m.L4 - 0.1), 0.5 * (bodies.BUCKET_BACK - 0.05)
            u, n = pose.u, pose.n
            centre = tuple(pin[i] + along * u[i] - back * n[i] for i in range(3))
            half = (along + 0.1, back + 0.05, 0.5 * m.bucket_width + bodies.BUCKET_SIDE)
            return centre, math.sqrt(sum(h * h for h in half))
        c1, s1 = math.cos(self.q[0]), math.sin(self.q[0])
        (x0, x1), (y0, y1), (z0, z1) = bodies.HOUSE
        x, y = 0.5 * (x0 + x1), 0.5 * (y0 + y1)
        house = (-m.L0 + c1 * x - s1 * y, s1 * x + c1 * y, 0.5 * (z0 + z1))
        return (self._rot(house) if self.rotation else house), self._house_radius


def _plan_gap(a, b, x: float, y: float) -> float:
    """Plan-view distance from the point ``(x, y)`` to the segment ``a b``."""
    dx, dy = b[0] - a[0], b[1] - a[1]
    px, py = x - a[0], y - a[1]
    length2 = dx * dx + dy * dy
    t = (px * dx + py * dy) / length2 if length2 > 1e-18 else 0.0
    t = 0.0 if t < 0.0 else 1.0 if t > 1.0 else t
    return math.hypot(px - t * dx, py - t * dy)


def _mid(a, b) -> tuple[float, float, float]:
    return (0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1]), 0.5 * (a[2] + b[2]))


def _near(body, other) -> float:
    """Exact distance when under ``HORIZON``, else a lower bound from ``body``'s sphere."""
    centre, radius = body.sphere()
    bound = bodies.distance(bodies.Capsule(centre, centre, radius), other)
    if bound >= HORIZON:
        return bound
    return bodies.distance(body, other)


def _lerp(a, b, t: float) -> list[float]:
    return [x + t * (y - x) for x, y in zip(a, b, strict=True)]
