"""The dual-arm cell's collision rule, written once: the world and the planners call it.

A step moves robot ``r`` uniformly over a span ``[a_r, b_r]`` of fractional
samples of its trajectory (both arms at once). Its verdict depends on the
environment's ``collision_check`` (:data:`CHECKS`):

* ``"samples"`` (``DualArmCell-v0``): the step collides when ``d(R1, R2)``
  (paper eq. 1, the least of the 25 link distances) at its end is
  ``<= margin``;
* ``"swept"`` (``DualArmCell-v1``): the step collides when any instant of it
  comes within ``margin`` (:mod:`.motion`, exact up to
  :data:`~.motion.RESOLUTION`, never missed). Decided in two stages:
  the end configuration within the margin collides; else the certified bound
  (:func:`bound_clears`: every configuration of the step lies within half of
  each arm's body motion of one of the step's two ends) clears it; else it is
  halved (:func:`motion_collides`).

:func:`step_collides` is one step as the world takes it;
:func:`schedule_collides` a whole schedule of robot 2's advances against
robot 1 on its nominal schedule, as the planners verify a plan;
:func:`bound_clears` and :func:`motion_collides` are the two stages, which a
table of many steps (``baselines.dual_arm.step_check.StepCheck``) calls
vectorised.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from motiongym.envs.dual_arm import model, motion

if TYPE_CHECKING:
    from motiongym.envs.dual_arm.task import Trajectory

CHECKS = ("samples", "swept")  # the values of the collision_check keyword
SAMPLES, SWEPT = CHECKS


def bound_clears(
    d_start: np.ndarray, d_end: np.ndarray, move1: np.ndarray, move2: np.ndarray, margin: float
) -> np.ndarray:
    """Does the certified bound clear the step(s)? ``d_start``, ``d_end``: (..., 5, 5) link
    distances at the two ends; ``move1``, ``move2``: (..., 5) how far any point of each
    body moves (:func:`.motion.body_motion`). (...,) bool."""
    slack = move1[..., :, None] / 2 + move2[..., None, :] / 2
    if slack.ndim == 2:  # one step (the world's): the same bound on scalars, faster
        return np.asarray(min((d_start - slack).min(), (d_end - slack).min()) > margin)
    low = np.minimum((d_start - slack).min(axis=(-2, -1)), (d_end - slack).min(axis=(-2, -1)))
    return low > margin


def motion_collides(
    samples1: np.ndarray,
    spans1: np.ndarray,
    samples2: np.ndarray,
    spans2: np.ndarray,
    margin: float,
) -> np.ndarray:
    """The halving stage for many steps: spans (n, 2) of each arm -> (n,) bool
    (:func:`.motion.simultaneous_collide_many`)."""
    return motion.simultaneous_collide_many(samples1, spans1, samples2, spans2, margin)


def step_collides(
    check: str,
    margin: float,
    d_start: np.ndarray,
    d_end: np.ndarray,
    samples: tuple[np.ndarray, np.ndarray],
    slopes: tuple[np.ndarray, np.ndarray],
    start: tuple[float, float],
    end: tuple[float, float],
    distance: float | None = None,
) -> bool:
    """One step's verdict under ``check`` (module docstring).

    ``d_start``, ``d_end``: (5, 5) link distances at the step's two ends;
    ``samples``: each arm's (N_r + 1, 6) samples; ``slopes``: their ``|dq|`` per
    sample (N_r, 6); ``start``, ``end``: each arm's progress (samples) at the
    step's start and end; ``distance``: ``d_end.min()`` where the caller has it.
    """
    if (float(d_end.min()) if distance is None else distance) <= margin:
        return True
    if check == SAMPLES:
        return False
    m1 = motion.body_motion(motion.span_variation(slopes[0], start[0], end[0]))
    m2 = motion.body_motion(motion.span_variation(slopes[1], start[1], end[1]))
    if bound_clears(d_start, d_end, m1, m2, margin):
        return False
    return motion.simultaneous_collide(
        samples[0], (start[0], end[0]), samples[1], (start[1], end[1]), margin
    )


def schedule_indices(advances: np.ndarray, n1: int, n2: int) -> tuple[np.ndarray, np.ndarray]:
    """Robot 1's and robot 2's sample index at every step of a schedule (incl. the start):
    robot 1 one sample per step, robot 2 by its ``advances`` (0 or 1)."""
    p2 = np.concatenate([[0], np.cumsum(advances)])
    return np.minimum(np.arange(len(p2)), n1), np.minimum(p2, n2)


def schedule_collides(
    check: str,
    traj1: Trajectory,
    traj2: Trajectory,
    advances: np.ndarray,
    margin: float = 0.0,
) -> bool:
    """Does the schedule collide under ``check``? Robot 1 runs one sample per step, robot
    2 advances by ``advances`` (0 or 1 per step).

    ``"samples"``: ``d(R1, R2) <= margin`` at some sample of the schedule, its start
    included (the arms' own samples, in one vectorised distance).
    ``"swept"``: some step, both arms moving at once, comes within ``margin`` by the
    halving stage alone (:func:`.motion.simultaneous_collide`, which also finds an end
    within the margin; exact up to the resolution).
    """
    p1, p2 = schedule_indices(advances, traj1.n_samples, traj2.n_samples)
    q1, q2 = traj1.samples(), traj2.samples()
    if check == SAMPLES:
        a1, b1 = model.link_segments(q1[p1], model.base_transform(traj1.robot))
        a2, b2 = model.link_segments(q2[p2], model.base_transform(traj2.robot))
        return bool(model.segments_collide(a1, b1, a2, b2, margin).any())
    for t in range(len(p1) - 1):
        if motion.simultaneous_collide(q1, (p1[t], p1[t + 1]), q2, (p2[t], p2[t + 1]), margin):
            return True
    return False
