"""The environment's own collision check of one step, as a lazy table.

``DualArmCell-v1`` (``collision_check="swept"``) calls a step a collision when
any instant of it, both arms moving at once on their straight joint-space
moves between samples, comes within ``safety_margin``
(:func:`motiongym.envs.dual_arm.collision.step_collides`, up to
:data:`motion.RESOLUTION`). Robot 1 runs on its nominal schedule, so in step
``x`` it moves over its samples ``[x, x + 1]`` (at rest at ``N1`` once done:
row ``min(x, N1)``); robot 2, at full speed or waiting, is in one of
``N2 + 2`` states (columns): ``0`` waiting at its start, ``k + 1`` moving
over ``[k, k + 1]``, ``N2 + 1`` at rest at its end. Entry ``(row, col)`` is
that step's verdict.

The two roles are the trajectories' order, not the robots': ``StepCheck(traj2,
traj1)`` (each trajectory on its own robot's base, ``Trajectory.robot``) is
the table of robot 2 on its nominal schedule and robot 1 waiting or moving,
for schedules in which robot 1 is the one that yields.

Each entry is decided in two stages, as the environment decides a step:

1. *Screen*: the 25 link distances at the step's two end configurations
   (paper eq. 1) and the certified motion bound of :mod:`.motion` (every
   configuration of the step is within half of each arm's body motion of an
   end): ``HIT`` when an end configuration is within the margin (a
   configuration the step certainly passes collides), ``CLEAR`` when the bound
   clears the whole step, else ``NEAR``.
2. *Decide* a ``NEAR`` entry by halving (:func:`motion.simultaneous_collide`,
   the environment's routine).

Screening is vectorised over tiles of ``TILE x TILE`` entries (a boundary
walk queries neighbouring steps); halving happens only where a verdict is
asked for. :meth:`StepCheck.certainly` needs the screen only (a lower bound
on collision: ``HIT`` implies the step collides); :meth:`StepCheck.collides`
is the exact verdict.
"""

from __future__ import annotations

import numpy as np

from motiongym.envs.dual_arm import collision, model, motion
from motiongym.envs.dual_arm.task import Trajectory
from motiongym.envs.geometry import closest_points_between_segments

UNKNOWN, CLEAR, HIT, NEAR, COLLIDES = -1, 0, 1, 2, 3
TILE = 8
REACH = (model.HALF + model.RADII)[:, None] + (model.HALF + model.RADII)[None, :]  # (5, 5)


