"""Excavator physics v1 (issue 16): each probe of the issue gives the physical answer.

The machine is driven through the environment (actions only) on a level,
flat scene built here (pipe and truck placed by the test); poses are set
through the ``start`` reset option from the closed-form IK, and every expected
position (corners, tips, pins) comes from :mod:`motiongym.envs.excavator.kinematics`
(the paper's matrix chain), not from the world's own code.
"""

from __future__ import annotations

import math
import os

os.environ.setdefault("MUJOCO_GL", "egl")

import gymnasium as gym  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

import motiongym  # noqa: E402,F401
from motiongym.baselines.excavator.newton_raphson import (  # noqa: E402
    analytic_solutions,
    within_limits,
)
from motiongym.envs.excavator import bodies  # noqa: E402
from motiongym.envs.excavator import kinematics as kin  # noqa: E402
from motiongym.envs.excavator.obstacles import Pipe, Truck  # noqa: E402
from motiongym.envs.excavator.scenes import GRID_SHAPE, DigZone, Scene  # noqa: E402

FAR_PIPE = Pipe((-9.0, -8.0, -3.0), (-9.0, 8.0, -3.0), 0.15)
FAR_TRUCK = Truck(cx=0.0, cy=-8.0, yaw=0.0, half_length=2.5, half_width=1.2, height=2.8)


def _env(task="dig", pipe=FAR_PIPE, truck=FAR_TRUCK, q0=None, **kwargs):
    """A v1 environment on flat ground (z = 0) with the given pipe and truck."""
    env_id = "motiongym/Excavator-v1" if task == "dig" else "motiongym/ExcavatorReach-v1"
    env = gym.make(env_id, slope=0.0, **kwargs).unwrapped
    scene = Scene(
        np.zeros(GRID_SHAPE),
        pipe,
        truck,
        zone=DigZone(0.0, 4.0, 8.0, 0.5),
        target=np.array([6.0, 0.0, 1.0, -1.6]),
    )
    env.task.sample_scene = lambda rng: scene
    options = None if q0 is None else {"start": q0}
    env.reset(seed=0, options=options)
    return env


def _pose(tip, beta, m):
    """Joint angles putting the tip at ``tip`` with bucket angle ``beta`` (closed form)."""
    return next(
        s for s in analytic_solutions(np.asarray(tip, float), beta, m) if within_limits(s, m)
    )


def _drive(env, velocity, beta_rate=0.0, seconds=1.0):
    """Command joint rates that move the tip at ``velocity`` (m/s) and turn the bucket.

    Resolved rates from the analytic Jacobian (position rows and the bucket
    angle row), as fractions of the rate limits. Returns the last info.
    """
    m, w = env.m, env.world
    info = {}
    for _ in range(round(seconds / env.dt)):
        _, dp = kin.tip_jacobian(np.array(w.q), m)
        jac = np.vstack([dp, [0.0, 1.0, 1.0, 1.0]])
        dq = np.linalg.lstsq(jac, np.append(velocity, beta_rate), rcond=None)[0]
        scale = max(1.0, np.max(np.abs(dq) / m.rate_max))
        _, _, terminated, _, info = env.step((dq / m.rate_max / scale).astype(np.float32))
        if terminated:
            break
    return info


def _edge_depth(env):
    """Deepest point of the cutting edge below the ground there (m), from kinematics.forward."""
    frame = kin.forward(np.array(env.world.q), env.m)
    t = env.world.terrain
    depths = []
    for s in (-0.5, 0.0, 0.5):
        p = frame[:3, 3] + s * env.m.bucket_width * frame[:3, 2]
        depths.append(t.height_at(p[0], p[1]) - p[2])
    return max(depths)


