"""Dual-arm model: PUMA-560 kinematics, link distances (numpy, MuJoCo, GJK), tasks."""

from __future__ import annotations

import math

import numpy as np
import pytest

from motiongym.envs.dual_arm import model, task

QZ = np.zeros(6)
QR = np.array([0.0, math.pi / 2, -math.pi / 2, 0.0, 0.0, 0.0])  # Corke's "ready" pose


def test_wrist_at_known_poses():
    # Robot 2 (unrotated, x = -0.65): at qz the upper arm points along +x and the
    # forearm straight up: wrist at (a2 + a3, -d3, d1 + d4) from the base.
    w = model.wrist_centre(QZ, model.base_transform(1))
    np.testing.assert_allclose(w, [-0.65 + 0.4318 + 0.0203, -0.15005, 0.672 + 0.4318], atol=1e-12)
    # Robot 1 is rotated by pi about z (paper eq. 3): mirrored in x and y.
    w = model.wrist_centre(QZ, model.base_transform(0))
    np.testing.assert_allclose(w, [0.65 - 0.4318 - 0.0203, 0.15005, 1.1038], atol=1e-12)
    # qr: arm straight up; Corke's fkine(qr) puts the wrist at (0.0203, -0.15005, 0.8636)
    # above the shoulder.
    w = model.wrist_centre(QR, model.base_transform(1))
    np.testing.assert_allclose(w, [-0.65 + 0.0203, -0.15005, 0.672 + 0.8636], atol=1e-12)


def test_hand_computed_distances_at_qz():
    d = model.pair_distances(QZ, QZ)
    # Upper arms: collinear along x at y = 0, z = d1, ends at x = +-(0.65 - a2).
    np.testing.assert_allclose(d[0, 0], 2 * (0.65 - 0.4318) - 2 * 0.075, atol=1e-12)
    # Forearms: vertical, at (+-0.1982, +-0.15005): parallel segments.
    gap = math.hypot(2 * (0.65 - 0.4318 - 0.0203), 2 * 0.15005)
    np.testing.assert_allclose(d[1, 1], gap - 2 * 0.055, atol=1e-12)
    assert model.robot_distance(QZ, QZ) == pytest.approx(d.min())


def test_numpy_mujoco_and_gjk_agree():
    cell = model.MujocoCell()
    rng = np.random.default_rng(3)
    lo, hi = model.JOINT_LIMITS[:, 0] / 2, model.JOINT_LIMITS[:, 1] / 2
    for _ in range(100):
        q1, q2 = rng.uniform(lo, hi), rng.uniform(lo, hi)
        ours = model.pair_distances(q1, q2)
        np.testing.assert_allclose(cell.distances(q1, q2), ours, atol=1e-9)
        i, j = rng.integers(5, size=2)
        if ours[i, j] > 0:  # GJK distance between separated convex bodies
            assert cell.geom_distance(i, j) == pytest.approx(ours[i, j], abs=1e-6)


def test_collision_test_is_exact():
    rng = np.random.default_rng(4)
    q1 = rng.uniform(-1.5, 1.5, (2000, 6))
    q2 = rng.uniform(-1.5, 1.5, (2000, 6))
    a1, b1 = model.link_segments(q1, model.base_transform(0))
    a2, b2 = model.link_segments(q2, model.base_transform(1))
    exact = model.segment_pair_distances(a1, b1, a2, b2).min(axis=(-2, -1))
    for margin in (0.0, 0.1, 0.3):
        np.testing.assert_array_equal(
            model.segments_collide(a1, b1, a2, b2, margin), exact <= margin
        )


def test_sampled_tasks_respect_speed_limits_and_compact_form():
    rng = np.random.default_rng(0)
    for _ in range(5):
        t1, t2 = task.sample_pair(rng, "colliding")
        for t in (t1, t2):
            assert task.speeds_ok(t)
            again = task.Trajectory.from_compact(t.vias.ravel(), t.durations, t.robot)
            np.testing.assert_allclose(again.samples(), t.samples())
            # the vias fall on samples
            ks = np.round(np.cumsum(np.r_[0, t.durations]) / task.DT).astype(int)
            np.testing.assert_allclose(t.samples()[ks], t.vias, atol=1e-12)
        assert task.undelayed_distance(t1, t2).min() <= 0.0
        assert task.sequential_clear(t1, t2)


def test_length_parametrisation():
    t1, t2 = task.paper_case()
    q_levels, tl, total = t2.length_parametrised(100)
    assert q_levels.shape == (101, 6) and tl[0] == 0 and tl[-1] == 100
    assert np.all(np.diff(tl) >= 0) and total > 0.5
    w = model.wrist_centre(q_levels, model.base_transform(1))
    steps = np.linalg.norm(np.diff(w, axis=0), axis=1)
    # equal arc-length steps: chords never longer, equal but where the wrist turns at a via
    assert steps.max() <= total / 100 * 1.001
    assert np.median(steps) == pytest.approx(total / 100, rel=1e-3)


def test_paper_case_collides_like_the_paper():
    t1, t2 = task.paper_case()
    d = task.undelayed_distance(t1, t2)
    hit = np.nonzero(d <= 0)[0] * task.DT
    # one contiguous interval like the paper's 0.76-1.16 s
    assert np.all(np.diff(hit) < task.DT * 1.5)
    assert 0.6 <= hit[0] <= 0.8 and 1.0 <= hit[-1] <= 1.2
    assert task.sequential_clear(t1, t2) and task.speeds_ok(t1) and task.speeds_ok(t2)


def test_unknown_task_mode():
    with pytest.raises(ValueError, match="colliding"):
        task.sample_pair(np.random.default_rng(0), "sometimes")
