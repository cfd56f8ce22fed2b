"""The harvest-arm task: scenes (the fruit and the obstacles, sampled per reset) and
what the episode asks of the arm (:class:`HarvestArmTask`: reward terms, success,
cost, the observation).

The paper generates "8 random obstacles" in the plane and "10 random
obstacles, 3 in 10 bars" in space, and does not say where. Our scene
distribution (fixed for the ``-v0`` IDs), a canopy around the fruit:

* The fruit: uniform in a fruit box (planar x in [0.2, 0.8], y in
  [-0.6, -0.1]; spatial x in [0.4, 0.8], y in [-0.35, 0.35], z in
  [0.1, 0.45]), at least ``MIN_TRAVEL`` = 0.35 m from the start gripper,
  within ``MAX_REACH`` = 0.8 x 0.861 m of the base (planar) or shoulder
  (spatial), so that the arm keeps some redundancy at the fruit, and
  reachable: a damped least-squares IK within the joint limits brings the
  gripper within 2 mm of it.
* Obstacle centres: uniform within +-``CLUSTER`` = 0.3 m (per axis) of the
  fruit, inside the canopy box (planar x in [0.05, 0.85], y in [-0.6, 0.2];
  spatial x in [0.15, 0.85], y in [-0.4, 0.4], z in [0.05, 0.75]).
  Immature fruit: spheres (circles in the plane) of radius U(0.01, 0.02) m.
  Spatial scenes have exactly ``n_bars`` branches: capsules of radius
  0.008 m, length U(0.2, 0.5) m, direction uniform on the sphere. No bars in
  the plane (the paper's bars are a 3-D case).
* Rejection: an obstacle must keep ``START_CLEARANCE`` = 0.05 m from the
  arm's start pose and ``FRUIT_CLEARANCE`` = 0.06 m of surface clearance
  from the fruit sphere (radius ``FRUIT_RADIUS``), so that the gripper can
  reach the fruit's centre.

Everything is drawn from the ``rng`` passed in (the env's ``np_random``).
The start pose (reset option ``start``, default the arm's home pose) travels
with the scene.
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from gymnasium import spaces

from motiongym.envs.core import (
    START,
    ArgumentError,
    Deprecated,
    Outcome,
    check_float,
    check_shape,
    zero_terms,
)
from motiongym.envs.geometry import closest_point_on_segment, closest_points_between_segments
from motiongym.envs.harvest_arm.model import REACH, ArmKinematics
from motiongym.envs.harvest_arm.observation import (
    POSITION_BOUND,
    arm_bounds,
    layout_for,
    obstacle_width,
)
from motiongym.envs.harvest_arm.params import REWARD_TERMS, HarvestArmParams

if TYPE_CHECKING:
    from motiongym.envs.harvest_arm.world import ArmEvents, HarvestArmWorld

FRUIT_RADIUS = 0.035  # m
SPHERE_RADIUS = (0.01, 0.02)  # m, immature fruit
BAR_RADIUS = 0.008  # m, branches
BAR_LENGTH = (0.2, 0.5)  # m
START_CLEARANCE = 0.05  # m, obstacles vs the arm's start pose
FRUIT_CLEARANCE = 0.06  # m, obstacle surface vs fruit surface
MIN_TRAVEL = 0.35  # m, fruit vs start gripper
MAX_REACH = 0.8 * REACH  # m, fruit vs the arm's base (planar) or shoulder (spatial)
_BATCH = 32  # candidate obstacles drawn at once
CLUSTER = 0.3  # m, obstacle centres within +-CLUSTER of the fruit (per axis)

PLANAR_BOX = np.array([[0.05, -0.6], [0.85, 0.2]])  # (2, 2): low, high (m)
PLANAR_FRUIT_BOX = np.array([[0.2, -0.6], [0.8, -0.1]])
SPATIAL_BOX = np.array([[0.15, -0.4, 0.05], [0.85, 0.4, 0.75]])  # (2, 3)
SPATIAL_FRUIT_BOX = np.array([[0.4, -0.35, 0.1], [0.8, 0.35, 0.45]])


@dataclass
class Scene:
    """One scenario. Spheres have ``a == b``; bars are the segments ``ab``."""

    fruit: np.ndarray  # (dim,) m
    a: np.ndarray  # (K, dim) m
    b: np.ndarray  # (K, dim) m
    radius: np.ndarray  # (K,) m
    is_bar: np.ndarray  # (K,) bool
    start: np.ndarray | None = None  # (n,) rad, the start pose (None: the arm's home pose)

    def __len__(self) -> int:
        return len(self.radius)


def check_position(name: str, value: Any, dim: int) -> np.ndarray:
    """A finite point (dim,) within +-``POSITION_BOUND`` m (the observation's bounds)."""
    point = check_shape(name, value, (dim,))
    if np.abs(point).max() > POSITION_BOUND:
        raise ArgumentError(
            f"{name} must lie within +-{POSITION_BOUND} m on every axis, got {value!r}"
        )
    return point


def scene_from_obstacles(
    fruit: Any, obstacles: Any, dim: int, slots: tuple[int, int] | None = None
) -> Scene:
    """A scene from explicit obstacles ``{"center", "radius"}`` or ``{"a", "b", "radius"}``.

    Every coordinate finite and within +-2 m, every radius in (0, 0.2] m, at
    most ``slots`` = (spheres, bars), and no obstacle overlapping the fruit
    sphere: otherwise an :class:`ArgumentError` naming the obstacle.
    """
    fruit = check_position("options['fruit']", fruit, dim)
    if not isinstance(obstacles, (list, tuple)):
        raise ArgumentError(f"options['obstacles'] must be a list of dicts, got {obstacles!r}")
    a, b, r = [], [], []
    for i, ob in enumerate(obstacles):
        name = f"options['obstacles'][{i}]"
        keys = set(ob) if isinstance(ob, dict) else None
        if keys == {"center", "radius"}:
            a.append(check_position(f"{name}['center']", ob["center"], dim))
            b.append(a[-1])
        elif keys == {"a", "b", "radius"}:
            a.append(check_position(f"{name}['a']", ob["a"], dim))
            b.append(check_position(f"{name}['b']", ob["b"], dim))
        else:
            raise ArgumentError(
                f"{name} must be a dict with keys {{'center', 'radius'}} (sphere) or "
                f"{{'a', 'b', 'radius'}} (bar), got {ob!r}"
            )
        r.append(check_float(f"{name}['radius']", ob["radius"], 0.0, 0.2, low_open=True))
    is_bar = np.array(["a" in ob for ob in obstacles], bool)
    scene = Scene(
        fruit, np.array(a, float).reshape(-1, dim), np.array(b, float).reshape(-1, dim),
        np.array(r, float), is_bar,
    )  # fmt: skip
    n_bars = int(is_bar.sum())
    if slots is not None and (len(scene) - n_bars > slots[0] or n_bars > slots[1]):
        raise ArgumentError(
            f"options['obstacles'] must hold at most {slots[0]} spheres and {slots[1]} bars "
            f"(the env's slots), got {len(scene) - n_bars} spheres and {n_bars} bars"
        )
    if len(scene):
        gap = closest_point_on_segment(fruit, scene.a, scene.b)[0] - scene.radius - FRUIT_RADIUS
        if (gap < 0.0).any():
            i = int(np.argmin(gap))
            raise ArgumentError(
                f"options['obstacles'][{i}] must not overlap the fruit (radius {FRUIT_RADIUS} m), "
                f"got a surface gap of {gap[i]:.3f} m"
            )
    return scene


def solve_ik(
    kin: ArmKinematics, target: np.ndarray, q0: np.ndarray, iters: int = 150
) -> tuple[np.ndarray, float]:
    """Damped least-squares IK of the gripper position within joint limits.

    Returns:
        ``(q, error)``: the joint angles (n,) and the final gripper error (m).
    """
    q = np.array(q0, float)
    limits = kin.spec.limits
    err, best, stalled = np.inf, np.inf, 0
    for _ in range(iters):
        points, jac = kin.jacobians(q)
        e = target - points[-1]
        err = float(np.linalg.norm(e))
        if err < 5e-4:
            break
        stalled = stalled + 1 if err > 0.98 * best else 0
        best = min(best, err)
        if stalled >= 8:  # no progress: at a joint limit or out of reach
            break
        j = jac[-1]  # (dim, n)
        step = j.T @ np.linalg.solve(j @ j.T + 1e-3 * np.eye(len(e)), e)
        q = np.clip(q + np.clip(step, -0.3, 0.3), -limits, limits)
    return q, err


def clearance_to_arm(points: np.ndarray, link_radius: float, scene: Scene) -> np.ndarray:
    """Surface clearance of each obstacle to the arm given by its points: (K,)."""
    p0, p1 = points[:-1, None, :], points[1:, None, :]  # (L, 1, dim)
    if scene.is_bar.any():
        dist = closest_points_between_segments(p0, p1, scene.a[None], scene.b[None])[0]  # (L, K)
    else:  # spheres only: the cheaper point-segment distance
        dist = closest_point_on_segment(scene.a[None], p0, p1)[0]  # (L, K)
    return dist.min(axis=0) - link_radius - scene.radius


def _sample_fruit(rng: np.random.Generator, kin: ArmKinematics, start: np.ndarray) -> np.ndarray:
    """The first reachable fruit candidate in draw order, in batches (dim,)."""
    planar = kin.spec.planar
    fruit_box = PLANAR_FRUIT_BOX if planar else SPATIAL_FRUIT_BOX
    home = np.array(kin.spec.home)
    root = start[0] if planar else start[1]
    for _ in range(20):
        cand = rng.uniform(fruit_box[0], fruit_box[1], size=(_BATCH, kin.dim))
        ok = (np.linalg.norm(cand - start[-1], axis=1) >= MIN_TRAVEL) & (
            np.linalg.norm(cand - root, axis=1) <= MAX_REACH
        )
        for c in cand[ok]:
            if solve_ik(kin, c, home)[1] < 2e-3:
                return c
    raise RuntimeError("no reachable fruit found in 20 batches")  # pragma: no cover


def sample_scene(
    rng: np.random.Generator,
    kin: ArmKinematics,
    n_obstacles: int,
    n_bars: int,
    link_radius: float,
) -> Scene:
    """Sample a scene as documented in the module docstring."""
    planar = kin.spec.planar
    box = PLANAR_BOX if planar else SPATIAL_BOX
    dim = kin.dim
    start = kin.forward(np.array(kin.spec.home))  # (P, dim)
    fruit = _sample_fruit(rng, kin, start)
    low, high = np.maximum(box[0], fruit - CLUSTER), np.minimum(box[1], fruit + CLUSTER)
    parts = []
    for count, bars in ((n_obstacles - n_bars, False), (n_bars, True)):
        found: list[Scene] = []
        n_found = 0
        for _ in range(100):  # batches of candidates, the first valid ones kept in draw order
            if n_found >= count:
                break
            centre = rng.uniform(low, high, size=(_BATCH, dim))
            if bars:
                direction = rng.normal(size=(_BATCH, dim))
                direction /= np.linalg.norm(direction, axis=1, keepdims=True)
                half = 0.5 * rng.uniform(*BAR_LENGTH, size=(_BATCH, 1)) * direction
                cand = Scene(
                    fruit, centre - half, centre + half, np.full(_BATCH, BAR_RADIUS),
                    np.ones(_BATCH, bool),
                )  # fmt: skip
            else:
                r = rng.uniform(*SPHERE_RADIUS, size=_BATCH)
                cand = Scene(fruit, centre, centre.copy(), r, np.zeros(_BATCH, bool))
            fruit_gap = closest_point_on_segment(fruit, cand.a, cand.b)[0] - cand.radius
            ok = (clearance_to_arm(start, link_radius, cand) >= START_CLEARANCE) & (
                fruit_gap - FRUIT_RADIUS >= FRUIT_CLEARANCE
            )
            keep = np.flatnonzero(ok)[: count - n_found]
            found.append(
                Scene(fruit, cand.a[keep], cand.b[keep], cand.radius[keep], cand.is_bar[keep])
            )
            n_found += len(keep)
        else:  # pragma: no cover - the box is far larger than the exclusions
            raise RuntimeError("could not place the obstacles in 100 batches")
        parts.extend(found)
    a = np.concatenate([p.a for p in parts]).reshape(-1, dim)
    b = np.concatenate([p.b for p in parts]).reshape(-1, dim)
    radius = np.concatenate([p.radius for p in parts])
    is_bar = np.concatenate([p.is_bar for p in parts])
    return Scene(fruit, a, b, radius, is_bar)


# ---------------------------------------------------------------- the task


def _checked_in_sample(name: str, value: Any) -> Any:
    """The reset option ``obstacles``: checked with the fruit, in :meth:`HarvestArmTask.sample`."""
    return value


class HarvestArmTask:
    """Bring the gripper to the fruit, links clear of the obstacles (the env's docstring).

    Scenes come from :func:`sample_scene` (or the reset options ``fruit`` and
    ``obstacles``, :func:`scene_from_obstacles`), with the start pose
    ``start``. The observation is :func:`~.observation.layout_for`'s layout:
    the scene's part (fruit, obstacle slots, mask) is written at
    :meth:`begin`, the arm's part at every :meth:`observe`.
    """

    reward_terms: tuple[str, ...] = REWARD_TERMS
    deprecated_options: Mapping[str, Deprecated] = {"q": Deprecated(START)}

    def __init__(self, params: HarvestArmParams, kinematics: ArmKinematics) -> None:
        self.params = params
        self.kinematics = kinematics  # forward kinematics and IK of scene sampling
        arm = params.arm
        n, dim = arm.dof, arm.dim
        self.layout = layout_for(params)
        low, high = arm_bounds(self.layout, arm.speeds)
        self.observation_space: spaces.Space = spaces.Box(low, high, dtype=np.float32)
        self.options: Mapping[str, Callable[[str, Any], Any]] = {  # partials: the env pickles
            "fruit": functools.partial(check_position, dim=dim),
            "obstacles": _checked_in_sample,
            START: functools.partial(check_shape, shape=(n,)),
        }
        self._home = np.array(arm.home, float)
        self._slots = (params.n_obstacles - params.n_bars, params.n_bars)
        self._obs = np.zeros(self.layout.size, dtype=np.float32)
        s = self.layout.slices
        self._s_sin, self._s_cos, self._s_qdot = s["sin_q"], s["cos_q"], s["qdot"]
        self._s_points, self._s_dist = s["points"], s["distances"]
        self._s_fruit_error = s["fruit_error"]
        self._fruit = np.zeros(dim)
        self._d_fruit = self._min_so_far = 0.0

    # ------------------------------------------------------------ the episode
    def sample(self, rng: np.random.Generator, options: Mapping[str, Any]) -> Scene:
        """A scene from ``rng`` (or the explicit ``fruit`` and ``obstacles``) and the
        start pose (``start``, else the home pose)."""
        if ("fruit" in options) != ("obstacles" in options):
            raise ArgumentError("reset options 'fruit' and 'obstacles' must be given together")
        p = self.params
        if "fruit" in options:
            scene = scene_from_obstacles(
                options["fruit"], options["obstacles"], self.kinematics.dim, self._slots
            )
        else:
            scene = sample_scene(rng, self.kinematics, p.n_obstacles, p.n_bars, p.link_radius)
        scene.start = np.array(options.get(START, self._home), float)
        return scene

    def begin(self, world: HarvestArmWorld) -> Outcome:
        """Write the scene's part of the observation; the reset's outcome (terms 0)."""
        scene = world.scene
        assert scene is not None
        s = self.layout.slices
        rows = np.zeros((len(world.slots), obstacle_width(len(scene.fruit))))
        present = world.slots >= 0
        k = world.slots[present]
        rows[present] = np.concatenate(
            [scene.a[k], scene.b[k], scene.radius[k, None], scene.is_bar[k, None]], axis=1
        )
        self._obs[s["fruit"]] = scene.fruit
        self._obs[s["obstacles"]] = rows.ravel()
        self._obs[s["mask"]] = present
        self._fruit = scene.fruit.copy()
        self._d_fruit = self._distance_to_fruit(world)
        self._min_so_far = world.min_distance
        return self._outcome(world, zero_terms(self.reward_terms), False, False, False)

    def evaluate(self, world: HarvestArmWorld, events: ArmEvents) -> Outcome:
        """The six reward terms of the step, success, cost and the measures."""
        d_fruit = self._distance_to_fruit(world)
        min_d = world.min_distance
        if min_d < self._min_so_far:
            self._min_so_far = min_d
        collided = events.collided
        p = self.params
        arrived = d_fruit <= p.success_tolerance
        a = events.action
        terms = {  # weights are magnitudes: costs subtracted
            "progress": p.progress * (self._d_fruit - d_fruit),
            "clearance": -p.clearance * max(0.0, 1.0 - min_d / p.safety_distance),
            "collision": -p.collision * float(collided),
            "effort": -p.effort * float(np.dot(a, a)) / len(a),
            "success": p.success * float(arrived),
            "distance": -p.distance * d_fruit,
        }
        self._d_fruit = d_fruit
        terminated = bool(arrived or (collided and p.terminate_on_collision))
        return self._outcome(world, terms, arrived, collided, terminated)

    def _outcome(
        self,
        world: HarvestArmWorld,
        terms: dict[str, float],
        arrived: bool,
        collided: bool,
        terminated: bool,
    ) -> Outcome:
        min_d = world.min_distance
        close = min_d < self.params.safety_distance
        measures: dict[str, Any] = {
            "distance_to_fruit": self._d_fruit,
            "min_distance": min_d,
            "min_distance_so_far": self._min_so_far,
            "close_approach": bool(close),
            "collision": bool(collided),
        }
        if self.params.self_collision:
            measures["self_distance"] = world.self_distance
            measures["self_collision"] = bool(world.self_distance <= 0.0)
        return Outcome(terms, arrived, 1.0 if close or collided else 0.0, measures, terminated)

    def _distance_to_fruit(self, world: HarvestArmWorld) -> float:
        g = world.points[-1] - self._fruit
        return float(np.sqrt(g @ g))

    # ------------------------------------------------------------ the observation
    def observe(self, world: HarvestArmWorld) -> np.ndarray:
        """The observation (a fresh float32 array): the scene's part from :meth:`begin`,
        the arm's from the world now."""
        obs, q = self._obs, world.q
        obs[self._s_sin] = np.sin(q)
        obs[self._s_cos] = np.cos(q)
        obs[self._s_qdot] = world.qdot
        points = world.points
        obs[self._s_points] = points.ravel()
        obs[self._s_fruit_error] = self._fruit - points[-1]
        obs[self._s_dist] = world.clearances
        return obs.copy()
