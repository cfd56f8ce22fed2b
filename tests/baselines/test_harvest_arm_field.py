"""The gripper's safe path by the potential field (paper eq. 2-7) and the virtual plane."""

from __future__ import annotations

import numpy as np
import pytest

from motiongym.baselines.harvest_arm.potential_field import (
    AVOIDANCE,
    TARGET,
    TRAJECTORY,
    eta_from_eq6,
    field_direction,
    obstacle_magnitude,
    plan_path,
    target_magnitude,
)
from motiongym.envs.geometry import closest_point_on_segment

SPEED, DT, LINK_R = 0.2, 0.05, 0.02


@pytest.mark.parametrize("params", [TRAJECTORY, TARGET, AVOIDANCE])
def test_eq6_eta_gives_m_at_k_rho0(params):
    assert obstacle_magnitude(params.k_rho0, params) == pytest.approx(params.m)
    assert obstacle_magnitude(params.rho0 + 1e-9, params) == 0.0
    assert obstacle_magnitude(params.rho0, params) == pytest.approx(0.0, abs=1e-12)
    assert params.eta == pytest.approx(eta_from_eq6(params.m, params.k_rho0, params.rho0))


def test_table_1_values_and_the_target_term():
    assert TRAJECTORY.eta == pytest.approx(0.6 * 0.1**2 / (10 - 5))
    assert target_magnitude(0.2) == pytest.approx(1.0 + 1.0)  # 1 + m at k d0
    assert target_magnitude(0.5) == 1.0
    with pytest.raises(ValueError, match="k\\*rho0"):
        eta_from_eq6(0.6, 0.3, 0.2)


def test_path_without_obstacles_is_the_straight_line_with_even_steps():
    empty = np.zeros((0, 3))
    path = plan_path(np.zeros(3), np.array([0.3, 0.4, 0.0]), empty, empty, np.zeros(0))
    np.testing.assert_allclose(path[-1], [0.3, 0.4, 0.0])
    assert np.abs(np.cross(path, [0.6, 0.8, 0.0])).max() < 1e-9  # on the line
    steps = np.linalg.norm(np.diff(path[:-1], axis=0), axis=1)
    np.testing.assert_allclose(steps, SPEED * DT, rtol=1e-6)


def test_path_goes_around_a_sphere_on_the_straight_line():
    start, fruit = np.array([0.0, 0.0]), np.array([0.6, 0.0])
    centre, r = np.array([[0.3, 0.01]]), np.array([0.02])
    path = plan_path(start, fruit, centre, centre, r, gripper_radius=LINK_R)
    np.testing.assert_allclose(path[-1], fruit)
    clearance = np.linalg.norm(path - centre, axis=1) - r - LINK_R
    assert clearance.min() > 0.05  # the straight line would hit it
    # the field pushes away from the obstacle: below it (it sits above the line)
    assert path[:, 1].min() < -0.05
    v = field_direction(np.array([0.2, 0.0]), fruit, centre, centre, r, LINK_R)
    assert np.linalg.norm(v) == pytest.approx(1.0) and v[1] < 0


def test_a_local_minimum_is_escaped_or_reported():
    """An obstacle exactly between gripper and fruit: the plain eq. 7 stalls before it."""
    start, fruit = np.array([0.0, 0.0]), np.array([0.6, 0.0])
    centre, r = np.array([[0.4, 0.0]]), np.array([0.03])
    report = {}
    stuck = plan_path(
        start, fruit, centre, centre, r, gripper_radius=LINK_R, escape=False,
        virtual_plane=False, report=report,
    )  # fmt: skip
    assert np.linalg.norm(stuck[-1] - fruit) > 0.1  # stopped in front of the obstacle
    assert stuck[-1][0] < 0.4
    assert report == {"stalled": True, "escapes": 0}
    path = plan_path(
        start, fruit, centre, centre, r, gripper_radius=LINK_R, virtual_plane=False, report=report
    )
    assert report["escapes"] >= 1
    np.testing.assert_allclose(path[-1], fruit)
    clearance = np.linalg.norm(path - centre, axis=1) - r - LINK_R
    assert clearance.min() > 0.03
    assert np.linalg.norm(np.diff(path, axis=0), axis=1).max() < 2 * SPEED * DT


@pytest.mark.parametrize("dim", [2, 3])
def test_virtual_plane_turns_the_obstacle_terms_across_the_way(dim):
    """The paper's "20-45 degrees" for m = 0.4-1: the obstacle term is normal to the target term."""
    start, fruit = np.zeros(dim), np.eye(dim)[0] * 0.6
    x, r = start, np.array([0.0])
    centre = (np.eye(dim)[0] * 0.06 + np.eye(dim)[1] * 0.08)[None]  # rho = k rho0, ahead
    v = field_direction(x, fruit, centre, centre, r)
    # the term is m at rho = k rho0, across the fruit direction: atan(m) off the line
    angle = np.degrees(np.arccos(v @ fruit / 0.6))
    assert angle == pytest.approx(np.degrees(np.arctan(TRAJECTORY.m)), abs=1e-6)
    assert v[1] < 0  # away from the obstacle's side
    plain = field_direction(x, fruit, centre, centre, r, virtual_plane=False)
    assert np.degrees(np.arccos(plain @ fruit / 0.6)) > angle + 5  # along rho: also backwards
    # an obstacle dead ahead: no local minimum with the plane, without any escape
    ahead, big = (np.eye(dim)[0] * 0.4)[None], np.array([0.03])
    report = {}
    path = plan_path(start, fruit, ahead, ahead, big, gripper_radius=LINK_R, escape=False,
                     report=report)  # fmt: skip
    np.testing.assert_allclose(path[-1], fruit)
    assert report == {"stalled": False, "escapes": 0}
    assert (np.linalg.norm(path - ahead, axis=1) - 0.03 - LINK_R).min() > 0.0


def test_path_keeps_clear_of_a_bar_across_the_way():
    a, b = np.array([[0.3, -0.1, 0.05]]), np.array([[0.3, 0.2, 0.05]])
    path = plan_path(np.zeros(3), np.array([0.6, 0.0, 0.0]), a, b, np.array([0.008]))
    dist, _ = closest_point_on_segment(path, a, b)
    assert dist.min() - 0.008 > 0.04
    np.testing.assert_allclose(path[-1], [0.6, 0.0, 0.0])
