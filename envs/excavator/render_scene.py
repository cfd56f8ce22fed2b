"""The render scene: the excavator as a MuJoCo model built from the same DH table.

:func:`build_spec` turns each row of Table 1 (Craig's modified DH,
``T_i^{i-1} = RotX(alpha_{i-1}) TransX(a_{i-1}) RotZ(theta_i) TransZ(d_i)``)
into a body placed at ``RotX(alpha_{i-1}) TransX(a_{i-1}) TransZ(d_i)`` with a
hinge about its local z axis, so MuJoCo's kinematics is the paper's (tested:
the ``tip`` site equals :func:`kinematics.forward` at random joint angles).
The world adds the height-field ground, the pipe, the truck body, the dig
zone and the target marker (a glowing sphere; the pipe glows through the see-through
ground). MuJoCo is used for rendering and for that
cross-check; an environment step uses the NumPy/scalar kinematics.
"""

from __future__ import annotations

import math
import os
from typing import TYPE_CHECKING

if not os.environ.get("DISPLAY"):  # offscreen by default on a headless machine
    os.environ.setdefault("MUJOCO_GL", "egl")

import mujoco  # noqa: E402
import numpy as np

from motiongym.envs.excavator.config import Machine
from motiongym.envs.excavator.scenes import GRID_CELL, GRID_ORIGIN, GRID_SHAPE

if TYPE_CHECKING:  # pragma: no cover
    from motiongym.envs.excavator.world import ExcavatorWorld

Z_MIN, Z_MAX = -4.0, 3.0  # m: height-field range
JOINTS = ("swing", "boom", "stick", "bucket")
_YELLOW = (0.95, 0.75, 0.1, 1.0)


def _quat_x(angle: float) -> list[float]:
    return [math.cos(angle / 2), math.sin(angle / 2), 0.0, 0.0]


def _quat_z(angle: float) -> list[float]:
    return [math.cos(angle / 2), 0.0, 0.0, math.sin(angle / 2)]


def build_spec(m: Machine, with_world: bool = True) -> mujoco.MjSpec:
    """The machine (and, with ``with_world``, ground, pipe, truck, markers) as an MjSpec."""
    spec = mujoco.MjSpec()
    spec.modelname = "excavator"
    spec.visual.headlight.ambient = [0.45, 0.45, 0.45]
    spec.visual.headlight.diffuse = [0.5, 0.5, 0.5]
    world = spec.worldbody
    world.add_light(pos=[0, 0, 30], dir=[0, 0, -1], diffuse=[0.6, 0.6, 0.6])
    tracks = world.add_geom(type=mujoco.mjtGeom.mjGEOM_BOX, size=[2.3, 1.6, 0.45])
    tracks.pos, tracks.rgba = [-m.L0, 0, 0.45], [0.2, 0.2, 0.2, 1]
    parent = world
    lengths = (None, m.L2, m.L3, m.L4)
    radii = (None, *m.link_radius)
    for i, ((alpha, a, d), name) in enumerate(zip(m.dh, JOINTS, strict=True)):
        body = parent.add_body(name=name)
        body.pos = [a, -math.sin(alpha) * d, math.cos(alpha) * d]
        body.quat = _quat_x(alpha)
        joint = body.add_joint(name=name, type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0, 0, 1])
        joint.range = [m.q_min[i], m.q_max[i]]
        if i == 0:  # the upper structure: cab and counterweight, below the boom foot
            cab = body.add_geom(type=mujoco.mjtGeom.mjGEOM_BOX, size=[1.5, 1.3, 0.7])
            cab.pos, cab.rgba = [-0.6, 0.0, -m.d1 + 1.6], _YELLOW
        else:
            geom = body.add_geom(type=mujoco.mjtGeom.mjGEOM_CAPSULE, size=[radii[i], 0, 0])
            geom.fromto = [0, 0, 0, lengths[i], 0, 0]
            geom.rgba = _YELLOW if i < 3 else (0.3, 0.3, 0.3, 1)
        parent = body
    shell = parent.add_geom(type=mujoco.mjtGeom.mjGEOM_BOX)
    shell.size, shell.pos = [0.55 * m.L4, 0.3, 0.5 * m.bucket_width], [0.5 * m.L4, -0.3, 0]
    shell.rgba = (0.35, 0.35, 0.35, 1)
    soil = parent.add_geom(name="bucket_soil", type=mujoco.mjtGeom.mjGEOM_SPHERE, size=[0.01, 0, 0])
    soil.pos, soil.rgba = [0.5 * m.L4, -0.5, 0], (0.45, 0.3, 0.15, 1)
    parent.add_site(name="tip", pos=[m.L4, 0, 0], size=[0.08, 0, 0])
    if with_world:
        _add_world(spec, m)
    return spec


