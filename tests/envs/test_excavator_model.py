"""Excavator kinematics (eq. 1-5), the MuJoCo model, soil and clearances."""

from __future__ import annotations

import math
import os

os.environ.setdefault("MUJOCO_GL", "egl")

import mujoco  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

from motiongym.envs.excavator import kinematics as kin  # noqa: E402
from motiongym.envs.excavator.config import DEFAULT_MACHINE as M  # noqa: E402
from motiongym.envs.excavator.config import Machine, machine_from_kwargs  # noqa: E402
from motiongym.envs.excavator.obstacles import (  # noqa: E402
    Pipe,
    Truck,
    pipe_clearance,
    segment_box_distance,
    truck_clearance,
)
from motiongym.envs.excavator.render_scene import build_model  # noqa: E402
from motiongym.envs.excavator.scenes import (  # noqa: E402
    GRID_CELL,
    GRID_ORIGIN,
    GRID_SHAPE,
    ZONE_MARGIN,
    DigZone,
)
from motiongym.envs.excavator.soil import Terrain, cutting_force, speed_fraction  # noqa: E402
from motiongym.envs.geometry import (
    closest_points_between_segments,  # noqa: E402
    segment_distance,  # noqa: E402
)


def _rot(axis: str, a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return {
        "x": np.array([[1, 0, 0], [0, c, -s], [0, s, c]]),
        "y": np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]]),
        "z": np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]]),
    }[axis]


def _random_q(rng: np.random.Generator, n: int) -> np.ndarray:
    return rng.uniform(M.q_min, M.q_max, size=(n, 4))


def test_base_rotation_is_rz_ry_rx_with_the_typo_fixed():
    phi, theta, psi = 0.3, -0.2, 1.1
    r = kin.base_rotation(phi, theta, psi)
    np.testing.assert_allclose(r, _rot("z", psi) @ _rot("y", theta) @ _rot("x", phi), atol=1e-12)
    assert r[0, 0] == pytest.approx(math.cos(psi) * math.cos(theta))  # printed: c(theta)c(phi)
    np.testing.assert_allclose(r @ r.T, np.eye(3), atol=1e-12)


def test_dh_transform_is_craigs_modified_convention():
    alpha, a, d, theta = 0.7, 1.3, -0.4, 0.9
    rx, rz = np.eye(4), np.eye(4)
    rx[:3, :3], rz[:3, :3] = _rot("x", alpha), _rot("z", theta)
    tx, tz = np.eye(4), np.eye(4)
    tx[0, 3], tz[2, 3] = a, d
    np.testing.assert_allclose(kin.dh_transform(alpha, a, d, theta), rx @ tx @ rz @ tz, atol=1e-12)


def test_rest_pose_geometry_by_hand():
    # theta2 = theta3 = theta4 = 0: everything along x at the boom-foot height.
    h = kin.forward(np.zeros(4), M)
    assert h[:3, 3] == pytest.approx([-M.L0 + M.L1 + M.L2 + M.L3 + M.L4, -M.d2, M.d1])
    # Boom straight up: the tip rises by L2.
    up = kin.forward(np.array([0, math.pi / 2, -math.pi / 2, 0]), M)
    assert up[:3, 3] == pytest.approx([M.L1 + M.L3 + M.L4, 0.0, M.d1 + M.L2])


def test_scalar_chain_equals_matrix_product_and_base_pose_applies():
    rng = np.random.default_rng(0)
    base = kin.base_pose((3.0, -2.0, 0.5), (0.05, -0.03, 0.8))
    for q in _random_q(rng, 50):
        h = kin.forward(q, M)
        assert kin.arm_points(*q, M)[3] == pytest.approx(tuple(h[:3, 3]), abs=1e-12)
        np.testing.assert_allclose(kin.tip_frame(q, M), h, atol=1e-12)
        np.testing.assert_allclose(kin.forward(q, M, base), base @ h, atol=1e-12)
        # The bucket's x axis has elevation beta = q2 + q3 + q4.
        assert math.asin(h[2, 0]) == pytest.approx(
            math.asin(math.sin(kin.bucket_angle(q))), abs=1e-12
        )


