"""Exact minimum start delay on the v1 check: brute force over every delay.

Not the paper's method: the independent truth that ``motiongym reproduce
dual-arm`` measures boundary following against, and the policies' fallback
where boundary following finds no delay (so they never fall back to
sequential operation while a pure delay exists).

A pure delay ``D`` runs robot 1 at nominal speed and starts robot 2 ``D``
steps late. In environment step ``t`` (1-based) robot 1 moves over its
samples ``[t - 1, t]`` and robot 2 over ``[t - 1 - D, t - D]`` (clamped: at
rest before its start and after its end), both at once; ``DualArmCell-v1``
calls that step a collision by
:func:`motiongym.envs.dual_arm.motion.simultaneous_collide`. So step ``t``
of delay ``D`` depends only on ``(s1, k) = (t - 1, t - 1 - D)``: the table of
every ``(s1, k)`` decides every delay at once, and ``D`` is collision free iff
its diagonal ``k = s1 - D`` is free for ``s1 = 0 .. max(N1, D + N2) - 1``.
The table uses the environment's own check and nothing of the collision map.
"""

from __future__ import annotations

import numpy as np

from motiongym.envs.dual_arm import model, motion
from motiongym.envs.dual_arm.task import Trajectory


def step_table(traj1: Trajectory, traj2: Trajectory, margin: float = 0.0) -> np.ndarray:
    """(N1 + 1, N2 + 2) bool: does the step with robot 1 on ``[s1, s1 + 1]`` and robot 2 on
    ``[k, k + 1]`` collide? Column ``0`` is robot 2 waiting at its start (``k < 0``); column
    ``k + 1`` its move ``k`` (``k = N2``: at rest at its end); row ``N1``: robot 1 at rest."""
    q1, q2 = traj1.samples(), traj2.samples()
    n1, n2 = len(q1) - 1, len(q2) - 1
    a1 = np.minimum(np.arange(n1 + 1), n1)
    b1 = np.minimum(a1 + 1, n1)
    a2 = np.concatenate([[0], np.minimum(np.arange(n2 + 1), n2)])
    b2 = np.concatenate([[0], np.minimum(np.arange(n2 + 1) + 1, n2)])
    d_start = model.pair_distances(q1[a1][:, None], q2[a2][None, :])  # (R, C, 5, 5)
    d_end = model.pair_distances(q1[b1][:, None], q2[b2][None, :])
    m1 = motion.body_motion(np.abs(q1[b1] - q1[a1]))  # (R, 5)
    m2 = motion.body_motion(np.abs(q2[b2] - q2[a2]))  # (C, 5)
    slack = m1[:, None, :, None] / 2 + m2[None, :, None, :] / 2
    low = np.minimum((d_start - slack).min(axis=(-2, -1)), (d_end - slack).min(axis=(-2, -1)))
    hit = (d_end.min(axis=(-2, -1)) <= margin) | (d_start.min(axis=(-2, -1)) <= margin)
    table = hit.copy()
    for r, c in np.argwhere(~hit & (low <= margin)):
        table[r, c] = motion.simultaneous_collide(q1, (a1[r], b1[r]), q2, (a2[c], b2[c]), margin)
    return table


def free_delays(table: np.ndarray, n1: int, n2: int) -> np.ndarray:
    """(N1 + N2 + 1,) bool: which pure delays ``D = 0 .. N1 + N2`` never collide."""
    out = np.zeros(n1 + n2 + 1, dtype=bool)
    for delay in range(n1 + n2 + 1):
        s1 = np.arange(max(n1, delay + n2))
        k = s1 - delay
        rows = np.minimum(s1, n1)
        cols = np.where(k < 0, 0, np.minimum(k, n2) + 1)
        out[delay] = not table[rows, cols].any()
    return out


def true_min_delay(traj1: Trajectory, traj2: Trajectory, margin: float = 0.0) -> int | None:
    """The smallest collision-free pure delay on the v1 check (None: none exists)."""
    free = free_delays(step_table(traj1, traj2, margin), traj1.n_samples, traj2.n_samples)
    found = np.flatnonzero(free)
    return int(found[0]) if len(found) else None


def solve_paper_case() -> int | None:
    """The exact minimum delay of the paper case (a benchmark hook: the brute force
    that boundary following is timed against)."""
    from motiongym.envs.dual_arm.task import paper_case

    return true_min_delay(*paper_case())
