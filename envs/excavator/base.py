"""The machine in the world: what both excavator environments share.

One step (``dt`` s) of the hydraulic machine:

1. action ``a`` (4,) in [-1, 1] -> commanded joint rates ``a * rate_max``;
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
it (a machine would not drive them into the soil; nothing stops an agent).
The base stands level at the origin (``H_M^O`` = identity): frame M is the
world frame.

Subclasses (the tasks) supply ``TASK``, scene sampling, reward and success.
The scalar state lives in Python floats: the step makes few NumPy calls
(an environment step costs tens of microseconds).
"""

from __future__ import annotations

import functools
import math
import struct
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from motiongym.envs.actions import checked_box_action
from motiongym.envs.excavator import observation as obs_layout
from motiongym.envs.excavator.config import Machine, machine_from_kwargs
from motiongym.envs.excavator.kinematics import arm_points
from motiongym.envs.excavator.obstacles import Pipe, Truck, pipe_clearance, truck_clearance
from motiongym.envs.excavator.soil import Terrain, speed_fraction
from motiongym.envs.excavator.task import GRID_CELL, GRID_ORIGIN, GRID_SHAPE, Scene
from motiongym.envs.rendering import OwnsRenderer

POUR_NZ = -0.3  # opening normal z below which soil pours
POUR_TIME = 1.0  # s to empty a full bucket
HORIZON = 1.0  # m: exact clearances below this bound
RESET_OPTIONS = ("q0",)
PROFILE_BINS_PER_DEG = 10
# Observation entries 0-12 (q, qdot, tip, bucket angle, fill) written as float32
# straight into the buffer: the same rounding as NumPy's cast, without
# converting a list (the observation is C-contiguous, native float32).
_STATE = struct.Struct("=13f")


@functools.lru_cache(maxsize=8)
def profile_table(L0: float, d2: float) -> np.ndarray:
    """Flat map indices of the profile samples per 0.1 deg of swing, (3600, 24).

    The samples lie on the boom plane (offset ``d2``) at the radii of
    :data:`observation.PROFILE_RADII` from the swing axis (at ``x = -L0``);
    they stay inside the map (radii <= 10.2 m, map +-11 m).
    """
    angles = np.radians(np.arange(360 * PROFILE_BINS_PER_DEG) / PROFILE_BINS_PER_DEG)[:, None]
    r = obs_layout.PROFILE_RADII[None, :]
    x = -L0 + np.cos(angles) * r + np.sin(angles) * d2
    y = np.sin(angles) * r - np.cos(angles) * d2
    i = np.clip(((x - GRID_ORIGIN[0]) / GRID_CELL).astype(np.intp), 0, GRID_SHAPE[0] - 1)
    j = np.clip(((y - GRID_ORIGIN[1]) / GRID_CELL).astype(np.intp), 0, GRID_SHAPE[1] - 1)
    return i * GRID_SHAPE[1] + j