# ----------------------------------------------------------------- soil probes
def test_heel_first_push_takes_no_soil_and_is_stopped():
    m = gym.make("motiongym/Excavator-v1").unwrapped.m
    env = _env(q0=_pose((6.0, 0.0, 0.01), -1.6, m))  # opening toward the machine
    x0 = env.world.tip[0]
    info = _drive(env, (0.5, 0.0, -0.15), seconds=3.0)  # 1.5 m away, heel first, down
    assert info["bucket_fill"] == 0.0
    assert _edge_depth(env) < 0.05
    assert env.world.tip[0] - x0 < 0.5  # stopped, not pushed 1.5 m


def test_sideways_swing_in_the_ground_takes_no_soil_and_is_stopped():
    m = gym.make("motiongym/Excavator-v1").unwrapped.m
    env = _env(q0=_pose((6.0, 0.0, -0.5), -1.6, m))  # edge 0.5 m deep (placed there)
    swing0 = env.world.q[0]
    for _ in range(10):  # full swing rate for 1 s
        _, _, _, _, info = env.step(np.array([1.0, 0.0, 0.0, 0.0], np.float32))
    assert info["bucket_fill"] == 0.0
    assert abs(env.world.q[0] - swing0) < 0.01  # the side plates do not cut


def test_curled_bucket_plunged_takes_no_soil_and_stays_on_the_surface():
    m = gym.make("motiongym/Excavator-v1").unwrapped.m
    env = _env(q0=_pose((6.0, 0.0, 0.6), -2.9, m))  # curled: opening up
    info = _drive(env, (0.0, 0.0, -0.5), seconds=2.0)  # plunge 1 m
    assert info["bucket_fill"] == 0.0
    assert _edge_depth(env) < 0.05


def test_a_forward_cut_fills_the_bucket_in_loose_volume_and_conserves_soil():
    m = gym.make("motiongym/Excavator-v1").unwrapped.m
    env = _env(q0=_pose((7.5, 0.0, 0.01), -1.0, m))  # opening toward the machine and down
    world = env.world
    total0 = world.soil_volume()
    _drive(env, (-0.35, 0.0, -0.2), seconds=1.5)  # into the soil, edge first
    info = _drive(env, (-0.5, 0.0, 0.0), beta_rate=-0.3, seconds=3.0)  # drag toward the machine
    assert info["bucket_fill"] > 0.3
    bank = -(world.terrain.volume())  # the ground was flat at z = 0
    assert info["bucket_fill"] == pytest.approx(m.swell * bank, rel=1e-9)
    assert world.soil_volume() == pytest.approx(total0, abs=1e-9)


def test_resistance_grows_with_depth_and_stops_the_machine():
    m = gym.make("motiongym/Excavator-v1").unwrapped.m
    forces, fractions = [], []
    for depth in (0.3, 0.8):
        env = _env(q0=_pose((7.0, 0.0, -depth), -1.0, m))
        info = _drive(env, (-0.5, 0.0, 0.0), seconds=0.3)
        forces.append(info["cut_force"])
        fractions.append(info["advance_fraction"])
    assert forces[0] > 0.0 and forces[1] > 2 * forces[0]  # d^2 and d terms
    assert fractions[0] > fractions[1]
    # Beyond the stall depth (1.35 m for the loam and a 1.2 m bucket) nothing moves.
    env = _env(q0=_pose((7.0, 0.0, -1.6), -1.0, m))
    x0 = env.world.tip[0]
    _drive(env, (-0.5, 0.0, 0.0), seconds=1.0)
    assert abs(env.world.tip[0] - x0) < 0.02


def test_full_bucket_dragged_through_soil_pushes_it_and_conserves_it():
    m = gym.make("motiongym/Excavator-v1").unwrapped.m
    env = _env(q0=_pose((8.0, 0.0, -0.3), -1.0, m))
    world = env.world
    world.fill = m.bucket_capacity  # a full bucket
    total0 = world.soil_volume()
    pushed = 0.0
    for _ in range(30):
        info = _drive(env, (-0.5, 0.0, 0.0), seconds=0.1)
        pushed += info["pushed_soil"]
    assert pushed > 0.3  # the soil ahead is pushed, not ghosted through
    assert info["bucket_fill"] == pytest.approx(m.bucket_capacity)
    assert world.soil_volume() == pytest.approx(total0, abs=1e-9)