def _glowing(spec: mujoco.MjSpec, name: str, emission: float) -> str:
    """A material that glows by ``emission`` (geom colours stay the geoms')."""
    material = spec.add_material(name=name)
    material.emission = emission
    return name


def _add_world(spec: mujoco.MjSpec, m: Machine) -> None:
    world = spec.worldbody
    nx, ny = GRID_SHAPE
    field = spec.add_hfield(name="ground")
    field.nrow, field.ncol = ny, nx
    field.size = [(nx - 1) * GRID_CELL / 2, (ny - 1) * GRID_CELL / 2, Z_MAX - Z_MIN, 0.2]
    field.userdata = list(np.full(nx * ny, -Z_MIN / (Z_MAX - Z_MIN)))
    ground = world.add_geom(name="ground", type=mujoco.mjtGeom.mjGEOM_HFIELD, hfieldname="ground")
    ground.pos = [GRID_ORIGIN[0] + nx * GRID_CELL / 2, GRID_ORIGIN[1] + ny * GRID_CELL / 2, Z_MIN]
    ground.rgba = (0.6, 0.47, 0.32, 0.5)  # see-through: the buried pipe shows
    pipe = world.add_geom(name="pipe", type=mujoco.mjtGeom.mjGEOM_CAPSULE, size=[0.15, 0, 0])
    pipe.fromto, pipe.rgba = [0, 0, -2, 1, 0, -2], (0.1, 0.5, 1.0, 1)
    pipe.material = _glowing(spec, "pipe_glow", 1.0)  # lit from within: seen through soil
    truck = world.add_geom(name="truck", type=mujoco.mjtGeom.mjGEOM_BOX, size=[2.5, 1.2, 1.4])
    truck.rgba = (0.8, 0.15, 0.1, 0.55)
    load = world.add_geom(name="truck_soil", type=mujoco.mjtGeom.mjGEOM_BOX, size=[2.4, 1.1, 0.01])
    load.rgba = (0.45, 0.3, 0.15, 1)
    zone = world.add_geom(name="zone", type=mujoco.mjtGeom.mjGEOM_BOX, size=[1, 0.6, 0.01])
    zone.rgba = (1.0, 1.0, 1.0, 0.6)
    # The reach target (m): drawn larger than the tip's 0.1 m tolerance so it shows at the
    # camera's 24 m; glowing green, whatever the light.
    target = world.add_geom(name="target", type=mujoco.mjtGeom.mjGEOM_SPHERE, size=[0.35, 0, 0])
    target.pos, target.rgba = [0, 0, -10], (0.1, 1.0, 0.2, 1)
    target.material = _glowing(spec, "target_glow", 0.8)
    for geom in (ground, pipe, truck, load, zone, target):
        geom.contype, geom.conaffinity = 0, 0


def build_model(m: Machine, with_world: bool = True) -> mujoco.MjModel:
    """Compiled :func:`build_spec`."""
    model = build_spec(m, with_world).compile()
    model.geom_contype[:] = 0
    model.geom_conaffinity[:] = 0
    # The scene geoms are placed at render time: their frames are not the body's.
    model.geom_sameframe[:] = 0
    return model


