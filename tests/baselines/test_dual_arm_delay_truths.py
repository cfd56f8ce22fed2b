"""Boundary following on DualArmCell-v1 against two truths that share none of its code.

(a) The environment's own brute force: every pure delay below the policy's is run in
the environment, step by step, and must collide there; the policy's own run must
succeed. (b) An independent continuous-time check (``tests/dual_arm_truth.py``: own
PUMA-560 kinematics from the published DH table, own capsule distance, dense sampling
of the joint motion the environment executes) of the policy's run.

The pairs are development seeds of the early-delay study (docs/experiments/DualArmCell-v1.md).
"""

from __future__ import annotations

import dual_arm_truth as truth
import gymnasium as gym
import numpy as np
import pytest
from dual_arm_runs import run_pure_delay

import motiongym  # noqa: F401
from motiongym.baselines import make_policy

V1 = "motiongym/DualArmCell-v1"
FAST = (610_004, 610_011, 610_028, 610_036)  # delays 8, 6, 14, 3


def _policy_run(env: gym.Env, seed: int) -> tuple[int, dict, np.ndarray, np.ndarray]:
    """Boundary following (the v1 policy, told the environment's keywords) for one episode:
    its delay, the last info and both arms' joints after every step, start included."""
    policy = make_policy(V1, "boundary-following", env.observation_space, env.action_space,
                         dict(env.spec.kwargs))  # fmt: skip
    obs, _ = env.reset(seed=seed)
    world = env.unwrapped.world
    joints = [world.q]
    done = False
    while not done:
        action, _ = policy.predict(obs)
        obs, _, terminated, truncated, info = env.step(action)
        joints.append(world.q)
        done = terminated or truncated
    q1, q2 = (np.array([q[r] for q in joints]) for r in (0, 1))
    return policy.diagnostics()["delay"], info, q1, q2


def _check_against_the_environment(env: gym.Env, seed: int) -> None:
    delay, info, q1, q2 = _policy_run(env, seed)
    assert info["is_success"] and not info["collision"], seed
    # (a) every earlier pure delay collides in the environment: the policy's is its minimum.
    early = [d for d in range(delay) if run_pure_delay(env, seed, d)]
    assert early == [], (seed, delay, early)
    # (b) the motion it ran is clear in continuous time, by independent code.
    assert truth.motion_clearance(q1, q2) > 0.0, (seed, delay)


@pytest.mark.parametrize("seed", FAST)
def test_boundary_following_is_the_environments_minimum_and_clear(seed):
    _check_against_the_environment(gym.make(V1), seed)


@pytest.mark.slow
def test_boundary_following_on_eight_more_pairs():
    env = gym.make(V1)
    for seed in range(610_000, 610_008):
        _check_against_the_environment(env, seed)


def test_the_independent_geometry_is_the_environments_at_the_samples():
    # The truth's kinematics and distance reproduce the environment's reported least
    # distance (MuJoCo's) along a run, to rounding: it checks the same bodies.
    env = gym.make(V1)
    env.reset(seed=FAST[0])
    world = env.unwrapped.world
    ours, theirs = [], []
    for t in range(60):
        env.step(np.array([1.0, 1.0 if t >= 8 else 0.0], np.float32))
        q1, q2 = world.q
        ours.append(truth.clearance(q1[None], q2[None])[0])
        theirs.append(world.distance)
    np.testing.assert_allclose(ours, theirs, atol=1e-9)


def test_the_independent_check_sees_a_collision_between_samples():
    # Dev pair 610001 with robot 2 started 155 steps late (its minimum is 159): the
    # environment stops it on a collision; every step end is clear (0.66 mm at least),
    # and the independent check finds the arms interpenetrating (2.3 mm) between them.
    env = gym.make(V1)
    env.reset(seed=610_001)
    world = env.unwrapped.world
    joints, t, done = [world.q], 0, False
    while not done:
        _, _, terminated, truncated, info = env.step(
            np.array([1.0, 1.0 if t >= 155 else 0.0], np.float32)
        )
        joints.append(world.q)
        t, done = t + 1, terminated or truncated
    assert info["collision"]
    q1, q2 = (np.array([q[r] for q in joints]) for r in (0, 1))
    assert truth.clearance(q1, q2).min() > 0.0  # clear at every step end
    assert truth.motion_clearance(q1, q2) < -1e-3  # not between them
