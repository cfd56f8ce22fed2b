"""Two PUMA-560 arms: kinematics, convex link bodies, the MuJoCo model, link distances.

Kinematics: standard Denavit-Hartenberg parameters of the PUMA 560 from
P. Corke and B. Armstrong-Helouvry, "A search for consensus among model
parameters reported for the PUMA 560 robot", ICRA 1994, as shipped in Corke's
Robotics Toolbox (``mdl_puma560`` / ``models.DH.Puma560``)::

    joint   theta   d [m]     a [m]    alpha
    1       q1      0.672     0        +pi/2
    2       q2      0         0.4318   0
    3       q3      0.15005   0.0203   -pi/2
    4       q4      0.4318    0        +pi/2
    5       q5      0         0        -pi/2
    6       q6      0         0        0

(d1 = 0.672 m is the shoulder height of the Robotics Toolbox for Python model;
the MATLAB model puts it in the base transform instead.) Joint ranges are the
toolbox's ``qlim``: +-160, +-110, +-135, +-266, +-100, +-266 degrees.

Bases (paper eq. 3): robot 1 at x = +0.65 m rotated by pi about z, robot 2 at
x = -0.65 m unrotated, both on z = 0: at q = 0 each arm reaches towards the
other along its base x axis.

Bodies (paper Fig. 1: seven convex bodies per arm). Body ``k`` (1..6) has the
frame ``B_k = F_{k-1} Rz(q_k)`` (``F_0`` the base, ``F_k = B_k Tz(d_k) Tx(a_k)
Rx(alpha_k)``), i.e. the hinge of joint ``k`` at its origin about its z axis,
which is exactly how the MuJoCo model nests them. Each body is one capsule
given by two end points in its own frame and a radius (``LINKS``); the base is
a fixed cylinder. Links 4 and 5 of the PUMA are the wrist; the gripper is
rigid with link 6 and modelled with it as one body ("gripper"), so the seven
bodies are base, link 1 (turret), upper arm, forearm, wrist roll, wrist bend,
gripper. Capsules keep the distance exact and cheap: for capsules ``A``, ``B``
about segments ``a``, ``b`` with radii ``ra``, ``rb``,
``d(A, B) = d(a, b) - ra - rb`` (paper eq. 1; negative = penetration depth).

Distances (paper eq. 2): base and link 1 are excluded; the 5 x 5 pairs of the
remaining bodies give ``d_ij`` and ``d(R1, R2) = min d_ij``. Two evaluators
give the same numbers: :func:`pair_distances` (NumPy, batched over many
configurations: used by the planners for the collision map) and
:class:`MujocoCell` (``mj_kinematics`` + ``mj_collision`` over 25 explicit
geom pairs, zero geom margin; used by the environment step and the renderer).
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from motiongym.envs.geometry import closest_points_between_segments

# Standard DH table (Corke & Armstrong-Helouvry 1994): rows (d, a, alpha).
DH = np.array(
    [
        [0.672, 0.0, math.pi / 2],
        [0.0, 0.4318, 0.0],
        [0.15005, 0.0203, -math.pi / 2],
        [0.4318, 0.0, math.pi / 2],
        [0.0, 0.0, -math.pi / 2],
        [0.0, 0.0, 0.0],
    ]
)  # (6, 3)
JOINT_LIMITS = np.deg2rad(
    np.array([[-160, 160], [-110, 110], [-135, 135], [-266, 266], [-100, 100], [-266, 266]])
)  # (6, 2) rad
BASE_X = (0.65, -0.65)  # m, paper eq. 3
BASE_YAW = (math.pi, 0.0)  # rad, paper eq. 3

BODY_NAMES = ("base", "link1", "upper_arm", "forearm", "wrist_roll", "wrist_bend", "gripper")
# Capsules of bodies 1..6 in their own frame B_k: (start xyz, end xyz, radius) in m.
LINKS = (
    ((0.0, 0.0, 0.50), (0.0, 0.0, 0.672), 0.10),  # link1: turret (excluded)
    ((0.0, 0.0, 0.0), (0.4318, 0.0, 0.0), 0.075),  # upper arm, shoulder to elbow
    ((0.0203, 0.0, 0.15005), (0.0203, 0.33, 0.15005), 0.055),  # forearm, elbow to wrist
    ((0.0, 0.0, 0.33), (0.0, 0.0, 0.40), 0.05),  # wrist roll housing (about z3)
    ((0.0, 0.0, -0.04), (0.0, 0.0, 0.04), 0.045),  # wrist bend, about joint-5 axis
    ((0.0, 0.0, 0.05), (0.0, 0.0, 0.20), 0.035),  # flange + gripper along approach
)
BASE_HEIGHT = 0.50  # m, fixed pedestal cylinder 0..BASE_HEIGHT
BASE_RADIUS = 0.12  # m
CHECKED = (2, 3, 4, 5, 6)  # bodies in the 25 pairs (base and link 1 excluded)
N_PAIRS = 25

_SEG_A = np.array([LINKS[k - 1][0] for k in CHECKED])  # (5, 3)
_SEG_B = np.array([LINKS[k - 1][1] for k in CHECKED])  # (5, 3)
RADII = np.array([LINKS[k - 1][2] for k in CHECKED])  # (5,)
HALF = np.linalg.norm(_SEG_B - _SEG_A, axis=1) / 2  # (5,) capsule half lengths
# Lower bound of d_ij from the capsules' centre distance: |c_i - c_j| - _REACH_ij.
_REACH = (HALF + RADII)[:, None] + (HALF + RADII)[None, :]  # (5, 5)


def _link_transform(d: float, a: float, alpha: float) -> np.ndarray:
    """``Tz(d) Tx(a) Rx(alpha)`` (4, 4)."""
    ca, sa = math.cos(alpha), math.sin(alpha)
    return np.array([[1, 0, 0, a], [0, ca, -sa, 0], [0, sa, ca, d], [0, 0, 0, 1.0]])


_LINK = [_link_transform(*row) for row in DH]


def base_transform(robot: int) -> np.ndarray:
    """Homogeneous base frame of robot 0 or 1 (paper eq. 3). Shape (4, 4)."""
    c, s = math.cos(BASE_YAW[robot]), math.sin(BASE_YAW[robot])
    t = np.eye(4)
    t[:2, :2] = [[c, -s], [s, c]]
    t[0, 3] = BASE_X[robot]
    return t


def body_frames(q: np.ndarray, base: np.ndarray) -> np.ndarray:
    """World frames ``B_1..B_6`` of the link bodies, batched.

    Args:
        q: joint angles, shape (..., 6), rad.
        base: base transform (4, 4).
    Returns:
        (..., 6, 4, 4) homogeneous transforms; ``B_k`` has joint k's axis as z.
    """
    q = np.asarray(q, float)
    lead = q.shape[:-1]
    c, s = np.cos(q), np.sin(q)  # (..., 6)
    frames = np.empty(lead + (6, 4, 4))
    f = np.broadcast_to(base, lead + (4, 4))
    for k in range(6):
        # b = f @ Rz(q_k): only the first two columns change.
        b = frames[..., k, :, :]
        ck, sk = c[..., k, None], s[..., k, None]
        b[..., :, 0] = ck * f[..., :, 0] + sk * f[..., :, 1]
        b[..., :, 1] = ck * f[..., :, 1] - sk * f[..., :, 0]
        b[..., :, 2:] = f[..., :, 2:]
        f = b @ _LINK[k]
    return frames


def wrist_centre(q: np.ndarray, base: np.ndarray) -> np.ndarray:
    """Wrist centre (origin of frames 4-6), shape (..., 3): the paper's wrist point."""
    return body_frames(q, base)[..., 4, :3, 3]


