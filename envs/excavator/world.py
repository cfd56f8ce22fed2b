"""The excavator world: the machine's state and dynamics on carving ground.

:class:`ExcavatorWorld` is the only code that changes the machine, the
terrain and the soil accounts (a :class:`motiongym.envs.core.World`); the
tasks (:mod:`.task`) read it, the environments (:mod:`.env`) wire the two.
API::

    world = ExcavatorWorld(params, carve=True)
    world.action_space              # Box(-1, 1, (4,), float32)
    world.reset(scene, rng)         # a scene of .scenes; the machine at scene.start
    world.advance([a1, a2, a3, a4]) # one step of dt s, actions clipped to [-1, 1]; -> None
    world.render((rows, columns))   # an RGB frame (.render_scene)
    world.q, world.qdot, world.tip, world.beta, world.fill, world.truck_soil,
    world.spill, world.pipe_clear, world.truck_clear, world.contact,
    world.taken (m3 cut this step), world.terrain, world.profile()

``advance`` returns no events: what happened in the step is the state it
leaves (``contact``, ``taken``, the clearances, the soil accounts). The
world draws no noise (``reset``'s ``rng`` is not used).

Physics "v0" (the v0 IDs), one step:

1. action ``a`` (4,) in [-1, 1] (clipped) -> commanded joint rates ``a * rate_max``;
2. in soil (carving worlds), rates scaled by the resistance model
   (:func:`motiongym.envs.excavator.soil.speed_fraction` at the depth of cut
   of the previous step, the soil thickness the cutting edge went through);
3. joint angles integrated and held inside the joint ranges (the rate of a
   joint at its stop is zero);
4. forward kinematics (:func:`arm_points`, the scalar form of eq. 4);
5. carving (the cutting edge sweeps the height map, soil into the bucket)
   and pouring: the bucket opening faces ``n = (sin beta, -cos beta)`` in the
   boom plane (radial, up); when ``n_z < -0.3`` (opening turned more than
   about 17 deg below horizontal) the soil pours out at ``capacity / 1 s``,
   into the truck if the bucket is over its body, else spilled on the ground;
6. clearances to the pipe and the truck (:mod:`.obstacles`).

Only the bucket's cutting edge works the ground; boom and stick do not touch
it (nothing stops an agent). The base stands level at the origin
(``H_M^O`` = identity): frame M is the world frame. Physics "v1" is
:class:`motiongym.envs.excavator.world_v1.ExcavatorWorldV1`.

The scalar state lives in Python floats: the step makes few NumPy calls.
"""

from __future__ import annotations

import functools
import math

import numpy as np
from gymnasium import spaces

from motiongym.envs.excavator.config import Machine
from motiongym.envs.excavator.kinematics import arm_points
from motiongym.envs.excavator.observation import PROFILE_RADII
from motiongym.envs.excavator.obstacles import Pipe, Truck, pipe_clearance, truck_clearance
from motiongym.envs.excavator.params import ExcavatorParams
from motiongym.envs.excavator.scenes import GRID_CELL, GRID_ORIGIN, GRID_SHAPE, Scene
from motiongym.envs.excavator.soil import Terrain, speed_fraction
from motiongym.envs.rendering import OwnsRenderer

POUR_NZ = -0.3  # opening normal z below which soil pours
POUR_TIME = 1.0  # s to empty a full bucket
HORIZON = 1.0  # m: exact clearances below this bound
PROFILE_BINS_PER_DEG = 10


@functools.lru_cache(maxsize=8)
def profile_table(L0: float, d2: float) -> np.ndarray:
    """Flat map indices of the profile samples per 0.1 deg of swing, (3600, 24).

    The samples lie on the boom plane (offset ``d2``) at the radii of
    :data:`observation.PROFILE_RADII` from the swing axis (at ``x = -L0``);
    they stay inside the map (radii <= 10.2 m, map +-11 m).
    """
    angles = np.radians(np.arange(360 * PROFILE_BINS_PER_DEG) / PROFILE_BINS_PER_DEG)[:, None]
    r = PROFILE_RADII[None, :]
    x = -L0 + np.cos(angles) * r + np.sin(angles) * d2
    y = np.sin(angles) * r - np.cos(angles) * d2
    i = np.clip(((x - GRID_ORIGIN[0]) / GRID_CELL).astype(np.intp), 0, GRID_SHAPE[0] - 1)
    j = np.clip(((y - GRID_ORIGIN[1]) / GRID_CELL).astype(np.intp), 0, GRID_SHAPE[1] - 1)
    return i * GRID_SHAPE[1] + j