def test_tip_jacobian_matches_central_differences():
    rng = np.random.default_rng(1)
    for q in _random_q(rng, 20):
        dx, dp = kin.tip_jacobian(q, M)
        for j in range(4):
            e = np.zeros(4)
            e[j] = 1e-6
            hp, hm = kin.forward(q + e, M), kin.forward(q - e, M)
            np.testing.assert_allclose(dx[:, j], (hp[:3, 0] - hm[:3, 0]) / 2e-6, atol=1e-7)
            np.testing.assert_allclose(dp[:, j], (hp[:3, 3] - hm[:3, 3]) / 2e-6, atol=1e-6)


def test_desired_pose_matches_forward_kinematics():
    machine = Machine(L0=0.3, d2=0.2)  # offsets exercised
    rng = np.random.default_rng(2)
    for q in rng.uniform(machine.q_min, machine.q_max, size=(20, 4)):
        h = kin.forward(q, machine)
        np.testing.assert_allclose(
            kin.desired_pose(h[:3, 3], kin.bucket_angle(q), machine), h, atol=1e-9
        )


def test_mujoco_tip_equals_dh_forward_kinematics():
    for machine in (M, Machine(L0=0.3, d2=0.25)):
        model = build_model(machine, with_world=False)
        data = mujoco.MjData(model)
        site = model.site("tip").id
        rng = np.random.default_rng(3)
        for q in rng.uniform(machine.q_min, machine.q_max, size=(30, 4)):
            data.qpos[:4] = q
            mujoco.mj_kinematics(model, data)
            h = kin.forward(q, machine)
            np.testing.assert_allclose(data.site_xpos[site], h[:3, 3], atol=1e-9)
            np.testing.assert_allclose(data.site_xmat[site].reshape(3, 3), h[:3, :3], atol=1e-9)


def test_machine_overrides_are_checked():
    assert machine_from_kwargs({"L2": 6.0}).L2 == 6.0
    with pytest.raises(ValueError, match="unknown machine parameter"):
        machine_from_kwargs({"boom": 6.0})


# ------------------------------------------------------------------ soil
def test_fundamental_earthmoving_equation_known_values():
    assert cutting_force(0.0, 1.2, M) == 0.0
    assert cutting_force(0.5, 1.2, M) == pytest.approx(1.2 * (18e3 * 1.5 * 0.25 + 10e3 * 2.5 * 0.5))
    assert cutting_force(1.0, 1.2, M) == pytest.approx(62_400.0)
    assert speed_fraction(-0.1, 1.2, M) == 1.0
    assert speed_fraction(0.5, 1.2, M) == pytest.approx(1 - 23_100 / 100e3)
    assert speed_fraction(3.0, 1.2, M) == M.min_speed_fraction
    depths = np.linspace(0, 2, 50)
    fractions = [speed_fraction(d, 1.2, M) for d in depths]
    assert all(a >= b for a, b in zip(fractions, fractions[1:], strict=False))


def _flat(h: float = 0.0) -> Terrain:
    return Terrain(np.full((100, 100), h), (-5.0, -5.0), 0.1)


def test_carving_a_strip_removes_its_volume_and_conserves_soil():
    t = _flat()
    edge0 = (np.array([2.0, -0.6]), np.array([2.0, 0.6]))
    edge1 = (np.array([1.0, -0.6]), np.array([1.0, 0.6]))
    before = t.volume()
    removed = t.carve(edge0, edge1, -0.5, -0.5, free_capacity=10.0)
    # A 1.2 m x 1.0 m strip 0.5 m deep: 12 x 10 cells of 0.1 m.
    assert removed == pytest.approx(0.6, rel=1e-9)
    assert before - t.volume() == pytest.approx(removed, abs=1e-9)
    assert t.h.min() == pytest.approx(-0.5)
    assert t.carve(edge0, edge1, -0.5, -0.5, free_capacity=10.0) == 0.0  # already cut


