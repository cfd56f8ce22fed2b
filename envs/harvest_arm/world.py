"""The harvest arm's world: the MuJoCo model, its pose and its distances.

The only module of the harvest arm that talks to MuJoCo at run time. The arm
is kinematic: a pose is set, ``mj_kinematics`` places the bodies and
``mj_collision`` on explicit pairs gives every link-obstacle (and, with
``self_collision``, every link-link) signed distance, exact for spheres and
capsules (see :func:`motiongym.envs.harvest_arm.model.build_model`).
"""

from __future__ import annotations

import mujoco
import numpy as np

from motiongym.envs.harvest_arm.model import ArmKinematics, build_model
from motiongym.envs.harvest_arm.observation import DISTANCE_CLIP
from motiongym.envs.harvest_arm.params import HarvestArmParams
from motiongym.envs.harvest_arm.task import FRUIT_RADIUS, Scene

_FAR = (0.0, 0.0, -100.0)  # m, where empty obstacle slots wait (beyond every pair's margin)


class HarvestArmWorld:
    """State (pose, scene) and distances of one arm among its obstacle slots.

    After :meth:`pose`: ``points`` (P, dim) joint points base to gripper,
    ``clearances`` (L * K,) link-obstacle surface distances clipped at 1 m
    (link-major), ``min_distance`` their minimum and ``self_distance`` the
    smallest link-link surface distance of non-adjacent links (1 m without
    ``self_collision``).
    """

    def __init__(self, params: HarvestArmParams) -> None:
        self.params = params
        self.arm = params.arm
        self.dim = self.arm.dim
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
        self._slots: np.ndarray | None = None

    @property
    def clearances(self) -> np.ndarray:
        """Link-obstacle surface distances (L * K,), link-major, clipped at 1 m (a view)."""
        return self._clear[: self._n_lk]

    def set_scene(self, scene: Scene, width: int) -> tuple[np.ndarray, np.ndarray]:
        """Move the obstacle slots (spheres first, then bars) and the fruit.

        Returns the observation's per-slot rows (K, ``width``: a, b, radius,
        is_bar) and the slots' mask (K,).
        """
        m, dim, p = self.model, self.dim, self.params
        n_sphere_slots = p.n_obstacles - p.n_bars
        order = np.concatenate([np.flatnonzero(~scene.is_bar), np.flatnonzero(scene.is_bar)])
        sphere_ids = list(range(int((~scene.is_bar).sum())))
        bar_ids = list(range(n_sphere_slots, n_sphere_slots + int(scene.is_bar.sum())))
        placed = dict(zip(sphere_ids + bar_ids, order, strict=True))
        rows, mask = np.zeros((p.n_obstacles, width)), np.zeros(p.n_obstacles)
        for slot, g in enumerate(self.index["obstacle_geoms"]):
            if slot not in placed:
                m.geom_pos[g] = _FAR
                continue
            k = placed[slot]
            self._place(g, scene.a[k], scene.b[k], scene.radius[k], bool(scene.is_bar[k]))
            rows[slot] = [*scene.a[k], *scene.b[k], scene.radius[k], float(scene.is_bar[k])]
            mask[slot] = 1.0
        fruit3 = np.zeros(3)
        fruit3[:dim] = scene.fruit
        m.geom_pos[self.index["fruit_geom"][0]] = fruit3
        m.geom_size[self.index["fruit_geom"][0]] = (FRUIT_RADIUS, 0.0, 0.0)
        self.scene = scene
        self._n_pairs = len(self.index["link_geoms"]) * len(scene) + self._n_self
        self._slots = None  # contact order -> clearance slot, learnt at the first pose
        return rows, mask

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
            self.min_distance = float(clear[: self._n_lk].min())
            self.self_distance = float(clear[self._n_lk :].min())
        else:
            self.min_distance = float(clear.min())
        self.points = d.site_xpos[self.index["point_sites"], : self.dim]

    def render(self, renderer: mujoco.Renderer, path: list[np.ndarray]) -> np.ndarray:
        """One frame: the arm, the scene and the gripper's ``path`` (3-D points) so far."""
        camera = mujoco.MjvCamera()
        if self.arm.planar:
            camera.lookat[:] = (0.35, -0.15, 0.0)
            camera.distance, camera.azimuth, camera.elevation = 1.7, 90.0, -90.0
        else:
            camera.lookat[:] = (0.35, 0.0, 0.35)
            camera.distance, camera.azimuth, camera.elevation = 1.15, 210.0, -25.0
        renderer.update_scene(self.data, camera=camera)
        scene = renderer.scene
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
                np.array([0.9, 0.5, 0.1, 1.0], dtype=np.float32),
            )
            mujoco.mjv_connector(geom, mujoco.mjtGeom.mjGEOM_CAPSULE, 0.004, p0, p1)
            scene.ngeom += 1
        return renderer.render()

    def gripper_3d(self) -> np.ndarray:
        """The gripper's position in 3-D (for the rendered path)."""
        return self.data.site_xpos[self.index["point_sites"][-1]].copy()
