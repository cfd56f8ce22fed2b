"""The harvest-arm environment: a redundant arm reaching a fruit among obstacles."""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import mujoco
import numpy as np
from gymnasium import spaces

from motiongym.envs.actions import checked_box_action
from motiongym.envs.core import check_bool
from motiongym.envs.harvest_arm.model import ArmKinematics, arm_spec, build_model
from motiongym.envs.harvest_arm.observation import DISTANCE_CLIP, ObservationLayout
from motiongym.envs.harvest_arm.task import (
    FRUIT_RADIUS,
    Scene,
    sample_scene,
    scene_from_obstacles,
)
from motiongym.envs.rendering import OwnsRenderer

_RESET_OPTIONS = ("fruit", "obstacles", "q")


class HarvestArmEnv(OwnsRenderer, gym.Env):
    """Bring a redundant arm's gripper to a fruit while its links keep clear.

    The arm of Ryu et al. (fruit-harvesting redundant robot) among immature
    fruit (spheres) and branches (bars). The arm is kinematic: joint velocity
    commands are integrated over the control period ``dt`` (no dynamics), the
    pose is evaluated with ``mj_kinematics`` and every link-obstacle clearance
    with ``mj_collision`` on explicit pairs (exact for spheres and capsules).
    Arms, ranges and speeds: :mod:`motiongym.envs.harvest_arm.model`; scenes:
    :mod:`motiongym.envs.harvest_arm.task`.

    Variants: ``planar=False`` with ``dof`` 5 (CRS A465 with the added wrist
    link), 6, 7 (default) and 10 obstacles of which 3 bars; ``planar=True``
    with ``dof`` 3, 4, 5 (default) and 8 spherical obstacles (coordinates x,
    y). Links are capsules of radius ``link_radius``; the control period is
    ``dt`` (registered IDs: 300 steps, 15 s).

    Action (Box(-1, 1, (n,))): joint ``j``'s velocity as a fraction of its
    speed limit (rad/s); the pose is clipped to the joint ranges.

    Observation (Box float32, ``dim`` = 2 planar or 3 spatial, ``P`` joint
    points base to gripper, ``L = P - 1`` links, ``K`` obstacle slots; the
    slices are named by :class:`ObservationLayout`):

    | slice | meaning | unit | frame |
    |---|---|---|---|
    | sin_q (n), cos_q (n) | joint angles | - | joint |
    | qdot (n) | joint rates applied last step | rad/s | joint |
    | points (P * dim) | joint points, base first, gripper last | m | world |
    | fruit (dim) | fruit centre | m | world |
    | fruit_error (dim) | fruit centre - gripper (as Reacher's fingertip - target) | m | world |
    | obstacles (K * (2 dim + 2)) | per slot: ends a, b (b = a: sphere), radius, is_bar | m | - |
    | mask (K) | 1 for a present obstacle | - | - |
    | distances (L * K) | clearance link l to obstacle k, clipped at 1 m (1 m if absent) | m | - |

    Reward, the sum of the terms (weights are keyword arguments of the same
    name): ``progress`` * decrease of the gripper-fruit distance (m);
    ``- clearance`` * max(0, 1 - d_min / safety_distance); ``- collision`` on
    contact (d_min <= 0); ``- effort`` * mean(action^2); ``success`` on arrival;
    ``- distance`` * gripper-fruit distance (m) every step, 0 in the registered
    IDs: a dense shaping that training configurations switch on (the progress
    term telescopes, so a policy parked 0.5 m short loses only 5 in all). Being
    negative, it makes ending an episode on an obstacle cheaper than a long
    miss; ``terminate_on_collision=False`` removes that way out (the configs
    record how each choice trained).

    Termination: the gripper within ``success_tolerance`` of the fruit centre,
    or a collision (if ``terminate_on_collision``). Truncation: the
    ``max_episode_steps`` of the registration (TimeLimit).

    ``info``: ``distance_to_fruit`` (m), ``min_distance`` (smallest
    link-obstacle clearance this step, m), ``min_distance_so_far`` (m),
    ``close_approach`` (d_min < safety_distance), ``collision`` (d_min <= 0,
    or with ``self_collision`` two non-adjacent links touching), ``cost``
    (1.0 on a close approach or a collision), ``is_success``,
    ``reward_<term>``; with ``self_collision`` also ``self_distance`` (m,
    smallest surface distance between two links that share no joint point,
    clipped at 1 m) and ``self_collision`` (it is <= 0).

    Reset options: ``fruit`` (dim,) and ``obstacles`` (list of
    ``{"center", "radius"}`` or ``{"a", "b", "radius"}``) together give an
    explicit scene; ``q`` (n,) a start pose (default the arm's home pose).

    Version history:

    * v1: ``self_collision=True``: two non-adjacent links touching is a
      collision (``info["collision"]``, the cost, the collision reward term and,
      with ``terminate_on_collision``, termination), measured by MuJoCo on
      explicit link-link pairs. Observation and scenes as v0.
    * v0 (initial): only link-obstacle contact is a collision.
    """

    metadata = {
        "render_modes": ["rgb_array"],
        "render_fps": 20,
        "info_measures": {
            "is_success": "last",
            "cost": "sum",
            "collision": "max",
            "close_approach": "max",
            "min_distance": "min",
            "distance_to_fruit": "last",
        },
    }

    def __init__(
        self,
        dof: int | None = None,  # default 5 planar, 7 spatial
        planar: bool = False,
        n_obstacles: int | None = None,  # default 8 planar, 10 spatial
        n_bars: int | None = None,  # default 0 planar, 3 spatial
        link_radius: float = 0.02,  # m
        dt: float = 0.05,  # s, control period
        safety_distance: float = 0.03,  # m, the paper's collision-risk distance
        success_tolerance: float = 0.02,  # m, gripper to fruit centre
        terminate_on_collision: bool = True,
        self_collision: bool = False,
        progress: float = 10.0,
        clearance: float = 1.0,
        collision: float = 10.0,
        effort: float = 0.01,
        success: float = 10.0,
        distance: float = 0.0,
        render_mode: str | None = None,
        width: int = 480,
        height: int = 360,
    ) -> None:
        dof = (5 if planar else 7) if dof is None else int(dof)
        self.spec_arm = arm_spec(dof, bool(planar))
        n_obstacles = (8 if planar else 10) if n_obstacles is None else int(n_obstacles)
        n_bars = (0 if planar else 3) if n_bars is None else int(n_bars)
        if not 0 <= n_bars <= n_obstacles:
            raise ValueError(f"n_bars must be in [0, n_obstacles={n_obstacles}], got {n_bars}")
        if render_mode not in (None, *self.metadata["render_modes"]):
            raise ValueError(f"render_mode must be None or 'rgb_array', got {render_mode!r}")
        self.n_obstacles, self.n_bars = n_obstacles, n_bars
        self.link_radius, self.dt = float(link_radius), float(dt)
        self.safety_distance = float(safety_distance)
        self.success_tolerance = float(success_tolerance)
        self.terminate_on_collision = bool(terminate_on_collision)
        self.weights = {
            "progress": progress,
            "clearance": clearance,
            "collision": collision,
            "effort": effort,
            "success": success,
            "distance": distance,
        }
        self.render_mode, self.width, self.height = render_mode, width, height

        self.self_collision = check_bool("self_collision", self_collision)
        self.model, self.index = build_model(
            self.spec_arm,
            self.link_radius,
            n_obstacles - n_bars,
            n_bars,
            self.dt,
            self_pairs=self.self_collision,
        )
        self.data = mujoco.MjData(self.model)
        self.kinematics = ArmKinematics(self.spec_arm, self.link_radius, self.dt)
        n, self.dim = self.spec_arm.dof, self.spec_arm.dim
        self.layout = ObservationLayout(n, self.dim, len(self.index["point_sites"]), n_obstacles)
        self._slices = self.layout.slices
        self._limits = self.spec_arm.limits
        self._low = -self._limits
        self._speeds = self.spec_arm.speeds
        self._step_size = self._speeds * self.dt  # rad per unit action
        low, high = self.layout.bounds(self._speeds)
        self.observation_space = spaces.Box(low, high, dtype=np.float32)
        self.action_space = spaces.Box(-1.0, 1.0, (n,), dtype=np.float32)
        self._action_shape = (n,)
        # contact (geom1, geom2) -> flat index into the (L, K) clearance matrix, then
        # the self pairs
        links, obstacles = self.index["link_geoms"], self.index["obstacle_geoms"]
        self._pair_slot = np.zeros((self.model.ngeom, self.model.ngeom), dtype=np.int64)
        for li, lg in enumerate(links):
            for k, og in enumerate(obstacles):
                self._pair_slot[lg, og] = self._pair_slot[og, lg] = li * n_obstacles + k
        self._n_lk = len(links) * n_obstacles
        for s_, (i, j) in enumerate(self.index["self_pairs"]):
            gi, gj = links[i], links[j]
            self._pair_slot[gi, gj] = self._pair_slot[gj, gi] = self._n_lk + s_
        self._n_self = len(self.index["self_pairs"])
        self._clear = np.full(self._n_lk + self._n_self, DISTANCE_CLIP)  # (L*K + S,)
        self._self_d = DISTANCE_CLIP
        self._obs = np.zeros(self.layout.size, dtype=np.float32)
        self._sites = self.index["point_sites"]
        self._s_sin, self._s_cos = self._slices["sin_q"], self._slices["cos_q"]
        self._s_qdot, self._s_points = self._slices["qdot"], self._slices["points"]
        self._s_dist = self._slices["distances"]
        self._s_fruit_error = self._slices["fruit_error"]
        self._q = np.zeros(n)
        self._renderer: mujoco.Renderer | None = None
        self._path: list[np.ndarray] = []
        self.scene: Scene | None = None

    # ------------------------------------------------------------------ reset
    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        super().reset(seed=seed)
        options = dict(options or {})
        unknown = set(options) - set(_RESET_OPTIONS)
        if unknown:
            raise ValueError(f"unknown reset options {sorted(unknown)}; valid: {_RESET_OPTIONS}")
        if ("fruit" in options) != ("obstacles" in options):
            raise ValueError("reset options 'fruit' and 'obstacles' must be given together")
        if "fruit" in options:
            scene = scene_from_obstacles(options["fruit"], options["obstacles"], self.dim)
            n_bar = int(scene.is_bar.sum())
            if n_bar > self.n_bars or len(scene) - n_bar > self.n_obstacles - self.n_bars:
                raise ValueError(
                    f"explicit scene has {len(scene) - n_bar} spheres and {n_bar} bars; this env "
                    f"has {self.n_obstacles - self.n_bars} sphere and {self.n_bars} bar slots"
                )
        else:
            scene = sample_scene(
                self.np_random, self.kinematics, self.n_obstacles, self.n_bars, self.link_radius
            )
        q = np.array(options.get("q", self.spec_arm.home), float).reshape(-1)
        if q.shape != (self.spec_arm.dof,):
            raise ValueError(f"option 'q' must have shape ({self.spec_arm.dof},), got {q.shape}")
        self._set_scene(scene)
        self._q = np.clip(q, -self._limits, self._limits)
        self._update(np.zeros(self.spec_arm.dof))
        self._d_fruit = self._distance_to_fruit()
        self._min_so_far = self._min_d
        self._path = [self.data.site_xpos[self.index["point_sites"][-1]].copy()]
        info = self._info(False, False, {k: 0.0 for k in self.weights})
        return self._obs.copy(), info

    def _set_scene(self, scene: Scene) -> None:
        """Move the obstacle slots (spheres first, then bars) and the fruit."""
        m, dim, slots = self.model, self.dim, self.index["obstacle_geoms"]
        n_sphere_slots = self.n_obstacles - self.n_bars
        order = np.concatenate([np.flatnonzero(~scene.is_bar), np.flatnonzero(scene.is_bar)])
        sphere_ids = list(range(int((~scene.is_bar).sum())))
        bar_ids = list(range(n_sphere_slots, n_sphere_slots + int(scene.is_bar.sum())))
        placed = dict(zip(sphere_ids + bar_ids, order, strict=True))
        obstacles = np.zeros((self.n_obstacles, self.layout.obstacle_width))
        mask = np.zeros(self.n_obstacles)
        for slot, g in enumerate(slots):
            if slot not in placed:
                m.geom_pos[g] = (0.0, 0.0, -100.0)
                continue
            k = placed[slot]
            a3, b3 = np.zeros(3), np.zeros(3)
            a3[:dim], b3[:dim] = scene.a[k], scene.b[k]
            r = scene.radius[k]
            m.geom_pos[g] = 0.5 * (a3 + b3)
            if scene.is_bar[k]:
                half = 0.5 * np.linalg.norm(b3 - a3)
                m.geom_size[g] = (r, max(half, 1e-6), 0.0)
                quat = np.zeros(4)
                mujoco.mju_quatZ2Vec(quat, b3 - a3)
                m.geom_quat[g] = quat
                m.geom_rbound[g] = r + half
            else:
                m.geom_size[g] = (r, 0.0, 0.0)
                m.geom_rbound[g] = r
            obstacles[slot] = [*scene.a[k], *scene.b[k], r, float(scene.is_bar[k])]
            mask[slot] = 1.0
        fruit3 = np.zeros(3)
        fruit3[:dim] = scene.fruit
        m.geom_pos[self.index["fruit_geom"][0]] = fruit3
        m.geom_size[self.index["fruit_geom"][0]] = (FRUIT_RADIUS, 0.0, 0.0)
        self.scene = scene
        self._n_pairs = len(self.index["link_geoms"]) * len(scene) + self._n_self
        self._slots: np.ndarray | None = None  # contact order -> clearance slot, set once
        s = self._slices
        self._obs[s["fruit"]] = scene.fruit
        self._obs[s["obstacles"]] = obstacles.ravel()
        self._obs[s["mask"]] = mask
        self._fruit = scene.fruit.copy()

    # ------------------------------------------------------------------- step
    def step(self, action: np.ndarray) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        a = checked_box_action(action, self._action_shape, "one rate per joint")
        if self.scene is None:
            raise RuntimeError("call reset() before step()")
        a = np.minimum(np.maximum(a, -1.0), 1.0)
        q_old = self._q
        q = q_old + a * self._step_size  # rad
        self._q = np.minimum(np.maximum(q, self._low), self._limits)
        self._update((self._q - q_old) / self.dt)
        d_fruit = self._distance_to_fruit()
        min_d = self._min_d
        self._min_so_far = min(self._min_so_far, min_d)
        collided = min_d <= 0.0 or self._self_d <= 0.0
        arrived = d_fruit <= self.success_tolerance
        w = self.weights
        terms = {
            "progress": w["progress"] * (self._d_fruit - d_fruit),
            "clearance": -w["clearance"] * max(0.0, 1.0 - min_d / self.safety_distance),
            "collision": -w["collision"] * float(collided),
            "effort": -w["effort"] * float(np.dot(a, a)) / len(a),
            "success": w["success"] * float(arrived),
            "distance": -w["distance"] * d_fruit,
        }
        self._d_fruit = d_fruit
        if self.render_mode is not None:
            self._path.append(self.data.site_xpos[self.index["point_sites"][-1]].copy())
        terminated = bool(arrived or (collided and self.terminate_on_collision))
        info = self._info(arrived, collided, terms)
        return self._obs.copy(), float(sum(terms.values())), terminated, False, info

    def _update(self, qdot: np.ndarray) -> None:
        """Pose, clearances and the per-step part of the observation."""
        d, obs, q = self.data, self._obs, self._q
        d.qpos[:] = q
        mujoco.mj_kinematics(self.model, d)
        mujoco.mj_collision(self.model, d)
        clear = self._clear
        clear.fill(DISTANCE_CLIP)
        if d.ncon == self._n_pairs and self._slots is not None:
            # one contact per pair, in the model's pair order (the explicit pairs are
            # the only collision source and every present pair is within the margin)
            clear[self._slots] = np.minimum(d.contact.dist, DISTANCE_CLIP)
        elif d.ncon:
            geom, dist = d.contact.geom, d.contact.dist  # (ncon, 2), (ncon,)
            slots = self._pair_slot[geom[:, 0], geom[:, 1]]
            if d.ncon == self._n_pairs:
                self._slots = slots
                clear[slots] = np.minimum(dist, DISTANCE_CLIP)
            else:  # a pair with two contacts (parallel capsules): keep the smaller
                np.minimum.at(clear, slots, dist)
        if self._n_self:
            self._min_d = float(clear[: self._n_lk].min())
            self._self_d = float(clear[self._n_lk :].min())
        else:
            self._min_d = float(clear.min())
        obs[self._s_sin] = np.sin(q)
        obs[self._s_cos] = np.cos(q)
        obs[self._s_qdot] = qdot
        points = d.site_xpos[self._sites, : self.dim]
        obs[self._s_points] = points.ravel()
        obs[self._s_fruit_error] = self._fruit - points[-1]
        obs[self._s_dist] = clear[: self._n_lk]
        self._gripper = points[-1]

    def _distance_to_fruit(self) -> float:
        g = self._gripper - self._fruit
        return float(np.sqrt(g @ g))

    def _info(self, arrived: bool, collided: bool, terms: dict[str, float]) -> dict[str, Any]:
        close = self._min_d < self.safety_distance
        info = {
            "distance_to_fruit": self._d_fruit,
            "min_distance": self._min_d,
            "min_distance_so_far": self._min_so_far,
            "close_approach": bool(close),
            "collision": bool(collided),
            "cost": 1.0 if close or collided else 0.0,
            "is_success": bool(arrived),
        }
        if self._n_self:
            info["self_distance"] = self._self_d
            info["self_collision"] = bool(self._self_d <= 0.0)
        for key, value in terms.items():
            info[f"reward_{key}"] = float(value)
        return info

    # ----------------------------------------------------------------- render
    def render(self) -> np.ndarray | None:
        if self.render_mode != "rgb_array":
            return None
        if self._renderer is None:
            self._renderer = mujoco.Renderer(self.model, self.height, self.width)
        camera = mujoco.MjvCamera()
        if self.spec_arm.planar:
            camera.lookat[:] = (0.35, -0.15, 0.0)
            camera.distance, camera.azimuth, camera.elevation = 1.7, 90.0, -90.0
        else:
            camera.lookat[:] = (0.35, 0.0, 0.4)
            camera.distance, camera.azimuth, camera.elevation = 1.7, 200.0, -20.0
        self._renderer.update_scene(self.data, camera=camera)
        scene = self._renderer.scene
        for p0, p1 in zip(self._path[:-1], self._path[1:], strict=False):
            if scene.ngeom >= scene.maxgeom:
                break
            geom = scene.geoms[scene.ngeom]
            mujoco.mjv_initGeom(
                geom,
                mujoco.mjtGeom.mjGEOM_LINE,
                np.zeros(3),
                np.zeros(3),
                np.eye(3).ravel(),
                np.array([0.9, 0.5, 0.1, 1.0], dtype=np.float32),
            )
            mujoco.mjv_connector(geom, mujoco.mjtGeom.mjGEOM_CAPSULE, 0.004, p0, p1)
            scene.ngeom += 1
        return self._renderer.render()