class ExcavatorBase(OwnsRenderer, gym.Env):
    """Shared machinery; see :class:`ExcavatorReachEnv` and :class:`ExcavatorEnv`."""

    metadata = {"render_modes": ["rgb_array"], "render_fps": 10}
    TASK = "reach"
    CARVE = False
    REWARD_TERMS: tuple[str, ...] = ()

    def __init__(
        self,
        machine: dict | Machine | None = None,
        dt: float = 0.1,  # s
        pipe_safety: float = 0.5,  # m
        render_mode: str | None = None,
        render_size: tuple[int, int] = (480, 640),
    ) -> None:
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(
                f"unknown render_mode {render_mode!r}; valid: {self.metadata['render_modes']}"
            )
        if not dt > 0:
            raise ValueError(f"dt must be positive, got {dt!r}")
        self.m = machine_from_kwargs(machine)
        m = self.m
        self._joints = tuple(zip(range(4), m.rate_max, m.q_min, m.q_max, strict=True))  # per joint
        self.dt = float(dt)
        self.pipe_safety = float(pipe_safety)
        self.render_mode = render_mode
        self.render_size = tuple(render_size)
        self.layout = obs_layout.layout(self.TASK)
        low, high = obs_layout.bounds(self.TASK, self.m)
        self.observation_space = spaces.Box(low, high, dtype=np.float32)
        self.action_space = spaces.Box(-1.0, 1.0, shape=(4,), dtype=np.float32)
        self._renderer = None
        self.scene: Scene | None = None
        self._reward_keys = {k: f"reward_{k}" for k in self.REWARD_TERMS}

    # ----------------------------------------------------------------- hooks
    def _sample_scene(self, rng: np.random.Generator) -> Scene:
        raise NotImplementedError

    def _task_reset(self) -> None:
        """Set per-episode task state after the scene is in place."""

    def _task_step(self) -> tuple[dict[str, float], bool, dict[str, Any]]:
        """``(reward terms, success, extra info)`` after the physics of a step."""
        raise NotImplementedError

    def _on_cut(self, volume: float) -> None:
        """Called after the bucket took ``volume`` m3 (``terrain.last_cut`` says where)."""

    def _task_obs(self, buf: np.ndarray) -> None:
        """Write the task's changing slices into ``buf`` (static ones are set at reset)."""

    # ----------------------------------------------------------------- reset
    def reset(self, *, seed: int | None = None, options: dict | None = None):
        super().reset(seed=seed)
        options = dict(options or {})
        unknown = sorted(set(options) - set(RESET_OPTIONS))
        if unknown:
            raise ValueError(f"unknown reset option(s) {unknown}; valid: {list(RESET_OPTIONS)}")
        scene = self._sample_scene(self.np_random)
        self.scene = scene
        self.terrain = Terrain(scene.heights, GRID_ORIGIN, GRID_CELL)
        self.pipe: Pipe = scene.pipe
        self.truck: Truck = scene.truck
        q0 = options.get("q0", self.m.q_ready)
        q0 = np.asarray(q0, dtype=np.float64)
        if q0.shape != (4,) or not np.all(np.isfinite(q0)):
            raise ValueError(f"option q0 must be 4 finite joint angles, got {options.get('q0')!r}")
        self.q = np.clip(q0, self.m.q_min, self.m.q_max).tolist()
        self.qdot = [0.0, 0.0, 0.0, 0.0]
        self.fill = 0.0
        self.truck_soil = 0.0
        self.spill = 0.0
        self.elapsed = 0.0
        self.steps = 0
        a, b = self.pipe.a, self.pipe.b
        length = math.hypot(b[0] - a[0], b[1] - a[1])
        if length > 1e-9:
            self._pipe_line = (
                (a[0], a[1]),
                ((b[0] - a[0]) / length, (b[1] - a[1]) / length),
                length,
            )
        else:  # a vertical or point pipe: no plan-view bound
            self._pipe_line = ((a[0], a[1]), (0.0, 0.0), 0.0)
        self._pipe_zmax = max(a[2], b[2])
        self._truck_radius = math.hypot(self.truck.half_length, self.truck.half_width)
        self._truck_corners = self.truck.corners()
        self._max_r = max(self.m.link_radius)
        self._profile_key = None
        self._profile_table = profile_table(self.m.L0, self.m.d2)
        self._flat_heights = self.terrain.h.reshape(-1)  # a view, follows the carving
        self._obs = np.zeros(self.observation_space.shape, dtype=np.float32)
        self._obs[self.layout["truck"]] = self.truck.as_array()
        self._obs[self.layout["pipe"]] = self.pipe.as_array()
        self._forward()
        self._prev_tip, self._prev_swing = self.tip, self.q[0]
        self._clearances()
        self._task_reset()
        info = self._info(dict.fromkeys(self.REWARD_TERMS, 0.0), False)
        return self._observation(), info

    # ------------------------------------------------------------------ step
    def step(self, action):
        values = checked_box_action(action, (4,), "swing, boom, stick, bucket rates").tolist()
        if self.scene is None:
            raise RuntimeError("call reset() before step()")
        m, dt = self.m, self.dt
        scale = 1.0
        if self.CARVE:
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
        if self.CARVE:
            self._carve_and_pour()
        self._clearances()
        terms, success, extra = self._task_step()
        reward = float(sum(terms.values()))
        contact = self.pipe_clear <= 0.0 or self.truck_clear <= 0.0
        terminated = bool(success or contact)
        info = self._info(terms, success)
        info.update(extra)
        return self._observation(), reward, terminated, False, info

    # --------------------------------------------------------------- physics
    def _forward(self) -> None:
        self.points = arm_points(*self.q, self.m)
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
                self._on_cut(taken)
        else:
            self.terrain.last_cut_depth = 0.0
        self._prev_tip, self._prev_swing = self.tip, self.q[0]
        if self.fill > 0.0 and -math.cos(self.beta) < POUR_NZ:
            amount = min(self.fill, m.bucket_capacity * self.dt / POUR_TIME)
            self.fill -= amount
            pin = self.points[2]
            x, y = 0.5 * (pin[0] + self.tip[0]), 0.5 * (pin[1] + self.tip[1])
            if self.truck.contains_xy(x, y) and min(pin[2], self.tip[2]) > self.truck.height:
                self.truck_soil += amount
            else:
                self.spill += amount
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
        r_link = self.m.link_radius
        c1, s1 = math.cos(self.q[0]), math.sin(self.q[0])
        ox, oy = -self.m.L0 + s1 * self.m.d2, -c1 * self.m.d2  # the plane's origin in plan
        heights = [p[2] for p in pts]
        lowest = min(heights)
        radial = None
        # Pipe: first the whole arm's height above it, then per link.
        zmax, rp = self._pipe_zmax, self.pipe.radius
        bound = lowest - zmax - rp - self._max_r
        if bound < HORIZON:
            radial = [c1 * (p[0] - ox) + s1 * (p[1] - oy) for p in pts]
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
                links.append(math.hypot(plan, vertical) - r_link[k] - rp)
            bound = min(links)
        if bound < HORIZON:
            self.pipe_clear = pipe_clearance(pts, r_link, self.pipe, links)
        else:
            self.pipe_clear = bound
        # Truck: first its circumscribed circle's lateral gap and the rim height.
        truck = self.truck
        rim = truck.height
        centre = -s1 * (truck.cx - ox) + c1 * (truck.cy - oy)
        bound = max(abs(centre) - self._truck_radius, lowest - rim) - self._max_r
        if bound < HORIZON:
            lateral, along = [], []  # the corners across and along the plane
            for x, y in self._truck_corners:
                dx, dy = x - ox, y - oy
                lateral.append(-s1 * dx + c1 * dy)
                along.append(c1 * dx + s1 * dy)
            lo, hi = min(lateral), max(lateral)
            side = 0.0 if lo * hi <= 0.0 else min(abs(lo), abs(hi))
            amin, amax = min(along), max(along)
            if radial is None:
                radial = [c1 * (p[0] - ox) + s1 * (p[1] - oy) for p in pts]
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
                gap = (gap if gap > above else above) - r_link[k]
                if gap < bound:
                    bound = gap
        if bound < HORIZON:
            self.truck_clear = truck_clearance(pts, r_link, truck)
        else:
            self.truck_clear = bound

    # ----------------------------------------------------------- observation
    def _profile(self) -> np.ndarray:
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

    def _observation(self) -> np.ndarray:
        """The layout of :mod:`.observation`; inside the bounds by construction (tested).

        The static slices (task, truck, pipe) are written once at reset.
        """
        buf = self._obs
        _STATE.pack_into(buf, 0, *self.q, *self.qdot, *self.tip, self.beta, self.fill)
        buf[13:37] = self._profile()
        self._task_obs(buf)
        return buf.copy()

    def _info(self, terms: dict[str, float], success: bool) -> dict[str, Any]:
        cost = (
            self.pipe_clear < self.pipe_safety or self.pipe_clear <= 0.0 or self.truck_clear <= 0.0
        )
        keys = self._reward_keys
        info = {keys[k]: float(v) for k, v in terms.items()}
        info.update(
            {
                "is_success": bool(success),
                "cost": 1.0 if cost else 0.0,
                "pipe_clearance": float(self.pipe_clear),
                "truck_clearance": float(self.truck_clear),
                "pipe_contact": 1.0 if self.pipe_clear <= 0.0 else 0.0,
                "truck_contact": 1.0 if self.truck_clear <= 0.0 else 0.0,
                "bucket_fill": float(self.fill),
                "truck_soil": float(self.truck_soil),
                "spill": float(self.spill),
                "elapsed": float(self.elapsed),
            }
        )
        return info

    # ---------------------------------------------------------------- render
    def render(self):
        if self.render_mode is None:
            gym.logger.warn("render() called without render_mode; pass render_mode='rgb_array'")
            return None
        if self._renderer is None:
            from motiongym.envs.excavator.model import SceneRenderer

            self._renderer = SceneRenderer(self.m, self.render_size)
        return self._renderer.render(self)