def test_boom_lowered_from_rest_keeps_every_part_above_the_ground():
    for task in ("dig", "reach"):
        env = _env(task, q0=gym.make("motiongym/Excavator-v1").unwrapped.m.q_ready)
        for _ in range(20):  # boom down, full rate, 2 s
            env.step(np.array([0.0, -1.0, 0.0, 0.0], np.float32))
        assert _edge_depth(env) < 0.05
        pin = kin.link_frames(np.array(env.world.q), env.m)[3][:3, 3]
        assert pin[2] > -0.05  # the bucket pin stays above the surface
        for p in env.world._pose_now.under():
            assert p[2] > -0.05


# ----------------------------------------------------------------- collision bodies
def _bucket_corner(q, m, side=1.0, back=0.0):
    """A corner of the cutting edge (side +-1), moved ``back`` behind the opening."""
    frame = kin.forward(np.array(q), m)
    z_axis, y_axis = frame[:3, 2], frame[:3, 1]  # joint axis; y = z x x = -n
    return frame[:3, 3] + side * 0.5 * m.bucket_width * z_axis + back * y_axis


def test_pipe_beside_the_boom_plane_touches_the_cutting_edge_corner():
    """The issue's case: the pipe 0.65 m beside the boom plane at the tip's height."""
    m = gym.make("motiongym/Excavator-v1").unwrapped.m
    q = _pose((6.0, 0.0, 0.5), -1.6, m)
    tip = kin.forward(np.array(q), m)[:3, 3]
    for offset, touching in ((0.65, True), (0.6 + 0.15, True), (0.6 + 0.15 + 0.1, False)):
        pipe = Pipe(
            (tip[0] - 5, tip[1] - offset, tip[2]), (tip[0] + 5, tip[1] - offset, tip[2]), 0.15
        )
        env = _env(pipe=pipe, q0=q)
        assert (env.world.pipe_clear <= 0.0) == touching, offset
        if touching:
            assert env.step(np.zeros(4, np.float32))[2]  # contact ends the episode


@pytest.mark.parametrize("part", ["edge corner", "bucket back", "stick", "boom"])
def test_each_part_touching_the_truck_is_a_contact(part):
    m = gym.make("motiongym/Excavator-v1").unwrapped.m
    q = _pose((6.5, 0.0, 3.5), -1.6, m)
    frames = kin.link_frames(np.array(q), m)
    if part == "edge corner":
        point = _bucket_corner(q, m, side=1.0)
    elif part == "bucket back":
        point = _bucket_corner(q, m, side=1.0, back=0.85)
    elif part == "stick":  # the stick's surface 0.25 m (inside its 0.30 m body) below its middle
        point = 0.5 * (frames[2][:3, 3] + frames[3][:3, 3]) - np.array([0, 0, 0.25])
    else:
        point = 0.5 * (frames[1][:3, 3] + frames[2][:3, 3]) - np.array([0, 0, 0.35])
    # A truck whose rim is 1 cm above the point, the point inside its footprint.
    truck = Truck(point[0], point[1], 0.0, 0.3, 0.3, point[2] + 0.01)
    env = _env(truck=truck, q0=q)
    assert env.world.truck_clear <= 0.0
    truck = Truck(point[0], point[1], 0.0, 0.3, 0.3, point[2] - 0.6)
    env = _env(truck=truck, q0=q)
    assert env.world.truck_clear > 0.0


def test_bucket_in_the_tracks_is_a_self_contact():
    m = gym.make("motiongym/Excavator-v1").unwrapped.m
    inside = within = 0
    rng = np.random.default_rng(3)
    env = _env(q0=m.q_ready)
    for q in rng.uniform(m.q_min, m.q_max, size=(400, 4)):
        tip = kin.forward(q, m)[:3, 3]
        corner = _bucket_corner(q, m, side=1.0)
        (x0, x1), (y0, y1), (z0, z1) = bodies.TRACKS
        in_tracks = any(
            x0 <= p[0] + m.L0 <= x1 and y0 <= p[1] <= y1 and z0 <= p[2] <= z1 for p in (tip, corner)
        )
        if not in_tracks:
            continue
        inside += 1
        env.world.q = list(q)
        env.world._forward()
        env.world._clearances()
        within += env.world.self_clear <= 0.0
    assert inside > 0 and within == inside


