"""Arm models of the harvest-arm world: link tables, MuJoCo model, kinematics.

The paper (Ryu et al., redundant fruit-harvesting robot) studies six arms:
planar arms with 3, 4, 5 positioning DOF and spatial arms with 5, 6, 7.
Only the spatial 5-DOF arm has published geometry: the CRS A465 of Table 3
(column 0.3302 m, upper arm 0.3048 m, forearm 0.3302 m, wrist 0.076 m) with a
link added at the wrist so that the wrist roll and pitch position that
link's end (Fig. 7b). The rest are our documented choices:

* added link: 0.15 m, so the hand (wrist pitch to gripper) is
  0.076 + 0.15 = 0.226 m; the A465 reach beyond the shoulder is then
  0.3048 + 0.3302 + 0.226 = 0.861 m.
* spatial 6-DOF: the 5-DOF arm with the hand split into two 0.113 m links
  joined by one more pitch joint; 7-DOF: the 6-DOF arm with a roll joint about
  the upper arm before the elbow. Same reach, same column.
* planar n-DOF: n equal links in the x-y plane, all joints about z, total
  reach 0.861 m.
* ranges and speeds: the A465's for its joints (waist ±175°, shoulder ±90°,
  elbow ±110°, roll ±180°, wrist pitch ±105°; 3.14/3.14/3.14/2.99/3.02 rad/s);
  added pitch joints as the wrist pitch (±105°, 3.02 rad/s), the added roll as
  the wrist roll (±180°, 2.99 rad/s); planar: first joint ±175°, the others
  ±150°, all 3.14 rad/s.

Links are capsules about the segments joining consecutive *joint points*
(distinct joint positions, base to gripper). Kinematics come from
``mj_kinematics``; positional Jacobians of the joint points from
``mj_jacSite`` (equal to ``J[:, j] = a_j x (p - o_j)`` for every joint ``j``
proximal to the point, zero columns beyond it; both tested against finite
differences).
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

REACH = 0.3048 + 0.3302 + 0.226  # m, A465 reach beyond the shoulder with the added link
COLUMN = 0.3302  # m, A465 base column (Table 3, link 1)
SPATIAL_DOFS = (5, 6, 7)
PLANAR_DOFS = (3, 4, 5)

_X, _Y, _Z = (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)


@dataclass(frozen=True)
class Joint:
    """One revolute joint: its offset from the previous joint (previous frame)."""

    name: str
    offset: tuple[float, float, float]  # m, in the previous joint's frame
    axis: tuple[float, float, float]  # unit, in this joint's frame
    limit: float  # rad, symmetric range +-limit
    speed: float  # rad/s


@dataclass(frozen=True)
class ArmSpec:
    """A link table: joints base to wrist, then the gripper offset."""

    name: str
    planar: bool
    joints: tuple[Joint, ...]
    tool: tuple[float, float, float]  # m, gripper point in the last joint's frame
    home: tuple[float, ...]  # rad, the start pose of every episode

    @property
    def dof(self) -> int:
        return len(self.joints)

    @property
    def dim(self) -> int:
        return 2 if self.planar else 3

    @property
    def limits(self) -> np.ndarray:  # (n,)
        return np.array([j.limit for j in self.joints])

    @property
    def speeds(self) -> np.ndarray:  # (n,)
        return np.array([j.speed for j in self.joints])


def _deg(x: float) -> float:
    return float(np.deg2rad(x))


def arm_spec(dof: int, planar: bool) -> ArmSpec:
    """The link table of one of the paper's six arms."""
    if planar:
        if dof not in PLANAR_DOFS:
            raise ValueError(f"planar dof must be one of {PLANAR_DOFS}, got {dof!r}")
        length = REACH / dof
        joints = [Joint("j1", (0.0, 0.0, 0.0), _Z, _deg(175), 3.14)]
        joints += [
            Joint(f"j{i + 1}", (length, 0.0, 0.0), _Z, _deg(150), 3.14) for i in range(1, dof)
        ]
        bend = -2.6 / (dof - 1)  # rad: an arm curled over the workspace, gripper pointing down
        curled = (1.8,) + (bend,) * (dof - 1)
        return ArmSpec(f"planar{dof}", True, tuple(joints), (length, 0.0, 0.0), curled)
    if dof not in SPATIAL_DOFS:
        raise ValueError(f"spatial dof must be one of {SPATIAL_DOFS}, got {dof!r}")
    waist = Joint("waist", (0.0, 0.0, 0.0), _Z, _deg(175), 3.14)
    shoulder = Joint("shoulder", (0.0, 0.0, COLUMN), _Y, _deg(90), 3.14)
    elbow = Joint("elbow", (0.0, 0.0, 0.3048), _Y, _deg(110), 3.14)
    joints = [waist, shoulder]
    home = [0.0, -0.2]
    if dof == 7:
        joints.append(Joint("upper_roll", (0.0, 0.0, 0.0), _Z, _deg(180), 2.99))
        home.append(0.0)
    joints += [elbow, Joint("wrist_roll", (0.0, 0.0, 0.3302), _Z, _deg(180), 2.99)]
    joints.append(Joint("wrist_pitch", (0.0, 0.0, 0.0), _Y, _deg(105), 3.02))
    home += [1.8, 0.0, 0.4]
    if dof == 5:
        tool = (0.0, 0.0, 0.226)
    else:
        joints.append(Joint("hand_pitch", (0.0, 0.0, 0.113), _Y, _deg(105), 3.02))
        home[-1] = 0.3
        home.append(0.3)
        tool = (0.0, 0.0, 0.113)
    return ArmSpec(f"spatial{dof}", False, tuple(joints), tool, tuple(home))