def test_a_sweep_over_the_ground_changes_nothing_and_one_into_it_cuts():
    t = _flat()
    t.h[30:40, 40:60] = 0.2  # a mound under the sweep's end
    edge0 = (np.array([-2.0, -0.6]), np.array([-2.0, 0.6]))
    edge1 = (np.array([-1.0, -0.6]), np.array([-1.0, 0.6]))
    before = t.h.copy()
    assert t.carve(edge0, edge1, 0.3, 0.2, free_capacity=10.0) == 0.0
    assert t.version == 0 and t.last_cut_depth == 0.0 and t.last_cut is None
    np.testing.assert_array_equal(t.h, before)
    # Down to 0.1 m at the end: 12 cells across, and along the second half cell
    # 30 + m down to its deeper sample, 0.3 - 0.2 (2m + 1.5) / 20, for m = 5..9.
    removed = t.carve(edge0, edge1, 0.3, 0.1, free_capacity=10.0)
    depths = [0.2 - (0.3 - 0.2 * (2 * m + 1.5) / 20) for m in range(5, 10)]
    assert removed == pytest.approx(12 * 0.01 * sum(depths), rel=1e-9) and t.version == 1
    assert t.h[30:40, 40:60].min() == pytest.approx(0.2 - depths[-1]) and t.h.max() == 0.2


def test_a_full_bucket_takes_only_its_free_capacity():
    t = _flat()
    edge0 = (np.array([2.0, -0.6]), np.array([2.0, 0.6]))
    edge1 = (np.array([0.0, -0.6]), np.array([0.0, 0.6]))
    before = t.volume()
    assert t.carve(edge0, edge1, -0.5, -0.5, free_capacity=0.25) == pytest.approx(0.25)
    assert before - t.volume() == pytest.approx(0.25)


def test_deposit_conserves_volume():
    t = _flat()
    t.deposit(1.0, 1.0, 0.3)
    assert t.volume() == pytest.approx(0.3)


# ------------------------------------------------------------ clearances
def _dense(p0, p1, q0, q1, n=400):
    s = np.linspace(0, 1, n)
    a = p0 + s[:, None] * (p1 - p0)
    b = q0 + s[:, None] * (q1 - q0)
    return np.min(np.linalg.norm(a[:, None] - b[None], axis=-1))


def test_pipe_clearance_known_case():
    pipe = Pipe(a=(0.0, -5.0, -2.0), b=(0.0, 5.0, -2.0), radius=0.15)
    link = [(-1.0, 0.0, 0.0), (1.0, 0.0, -1.0)]
    # Closest at x = 0.6 on the segment: distance sqrt(0.6^2 + 1.2^2) to the pipe's axis.
    assert pipe_clearance(link, [0.45], pipe) == pytest.approx(
        math.sqrt(1.8) - 0.45 - 0.15, abs=1e-9
    )


def test_truck_clearance_known_cases_and_dense_sampling():
    truck = Truck(cx=0.0, cy=6.0, yaw=0.3, half_length=2.5, half_width=1.2, height=2.8)
    r = [0.0]
    above = truck_clearance([(0.0, 6.0, 4.0), (0.5, 6.2, 4.5)], r, truck)
    assert above == pytest.approx(1.2)
    through = truck_clearance([(0.0, 6.0, 5.0), (0.0, 6.0, -1.0)], r, truck)
    assert through == 0.0
    rng = np.random.default_rng(4)
    g = np.stack(
        np.meshgrid(
            np.linspace(-2.5, 2.5, 26), np.linspace(-1.2, 1.2, 13), np.linspace(0, 2.8, 15)
        ),
        axis=-1,
    ).reshape(-1, 3)  # a 0.2 m grid filling the box, in its frame
    c, s = math.cos(truck.yaw), math.sin(truck.yaw)
    box_pts = np.column_stack(
        [truck.cx + c * g[:, 0] - s * g[:, 1], truck.cy + s * g[:, 0] + c * g[:, 1], g[:, 2]]
    )
    for _ in range(20):
        p0, p1 = rng.uniform([-6, 0, 0], [6, 12, 6], size=(2, 3))
        exact = truck_clearance([p0, p1], r, truck)
        s = np.linspace(0, 1, 300)[:, None]
        seg = p0 + s * (p1 - p0)
        sampled = np.min(np.linalg.norm(seg[:, None] - box_pts[None], axis=-1))
        assert exact <= sampled + 1e-9
        if exact > 0:
            assert exact == pytest.approx(sampled, abs=0.2)


