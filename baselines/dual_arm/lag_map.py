"""Robot 2's choices read off the step table: which further waits are collision free from now.

Not the paper's method: a re-planning form of the minimum start delay, for a
teacher whose labels are a function of the current state (DAgger,
:mod:`motiongym.agents.training.dagger`) and for a learner-side view of the same
table (:mod:`motiongym.agents.learners.dual_arm`, ``dual_arm_map``).

The step table (:func:`.exact_delay.step_table` on v1's check; on v0's,
:func:`sample_table`) says for robot 1 on ``[s1, s1 + 1]`` and robot 2 on
``[k, k + 1]`` whether that environment step collides; column ``0`` is robot 2
waiting at its start, column ``k + 1`` its move ``k`` (``k = N2``: at rest at
its end). From the state at step ``x`` (robot 1 at sample ``x``, robot 2 at
``p2`` samples), the schedule "wait ``w`` more steps, then run at full speed"
takes in its step ``x + i`` robot 1's row ``min(x + i, N1)`` and robot 2's
column ``waiting`` (``i < w``) or ``moving p2 + i - w`` (``i >= w``). The
*lag map* marks, for each ``w`` of a list of lags, which of those steps
collide. Row ``w = 0`` clear means "go now" is collision free to the end;
at ``p2 = 0`` that is exactly the pure delay ``x`` being free, so the
first step at which a waiting robot 2 sees row 0 clear is the minimum start
delay (:func:`.exact_delay.true_min_delay`, tested).

The roles follow the trajectories' order: ``LagMap(traj2, traj1, ...)`` is
the same map with robot 1 as the one that waits (:class:`.step_check.StepCheck`
takes either order), for a policy that may let either robot yield
(``either-waits`` in :mod:`.policies`). :meth:`LagMap.finish` gives the
smallest free wait and when both arms would be done after it.

The table holds the states a pure delay visits. Where robot 2 is off them
(stopped part-way, or at a fractional sample after an advance below 1), a
step is read as the neighbouring columns (colliding if either does): an
approximation of the environment's check there, not a bound.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from motiongym.baselines.dual_arm.exact_delay import step_table
from motiongym.baselines.dual_arm.step_check import StepCheck
from motiongym.envs.checks import check_choice
from motiongym.envs.dual_arm.collision import CHECKS, SWEPT
from motiongym.envs.dual_arm.task import LAYOUT, Trajectory


def sample_table(traj1: Trajectory, traj2: Trajectory, margin: float = 0.0) -> np.ndarray:
    """The step table on v0's check (``d(R1, R2) <= margin`` at the step's end only):
    entry ``(s1, c)`` is the distance of robot 1 at ``min(s1 + 1, N1)`` and robot 2 at the
    end of column ``c``'s move (its start for ``c = 0``), as :func:`.exact_delay.step_table`
    lays out its entries."""
    check = StepCheck(traj1, traj2, margin)
    rows, cols = np.indices(check.shape).reshape(2, -1)
    out = np.zeros(check.shape, dtype=bool)
    for chunk in np.array_split(np.arange(len(rows)), max(1, len(rows) // 4096)):
        d = check._distances(check.hi1[rows[chunk]], check.hi2[cols[chunk]])
        out.flat[chunk] = d.min(axis=(1, 2)) <= check.margin
    return out


class LagMap:
    """One episode's step table and the lag map read from it (module docstring).

    Args:
        traj1, traj2: the two arms' trajectories, in either order: ``traj1``'s robot
            runs on, ``traj2``'s is the one that waits.
        margin: the environment's ``safety_margin`` (m).
        check: the environment's ``collision_check``: ``"swept"`` (v1, the motion of each
            step) or ``"samples"`` (v0, the step's end).
    """

    def __init__(
        self, traj1: Trajectory, traj2: Trajectory, margin: float = 0.0, check: str = SWEPT
    ) -> None:
        self.n1, self.n2 = traj1.n_samples, traj2.n_samples
        self.lead, self.wait = traj1.robot, traj2.robot
        swept = check_choice("check", check, CHECKS) == SWEPT
        self.table = (step_table if swept else sample_table)(traj1, traj2, margin)

    def state(self, observation: np.ndarray) -> tuple[int, float]:
        """``(x, p2)`` from an observation's progress fields: the running robot's sample
        (rounded) and the waiting robot's samples run (to 1e-3: the float32 observation
        reads a whole sample as 244.000007)."""
        progress = np.asarray(observation, dtype=float)[LAYOUT["progress"]]
        x = int(round(progress[self.lead] * self.n1))
        return x, round(float(progress[self.wait] * self.n2), 3)

    def _columns(self, p2: float, i: np.ndarray, lag) -> tuple[np.ndarray, np.ndarray]:
        """The two (possibly equal) columns read for robot 2 in step ``x + i`` (``lag`` an
        int, or an array broadcasting against ``i``)."""
        n2 = self.n2
        base, frac = int(np.floor(p2)), p2 - np.floor(p2)
        moved = np.maximum(i - lag, 0)  # samples run since it went on
        lo = np.minimum(base + moved, n2) + 1
        hi = np.minimum(base + moved + (frac > 0), n2) + 1
        if p2 == 0:
            still_lo = still_hi = 0  # waiting at its start: column 0, exact
        elif frac == 0:  # stopped at a sample: the moves that end and start there
            still_lo, still_hi = min(base, n2 + 1), min(base + 1, n2 + 1)
        else:  # stopped inside move ``base``
            still_lo = still_hi = min(base + 1, n2 + 1)
        waiting = i < lag
        return np.where(waiting, still_lo, lo), np.where(waiting, still_hi, hi)

    def blocked(self, x: int, p2: float, lag, horizon: int) -> np.ndarray:
        """(horizon,) bool: does step ``x + i`` of "wait ``lag``, then go" collide?
        Steps after both arms are done are clear. ``lag`` may be an (L, 1) array: then
        (L, horizon), one row per lag."""
        i = np.arange(horizon)
        rows = np.minimum(x + i, self.n1)
        lo, hi = self._columns(float(p2), i, lag)
        hit = self.table[rows, lo] | self.table[rows, hi]
        done = (x + i >= self.n1) & (lo == self.n2 + 1)
        return hit & ~done

    def clear_now(self, x: int, p2: float) -> bool:
        """Is "go now at full speed" collision free until both arms are done?"""
        horizon = max(self.n1 - x, 0) + self.n2 + 2
        return not bool(self.blocked(x, p2, 0, horizon).any())

    def free_lags(self, x: int, p2: float, lags: np.ndarray | None = None) -> np.ndarray:
        """bool per wait ``w`` of ``lags`` (default ``0 .. max(N1 - x, 0)``: a longer wait
        only idles, the running robot being at rest from there): is "wait ``w``, then go"
        collision free to the end?"""
        last = max(self.n1 - x, 0)
        lags = np.arange(last + 1) if lags is None else np.asarray(lags)
        horizon = last + int(lags.max(initial=0)) + self.n2 + 2
        return np.asarray(~self.blocked(x, p2, lags[:, None], horizon).any(axis=1), dtype=bool)

    def min_wait(self, x: int, p2: float, chunk: int = 32) -> int | None:
        """The smallest free wait from ``(x, p2)`` (:meth:`free_lags`), None if none; the
        waits are tried ``chunk`` at a time, shortest first (most are short)."""
        last = max(self.n1 - x, 0)
        for start in range(0, last + 1, chunk):
            lags = np.arange(start, min(start + chunk, last + 1))
            free = self.free_lags(x, p2, lags)
            if free.any():
                return int(lags[np.argmax(free)])
        return None

    def finish(self, x: int, p2: float) -> tuple[int, int] | None:
        """``(w, steps)``: the smallest free wait from ``(x, p2)`` and the steps until both
        arms are done after it (the running robot's rest of its path, or the wait plus
        the waiting robot's); None where no wait is free."""
        wait = self.min_wait(x, p2)
        if wait is None:
            return None
        return wait, max(self.n1 - x, wait + int(np.ceil(self.n2 - p2 - 1e-9)))

    def window(
        self, x: int, p2: float, lags: Sequence[int], bin_steps: int, bins: int
    ) -> np.ndarray:
        """(len(lags), bins + 1) float32: row ``j`` marks the bins of ``bin_steps`` steps in
        which "wait ``lags[j]``, then go" collides, over the next ``bins * bin_steps``
        steps; its last entry is the first colliding step's distance as a fraction of
        that horizon (1: none within it)."""
        horizon = bins * bin_steps
        out = np.empty((len(lags), bins + 1), dtype=np.float32)
        for j, lag in enumerate(lags):
            hit = self.blocked(x, p2, int(lag), horizon)
            out[j, :bins] = hit.reshape(bins, bin_steps).any(axis=1)
            out[j, bins] = np.argmax(hit) / horizon if hit.any() else 1.0
        return out
