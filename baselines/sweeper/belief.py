"""The robot's own maps, built from what it senses (paper 3.1 sweep map, 3.3 obstacle map).

The sweeper knows nothing of the area in advance. Each observation's
``sensed`` window (obstacles around the footprint) and ``swept`` window are
written into full-resolution maps at the believed pose (the latest window
wins, so a drifted map heals where it is seen again); the footprint is
marked swept. Cells felt by a bump stay obstacles while the robot stands
there: under odometry error the window may show them free, and trusting it
would bump on the same spot for ever. Planning works on the bounding box of what has been sensed,
padded by the robot width, so its cost follows the explored area, not the
largest allowed map.
"""

from __future__ import annotations

import numpy as np

from motiongym.envs.sweeper.maps import MAX_SIDE

UNKNOWN, FREE, OBSTACLE = -1, 0, 1


class RobotMap:
    """Occupancy (unknown / free / obstacle) and sweep maps in the map frame.

    Args:
        w: robot width (cells).
        sensor_range: cells sensed beyond the footprint (R); the windows are
            ``w + 2R`` cells wide.
        evidence: 0, the latest window wins; ``n > 0``, occupancy by votes
            (Moravec & Elfes 1985, occupancy grids, in counts): each sensing
            adds one for obstacle or takes one for free, clipped to ``+-n``,
            and a cell is an obstacle while its count is positive, so a
            window filed at a wrong pose cannot wall off a corridor seen
            free before.
    """

    def __init__(self, w: int, sensor_range: int, evidence: int = 0) -> None:
        self.w, self.R = int(w), int(sensor_range)
        self.evidence = int(evidence)
        self.S = self.w + 2 * self.R
        self.off = self.S + self.w  # array index = map cell + off
        side = MAX_SIDE + 2 * self.off
        self.occ = np.full((side, side), UNKNOWN, np.int8)  # (side, side)
        self.swept = np.zeros((side, side), bool)  # (side, side)
        self.felt = np.zeros((side, side), bool)  # (side, side) obstacles felt by bumping
        # (side, side) sensed obstacle minus sensed free, clipped to +-evidence (with evidence)
        self.votes = np.zeros((side, side) if self.evidence else (0, 0), np.int8)
        self.lo = np.array([10**9, 10**9])  # bounding box of sensed cells (array index)
        self.hi = np.array([-1, -1])

    def integrate(
        self, obs: dict, cell: tuple[int, int] | None = None
    ) -> tuple[int, int, int, bool]:
        """Write one observation into the maps; return ``(row, col, heading, bump)``.

        ``cell``: where the footprint is (a :class:`~.localise.Localiser`'s
        estimate); None takes the observation's ``pose`` and also merges its
        ``swept`` window (the environment's dead-reckoned sweep map, right
        only without odometry error). Only cells sensed now are written
        (``known``; all of the window in v0); the others keep what the map
        held, unknown until first sensed.
        """
        pose = np.asarray(obs["pose"])
        h = int(round(float(pose[2])))
        bump = bool(pose[3] > 0.5)
        if cell is None:
            r, c = int(round(float(pose[0]))), int(round(float(pose[1])))
        else:
            r, c = cell
        o, R, S, w = self.off, self.R, self.S, self.w
        r0, c0 = r - R + o, c - R + o
        window = np.asarray(obs["sensed"]).reshape(S, S) > 0.5
        felt = self.felt[r0 : r0 + S, c0 : c0 + S]
        region = self.occ[r0 : r0 + S, c0 : c0 + S]
        known = np.asarray(obs["known"]).reshape(S, S) > 0.5 if "known" in obs else True
        if self.evidence:
            votes = self.votes[r0 : r0 + S, c0 : c0 + S]
            step = np.where(window, 1, -1) * known
            votes[:] = np.clip(votes + step, -self.evidence, self.evidence)
            window = votes > 0
        if "known" in obs:
            region[known] = window[known]
        else:
            region[:] = window
        region[felt] = OBSTACLE  # a bump outweighs the range sensor
        if cell is None:
            self.swept[r0 : r0 + S, c0 : c0 + S] |= np.asarray(obs["swept"]).reshape(S, S) > 0.5
        self.swept[r + o : r + o + w, c + o : c + o + w] = True
        self.lo = np.minimum(self.lo, (r0, c0))
        self.hi = np.maximum(self.hi, (r0 + S, c0 + S))
        return r, c, h, bump

    def mark_obstacle(self, cells_r: np.ndarray, cells_c: np.ndarray) -> None:
        """Record obstacle cells (map frame) felt by a bump; windows keep them until forgotten."""
        self.occ[cells_r + self.off, cells_c + self.off] = OBSTACLE
        self.felt[cells_r + self.off, cells_c + self.off] = True

    def forget_felt(self, unmark: bool = False) -> None:
        """Drop the bump marks (they become plain map cells, rewritten when seen again;
        with ``unmark``, unknown cells until then)."""
        if unmark:
            self.occ[self.felt] = UNKNOWN
        self.felt[:] = False

    def window(self) -> tuple[int, int, np.ndarray, np.ndarray]:
        """``(r0, c0, occ, swept)``: the explored box padded by ``w``; ``r0, c0`` its map origin.

        ``occ`` and ``swept`` are views of shape ``(h, w)`` of the box.
        """
        pad = self.w
        lo = np.maximum(self.lo - pad, 0)
        hi = np.minimum(self.hi + pad, self.occ.shape[0])
        occ = self.occ[lo[0] : hi[0], lo[1] : hi[1]]
        swept = self.swept[lo[0] : hi[0], lo[1] : hi[1]]
        return int(lo[0] - self.off), int(lo[1] - self.off), occ, swept

    def footprint(self, r: int, c: int) -> tuple[np.ndarray, np.ndarray]:
        """Occupancy and sweep state of the footprint anchored at map cell ``(r, c)``."""
        o, w = self.off, self.w
        return self.occ[r + o : r + o + w, c + o : c + o + w], self.swept[
            r + o : r + o + w, c + o : c + o + w
        ]
