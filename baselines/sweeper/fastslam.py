"""A map per particle: grid-based FastSLAM (a Rao-Blackwellised particle filter).

:class:`~.localise.Localiser` files every window into one map at its
estimate; a window filed at a wrong pose stays there, the map then agrees
with the error, and nothing repairs it. Here each particle carries its own
pose *and* its own map (occupancy votes and sweep marks), built from the
windows filed at that particle's own poses: the posterior over the robot's
path and map is factored into the path (sampled) and the map given the path
(Rao-Blackwellisation: Murphy 1999, Doucet, de Freitas, Murphy & Russell
2000; FastSLAM: Montemerlo, Thrun, Koller & Wegbreit 2002; on occupancy
grids: Haehnel, Burgard, Fox & Thrun 2003; Grisetti, Stachniss & Burgard
2007, "GMapping"). A particle whose path went wrong holds a map that
disagrees with what the robot senses when it comes back to a place it has
mapped, and it loses weight there; the particles whose paths stayed right
keep maps without double walls, and resampling copies those maps.

The rules (motion, bump evidence, window likelihood, roughening) are the
single-map filter's (:mod:`.localise`), each applied with the particle's own
map; what differs:

- **Maps.** Per particle, a vote count per cell (``+1`` per sensing as
  obstacle, ``-1`` as free, clipped to ``+-evidence``; never sensed:
  unknown) and a sweep mark per cell, on a box that grows with the explored
  area. After weighing, every particle files the window at its own cell and
  marks its footprint swept.
- **Resampling** (systematic, when the effective number of particles falls
  below half: selective resampling, Grisetti et al. 2007): a surviving
  particle keeps its map in place, only the particles that die get a copy of
  a parent's.
- **The policy's map** is the map of the particle with the highest
  accumulated log-weight along its ancestry (GMapping's choice of map), the
  estimate its cell; the policy plans on that map and its sweep marks, so
  the pose and the map it acts on belong to one path.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from motiongym.baselines.sweeper.belief import FREE, OBSTACLE, UNKNOWN, RobotMap
from motiongym.baselines.sweeper.localise import BLOCKED, MISMATCH, Localiser

MARGIN = 16  # cells the map box grows by beyond a window that leaves it


class ParticleMaps(Localiser):
    """Particles with a map each (see the module docstring); the same arguments as
    :class:`~.localise.Localiser` and ``evidence``, the votes a cell holds at most."""

    def __init__(self, *args: Any, evidence: int = 4, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.evidence = evidence
        n = self.n
        self.origin = np.zeros(2, np.int64)  # map cell of the box's index (0, 0)
        self.votes = np.zeros((n, 0, 0), np.int8)  # (n, H, W) clipped votes
        self.seen = np.zeros((n, 0, 0), bool)  # (n, H, W) sensed at least once
        self.swept = np.zeros((n, 0, 0), bool)  # (n, H, W) footprint marks
        self.score = np.zeros(n)  # accumulated log-weight along each particle's ancestry
        self.best = 0  # the particle whose map the policy plans on

    # ---------------------------------------------------------------- the box
    def _fit(self, rows: np.ndarray, cols: np.ndarray) -> None:
        """Grow the box so that the cells from ``rows.min()`` to ``rows.max()`` (and the
        columns) fit."""
        n, H, W = self.votes.shape
        lo = np.array([rows.min(), cols.min()]) - self.origin
        hi = np.array([rows.max(), cols.max()]) - self.origin + 1
        if H and (lo >= 0).all() and hi[0] <= H and hi[1] <= W:
            return
        if not H:
            self.origin = np.array([rows.min(), cols.min()]) - MARGIN
            pad_lo, size = np.array([0, 0]), hi - lo + 2 * MARGIN
        else:
            pad_lo = np.maximum(-lo, 0) + np.where(lo < 0, MARGIN, 0)
            pad_hi = np.maximum(hi - (H, W), 0) + np.where(hi > (H, W), MARGIN, 0)
            size = np.array([H, W]) + pad_lo + pad_hi
            self.origin = self.origin - pad_lo
        for name in ("votes", "seen", "swept"):
            old = getattr(self, name)
            new = np.zeros((n, int(size[0]), int(size[1])), old.dtype)
            new[:, pad_lo[0] : pad_lo[0] + H, pad_lo[1] : pad_lo[1] + W] = old
            setattr(self, name, new)

    def _windows(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Per particle its window's box indices: ``(k, rr, cc)`` broadcastable to (n, S, S)."""
        S, R = self.S, self.R
        cr = np.rint(self.y).astype(np.int64) - R - self.origin[0]
        cc = np.rint(self.x).astype(np.int64) - R - self.origin[1]
        k = np.arange(self.n)[:, None, None]
        ar = np.arange(S)
        return k, cr[:, None, None] + ar[None, :, None], cc[:, None, None] + ar[None, None, :]

    def _occ(self, k, rr, cc) -> np.ndarray:
        """Occupancy (UNKNOWN / FREE / OBSTACLE) of particle ``k``'s map at box cells."""
        seen = self.seen[k, rr, cc]
        return np.where(seen, np.where(self.votes[k, rr, cc] > 0, OBSTACLE, FREE), UNKNOWN)

    # -------------------------------------------------------------- one step
    def observe(self, robot_map: RobotMap, obs: dict) -> tuple[int, int, int, bool]:
        """Track, file the window in every particle's map, and copy the best particle's
        map into ``robot_map``; return ``(row, col, heading, bump)`` as
        :meth:`.belief.RobotMap.integrate` does."""
        pose = np.asarray(obs["pose"])
        h, bump = int(round(float(pose[2]))), bool(pose[3] > 0.5)
        first = self.reckoned is None
        cell = self.locate(robot_map, obs)
        if first:
            self.best = 0
        self._file(obs)
        self._publish(robot_map)
        self.cell = cell = (int(np.rint(self.y[self.best])), int(np.rint(self.x[self.best])))
        return cell[0], cell[1], h, bump

    def _felt(self, robot_map: RobotMap, h: int) -> None:
        angle = h * math.pi / 2 + self.e
        r = np.rint(self.y - np.sin(angle)).astype(np.int64)
        c = np.rint(self.x + np.cos(angle)).astype(np.int64)
        w, o = self.w, robot_map.off
        self._fit(np.concatenate([r, r + w]), np.concatenate([c, c + w]))
        k = np.arange(self.n)[:, None, None]
        a = np.arange(w)
        rr = (r - self.origin[0])[:, None, None] + a[None, :, None]
        cc = (c - self.origin[1])[:, None, None] + a[None, None, :]
        free = (self._occ(k, rr, cc) == FREE).all(axis=(1, 2)) & ~robot_map.felt[r + o, c + o]
        logw = np.where(free, -BLOCKED, 0.0)
        self.score += logw
        self.wt = self.wt * np.exp(logw)
        self.wt /= self.wt.sum()

    def _weigh(self, robot_map: RobotMap, obs: dict) -> None:
        S, R, w, o = self.S, self.R, self.w, robot_map.off
        sensed = np.asarray(obs["sensed"]).reshape(S, S) > 0.5
        known = np.asarray(obs["known"]).reshape(S, S) > 0.5 if "known" in obs else True
        cr, cc = np.rint(self.y).astype(np.int64), np.rint(self.x).astype(np.int64)
        self._fit(np.concatenate([cr - R, cr + R + w]), np.concatenate([cc - R, cc + R + w]))
        k, rr, cc_ = self._windows()
        occ = self._occ(k, rr, cc_)  # (n, S, S)
        gr, gc = rr + self.origin[0] + o, cc_ + self.origin[1] + o
        occ = np.where(robot_map.felt[gr, gc], UNKNOWN, occ)
        valid = (occ != UNKNOWN) & known
        disagree = (valid & ((occ == OBSTACLE) != sensed)).sum(axis=(1, 2))
        blocked = (occ[:, R : R + w, R : R + w] != FREE).sum(axis=(1, 2))
        logw = -(MISMATCH * disagree + BLOCKED * blocked).astype(float)
        self.score += logw
        wt = self.wt * np.exp(logw - logw.max())
        self.wt = wt / wt.sum()
        if 1.0 / np.sum(self.wt**2) < self.n / 2:
            self._resample()

    def _resample(self) -> None:
        n = self.n
        edges = np.cumsum(self.wt)
        edges[-1] = 1.0
        parent = np.searchsorted(edges, (self.rng.random() + np.arange(n)) / n)
        counts = np.bincount(parent, minlength=n)
        # survivors stay in place; each dead slot takes a copy of a parent drawn twice or more
        dead = np.flatnonzero(counts == 0)
        extra = np.repeat(np.arange(n), np.maximum(counts - 1, 0))
        k = np.arange(n)
        k[dead] = extra
        if len(dead):
            self.votes[dead] = self.votes[extra]
            self.seen[dead] = self.seen[extra]
            self.swept[dead] = self.swept[extra]
        self.y, self.x, self.e, self.score = self.y[k], self.x[k], self.e[k], self.score[k]
        self.wt = np.full(n, 1.0 / n)

    def _estimate(self) -> None:
        self.score -= self.score.max()
        self.best = int(np.argmax(self.score))
        self.cell = int(np.rint(self.y[self.best])), int(np.rint(self.x[self.best]))

    def _file(self, obs: dict) -> None:
        """Every particle files the window at its cell and marks its footprint swept."""
        S, R, w = self.S, self.R, self.w
        sensed = np.asarray(obs["sensed"]).reshape(S, S) > 0.5
        known = np.ones((S, S), bool)
        if "known" in obs:
            known = np.asarray(obs["known"]).reshape(S, S) > 0.5
        cr, cc0 = np.rint(self.y).astype(np.int64), np.rint(self.x).astype(np.int64)
        self._fit(np.concatenate([cr - R, cr + R + w]), np.concatenate([cc0 - R, cc0 + R + w]))
        k, rr, cc = self._windows()
        step = np.where(sensed, 1, -1).astype(np.int8) * known
        v = self.votes[k, rr, cc]
        self.votes[k, rr, cc] = np.clip(v + step, -self.evidence, self.evidence)
        self.seen[k, rr, cc] |= known
        self.swept[k, rr[:, R : R + w], cc[:, :, R : R + w]] = True

    def _publish(self, robot_map: RobotMap) -> None:
        """Copy the best particle's map into the policy's (bump marks stay obstacles)."""
        b, o = self.best, robot_map.off
        H, W = self.votes.shape[1:]
        r0, c0 = int(self.origin[0]) + o, int(self.origin[1]) + o
        # the box may reach past the policy map's array: clip it there
        a0, b0 = max(r0, 0), max(c0, 0)
        a1, b1 = min(r0 + H, robot_map.occ.shape[0]), min(c0 + W, robot_map.occ.shape[1])
        sub = (slice(a0 - r0, a1 - r0), slice(b0 - c0, b1 - c0))
        occ = np.where(self.seen[b][sub], np.where(self.votes[b][sub] > 0, OBSTACLE, FREE), UNKNOWN)
        region = robot_map.occ[a0:a1, b0:b1]
        region[:] = occ
        region[robot_map.felt[a0:a1, b0:b1]] = OBSTACLE
        robot_map.swept[a0:a1, b0:b1] = self.swept[b][sub]
        seen = np.argwhere(self.seen[b][sub])
        if len(seen):
            robot_map.lo = np.minimum(robot_map.lo, seen.min(axis=0) + (a0, b0))
            robot_map.hi = np.maximum(robot_map.hi, seen.max(axis=0) + (a0, b0) + 1)