def joint_points(spec: ArmSpec) -> list[int]:
    """Indices of the joints that start a new point (distinct positions).

    A joint whose offset is zero sits on the previous joint's point (a roll
    and a pitch in one wrist), so only the first of such a group is a point.
    """
    starts = []
    for i, joint in enumerate(spec.joints):
        if i == 0 or any(joint.offset):
            starts.append(i)
    return starts


def build_model(
    spec: ArmSpec,
    link_radius: float,
    n_spheres: int,
    n_bars: int,
    dt: float,
    self_pairs: bool = False,
) -> tuple[mujoco.MjModel, dict[str, np.ndarray]]:
    """The MuJoCo model: arm bodies, link capsules, obstacle slots, the fruit.

    Obstacle slots are world geoms moved at reset (spheres first, then bars as
    capsules). Every (link, obstacle) pair is an explicit contact pair with a
    5 m margin, so ``mj_collision`` reports the exact signed distance of every
    pair each step (MuJoCo's analytic sphere-capsule and capsule-capsule
    tests) while nothing moves under contact forces (the arm is kinematic).
    ``self_pairs`` adds, after those, one pair per two non-adjacent links
    (no shared joint point) with the same margin: their signed distances
    measure self-collision.

    Returns:
        the compiled model and index arrays: ``link_geoms`` (L,),
        ``obstacle_geoms`` (K,), ``point_sites`` (P,), ``fruit_geom`` (1,),
        ``self_pairs`` (S, 2) link indices of the self pairs (S = 0 without).
    """
    s = _scene_spec(spec, dt)
    point_sites, link_geoms = _add_arm(s, spec, link_radius)
    obstacle_geoms = _add_obstacles(s, n_spheres, n_bars)
    for link in link_geoms:
        for obstacle in obstacle_geoms:
            s.add_pair(geomname1=link, geomname2=obstacle, margin=5.0)
    n_links = len(link_geoms)
    pairs = [(i, j) for i in range(n_links) for j in range(i + 2, n_links)] if self_pairs else []
    for i, j in pairs:
        s.add_pair(geomname1=link_geoms[i], geomname2=link_geoms[j], margin=5.0)
    model = s.compile()
    for name in obstacle_geoms:  # moved and turned at reset: never assume the body's frame
        model.geom_sameframe[model.geom(name).id] = mujoco.mjtSameFrame.mjSAMEFRAME_NONE
    index = {
        "link_geoms": np.array([model.geom(g).id for g in link_geoms]),
        "obstacle_geoms": np.array([model.geom(g).id for g in obstacle_geoms], dtype=int),
        "point_sites": np.array([model.site(p).id for p in point_sites]),
        "fruit_geom": np.array([model.geom("fruit").id]),
        "self_pairs": np.array(pairs, dtype=int).reshape(-1, 2),
    }
    return model, index


