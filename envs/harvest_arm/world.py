"""The harvest arm's world: the MuJoCo model, its pose, its distances and its frames.

The only module of the harvest arm that moves state or talks to MuJoCo at run
time. The arm is kinematic: an action (joint rates as fractions of the speed
limits) is integrated over the control period, the pose is clipped to the
joint ranges, ``mj_kinematics`` places the bodies and ``mj_collision`` on
explicit pairs gives every link-obstacle (and, with ``self_collision``,
every link-link) signed distance, exact for spheres and capsules (see
:func:`motiongym.envs.harvest_arm.model.build_model`).
"""

from __future__ import annotations

from typing import NamedTuple

import mujoco
import numpy as np
from gymnasium import spaces

from motiongym.envs.harvest_arm.model import ArmKinematics, build_model
from motiongym.envs.harvest_arm.observation import DISTANCE_CLIP
from motiongym.envs.harvest_arm.params import HarvestArmParams
from motiongym.envs.harvest_arm.task import FRUIT_RADIUS, Scene
from motiongym.envs.rendering import OwnsRenderer

_FAR = (0.0, 0.0, -100.0)  # m, where empty obstacle slots wait (beyond every pair's margin)
_PATH_RGBA = np.array([0.9, 0.5, 0.1, 1.0], dtype=np.float32)  # the gripper's drawn path


class ArmEvents(NamedTuple):
    """What happened in one control step."""

    action: np.ndarray  # (n,) the action applied, clipped to [-1, 1]
    collided: bool  # a link touched an obstacle, or (self_collision) two non-adjacent links
    self_collided: bool  # two non-adjacent links touched (always False without self_collision)