class SceneRenderer:
    """Offscreen rendering of an excavator world (``MUJOCO_GL=egl``) at ``size`` =
    (rows, columns).

    The model's offscreen buffer (``vis.global_.offheight`` / ``offwidth``,
    640 x 480 by default) is enlarged to ``size`` where that is larger, so
    every size :func:`motiongym.envs.core.check_render_size` allows renders.
    """

    def __init__(self, m: Machine, size: tuple[int, int]) -> None:
        self.size = (int(size[0]), int(size[1]))
        self.model = build_model(m)
        buffer = self.model.vis.global_
        buffer.offheight = max(buffer.offheight, self.size[0])
        buffer.offwidth = max(buffer.offwidth, self.size[1])
        self.data = mujoco.MjData(self.model)
        self.renderer = mujoco.Renderer(self.model, height=self.size[0], width=self.size[1])
        self.camera = mujoco.MjvCamera()
        self.camera.lookat[:] = [3.0, 0.0, 0.5]
        self.camera.distance, self.camera.elevation, self.camera.azimuth = 24.0, -28.0, -130.0
        self._terrain_key: tuple[int, int] | None = None
        self._hfield = self.model.hfield("ground").id
        self._swing_pos = self.model.body("swing").pos.copy()

    def _geom(self, name: str) -> int:
        return self.model.geom(name).id

    def render(self, world: ExcavatorWorld) -> np.ndarray:
        """A frame of the world's state (an :class:`ExcavatorWorld` or its v1 twin)."""
        model, data = self.model, self.data
        data.qpos[:4] = world.q
        key = (id(world.terrain), world.terrain.version)
        if key != self._terrain_key:
            levels = np.clip((world.terrain.h.T - Z_MIN) / (Z_MAX - Z_MIN), 0.0, 1.0)
            model.hfield_data[:] = levels.reshape(-1)
            mujoco.mjr_uploadHField(model, self.renderer._mjr_context, self._hfield)
            self._terrain_key = key
        pipe, truck = world.pipe, world.truck
        g = self._geom("pipe")
        a, b = np.array(pipe.a), np.array(pipe.b)
        model.geom_pos[g] = 0.5 * (a + b)
        model.geom_size[g, :2] = [pipe.radius, 0.5 * np.linalg.norm(b - a)]
        mujoco.mju_quatZ2Vec(model.geom_quat[g], b - a)
        g = self._geom("truck")
        model.geom_pos[g] = [truck.cx, truck.cy, truck.height / 2]
        model.geom_size[g] = [truck.half_length, truck.half_width, truck.height / 2]
        model.geom_quat[g] = _quat_z(truck.yaw)
        g = self._geom("truck_soil")
        fill_height = world.truck_soil / (4 * 2.4 * 1.1) + 0.01
        model.geom_pos[g] = [truck.cx, truck.cy, truck.height - 1.3 + fill_height]
        model.geom_size[g, 2] = fill_height
        model.geom_quat[g] = _quat_z(truck.yaw)
        g = self._geom("bucket_soil")
        model.geom_size[g, 0] = 0.01 + 0.6 * (world.fill / world.m.bucket_capacity) ** (1 / 3)
        zone = getattr(world.scene, "zone", None)
        g = self._geom("zone")
        if zone is not None:
            mid = 0.5 * (zone.r_near + zone.r_far)
            c, s = math.cos(zone.azimuth), math.sin(zone.azimuth)
            model.geom_pos[g] = [c * mid, s * mid, world.terrain.height_at(c * mid, s * mid) + 0.05]
            model.geom_size[g] = [
                0.5 * (zone.r_far - zone.r_near),
                0.5 * world.m.bucket_width,
                0.01,
            ]
            model.geom_quat[g] = _quat_z(zone.azimuth)
        else:
            model.geom_pos[g] = [0, 0, -10]
        target = getattr(world.scene, "target", None)
        model.geom_pos[self._geom("target")] = [0, 0, -10] if target is None else target[:3]
        self._place_base(getattr(world, "rotation", None))
        mujoco.mj_kinematics(model, data)
        self.renderer.update_scene(data, self.camera)
        return self.renderer.render().copy()

    def _place_base(self, rotation) -> None:
        """Turn the machine (its first body) by the base rotation ``R`` (None: level)."""
        body = self.model.body("swing").id
        r = np.eye(3) if rotation is None else np.asarray(rotation, float)
        self.model.body_pos[body] = r @ self._swing_pos
        mujoco.mju_mat2Quat(self.model.body_quat[body], r.reshape(-1))

    def close(self) -> None:
        self.renderer.close()