def test_house_corner_touching_the_truck_is_a_contact():
    m = gym.make("motiongym/Excavator-v1").unwrapped.m
    q = (math.pi, 0.6, -1.9, -1.6)  # house tail toward +x
    (x0, _), (_, y1), (z0, _) = bodies.HOUSE
    corner = np.array([-x0 - m.L0, -y1, z0 + 0.5])  # the tail corner turned by pi
    truck = Truck(corner[0] + 0.29, corner[1], 0.0, 0.3, 0.3, 3.0)
    env = _env(truck=truck, q0=q)
    assert env.world.truck_clear <= 0.0


# ----------------------------------------------------------------- hydraulics
def test_hydraulics_limit_acceleration_and_share_the_pump():
    env = _env(task="reach", q0=(0.0, 0.3, -1.5, -1.0))
    m = env.m
    env.step(np.array([0.0, 1.0, 0.0, 0.0], np.float32))
    assert env.world.qdot[1] == pytest.approx(m.accel_max[1] * env.dt)  # not full rate at once
    for _ in range(5):
        env.step(np.array([0.0, 1.0, 0.0, 0.0], np.float32))
    assert env.world.qdot[1] == pytest.approx(m.rate_max[1])  # alone: full rate
    for _ in range(10):
        env.step(np.array([0.0, 1.0, -1.0, 0.0], np.float32))  # boom and stick: one pump
    flow = sum(
        abs(r) / rm * s for r, rm, s in zip(env.world.qdot, m.rate_max, m.pump_share, strict=True)
    )
    assert flow == pytest.approx(1.0)
    assert env.world.qdot[1] < m.rate_max[1]
    # Ablation: without the shared flow both run at full rate.
    env = _env(task="reach", q0=(0.0, 0.3, -1.5, -1.0), machine={"pump_share": (0, 0, 0, 0)})
    for _ in range(10):
        env.step(np.array([0.0, 1.0, -1.0, 0.0], np.float32))
    assert env.world.qdot[1] == pytest.approx(m.rate_max[1])


# ----------------------------------------------------------------- slope
@pytest.mark.parametrize("env_id", ["motiongym/Excavator-v1", "motiongym/ExcavatorReach-v1"])
def test_machine_on_a_slope_is_the_papers_base_pose(env_id):
    env = gym.make(env_id).unwrapped
    rolls = []
    for seed in range(8):
        obs, _ = env.reset(seed=seed)
        base = env.scene.base
        rolls.append(base[0])
        assert max(abs(base[0]), abs(base[1])) <= 0.1
        h = kin.base_pose((0.0, 0.0, 0.0), base)
        expected = kin.forward(np.array(env.world.q), env.m, base=h)[:3, 3]
        np.testing.assert_allclose(env.world.tip, expected, atol=1e-9)
        np.testing.assert_allclose(obs[env.layout["base"]], base[:2], atol=1e-6)
        # The tracks stand on the ground: the plane under the base's corners.
        for x, y in ((2.0, 1.4), (-2.0, -1.4)):
            corner = h[:3, :3] @ np.array([x, y, 0.0])
            assert env.world.terrain.height_at(corner[0], corner[1]) == pytest.approx(
                corner[2], abs=0.02
            )
    assert np.std(rolls) > 0.01


# ----------------------------------------------------------------- ablations
def test_ablation_without_the_cutting_cone_a_heel_first_push_fills(monkeypatch):
    from motiongym.envs.excavator import digging

    monkeypatch.setattr(digging, "CUT_CONE", -1.0)  # every motion into the soil cuts
    m = gym.make("motiongym/Excavator-v1").unwrapped.m
    env = _env(q0=_pose((6.0, 0.0, 0.01), -1.6, m))
    info = _drive(env, (0.5, 0.0, -0.15), seconds=3.0)
    assert info["bucket_fill"] > 0.1  # the v0 behaviour the issue reported


