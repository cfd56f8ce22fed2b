"""Pose correction from what the robot senses: Monte Carlo localisation on its own map.

Under odometry error the ``pose`` of the observation is dead reckoning
(paper 4.2, its open problem): every forward move adds one cell along the
commanded heading, whatever the wheels did, and the heading error random-
walks. The sensing window, though, is read at the true pose.
:class:`Localiser` tracks the pose with a particle filter (Monte Carlo
localisation: Dellaert, Fox, Burgard & Thrun 1999; grid Markov localisation
before it: Burgard, Fox, Hennig & Schmidt 1996), each particle a continuous
pose ``(y, x)`` and a heading error ``e``, weighed by how well the sensed
window matches the policy's own map (:class:`~.belief.RobotMap`), grid scan
matching (Lu & Milios 1997). The map is built at the estimated pose, so
this is SLAM with one map (Thrun, Burgard & Fox 2005, "Probabilistic
Robotics", ch. 10-13, simplified); coverage under drift with localisation
on the robot's own map is BSA's setting (Gonzalez, Alvarez & Fernandez
2005).

The rules:

- **Motion** (the environment's odometry model, with its noise levels
  known to the robot as its odometry spec): every action adds
  ``N(0, heading_noise)`` to each particle's ``e``; a forward move (the
  heading unchanged, as a turn always changes it, and no bump; not the
  dead-reckoned pose changing, which the environment clips to the map's
  extent, so that a drifted reckoning hides moves) moves each particle
  ``d ~ N(1, max(slip_noise, 0.05))`` (clipped to ``[0, 1.4]``) along the
  commanded heading turned by ``e``; the floor is roughening (Gordon,
  Salmond & Smith 1993): with exact moves the particles differ only by
  their heading error, resampling leaves a few tracks, and a pose error
  that none of them holds is never repaired (heading noise alone:
  docs/experiments/Sweeper-v1.md); with ``diffusion`` a forward move also
  adds ``N(0, diffusion)`` to each particle's ``e`` (the policy passes the
  heading noise: the particles' heading noise on a move is doubled in
  variance, process-noise inflation against sample impoverishment, Thrun,
  Burgard & Fox 2005, 4.3.4: after resampling the particles' heading errors
  are copies of a few, and a heading error none of them holds is otherwise
  reached only by the spec's own noise, 0.01 rad per action, while every move
  at the wrong heading files the map further off); a bump leaves it where it
  was, and weighs down the particles whose move would have found a footprint
  the map holds free (``exp(-BLOCKED)``).
- **Weight.** Over the window's cells sensed now (``known``; all in v0)
  and known in the map (cells the map holds only from a bump do not
  count): each disagreement multiplies a particle's weight by
  ``exp(-MISMATCH)``, each map obstacle under its footprint by
  ``exp(-BLOCKED)``. Resampled (systematic) when the effective number of
  particles falls below half.
- **Estimate.** The cell that holds the most weight; the map is filed and
  the footprint marked swept there.
"""

from __future__ import annotations

import math

import numpy as np

from motiongym.baselines.sweeper.belief import FREE, OBSTACLE, UNKNOWN, RobotMap
from motiongym.envs.sweeper.maps import MAX_SIDE

MISMATCH = 0.5  # log-weight per window cell that disagrees with the map
BLOCKED = 4.0  # log-weight per map obstacle under the footprint
MAX_SLIP = 1.4  # the environment's longest move (cells)
MIN_SLIP = 0.05  # the particles' slip std at least (roughening; see the module docstring)


