"""The weak baseline the paper compares with (section 2, Fig. 1): Microcomputing's robot.

As the paper describes it: the robot first follows the outer walls, which
gives it the area's contour map; then, from where it stands, it looks in the
four directions (east, north, west, south), moves in the one that is least
swept until it meets a wall or an obstacle, sweeping, and repeats. The paper
reports about 90 % of an empty room swept, with much overlap.

Our reading:

- Wall following: move straight until blocked, then keep the wall on the
  right (right-hand rule on configurations) until the robot is back at its
  first contact pose.
- The robot looks again after every robot width travelled, and earlier
  when a wall or an obstacle stops it. Taken literally ("move until the
  wall, then look"), a robot in an empty rectangle goes from corner to
  corner along the walls for ever once a leg has ended in a corner, and
  sweeps only the ring it swept while following the walls; looking at
  every robot width is the coarsest rule that leaves the ring
  (docs/experiments/Sweeper-v0.md).
- "Least swept direction": for each heading, the straight run ahead up to
  the first known obstacle (unknown cells count as free); its sweep fraction
  is the share of swept cells in the footprints along it. The run with the
  smallest fraction (to two decimals) is taken, ties broken at random by the
  policy's own generator (seeded per episode, so runs repeat), except
  straight back along the last leg (which would trace the
  same line for ever). The robot never decides to stop; the episode's time
  limit ends it.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from motiongym.baselines.policy import ScriptedPolicy
from motiongym.baselines.sweeper.belief import OBSTACLE, RobotMap
from motiongym.baselines.sweeper.psa_cwa import robot_geometry
from motiongym.envs.sweeper.occupancy import DC, DR
from motiongym.envs.sweeper.world import FORWARD, LEFT, RIGHT


@dataclass
class WallFollowMemory:
    map: RobotMap
    phase: str = "approach"  # approach | follow | legs
    first_contact: tuple[int, int, int] | None = None
    moved_since_contact: int = 0
    leg_heading: int | None = None
    last_leg: int | None = None
    leg_moves: int = 0
    rng: np.random.Generator = field(default_factory=lambda: np.random.default_rng(0))
    steps: int = 0
    history: list = field(default_factory=list)


class WallFollowPolicy(ScriptedPolicy):
    """Follow the outer wall, then legs in the least swept of four directions (Fig. 1)."""

    leg_cells: int | None = None  # cells between looks; None: the robot width

    def __init__(self, observation_space, action_space, env_kwargs=None) -> None:
        super().__init__(observation_space, action_space, env_kwargs)
        self.w, self.R = robot_geometry(observation_space, self.env_kwargs)

    def new_memory(self) -> WallFollowMemory:
        return WallFollowMemory(RobotMap(self.w, self.R))

    def _free(self, m: WallFollowMemory, r: int, c: int) -> bool:
        occ, _ = m.map.footprint(r, c)
        return not (occ == OBSTACLE).any()

    def _ahead_free(self, m: WallFollowMemory, r: int, c: int, h: int) -> bool:
        return self._free(m, r + int(DR[h]), c + int(DC[h]))

    def act(self, observation: Any, memory: WallFollowMemory) -> int:
        m = memory
        r, c, h, bump = m.map.integrate(observation)
        m.steps += 1
        if m.phase == "approach":
            if self._ahead_free(m, r, c, h) and not bump:
                return FORWARD
            m.phase, m.first_contact = "follow", (r, c, h)
        if m.phase == "follow":
            if (r, c, h) == m.first_contact and m.moved_since_contact > 0:
                m.phase = "legs"
            elif m.moved_since_contact > 4 * 256 * 256:  # pragma: no cover - guard
                m.phase = "legs"
            else:
                return self._follow_wall(m, r, c, h)
        return self._legs(m, r, c, h)

    def _follow_wall(self, m: WallFollowMemory, r: int, c: int, h: int) -> int:
        """Right-hand rule: turn right into an opening, else straight, else turn left."""
        right = (h + 3) % 4
        turned_right = m.history[-1:] == ["R"]
        if not turned_right and self._ahead_free(m, r, c, right):
            m.history.append("R")
            return RIGHT
        if self._ahead_free(m, r, c, h):
            m.history.append("F")
            m.moved_since_contact += 1
            return FORWARD
        m.history.append("L")
        return LEFT

    def _legs(self, m: WallFollowMemory, r: int, c: int, h: int) -> int:
        if m.leg_heading is not None:
            if h != m.leg_heading:
                return RIGHT if (m.leg_heading - h) % 4 == 3 else LEFT
            if self._ahead_free(m, r, c, h) and m.leg_moves < (self.leg_cells or self.w):
                m.leg_moves += 1
                return FORWARD
            m.last_leg, m.leg_heading = m.leg_heading, None  # look again
        m.leg_moves = 0
        best = None
        for k in range(4):
            length, fraction = self._run(m, r, c, k)
            if length == 0:
                continue
            back = m.last_leg is not None and k == (m.last_leg + 2) % 4
            key = (back, round(fraction, 2), float(m.rng.random()), k)
            if best is None or key < best:
                best = key
        if best is None:
            return LEFT
        m.leg_heading = best[3]
        return self._legs(m, r, c, h)

    def _run(self, m: WallFollowMemory, r: int, c: int, k: int) -> tuple[int, float]:
        """Length of the straight run ahead in heading ``k`` and its swept fraction."""
        o, w = m.map.off, self.w
        (lo_r, lo_c), (hi_r, hi_c) = m.map.lo - o, m.map.hi - o - w  # explored box
        n = 0
        rr, cc = r, c
        while lo_r <= rr + int(DR[k]) <= hi_r and lo_c <= cc + int(DC[k]) <= hi_c:
            if not self._free(m, rr + int(DR[k]), cc + int(DC[k])):
                break
            rr, cc = rr + int(DR[k]), cc + int(DC[k])
            n += 1
        if n == 0:
            return 0, 1.0
        r0, r1 = min(r, rr) + o, max(r, rr) + o + w
        c0, c1 = min(c, cc) + o, max(c, cc) + o + w
        # the cells the run would newly cover: the lane beyond the footprint
        if k == 0:
            c0 = c + o + w
        elif k == 2:
            c1 = c + o
        elif k == 1:
            r1 = r + o
        else:
            r0 = r + o + w
        return n, float(np.mean(m.map.swept[r0:r1, c0:c1]))