def _box_distance_by_edges(p0, p1, low, high):
    """Segment-box distance the general way: 0 if the slabs' parameter ranges
    overlap in [0, 1] (the segment meets the box), else the closest of the 12
    edges (:mod:`motiongym.envs.geometry`) and the two end points."""
    d = p1 - p0
    with np.errstate(divide="ignore", invalid="ignore"):
        t_a, t_b = (low - p0) / d, (high - p0) / d
    inside = (p0 >= low) & (p0 <= high)  # an axis the segment runs along
    enter = np.where(d == 0, np.where(inside, -np.inf, np.inf), np.minimum(t_a, t_b))
    leave = np.where(d == 0, np.where(inside, np.inf, -np.inf), np.maximum(t_a, t_b))
    if max(enter.max(), 0.0) <= min(leave.min(), 1.0):
        return 0.0
    corners = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)])
    corners = np.where(corners == 1, high, low)  # (8, 3); index bits x, y, z
    pairs = [(i, i | bit) for i in range(8) for bit in (1, 2, 4) if not i & bit]  # the 12 edges
    e0, e1 = corners[[a for a, _ in pairs]], corners[[b for _, b in pairs]]
    edges, _, _ = closest_points_between_segments(p0, p1, e0, e1)
    ends = [np.linalg.norm(p - np.clip(p, low, high)) for p in (p0, p1)]
    return min(edges.min(), *ends)


def test_segment_box_distance_equals_the_edge_construction():
    rng = np.random.default_rng(11)
    low, high = np.array([-2.5, -1.2, 0.0]), np.array([2.5, 1.2, 2.8])
    kinds = {"meets": 0, "apart": 0}
    for k in range(600):
        p0, p1 = rng.uniform([-6, -5, -2], [6, 5, 6], size=(2, 3))
        if k % 5 == 0:  # along one axis, and a point
            p1 = p0.copy()
            p1[k % 3] += rng.uniform(-6, 6) if k % 10 else 0.0
        if k % 7 == 0:  # an end point on a face plane
            p0[k % 3] = high[k % 3]
        got = segment_box_distance(tuple(p0), tuple(p1), tuple(low), tuple(high))
        want = _box_distance_by_edges(p0, p1, low, high)
        assert got == pytest.approx(want, abs=1e-12)
        kinds["meets" if want == 0.0 else "apart"] += 1
    assert min(kinds.values()) > 100


def test_segment_box_distance_known_cases():
    low, high = (0.0, 0.0, 0.0), (2.0, 1.0, 1.0)
    # Over the top, parallel to it: the height above.
    assert segment_box_distance((-1.0, 0.5, 3.0), (3.0, 0.5, 3.0), low, high) == 2.0
    # Diagonal past an edge: the segment x + y = 4 at z = 0.5 is sqrt(2)/2 from (2, 1).
    got = segment_box_distance((4.0, 0.0, 0.5), (0.0, 4.0, 0.5), low, high)
    assert got == pytest.approx(math.sqrt(0.5), abs=1e-15)
    # A point beyond a corner, and a segment through the box.
    assert segment_box_distance((3.0, 2.0, 2.0), (3.0, 2.0, 2.0), low, high) == pytest.approx(
        math.sqrt(3.0)
    )
    assert segment_box_distance((-1.0, -1.0, -1.0), (3.0, 2.0, 2.0), low, high) == 0.0


