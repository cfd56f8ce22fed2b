"""The collision map of paper section III (after Lee & Lee 1987), evaluated lazily.

Axes: ``s1`` is robot 1's controller sample (``t = s1 * dt``), ``s2`` robot 2's
discretised travelled length (``l = s2 * dl``, ``dl = L_T / N_l``). Cell
``(s1, s2)`` is a collision cell iff ``d(R1, R2) <= margin`` (paper eq. 2)
with robot 1 at its sample ``min(s1, N1)`` (it rests at its end once done)
and robot 2 at travelled length ``s2 * dl``. Cells are computed on demand and
cached; :attr:`CollisionMap.evaluated` counts the distinct cells computed
(the measure of the boundary-following method's cost). Outside the map
``s1 < 0``, ``s2 < 0`` and ``s2 > N_l`` are walls (blocked): robot 2 cannot
run before its start or past its end.

Three kinds of cells: the paper's (one configuration each: exact at no
instant of the motion, so a delay may be early or late on the environment's
check), the swept ones (any configuration of robot 1's step against any of
robot 2's level interval: safe but late by 1-3 samples, since the two arms
never take every pair of these configurations at once), and cells that are
verdicts of ``DualArmCell-v1``'s own step check (:meth:`CollisionMap.from_steps`:
an upper map, safe, and a lower map, never blocking a feasible delay; the
v1 policy searches the lower one and checks its delay exactly,
:mod:`.bracket`).

TLVST (travelled length versus sampling time): ``tl[k] = floor(l(k dt) / dl)``,
the level robot 2 has reached at its own sample ``k`` (``tl[N2] = N_l``). As a
path of the paper's moves "0" (+s1) and "1" (+s2), the curve delayed by ``D``
samples is: along ``s2 = 0`` from ``s1 = 0`` to ``D`` (robot 2 waits), then at
each column ``D + k`` up from ``tl[k]`` to ``tl[k + 1]`` and one step right,
and once robot 2 is done along ``s2 = N_l`` until robot 1 is done too
(``s1 = max(N1, D + N2)``). A delay is collision free iff every cell of that
path is free; with a pause-and-resume schedule ``p(s1)`` (robot 2's sample at
column ``s1``), column ``s1`` covers levels ``tl[p(s1)] .. tl[p(s1 + 1)]``.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from motiongym.baselines.dual_arm.step_check import StepCheck
from motiongym.envs.checks import check_choice
from motiongym.envs.dual_arm import model
from motiongym.envs.dual_arm.collision import CHECKS, SAMPLES, SWEPT
from motiongym.envs.dual_arm.motion import body_motion, configs, spans_collide, variation
from motiongym.envs.dual_arm.task import DT, Trajectory

CellFunction = Callable[[np.ndarray, np.ndarray], np.ndarray]


class CollisionMap:
    """Lazy, counting collision map.

    Args:
        cells: vectorised occupancy ``(s1 (n,), s2 (n,)) -> bool (n,)`` for
            in-range indices (``0 <= s1 <= n1``, ``0 <= s2 <= n_levels``).
        n1: robot 1's last sample ``N1``.
        tlvst: (N2 + 1,) robot 2's TLVST levels, non-decreasing, last = ``n_levels``.
        n_levels: ``N_l``.
    """

    def __init__(self, cells: CellFunction, n1: int, tlvst: np.ndarray, n_levels: int) -> None:
        tl = np.asarray(tlvst, dtype=np.int64)
        if tl[0] != 0 or tl[-1] != n_levels or np.any(np.diff(tl) < 0):
            raise ValueError("tlvst must start at 0, end at n_levels and never decrease")
        self._cells = cells
        self.n1 = int(n1)
        self.n2 = len(tl) - 1
        self.n_levels = int(n_levels)
        self.tl = tl
        self._known = np.full((self.n1 + 1, self.n_levels + 1), -1, dtype=np.int8)
        self.evaluated = 0
        # first_col[s2]: the first column a(s2) of the undelayed curve at level s2.
        nxt = np.append(tl[1:], n_levels)
        self.first_col = np.searchsorted(nxt, np.arange(n_levels + 1), side="left")
        self.first_col[0] = 0
        # last_col[s2]: the last column b(s2) of the undelayed curve at level s2.
        self.last_col = np.searchsorted(tl, np.arange(n_levels + 1), side="right") - 1

    # ------------------------------------------------------------------ building

    @classmethod
    def from_tasks(
        cls,
        traj1: Trajectory,
        traj2: Trajectory,
        n_levels: int = 100,
        margin: float = 0.0,
        check: str = SAMPLES,
    ) -> CollisionMap:
        """The map of two arms' tasks (the link geometry of ``envs.dual_arm.model``).

        ``check="samples"`` (v0's check): the paper's cells, one configuration each (robot 1 at
        sample ``s1``, robot 2 at the level's floor). ``check="swept"`` (v1's): each
        cell stands for a motion and is blocked when *any* configuration of it
        comes within ``margin`` (certified, :func:`motion.spans_collide`):
        robot 1 over its samples ``[s1, s1 + 1]``, robot 2 over the samples in
        which its wrist travels from ``s2 dl`` to ``(s2 + 1) dl``, both on the
        straight joint-space moves between samples that the environment makes.
        Every step of a delayed TLVST curve (column ``D + k``: robot 1 from
        sample ``D + k`` to the next, robot 2 from ``k`` to ``k + 1``, whose
        length runs from ``>= tl[k] dl`` to ``< (tl[k + 1] + 1) dl``) lies in
        the union of the curve's cells in that column, so a delay whose curve
        is free on this map never collides, between samples included.
        """
        if check_choice("check", check, CHECKS) == SWEPT:
            return cls._swept(traj1, traj2, n_levels, margin)
        q1 = traj1.samples()  # (N1 + 1, 6)
        q2, tl, _ = traj2.length_parametrised(n_levels)  # (N_l + 1, 6), (N2 + 1,)
        a1, b1 = model.link_segments(q1, model.base_transform(0))  # (N1+1, 5, 3)
        a2, b2 = model.link_segments(q2, model.base_transform(1))  # (N_l+1, 5, 3)

        def cells(s1: np.ndarray, s2: np.ndarray) -> np.ndarray:
            return model.segments_collide(a1[s1], b1[s1], a2[s2], b2[s2], margin)

        return cls(cells, traj1.n_samples, tl, n_levels)

    @classmethod
    def _swept(
        cls, traj1: Trajectory, traj2: Trajectory, n_levels: int, margin: float
    ) -> CollisionMap:
        samples1, samples2 = traj1.samples(), traj2.samples()
        n1 = traj1.n_samples
        _, tl, _ = traj2.length_parametrised(n_levels)
        tau = traj2.level_times(n_levels) / DT  # (N_l + 1,) fractional samples
        pad = 1e-6  # samples: covers the rounding of the TLVST levels
        lo = np.maximum(tau - pad, 0.0)
        hi = np.minimum(np.append(tau[1:], tau[-1]) + pad, traj2.n_samples)
        # Corners and motion bounds of every cell's two moves, computed once.
        ends1 = np.minimum(np.arange(n1 + 2), n1)  # robot 1's span [s1, s1 + 1], clamped
        moves1 = body_motion(variation(samples1, ends1[:-1], ends1[1:]))  # (N1 + 1, 5)
        moves2 = body_motion(variation(samples2, lo, hi))  # (N_l + 1, 5)
        q2_lo, q2_hi = configs(samples2, lo), configs(samples2, hi)  # (N_l + 1, 6)

        def cells(s1: np.ndarray, s2: np.ndarray) -> np.ndarray:
            s1 = np.minimum(s1, n1)
            q1 = np.stack([samples1[ends1[s1]], samples1[ends1[s1 + 1]]])  # (2, n, 6)
            q2 = np.stack([q2_lo[s2], q2_hi[s2]])  # (2, n, 6)
            d = model.pair_distances(q1[:, None], q2[None, :])  # (2, 2, n, 5, 5)
            hit = (d.min(axis=(-2, -1)) <= margin).any(axis=(0, 1))
            slack = moves1[s1][:, :, None] / 2 + moves2[s2][:, None, :] / 2  # (n, 5, 5)
            clear = (d - slack).min(axis=(0, 1, 3, 4)) > margin
            out = hit.copy()
            for i in np.flatnonzero(~hit & ~clear):  # near misses: halve until decided
                a, b = int(s1[i]), int(s2[i])
                out[i] = spans_collide(
                    samples1, (ends1[a], ends1[a + 1]), samples2, (lo[b], hi[b]), margin
                )
            return out

        return cls(cells, n1, tl, n_levels)

    @classmethod
    def from_steps(
        cls, check: StepCheck, traj2: Trajectory, n_levels: int = 100, bound: str = "lower"
    ) -> CollisionMap:
        """A map whose cells are verdicts of the environment's own step check.

        A cell ``(s1, s2)`` lies on the curves of the delays whose step in column
        ``s1`` has robot 2 in a state of ``K(s2)`` (the columns of
        :class:`~.step_check.StepCheck`): waiting (``s2 = 0``), moving ``k`` with
        ``tl[k] <= s2 <= tl[k + 1]``, or at rest (``s2 = N_l``); ``K(s2)`` is a
        contiguous range. Robot 1 is on its step ``min(s1, N1)`` (the last
        column, ``s1 = max(N1, D + N2)``, is both at rest: its verdict is the end
        configuration's, which the delay's last step ends in).

        * ``bound="upper"``: blocked iff *some* step of ``K(s2)`` collides (exact
          verdicts). **Every delay free on this map is free on the environment's
          check**: step ``x`` of delay ``D`` has robot 2 in a state ``c`` that
          belongs to ``K(s2)`` of a cell of ``D``'s curve in column ``x``
          (waiting: ``(x, 0)``; moving ``k``: ``(x, tl[k])``; at rest:
          ``(x, N_l)``); that cell is free, so step ``(x, c)`` is clear.
        * ``bound="lower"``: blocked iff *every* step of ``K(s2)`` certainly
          collides (an end configuration within the margin: the screen alone).
          **Every delay free on the environment's check is free on this map**:
          a cell ``(x, s2)`` of delay ``D``'s curve belongs to ``D``'s step ``x``
          with robot 2 in a state of ``K(s2)`` (the last column: the end
          configuration, which ``D``'s last step ends in); were the cell blocked,
          that step would collide. So the map's minimum delay is a lower bound
          on the true one.
        """
        if bound not in ("lower", "upper"):
            raise ValueError(f"bound must be 'lower' or 'upper', got {bound!r}")
        _, tl, _ = traj2.length_parametrised(n_levels)
        n2 = len(tl) - 1
        levels = np.arange(n_levels + 1)
        c_lo = np.searchsorted(tl[1:], levels, side="left") + 1  # first k with tl[k+1] >= s2
        c_hi = np.searchsorted(tl[:-1], levels, side="right")  # last k with tl[k] <= s2, + 1
        c_lo[0], c_hi[-1] = 0, n2 + 1  # waiting at level 0, at rest at N_l

        def cells(s1: np.ndarray, s2: np.ndarray) -> np.ndarray:
            out = np.empty(len(s1), dtype=bool)
            for i, (row, level) in enumerate(zip(s1.tolist(), s2.tolist(), strict=True)):
                cols = np.arange(c_lo[level], c_hi[level] + 1)
                rows = np.full(len(cols), row)
                if bound == "lower":
                    out[i] = bool(check.certainly(rows, cols).all())
                else:
                    out[i] = bool(check.collides(rows, cols, first=True).any())
            return out

        return cls(cells, check.n1, tl, n_levels)

    @classmethod
    def from_array(cls, occupied: np.ndarray, tlvst: np.ndarray) -> CollisionMap:
        """A map given in full as a bool array (N1 + 1, N_l + 1) (for tests)."""
        occ = np.asarray(occupied, dtype=bool)
        return cls(lambda s1, s2: occ[s1, s2], occ.shape[0] - 1, tlvst, occ.shape[1] - 1)

    # ------------------------------------------------------------------ queries

    @property
    def full_count(self) -> int:
        """Number of distinct cells of the full map, ``(N1 + 1) (N_l + 1)``."""
        return self._known.size

    def blocked(self, s1: int, s2: int) -> bool:
        """Collision (or wall) at ``(s1, s2)``; evaluates and caches the cell."""
        if s1 < 0 or s2 < 0 or s2 > self.n_levels:
            return True
        s1 = min(s1, self.n1)
        known = self._known[s1, s2]
        if known < 0:
            known = int(self._cells(np.array([s1]), np.array([s2]))[0])
            self._known[s1, s2] = known
            self.evaluated += 1
        return bool(known)

    def full(self) -> np.ndarray:
        """Every cell, (N1 + 1, N_l + 1) bool (evaluates all unknown cells at once)."""
        todo = np.argwhere(self._known < 0)
        if len(todo):
            for chunk in np.array_split(todo, max(1, len(todo) // 4096)):
                self._known[chunk[:, 0], chunk[:, 1]] = self._cells(chunk[:, 0], chunk[:, 1])
            self.evaluated += len(todo)
        return self._known.astype(bool)

    def column(self, s1: int) -> np.ndarray:
        """Occupancy of column ``s1`` (clamped to ``N1``) from the full map."""
        return self.full()[min(s1, self.n1)]

    # ------------------------------------------------------------------ the TLVST curve

    def end_column(self, delay: int) -> int:
        return max(self.n1, delay + self.n2)

    def curve(self, delay: int) -> tuple[np.ndarray, np.ndarray]:
        """Cells of the TLVST path delayed by ``delay``, in order: ``(s1s, s2s)``."""
        s1s: list[np.ndarray] = [np.arange(delay)]
        s2s: list[np.ndarray] = [np.zeros(delay, dtype=np.int64)]
        for k in range(self.n2):
            lo, hi = self.tl[k], self.tl[k + 1]
            s2s.append(np.arange(lo, hi + 1))
            s1s.append(np.full(hi - lo + 1, delay + k))
        tail = np.arange(delay + self.n2, self.end_column(delay) + 1)
        s1s.append(tail)
        s2s.append(np.full(len(tail), self.n_levels))
        return np.concatenate(s1s).astype(np.int64), np.concatenate(s2s).astype(np.int64)

    def next_on_curve(self, s1: int, s2: int, delay: int) -> int | None:
        """The TLVST move ("0" or "1") from ``(s1, s2)`` on the curve delayed by
        ``delay``; ``None`` at its end."""
        if s2 >= self.n_levels:
            return 0 if s1 < self.end_column(delay) else None
        k = s1 - delay
        if k >= self.n2:
            return 1
        if k < 0 or s2 >= self.tl[k + 1]:
            return 0
        return 1

    def departure_delay(self, s1: int, s2: int, move: int | None = None) -> int | None:
        """The delay of the TLVST curve shifted to pass through ``(s1, s2)``.

        Without ``move``: the curve that enters level ``s2`` at ``s1``,
        ``s1 - a(s2)``. With ``move`` 0 or 1: the smallest delay whose curve
        passes through the cell and leaves it by that move: for "1" the cell is
        the last of the curve's run on its level, ``s1 - b(s2)``; for "0" the
        one before, ``s1 - b(s2) + 1`` (never more than ``s1 - a(s2)``, never
        below 0). None if no delay >= 0 passes through the cell (it lies left
        of the undelayed curve).
        """
        enter = int(s1 - self.first_col[s2])
        if enter < 0:
            return None
        if move is None:
            return enter
        last = int(s1 - self.last_col[s2])
        return max(0, min(enter, last + 1 if move == 0 else last))