class Localiser:
    """The policy's pose estimate in its own map frame (see the module docstring).

    Args:
        w, R: robot width and sensing range (cells).
        heading_noise, slip_noise: the odometry spec (rad per action, relative).
        n: particles.
        seed: of the filter's own random generator (same seed, same run).
        diffusion: extra heading-error std per forward move (rad; see the docstring).
    """

    def __init__(
        self,
        w: int,
        R: int,
        heading_noise: float,
        slip_noise: float,
        n: int = 256,
        seed: int = 0,
        diffusion: float = 0.0,
    ) -> None:
        self.w, self.R, self.S = w, R, w + 2 * R
        self.diffusion = diffusion
        self.sh, self.ss, self.n = heading_noise, max(slip_noise, MIN_SLIP), n
        self.rng = np.random.default_rng(seed)
        # (n,) particle states (row, column, heading error), set at the first observation
        self.y: np.ndarray = np.zeros(0)
        self.x: np.ndarray = np.zeros(0)
        self.e: np.ndarray = np.zeros(0)
        self.wt = np.full(n, 1.0 / n)
        self.reckoned: tuple[int, int] | None = None  # the last dead-reckoned cell
        self.heading = 0  # the last observed (commanded) heading
        self.cell = (0, 0)

    def locate(self, robot_map: RobotMap, obs: dict) -> tuple[int, int]:
        """The estimated cell for this observation (call before writing it into the map)."""
        pose = np.asarray(obs["pose"])
        reckoned = int(round(float(pose[0]))), int(round(float(pose[1])))
        h = int(round(float(pose[2])))
        if self.reckoned is None:  # the first observation: the start is known exactly
            self.reckoned, self.cell, self.heading = reckoned, reckoned, h
            self.y = np.full(self.n, float(reckoned[0]))
            self.x = np.full(self.n, float(reckoned[1]))
            self.e = np.zeros(self.n)
            return self.cell
        # a forward move that did not bump: the heading is unchanged (a turn always changes
        # it) and no bump; the dead-reckoned cell is no witness, as it is clipped to the map
        self._move(h == self.heading and pose[3] <= 0.5, h)
        self.reckoned, self.heading = reckoned, h
        if pose[3] > 0.5:
            self._felt(robot_map, h)
        self._weigh(robot_map, obs)
        self._estimate()
        return self.cell

    def observe(self, robot_map: RobotMap, obs: dict) -> tuple[int, int, int, bool]:
        """Locate, then write the observation into ``robot_map`` at the estimate; return
        ``(row, col, heading, bump)`` (:meth:`.belief.RobotMap.integrate`)."""
        return robot_map.integrate(obs, self.locate(robot_map, obs))

    def _move(self, moved: bool, h: int) -> None:
        n = self.n
        self.e += self.rng.normal(0.0, self.sh, n) if self.sh else 0.0
        if moved:
            if self.diffusion:
                self.e += self.rng.normal(0.0, self.diffusion, n)
            d = 1.0 + (self.rng.normal(0.0, self.ss, n) if self.ss else 0.0)
            d = np.clip(d, 0.0, MAX_SLIP)
            angle = h * math.pi / 2 + self.e
            self.y = np.clip(self.y - d * np.sin(angle), -self.w, MAX_SIDE - 1)
            self.x = np.clip(self.x + d * np.cos(angle), -self.w, MAX_SIDE - 1)

    def _felt(self, robot_map: RobotMap, h: int) -> None:
        """A bump: a particle whose move ahead would have found its footprint free in
        the map explains it badly (weight times ``exp(-BLOCKED)``)."""
        angle = h * math.pi / 2 + self.e
        r = np.rint(self.y - np.sin(angle)).astype(np.int64)
        c = np.rint(self.x + np.cos(angle)).astype(np.int64)
        o, w = robot_map.off, self.w
        k = np.arange(w)
        occ = robot_map.occ[(r + o)[:, None, None] + k[:, None], (c + o)[:, None, None] + k]
        free = (occ == FREE).all(axis=(1, 2)) & ~robot_map.felt[r + o, c + o]
        self.wt = self.wt * np.where(free, math.exp(-BLOCKED), 1.0)
        self.wt /= self.wt.sum()

    def _cells(self) -> tuple[np.ndarray, np.ndarray]:
        """Unique particle cells ``(U, 2)`` and each particle's index into them."""
        cells = np.stack([np.rint(self.y), np.rint(self.x)], axis=1).astype(np.int64)
        return np.unique(cells, axis=0, return_inverse=True)

    def _weigh(self, robot_map: RobotMap, obs: dict) -> None:
        S, R, w, o = self.S, self.R, self.w, robot_map.off
        sensed = np.asarray(obs["sensed"]).reshape(S, S) > 0.5
        known = np.asarray(obs["known"]).reshape(S, S) > 0.5 if "known" in obs else True
        uniq, inv = self._cells()
        rr = uniq[:, 0, None, None] - R + o + np.arange(S)[None, :, None]
        cc = uniq[:, 1, None, None] - R + o + np.arange(S)[None, None, :]
        occ = np.where(robot_map.felt[rr, cc], UNKNOWN, robot_map.occ[rr, cc])  # (U, S, S)
        valid = (occ != UNKNOWN) & known
        disagree = (valid & ((occ == OBSTACLE) != sensed)).sum(axis=(1, 2))
        blocked = (occ[:, R : R + w, R : R + w] != FREE).sum(axis=(1, 2))
        logw = -(MISMATCH * disagree + BLOCKED * blocked).astype(float)
        wt = self.wt * np.exp(logw - logw.max())[inv.ravel()]
        self.wt = wt / wt.sum()
        if 1.0 / np.sum(self.wt**2) < self.n / 2:
            self._resample()

    def _resample(self) -> None:
        n = self.n
        edges = np.cumsum(self.wt)
        edges[-1] = 1.0
        k = np.searchsorted(edges, (self.rng.random() + np.arange(n)) / n)
        self.y, self.x, self.e = self.y[k], self.x[k], self.e[k]
        self.wt = np.full(n, 1.0 / n)

    def _estimate(self) -> None:
        uniq, inv = self._cells()
        mass = np.bincount(inv.ravel(), weights=self.wt, minlength=len(uniq))
        best = uniq[int(np.argmax(mass))]
        self.cell = int(best[0]), int(best[1])

    def continuous(self) -> tuple[float, float, float]:
        """``(y, x, e)``: the weighted mean position of the particles in the estimated cell
        and the weighted mean heading error of all."""
        at = (np.rint(self.y) == self.cell[0]) & (np.rint(self.x) == self.cell[1])
        wt = self.wt * at if at.any() else self.wt
        if wt.sum() <= 0:  # every weight in the cell underflowed: its particles alike
            wt = at.astype(float)  # (at.any() here: self.wt alone sums to 1)
        e = float(np.average(self.e, weights=self.wt))
        return float(np.average(self.y, weights=wt)), float(np.average(self.x, weights=wt)), e

    @property
    def spread(self) -> float:
        """Weighted standard deviation of the particles' positions (cells)."""
        my, mx = np.average(self.y, weights=self.wt), np.average(self.x, weights=self.wt)
        return float(np.sqrt(np.average((self.y - my) ** 2 + (self.x - mx) ** 2, weights=self.wt)))
