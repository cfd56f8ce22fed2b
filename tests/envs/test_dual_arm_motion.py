"""The certified motion bound, the v1 swept check and the swept collision map.

Independent truths: capsule end points from the forward kinematics on a fine
grid of the motion (the bound), the NumPy link distances on a fine grid of
each step (the swept check), and the environment itself (the map's delays).
"""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import motiongym  # noqa: F401
from motiongym.baselines.dual_arm.boundary_following import boundary_following
from motiongym.baselines.dual_arm.collision_map import CollisionMap
from motiongym.envs.dual_arm import model, motion, task


def test_no_point_of_a_body_moves_farther_than_its_bound():
    rng = np.random.default_rng(0)
    worst = 0.0
    for _ in range(300):
        qa = rng.uniform(model.JOINT_LIMITS[:, 0], model.JOINT_LIMITS[:, 1])
        dq = rng.normal(0.0, 0.1, 6)
        q = qa + np.linspace(0.0, 1.0, 41)[:, None] * dq  # (41, 6)
        for robot in (0, 1):
            a, b = model.link_segments(q, model.base_transform(robot))  # (41, 5, 3)
            moved = np.maximum(np.linalg.norm(a - a[0], axis=-1), np.linalg.norm(b - b[0], axis=-1))
            worst = max(worst, float((moved.max(axis=0) / motion.body_motion(np.abs(dq))).max()))
    assert worst <= 1.0
    assert worst > 0.9  # and the bound is not loose


def test_span_variation_equals_the_general_one():
    rng = np.random.default_rng(1)
    samples = rng.normal(size=(30, 6))
    slopes = np.abs(np.diff(samples, axis=0))
    for lo, hi in [(0.2, 0.7), (0.2, 1.7), (3.5, 9.25), (28.5, 29.0), (5.0, 5.0)]:
        np.testing.assert_allclose(
            motion.span_variation(slopes, lo, hi), motion.variation(samples, lo, hi)
        )


def _graze():
    """Two one-step motions that clear each other at both ends but cross in between."""
    middle = np.array([-0.32, -0.12, -0.75, -0.6, 0.27, 0.24])
    q1 = np.stack([middle, middle])
    q1[:, 0] += [0.5, -0.5]  # robot 1 swings its waist by 1 rad through robot 2's arm
    q2 = np.array([[0.57, -0.75, 0.37, -0.52, 0.58, 0.07]] * 2)  # robot 2 at rest
    return q1, q2


def test_the_swept_check_finds_a_contact_between_samples_that_samples_miss():
    q1, q2 = _graze()
    ends = model.robot_distance(q1, q2)
    fine = np.linspace(0.0, 1.0, 201)[:, None]
    truth = model.robot_distance(q1[0] + fine * (q1[1] - q1[0]), q2[0]).min()  # about -0.046
    assert ends.min() > 0.0 and truth < 0.0  # the case is what it says
    assert motion.simultaneous_collide(q1, (0.0, 1.0), q2, (0.0, 1.0), 0.0)
    assert motion.spans_collide(q1, (0.0, 1.0), q2, (0.0, 1.0), 0.0)


def test_the_swept_check_clears_what_stays_apart():
    rng = np.random.default_rng(2)
    for _ in range(40):
        q1 = rng.uniform(-0.3, 0.3, (2, 6))
        q2 = rng.uniform(-0.3, 0.3, (2, 6))
        fine = np.linspace(0.0, 1.0, 101)[:, None]
        truth = model.robot_distance(q1[0] + fine * (q1[1] - q1[0]), q2[0] + fine * (q2[1] - q2[0]))
        said = motion.simultaneous_collide(q1, (0.0, 1.0), q2, (0.0, 1.0), 0.05)
        if truth.min() <= 0.05:
            assert said  # never missed
        if truth.min() > 0.05 + motion.RESOLUTION:
            assert not said  # and exact up to the resolution


@pytest.mark.parametrize("seed", [0, 2])
def test_the_swept_map_delay_never_collides_in_the_v1_environment(seed):
    rng = np.random.default_rng(seed)
    t1, t2 = task.sample_pair(rng, "colliding", 0.0)
    delay = boundary_following(CollisionMap.from_tasks(t1, t2, 100, 0.0, check="swept")).delay
    assert delay is not None
    env = gym.make("motiongym/DualArmCell-v1").unwrapped
    env.reset(seed=0)
    env.world.load(t1, t2)
    collided = False
    for step in range(t1.n_samples + t2.n_samples + delay + 2):
        _, _, terminated, _, info = env.step(np.array([1.0, 1.0 if step >= delay else 0.0]))
        collided |= info["collision"]
        if terminated:
            break
    assert not collided and info["is_success"]
