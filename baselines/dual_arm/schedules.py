"""Reference schedules on the full collision map: exhaustive minimum delay,
sequential operation, and (beyond the paper) minimum-makespan coordination.

A schedule is robot 2's advance per step ``a2[x]`` in {0, 1} for the columns
``x = 0 .. makespan - 1`` while robot 1 runs on its nominal schedule (one
sample per step, then rests). Robot 2's sample before step ``x`` is
``p(x) = sum(a2[:x])``; column ``x`` of the map is covered from level
``tl[p(x)]`` to ``tl[p(x + 1)]`` (see :mod:`.collision_map`). The makespan is
the number of steps until both arms are done: ``max(N1, D + N2)`` for a
delay ``D``, ``N1 + N2`` for sequential operation (the delay ``D = N1``).

* :func:`exhaustive_min_delay`: the correctness reference for boundary
  following: the smallest ``D`` in ``0 .. N1 + N2`` whose delayed TLVST curve
  (paper Fig. 2, shifted right by ``D``) has no collision cell.
* :func:`collides_at_samples`: a schedule checked at the arms' own 20 ms
  samples rather than on the map, whose length axis places robot 2 at the
  level configurations ``s2 * dl`` and not where it actually is at a sample:
  the map can miss a graze by a few millimetres.
* :func:`min_makespan`: robot 2 may pause and resume at any sample (advance 0
  or 1 per step, the environment's action set at its extremes): a shortest
  monotone path through the free cells by dynamic programming over
  (column, robot-2 sample). Every delay schedule is such a path, so its
  makespan is never longer than the minimum delay's.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from motiongym.baselines.dual_arm.collision_map import CollisionMap
from motiongym.envs.dual_arm import collision
from motiongym.envs.dual_arm.task import Trajectory


@dataclass
class Schedule:
    """Robot 2's per-step advances and what they achieve.

    Attributes:
        advances: (makespan,) robot 2's advance per step (0 or 1).
        makespan: steps until both arms are done.
        delay: the start delay in samples for delay schedules (None otherwise).
    """

    advances: np.ndarray
    makespan: int
    delay: int | None = None


def delay_schedule(cmap: CollisionMap, delay: int) -> Schedule:
    """Wait ``delay`` steps, then run robot 2 at nominal speed."""
    makespan = cmap.end_column(delay)
    adv = np.zeros(makespan, dtype=np.int64)
    adv[delay : delay + cmap.n2] = 1
    return Schedule(adv, makespan, delay)


def curve_is_free(cmap: CollisionMap, delay: int) -> bool:
    """True iff the TLVST curve delayed by ``delay`` meets no collision cell."""
    occ = cmap.full()
    s1s, s2s = cmap.curve(delay)
    return not bool(occ[np.minimum(s1s, cmap.n1), s2s].any())


def exhaustive_min_delay(cmap: CollisionMap, max_delay: int | None = None) -> int | None:
    """Smallest collision-free delay over the full map (None if none up to ``max_delay``)."""
    top = cmap.n1 + cmap.n2 if max_delay is None else max_delay
    for delay in range(top + 1):
        if curve_is_free(cmap, delay):
            return delay
    return None


def sequential(cmap: CollisionMap) -> Schedule:
    """Robot 2 starts when robot 1 ends (delay ``N1``)."""
    return delay_schedule(cmap, cmap.n1)


def schedule_is_free(cmap: CollisionMap, advances: np.ndarray) -> bool:
    """True iff robot 2 following ``advances`` meets no collision cell."""
    occ = cmap.full()
    p = np.concatenate([[0], np.cumsum(advances)])  # (makespan + 1,)
    if p[-1] != cmap.n2:
        return False
    for x in range(len(p)):
        lo = cmap.tl[p[x]]
        hi = cmap.tl[p[x + 1]] if x + 1 < len(p) else lo
        if occ[min(x, cmap.n1), lo : hi + 1].any():
            return False
    return True


def min_makespan(cmap: CollisionMap) -> Schedule | None:
    """Shortest pause-and-resume schedule of robot 2 (None if robot 2 can never finish)."""
    occ = cmap.full()  # (N1 + 1, N_l + 1)
    tl, n2 = cmap.tl, cmap.n2
    # run_free[c, p]: column c is free from tl[p] to tl[p + 1] (robot 2 advances at c).
    csum = np.concatenate([np.zeros((occ.shape[0], 1), int), np.cumsum(occ, axis=1)], axis=1)
    run_free = csum[:, tl[1:] + 1] - csum[:, tl[:-1]] == 0  # (N1 + 1, N2)
    stay_free = ~occ[:, tl]  # (N1 + 1, N2 + 1)
    # tail_free[c]: the top row is free from column c to N1 (robot 2 done, robot 1 runs).
    top = occ[:, cmap.n_levels]
    tail_free = np.flip(np.cumsum(np.flip(top)) == 0)
    horizon = cmap.n1 + n2 + 1
    reach = np.zeros((horizon + 1, n2 + 1), dtype=bool)
    reach[0, 0] = stay_free[0, 0]
    for x in range(horizon):
        c, c_next = min(x, cmap.n1), min(x + 1, cmap.n1)
        here = reach[x]
        nxt = here.copy()
        nxt[1:] |= here[:-1] & run_free[c]
        reach[x + 1] = nxt & stay_free[c_next]
        if reach[x + 1, n2] and tail_free[c_next]:
            return _backtrack(reach, run_free, cmap, x + 1, max(cmap.n1, x + 1))
    return None


def _backtrack(
    reach: np.ndarray, run_free: np.ndarray, cmap: CollisionMap, x_end: int, makespan: int
) -> Schedule:
    adv = np.zeros(makespan, dtype=np.int64)
    p = cmap.n2
    for x in range(x_end, 0, -1):
        c = min(x - 1, cmap.n1)
        if p > 0 and reach[x - 1, p - 1] and run_free[c, p - 1]:
            adv[x - 1], p = 1, p - 1
        # else robot 2 waited at p during step x - 1 (reach[x - 1, p] holds).
    return Schedule(adv, makespan, None)


def sample_indices(advances: np.ndarray, n1: int, n2: int) -> tuple[np.ndarray, np.ndarray]:
    """Robot 1's and robot 2's sample index at every step of a schedule (incl. the start)."""
    return collision.schedule_indices(advances, n1, n2)


def collides_at_samples(
    traj1: Trajectory, traj2: Trajectory, advances: np.ndarray, margin: float = 0.0
) -> bool:
    """True iff ``d(R1, R2) <= margin`` at some step of the schedule, evaluated at the
    arms' actual samples (what the environment sees), not at the map's length levels:
    :func:`motiongym.envs.dual_arm.collision.schedule_collides` on ``"samples"``."""
    return collision.schedule_collides(collision.SAMPLES, traj1, traj2, advances, margin)


def collides_swept(
    traj1: Trajectory, traj2: Trajectory, advances: np.ndarray, margin: float = 0.0
) -> bool:
    """True iff some step of the schedule, both arms moving at once, comes within
    ``margin``: :func:`motiongym.envs.dual_arm.collision.schedule_collides` on ``"swept"``."""
    return collision.schedule_collides(collision.SWEPT, traj1, traj2, advances, margin)
