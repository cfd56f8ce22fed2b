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
The table uses the environment's own check (:mod:`.step_check`, every entry
decided) and nothing of the collision maps or of boundary following.
"""

from __future__ import annotations

import itertools

import numpy as np

from motiongym.baselines.dual_arm.step_check import StepCheck
from motiongym.envs.dual_arm.task import Trajectory


def step_table(traj1: Trajectory, traj2: Trajectory, margin: float = 0.0) -> np.ndarray:
    """(N1 + 1, N2 + 2) bool: does the step with robot 1 on ``[s1, s1 + 1]`` and robot 2 on
    ``[k, k + 1]`` collide? Column ``0`` is robot 2 waiting at its start (``k < 0``); column
    ``k + 1`` its move ``k`` (``k = N2``: at rest at its end); row ``N1``: robot 1 at rest.
    Every entry of :class:`.step_check.StepCheck`, each decided."""
    return StepCheck(traj1, traj2, margin).table()


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


_turn = itertools.count()


def solve_sampled_pair() -> int | None:
    """The brute force on the next of the pairs that ``bracket.plan_sampled_pair`` times
    (a benchmark hook, in the same turn order)."""
    from motiongym.baselines.dual_arm.bracket import bench_pairs

    pairs = bench_pairs()
    return true_min_delay(*pairs[next(_turn) % len(pairs)])