def test_ablation_without_the_stall_the_machine_cuts_beyond_its_force():
    m = gym.make("motiongym/Excavator-v1").unwrapped.m
    env = _env(q0=_pose((7.0, 0.0, -1.6), -1.0, m), machine={"dig_force": 1e7})
    x0 = env.world.tip[0]
    _drive(env, (-0.5, 0.0, 0.0), seconds=1.0)
    assert x0 - env.world.tip[0] > 0.2


def test_ablation_swell_one_counts_bank_volume():
    m = gym.make("motiongym/Excavator-v1").unwrapped.m
    env = _env(q0=_pose((7.5, 0.0, 0.01), -1.0, m), machine={"swell": 1.0})
    _drive(env, (-0.35, 0.0, -0.2), seconds=1.5)
    info = _drive(env, (-0.5, 0.0, 0.0), beta_rate=-0.3, seconds=2.0)
    assert info["bucket_fill"] == pytest.approx(-env.world.terrain.volume(), rel=1e-9)


@pytest.mark.parametrize("seed", [0, 1])
def test_random_play_conserves_soil_and_keeps_parts_out_of_the_ground(seed):
    env = gym.make("motiongym/Excavator-v1").unwrapped
    env.reset(seed=seed)
    world = env.world
    total = world.soil_volume()
    rng = np.random.default_rng(seed)
    for _ in range(300):
        _, _, terminated, _, info = env.step(rng.uniform(-1, 1, 4).astype(np.float32))
        assert world.soil_volume() == pytest.approx(total, abs=1e-9)
        assert world._penetration(world._pose_now) < 0.05
        assert 0.0 <= info["bucket_fill"] <= env.m.bucket_capacity + 1e-12
        if terminated:
            env.reset(seed=seed + 10)
            total = world.soil_volume()


def _random_box(rng):
    a = np.linalg.qr(rng.normal(size=(3, 3)))[0]
    return bodies.Box(
        tuple(rng.uniform(-2, 2, 3)), tuple(map(tuple, a)), tuple(rng.uniform(0.2, 1.0, 3))
    )


def test_box_distance_against_sampled_surfaces_and_its_bound():
    rng = np.random.default_rng(0)
    grid = np.linspace(-1.0, 1.0, 9)
    unit = np.array([(x, y, z) for x in grid for y in grid for z in grid])
    for _ in range(30):
        p, q = _random_box(rng), _random_box(rng)
        exact = bodies.box_to_box(p, q)
        assert bodies.separation(p, q) <= exact + 1e-9
        points = [
            np.array(b.centre) + (unit * b.half) @ np.array(b.axes) for b in (p, q)
        ]  # points filling each box
        gaps = np.linalg.norm(points[0][:, None] - points[1][None], axis=-1).min()
        assert exact <= gaps + 1e-9
        if exact > 0.0:  # the closest pair is within a grid step of the samples
            assert gaps - exact < 0.25 * (max(p.half) + max(q.half))


def test_bucket_body_contains_the_bucket():
    m = gym.make("motiongym/Excavator-v1").unwrapped.m
    rng = np.random.default_rng(1)
    env = _env(q0=m.q_ready)
    for q in rng.uniform(m.q_min, m.q_max, size=(50, 4)):
        env.world.q = list(q)
        env.world._forward()
        box = env.world._bodies(("bucket",))["bucket"]
        pin = kin.link_frames(q, m)[3][:3, 3]
        points = [pin, kin.forward(q, m)[:3, 3]]
        points += [_bucket_corner(q, m, side, back) for side in (-1, 1) for back in (0.0, 0.85)]
        points += list(env.world._pose_now.under()[-6:])  # the shell's underside samples
        for point in points:
            assert box.contains(point)