class HarvestArmWorld(OwnsRenderer):
    """State (pose, scene) and distances of one arm among its obstacle slots.

    State: ``q`` (n,) joint angles (rad), ``qdot`` (n,) the rates applied last
    step (rad/s), ``scene`` and ``slots`` (K,) the scene's obstacle in each
    slot (spheres first, then bars; -1 empty). After every pose: ``points``
    (P, dim) joint points base to gripper (m), ``clearances`` (L * K,)
    link-obstacle surface distances clipped at 1 m (link-major),
    ``min_distance`` their minimum and ``self_distance`` the smallest
    link-link surface distance of non-adjacent links (1 m without
    ``self_collision``). With ``record_path`` the gripper's positions are
    kept in ``path`` (3-D, for the rendered trail); otherwise only the start.
    """

    def __init__(self, params: HarvestArmParams, record_path: bool = False) -> None:
        self.params = params
        self.arm = params.arm
        self.dim = self.arm.dim
        n = self.arm.dof
        self.action_space: spaces.Space = spaces.Box(-1.0, 1.0, (n,), dtype=np.float32)
        self.record_path = record_path
        self._limits = self.arm.limits  # rad
        self._step_size = self.arm.speeds * params.dt  # rad per unit action
        self._dt = params.dt
        self.q = np.zeros(n)
        self.qdot = np.zeros(n)
        self.path: list[np.ndarray] = []
        self.slots = np.full(params.n_obstacles, -1, dtype=np.int64)
        n_spheres = params.n_obstacles - params.n_bars
        self.model, self.index = build_model(
            self.arm, params.link_radius, n_spheres, params.n_bars, params.dt,
            self_pairs=params.self_collision,
        )  # fmt: skip
        self.data = mujoco.MjData(self.model)
        self.kinematics = ArmKinematics(self.arm, params.link_radius, params.dt)
        self.n_points = len(self.index["point_sites"])
        # contact (geom1, geom2) -> slot: the (L, K) clearances link-major, then the self pairs
        links, obstacles = self.index["link_geoms"], self.index["obstacle_geoms"]
        self._pair_slot = np.zeros((self.model.ngeom, self.model.ngeom), dtype=np.int64)
        for li, lg in enumerate(links):
            for k, og in enumerate(obstacles):
                self._pair_slot[lg, og] = self._pair_slot[og, lg] = li * params.n_obstacles + k
        self._n_lk = len(links) * params.n_obstacles
        for s, (i, j) in enumerate(self.index["self_pairs"]):
            gi, gj = links[i], links[j]
            self._pair_slot[gi, gj] = self._pair_slot[gj, gi] = self._n_lk + s
        self._n_self = len(self.index["self_pairs"])
        self._clear = np.full(self._n_lk + self._n_self, DISTANCE_CLIP)  # (L*K + S,)
        self.min_distance = self.self_distance = DISTANCE_CLIP
        self.points = np.zeros((self.n_points, self.dim))
        self.scene: Scene | None = None
        self._n_pairs = 0
        self._contact_slots: np.ndarray | None = None
        self._render_size: tuple[int, int] | None = None

    @property
    def clearances(self) -> np.ndarray:
        """Link-obstacle surface distances (L * K,), link-major, clipped at 1 m (a view)."""
        return self._clear[: self._n_lk]

    # ------------------------------------------------------------ the contract
    def reset(self, scene: Scene, rng: np.random.Generator | None = None) -> None:
        """Put ``scene`` in place and the arm at its start pose (clipped to the ranges)."""
        self.set_scene(scene)
        start = np.array(self.arm.home, float) if scene.start is None else scene.start
        self.q = np.clip(start, -self._limits, self._limits)
        self.qdot = np.zeros(self.arm.dof)
        self.pose(self.q)
        self.path = [self.gripper_3d()]

    def advance(self, action: np.ndarray) -> ArmEvents:
        """One control step: clip ``action`` (n,) to [-1, 1], integrate
        ``q += action * speeds * dt``, clip to the joint ranges, pose."""
        a = np.minimum(np.maximum(action, -1.0), 1.0)
        q_old = self.q
        q = q_old + a * self._step_size  # rad
        self.q = np.minimum(np.maximum(q, -self._limits), self._limits)
        self.qdot = (self.q - q_old) / self._dt
        self.pose(self.q)
        if self.record_path:
            self.path.append(self.gripper_3d())
        self_collided = self.self_distance <= 0.0
        return ArmEvents(a, self.min_distance <= 0.0 or self_collided, self_collided)

    # ------------------------------------------------------------ scene and pose
    def set_scene(self, scene: Scene) -> None:
        """Move the obstacle slots (spheres first, then bars; ``slots``) and the fruit."""
        m, dim, p = self.model, self.dim, self.params
        n_sphere_slots = p.n_obstacles - p.n_bars
        order = np.concatenate([np.flatnonzero(~scene.is_bar), np.flatnonzero(scene.is_bar)])
        sphere_ids = list(range(int((~scene.is_bar).sum())))
        bar_ids = list(range(n_sphere_slots, n_sphere_slots + int(scene.is_bar.sum())))
        placed = dict(zip(sphere_ids + bar_ids, order, strict=True))
        self.slots = np.full(p.n_obstacles, -1, dtype=np.int64)
        for slot, g in enumerate(self.index["obstacle_geoms"]):
            if slot not in placed:
                m.geom_pos[g] = _FAR
                continue
            k = placed[slot]
            self._place(g, scene.a[k], scene.b[k], scene.radius[k], bool(scene.is_bar[k]))
            self.slots[slot] = k
        fruit3 = np.zeros(3)
        fruit3[:dim] = scene.fruit
        m.geom_pos[self.index["fruit_geom"][0]] = fruit3
        m.geom_size[self.index["fruit_geom"][0]] = (FRUIT_RADIUS, 0.0, 0.0)
        self.scene = scene
        self._n_pairs = len(self.index["link_geoms"]) * len(scene) + self._n_self
        self._contact_slots = None  # contact order -> clearance slot, learnt at the first pose

    def _place(self, g: int, a: np.ndarray, b: np.ndarray, r: float, bar: bool) -> None:
        m = self.model
        a3, b3 = np.zeros(3), np.zeros(3)
        a3[: self.dim], b3[: self.dim] = a, b
        m.geom_pos[g] = 0.5 * (a3 + b3)
        if bar:
            half = 0.5 * np.linalg.norm(b3 - a3)
            m.geom_size[g] = (r, max(half, 1e-6), 0.0)
            quat = np.zeros(4)
            mujoco.mju_quatZ2Vec(quat, b3 - a3)
            m.geom_quat[g] = quat
            m.geom_rbound[g] = r + half
        else:
            m.geom_size[g] = (r, 0.0, 0.0)
            m.geom_rbound[g] = r

    def pose(self, q: np.ndarray) -> None:
        """Set the joint angles ``q`` (n,); update points and distances."""
        d = self.data
        d.qpos[:] = q
        mujoco.mj_kinematics(self.model, d)
        mujoco.mj_collision(self.model, d)
        clear = self._clear
        clear.fill(DISTANCE_CLIP)
        if d.ncon == self._n_pairs and self._contact_slots is not None:
            # one contact per pair, in the model's pair order (the explicit pairs are
            # the only collision source and every present pair is within the margin)
            clear[self._contact_slots] = np.minimum(d.contact.dist, DISTANCE_CLIP)
        elif d.ncon:
            geom, dist = d.contact.geom, d.contact.dist  # (ncon, 2), (ncon,)
            slots = self._pair_slot[geom[:, 0], geom[:, 1]]
            if d.ncon == self._n_pairs:
                self._contact_slots = slots
                clear[slots] = np.minimum(dist, DISTANCE_CLIP)
            else:  # a pair with two contacts (parallel capsules): keep the smaller
                np.minimum.at(clear, slots, dist)
        if self._n_self:
            self.min_distance = float(clear[: self._n_lk].min())
            self.self_distance = float(clear[self._n_lk :].min())
        else:
            self.min_distance = float(clear.min())
        self.points = d.site_xpos[self.index["point_sites"], : self.dim]

    # ------------------------------------------------------------ rendering
    def render(self, size: tuple[int, int]) -> np.ndarray:
        """One frame (rows, columns, 3) uint8: the arm, the scene and the gripper's path.

        The renderer is made at the first frame (and again for another size);
        the model's offscreen buffer is enlarged to ``size`` where it is smaller.
        """
        renderer = self._renderer_for(size)
        camera = mujoco.MjvCamera()
        if self.arm.planar:
            camera.lookat[:] = (0.35, -0.15, 0.0)
            camera.distance, camera.azimuth, camera.elevation = 1.7, 90.0, -90.0
        else:
            camera.lookat[:] = (0.35, 0.0, 0.35)
            camera.distance, camera.azimuth, camera.elevation = 1.15, 210.0, -25.0
        renderer.update_scene(self.data, camera=camera)
        scene = renderer.scene
        path = self.path
        for p0, p1 in zip(path[:-1], path[1:], strict=False):
            if scene.ngeom >= scene.maxgeom:
                break
            geom = scene.geoms[scene.ngeom]
            mujoco.mjv_initGeom(
                geom,
                mujoco.mjtGeom.mjGEOM_LINE,
                np.zeros(3),
                np.zeros(3),
                np.eye(3).ravel(),
                _PATH_RGBA,
            )
            mujoco.mjv_connector(geom, mujoco.mjtGeom.mjGEOM_CAPSULE, 0.004, p0, p1)
            scene.ngeom += 1
        return renderer.render()

    def _renderer_for(self, size: tuple[int, int]) -> mujoco.Renderer:
        rows, columns = size
        if self._renderer is not None and self._render_size == (rows, columns):
            return self._renderer
        self.close()
        buffer = self.model.vis.global_
        buffer.offwidth = max(buffer.offwidth, columns)
        buffer.offheight = max(buffer.offheight, rows)
        self._renderer = mujoco.Renderer(self.model, rows, columns)
        self._render_size = (rows, columns)
        return self._renderer

    def gripper_3d(self) -> np.ndarray:
        """The gripper's position in 3-D (for the rendered path)."""
        return self.data.site_xpos[self.index["point_sites"][-1]].copy()