class ExcavatorWorld(OwnsRenderer):
    """The machine, the ground, the pipe and the truck (see the module docstring)."""

    def __init__(self, params: ExcavatorParams, carve: bool) -> None:
        self.params = params
        self.m: Machine = params.machine
        self.dt = params.dt
        self.carve = carve
        m = self.m
        self._joints = tuple(zip(range(4), m.rate_max, m.q_min, m.q_max, strict=True))
        self.action_space: spaces.Space = spaces.Box(-1.0, 1.0, shape=(4,), dtype=np.float32)
        self.scene: Scene | None = None

    # ----------------------------------------------------------------- reset
    def reset(self, scene: Scene, rng: np.random.Generator | None = None) -> None:
        """Place the scene and the machine at ``scene.start`` (4 joint angles, clipped to
        the ranges; None: ``Machine.q_ready``)."""
        self.scene = scene
        self.terrain = Terrain(scene.heights, GRID_ORIGIN, GRID_CELL)
        self.pipe: Pipe = scene.pipe
        self.truck: Truck = scene.truck
        q0 = self.m.q_ready if scene.start is None else scene.start
        self.q = np.clip(np.asarray(q0, dtype=np.float64), self.m.q_min, self.m.q_max).tolist()
        self.qdot = [0.0, 0.0, 0.0, 0.0]
        self.fill = 0.0
        self.truck_soil = 0.0
        self.spill = 0.0
        self.elapsed = 0.0
        self.steps = 0
        self.taken = 0.0
        a, b = self.pipe.a, self.pipe.b
        length = math.hypot(b[0] - a[0], b[1] - a[1])
        if length > 1e-9:
            direction = ((b[0] - a[0]) / length, (b[1] - a[1]) / length)
        else:  # a vertical or point pipe: no plan-view bound
            direction = (0.0, 0.0)
        self._pipe_line = ((a[0], a[1]), direction, length)
        self._pipe_zmax = max(a[2], b[2])
        self._truck_radius = math.hypot(self.truck.half_length, self.truck.half_width)
        self._truck_corners = self.truck.corners()
        self._max_r = max(self.m.link_radius)
        self._profile_key = None
        self._profile_table = profile_table(self.m.L0, self.m.d2)
        self._flat_heights = self.terrain.h.reshape(-1)  # a view, follows the carving
        self._forward()
        self._prev_tip, self._prev_swing = self.tip, self.q[0]
        self._clearances()

    # ------------------------------------------------------------------ step
    def advance(self, values: list[float]) -> None:
        """One step of ``dt`` s under the actions ``values`` (4 floats, clipped to [-1, 1]).

        No events are returned: the step's are the state it leaves (module docstring).
        """
        m, dt = self.m, self.dt
        scale = 1.0
        if self.carve:
            depth = self.terrain.last_cut_depth
            if depth > 0.0:
                scale = speed_fraction(depth, m.bucket_width, m)
        q, qdot = self.q, self.qdot
        for (k, rmax, lo, hi), v in zip(self._joints, values, strict=True):
            rate = (1.0 if v > 1.0 else -1.0 if v < -1.0 else v) * rmax * scale
            new = q[k] + rate * dt
            if new < lo or new > hi:
                new = lo if new < lo else hi
                rate = (new - q[k]) / dt
            q[k] = new
            qdot[k] = rate
        self._forward()
        self.steps += 1
        self.elapsed = self.steps * dt
        self.taken = 0.0
        if self.carve:
            self._carve_and_pour()
        self._clearances()

    def measures(self) -> dict[str, float]:
        """Extra ``info`` keys of this physics (none in v0)."""
        return {}

    def render(self, size: tuple[int, int]) -> np.ndarray:
        """An RGB frame of ``size`` = (rows, columns) (:class:`.render_scene.SceneRenderer`,
        made on the first call and again when the size changes)."""
        renderer = self._renderer
        if renderer is None or renderer.size != tuple(size):
            from motiongym.envs.excavator.render_scene import SceneRenderer

            self.close()
            self._renderer = renderer = SceneRenderer(self.m, size)
        return renderer.render(self)

    @property
    def contact(self) -> bool:
        """Whether the arm touches the pipe or the truck (clearance <= 0)."""
        return self.pipe_clear <= 0.0 or self.truck_clear <= 0.0

    # --------------------------------------------------------------- physics
    def _forward(self) -> None:
        q1, q2, q3, q4 = self.q
        self.points = arm_points(q1, q2, q3, q4, self.m)
        self.tip = self.points[3]
        self.beta = self.q[1] + self.q[2] + self.q[3]

    def _edge(
        self, tip: tuple[float, float, float], swing: float
    ) -> tuple[tuple[float, float], tuple[float, float]]:
        """End points (x, y) of the cutting edge, across the boom plane at the tip."""
        half = 0.5 * self.m.bucket_width
        c1, s1 = math.cos(swing), math.sin(swing)
        x, y = tip[0], tip[1]
        return (x + half * s1, y - half * c1), (x - half * s1, y + half * c1)

    def _carve_and_pour(self) -> None:
        m = self.m
        z = self.tip[2]
        top = self.terrain.max_height
        prev_tip, prev_swing = self._prev_tip, self._prev_swing
        if z < top or prev_tip[2] < top:
            free = m.bucket_capacity - self.fill
            edge0 = self._edge(prev_tip, prev_swing)
            edge1 = self._edge(self.tip, self.q[0])
            taken = self.terrain.carve(edge0, edge1, prev_tip[2], z, free)
            if taken > 0.0:
                self.fill += taken
                self.taken = taken
        else:
            self.terrain.last_cut_depth = 0.0
        self._prev_tip, self._prev_swing = self.tip, self.q[0]
        if self.fill > 0.0 and -math.cos(self.beta) < POUR_NZ:
            self._pour(min(self.fill, m.bucket_capacity * self.dt / POUR_TIME))

    def _pour(self, amount: float) -> None:
        """Empty ``amount`` (m3) from the bucket: into the truck if over it, else on the ground."""
        self.fill -= amount
        pin = self.points[2]
        x, y = 0.5 * (pin[0] + self.tip[0]), 0.5 * (pin[1] + self.tip[1])
        if self.truck.contains_xy(x, y) and min(pin[2], self.tip[2]) > self.truck.height:
            self.truck_soil += amount
        else:
            self.spill += amount
            self._spill_on_ground(x, y, amount)

    def _spill_on_ground(self, x: float, y: float, amount: float) -> None:
        """Soil poured beside the truck lands on the ground at ``(x, y)``."""
        self.terrain.deposit(x, y, amount)

    def _clearances(self) -> None:
        """Pipe and truck clearance: cheap lower bounds first, exact when under HORIZON.

        Every arm point lies on the vertical plane at azimuth ``q1`` (lateral
        offset ``-d2``); link ``k`` spans radii ``[ra, rb]`` and heights
        ``[za, zb]`` in it. Lower bounds per link (a projection is
        1-Lipschitz, and a box's projection spans its corners'):

        * pipe: plan gap from the link's radial segment to the pipe's
          (infinite) line, vertical gap from the link's lowest point to the
          pipe's axis; the distance is at least their Euclidean combination;
        * truck: the largest of the lateral gap of the footprint's corners to
          the plane (all on one side), the radial gap between the link and the
          corners, and the link's height above the rim.

        Before those, whole-arm bounds (the arm's lowest point above the pipe
        or the rim; the truck's circumscribed circle against the plane) skip
        the per-link ones when they already exceed ``HORIZON``. The exact
        distance (:mod:`.obstacles`) is computed when a bound is under
        ``HORIZON``; else the bound is reported.
        """
        pts = self.points
        c1, s1 = math.cos(self.q[0]), math.sin(self.q[0])
        ox, oy = -self.m.L0 + s1 * self.m.d2, -c1 * self.m.d2  # the plane's origin in plan
        heights = [p[2] for p in pts]
        radial = [c1 * (p[0] - ox) + s1 * (p[1] - oy) for p in pts]
        lowest = min(heights)
        bound, links = self._pipe_bound(c1, s1, ox, oy, heights, radial, lowest)
        if bound < HORIZON:
            self.pipe_clear = pipe_clearance(pts, self.m.link_radius, self.pipe, links)
        else:
            self.pipe_clear = bound
        bound = self._truck_bound(c1, s1, ox, oy, heights, radial, lowest)
        if bound < HORIZON:
            self.truck_clear = truck_clearance(pts, self.m.link_radius, self.truck)
        else:
            self.truck_clear = bound

    def _pipe_bound(self, c1, s1, ox, oy, heights, radial, lowest):
        """Lower bound of the pipe clearance and the per-link bounds (None if not needed)."""
        zmax, rp = self._pipe_zmax, self.pipe.radius
        bound = lowest - zmax - rp - self._max_r
        if bound >= HORIZON:
            return bound, None
        # The plan gap to the pipe's line is linear in the radius: a + b r.
        (px, py), (ux, uy), _ = self._pipe_line
        a = (ox - px) * -uy + (oy - py) * ux
        b = c1 * -uy + s1 * ux
        g = [a + b * r for r in radial]
        links = []
        for k in range(3):
            g0, g1 = g[k], g[k + 1]
            plan = 0.0 if g0 * g1 <= 0.0 else min(abs(g0), abs(g1))
            vertical = max(min(heights[k], heights[k + 1]) - zmax, 0.0)
            links.append(math.hypot(plan, vertical) - self.m.link_radius[k] - rp)
        return min(links), links

    def _truck_bound(self, c1, s1, ox, oy, heights, radial, lowest) -> float:
        """Lower bound of the truck clearance: circumscribed circle and rim, then per link."""
        truck = self.truck
        rim = truck.height
        centre = -s1 * (truck.cx - ox) + c1 * (truck.cy - oy)
        bound = max(abs(centre) - self._truck_radius, lowest - rim) - self._max_r
        if bound >= HORIZON:
            return bound
        lateral, along = [], []  # the corners across and along the plane
        for x, y in self._truck_corners:
            dx, dy = x - ox, y - oy
            lateral.append(-s1 * dx + c1 * dy)
            along.append(c1 * dx + s1 * dy)
        lo, hi = min(lateral), max(lateral)
        side = 0.0 if lo * hi <= 0.0 else min(abs(lo), abs(hi))
        amin, amax = min(along), max(along)
        bound = math.inf
        # Comparisons, not min/max calls (this runs on many steps); side >= 0
        # stands for the clamp of ``ahead`` at zero.
        for k in range(3):
            near, far = radial[k], radial[k + 1]
            if near > far:
                near, far = far, near
            ahead = amin - far if amin - far > near - amax else near - amax
            za, zb = heights[k], heights[k + 1]
            above = (za if za < zb else zb) - rim
            gap = side if side > ahead else ahead
            gap = (gap if gap > above else above) - self.m.link_radius[k]
            if gap < bound:
                bound = gap
        return bound

    # ----------------------------------------------------------- observation
    def profile(self) -> np.ndarray:
        """Ground heights along the boom plane, at the nearest 0.1 deg of swing."""
        key = (self.q[0], self.terrain.version)
        if key != self._profile_key:
            b = (
                int(round(math.degrees(self.q[0]) * PROFILE_BINS_PER_DEG))
                % self._profile_table.shape[0]
            )
            self._profile_cache = self._flat_heights[self._profile_table[b]]
            self._profile_key = key
        return self._profile_cache