def _scene_spec(spec: ArmSpec, dt: float) -> mujoco.MjSpec:
    """An empty scene: options, light, the ground."""
    s = mujoco.MjSpec()
    s.modelname = f"harvest_{spec.name}"
    s.option.timestep = dt
    s.option.gravity = [0.0, 0.0, 0.0]
    s.visual.global_.offwidth = 640
    s.visual.global_.offheight = 480
    s.visual.headlight.ambient = [0.35, 0.35, 0.35]
    s.visual.headlight.diffuse = [0.6, 0.6, 0.6]
    s.worldbody.add_light(pos=[0.5, -1.0, 2.5], dir=[-0.2, 0.4, -1.0], diffuse=[0.8, 0.8, 0.8])
    s.worldbody.add_geom(
        type=mujoco.mjtGeom.mjGEOM_PLANE,
        size=[2.0, 2.0, 0.1],
        pos=[0.0, 0.0, -0.6 if spec.planar else 0.0],
        rgba=[0.85, 0.85, 0.8, 1.0],
        contype=0,
        conaffinity=0,
    )
    return s


def _add_arm(s: mujoco.MjSpec, spec: ArmSpec, link_radius: float) -> tuple[list[str], list[str]]:
    """The arm's bodies, joints, link capsules and point sites: (site names, link names)."""
    point_starts = set(joint_points(spec))
    parent = s.worldbody
    point_sites: list[str] = []
    link_geoms: list[str] = []
    pending_from: str | None = None
    for i, joint in enumerate(spec.joints):
        body = parent.add_body(name=f"body_{joint.name}", pos=list(joint.offset))
        body.mass, body.inertia, body.explicitinertial = 0.5, [1e-3, 1e-3, 1e-3], True
        body.add_joint(
            name=joint.name,
            type=mujoco.mjtJoint.mjJNT_HINGE,
            axis=list(joint.axis),
            range=[-joint.limit, joint.limit],
        )
        if i in point_starts:
            if pending_from is not None and i > 0:
                # the previous link ends here: a capsule in the parent body
                link_geoms.append(
                    _add_link(parent, f"link{len(link_geoms)}", joint.offset, link_radius)
                )
            site = f"point{len(point_sites)}"
            body.add_site(name=site, size=[0.012, 0, 0], rgba=[0.2, 0.2, 0.2, 1.0])
            point_sites.append(site)
            pending_from = site
        parent = body
    link_geoms.append(_add_link(parent, f"link{len(link_geoms)}", spec.tool, link_radius))
    parent.add_site(
        name="gripper", pos=list(spec.tool), size=[0.015, 0, 0], rgba=[0.9, 0.5, 0.1, 1]
    )
    point_sites.append("gripper")
    return point_sites, link_geoms


