"""Reference velocities of the arm's points: trajectory following and link avoidance
(paper eq. 8-11)."""

from __future__ import annotations

import numpy as np
import pytest

from motiongym.baselines.harvest_arm.redundancy import limited_rates
from motiongym.baselines.harvest_arm.reference_velocity import (
    combine,
    follow_the_leader,
    link_avoidance,
    trajectory_following,
)
from motiongym.envs.geometry import closest_point_on_segment, closest_points_between_segments
from motiongym.envs.harvest_arm.model import ArmKinematics, arm_spec

SPEED, DT, LINK_R = 0.2, 0.05, 0.02


def _follow(kin, spec, v_of_t, mode, steps=60):
    """Drive the gripper along directions ``v_of_t``; the joints' references by ``mode``.

    ``mode``: +1 eq. 8 as printed, -1 its sign flipped, 0 eq. 8 off (zero references).
    """
    q = np.array(spec.home)
    trail, joints = [], []
    for t in range(steps):
        points, jacs = kin.jacobians(q)
        x_dot = SPEED * v_of_t(t)
        refs = follow_the_leader(points, x_dot, mode or 1.0)
        if mode == 0:
            refs[:-1] = 0.0
        rates = limited_rates(
            jacs[-1], x_dot, jacs, refs, np.ones(len(points)), q, spec.limits, spec.speeds, DT
        )
        q = q + rates * DT
        trail.append(points[-1])
        joints.append(points[1:-1])
    return np.array(trail), np.array(joints)


def _trace_error(trail, joints, first):
    """Mean distance of each joint to the gripper's path travelled so far: (P-2,)."""
    errors = []
    for t in range(first, len(trail)):
        d, _ = closest_point_on_segment(joints[t][:, None], trail[None, :t], trail[None, 1 : t + 1])
        errors.append(d.min(axis=1))
    return np.mean(errors, axis=0)


def test_trajectory_following_makes_the_joints_trace_the_gripper_path():
    """Paper Fig. 3: without obstacles the joints trace the gripper's path (eq. 8 ablation).

    Planar 5-DOF arm from its home pose, gripper on an arc: mean joint-to-path
    distance, joints 1-4, 0.374 / 0.221 / 0.119 / 0.066 m with eq. 8, 0.380 /
    0.225 / 0.135 / 0.083 m with zero joint references (eq. 1 alone already
    keeps the last link near the path: the least motion of a rigid link's
    near end is along the link), 0.545 / 0.480 / 0.314 / 0.150 m with the sign
    flipped. On the environment's scenes the difference is larger (see
    :func:`test_ablations_on_fixed_scenes`).
    """
    spec = arm_spec(5, planar=True)
    kin = ArmKinematics(spec)

    def curve(t):
        return np.array([np.cos(-0.3 - 0.02 * t), np.sin(-0.3 - 0.02 * t)])

    printed = _trace_error(*_follow(kin, spec, curve, +1.0), first=30)
    flipped = _trace_error(*_follow(kin, spec, curve, -1.0), first=30)
    off = _trace_error(*_follow(kin, spec, curve, 0), first=30)
    # every joint is closer to the path than with eq. 8 off or with the sign flipped
    assert (printed < off).all() and (printed[2:] < off[2:] - 0.01).all(), (printed, off)
    assert (printed[1:] < flipped[1:] - 0.03).all(), (printed, flipped)


def test_follow_the_leader_is_the_printed_w_d_relative_to_the_point_ahead():
    points = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 0.3], [0.3, 0.0, 0.3], [0.3, 0.2, 0.3]])
    x_dot = SPEED * np.array([0.6, 0.0, 0.8])
    refs = follow_the_leader(points, x_dot)
    w_d = trajectory_following(points, x_dot / SPEED)
    np.testing.assert_allclose(refs[-1], x_dot)
    u = np.diff(points, axis=0) / np.linalg.norm(np.diff(points, axis=0), axis=1)[:, None]
    for i in range(3):
        ahead = refs[i + 1]
        v = ahead / np.linalg.norm(ahead) if np.linalg.norm(ahead) > 0 else ahead
        np.testing.assert_allclose(
            refs[i] - ahead, np.linalg.norm(ahead) * np.cross(np.cross(v, u[i]), u[i]), atol=1e-12
        )
        assert np.linalg.norm(np.cross(refs[i], u[i])) < 1e-12  # along its own link
        assert abs((refs[i] - ahead) @ u[i]) < 1e-12  # relative motion normal to the link
    np.testing.assert_allclose(np.sum(w_d * u, axis=1), 0.0, atol=1e-12)


