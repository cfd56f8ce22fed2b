"""Acting under odometry error: bumps, the sidestep, steering by the heading error.

:class:`DriftActing` is mixed into :class:`.psa_cwa.PsaCwaPolicy`: the parts of
its acting that read the localiser (:mod:`.localise`, :mod:`.fastslam`).
Without odometry noise (no localiser) only :meth:`DriftActing._bumped`'s
plain rule runs: a bump marks the cells ahead as obstacle and drops the plan.

Under noise:

- **Bumps.** The cells ahead are marked along the way the robot truly faced,
  the commanded heading turned by the estimated heading error rounded to
  quarter turns, and the commanded heading that bumped is not commanded
  again from this cell. A bump the map does not explain sends the robot one
  cell sideways against the drift (:meth:`DriftActing._sidestep`); its bump
  marks become unknown, not walls, once it has moved on.
- **Steering** (``steering``): the next cell of a lane or a planned path is
  reached with the command :func:`.steer.steer` predicts to get there from
  the estimated continuous pose and heading error; where every useful
  command bumped from this cell the next cell is marked blocked and the
  mode replans. Without it (the ablation) the robot turns to the next
  cell's direction and moves forward, as without noise.
"""

from __future__ import annotations

from collections import deque
from typing import Any

import numpy as np

from motiongym.baselines.sweeper import psa
from motiongym.baselines.sweeper.belief import OBSTACLE
from motiongym.baselines.sweeper.steer import DIRECTION, steer
from motiongym.envs.sweeper import occupancy
from motiongym.envs.sweeper.occupancy import DC, DR


class DriftActing:
    """The policy's acting on its estimated pose (see the module docstring); expects
    ``w``, ``sidestep`` and ``steering`` on the policy and ``map``, ``loc``, ``path``,
    ``heading``, ``blocked``, ``last_pose`` on its memory."""

    w: int
    sidestep: bool
    steering: bool

    def _bumped(self, m: Any, r: int, c: int, h: int, bump: bool) -> None:
        """Bump bookkeeping for the observation at estimated cell ``(r, c)``, heading ``h``."""
        m.heading = h
        if (r, c) != m.last_pose:
            m.blocked.clear()
        if bump:  # the cells ahead are blocked, whatever the map said
            m.blocked.add(h)
            if m.loc is not None and self.steering:  # the way the robot truly faced
                h = (h + int(round(m.loc.continuous()[2] / (np.pi / 2)))) % 4
            ahead = self._ahead(r, c, h)
            unexplained = m.loc is not None and self.sidestep and self._free(m, ahead)
            self._mark_ahead(m, r, c, h)
            m.path.clear()
            if unexplained:
                self._sidestep(m, r, c, h)
        elif (r, c) != m.last_pose and m.map.felt.any():
            # moved on: bump marks were for where it stood (localising: unknown until seen
            # again, so that a bump the map did not explain leaves no wall behind)
            m.map.forget_felt(unmark=m.loc is not None and self.sidestep)
        m.last_pose = (r, c)

    @staticmethod
    def _ahead(r: int, c: int, h: int) -> tuple[int, int]:
        return r + int(DR[h]), c + int(DC[h])

    def _free(self, m: Any, cell: tuple[int, int]) -> bool:
        """True when the map holds no obstacle in the footprint at ``cell``."""
        occ, _ = m.map.footprint(*cell)
        return not (occ == OBSTACLE).any()

    def _sidestep(self, m: Any, r: int, c: int, h: int) -> None:
        """After a bump the map does not explain: one cell sideways, against the drift.

        The true heading is ``h`` turned by the heading error ``e``, so a move
        drifts to the left of ``h`` when ``e > 0``; the robot's continuous
        position can sit just short of the next cell across, and every move
        ahead then rounds into the wall beside the path (the same bump for
        ever). A step to the side away from the drift (the localiser's
        weighted mean ``e``, less the quarter turns already in ``h`` when
        steering) takes it off that line.
        """
        e = float(np.average(m.loc.e, weights=m.loc.wt)) if m.loc is not None else 0.0
        if self.steering:
            e -= round(e / (np.pi / 2)) * (np.pi / 2)
        first = psa.right_of(h) if e > 0 else psa.left_of(h)
        for s in (first, (first + 2) % 4):
            cell = self._ahead(r, c, s)
            if self._free(m, cell):
                m.path = deque([cell])
                return

    def _mark_ahead(self, m: Any, r: int, c: int, h: int) -> None:
        rr, cc = np.nonzero(occupancy.entering_mask(int(DR[h]), int(DC[h]), self.w))
        m.map.mark_obstacle(rr + r + int(DR[h]), cc + c + int(DC[h]))

    def _steered(self, m: Any, r: int, c: int, path: list) -> int | None:
        """The command towards ``path[0]`` (:func:`.steer.steer`); None, with the next
        cell marked blocked, when every useful command bumped from here."""
        pose = m.loc.continuous()
        a = steer(m.heading, pose, (r, c), path, lambda q: self._free(m, q), m.blocked)
        if a is None:
            self._mark_ahead(m, r, c, DIRECTION[(path[0][0] - r, path[0][1] - c)])
        return a