def _add_obstacles(s: mujoco.MjSpec, n_spheres: int, n_bars: int) -> list[str]:
    """Obstacle slots (spheres, then bar capsules) and the fruit, parked far away."""
    obstacle_geoms = []
    far = [0.0, 0.0, -100.0]
    for k in range(n_spheres + n_bars):
        bar = k >= n_spheres
        name = f"bar{k - n_spheres}" if bar else f"sphere{k}"
        s.worldbody.add_geom(
            name=name,
            type=mujoco.mjtGeom.mjGEOM_CAPSULE if bar else mujoco.mjtGeom.mjGEOM_SPHERE,
            size=[0.01, 0.1, 0] if bar else [0.02, 0, 0],
            pos=far,
            rgba=[0.45, 0.3, 0.15, 1.0] if bar else [0.45, 0.75, 0.25, 1.0],
            contype=0,
            conaffinity=0,
        )
        obstacle_geoms.append(name)
    s.worldbody.add_geom(
        name="fruit",
        type=mujoco.mjtGeom.mjGEOM_SPHERE,
        size=[0.035, 0, 0],
        pos=far,
        rgba=[0.9, 0.15, 0.1, 1.0],
        contype=0,
        conaffinity=0,
    )
    return obstacle_geoms


def _add_link(body: mujoco.MjsBody, name: str, end: tuple[float, ...], radius: float) -> str:
    body.add_geom(
        name=name,
        type=mujoco.mjtGeom.mjGEOM_CAPSULE,
        fromto=[0.0, 0.0, 0.0, *end],
        size=[radius, 0, 0],
        rgba=[0.3, 0.45, 0.8, 1.0],
        contype=0,
        conaffinity=0,
    )
    return name


class ArmKinematics:
    """Forward kinematics and point Jacobians of one arm (own MjData).

    Usable without an environment: the scripted policies build one from the
    environment's keyword arguments.
    """

    def __init__(self, spec: ArmSpec, link_radius: float = 0.02, dt: float = 0.05) -> None:
        self.spec = spec
        self.model, self.index = build_model(spec, link_radius, 0, 0, dt)
        self.data = mujoco.MjData(self.model)
        self.dim = spec.dim
        sites = self.index["point_sites"]
        site_body = self.model.site_bodyid[sites]  # (P,)
        jnt_body = self.model.jnt_bodyid  # (n,)
        # joint j moves point p iff the joint's body is an ancestor of (or is) the point's body
        self._moves = np.zeros((len(sites), spec.dof), dtype=bool)  # (P, n)
        for p, body in enumerate(site_body):
            chain = set()
            b = int(body)
            while b > 0:
                chain.add(b)
                b = int(self.model.body_parentid[b])
            self._moves[p] = [int(jb) in chain for jb in jnt_body]
        self._jac = np.zeros((len(sites), 3, spec.dof))

    @property
    def n_points(self) -> int:
        return len(self.index["point_sites"])

    def forward(self, q: np.ndarray) -> np.ndarray:
        """Joint points base to gripper for joint angles ``q`` (n,): (P, dim)."""
        self.data.qpos[:] = q
        mujoco.mj_kinematics(self.model, self.data)
        return self.data.site_xpos[self.index["point_sites"], : self.dim].copy()

    def jacobians(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Points (P, dim) and their positional Jacobians (P, dim, n)."""
        m, d = self.model, self.data
        d.qpos[:] = q
        mujoco.mj_kinematics(m, d)
        mujoco.mj_comPos(m, d)
        jac = self._jac  # (P, 3, n)
        for i, site in enumerate(self.index["point_sites"]):
            mujoco.mj_jacSite(m, d, jac[i], None, int(site))
        points = d.site_xpos[self.index["point_sites"], : self.dim].copy()
        return points, jac[:, : self.dim, :].copy()

    def jacobians_from_axes(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The same from joint anchors and axes, ``J[:, j] = a_j x (p - o_j)`` (a check)."""
        self.data.qpos[:] = q
        mujoco.mj_kinematics(self.model, self.data)
        points = self.data.site_xpos[self.index["point_sites"]]  # (P, 3)
        arm = points[:, None, :] - self.data.xanchor[None, :, :]  # (P, n, 3)
        jac = np.cross(self.data.xaxis[None, :, :], arm) * self._moves[:, :, None]  # (P, n, 3)
        jac = np.transpose(jac, (0, 2, 1))  # (P, 3, n)
        return points[:, : self.dim].copy(), jac[:, : self.dim, :].copy()