def link_segments(q: np.ndarray, base: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """World end points of the 5 checked capsules, each (..., 5, 3)."""
    return segments_from_frames(body_frames(q, base))


def segments_from_frames(frames: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Capsule end points (..., 5, 3) x 2 from body frames (..., 6, 4, 4)."""
    fr = frames[..., 1:, :, :]  # (..., 5, 4, 4)
    rot, pos = fr[..., :3, :3], fr[..., :3, 3]
    a = (rot @ _SEG_A[:, :, None])[..., 0] + pos
    b = (rot @ _SEG_B[:, :, None])[..., 0] + pos
    return a, b


def segment_pair_distances(
    a1: np.ndarray, b1: np.ndarray, a2: np.ndarray, b2: np.ndarray
) -> np.ndarray:
    """``d_ij`` from precomputed capsule end points (..., 5, 3) -> (..., 5, 5), m."""
    dist, _, _ = closest_points_between_segments(
        a1[..., :, None, :], b1[..., :, None, :], a2[..., None, :, :], b2[..., None, :, :]
    )
    return dist - RADII[:, None] - RADII[None, :]


def segments_collide(
    a1: np.ndarray, b1: np.ndarray, a2: np.ndarray, b2: np.ndarray, margin: float = 0.0
) -> np.ndarray:
    """``d(R1, R2) <= margin`` from capsule end points (..., 5, 3) -> bool (...).

    Exact: pairs whose bounding spheres (about the capsule centres) are already
    farther apart than ``margin`` are skipped, the rest get the exact distance.
    """
    lead = a1.shape[:-2]
    c1, c2 = (a1 + b1) / 2, (a2 + b2) / 2
    diff = c1[..., :, None, :] - c2[..., None, :, :]  # (..., 5, 5, 3)
    gap = np.sqrt(np.sum(diff * diff, axis=-1)) - _REACH
    near = np.nonzero(gap <= margin)  # indices (lead..., i, j)
    out = np.zeros(lead, dtype=bool)
    if len(near[0]) == 0:
        return out
    lead_idx, i, j = near[:-2], near[-2], near[-1]
    at_i, at_j = (*lead_idx, i), (*lead_idx, j)
    dist, _, _ = closest_points_between_segments(a1[at_i], b1[at_i], a2[at_j], b2[at_j])
    hit = dist - RADII[i] - RADII[j] <= margin
    if lead:
        out[tuple(idx[hit] for idx in lead_idx)] = True
        return out
    return np.asarray(bool(hit.any()))


def pair_distances(q1: np.ndarray, q2: np.ndarray) -> np.ndarray:
    """The 25 link-pair distances ``d_ij`` (paper eq. 1), batched.

    Args:
        q1, q2: joint angles of robot 1 and robot 2, shapes broadcastable (..., 6).
    Returns:
        (..., 5, 5): row i a body of robot 1, column j one of robot 2 (order ``CHECKED``).
    """
    a1, b1 = link_segments(q1, base_transform(0))
    a2, b2 = link_segments(q2, base_transform(1))
    return segment_pair_distances(a1, b1, a2, b2)


def robot_distance(q1: np.ndarray, q2: np.ndarray) -> np.ndarray:
    """``d(R1, R2) = min_ij d_ij`` (paper eq. 2), shape (...)."""
    return pair_distances(q1, q2).min(axis=(-2, -1))


# --------------------------------------------------------------------------- MuJoCo


def _quat_z(yaw: float) -> list[float]:
    return [math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2)]


def _add_arm(world: mujoco.MjsBody, r: int, rgba: list[float]) -> None:
    """Robot ``r + 1``: its base cylinder and six hinged link capsules (DH chain)."""
    base = world.add_body(name=f"r{r + 1}_base", pos=[BASE_X[r], 0, 0], quat=_quat_z(BASE_YAW[r]))
    base.add_geom(
        name=f"r{r + 1}_base",
        type=mujoco.mjtGeom.mjGEOM_CYLINDER,
        size=[BASE_RADIUS, BASE_HEIGHT / 2, 0],
        pos=[0, 0, BASE_HEIGHT / 2],
        rgba=[0.3, 0.3, 0.3, 1],
        contype=0,
        conaffinity=0,
    )
    parent, pos, quat = base, [0.0, 0.0, 0.0], [1.0, 0.0, 0.0, 0.0]
    for k in range(6):
        body = parent.add_body(name=f"r{r + 1}_{BODY_NAMES[k + 1]}", pos=pos, quat=quat)
        body.add_joint(
            name=f"r{r + 1}_q{k + 1}",
            type=mujoco.mjtJoint.mjJNT_HINGE,
            axis=[0, 0, 1],
            range=JOINT_LIMITS[k].tolist(),
        )
        start, end, radius = LINKS[k]
        body.add_geom(
            name=f"r{r + 1}_{BODY_NAMES[k + 1]}",
            type=mujoco.mjtGeom.mjGEOM_CAPSULE,
            fromto=[*start, *end],
            size=[radius, 0, 0],
            rgba=rgba,
            margin=0.0,
            contype=0,
            conaffinity=0,
        )
        d, a, alpha = DH[k]
        parent, pos = body, [a, 0.0, d]
        quat = [math.cos(alpha / 2), math.sin(alpha / 2), 0.0, 0.0]


def build_spec(pair_range: float = 10.0) -> mujoco.MjSpec:
    """Both arms as a kinematic MuJoCo model built with ``MjSpec``.

    Geoms have zero margin; the 25 checked pairs are explicit ``<pair>`` elements
    whose margin ``pair_range`` (m) only makes ``mj_collision`` report every pair
    with its exact signed distance (``contact.dist``); no other pair collides.
    """
    spec = mujoco.MjSpec()
    spec.modelname = "dual_puma560"
    spec.option.gravity = [0.0, 0.0, 0.0]
    spec.visual.global_.offwidth = 640
    spec.visual.global_.offheight = 480
    world = spec.worldbody
    world.add_light(pos=[0, 0, 3.0], dir=[0, 0, -1], diffuse=[0.8, 0.8, 0.8])
    world.add_geom(
        name="floor",
        type=mujoco.mjtGeom.mjGEOM_PLANE,
        size=[2.0, 2.0, 0.05],
        rgba=[0.85, 0.85, 0.82, 1],
        contype=0,
        conaffinity=0,
    )
    # Looking along +y, 17 degrees down at the middle of the cell: rotation about x by 73 deg.
    world.add_camera(name="overview", pos=[0.0, -2.3, 1.5], quat=[0.803857, 0.594823, 0.0, 0.0])
    colours = ([0.85, 0.35, 0.2, 1.0], [0.2, 0.45, 0.85, 1.0])
    for r in range(2):
        _add_arm(world, r, colours[r])
    for i in CHECKED:
        for j in CHECKED:
            spec.add_pair(
                geomname1=f"r1_{BODY_NAMES[i]}",
                geomname2=f"r2_{BODY_NAMES[j]}",
                margin=pair_range,
            )
    return spec


class MujocoCell:
    """The MuJoCo world of both arms and its 25 link-pair distances.

    ``distances(q1, q2)`` sets the joints, runs ``mj_kinematics`` and
    ``mj_collision`` and returns ``d_ij`` (5, 5) in the order of
    :func:`pair_distances`.
    """

    def __init__(self) -> None:
        self.model = build_spec().compile()
        self.data = mujoco.MjData(self.model)
        m = self.model
        lookup = np.full((m.ngeom, m.ngeom), -1, dtype=np.int64)
        for p in range(m.npair):
            g1, g2 = m.pair_geom1[p], m.pair_geom2[p]
            lookup[g1, g2] = lookup[g2, g1] = p
        self._pair_of = lookup
        self.geom_ids = [
            [
                mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, f"r{r + 1}_{BODY_NAMES[k]}")
                for k in CHECKED
            ]
            for r in range(2)
        ]

    def distances(self, q1: np.ndarray, q2: np.ndarray) -> np.ndarray:
        self.data.qpos[:6] = q1
        self.data.qpos[6:] = q2
        return self.current_distances()

    def current_distances(self) -> np.ndarray:
        """``d_ij`` (5, 5) at the joints already in ``data.qpos``."""
        mujoco.mj_kinematics(self.model, self.data)
        mujoco.mj_collision(self.model, self.data)
        n = self.data.ncon
        con = self.data.contact
        if n == N_PAIRS:  # one contact per pair, in pair order
            return con.dist[:n].reshape(5, 5).copy()
        out = np.full(N_PAIRS, np.inf)
        idx = self._pair_of[con.geom[:n, 0], con.geom[:n, 1]]
        np.minimum.at(out, idx, con.dist[:n])
        return out.reshape(5, 5)

    def geom_distance(self, i: int, j: int, distmax: float = 10.0) -> float:
        """``mj_geomDistance`` (GJK) between body ``CHECKED[i]`` of robot 1 and ``j`` of 2."""
        fromto = np.zeros(6)
        return mujoco.mj_geomDistance(
            self.model, self.data, self.geom_ids[0][i], self.geom_ids[1][j], distmax, fromto
        )