def _push(spec, obstacle, clearance, link_avoid=True, steps=12):
    """Hold the gripper still, eq. 8 off, and let eq. 9-10 move the arm (a, b, r, is_bar)."""
    kin = ArmKinematics(spec)
    q = np.array(spec.home)
    gripper0 = kin.forward(q)[-1]
    history = []
    for _ in range(steps):
        points, jacs = kin.jacobians(q)
        history.append(clearance(points))
        refs, weights = np.zeros_like(points), np.ones(len(points))
        if link_avoid:
            cp = link_avoidance(points, *obstacle, LINK_R)
            jacs = np.concatenate([jacs[:-1], cp.jacobians(jacs), jacs[-1:]])
            refs = np.concatenate([refs[:-1], combine(0 * cp.w_ob, cp.w_ob, SPEED), refs[-1:]])
            weights = np.concatenate([weights[:-1], 1 + np.linalg.norm(cp.w_ob, axis=1), [1.0]])
        zero = np.zeros(points.shape[1])
        rates = limited_rates(jacs[-1], zero, jacs, refs, weights, q, spec.limits, spec.speeds, DT)
        q = q + rates * DT
    history.append(clearance(kin.forward(q)))
    return np.array(history), np.linalg.norm(kin.forward(q)[-1] - gripper0)


@pytest.mark.parametrize(("link", "s"), [(1, 0.5), (2, 0.85), (3, 0.9)])
def test_a_point_obstacle_by_any_part_of_a_link_pushes_the_link_away(link, s):
    """Paper Fig. 5, at the link's closest point (here near its distal end), eq. 9 ablation."""
    spec = arm_spec(5, planar=True)
    home = ArmKinematics(spec).forward(np.array(spec.home))
    u = home[link + 1] - home[link]
    normal = np.array([-u[1], u[0]]) / np.linalg.norm(u)
    centre = home[link] + s * u + 0.07 * normal
    obstacle = (centre[None], centre[None], np.array([0.015]), np.array([False]))

    def clearance(points):
        d, _ = closest_point_on_segment(centre, points[:-1], points[1:])
        return d.min() - 0.015 - LINK_R

    cp = link_avoidance(home, *obstacle, LINK_R)
    mine = cp.link == link
    assert cp.s[mine] == pytest.approx(s, abs=1e-9)
    assert cp.w_ob[mine][0] @ normal < 0  # away from the obstacle
    history, drift = _push(spec, obstacle, clearance)
    without, _ = _push(spec, obstacle, clearance, link_avoid=False)
    assert history[-1] > history[0] + 0.02
    assert abs(without[-1] - without[0]) < 1e-9  # nothing else moves the arm
    assert drift < 0.01


@pytest.mark.parametrize("s", [0.5, 0.9])
def test_a_bar_obstacle_across_any_part_of_a_link_pushes_the_link_away(s):
    """Paper Fig. 6: a branch crossing the forearm of the 7-DOF arm (eq. 10 ablation)."""
    spec = arm_spec(7, planar=False)
    home = ArmKinematics(spec).forward(np.array(spec.home))
    elbow, wrist = home[2], home[3]
    at = elbow + s * (wrist - elbow)
    a, b = at + [0.0, 0.06, -0.2], at + [0.0, 0.06, 0.2]  # upright, 6 cm to the side
    obstacle = (a[None], b[None], np.array([0.008]), np.array([True]))

    def clearance(points):
        d, _, _ = closest_points_between_segments(points[:-1], points[1:], a, b)
        return d.min() - 0.008 - LINK_R

    cp = link_avoidance(home, *obstacle, LINK_R)
    forearm = cp.link == 2
    assert cp.s[forearm] == pytest.approx(s, abs=0.02)
    assert cp.w_ob[forearm][0][1] < 0  # pushed to -y, away from the bar
    history, drift = _push(spec, obstacle, clearance)
    assert history[-1] > history[0] + 0.02
    assert drift < 0.01
    # a bar's end near a link acts too (the closest points need not be interior)
    end_a, end_b = wrist + [0.0, 0.06, 0.0], wrist + [0.0, 0.4, 0.0]
    near_end = link_avoidance(home, end_a[None], end_b[None], np.array([0.008]), np.array([True]))
    assert len(near_end) and (near_end.w_ob[:, 1] < 0).all()


def test_eq11_normalises_only_sums_longer_than_one():
    w_d = np.array([[0.6, 0.0], [0.1, 0.0]])
    w_ob = np.array([[0.0, 3.0], [0.0, 0.2]])
    out = combine(w_d, w_ob, SPEED)
    assert np.linalg.norm(out[0]) == pytest.approx(SPEED)
    np.testing.assert_allclose(out[1], SPEED * np.array([0.1, 0.2]))