class StepCheck:
    """Lazy verdicts of ``DualArmCell-v1``'s check for every (robot-1 step, robot-2 state).

    Args:
        traj1, traj2: the two arms' trajectories, one per robot, in either order: rows
            are ``traj1``'s moves, columns ``traj2``'s states.
        margin: the safety margin (m), the environment's ``safety_margin``.
    Attributes:
        state: (N1 + 1, N2 + 2) int8, ``UNKNOWN``, ``CLEAR``, ``HIT`` (an end
            configuration collides), ``NEAR`` (screened, undecided) or
            ``COLLIDES`` (decided by halving).
        halvings: how many entries needed halving so far.
    """

    def __init__(self, traj1: Trajectory, traj2: Trajectory, margin: float = 0.0) -> None:
        if {traj1.robot, traj2.robot} != {0, 1}:
            raise ValueError(
                f"a step check needs one trajectory per robot, got robots "
                f"{traj1.robot} and {traj2.robot}"
            )
        self.swapped = traj1.robot == 1  # rows are robot 2's
        self.q1, self.q2 = traj1.samples(), traj2.samples()
        self.n1, self.n2 = len(self.q1) - 1, len(self.q2) - 1
        self.margin = float(margin)
        n1, n2 = self.n1, self.n2
        # Each row's and column's move as sample spans [lo, hi].
        self.lo1 = np.arange(n1 + 1)
        self.hi1 = np.minimum(self.lo1 + 1, n1)
        self.lo2 = np.concatenate([[0], np.arange(n2 + 1)])
        self.hi2 = np.concatenate([[0], np.minimum(np.arange(n2 + 1) + 1, n2)])
        self.seg1 = model.link_segments(self.q1, model.base_transform(traj1.robot))  # (N1+1, 5, 3)
        self.seg2 = model.link_segments(self.q2, model.base_transform(traj2.robot))
        self.centres1 = (self.seg1[0] + self.seg1[1]) / 2  # (N1 + 1, 5, 3)
        self.centres2 = (self.seg2[0] + self.seg2[1]) / 2
        self.move1 = motion.body_motion(np.abs(self.q1[self.hi1] - self.q1[self.lo1]))
        self.move2 = motion.body_motion(np.abs(self.q2[self.hi2] - self.q2[self.lo2]))
        self.state = np.full((n1 + 1, n2 + 2), UNKNOWN, dtype=np.int8)
        self.halvings = 0

    @property
    def shape(self) -> tuple[int, int]:
        return self.state.shape

    def _distances(self, s1: np.ndarray, s2: np.ndarray) -> np.ndarray:
        """(n, 5, 5) link distances of robot 1 at samples ``s1`` and robot 2 at ``s2``."""
        a1, b1 = self.seg1
        a2, b2 = self.seg2
        return model.segment_pair_distances(a1[s1], b1[s1], a2[s2], b2[s2])

    def _bounded_distances(self, s1: np.ndarray, s2: np.ndarray, slack: np.ndarray) -> np.ndarray:
        """(n, 5, 5) link distances where ``d - slack`` may reach the margin, elsewhere a
        lower bound above ``margin + slack``: the capsule centres' distance less both
        capsules' reach (half length plus radius). Screens the same as exact distances."""
        c1, c2 = self.centres1[s1], self.centres2[s2]  # (n, 5, 3)
        diff = c1[:, :, None, :] - c2[:, None, :, :]
        d = np.sqrt(np.einsum("nijk,nijk->nij", diff, diff)) - REACH
        near = np.nonzero(d - slack <= self.margin)
        if len(near[0]):
            n, i, j = near
            (a1, b1), (a2, b2) = self.seg1, self.seg2
            exact, _, _ = closest_points_between_segments(
                a1[s1[n], i], b1[s1[n], i], a2[s2[n], j], b2[s2[n], j]
            )
            d[near] = exact - model.RADII[i] - model.RADII[j]
        return d

    def screen_entries(self, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
        """Screen (stage 1) the given entries, whatever their state; returns their screen."""
        slack = self.move1[rows][:, :, None] / 2 + self.move2[cols][:, None, :] / 2
        d_lo = self._bounded_distances(self.lo1[rows], self.lo2[cols], slack)
        d_hi = self._bounded_distances(self.hi1[rows], self.hi2[cols], slack)
        hit = np.minimum(d_lo.min(axis=(1, 2)), d_hi.min(axis=(1, 2))) <= self.margin
        clear = collision.bound_clears(d_lo, d_hi, self.move1[rows], self.move2[cols], self.margin)
        return np.where(hit, HIT, np.where(clear, CLEAR, NEAR)).astype(np.int8)

    def _screen(self, rows: np.ndarray, cols: np.ndarray, tiles: bool = True) -> None:
        """Screen the unknown given entries (``tiles``: every unknown entry of their tiles)."""
        unknown = self.state[rows, cols] == UNKNOWN
        if not unknown.any():
            return
        if not tiles:
            rows, cols = rows[unknown], cols[unknown]
            self.state[rows, cols] = self.screen_entries(rows, cols)
            return
        keys = zip((rows[unknown] // TILE).tolist(), (cols[unknown] // TILE).tolist(), strict=True)
        found = np.array(sorted(set(keys)), dtype=np.int64)  # (n, 2): the tiles
        offsets = np.indices((TILE, TILE)).reshape(2, -1).T  # (TILE^2, 2)
        idx = (found[:, None, :] * TILE + offsets[None]).reshape(-1, 2)
        idx = idx[(idx[:, 0] <= self.n1) & (idx[:, 1] <= self.n2 + 1)]
        idx = idx[self.state[idx[:, 0], idx[:, 1]] == UNKNOWN]
        self.state[idx[:, 0], idx[:, 1]] = self.screen_entries(idx[:, 0], idx[:, 1])

    def certainly(self, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
        """bool: the step certainly collides (an end configuration is within the margin)."""
        rows, cols = np.asarray(rows, np.int64), np.asarray(cols, np.int64)
        self._screen(rows, cols)
        return self.state[rows, cols] == HIT

    def collides(self, rows: np.ndarray, cols: np.ndarray, first: bool = False) -> np.ndarray:
        """bool: the environment's verdict on each step (halving the ``NEAR`` ones at once).

        With ``first``, no halving where an entry is already known to collide
        (the undecided ones are then reported clear: use where only ``any()`` matters).
        """
        rows, cols = np.asarray(rows, np.int64), np.asarray(cols, np.int64)
        self._screen(rows, cols, tiles=False)
        near = self.state[rows, cols] == NEAR
        if near.any() and not (first and np.isin(self.state[rows, cols], (HIT, COLLIDES)).any()):
            self.decide(rows[near], cols[near])
        return np.isin(self.state[rows, cols], (HIT, COLLIDES))

    def decide(self, rows: np.ndarray, cols: np.ndarray) -> None:
        """Stage 2: entries ``COLLIDES`` or ``CLEAR`` by halving, all at once."""
        rows, cols = np.divmod(np.unique(rows * self.shape[1] + cols), self.shape[1])
        self.halvings += len(rows)
        spans1 = np.stack([self.lo1[rows], self.hi1[rows]], 1)
        spans2 = np.stack([self.lo2[cols], self.hi2[cols]], 1)
        if self.swapped:  # the routine takes robot 1's samples first; its halving is symmetric
            hit = collision.motion_collides(self.q2, spans2, self.q1, spans1, self.margin)
        else:
            hit = collision.motion_collides(self.q1, spans1, self.q2, spans2, self.margin)
        self.state[rows, cols] = np.where(hit, COLLIDES, CLEAR)

    def table(self) -> np.ndarray:
        """(N1 + 1, N2 + 2) bool: every entry's verdict (the brute force's table)."""
        rows, cols = np.indices(self.shape).reshape(2, -1)
        todo = self.state[rows, cols] == UNKNOWN
        for chunk in np.array_split(np.flatnonzero(todo), max(1, int(todo.sum()) // 4096)):
            self.state[rows[chunk], cols[chunk]] = self.screen_entries(rows[chunk], cols[chunk])
        return self.collides(rows, cols).reshape(self.shape)

    # ------------------------------------------------------------------ pure delays

    def delay_steps(self, delay: int) -> tuple[np.ndarray, np.ndarray]:
        """The entries ``(rows, cols)`` of the steps of the pure delay ``delay``.

        Step ``x = 0 .. max(N1, D + N2) - 1``: robot 1 on row ``min(x, N1)``,
        robot 2 waiting (``x < D``), moving ``x - D`` or at rest (``x >= D + N2``).
        """
        x = np.arange(max(self.n1, delay + self.n2))
        k = x - delay
        return np.minimum(x, self.n1), np.where(k < 0, 0, np.minimum(k, self.n2) + 1)

    def delay_collides(self, delay: int) -> bool:
        """Does the pure delay ``delay`` collide on the environment's check?"""
        rows, cols = self.delay_steps(delay)
        return bool(self.collides(rows, cols, first=True).any())

    def at_rest_collides(self) -> str:
        """Where the arms collide at rest, at their start or end configurations (no
        delay can help): "start", "end", or "" where they do not."""
        for name, (s1, s2) in (("start", (0, 0)), ("end", (self.n1, self.n2))):
            if self._distances(np.array([s1]), np.array([s2])).min() <= self.margin:
                return name
        return ""