def test_truck_clearance_of_a_chain_is_its_closest_capsules():
    rng = np.random.default_rng(12)
    truck = Truck(cx=1.0, cy=6.0, yaw=-0.4, half_length=2.5, half_width=1.2, height=2.8)
    radii = [0.35, 0.25, 0.45]
    for _ in range(300):
        pts = [tuple(p) for p in rng.uniform([-6, 0, -1], [6, 12, 6], size=(4, 3))]
        links = zip(pts[:3], pts[1:], radii, strict=True)
        each = [truck_clearance([a, b], [r], truck) for a, b, r in links]
        assert truck_clearance(pts, radii, truck) == pytest.approx(min(each), abs=1e-12)


def test_segment_distance_equals_the_shared_routine():
    rng = np.random.default_rng(13)
    for k in range(400):
        p0, p1, q0, q1 = rng.uniform(-3, 3, size=(4, 3))
        if k % 4 == 1:  # parallel, overlapping or not
            q1 = q0 + rng.uniform(-2, 2) * (p1 - p0)
        if k % 4 == 2:  # a point against a segment
            p1 = p0.copy()
        if k % 8 == 3:  # two points
            p1, q1 = p0.copy(), q0.copy()
        want, _, _ = closest_points_between_segments(p0, p1, q0, q1)
        got = segment_distance(tuple(p0), tuple(p1), tuple(q0), tuple(q1))
        assert got == pytest.approx(float(want), abs=1e-12)


def test_pipe_clearance_bounds_only_skip_capsules_that_cannot_be_closest():
    rng = np.random.default_rng(14)
    pipe = Pipe(a=(-4.0, -5.0, -2.0), b=(6.0, 5.0, -2.5), radius=0.15)
    radii = [0.35, 0.25, 0.45]
    for _ in range(200):
        pts = [tuple(p) for p in rng.uniform([-6, -6, -3], [6, 6, 3], size=(4, 3))]
        links = zip(pts[:3], pts[1:], radii, strict=True)
        each = [pipe_clearance([a, b], [r], pipe) for a, b, r in links]
        bounds = [e - s for e, s in zip(each, rng.uniform(0.0, 2.0, 3), strict=True)]
        assert pipe_clearance(pts, radii, pipe) == min(each)
        assert pipe_clearance(pts, radii, pipe, bounds) == min(each)


def test_zone_mask_is_the_strip_test_over_every_cell():
    rng = np.random.default_rng(15)
    xs = GRID_ORIGIN[0] + (np.arange(GRID_SHAPE[0]) + 0.5) * GRID_CELL
    ys = GRID_ORIGIN[1] + (np.arange(GRID_SHAPE[1]) + 0.5) * GRID_CELL
    sizes = []
    for _ in range(40):  # some reach past the map's edge (11 m)
        zone = DigZone(rng.uniform(-math.pi, math.pi), rng.uniform(-2.0, 8.0), 0.0, 0.7)
        zone = DigZone(zone.azimuth, zone.r_near, zone.r_near + rng.uniform(1.0, 7.0), 0.7)
        half = rng.uniform(0.3, 1.0)
        c, s = math.cos(zone.azimuth), math.sin(zone.azimuth)
        along = c * xs[:, None] + s * ys[None, :]
        across = -s * xs[:, None] + c * ys[None, :]
        want = (
            (along >= zone.r_near - ZONE_MARGIN)
            & (along <= zone.r_far + ZONE_MARGIN)
            & (np.abs(across) <= half + ZONE_MARGIN)
        )
        np.testing.assert_array_equal(zone.mask(half), want)
        sizes.append(want.sum())
    assert min(sizes) > 0
